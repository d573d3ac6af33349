#include <cmath>
#include <iostream>
#include <limits>

#include "core/text.hpp"
#include "opt/chart.hpp"
#include "opt/display_units.hpp"
#include "opt/interrupt.hpp"
#include "opt/record.hpp"
#include "report/report.hpp"
#include "studies/studies.hpp"

namespace opt::studies {

using text::fmt;
using report::print_row;

// Epsilon-constraint Pareto front of two minimised metrics f1, f2: the two
// single-objective optima bound f2's range; at each of `points` levels eps,
// f1 is minimised subject to f2 <= eps (and the config's constraints), each
// run warm-started from the previous answer. Writes pareto.csv and
// pareto.svg (the front, both single-objective optima, the model design).
nlohmann::json pareto(const Problem& p, const RunSpec& s, std::ostream& out, const std::string& dir,
                      std::vector<std::string>& files) {
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
  RecordLayout layout{"point", {}, {"epsilon", f1, f2, "evaluations"}};
  for (const auto& v : p.variables()) layout.variables.push_back(v.name);
  CsvRecorder csv(dir + "pareto.csv", layout);
  out << "pareto front: minimise " << f1 << " subject to " << f2 << " <= epsilon, " << s.points
      << " points from " << shown_value(b2, p.metric_unit(f2)) << " to " << shown_value(a2, p.metric_unit(f2)) << "\n";
  std::vector<std::string> head{shown_label("epsilon", p.metric_unit(f2)), shown_label(f1, p.metric_unit(f1)),
                                shown_label(f2, p.metric_unit(f2))};
  std::vector<double> scale{shown_unit(p.metric_unit(f2)).scale, shown_unit(p.metric_unit(f1)).scale,
                            shown_unit(p.metric_unit(f2)).scale};  // of each column, to its shown unit
  for (const auto& v : p.variables()) {
    head.push_back(shown_label(v.name, si_unit(v.dimension)));
    scale.push_back(shown_unit(si_unit(v.dimension)).scale);
  }
  head.push_back("          status");
  print_row(out, head, head);
  Series front{"Pareto front", {}, {}, Series::Style::line};
  nlohmann::json rows = nlohmann::json::array();
  Eigen::VectorXd x = b.x;  // from the f2 end, where the bound is tightest
  int evaluations = a.evaluations + b.evaluations;
  int k = 0;
  for (; k < s.points && !stop_requested(); ++k) {
    const double eps = b2 + (a2 - b2) * k / (s.points - 1);
    std::vector<Constraint> cons = s.constraints;
    cons.push_back({f2, true, eps});
    const Result r = driver->minimize(p, {f1}, cons, x);
    evaluations += r.evaluations;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const auto [v1, v2] = r.success() ? both(r.x) : std::pair<double, double>{nan, nan};
    if (r.success()) x = r.x, front.x.push_back(v2), front.y.push_back(v1);
    const double cells[] = {eps, v1, v2, static_cast<double>(r.evaluations)};
    csv.record({k, r.x, to_string(r.status), cells});
    std::vector<std::string> row{fmt(eps * scale[0]), fmt(v1 * scale[1], 8), fmt(v2 * scale[2], 8)};
    for (int d = 0; d < r.x.size(); ++d) row.push_back(fmt(r.x[d] * scale[row.size()], 8));
    row.push_back(to_string(r.status));
    print_row(out, row, head);
    rows.push_back({{"epsilon", eps}, {"status", to_string(r.status)}, {f1, v1}, {f2, v2},
                    {"variables", report::variables_json(p, r.x)}});
  }
  csv.close(k == s.points);
  const auto [m1, m2] = both(p.initial_point(false));
  nlohmann::json j = {{"objectives", {f1, f2}},
                 {"optimum_" + f1, {{"x", report::variables_json(p, a.x)}, {f1, a1}, {f2, a2}}},
                 {"optimum_" + f2, {{"x", report::variables_json(p, b.x)}, {f1, b1}, {f2, b2}}},
                 {"model_design", {{f1, m1}, {f2, m2}}},
                 {"points", rows},
                 {"evaluations", evaluations},
                 {"driver", {{"library", a.library}, {"algorithm", a.algorithm}}},
                 {"points_done", k},
                 {"csv", dir + "pareto.csv"}};
  Chart c;
  c.title = p.name() + ": Pareto front, " + f1 + " against " + f2;
  c.set_x(f2, p.metric_unit(f2));
  c.set_y(f1, p.metric_unit(f1));
  c.series.push_back(front);
  c.series.push_back({"least " + f1, {a2}, {a1}, Series::Style::star});
  c.series.push_back({"least " + f2, {b2}, {b1}, Series::Style::star});
  if (std::isfinite(m1)) c.series.push_back({"config design", {m2}, {m1}, Series::Style::markers});
  if (write_svg(c, dir + "pareto.svg")) files.push_back(dir + "pareto.svg");
  return j;
}


}  // namespace opt::studies
