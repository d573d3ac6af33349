// `refine: {best: K, driver}` (docs/doe.md, "Refine"): after the samples, a
// local optimisation of the objective from each of the K best feasible
// samples, over the factors that are design variables (within their
// ranges; model-value factors stay at the sample's values). Each run is a
// row of the store's `refined` table, committed when it ends, so a rerun
// redoes only the runs it lacks; changed refine settings start the table
// afresh (the samples stay).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>

#include "doe/evaluator.hpp"
#include "doe/sqlite.hpp"
#include "opt/display_units.hpp"
#include "opt/interrupt.hpp"

namespace opt::doe {
namespace {

using sql::identifier;
using sql::Statement;

struct Start {
  std::int64_t index = 0;
  std::vector<double> factors;  // a categorical factor as its option index
  double value = 0;             // the objective
};

// The K best feasible samples, best first (ties by index).
std::vector<Start> best_samples(const sql::Db& db, const DoeSpec& spec) {
  std::string columns;
  for (const auto& f : spec.factors) columns += identifier(f.factor.name) + ", ";
  const std::string m = identifier(metric_column(spec, spec.objective.metric));
  Statement s(db, "SELECT idx, " + columns + m + " FROM samples WHERE " + feasible_where(spec) +
                      " AND " + m + " IS NOT NULL ORDER BY " + m + (spec.objective.maximize ? " DESC" : " ASC") +
                      ", idx LIMIT " + std::to_string(spec.refine_best));
  std::vector<Start> out;
  while (s.step()) {
    Start b{s.int64(0), {}, 0};
    for (std::size_t j = 0; j < spec.factors.size(); ++j) {
      const auto& labels = spec.factors[j].factor.labels;
      const int c = static_cast<int>(j) + 1;
      if (labels.empty()) {
        b.factors.push_back(s.real(c));
      } else {
        const auto at = std::find(labels.begin(), labels.end(), s.text(c).value_or(""));
        b.factors.push_back(static_cast<double>(at - labels.begin()));
      }
    }
    b.value = s.real(static_cast<int>(spec.factors.size()) + 1);
    out.push_back(std::move(b));
  }
  return out;
}

// The `refined` table, emptied when its rows came from other refine settings.
void prepare_table(const sql::Db& db, const DoeSpec& spec, const std::vector<std::string>& metrics) {
  std::string sql = "CREATE TABLE IF NOT EXISTS refined(start INTEGER PRIMARY KEY, rank INTEGER NOT NULL, "
                    "driver_status TEXT NOT NULL, message TEXT, evaluations INTEGER, seconds REAL, "
                    "start_value REAL, value REAL, status TEXT";
  for (const auto& f : spec.factors) sql += ", " + identifier(f.factor.name) + (f.factor.labels.empty() ? " REAL" : " TEXT");
  for (const auto& m : metrics) sql += ", " + identifier(metric_column(spec, m)) + " REAL";
  db.exec(sql + ")");
  const std::string settings = spec.refine_settings.dump();
  Statement old(db, "SELECT value FROM meta WHERE key = 'refine'");
  if (old.step() && old.text(0) == settings) return;
  sql::Transaction t(db);
  db.exec("DELETE FROM refined");
  Statement set(db, "INSERT INTO meta(key, value) VALUES('refine', ?) "
                    "ON CONFLICT(key) DO UPDATE SET value = excluded.value");
  set.bind(1, std::string_view(settings));
  set.step();
  t.commit();
}

bool recorded(const sql::Db& db, std::int64_t start) {
  Statement s(db, "SELECT 1 FROM refined WHERE start = ?");
  s.bind(1, start);
  return s.step();
}

}  // namespace

nlohmann::json refine(const Evaluator& ev, const SampleMaker& maker, const DoeSpec& spec,
                      const std::string& store_file, std::ostream& out) {
  const sql::Db db(store_file, SQLITE_OPEN_READWRITE);
  const std::vector<std::string>& metrics = ev.base().metric_names();
  prepare_table(db, spec, metrics);
  const std::vector<Start> starts = best_samples(db, spec);
  const auto driver = make_driver(spec.refine_driver);
  const std::string& goal = spec.objective.metric;
  out << "refine: " << starts.size() << " local optimisations of " << goal << " from the best feasible samples\n";

  std::string insert = "INSERT INTO refined VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?";
  for (std::size_t c = 0; c < spec.factors.size() + metrics.size(); ++c) insert += ", ?";
  Statement add(db, insert + ")");
  for (std::size_t rank = 0; rank < starts.size() && !stop_requested(); ++rank) {
    const Start& b = starts[rank];
    if (recorded(db, b.index)) continue;
    const Evaluator::Sample s = ev.sample(maker, b.index, b.factors);
    const Result r = driver->minimize(*s.problem, spec.objective, spec.constraints, s.x);
    if (r.status == DriverStatus::interrupted) break;  // not recorded: the rerun redoes it
    const Evaluation e = s.problem->evaluate(r.x, MetricSet::all(), false);
    add.reset();
    int c = 1;
    add.bind(c++, b.index);
    add.bind(c++, static_cast<std::int64_t>(rank + 1));
    add.bind(c++, std::string_view(to_string(r.status)));
    add.bind(c++, std::string_view(r.message), true);
    add.bind(c++, static_cast<std::int64_t>(r.evaluations));
    add.bind(c++, r.seconds);
    add.bind(c++, b.value);
    add.bind(c++, e.has(goal) ? e.at(goal) : std::nan(""));
    add.bind(c++, std::string_view(mech::to_string(e.status)));
    for (std::size_t j = 0; j < spec.factors.size(); ++j) {
      const double v = ev.variable(j) >= 0 ? r.x[ev.variable(j)] : b.factors[j];
      const auto& labels = spec.factors[j].factor.labels;
      if (labels.empty()) add.bind(c++, v);
      else add.bind(c++, std::string_view(labels.at(static_cast<std::size_t>(v))));
    }
    for (std::size_t m = 0; m < metrics.size(); ++m)
      add.bind(c++, e.has(static_cast<MetricId>(m)) ? e[static_cast<MetricId>(m)].value : std::nan(""));
    add.step();  // autocommit: each run is committed when it ends
  }

  // Every run in the table (this run's and earlier ones'), by rank.
  nlohmann::json runs = nlohmann::json::array();
  std::string columns;
  for (const auto& f : spec.factors) columns += ", " + identifier(f.factor.name);
  Statement all(db, "SELECT rank, start, driver_status, evaluations, start_value, value, status" + columns +
                        " FROM refined ORDER BY rank");
  const std::string unit = ev.base().metric_unit(goal);  // the objective's values, shown as the charts show them
  const std::string start_head = shown_label("start", unit), refined_head = shown_label("refined", unit);
  const int width = static_cast<int>(std::max<size_t>(14, refined_head.size() + 1));
  out << "  rank  sample        " << std::setw(width) << start_head << std::setw(width) << refined_head
      << "  driver           evaluations\n";
  while (all.step()) {
    nlohmann::json run = {{"rank", all.int64(0)},         {"start", all.int64(1)},
                          {"driver_status", *all.text(2)}, {"evaluations", all.int64(3)},
                          {"start_value", all.real(4)},    {"value", all.real(5)},
                          {"status", all.text(6).value_or("")}};
    for (std::size_t j = 0; j < spec.factors.size(); ++j) {
      const int col = 7 + static_cast<int>(j);
      run["factors"][spec.factors[j].factor.name] =
          spec.factors[j].factor.labels.empty() ? nlohmann::json(all.real(col)) : nlohmann::json(*all.text(col));
    }
    out << "  " << std::setw(4) << all.int64(0) << "  " << std::setw(12) << all.int64(1) << "  " << std::setw(width)
        << std::setprecision(8) << all.real(4) * shown_unit(unit).scale << std::setw(width)
        << all.real(5) * shown_unit(unit).scale << "  " << std::setw(17) << std::left
        << *all.text(2) << std::right << all.int64(3) << "\n";
    runs.push_back(std::move(run));
  }
  out << std::setprecision(6);
  return {{"best", spec.refine_best}, {"driver", spec.refine_settings["driver"]}, {"runs", runs}};
}

}  // namespace opt::doe
