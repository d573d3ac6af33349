// YAML configs with errors that name the file, line, column and key, what was
// expected and what came. Unknown keys are errors (with a suggestion).
#pragma once
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "opt/units.hpp"

namespace opt {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A node of a config, with the file and key path it came from.
class ConfigNode {
 public:
  ConfigNode(YAML::Node node, std::string file, std::string path, YAML::Mark fallback = {})
      : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)),
        mark_(node_.IsDefined() && node_.Mark().line >= 0 ? node_.Mark() : fallback) {}

  // Loads a YAML file; unreadable files and YAML syntax errors are ConfigErrors.
  // `base: FILE` (relative to the file) names a config whose keys this one
  // inherits and may override, map by map.
  static ConfigNode load(const std::string& file);
  static ConfigNode parse(const std::string& text, const std::string& name);
  // This config with `over`'s keys over its own, map by map (as a file's
  // keys over its base file's): e.g. one DOE sample's model values. Errors
  // in `over` name `name`.
  ConfigNode with(const YAML::Node& over, const std::string& name) const;
  // A deep copy (base files included) that shares no YAML tree with this
  // one: yaml-cpp trees are not to be read from two threads.
  ConfigNode clone() const;
  // The config with its base files merged, as JSON (scalars as written), for
  // hashing and for the record of a run.
  nlohmann::json to_json() const;

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  const YAML::Node& yaml() const { return node_; }
  bool is_map() const { return node_.IsMap(); }
  bool is_sequence() const { return node_.IsSequence(); }
  bool is_scalar() const { return node_.IsScalar(); }

  bool has(const std::string& key) const;
  // A required child (error if absent).
  ConfigNode at(const std::string& key) const;
  std::vector<std::string> keys() const;
  std::vector<ConfigNode> items() const;  // elements of a sequence
  // Errors if this map has a key outside `allowed`.
  void allow_only(const std::vector<std::string>& allowed) const;
  void expect_map() const;

  std::string text() const;                                   // a scalar as written
  std::string choice(const std::vector<std::string>& options) const;
  double quantity(Dimension d) const;                         // SI value
  // The same, and outside `domain` is an error naming the domain.
  double quantity(Dimension d, const Domain& domain) const;
  double number() const { return quantity(Dimension::dimensionless); }
  // The quantity under `key` if present, else `fallback`; outside `domain`
  // is an error naming the domain.
  double quantity_or(const std::string& key, Dimension d, double fallback,
                     const Domain& domain = kAnyValue) const;
  int integer(int min, int max) const;
  bool boolean() const;

  // "FILE:LINE:COL" of this node (1-based).
  std::string where() const;
  // "FILE:LINE:COL: key 'PATH': WHAT" (line and column 1-based).
  [[noreturn]] void fail(const std::string& what) const;

 private:
  YAML::Node node_;
  std::string file_, path_;
  YAML::Mark mark_;
  std::shared_ptr<const ConfigNode> base_;  // the same path in the base file, if any
};

// A path a config names (`base:`, a link's `from:`), relative to the file it
// is written in unless absolute.
std::string relative_to(const std::string& file, const std::string& name);

// Sets KEY of map n; a dotted key names a key in sections: "motor.slip" is
// n["motor"]["slip"].
void set_dotted(YAML::Node n, const std::string& key, const YAML::Node& v);
// The config with model values set by key (a dotted key walks the model's
// maps; a pair's x or y sets that coordinate), as `mechopt eval --set` and a
// DOE sample set them; a variable KEY's `initial` too, so that the variable
// is evaluated at the value set rather than at its initial.
ConfigNode with_model_values(const ConfigNode& root, const std::vector<std::pair<std::string, std::string>>& values);

}  // namespace opt
