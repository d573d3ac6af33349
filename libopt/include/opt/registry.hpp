// Problems registered by name for YAML configs: `problem: NAME`. A problem
// registers itself from its own file at start-up, in this tree or outside it.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "opt/config.hpp"
#include "opt/parameters.hpp"
#include "opt/problem.hpp"
#include "opt/run_spec.hpp"

namespace opt {

using Factory = std::function<std::unique_ptr<Problem>(const ConfigNode& root)>;

struct Entry {
  std::string name, summary;
  std::vector<Parameter> parameters;  // its table, with the default values
  Factory make;
  // A table the config makes (the general linkage's, named by its
  // description), for model_parameters; none: `parameters`.
  std::function<std::vector<Parameter>(const ConfigNode& root)> table = nullptr;
};

// Registers a problem with its own factory:
//   const opt::Registration kRegistration{{"name", "summary", parameters, make}};
struct Registration {
  explicit Registration(Entry e);
};

// A problem P on the parameter table `table`, built from a config: the model
// values read (read_values); P::resolve(values, root) where P declares it
// (values left at auto, rules across values, each failing at its key); the
// variables read (parse_variables); P::check_variables(vars, values, root)
// where P declares it; then P(values, vars), or P(values, vars, given) where
// P takes the values as the config gave them (auto as 0) too, or
// P(table, values, vars) where the table is built at run time (its rows
// named by the config) and P takes it.
template <class P>
std::unique_ptr<Problem> make_tabled(const ConfigNode& root, const std::vector<Parameter>& table) {
  const Values<double> given = read_values(root, table);
  Values<double> v = given;
  if constexpr (requires { P::resolve(v, root); }) P::resolve(v, root);
  std::vector<Variable> vars = parse_variables(root, with_values(table, v));
  if constexpr (requires { P::check_variables(vars, v, root); }) P::check_variables(vars, v, root);
  if constexpr (std::is_constructible_v<P, std::vector<Parameter>, Values<double>, std::vector<Variable>>)
    return std::make_unique<P>(table, std::move(v), std::move(vars));
  else if constexpr (std::is_constructible_v<P, Values<double>, std::vector<Variable>, const Values<double>&>)
    return std::make_unique<P>(std::move(v), std::move(vars), given);
  else
    return std::make_unique<P>(std::move(v), std::move(vars));
}

// Registers P, built by make_tabled, from the problem's own file:
//   const opt::Registered<SliderCrankProblem> kRegistration{"slider_crank", "one slider-crank ...", kTable};
// (`table` lives as long as the program: a namespace-scope table.)
template <class P>
struct Registered : Registration {
  Registered(std::string name, std::string summary, const std::vector<Parameter>& table)
      : Registration({std::move(name), std::move(summary), table,
                      [t = &table](const ConfigNode& root) { return make_tabled<P>(root, *t); }}) {}
};

// Every registered problem, sorted by name.
const std::vector<Entry>& registry();

// Builds the problem named by the config's `problem` key from its `model` and
// `variables` sections; bad input is an opt::ConfigError. A model value
// written as a link, {from: FILE, metric: NAME, KEY: VALUE...}, is the
// metric of FILE's problem (KEY: VALUE over its model values) at its
// initial design; the problem's `links` record each one.
std::unique_ptr<Problem> make_problem(const ConfigNode& root);

// The parameters a config's model values and DOE factors may name: the
// problem's table, and for each `from:` link KEY the linked problem's table
// as KEY.NAME (a factor `crank_radius.variant` sets the linked config's
// `variant` in every sample).
std::vector<Parameter> model_parameters(const ConfigNode& root);

// Top-level keys a config may have.
const std::vector<std::string>& config_keys();

}  // namespace opt
