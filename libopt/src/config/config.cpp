#include "opt/config.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/text.hpp"

namespace opt {
namespace {

// Edit distance, for "did you mean" on misspelt keys.
size_t distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t prev = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t cur = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, prev + (a[i - 1] != b[j - 1])});
      prev = cur;
    }
  }
  return row[b.size()];
}

using text::join;

std::string child_path(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

// A node as one short line for a message: a block list or map would break
// the one-line error.
std::string shown(const YAML::Node& n) {
  YAML::Emitter e;
  e.SetSeqFormat(YAML::Flow);
  e.SetMapFormat(YAML::Flow);
  e << n;
  std::string t = e.c_str();
  for (char& c : t)
    if (c == '\n') c = ' ';
  return t.size() > 60 ? t.substr(0, 57) + "..." : t;
}

std::string line_col(const YAML::Mark& m) {
  return std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
}

// The most nodes one walk of a config may visit. yaml-cpp loads an alias
// (*a) as a reference to its anchor's node, so a 1 KB file of nested aliases
// (nine of *a0 in &a1, nine of *a1 in &a2, ... twelve deep) is a small tree
// in memory that every walk of it (this check, hashing, copying for a DOE
// sample) expands to 9^12 nodes. The largest shipped config has a few
// hundred nodes; a list of points this long (200 000 rows of four factors)
// belongs in a points_file. A walk of 10^6 nodes takes about 0.2 s.
constexpr long kMaxNodes = 1'000'000;

// yaml-cpp keeps a key written twice and reads the first: a config that sets
// a value twice is an error naming both lines. The same walk counts the nodes
// (kMaxNodes).
void reject_duplicate_keys(const YAML::Node& n, const std::string& file, const std::string& path,
                           long& visited) {
  if (++visited > kMaxNodes)
    throw ConfigError(file + ":" + line_col(n.Mark()) + ": " + (path.empty() ? "" : "key '" + path + "': ") +
                      "the YAML expands to more than " + std::to_string(kMaxNodes) +
                      " nodes through its aliases (*name); write the values out or use fewer nested aliases");
  if (n.IsSequence())
    for (size_t i = 0; i < n.size(); ++i)
      reject_duplicate_keys(n[i], file, path + "[" + std::to_string(i) + "]", visited);
  if (!n.IsMap()) return;
  std::vector<std::pair<std::string, YAML::Mark>> seen;
  for (const auto& kv : n) {
    if (!kv.first.IsScalar()) {
      throw ConfigError(file + ":" + line_col(kv.first.Mark()) + ": " +
                        (path.empty() ? "" : "key '" + path + "': ") + "expected a plain key name");
    }
    const std::string key = kv.first.Scalar();
    for (const auto& [k, mark] : seen)
      if (k == key)
        throw ConfigError(file + ":" + line_col(kv.first.Mark()) + ": key '" + child_path(path, key) +
                          "': written twice (first at line " + std::to_string(mark.line + 1) +
                          ", again at line " + std::to_string(kv.first.Mark().line + 1) +
                          "); give it once");
    seen.emplace_back(key, kv.first.Mark());
    reject_duplicate_keys(kv.second, file, child_path(path, key), visited);
  }
}

}  // namespace

ConfigNode ConfigNode::load(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw ConfigError(file + ": cannot read the config file (does it exist?)");
  std::stringstream ss;
  ss << in.rdbuf();
  ConfigNode root = parse(ss.str(), file);
  ConfigNode* layer = &root;
  for (int depth = 0; layer->node_["base"].IsDefined(); ++depth) {
    const ConfigNode b(layer->node_["base"], layer->file_, "base", layer->mark_);
    if (depth == 8) b.fail("more than 8 base files in a chain (does one name itself?)");
    const std::string name = relative_to(layer->file_, b.text());
    if (!std::ifstream(name)) b.fail("cannot read the base file '" + name + "'");
    std::ifstream bin(name);
    std::stringstream bs;
    bs << bin.rdbuf();
    layer->base_ = std::make_shared<ConfigNode>(parse(bs.str(), name));
    layer = const_cast<ConfigNode*>(layer->base_.get());
  }
  return root;
}

ConfigNode ConfigNode::parse(const std::string& text, const std::string& name) {
  try {
    YAML::Node root = YAML::Load(text);
    if (!root.IsMap())
      throw ConfigError(name + ":1:1: expected a YAML mapping of keys at the top level");
    long visited = 0;
    reject_duplicate_keys(root, name, "", visited);
    return ConfigNode(root, name, "");
  } catch (const YAML::Exception& e) {
    throw ConfigError(name + ":" + std::to_string(e.mark.line + 1) + ":" +
                      std::to_string(e.mark.column + 1) + ": invalid YAML: " + e.msg);
  }
}

ConfigNode ConfigNode::with(const YAML::Node& over, const std::string& name) const {
  ConfigNode top(over, name, path_, YAML::Mark::null_mark());
  top.base_ = std::make_shared<ConfigNode>(*this);
  return top;
}

ConfigNode ConfigNode::clone() const {
  ConfigNode c(YAML::Clone(node_), file_, path_, mark_);
  if (base_) c.base_ = std::make_shared<ConfigNode>(base_->clone());
  return c;
}

nlohmann::json ConfigNode::to_json() const {
  if (is_map()) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& k : keys()) j[k] = has(k) ? at(k).to_json() : nlohmann::json();
    return j;
  }
  if (is_sequence()) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& item : items()) j.push_back(item.to_json());
    return j;
  }
  return is_scalar() ? nlohmann::json(text()) : nlohmann::json();
}

std::string ConfigNode::where() const {
  return mark_.line >= 0 ? file_ + ":" + line_col(mark_) : file_;
}

