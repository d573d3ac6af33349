// Problems registered by name for YAML configs: `problem: NAME`.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "opt/config.hpp"
#include "opt/problem.hpp"
#include "opt/study.hpp"

namespace problems {

using Factory = std::function<std::unique_ptr<opt::Problem>(const opt::ConfigNode& root)>;

struct Entry {
  std::string name, summary;
  std::vector<opt::Parameter> parameters;  // its table, with the default values
  Factory make;
};

// Each problem registers itself from its own file, at start-up:
//   const problems::Registration kRegistration{{"name", "summary", parameters, make}};
struct Registration {
  explicit Registration(Entry e);
};

// Every registered problem, sorted by name.
const std::vector<Entry>& registry();

// Builds the problem named by the config's `problem` key from its `model` and
// `variables` sections; bad input is an opt::ConfigError. A model value
// written as a link, {from: FILE, metric: NAME, KEY: VALUE...}, is the
// metric of FILE's problem (KEY: VALUE over its model values) at its
// initial design; the problem's `links` record each one.
std::unique_ptr<opt::Problem> make_problem(const opt::ConfigNode& root);

// The parameters a config's model values and DOE factors may name: the
// problem's table, and for each `from:` link KEY the linked problem's table
// as KEY.NAME (a factor `crank_radius.variant` sets the linked config's
// `variant` in every sample).
std::vector<opt::Parameter> parameters(const opt::ConfigNode& root);

// Top-level keys a config may have.
const std::vector<std::string>& config_keys();

}  // namespace problems
