#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>

#include "core/text.hpp"
#include "opt/chart.hpp"
#include "opt/display_units.hpp"
#include "opt/interrupt.hpp"
#include "opt/record.hpp"
#include "report/report.hpp"
#include "studies/front.hpp"
#include "studies/studies.hpp"

namespace opt::studies {

using text::fmt;

Objectives objectives_at(const Problem& p, const Eigen::VectorXd& x, const std::string& f1, const std::string& f2) {
  const Evaluation e = p.evaluate(x, {f1, f2}, false);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return e.ok() ? Objectives{e.at(f1), e.at(f2)} : Objectives{nan, nan};
}

FrontEnds front_ends(const Problem& p, const RunSpec& s, const DriverOptions& driver) {
  const auto d = make_driver(driver);
  const std::string f1 = s.objectives[0], f2 = s.objectives[1];
  FrontEnds ends{d->minimize(p, {f1}, s.constraints, p.initial_point()),
                 d->minimize(p, {f2}, s.constraints, p.initial_point()), {}, {}};
  if (!ends.a.success() || !ends.b.success())
    throw std::runtime_error("pareto: a single-objective optimum failed (" + to_string(ends.a.status) + ", " +
                             to_string(ends.b.status) + ": " + ends.a.message + " / " + ends.b.message + ")");
  // Lexicographic: where one objective's optimum is not unique (the mean
  // kinetic energy of two carts does not depend on their phase), the other
  // objective is minimised with the first held at its optimum, so that the
  // end is not dominated and the nadir is the front's.
  auto second = [&](Result& r, const std::string& held, const std::string& other) {
    std::vector<Constraint> cons = s.constraints;
    cons.push_back({held, true, objectives_at(p, r.x, held, held)[0]});
    Result better = d->minimize(p, {other}, cons, r.x);
    if (better.success() && objectives_at(p, better.x, other, other)[0] <= objectives_at(p, r.x, other, other)[0])
      better.evaluations += r.evaluations, r = better;
  };
  second(ends.a, f1, f2);
  second(ends.b, f2, f1);
  ends.fa = objectives_at(p, ends.a.x, f1, f2);
  ends.fb = objectives_at(p, ends.b.x, f1, f2);
  if (!(ends.fb[0] > ends.fa[0]) || !(ends.fa[1] > ends.fb[1]))
    throw std::runtime_error("pareto: " + f1 + " and " + f2 + " do not trade: the least " + f1 + " (" +
                             fmt(ends.fa[0]) + ", " + fmt(ends.fa[1]) + ") and the least " + f2 + " (" +
                             fmt(ends.fb[0]) + ", " + fmt(ends.fb[1]) + ") leave no front between them");
  return ends;
}

FrontTable::FrontTable(const Problem& p, std::ostream& out, const std::vector<std::string>& lead,
                       const std::vector<std::string>& lead_units)
    : out_(out) {
  for (size_t c = 0; c < lead.size(); ++c) {
    head_.push_back(shown_label(lead[c], lead_units[c]));
    scale_.push_back(shown_unit(lead_units[c]).scale);
  }
  for (const auto& v : p.variables()) {
    head_.push_back(shown_label(v.name, si_unit(v.dimension)));
    scale_.push_back(shown_unit(si_unit(v.dimension)).scale);
  }
  head_.push_back("          status");
  report::print_row(out_, head_, head_);
}

void FrontTable::row(const std::vector<double>& lead, const Eigen::VectorXd& x, const std::string& status) const {
  std::vector<std::string> cells;
  for (double v : lead) cells.push_back(fmt(v * scale_[cells.size()], 8));
  for (int d = 0; d < x.size(); ++d) cells.push_back(fmt(x[d] * scale_[cells.size()], 8));
  cells.push_back(status);
  report::print_row(out_, cells, head_);
}

nlohmann::json front_json(const Problem& p, const RunSpec& s, const FrontEnds& ends,
                          const std::vector<Objectives>& front) {
  const std::string f1 = s.objectives[0], f2 = s.objectives[1];
  const Objectives m = objectives_at(p, p.initial_point(false), f1, f2);
  const Normalisation n = ends.normalisation();
  return {{"objectives", {f1, f2}},
          {"optimum_" + f1, {{"x", report::variables_json(p, ends.a.x)}, {f1, ends.fa[0]}, {f2, ends.fa[1]}}},
          {"optimum_" + f2, {{"x", report::variables_json(p, ends.b.x)}, {f1, ends.fb[0]}, {f2, ends.fb[1]}}},
          {"model_design", {{f1, m[0]}, {f2, m[1]}}},
          {"normalisation", {{"ideal", n.ideal}, {"nadir", n.nadir}, {"reference", kHypervolumeReference}}},
          {"hypervolume", normalised_hypervolume(front, n)}};
}

void write_front_chart(const Problem& p, const RunSpec& s, const FrontEnds& ends, const std::vector<Objectives>& front,
                       bool line, const std::string& dir, std::vector<std::string>& files) {
  const std::string f1 = s.objectives[0], f2 = s.objectives[1];
  Chart c;
  c.title = p.name() + ": Pareto front, " + f1 + " against " + f2;
  c.set_x(f2, p.metric_unit(f2));
  c.set_y(f1, p.metric_unit(f1));
  Series shown{"Pareto front", {}, {}, line ? Series::Style::line : Series::Style::markers};
  for (const auto& f : front) shown.x.push_back(f[1]), shown.y.push_back(f[0]);
  c.series.push_back(shown);
  c.series.push_back({"least " + f1, {ends.fa[1]}, {ends.fa[0]}, Series::Style::star});
  c.series.push_back({"least " + f2, {ends.fb[1]}, {ends.fb[0]}, Series::Style::star});
  const Objectives m = objectives_at(p, p.initial_point(false), f1, f2);
  if (std::isfinite(m[0])) c.series.push_back({"config design", {m[1]}, {m[0]}, Series::Style::markers});
  if (write_svg(c, dir + "pareto.svg")) files.push_back(dir + "pareto.svg");
}

// Epsilon-constraint Pareto front of two minimised metrics f1, f2: the two
// single-objective optima bound f2's range; at each of `points` levels eps,
// f1 is minimised subject to f2 <= eps (and the config's constraints), each
// run warm-started from the previous answer. Writes pareto.csv and
// pareto.svg (the front, both single-objective optima, the model design).
// A pagmo driver draws an evolutionary front instead (pareto_evolution.cpp).
nlohmann::json pareto(const Problem& p, const RunSpec& s, std::ostream& out, const std::string& dir,
                      std::vector<std::string>& files) {
  if (s.driver.library == "pagmo") return pareto_evolution(p, s, out, dir, files);
  const auto started = std::chrono::steady_clock::now();
  const auto driver = make_driver(s.driver);
  const std::string f1 = s.objectives[0], f2 = s.objectives[1];
  const FrontEnds ends = front_ends(p, s, s.driver);
  RecordLayout layout{"point", {}, {"epsilon", f1, f2, "evaluations"}};
  for (const auto& v : p.variables()) layout.variables.push_back(v.name);
  CsvRecorder csv(dir + "pareto.csv", layout);
  const double lo = ends.fb[1], hi = ends.fa[1];
  out << "pareto front: minimise " << f1 << " subject to " << f2 << " <= epsilon, " << s.points << " points from "
      << shown_value(lo, p.metric_unit(f2)) << " to " << shown_value(hi, p.metric_unit(f2)) << "\n";
  const FrontTable table(p, out, {"epsilon", f1, f2}, {p.metric_unit(f2), p.metric_unit(f1), p.metric_unit(f2)});
  std::vector<Objectives> front;
  nlohmann::json rows = nlohmann::json::array();
  Eigen::VectorXd x = ends.b.x;  // from the f2 end, where the bound is tightest
  int evaluations = ends.a.evaluations + ends.b.evaluations;
  int k = 0;
  for (; k < s.points && !stop_requested(); ++k) {
    const double eps = lo + (hi - lo) * k / (s.points - 1);
    std::vector<Constraint> cons = s.constraints;
    cons.push_back({f2, true, eps});
    const Result r = driver->minimize(p, {f1}, cons, x);
    evaluations += r.evaluations;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const Objectives v = r.success() ? objectives_at(p, r.x, f1, f2) : Objectives{nan, nan};
    if (r.success()) x = r.x, front.push_back(v);
    const double cells[] = {eps, v[0], v[1], static_cast<double>(r.evaluations)};
    csv.record({k, r.x, to_string(r.status), cells});
    table.row({eps, v[0], v[1]}, r.x, to_string(r.status));
    rows.push_back({{"epsilon", eps}, {"status", to_string(r.status)}, {f1, v[0]}, {f2, v[1]},
                    {"variables", report::variables_json(p, r.x)}});
  }
  csv.close(k == s.points);
  nlohmann::json j = front_json(p, s, ends, front);
  j.update({{"points", rows},
            {"evaluations", evaluations},
            {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count()},
            {"driver", {{"library", ends.a.library}, {"algorithm", ends.a.algorithm}}},
            {"points_done", k},
            {"csv", dir + "pareto.csv"}});
  out << "hypervolume " << fmt(j["hypervolume"].get<double>(), 6) << " (objectives scaled to the two optima, "
      << "reference point (1.1, 1.1))\n";
  write_front_chart(p, s, ends, front, true, dir, files);
  return j;
}

}  // namespace opt::studies
