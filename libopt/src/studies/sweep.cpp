#include <cmath>
#include <iostream>
#include <limits>

#include "opt/interrupt.hpp"
#include "opt/record.hpp"
#include "report/report.hpp"
#include "studies/studies.hpp"

namespace opt::studies {
namespace {

using report::fmt;
using report::print_row;

// Relative differences from the paper where it printed the same column.
void print_reference_differences(std::ostream& out, const RunSpec& s, const std::vector<std::string>& head,
                                 const std::vector<std::vector<double>>& printed) {
  const auto& ref = s.reference.columns;
  if (s.grid.size() != 1 || !ref.count(s.grid[0].variable)) return;
  const auto& values = s.grid[0].values;
  out << "relative difference from " << s.reference.source << " [%] (ours - paper) / paper:\n";
  const std::vector<std::string> ref_head(head.begin(), head.end() - 1);
  print_row(out, ref_head, ref_head);
  const auto& rx = ref.at(s.grid[0].variable);
  for (size_t r = 0; r < rx.size(); ++r) {
    size_t i = 0;
    while (i < printed[0].size() && std::abs(values[i] - rx[r]) > 1e-9) ++i;
    if (i == printed[0].size()) continue;
    std::vector<std::string> row{fmt(rx[r])};
    for (size_t c = 0; c < s.columns.size(); ++c) {
      const auto it = ref.find(s.columns[c]);
      row.push_back(it == ref.end() || r >= it->second.size()
                        ? "-"
                        : fmt(100 * (printed[c][i] - it->second[r]) / it->second[r], 3));
    }
    print_row(out, row, ref_head);
  }
}

}  // namespace

SweepOutcome sweep(const Problem& p, const RunSpec& s, std::ostream& out, const std::string& dir) {
  SweepOutcome o;
  // Cartesian product of the axes, first axis slowest.
  const size_t n0 = s.grid[0].values.size(), n1 = s.grid.size() > 1 ? s.grid[1].values.size() : 1;
  o.total = static_cast<long>(n0 * n1);
  const std::vector<std::string>& names = p.metric_names();
  std::vector<MetricId> printed_ids;
  for (const auto& c : s.columns) printed_ids.push_back(p.metric_id(c));
  RecordLayout layout{"point", {}, names};
  for (const auto& v : p.variables()) layout.variables.push_back(v.name);
  CsvRecorder csv(dir + "sweep.csv", layout);
  std::vector<std::string> head;
  for (const auto& a : s.grid) head.push_back(a.variable);
  for (const auto& c : s.columns) head.push_back(c);
  head.push_back("          status");  // wide enough for "synthesis_failed"
  out << "sweep over " << o.total << " points (values in SI):\n";
  print_row(out, head, head);
  std::vector<std::vector<double>> printed(s.columns.size());
  std::vector<double> values(names.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  int infeasible = 0;
  for (long point = 0; point < o.total && !stop_requested(); ++point) {
    // x in the variables' order, whatever order the grid keys were written in.
    const size_t i = point / n1, k = point % n1;
    Eigen::VectorXd x(s.grid.size());
    x[s.grid[0].index] = s.grid[0].values[i];
    if (s.grid.size() > 1) x[s.grid[1].index] = s.grid[1].values[k];
    const Evaluation e = p.evaluate(x, MetricSet::all(), false);
    infeasible += !e.ok();
    for (size_t m = 0; m < names.size(); ++m) values[m] = e.has(static_cast<MetricId>(m)) ? e[static_cast<MetricId>(m)].value : nan;
    csv.record({point, x, mech::to_string(e.status), values});
    std::vector<std::string> row;
    for (const auto& a : s.grid) row.push_back(fmt(x[a.index]));
    for (size_t c = 0; c < s.columns.size(); ++c) {
      const double v = e.has(printed_ids[c]) ? e[printed_ids[c]].value : nan;
      printed[c].push_back(v);
      row.push_back(fmt(v));
    }
    row.push_back(std::string(mech::to_string(e.status)));
    print_row(out, row, head);
    o.x.push_back(x);
    o.e.push_back(e);
  }
  const bool complete = static_cast<long>(o.x.size()) == o.total;
  csv.close(complete);
  if (complete) print_reference_differences(out, s, head, printed);
  o.json = {{"points", o.total}, {"evaluated", o.x.size()}, {"infeasible", infeasible},
            {"csv", dir + "sweep.csv"}};
  return o;
}

}  // namespace opt::studies
