#include "opt/study.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>

#include "opt/chart.hpp"

namespace opt {
namespace {

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

std::string fmt(double v, int precision = 6) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + v[i];
  return out;
}

// Points a sweep may have in all (the product over its axes).
constexpr double kMaxGridPoints = 100000;

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
             fmt(kMaxGridPoints) + " (a larger step, or fewer values)");
    for (int i = 0; i < static_cast<int>(count); ++i) out.push_back(from + i * step);
  }
  if (out.empty()) n.fail("expected at least one value");
  return out;
}

DriverOptions parse_driver(const ConfigNode& n) {
  DriverOptions o;
  if (n.has("library")) o.library = n.at("library").choice({"nlopt", "ipopt"});
  if (o.library == "ipopt") {
    n.allow_only({"library", "tol", "max_iterations", "max_seconds", "constraint_tol",
                  "print_level", "epigraph", "hessian"});
    o.algorithm = "interior-point";
    if (n.has("tol")) o.tol = n.at("tol").number();
    if (n.has("max_iterations")) o.max_iterations = n.at("max_iterations").integer(1, 100000000);
    if (n.has("print_level")) o.print_level = n.at("print_level").integer(0, 12);
    if (n.has("epigraph")) o.epigraph = n.at("epigraph").boolean();
    if (n.has("hessian")) n.at("hessian").choice({"limited-memory"});  // no model gives exact Hessians yet
    if (!(o.tol > 0)) n.at("tol").fail("expected a tolerance > 0");
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

void check_metric(const ConfigNode& n, const Problem& p, const std::string& metric) {
  if (!p.has_metric(metric))
    n.fail("unknown metric '" + metric + "'; expected one of: " + join(p.metric_names()));
}

nlohmann::json variables_json(const Problem& p, const Eigen::VectorXd& x) {
  nlohmann::json j = nlohmann::json::object();
  const auto& vars = p.variables();
  for (size_t i = 0; i < vars.size(); ++i)
    j[vars[i].name] = {{"value", x[i]}, {"unit", si_unit(vars[i].dimension)},
                       {"min", vars[i].lower}, {"max", vars[i].upper}};
  return j;
}

void print_variables(std::ostream& out, const Problem& p, const Eigen::VectorXd& x) {
  const auto& vars = p.variables();
  for (size_t i = 0; i < vars.size(); ++i)
    out << "  " << std::left << std::setw(26) << vars[i].name << std::right << std::setw(14)
        << fmt(x[i], 10) << " " << std::left << std::setw(6) << si_unit(vars[i].dimension)
        << std::right << " in [" << fmt(vars[i].lower) << ", " << fmt(vars[i].upper) << "]\n";
}

void print_metrics(std::ostream& out, const Problem& p, const nlohmann::json& m) {
  for (const auto& [name, v] : m.items())
    out << "  " << std::left << std::setw(26) << name << std::right << std::setw(14)
        << fmt(v.get<double>(), 10) << " " << p.metric_unit(name) << "\n";
}

struct OptimizeOutcome {
  Result result;
  nlohmann::json json;
};

// Every evaluation the driver made: evaluation, status, variables, objective.
void write_history(const Problem& p, const Result& r, const std::string& file) {
  std::ofstream csv(file);
  csv << "evaluation,status";
  for (const auto& v : p.variables()) csv << "," << v.name;
  csv << ",objective\n" << std::setprecision(17);
  for (const auto& h : r.history) {
    csv << h.evaluation << "," << h.status;
    for (int i = 0; i < h.x.size(); ++i) csv << "," << h.x[i];
    csv << "," << (std::isfinite(h.objective) ? fmt(h.objective, 17) : std::string()) << "\n";
  }
}

OptimizeOutcome optimize(const Problem& p, const RunSpec& s, std::ostream& out) {
  const auto driver = make_driver(s.driver);
  OptimizeOutcome o;
  o.result = driver->minimize(p, s.objective, s.constraints, p.initial_point());
  const Result& r = o.result;
  write_history(p, r, s.output_directory + "/history.csv");
  nlohmann::json cons = nlohmann::json::array();
  for (size_t i = 0; i < s.constraints.size(); ++i) {
    const Constraint& k = s.constraints[i];
    cons.push_back({{"metric", k.metric}, {k.equal ? "equal" : k.upper ? "max" : "min", k.bound},
                    {"value", i < r.constraint_values.size() ? nlohmann::json(r.constraint_values[i])
                                                             : nlohmann::json(nullptr)}});
  }
  o.json = {{"status", to_string(r.status)},
            {"message", r.message},
            {"driver", {{"library", r.library}, {"algorithm", r.algorithm}, {"seed", s.driver.seed},
                        {"xtol_rel", s.driver.xtol_rel}, {"ftol_rel", s.driver.ftol_rel},
                        {"max_evaluations", s.driver.max_evaluations},
                        {"max_seconds", s.driver.max_seconds}}},
            {"variables", variables_json(p, r.x)},
            {"objective", {{"metric", s.objective.metric},
                           {"sense", s.objective.maximize ? "maximize" : "minimize"},
                           {"value", std::isfinite(r.objective) ? nlohmann::json(r.objective)
                                                                : nlohmann::json(nullptr)}}},
            {"constraints", cons},
            {"evaluations", r.evaluations},
            {"infeasible_evaluations", r.infeasible_evaluations},
            {"wall_seconds", r.seconds},
            {"history", s.output_directory + "/history.csv"}};
  const nlohmann::json at = metrics_json(p, r.x);
  o.json["metrics"] = at["metrics"];
  o.json["design_status"] = at["status"];

  out << "optimum (" << r.library << " " << r.algorithm << "): " << to_string(r.status) << " — "
      << r.message << "\n  " << r.evaluations << " evaluations ("
      << r.infeasible_evaluations << " infeasible), " << fmt(r.seconds * 1e6, 4)
      << " us wall time\n";
  print_variables(out, p, r.x);
  out << "  " << (s.objective.maximize ? "maximize " : "minimize ") << s.objective.metric
      << " = " << fmt(r.objective, 12) << " " << p.metric_unit(s.objective.metric) << "\n";
  for (size_t i = 0; i < s.constraints.size() && i < r.constraint_values.size(); ++i)
    out << "  constraint " << s.constraints[i].metric << " = " << fmt(r.constraint_values[i])
        << s.constraints[i].relation() << fmt(s.constraints[i].bound) << "\n";
  out << "metrics at the optimum:\n";
  print_metrics(out, p, o.json["metrics"]);
  return o;
}

// Metrics along the single variable (n + 1 points), one line each.
std::map<std::string, Series> profiles(const Problem& p, const std::vector<std::string>& metrics,
                                       int n) {
  std::map<std::string, Series> lines;
  const Variable& v = p.variables()[0];
  Eigen::VectorXd x = p.initial_point();
  for (int i = 0; i <= n; ++i) {
    x[0] = v.lower + (v.upper - v.lower) * i / n;
    const Evaluation e = p.evaluate(x, metrics, false);
    for (const auto& m : metrics) {
      Series& line = lines[m];
      line.label = "continuous";
      line.x.push_back(x[0]);
      line.y.push_back(e.ok() && e.metrics.count(m) ? e.at(m) : std::numeric_limits<double>::quiet_NaN());
    }
  }
  return lines;
}

// One chart per metric along the single variable: the continuous curve, the
// grid points, the paper's values, the constraint bound and the optimum.
// Returns the files written.
std::vector<std::string> write_charts(const Problem& p, const RunSpec& s,
                                      const std::vector<Eigen::VectorXd>& grid_x,
                                      const std::vector<Evaluation>& grid_e,
                                      const nlohmann::json* optimum, const std::string& dir) {
  std::vector<std::string> metrics = s.columns, files;
  if (!s.objective.metric.empty() &&
      std::find(metrics.begin(), metrics.end(), s.objective.metric) == metrics.end())
    metrics.insert(metrics.begin(), s.objective.metric);
  const auto lines = profiles(p, metrics, 200);
  const Variable& v = p.variables()[0];
  const auto& ref = s.reference.columns;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& m : metrics) {
    Chart c;
    c.title = p.name() + ": " + m + " along " + v.name;
    c.x_label = v.name + " [" + si_unit(v.dimension) + "]";
    c.y_label = m + " [" + p.metric_unit(m) + "]";
    c.series.push_back(lines.at(m));
    if (!grid_x.empty()) {
      Series g{"grid points", {}, {}, Series::Style::markers};
      for (size_t i = 0; i < grid_x.size(); ++i) {
        g.x.push_back(grid_x[i][0]);
        g.y.push_back(grid_e[i].ok() && grid_e[i].metrics.count(m) ? grid_e[i].at(m) : nan);
      }
      c.series.push_back(g);
    }
    if (ref.count(v.name) && ref.count(m))
      c.series.push_back({"paper (" + s.reference.source + ")", ref.at(v.name), ref.at(m),
                          Series::Style::markers});
    for (const auto& k : s.constraints)
      if (k.metric == m)
        c.series.push_back({std::string(k.equal ? "equal " : k.upper ? "max " : "min ") + "(constraint)",
                            {v.lower, v.upper}, {k.bound, k.bound}, Series::Style::line});
    if (optimum && (*optimum)["metrics"].contains(m))
      c.series.push_back({"optimum", {(*optimum)["variables"][v.name]["value"].get<double>()},
                          {(*optimum)["metrics"][m].get<double>()}, Series::Style::star});
    const std::string file = dir + (m == s.objective.metric ? "chart.svg" : "chart_" + m + ".svg");
    if (write_svg(c, file)) files.push_back(file);
  }
  return files;
}

// The problem's headline cycle curve over the crank angle at each design in
// `xs` (labelled), plus cycle.csv with every curve at the last design.
std::vector<std::string> write_cycle_chart(const Problem& p,
                                           const std::vector<std::pair<std::string, Eigen::VectorXd>>& xs,
                                           const std::string& dir) {
  Chart c;
  CycleCurves last;
  for (const auto& [label, x] : xs) {
    const CycleCurves curves = p.cycle_curves(x, 360);
    if (curves.names.size() < 2) continue;
    c.series.push_back({label, curves.columns[0], curves.columns[1], Series::Style::line});
    last = curves;
  }
  if (c.series.empty()) return {};
  c.title = p.name() + ": " + last.names[1] + " over one revolution";
  c.x_label = last.names[0] + (last.names[0] == "time" ? " [s]" : " [rad]");
  c.y_label = last.names[1] + " [SI]";
  std::vector<std::string> files;
  if (write_svg(c, dir + "cycle.svg")) files.push_back(dir + "cycle.svg");
  std::ofstream csv(dir + "cycle.csv");
  csv << std::setprecision(17);
  for (size_t k = 0; k < last.names.size(); ++k) csv << (k ? "," : "") << last.names[k];
  csv << "\n";
  for (size_t i = 0; i < last.columns[0].size(); ++i) {
    for (size_t k = 0; k < last.columns.size(); ++k) csv << (k ? "," : "") << last.columns[k][i];
    csv << "\n";
  }
  files.push_back(dir + "cycle.csv");
  return files;
}

// Right-aligned cells, each as wide as its column's header (at least 12).
void print_row(std::ostream& out, const std::vector<std::string>& cells,
               const std::vector<std::string>& head) {
  for (size_t i = 0; i < cells.size(); ++i)
    out << std::setw(std::max<int>(12, static_cast<int>(head[i].size())) + 1) << cells[i];
  out << "\n";
}

// Epsilon-constraint Pareto front of two minimised metrics f1, f2: the two
// single-objective optima bound f2's range; at each of `points` levels eps,
// f1 is minimised subject to f2 <= eps (and the config's constraints), each
// run warm-started from the previous answer. Writes pareto.csv and
// pareto.svg (the front, both single-objective optima, the model design).
std::vector<std::string> pareto(const Problem& p, const RunSpec& s, std::ostream& out,
                                const std::string& dir, nlohmann::json& j) {
  const auto driver = make_driver(s.driver);
  const std::string f1 = s.objectives[0], f2 = s.objectives[1];
  const Result a = driver->minimize(p, {f1}, s.constraints, p.initial_point());
  const Result b = driver->minimize(p, {f2}, s.constraints, p.initial_point());
  if (!a.success() || !b.success())
    throw std::runtime_error("pareto: a single-objective optimum failed (" + to_string(a.status) +
                             ", " + to_string(b.status) + ": " + a.message + " / " + b.message + ")");
  auto both = [&](const Eigen::VectorXd& x) {
    const Evaluation e = p.evaluate(x, {f1, f2}, false);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return e.ok() ? std::pair<double, double>{e.at(f1), e.at(f2)} : std::pair<double, double>{nan, nan};
  };
  const auto [a1, a2] = both(a.x);
  const auto [b1, b2] = both(b.x);
  std::ofstream csv(dir + "pareto.csv");
  csv << "epsilon,status," << f1 << "," << f2;
  for (const auto& v : p.variables()) csv << "," << v.name;
  csv << ",evaluations\n" << std::setprecision(17);
  out << "pareto front: minimise " << f1 << " subject to " << f2 << " <= epsilon, " << s.points
      << " points from " << fmt(b2) << " to " << fmt(a2) << "\n";
  std::vector<std::string> head{"epsilon", f1, f2};
  for (const auto& v : p.variables()) head.push_back(v.name);
  head.push_back("          status");
  print_row(out, head, head);
  Series front{"Pareto front", {}, {}, Series::Style::line};
  nlohmann::json rows = nlohmann::json::array();
  Eigen::VectorXd x = b.x;  // from the f2 end, where the bound is tightest
  int evaluations = a.evaluations + b.evaluations;
  for (int k = 0; k < s.points; ++k) {
    const double eps = b2 + (a2 - b2) * k / (s.points - 1);
    std::vector<Constraint> cons = s.constraints;
    cons.push_back({f2, true, eps});
    const Result r = driver->minimize(p, {f1}, cons, x);
    evaluations += r.evaluations;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const auto [v1, v2] = r.success() ? both(r.x) : std::pair<double, double>{nan, nan};
    if (r.success()) x = r.x, front.x.push_back(v2), front.y.push_back(v1);
    csv << eps << "," << to_string(r.status) << "," << v1 << "," << v2;
    std::vector<std::string> row{fmt(eps), fmt(v1, 8), fmt(v2, 8)};
    for (int d = 0; d < r.x.size(); ++d) csv << "," << r.x[d], row.push_back(fmt(r.x[d], 8));
    csv << "," << r.evaluations << std::endl;
    row.push_back(to_string(r.status));
    print_row(out, row, head);
    rows.push_back({{"epsilon", eps}, {"status", to_string(r.status)}, {f1, v1}, {f2, v2},
                    {"variables", variables_json(p, r.x)}});
  }
  const auto [m1, m2] = both(p.initial_point(false));
  j["pareto"] = {{"objectives", {f1, f2}},
                 {"optimum_" + f1, {{"x", variables_json(p, a.x)}, {f1, a1}, {f2, a2}}},
                 {"optimum_" + f2, {{"x", variables_json(p, b.x)}, {f1, b1}, {f2, b2}}},
                 {"model_design", {{f1, m1}, {f2, m2}}},
                 {"points", rows},
                 {"evaluations", evaluations},
                 {"driver", {{"library", a.library}, {"algorithm", a.algorithm}}},
                 {"csv", dir + "pareto.csv"}};
  Chart c;
  c.title = p.name() + ": Pareto front, " + f1 + " against " + f2;
  c.x_label = f2 + " [" + p.metric_unit(f2) + "]";
  c.y_label = f1 + " [" + p.metric_unit(f1) + "]";
  c.series.push_back(front);
  c.series.push_back({"least " + f1, {a2}, {a1}, Series::Style::star});
  c.series.push_back({"least " + f2, {b2}, {b1}, Series::Style::star});
  if (std::isfinite(m1)) c.series.push_back({"model design (config values)", {m2}, {m1}, Series::Style::markers});
  if (!write_svg(c, dir + "pareto.svg")) return {};
  return {dir + "pareto.svg"};
}


}  // namespace

