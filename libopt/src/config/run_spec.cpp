// Reading a run from a config: variables, objective, constraints, study,
// driver, grid, output and reference, each key checked against the problem.
#include "opt/run_spec.hpp"

#include <cmath>
#include <iostream>

#include "core/text.hpp"
#include "opt/drivers/nlopt.hpp"

namespace opt {
namespace {

using text::fmt;
using text::join;

int variable_index(const Problem& p, const std::string& name) {
  const auto& v = p.variables();
  for (size_t i = 0; i < v.size(); ++i)
    if (v[i].name == name) return static_cast<int>(i);
  return -1;
}

const Variable* find_variable(const Problem& p, const std::string& name) {
  const int i = variable_index(p, name);
  return i < 0 ? nullptr : &p.variables()[i];
}

// Points a sweep may have (on an axis always; in all without --force):
// a sweep is a factorial design, with the batch's limit.
constexpr double kMaxGridPoints = kMaxSamples;

std::vector<double> parse_values(const ConfigNode& n, const Variable& v) {
  std::vector<double> out;
  if (n.is_sequence()) {
    for (const auto& item : n.items()) out.push_back(item.quantity(v.dimension, v.domain));
  } else {
    n.allow_only({"from", "to", "step"});
    const double from = n.at("from").quantity(v.dimension, v.domain);
    const double to = n.at("to").quantity(v.dimension, v.domain);
    const double step = n.at("step").quantity(v.dimension);
    if (!(step > 0) || to < from) n.fail("expected from <= to and step > 0");
    // Counted in double: a tiny step must not overflow an integer.
    const double count = std::floor((to - from) / step + 1e-9) + 1;
    if (!(count <= kMaxGridPoints))
      n.fail("the grid would have " + fmt(count, 3) + " points; the limit is " +
             fmt(kMaxGridPoints, 3) + " (a larger step, or fewer values)");
    for (int i = 0; i < static_cast<int>(count); ++i) out.push_back(from + i * step);
  }
  if (out.empty()) n.fail("expected at least one value");
  return out;
}

// The metric named `name` at node n: a metric of p, or one renamed since
// (with a notice on stderr); anything else is an error listing the metrics.
std::string metric(const ConfigNode& n, const Problem& p, const std::string& name) {
  if (p.has_metric(name)) return name;
  const std::string now = p.renamed_metric(name);
  if (now.empty()) n.fail("unknown metric '" + name + "'; expected one of: " + join(p.metric_names()));
  std::cerr << "mechopt: note: " << n.where() << ": metric '" << name << "' is now called '" << now
            << "'; the old name will go\n";
  return now;
}

}  // namespace

DriverOptions parse_driver(const ConfigNode& n) {
  DriverOptions o;
  if (n.has("library")) o.library = n.at("library").choice({"nlopt", "ipopt", "line", "pagmo"});
  if (o.library == "pagmo") {
#ifndef MECHOPT_PAGMO
    n.at("library").fail("this mechopt was built without pagmo: install libpagmo-dev (make deps-test) and build "
                         "again (cmake finds it)");
#endif
    n.allow_only({"library", "algorithm", "population", "generations", "seed", "max_seconds"});
    o.algorithm = n.has("algorithm") ? n.at("algorithm").choice({"nsga2", "moead", "nspso"}) : "nsga2";
    if (n.has("population")) o.population = n.at("population").integer(8, 100000);
    if (n.has("generations")) o.generations = n.at("generations").integer(1, 1000000);
    if (o.algorithm == "nsga2" && o.population % 4 != 0)
      n.at("population").fail("NSGA-II takes a population that is a multiple of 4");
    o.max_seconds = 3600;
  } else if (o.library == "ipopt") {
    n.allow_only({"library", "tol", "max_iterations", "max_seconds", "constraint_tol",
                  "print_level", "epigraph", "hessian", "linear_solver"});
    o.algorithm = "interior-point";
    if (n.has("tol")) o.tol = n.at("tol").number();
    if (n.has("max_iterations")) o.max_iterations = n.at("max_iterations").integer(1, 100000000);
    if (n.has("print_level")) o.print_level = n.at("print_level").integer(0, 12);
    if (n.has("epigraph")) o.epigraph = n.at("epigraph").boolean();
    if (n.has("linear_solver")) o.linear_solver = n.at("linear_solver").choice({"dense", "mumps"});
    if (n.has("hessian")) n.at("hessian").choice({"limited-memory"});  // no model gives exact Hessians yet
    if (!(o.tol > 0)) n.at("tol").fail("expected a tolerance > 0");
  } else if (o.library == "line") {
    n.allow_only({"library", "xtol_rel", "max_evaluations", "max_seconds"});
    o.algorithm = "Brent on the derivative";
  } else {
    n.allow_only({"library", "algorithm", "xtol_rel", "ftol_rel", "max_evaluations",
                  "max_seconds", "constraint_tol", "local_algorithm", "polish", "seed"});
  }
  if (o.library == "nlopt" && n.has("algorithm")) o.algorithm = n.at("algorithm").choice(nlopt_algorithms());
  if (n.has("seed")) o.seed = static_cast<unsigned long>(n.at("seed").integer(0, 2147483647));
  if (n.has("local_algorithm")) {
    if (o.algorithm != "G_MLSL_LDS") n.at("local_algorithm").fail("goes with algorithm: G_MLSL_LDS");
    o.local_algorithm = n.at("local_algorithm").choice(nlopt_algorithms());
    if (algorithm_is_global(o.local_algorithm)) n.at("local_algorithm").fail("expected a local (L*) algorithm");
  }
  if (o.algorithm == "G_MLSL_LDS" && !n.has("max_evaluations") && !n.has("max_seconds"))
    n.fail("G_MLSL_LDS runs until a limit: give max_evaluations or max_seconds");
  if (n.has("polish")) {
    const ConfigNode pn = n.at("polish");
    o.polish = std::make_shared<DriverOptions>(parse_driver(pn));
    if (o.polish->polish) pn.at("polish").fail("one hand-off only: polish cannot have its own polish");
  }
  if (n.has("xtol_rel")) o.xtol_rel = n.at("xtol_rel").number();
  if (n.has("ftol_rel")) o.ftol_rel = n.at("ftol_rel").number();
  if (n.has("max_evaluations")) o.max_evaluations = n.at("max_evaluations").integer(1, 100000000);
  if (n.has("max_seconds")) o.max_seconds = n.at("max_seconds").quantity(Dimension::time);
  if (n.has("constraint_tol")) o.constraint_tol = n.at("constraint_tol").number();
  if (o.xtol_rel < 0 || o.ftol_rel < 0 || !(o.max_seconds > 0) || o.constraint_tol < 0)
    n.fail("tolerances must be >= 0 and max_seconds > 0");
  return o;
}

std::vector<Variable> parse_variables(const ConfigNode& root, const std::vector<Parameter>& parameters) {
  std::vector<Variable> out;
  if (!root.has("variables")) return out;
  const ConfigNode vars = root.at("variables");
  std::vector<std::string> names;
  for (const auto& c : parameters)
    if (c.variable) names.push_back(c.name);
  vars.allow_only(names);
  for (const auto& c : parameters) {
    if (!c.variable || !vars.has(c.name)) continue;
    const ConfigNode n = vars.at(c.name);
    n.allow_only({"min", "max", "initial"});
    Variable v{c.name, c.dimension, n.at("min").quantity(c.dimension, c.domain),
               n.at("max").quantity(c.dimension, c.domain), c.value, c.domain};
    if (!(v.lower < v.upper)) n.fail("expected min < max");
    if (n.has("initial")) v.initial = n.at("initial").quantity(c.dimension, c.domain);
    out.push_back(v);
  }
  return out;
}

RunSpec parse_run(const ConfigNode& root, const Problem& p, bool force) {
  RunSpec s;
  if (root.has("objective")) {
    const ConfigNode o = root.at("objective");
    o.allow_only({"minimize", "maximize"});
    if (o.keys().size() != 1) o.fail("expected exactly one of minimize or maximize");
    s.objective.maximize = o.has("maximize");
    const ConfigNode m = o.at(s.objective.maximize ? "maximize" : "minimize");
    s.objective.metric = metric(m, p, m.text());
  }
  if (root.has("constraints")) {
    const ConfigNode cs = root.at("constraints");
    for (const auto& key : cs.keys()) {
      const ConfigNode c = cs.at(key);
      const std::string name = metric(c, p, key);
      c.allow_only({"max", "min", "equal"});
      const Dimension d = dimension_of(p.metric_unit(name));
      for (const char* side : {"max", "min"})
        if (c.has(side)) s.constraints.push_back({name, side[1] == 'a', c.at(side).quantity(d)});
      if (c.has("equal")) {
        if (c.has("max") || c.has("min")) c.fail("expected equal: VALUE alone, or max/min");
        s.constraints.push_back({name, true, c.at("equal").quantity(d), true});
      }
      if (!c.has("max") && !c.has("min") && !c.has("equal"))
        c.fail("expected max: VALUE, min: VALUE or equal: VALUE");
    }
  }
  if (root.has("study")) {
    const ConfigNode st = root.at("study");
    if (st.has("type") && st.at("type").text() == "doe") {
      s.type = "doe";  // its own keys: opt::doe::parse_doe
    } else {
      st.allow_only({"type", "driver", "grid", "optimize", "columns", "objectives", "points", "anchor_driver"});
      s.type = st.at("type").choice({"optimize", "sweep", "pareto", "evaluate"});
      if (s.type == "pareto") {
        const ConfigNode ob = st.at("objectives");
        for (const auto& item : ob.items()) {
          s.objectives.push_back(metric(item, p, item.text()));
        }
        if (s.objectives.size() != 2 || s.objectives[0] == s.objectives[1])
          ob.fail("expected two different metrics, both minimised: [f1, f2]");
        if (st.has("points")) s.points = st.at("points").integer(3, 1000);
        if (root.has("objective")) root.at("objective").fail("a pareto study takes study.objectives instead");
        s.objective = {s.objectives[0], false};
      } else if (st.has("objectives") || st.has("points")) {
        st.fail("'objectives' and 'points' go with type: pareto");
      }
      if (st.has("driver")) s.driver = parse_driver(st.at("driver"));
      if (s.driver.library == "pagmo") {
        if (s.type != "pareto") st.at("driver").fail("pagmo evolves fronts: it goes with type: pareto");
        if (st.has("points")) st.at("points").fail("a pagmo front has its population's designs, not points");
        if (st.has("anchor_driver")) s.anchor_driver = parse_driver(st.at("anchor_driver"));
        if (s.anchor_driver.library == "pagmo") st.at("anchor_driver").fail("expected a gradient driver");
      } else if (st.has("anchor_driver")) {
        st.at("anchor_driver").fail("goes with driver: {library: pagmo}");
      }
      if (st.has("optimize")) s.optimize = st.at("optimize").boolean();
      if (s.type == "sweep") {
        const ConfigNode g = st.at("grid");
        double points = 1;
        for (const auto& name : g.keys()) {
          const int i = variable_index(p, name);
          if (i < 0) g.fail("grid variable '" + name + "' is not among the config's variables");
          s.grid.push_back({name, i, parse_values(g.at(name), p.variables()[i])});
          points *= static_cast<double>(s.grid.back().values.size());
        }
        if (s.grid.empty() || s.grid.size() > 2) g.fail("expected one or two grid variables");
        if (s.grid.size() != p.variables().size())
          g.fail("a sweep needs a grid for every variable in 'variables'");
        if (points > kMaxGridPoints && !force)
          g.fail("the grid would have " + fmt(points, 3) + " points in all; the limit is " +
                 fmt(kMaxGridPoints, 3) + " (run with --force to go beyond)");
      }
      if (st.has("columns"))
        for (const auto& c : st.at("columns").items()) {
          s.columns.push_back(metric(c, p, c.text()));
        }
    }
  }
  // Nothing to optimise and no study: every metric at the model values.
  if (!root.has("study") && !root.has("objective") && !root.has("variables")) s.type = "evaluate";
  if (s.objective.metric.empty() && (s.type == "optimize" || (s.type == "sweep" && s.optimize)))
    root.fail("missing required key 'objective' (e.g. objective: {minimize: METRIC})");
  if ((s.type == "optimize" || s.type == "pareto") && p.variables().empty())
    root.fail("missing required key 'variables': an optimisation needs at least one");
  if (s.type == "optimize" || s.type == "pareto" || (s.type == "sweep" && s.optimize)) {
    // The driver takes the problem, or the run stops here (exit 2), before any evaluation.
    // A pagmo front checks the driver of its two ends, which take the
    // constraints alone.
    const bool pagmo = s.driver.library == "pagmo";
    std::vector<Constraint> cons = s.constraints;
    if (s.type == "pareto" && !pagmo) cons.push_back({s.objectives[1], true, 0});  // the front's f2 <= epsilon
    const std::string why = driver_incompatibility(pagmo ? s.anchor_driver : s.driver, p, s.objective, cons);
    const char* key = pagmo ? "anchor_driver" : "driver";
    const bool written = root.has("study") && root.at("study").has(key);
    if (!why.empty()) (written ? root.at("study").at(key) : root).fail(why);
  }
  if (s.columns.empty() && s.type != "doe") {
    s.columns.push_back(s.objective.metric);
    for (const auto& c : s.constraints) s.columns.push_back(c.metric);
  }
  if (root.has("output")) {
    const ConfigNode o = root.at("output");
    o.allow_only({"directory", "chart"});
    if (o.has("directory")) s.output_directory = o.at("directory").text();
    if (o.has("chart")) s.chart = o.at("chart").boolean();
  }
  if (root.has("reference")) {
    const ConfigNode r = root.at("reference");
    for (const auto& key : r.keys()) {
      if (key == "source") { s.reference.source = r.at(key).text(); continue; }
      const Variable* v = find_variable(p, key);
      const std::string column = v ? key : metric(r.at(key), p, key);
      const Dimension d = v ? v->dimension : dimension_of(p.metric_unit(column));
      for (const auto& item : r.at(key).items()) s.reference.columns[column].push_back(item.quantity(d));
    }
  }
  return s;
}

}  // namespace opt