void ConfigNode::fail(const std::string& what) const {
  throw ConfigError(where() + ": " + (path_.empty() ? "" : "key '" + path_ + "': ") + what);
}

void ConfigNode::expect_map() const {
  if (!node_.IsMap()) fail("expected a mapping of keys, got '" + shown(node_) + "'");
}

bool ConfigNode::has(const std::string& key) const {
  return (node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull()) || (base_ && base_->has(key));
}

ConfigNode ConfigNode::at(const std::string& key) const {
  expect_map();
  if (!has(key)) fail("missing required key '" + key + "'");
  if (!(node_[key].IsDefined() && !node_[key].IsNull())) return base_->at(key);
  ConfigNode child(node_[key], file_, child_path(path_, key), mark_);
  // A map in both files: this one's keys over the base's. A map {x, y}
  // over a pair [x, y] (a point, one coordinate set): over its items as x, y.
  if (base_ && base_->has(key) && child.is_map()) {
    ConfigNode below = base_->at(key);
    if (below.is_sequence() && below.node_.size() == 2) {
      YAML::Node xy(YAML::NodeType::Map);
      xy["x"] = below.node_[0];
      xy["y"] = below.node_[1];
      below = ConfigNode(xy, below.file_, below.path_, below.mark_);
    }
    if (below.is_map()) child.base_ = std::make_shared<ConfigNode>(std::move(below));
  }
  return child;
}

std::vector<std::string> ConfigNode::keys() const {
  expect_map();
  std::vector<std::string> out;
  for (const auto& kv : node_) out.push_back(kv.first.as<std::string>());
  if (base_ && base_->is_map())
    for (const auto& k : base_->keys())
      if (std::find(out.begin(), out.end(), k) == out.end()) out.push_back(k);
  return out;
}

std::vector<ConfigNode> ConfigNode::items() const {
  if (!node_.IsSequence()) fail("expected a list [a, b, ...], got '" + shown(node_) + "'");
  std::vector<ConfigNode> out;
  for (size_t i = 0; i < node_.size(); ++i)
    out.emplace_back(node_[i], file_, path_ + "[" + std::to_string(i) + "]", mark_);
  return out;
}

void ConfigNode::allow_only(const std::vector<std::string>& allowed) const {
  expect_map();
  if (base_ && base_->is_map()) base_->allow_only(allowed);
  for (const auto& kv : node_) {
    const std::string key = kv.first.as<std::string>();
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
    std::string hint;
    size_t best = 3;
    for (const auto& a : allowed)
      if (const size_t dist = distance(key, a); dist < best) best = dist, hint = a;
    ConfigNode(kv.first, file_, child_path(path_, key), mark_)
        .fail("unknown key" + (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
              "; expected one of: " + join(allowed));
  }
}

std::string ConfigNode::text() const {
  if (!node_.IsScalar()) fail("expected a single value, got '" + shown(node_) + "'");
  return node_.Scalar();
}

std::string ConfigNode::choice(const std::vector<std::string>& options) const {
  const std::string t = text();
  if (std::find(options.begin(), options.end(), t) == options.end())
    fail("expected one of: " + join(options) + "; got '" + t + "'");
  return t;
}

double ConfigNode::quantity(Dimension d) const {
  const std::string t = text();
  const ParsedQuantity q = parse_quantity(t, d);
  if (!q.error.empty()) {
    const std::string si = si_unit(d);
    fail("expected " + to_string(d) + (si.empty() ? "" : " (SI unit " + si + ")") + ", got '" + t + "': " + q.error);
  }
  return q.value;
}

double ConfigNode::quantity_or(const std::string& key, Dimension d, double fallback,
                               const Domain& domain) const {
  if (!has(key)) return fallback;
  return at(key).quantity(d, domain);
}

double ConfigNode::quantity(Dimension d, const Domain& domain) const {
  const double v = quantity(d);
  if (!domain.contains(v)) {
    const bool interval = std::isfinite(domain.lo) && std::isfinite(domain.hi);
    fail("expected a value " + std::string(interval ? "in " : "") + to_string(domain, d) + ", got '" + text() + "'");
  }
  return v;
}

int ConfigNode::integer(int min, int max) const {
  // A whole number in any number form: 20000, 2e4 and 20000.0 alike.
  const std::string t = text();
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || *end != '\0' || !(v >= min && v <= max) || v != std::floor(v))
    fail("expected a whole number from " + std::to_string(min) + " to " + std::to_string(max) +
         ", got '" + t + "'");
  return static_cast<int>(v);
}

bool ConfigNode::boolean() const {
  return choice({"true", "false"}) == "true";
}

std::string relative_to(const std::string& file, const std::string& name) {
  return (std::filesystem::path(file).parent_path() / name).string();
}

void set_dotted(YAML::Node n, const std::string& key, const YAML::Node& v) {
  const auto dot = key.find('.');
  if (dot == std::string::npos) n[key] = v;
  else set_dotted(n[key.substr(0, dot)], key.substr(dot + 1), v);
}

ConfigNode with_model_values(const ConfigNode& root, const std::vector<std::pair<std::string, std::string>>& values) {
  if (values.empty()) return root;
  YAML::Node over;
  const YAML::Node variables = root.has("variables") ? root.at("variables").yaml() : YAML::Node();
  for (const auto& [key, value] : values) {
    set_dotted(over["model"], key, YAML::Node(value));
    if (variables.IsMap() && variables[key] && variables[key].IsMap()) over["variables"][key]["initial"] = value;
  }
  return root.with(over, "--set");  // a new node over the config: nothing written into its tree
}

}  // namespace opt