std::vector<Variable> parse_variables(const ConfigNode& root,
                                      const std::vector<VariableSpec>& candidates,
                                      const std::map<std::string, double>& model_values) {
  std::vector<Variable> out;
  if (!root.has("variables")) return out;
  const ConfigNode vars = root.at("variables");
  std::vector<std::string> names;
  for (const auto& c : candidates) names.push_back(c.name);
  vars.allow_only(names);
  for (const auto& c : candidates) {
    if (!vars.has(c.name)) continue;
    const ConfigNode n = vars.at(c.name);
    n.allow_only({"min", "max", "initial"});
    Variable v{c.name, c.dimension, n.at("min").quantity(c.dimension, c.domain),
               n.at("max").quantity(c.dimension, c.domain), model_values.at(c.name), c.domain};
    if (!(v.lower < v.upper)) n.fail("expected min < max");
    if (n.has("initial")) v.initial = n.at("initial").quantity(c.dimension, c.domain);
    out.push_back(v);
  }
  return out;
}

RunSpec parse_run(const ConfigNode& root, const Problem& p) {
  RunSpec s;
  if (root.has("objective")) {
    const ConfigNode o = root.at("objective");
    o.allow_only({"minimize", "maximize"});
    if (o.keys().size() != 1) o.fail("expected exactly one of minimize or maximize");
    s.objective.maximize = o.has("maximize");
    const ConfigNode m = o.at(s.objective.maximize ? "maximize" : "minimize");
    s.objective.metric = m.text();
    check_metric(m, p, s.objective.metric);
  }
  if (root.has("constraints")) {
    const ConfigNode cs = root.at("constraints");
    for (const auto& name : cs.keys()) {
      const ConfigNode c = cs.at(name);
      check_metric(c, p, name);
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
    st.allow_only({"type", "driver", "grid", "optimize", "columns", "objectives", "points"});
    s.type = st.at("type").choice({"optimize", "sweep", "pareto"});
    if (s.type == "pareto") {
      const ConfigNode ob = st.at("objectives");
      for (const auto& item : ob.items()) {
        check_metric(item, p, item.text());
        s.objectives.push_back(item.text());
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
      if (points > kMaxGridPoints)
        g.fail("the grid would have " + fmt(points, 3) + " points in all; the limit is " +
               fmt(kMaxGridPoints));
    }
    if (st.has("columns"))
      for (const auto& c : st.at("columns").items()) {
        check_metric(c, p, c.text());
        s.columns.push_back(c.text());
      }
  }
  if (s.objective.metric.empty() && (s.type == "optimize" || s.optimize))
    root.fail("missing required key 'objective' (e.g. objective: {minimize: METRIC})");
  if ((s.type == "optimize" || s.type == "pareto") && p.variables().empty())
    root.fail("missing required key 'variables': an optimisation needs at least one");
  if (s.columns.empty()) {
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
      if (!v) check_metric(r.at(key), p, key);
      const Dimension d = v ? v->dimension : dimension_of(p.metric_unit(key));
      for (const auto& item : r.at(key).items()) s.reference.columns[key].push_back(item.quantity(d));
    }
  }
  return s;
}

nlohmann::json metrics_json(const Problem& p, const Eigen::VectorXd& x) {
  const Evaluation e = p.evaluate(x, {}, false);
  nlohmann::json m = nlohmann::json::object();
  for (const auto& [name, v] : e.metrics) m[name] = v.value;
  return {{"status", e.status}, {"metrics", m}};
}

nlohmann::json run_study(const Problem& p, const RunSpec& s, std::ostream& out) {
  namespace fs = std::filesystem;
  fs::create_directories(s.output_directory);
  const std::string dir = s.output_directory + "/";
  nlohmann::json j = {{"mechopt_version", MECHOPT_VERSION},
                      {"problem", p.name()},
                      {"study", s.type},
                      {"settings", p.settings()}};
  out << "mechopt " << MECHOPT_VERSION << " — " << p.name() << ", " << s.type << "\n";

  std::vector<Eigen::VectorXd> grid_x;
  std::vector<Evaluation> grid_e;
  if (s.type == "sweep") {
    // Cartesian product of the axes, first axis slowest.
    const size_t n0 = s.grid[0].values.size(), n1 = s.grid.size() > 1 ? s.grid[1].values.size() : 1;
    std::ofstream csv(dir + "sweep.csv");
    std::vector<std::string> names = p.metric_names();
    for (const auto& a : s.grid) csv << a.variable << ",";
    csv << "status";
    for (const auto& m : names) csv << "," << m;
    csv << "\n" << std::setprecision(17);
    std::vector<std::string> head;
    for (const auto& a : s.grid) head.push_back(a.variable);
    for (const auto& c : s.columns) head.push_back(c);
    head.push_back("          status");  // wide enough for "synthesis_failed"
    out << "sweep over " << n0 * n1 << " points (values in SI):\n";
    print_row(out, head, head);
    std::vector<std::vector<double>> printed(s.columns.size());
    int infeasible = 0;
    for (size_t i = 0; i < n0; ++i)
      for (size_t k = 0; k < n1; ++k) {
        // x in the variables' order, whatever order the grid keys were written in.
        Eigen::VectorXd x(s.grid.size());
        x[s.grid[0].index] = s.grid[0].values[i];
        if (s.grid.size() > 1) x[s.grid[1].index] = s.grid[1].values[k];
        const Evaluation e = p.evaluate(x, {}, false);
        infeasible += !e.ok();
        std::vector<std::string> row;
        for (const auto& a : s.grid) csv << x[a.index] << ",", row.push_back(fmt(x[a.index]));
        csv << e.status;
        for (const auto& m : names)
          csv << "," << (e.metrics.count(m) ? fmt(e.at(m), 17) : std::string());
        csv << std::endl;  // flushed row by row: an interrupted sweep keeps its rows
        for (size_t c = 0; c < s.columns.size(); ++c) {
          const double v = e.metrics.count(s.columns[c]) ? e.at(s.columns[c])
                                                         : std::numeric_limits<double>::quiet_NaN();
          printed[c].push_back(v);
          row.push_back(fmt(v));
        }
        row.push_back(e.status);
        print_row(out, row, head);
        grid_x.push_back(x);
        grid_e.push_back(e);
      }
    // Relative differences from the paper where it printed the same column.
    const auto& ref = s.reference.columns;
    if (s.grid.size() == 1 && ref.count(s.grid[0].variable)) {
      out << "relative difference from " << s.reference.source << " [%] (ours - paper) / paper:\n";
      const std::vector<std::string> ref_head(head.begin(), head.end() - 1);
      print_row(out, ref_head, ref_head);
      const auto& rx = ref.at(s.grid[0].variable);
      for (size_t r = 0; r < rx.size(); ++r) {
        size_t i = 0;
        while (i < n0 && std::abs(s.grid[0].values[i] - rx[r]) > 1e-9) ++i;
        if (i == n0) continue;
        std::vector<std::string> row{fmt(rx[r])};
        for (size_t c = 0; c < s.columns.size(); ++c) {
          const auto it = ref.find(s.columns[c]);
          row.push_back(it == ref.end() || r >= it->second.size()
                            ? "-"
                            : fmt(100 * (printed[c][i] - it->second[r]) / it->second[r], 3));
        }
        print_row(out, row, std::vector<std::string>(head.begin(), head.end() - 1));
      }
    }
    j["sweep"] = {{"points", n0 * n1}, {"infeasible", infeasible}, {"csv", dir + "sweep.csv"}};
  }
  if (s.type == "pareto") {
    const auto files = pareto(p, s, out, dir, j);
    j["charts"] = files;
    std::ofstream(dir + "result.json") << j.dump(2) << "\n";
    out << "written: " << dir << "result.json, pareto.csv";
    for (const auto& f : files) out << ", " << f.substr(dir.size());
    out << "\n";
    return j;
  }
  OptimizeOutcome o;
  const bool optimized = s.type == "optimize" || s.optimize;
  if (optimized) {
    o = optimize(p, s, out);
    j.update(o.json);
  }
  std::vector<std::string> files;
  if (s.chart && p.variables().size() == 1 && !s.columns.empty())
    for (const auto& f : write_charts(p, s, grid_x, grid_e, optimized ? &o.json : nullptr, dir))
      files.push_back(f);
  if (s.chart) {
    // Cycle curves at the grid designs (up to 8) and at the optimum.
    std::vector<std::pair<std::string, Eigen::VectorXd>> designs;
    if (grid_x.size() <= 8)
      for (const auto& x : grid_x) {
        std::string label;
        for (int d = 0; d < x.size(); ++d)
          label += (d ? ", " : "") + p.variables()[d].name + " = " + fmt(x[d], 4);
        designs.emplace_back(label, x);
      }
    if (optimized && o.result.success()) designs.emplace_back("optimum", o.result.x);
    if (designs.empty()) designs.emplace_back("model values", p.initial_point());
    for (const auto& f : write_cycle_chart(p, designs, dir)) files.push_back(f);
  }
  j["charts"] = files;
  std::ofstream(dir + "result.json") << j.dump(2) << "\n";
  out << "written: " << dir << "result.json" << (j.contains("sweep") ? ", sweep.csv" : "")
      << (j.contains("history") ? ", history.csv" : "");
  for (const auto& f : files) out << ", " << f.substr(dir.size());
  out << "\n";
  return j;
}

}  // namespace opt
