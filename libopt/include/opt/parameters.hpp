// One parameter table per problem: for every model value a config may set,
// its name, physical dimension, domain, one doc line, seed equation, whether
// a config may free it as a design variable, and its default. The values
// themselves travel as one vector indexed by row (Values). The YAML reader,
// the checks on model values, bounds, initial values and grid points,
// `mechopt list` and the config reference all read the table.
#pragma once
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
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
  // finest; a config may write `auto` (opt::make_problem picks one).
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

// A problem's model values: one per row of its parameter table, in the
// table's order (a choice as its option's index, a whole number, or an SI
// quantity), on the scalar S of an evaluation: double, or an autodiff type
// whose derivatives are those of the variables. A problem names the rows by
// its own enum, whose values are the rows' positions: v[R::crank_radius].
template <class S>
using Values = std::vector<S>;

// A row of a problem's table as its file writes it: the problem's enum value
// for it (equal to its position, checked by table()), the parameter, and
// its default value.
struct TableRow {
  int id;
  Parameter p;
  template <class Id, class Number>  // (a whole number's default may be an int)
  TableRow(Id i, Parameter parameter, Number default_value)
      : id(static_cast<int>(i)), p(std::move(parameter)) {
    p.value = static_cast<double>(default_value);
  }
};

// The table of a problem's model values, each row's default in its `value`;
// throws std::logic_error naming `problem` when a row is not at its enum's
// position.
std::vector<Parameter> table(const std::string& problem, std::initializer_list<TableRow> rows);

// The model values of a config: each row's default, overwritten by the
// `model` section's value for it. Keys outside the table (or its sections)
// are errors, values outside their domain are located errors; `elsewhere`
// names model keys another reader takes (the elastic drive's `machine`, a
// linkage description), left alone here.
Values<double> read_values(const ConfigNode& root, const std::vector<Parameter>& table,
                           const std::vector<std::string>& elsewhere = {});

// The rows with their values set to v, for `mechopt list`, result files and
// parse_variables.
std::vector<Parameter> with_values(std::vector<Parameter> table, const Values<double>& v);

// The table row of each variable (by name, once, when the problem is built).
std::vector<int> variable_rows(const std::vector<Parameter>& table, const std::vector<Variable>& vars);

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

// Unknown keys of `model` and of its sections are errors naming what is
// allowed (`elsewhere`: keys of `model` another reader checks).
void check_model_keys(const ConfigNode& model, const std::vector<Parameter>& rows,
                      const std::vector<std::string>& elsewhere = {});

// {name: value} of every row, a choice by its name, for result files.
nlohmann::json parameters_json(const std::vector<Parameter>& rows);

}  // namespace opt
