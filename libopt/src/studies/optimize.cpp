#include <cmath>
#include <iostream>
#include <limits>

#include "core/text.hpp"
#include "opt/display_units.hpp"
#include "opt/record.hpp"
#include "report/report.hpp"
#include "studies/studies.hpp"

namespace opt::studies {
namespace {

using text::fmt;

// Every evaluation the driver made: evaluation, variables, status, objective.
void write_history(const Problem& p, const Result& r, const std::string& file) {
  RecordLayout layout{"evaluation", {}, {"objective"}};
  for (const auto& v : p.variables()) layout.variables.push_back(v.name);
  CsvRecorder csv(file, layout);
  for (const auto& h : r.history) {
    const double objective[] = {h.objective};
    csv.record({h.evaluation, h.x, mech::to_string(h.status), objective});
  }
  csv.close(true);
}

}  // namespace

OptimizeOutcome optimize(const Problem& p, const RunSpec& s, std::ostream& out, const std::string& dir) {
  const auto driver = make_driver(s.driver);
  OptimizeOutcome o;
  o.result = driver->minimize(p, s.objective, s.constraints, p.initial_point());
  const Result& r = o.result;
  write_history(p, r, dir + "history.csv");
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
            {"variables", report::variables_json(p, r.x)},
            {"objective", {{"metric", s.objective.metric},
                           {"sense", s.objective.maximize ? "maximize" : "minimize"},
                           {"value", std::isfinite(r.objective) ? nlohmann::json(r.objective)
                                                                : nlohmann::json(nullptr)}}},
            {"constraints", cons},
            {"evaluations", r.evaluations},
            {"iterations", r.iterations},  // Ipopt's; 0 for NLopt and line, which do not count them
            {"infeasible_evaluations", r.infeasible_evaluations},
            {"wall_seconds", r.seconds},
            {"history", dir + "history.csv"}};
  if (r.library == "ipopt") o.json["driver"]["linear_solver"] = s.driver.linear_solver;
  const nlohmann::json at = metrics_json(p, r.x);
  o.json["metrics"] = at["metrics"];
  o.json["design_status"] = at["status"];

  out << "optimum (" << r.library << " " << r.algorithm << "): " << to_string(r.status) << " — "
      << r.message << "\n  " << r.evaluations << " evaluations ("
      << r.infeasible_evaluations << " infeasible), " << fmt(r.seconds * 1e6, 4)
      << " us wall time\n";
  report::print_variables(out, p, r.x);
  out << "  " << (s.objective.maximize ? "maximize " : "minimize ") << s.objective.metric
      << " = " << shown_value(r.objective, p.metric_unit(s.objective.metric), 12) << "\n";
  for (size_t i = 0; i < s.constraints.size() && i < r.constraint_values.size(); ++i) {
    const std::string unit = p.metric_unit(s.constraints[i].metric);
    out << "  constraint " << s.constraints[i].metric << " = " << shown_value(r.constraint_values[i], unit)
        << s.constraints[i].relation() << shown_value(s.constraints[i].bound, unit) << "\n";
  }
  out << "metrics at the optimum:\n";
  report::print_metrics(out, p, o.json["metrics"]);
  return o;
}

}  // namespace opt::studies
