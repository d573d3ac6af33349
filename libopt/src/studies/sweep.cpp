#include <cmath>
#include <iostream>
#include <limits>

#include <unistd.h>

#include "core/text.hpp"
#include "opt/doe/batch.hpp"
#include "opt/display_units.hpp"
#include "opt/doe/store.hpp"
#include "opt/interrupt.hpp"
#include "opt/record.hpp"
#include "report/report.hpp"
#include "studies/studies.hpp"

namespace opt::studies {
namespace {

using text::fmt;
using report::print_row;

// The SI unit of a grid variable.
std::string unit_of(const Problem& p, const GridAxis& a) { return si_unit(p.variables()[a.index].dimension); }

// Relative differences from the paper where it printed the same column.
void print_reference_differences(std::ostream& out, const Problem& p, const RunSpec& s,
                                 const std::vector<std::vector<double>>& printed) {
  const auto& ref = s.reference.columns;
  if (s.grid.size() != 1 || !ref.count(s.grid[0].variable)) return;
  const auto& values = s.grid[0].values;
  out << "relative difference from " << s.reference.source << " [%] (ours - paper) / paper:\n";
  std::vector<std::string> ref_head{shown_label(s.grid[0].variable, unit_of(p, s.grid[0]))};
  ref_head.insert(ref_head.end(), s.columns.begin(), s.columns.end());
  print_row(out, ref_head, ref_head);
  const auto& rx = ref.at(s.grid[0].variable);
  for (size_t r = 0; r < rx.size(); ++r) {
    size_t i = 0;
    while (i < printed[0].size() && std::abs(values[i] - rx[r]) > 1e-9) ++i;
    if (i == printed[0].size()) continue;
    std::vector<std::string> row{fmt(rx[r] * shown_unit(unit_of(p, s.grid[0])).scale)};
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
  // A sweep is a factorial design over its grid (first axis slowest), run by
  // the batch runner into DIR/store.sqlite: all cores, and a run stopped
  // midway resumes (docs/doe.md).
  doe::DoeSpec spec;
  spec.sampler = "factorial";
  for (const auto& a : s.grid) {
    doe::FactorSpec f;
    f.factor.name = a.variable;
    f.factor.kind = doe::Factor::Kind::levels;
    f.factor.levels = a.values;
    f.through_x = true;
    spec.factors.push_back(f);
  }
  doe::BatchOptions batch;
  batch.output_directory = dir;
  batch.quiet = true;
  batch.threads = s.threads;
  batch.force = s.force;
  batch.progress = isatty(STDERR_FILENO) ? "bar" : "none";
  const nlohmann::json config = {{"study", "sweep"}};
  try {
    doe::run_samples(p, nullptr, spec, batch, config, out, std::cerr);
  } catch (const doe::StoreMismatch&) {  // another grid or model: a sweep starts afresh
    out << "(the store in " << dir << " holds another sweep: moved aside)\n";
    batch.fresh = true;
    doe::run_samples(p, nullptr, spec, batch, config, out, std::cerr);
  }

  const std::vector<std::string>& names = p.metric_names();
  const auto shared_names = p.shared_metric_names();
  std::vector<MetricId> printed_ids;
  for (const auto& c : s.columns) printed_ids.push_back(p.metric_id(c));
  RecordLayout layout{"point", {}, names};
  for (const auto& v : p.variables()) layout.variables.push_back(v.name);
  CsvRecorder csv(dir + "sweep.csv", layout);
  std::vector<std::string> head;
  std::vector<double> scale;  // of each printed column, to its shown unit
  for (const auto& a : s.grid) head.push_back(shown_label(a.variable, unit_of(p, a)));
  for (const auto& c : s.columns) head.push_back(shown_label(c, p.metric_unit(c)));
  for (const auto& a : s.grid) scale.push_back(shown_unit(unit_of(p, a)).scale);
  for (const auto& c : s.columns) scale.push_back(shown_unit(p.metric_unit(c)).scale);
  head.push_back("          status");  // wide enough for "synthesis_failed"
  o.total = 1;
  for (const auto& a : s.grid) o.total *= static_cast<long>(a.values.size());
  out << "sweep over " << o.total << " points:\n";
  print_row(out, head, head);
  std::vector<std::vector<double>> printed(s.columns.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  int infeasible = 0;
  doe::read_rows(dir + "store.sqlite", [&](const doe::Row& r) {
    // x in the variables' order, whatever order the grid keys were written in.
    Eigen::VectorXd x(s.grid.size());
    for (size_t a = 0; a < s.grid.size(); ++a) x[s.grid[a].index] = r.factors[a];
    Evaluation e;
    e.status = mech::status_from_string(r.status).value_or(Status::evaluation_error);
    e.message = r.message;
    e.names = shared_names;
    for (size_t m = 0; m < names.size(); ++m)
      if (!std::isnan(r.metrics[m])) e.set(static_cast<MetricId>(m), {r.metrics[m], {}});
    infeasible += !e.ok();
    csv.record({r.index, x, r.status, r.metrics});
    std::vector<std::string> row;
    for (const auto& a : s.grid) row.push_back(fmt(x[a.index] * scale[row.size()]));
    for (size_t c = 0; c < s.columns.size(); ++c) {
      const double v = e.has(printed_ids[c]) ? e[printed_ids[c]].value : nan;
      printed[c].push_back(v);
      row.push_back(fmt(v * scale[row.size()]));
    }
    row.push_back(std::string(mech::to_string(e.status)));
    print_row(out, row, head);
    o.x.push_back(x);
    o.e.push_back(std::move(e));
  });
  const bool complete = static_cast<long>(o.x.size()) == o.total;
  csv.close(complete);
  if (complete) print_reference_differences(out, p, s, printed);
  o.json = {{"points", o.total}, {"evaluated", o.x.size()}, {"infeasible", infeasible},
            {"csv", dir + "sweep.csv"}};
  return o;
}

}  // namespace opt::studies
