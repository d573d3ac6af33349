// One parameter table per problem: for every model value a config may set,
// its name, physical dimension, domain, one doc line, seed equation, whether
// a config may free it as a design variable, and where it is stored. The
// YAML reader, the checks on model values, bounds, initial values and grid
// points, `mechopt list` and the config reference in docs/ all read it.
#pragma once
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "opt/config.hpp"
#include "opt/problem.hpp"
#include "opt/units.hpp"

namespace opt {

struct Parameter {
  // The key under `model:`; a dotted name sits in a section
  // ("motor.critical_torque" is model: {motor: {critical_torque: ..}}).
  std::string name;
  Dimension dimension = Dimension::dimensionless;
  Domain domain = kAnyValue;
  std::string doc;       // one line: what it is
  std::string equation;  // where it comes from, e.g. "seed 000 eq. (14)"; or "" (a choice of ours)
  std::vector<std::string> choices;  // a named choice: the value is the option's index
  bool integer = false;              // a whole number within the domain
  bool automatic = false;            // `auto` is accepted too, stored as 0
  bool variable = false;             // a config may free it under `variables:`
  double value = 0;                  // the default (filled from the default model)
  // A model fidelity choice: its options from the coarsest (cheapest) to the
  // finest; a config may write `auto` (problems::make_problem picks one).
  std::vector<std::string> coarse_to_fine;

  // The same choice as a fidelity level, its options ordered coarsest first.
  Parameter fidelity(std::vector<std::string> coarsest_first) const {
    Parameter p = *this;
    p.coarse_to_fine = std::move(coarsest_first);
    return p;
  }
  // The same, also accepting `auto` (stored as 0, outside the domain proper).
  Parameter or_auto() const {
    Parameter p = *this;
    p.automatic = true;
    return p;
  }
};

// Rows of a table, by kind.
inline Parameter quantity(std::string name, Dimension d, Domain domain, std::string doc, std::string eq) {
  return {std::move(name), d, domain, std::move(doc), std::move(eq), {}, false, false, false, 0, {}};
}
// A quantity a config may also free as a design variable.
inline Parameter variable(std::string name, Dimension d, Domain domain, std::string doc, std::string eq) {
  Parameter p = quantity(std::move(name), d, domain, std::move(doc), std::move(eq));
  p.variable = true;
  return p;
}
inline Parameter choice(std::string name, std::vector<std::string> options, std::string doc, std::string eq) {
  return {std::move(name), Dimension::dimensionless, kAnyValue, std::move(doc), std::move(eq),
          std::move(options), false, false, false, 0, {}};
}
inline Parameter whole(std::string name, Domain domain, std::string doc, std::string eq) {
  return {std::move(name), Dimension::dimensionless, domain, std::move(doc), std::move(eq), {}, true, false, false, 0, {}};
}

// A row of a problem's table with where its value is stored in the problem's
// Model (as a double: a choice's index, an integer, or an SI quantity).
template <class Model>
struct ParameterRow {
  Parameter p;
  std::function<void(Model&, double)> set;
  std::function<double(const Model&)> get;
};

template <class Model>
using ParameterTable = std::vector<ParameterRow<Model>>;

// set and get of a row from one field expression of `m`:
//   {variable("crank_radius", Dimension::length, kPositive, "crank radius r", "seed 000 eq. (1)"),
//    MECHOPT_STORED_AT(m.drive.crank_radius)}
#define MECHOPT_STORED_AT(field)                                                         \
  [](auto& m, double v) { field = static_cast<std::remove_cvref_t<decltype(field)>>(v); }, \
      [](const auto& m) { return static_cast<double>(field); }

// The value of row p from node n (a choice by name, a whole number, or a
// quantity with its unit), checked against p's domain.
double read_parameter(const ConfigNode& n, const Parameter& p);

// The value as a config would write it, in the unit a designer reads
// (display_units.hpp): "0.2 m", "90 deg", "opposed", "auto", "64".
std::string value_text(const Parameter& p);

// Value v of row p as a config writes it, exactly: an option name, a whole
// number, or the SI value to 17 digits with its SI unit.
std::string exact_value_text(const Parameter& p, double v);

// The domain as text in the same unit, e.g. "> 0 m", "[0, 180] deg",
// "one of: opposed, same_side".
std::string domain_text(const Parameter& p);

// The table row of each variable (by name, once, when the problem is built).
template <class Model>
std::vector<int> variable_rows(const ParameterTable<Model>& table, const std::vector<Variable>& vars) {
  std::vector<int> rows;
  for (const auto& v : vars)
    for (size_t i = 0; i < table.size(); ++i)
      if (table[i].p.name == v.name) rows.push_back(static_cast<int>(i));
  return rows;
}

// Unknown keys of `model` and of its sections are errors naming what is allowed.
void check_model_keys(const ConfigNode& model, const std::vector<Parameter>& rows);

// {name: value} of every row, a choice by its name, for result files.
nlohmann::json parameters_json(const std::vector<Parameter>& rows);

// Reads the `model` section into m: keys outside the table (or its
// sections) are errors, values outside their domain are located errors.
// Returns the names of the rows the config set.
template <class Model>
std::vector<std::string> read_parameters(const ConfigNode& root, const ParameterTable<Model>& table,
                                         Model& m) {
  std::vector<std::string> set;
  if (!root.has("model")) return set;
  std::vector<Parameter> rows;
  for (const auto& r : table) rows.push_back(r.p);
  const ConfigNode model = root.at("model");
  check_model_keys(model, rows);
  for (const auto& r : table) {
    // (No ConfigNode is assigned to: a YAML::Node assignment writes into the tree.)
    const auto dot = r.p.name.find('.');
    if (dot != std::string::npos && !model.has(r.p.name.substr(0, dot))) continue;
    const ConfigNode section = dot == std::string::npos ? model : model.at(r.p.name.substr(0, dot));
    const std::string key = dot == std::string::npos ? r.p.name : r.p.name.substr(dot + 1);
    if (!section.has(key)) continue;
    r.set(m, read_parameter(section.at(key), r.p));
    set.push_back(r.p.name);
  }
  return set;
}

// The rows as Parameters with their values in m.
template <class Model>
std::vector<Parameter> parameters(const ParameterTable<Model>& table, const Model& m) {
  std::vector<Parameter> out;
  for (const auto& r : table) {
    out.push_back(r.p);
    out.back().value = r.get(m);
  }
  return out;
}

}  // namespace opt
