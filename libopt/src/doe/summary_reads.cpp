// The SQL of a store's summary: the feasible filter, failures, best samples,
// the scans for main-effect groups, Saltelli rows and the status map, and the
// summary table's write. Groups and map cells fill as a scan goes, so memory
// does not grow with the store; Saltelli rows hold one metric at a time.
#include "doe/summary_reads.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "opt/doe/sampler.hpp"

namespace opt::doe {
namespace {

using sql::identifier;
using sql::Statement;

std::string sql_number(double v) {
  char s[40];
  std::snprintf(s, sizeof s, "%.17g", v);
  return s;
}

// Column `col` of a row as a number: a categorical factor's option index (NaN when unknown).
double factor_value(const Statement& st, int col, const Factor& f) {
  if (f.labels.empty()) return st.real(col);
  const auto at = std::find(f.labels.begin(), f.labels.end(), st.text(col).value_or(""));
  return at == f.labels.end() ? NAN : static_cast<double>(at - f.labels.begin());
}

}  // namespace

std::string feasible_where(const DoeSpec& spec) {
  std::string w = "status = 'ok'";
  for (const auto& c : spec.constraints) {
    const std::string m = identifier(metric_column(spec, c.metric)), b = sql_number(c.bound);
    w += c.equal ? " and abs(" + m + " - " + b + ") <= 1e-6 * max(1, abs(" + b + "))"
                 : " and " + m + (c.upper ? " <= " : " >= ") + b;
  }
  return w;
}

std::vector<Failures> failures_by_status(const sql::Db& db) {
  Statement failures(db, "select status, count(*), min(message) from samples where status != 'ok' group by status "
                         "order by count(*) desc");
  std::vector<Failures> out;
  while (failures.step())
    out.push_back({failures.text(0).value_or(""), failures.int64(1), failures.text(2).value_or("")});
  return out;
}

std::int64_t count_samples(const sql::Db& db, const std::string& where) {
  Statement count(db, "select count(*) from samples where " + where);
  count.step();
  return count.int64(0);
}

std::optional<BestSample> best_sample(const sql::Db& db, const DoeSpec& spec, const std::string& metric,
                                      bool maximize, const std::string& where) {
  std::string factor_columns;
  for (const auto& f : spec.factors) factor_columns += ", " + identifier(f.factor.name);
  const std::string c = identifier(metric_column(spec, metric));
  Statement best(db, "select idx" + factor_columns + ", " + c + " from samples where " + where + " and " + c +
                         " is not null order by " + c +
                         (maximize ? " desc" : " asc") + " limit 1");
  if (!best.step()) return std::nullopt;
  BestSample b{best.int64(0), {}, best.real(static_cast<int>(spec.factors.size()) + 1)};
  for (size_t f = 0; f < spec.factors.size(); ++f) {
    const int col = static_cast<int>(f) + 1;
    if (spec.factors[f].factor.labels.empty()) b.factors.emplace_back(best.real(col));
    else b.factors.emplace_back(*best.text(col));
  }
  return b;
}

std::vector<FactorGroups> effect_groups(const sql::Db& db, const std::vector<FactorSpec>& factors,
                                        const std::vector<std::string>& metrics, const std::string& where) {
  std::string q = "select ";
  for (const auto& f : factors) q += identifier(f.factor.name) + ", ";
  for (const auto& m : metrics) q += identifier(m) + ", ";
  Statement st(db, q.substr(0, q.size() - 2) + " from samples where " + where);
  const std::size_t nf = factors.size();
  std::vector<FactorGroups> groups(nf);
  std::vector<double> v(metrics.size());
  while (st.step()) {
    for (std::size_t m = 0; m < metrics.size(); ++m) v[m] = st.real(static_cast<int>(nf + m));
    for (std::size_t j = 0; j < nf; ++j) {
      const Factor& f = factors[j].factor;
      const int c = static_cast<int>(j);
      if (!f.labels.empty()) add_option(groups[j], st.text(c).value_or(""), v);
      else add_value(groups[j], f, st.real(c), v);
    }
  }
  return groups;
}

std::vector<std::vector<double>> saltelli_rows(const sql::Db& db, const std::string& metric, int d,
                                               const std::string& where) {
  Statement st(db, "select idx, " + identifier(metric) + " from samples where " + where + " and " +
                       identifier(metric) + " is not null order by idx");
  std::vector<std::vector<double>> rows;
  std::vector<double> row(static_cast<size_t>(d + 2));
  std::int64_t current = -1;
  int filled = 0;
  while (st.step()) {
    const SaltelliIndex at = saltelli_index(st.int64(0), d);
    if (at.row != current) current = at.row, filled = 0;
    if (filled != at.block) continue;  // a block missing: the row is incomplete
    row[static_cast<size_t>(at.block)] = st.real(1);
    if (++filled == d + 2) rows.push_back(row);
  }
  return rows;
}

std::vector<MapSeries> status_map(const std::string& store_file, const DoeSpec& spec) {
  const Factor &fx = spec.factors.at(0).factor, &fy = spec.factors.at(1).factor;
  MapCells cells(fx, fy);
  sql::Db db(store_file, SQLITE_OPEN_READONLY);
  Statement st(db, "select idx, status, (" + feasible_where(spec) + "), " + identifier(fx.name) + ", " +
                       identifier(fy.name) + " from samples");
  while (st.step()) {
    const std::string status = st.text(1).value_or("");
    const std::string_view outcome = status != "ok" ? std::string_view(status)
                                     : st.int64(2)  ? "feasible"
                                                    : "constraint not met";
    cells.add(outcome, st.int64(0), factor_value(st, 3, fx), factor_value(st, 4, fy));
  }
  return cells.series();
}

void save_summary(const sql::Db& db, const nlohmann::json& j) {
  db.exec("create table if not exists summary(key TEXT PRIMARY KEY, value TEXT)");
  Statement put(db, "insert or replace into summary(key, value) values ('summary', ?)");
  put.bind(1, j.dump());
  put.step();
}

}  // namespace opt::doe
