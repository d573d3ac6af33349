#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>

#include "opt/chart.hpp"
#include "opt/record.hpp"
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
    c.set_x(v.name, si_unit(v.dimension));
    c.set_y(m, p.metric_unit(m));
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
  std::vector<std::string> files;
  if (const std::string svg = xs.empty() ? "" : p.mechanism_svg(xs.back().second, xs.back().first); !svg.empty()) {
    write_file_atomically(dir + "mechanism.svg", svg);
    files.push_back(dir + "mechanism.svg");
  }
  std::vector<std::pair<std::string, CycleCurves>> drawn;
  for (const auto& [label, x] : xs) {
    CycleCurves curves = p.cycle_curves(x, 360);
    if (!curves.plotted().empty() && !curves.columns.empty() && !curves.columns[0].empty())
      drawn.emplace_back(label, std::move(curves));
  }
  if (drawn.empty()) return files;
  const CycleCurves& last = drawn.back().second;
  const std::vector<size_t> cols = last.plotted();
  // Every plotted column at the last design; the primary alone at the others.
  // With several designs, a primary line is labelled by its design alone.
  Chart c;
  for (size_t d = 0; d < drawn.size(); ++d) {
    const CycleCurves& curves = drawn[d].second;
    for (size_t k : cols) {
      if (d + 1 < drawn.size() && k != curves.primary) continue;
      Series line{curves.names[k], curves.columns[0], curves.columns[k], Series::Style::line};
      if (drawn.size() > 1)
        line.label = k == curves.primary ? drawn[d].first : line.label + " (" + drawn[d].first + ")";
      c.series.push_back(std::move(line));
    }
  }
  std::string quantities = last.names[cols[0]];
  for (size_t i = 1; i < cols.size(); ++i) quantities += ", " + last.names[cols[i]];
  if (quantities.size() > 52) quantities = last.names[cols[0]] + " and others";
  c.title = p.name() + ": " +
            (drawn.size() > 1 ? last.names[cols[0]] + " at each design" : "cycle curves at " + drawn.back().first);
  c.set_x(last.names[0], last.units[0]);  // the crank angle in degrees
  if (last.units[0] == "rad" && last.columns[0].back() < 3.5) c.x_tick_step = 30;  // a half turn
  c.set_y(quantities, last.units[cols[0]]);
  if (write_svg(c, dir + "cycle.svg")) files.push_back(dir + "cycle.svg");
  // cycle.csv: every column at the last design, in SI, each header "name [unit]".
  std::ofstream csv(dir + "cycle.csv");
  csv << std::setprecision(17);
  for (size_t k = 0; k < last.names.size(); ++k) csv << (k ? "," : "") << last.names[k] << " [" << last.units[k] << "]";
  csv << "\n";
  for (size_t i = 0; i < last.columns[0].size(); ++i) {
    for (size_t k = 0; k < last.columns.size(); ++k) csv << (k ? "," : "") << last.columns[k][i];
    csv << "\n";
  }
  files.push_back(dir + "cycle.csv");
  return files;
}

}  // namespace opt::report
