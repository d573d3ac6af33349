#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>

#include "opt/chart.hpp"
#include "report/report.hpp"

namespace opt::report {
namespace {

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
      line.y.push_back(e.ok() && e.has(m) ? e.at(m) : std::numeric_limits<double>::quiet_NaN());
    }
  }
  return lines;
}

}  // namespace

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
        g.y.push_back(grid_e[i].ok() && grid_e[i].has(m) ? grid_e[i].at(m) : nan);
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

}  // namespace opt::report
