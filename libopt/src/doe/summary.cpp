// Summaries of a store (docs/doe.md, "Summaries"): failures by status, the
// best feasible sample per objective, main effects of each factor on each
// summarised metric, and Sobol' indices for a saltelli design. SQLite does
// the counting and averaging in one pass per factor, so memory does not grow
// with the store; the Sobol' indices hold one metric's values at a time.
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <ostream>

#include "doe/evaluator.hpp"
#include "doe/sqlite.hpp"
#include "opt/chart.hpp"
#include "opt/display_units.hpp"
#include "opt/doe/batch.hpp"
#include "opt/doe/random.hpp"
#include "report/report.hpp"

namespace opt::doe {
namespace {

using sql::identifier;
using sql::Statement;

constexpr int kBins = 10;          // a continuous factor's main effect: means over 10 equal bins
constexpr int kMaxLevels = 50;     // more levels than this are binned too
constexpr int kBootstrap = 200;    // resamples for the Sobol' indices' 95% intervals

std::string sql_number(double v) {
  char s[40];
  std::snprintf(s, sizeof s, "%.17g", v);
  return s;
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

namespace {

// A REAL as SQLite writes it as text ("0.1", "800.0").
std::string sql_text(double x) {
  char text[40];
  sqlite3_snprintf(sizeof text, text, "%!.15g", x);
  return text;
}

bool binned(const Factor& f) { return f.kind == Factor::Kind::range && (f.count == 0 || f.count > kMaxLevels); }

struct Effect {
  std::vector<std::string> groups;          // level, option or bin [lo, hi)
  std::vector<double> position;             // for charts: the group's place in the factor's range, 0..1
  std::vector<std::int64_t> counts;
  std::vector<std::vector<double>> means;   // [metric][group]
};

// Rows of one group: how many, and per metric the sum and count of its
// non-NULL values (a mean skips NULLs, as SQL's avg does).
struct Group {
  std::int64_t rows = 0;
  std::vector<double> sum;
  std::vector<std::int64_t> values;
};

void add(Group& g, const std::vector<double>& v) {
  if (g.sum.empty()) g.sum.assign(v.size(), 0.0), g.values.assign(v.size(), 0);
  ++g.rows;
  for (std::size_t m = 0; m < v.size(); ++m)
    if (!std::isnan(v[m])) g.sum[m] += v[m], ++g.values[m];
}

// The main effects of every factor: the mean of each metric per level (or
// option, or tenth of a range) over the rows `where` selects, in one scan of the
// store (a GROUP BY per factor was a scan and a sort each: ~35 s on 10^7
// rows). Groups in ascending order of value, or of name for options.
std::vector<Effect> main_effects(const sql::Db& db, const std::vector<FactorSpec>& factors,
                                 const std::vector<std::string>& metrics, const std::string& where) {
  std::string q = "select ";
  for (const auto& f : factors) q += identifier(f.factor.name) + ", ";
  for (const auto& m : metrics) q += identifier(m) + ", ";
  Statement st(db, q.substr(0, q.size() - 2) + " from samples where " + where);
  const std::size_t nf = factors.size();
  std::vector<std::map<double, Group>> by_value(nf);       // levels, or bin index
  std::vector<std::map<std::string, Group>> by_name(nf);   // options
  std::vector<double> v(metrics.size());
  while (st.step()) {
    for (std::size_t m = 0; m < metrics.size(); ++m) v[m] = st.real(static_cast<int>(nf + m));
    for (std::size_t j = 0; j < nf; ++j) {
      const Factor& f = factors[j].factor;
      const int c = static_cast<int>(j);
      if (!f.labels.empty()) {
        add(by_name[j][st.text(c).value_or("")], v);
        continue;
      }
      double x = st.real(c);
      if (std::isnan(x)) continue;
      if (binned(f)) x = std::clamp(std::trunc((x - f.lower) / ((f.upper - f.lower) / kBins)), 0.0, kBins - 1.0);
      add(by_value[j][x], v);
    }
  }
  std::vector<Effect> out(nf);
  for (std::size_t j = 0; j < nf; ++j) {
    const Factor& f = factors[j].factor;
    Effect& e = out[j];
    e.means.resize(metrics.size());
    auto put = [&](const std::string& name, double position, const Group& g) {
      e.groups.push_back(name);
      e.position.push_back(position);
      e.counts.push_back(g.rows);
      for (std::size_t m = 0; m < metrics.size(); ++m)
        e.means[m].push_back(g.values[m] ? g.sum[m] / double(g.values[m]) : NAN);
    };
    const double w = (f.upper - f.lower) / kBins;
    for (const auto& [x, g] : by_value[j])
      put(binned(f) ? "[" + sql_text(f.lower + x * w) + ", " + sql_text(f.lower + (x + 1) * w) + ")"
                    : sql_text(x),
          binned(f) ? (x + 0.5) / kBins : 0, g);
    for (const auto& [name, g] : by_name[j]) put(name, 0, g);
    if (!binned(f))  // levels and options: evenly by rank
      for (size_t g = 0; g < e.groups.size(); ++g)
        e.position[g] = e.groups.size() > 1 ? static_cast<double>(g) / static_cast<double>(e.groups.size() - 1) : 0.5;
  }
  return out;
}

struct Indices {
  double first = NAN, total = NAN, first_low = NAN, first_high = NAN, total_low = NAN, total_high = NAN;
};

// First-order (Saltelli 2010) and total (Jansen 1999) indices from rows of
// f_A, f_B, f_ABj, with percentile bootstrap intervals over the rows.
std::vector<Indices> sobol_indices(const std::vector<std::vector<double>>& rows, int d, std::uint64_t seed) {
  auto estimate = [&](const std::vector<size_t>& pick, int j, double& s1, double& st) {
    double mean = 0, sq = 0, a1 = 0, at = 0;
    for (size_t r : pick) {
      const auto& y = rows[r];
      mean += y[0] + y[1];
      sq += y[0] * y[0] + y[1] * y[1];
      a1 += y[1] * (y[2 + j] - y[0]);
      at += (y[0] - y[2 + j]) * (y[0] - y[2 + j]);
    }
    const double n = static_cast<double>(pick.size());
    const double var = sq / (2 * n) - (mean / (2 * n)) * (mean / (2 * n));
    s1 = a1 / n / var;
    st = at / (2 * n) / var;
  };
  std::vector<size_t> all(rows.size());
  std::iota(all.begin(), all.end(), 0);
  std::vector<Indices> out(static_cast<size_t>(d));
  if (rows.size() < 2) return out;
  for (int j = 0; j < d; ++j) estimate(all, j, out[j].first, out[j].total);
  std::vector<std::vector<double>> s1(static_cast<size_t>(d)), st(static_cast<size_t>(d));
  std::vector<size_t> pick(rows.size());
  for (int b = 0; b < kBootstrap; ++b) {
    for (size_t r = 0; r < rows.size(); ++r)
      pick[r] = static_cast<size_t>(uniform(seed, static_cast<std::uint64_t>(b), static_cast<std::uint32_t>(r)) *
                                    static_cast<double>(rows.size()));
    for (int j = 0; j < d; ++j) {
      double a, t;
      estimate(pick, j, a, t);
      s1[j].push_back(a);
      st[j].push_back(t);
    }
  }
  auto percentile = [](std::vector<double> v, double p) {
    std::sort(v.begin(), v.end());
    return v[static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
  };
  for (int j = 0; j < d; ++j) {
    out[j].first_low = percentile(s1[j], 0.025), out[j].first_high = percentile(s1[j], 0.975);
    out[j].total_low = percentile(st[j], 0.025), out[j].total_high = percentile(st[j], 0.975);
  }
  return out;
}

// Rows of (f_A, f_B, f_AB1..f_ABd) of `metric` for the saltelli rows whose
// d + 2 samples are all feasible.
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

}  // namespace

namespace {

// The span of a factor's values: its range, or its levels' (a categorical
// factor's levels are its options' indices).
std::pair<double, double> extent(const Factor& f) {
  if (f.kind == Factor::Kind::range || f.levels.empty()) return {f.lower, f.upper};
  const auto [lo, hi] = std::minmax_element(f.levels.begin(), f.levels.end());
  return {*lo, *hi};
}

// Column `col` of a row as a number: a categorical factor's option index (NaN when unknown).
double factor_value(const Statement& st, int col, const Factor& f) {
  if (f.labels.empty()) return st.real(col);
  const auto at = std::find(f.labels.begin(), f.labels.end(), st.text(col).value_or(""));
  return at == f.labels.end() ? NAN : static_cast<double>(at - f.labels.begin());
}

// The cell of v among kMapCells equal parts of [lo, hi] (v finite).
int map_cell(double v, std::pair<double, double> span) {
  const auto [lo, hi] = span;
  if (!(hi > lo)) return 0;
  return static_cast<int>(std::clamp(std::floor((v - lo) / (hi - lo) * kMapCells), 0.0, kMapCells - 1.0));
}

}  // namespace

std::vector<MapSeries> status_map(const std::string& store_file, const DoeSpec& spec) {
  const Factor &fx = spec.factors.at(0).factor, &fy = spec.factors.at(1).factor;
  const auto span_x = extent(fx), span_y = extent(fy);
  struct Pick {
    std::uint64_t hash = ~std::uint64_t{0};
    double x = NAN, y = NAN;
  };
  struct Outcome {
    std::int64_t count = 0;
    std::vector<double> x, y;  // every sample's, while there are at most kMaxDrawnPoints
    std::vector<Pick> picks;   // by cell
  };
  constexpr auto kAll = static_cast<std::int64_t>(kMaxDrawnPoints);
  std::map<std::string, Outcome, std::less<>> outcomes;
  sql::Db db(store_file, SQLITE_OPEN_READONLY);
  Statement st(db, "select idx, status, (" + feasible_where(spec) + "), " + identifier(fx.name) + ", " +
                       identifier(fy.name) + " from samples");
  while (st.step()) {
    const std::string status = st.text(1).value_or("");
    const std::string_view outcome = status != "ok" ? std::string_view(status)
                                     : st.int64(2)  ? "feasible"
                                                    : "constraint not met";
    auto at = outcomes.find(outcome);
    if (at == outcomes.end()) at = outcomes.try_emplace(std::string(outcome)).first;
    Outcome& o = at->second;
    const double x = factor_value(st, 3, fx), y = factor_value(st, 4, fy);
    if (++o.count <= kAll) o.x.push_back(x), o.y.push_back(y);
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    if (o.picks.empty()) o.picks.resize(kMapCells * kMapCells);
    Pick& p = o.picks[static_cast<size_t>(map_cell(x, span_x) * kMapCells + map_cell(y, span_y))];
    const std::uint64_t hash = philox_bits(0, static_cast<std::uint64_t>(st.int64(0)), 0, domain::status_map);
    if (hash < p.hash) p = {hash, x, y};
  }
  std::vector<MapSeries> out;
  for (auto& [name, o] : outcomes) {
    MapSeries m{name, o.count, std::move(o.x), std::move(o.y)};
    if (o.count > kAll) {
      m.x.clear(), m.y.clear();
      for (const Pick& p : o.picks)
        if (!std::isnan(p.x)) m.x.push_back(p.x), m.y.push_back(p.y);
    }
    out.push_back(std::move(m));
  }
  return out;
}

namespace {

// `text` right-aligned in `width` columns (left-aligned when `left`).
std::string pad(const std::string& text, size_t width, bool left = false) {
  const std::string fill(width > text.size() ? width - text.size() : 0, ' ');
  return left ? text + fill : fill + text;
}

// The SI unit of a factor's values; none for an option's name.
std::string unit_of(const FactorSpec& f) { return f.factor.labels.empty() ? si_unit(f.parameter.dimension) : ""; }

}  // namespace

nlohmann::json summarize(const std::string& store_file, const DoeSpec& spec, const std::vector<std::string>& metrics,
                         const Problem& problem, const std::string& dir, std::ostream& out,
                         std::vector<std::string>& charts) {
  sql::Db db(store_file, SQLITE_OPEN_READWRITE);
  nlohmann::json j;
  const std::string where = feasible_where(spec);
  std::vector<std::string> columns;  // of the metrics
  for (const auto& m : metrics) columns.push_back(metric_column(spec, m));

  // Failures by status, with one message each.
  Statement failures(db, "select status, count(*), min(message) from samples where status != 'ok' group by status "
                         "order by count(*) desc");
  j["failures"] = nlohmann::json::object();
  while (failures.step()) {
    const std::string s = failures.text(0).value_or("");
    j["failures"][s] = {{"count", failures.int64(1)}, {"example", failures.text(2).value_or("")}};
  }
  Statement feasible_count(db, "select count(*) from samples where " + where);
  feasible_count.step();
  j["feasible"] = feasible_count.int64(0);

  // The best feasible sample per objective (or, without one, per metric summarised, minimised).
  std::vector<std::pair<std::string, bool>> goals;  // metric, maximise
  if (!spec.objective.metric.empty()) goals.push_back({spec.objective.metric, spec.objective.maximize});
  else
    for (const auto& m : metrics) goals.push_back({m, false});
  std::string factor_columns;
  for (const auto& f : spec.factors) factor_columns += ", " + identifier(f.factor.name);
  for (const auto& [m, maximize] : goals) {
    const std::string c = identifier(metric_column(spec, m));
    Statement best(db, "select idx" + factor_columns + ", " + c + " from samples where " + where + " and " + c +
                           " is not null order by " + c +
                           (maximize ? " desc" : " asc") + " limit 1");
    if (!best.step()) continue;
    nlohmann::json b = {{"metric", m}, {"maximize", maximize}, {"index", best.int64(0)}};
    for (size_t f = 0; f < spec.factors.size(); ++f) {
      const int col = static_cast<int>(f) + 1;
      b["factors"][spec.factors[f].factor.name] =
          spec.factors[f].factor.labels.empty() ? nlohmann::json(best.real(col)) : nlohmann::json(*best.text(col));
    }
    b["value"] = best.real(static_cast<int>(spec.factors.size()) + 1);
    j["best"].push_back(b);
  }

  // Main effects: the mean of each metric per level (or bin) of each factor,
  // over every evaluated design, constraints met or not: a constraint met in
  // part of a factor's range only would cut that factor's curve there.
  const std::vector<Effect> effects = main_effects(db, spec.factors, columns, "status = 'ok'");
  for (std::size_t f = 0; f < spec.factors.size(); ++f) {
    const auto& fs = spec.factors[f];
    const Effect& e = effects[f];
    for (size_t m = 0; m < metrics.size(); ++m) {
      const auto [lo, hi] = std::minmax_element(e.means[m].begin(), e.means[m].end());
      j["main_effects"][fs.factor.name][metrics[m]] = {
          {"groups", e.groups}, {"positions", e.position}, {"counts", e.counts}, {"means", e.means[m]},
          {"range", e.means[m].empty() ? 0.0 : *hi - *lo}};
    }
  }

  // Sobol' indices of a saltelli design.
  if (spec.sampler == "saltelli") {
    const int d = static_cast<int>(spec.factors.size());
    for (std::size_t k = 0; k < metrics.size(); ++k) {
      const std::string& m = metrics[k];
      const auto rows = saltelli_rows(db, columns[k], d, where);
      const auto idx = sobol_indices(rows, d, spec.seed.value_or(0));
      for (int f = 0; f < d; ++f)
        j["sobol"][m][spec.factors[static_cast<size_t>(f)].factor.name] = {
            {"first", idx[f].first}, {"first_95", {idx[f].first_low, idx[f].first_high}},
            {"total", idx[f].total}, {"total_95", {idx[f].total_low, idx[f].total_high}},
            {"rows", rows.size()}};
    }
  }

  // Printed, in the units the charts show.
  out << "summary: " << j["feasible"].get<std::int64_t>() << " feasible samples\n";
  for (const auto& [s, v] : j["failures"].items())
  {
    const std::string example = v["example"].get<std::string>();
    out << "  " << s << ": " << v["count"].get<std::int64_t>() << (example.empty() ? "" : " (e.g. " + example + ")")
        << "\n";
  }
  if (j.contains("best"))
    for (const auto& b : j["best"]) {
      const std::string m = b["metric"].get<std::string>();
      out << "  best " << m << " = " << shown_value(b["value"].get<double>(), problem.metric_unit(m), 8)
          << " at sample " << b["index"].get<std::int64_t>() << ":";
      for (size_t f = 0; f < spec.factors.size(); ++f) {
        const auto& v = b["factors"][spec.factors[f].factor.name];
        out << (f ? ", " : " ") << spec.factors[f].factor.name << " = "
            << (v.is_string() ? v.get<std::string>() : shown_value(v.get<double>(), unit_of(spec.factors[f]), 8));
      }
      out << "\n";
    }
  std::vector<std::string> factor_names;
  for (const auto& fs : spec.factors) factor_names.push_back(fs.factor.name);
  const size_t factor_width = report::longest(factor_names, 6);
  if (!metrics.empty()) {
    out << "main effects (max - min of the metric's mean over a factor's levels or 10 bins):\n  "
        << pad("factor", factor_width, true);
    std::vector<std::string> head;
    for (const auto& m : metrics) head.push_back(shown_label(m, problem.metric_unit(m)));
    for (const auto& h : head) out << "  " << pad(h, std::max<size_t>(12, h.size()));
    out << "\n";
    for (const auto& f : factor_names) {
      out << "  " << pad(f, factor_width, true);
      for (size_t m = 0; m < metrics.size(); ++m) {
        const double range = j["main_effects"][f][metrics[m]]["range"].get<double>();
        out << "  " << pad(report::fmt(range * shown_unit(problem.metric_unit(metrics[m])).scale),
                           std::max<size_t>(12, head[m].size()));
      }
      out << "\n";
    }
  }
  if (j.contains("sobol")) {
    out << "Sobol' indices (first order, total; 95% bootstrap intervals):\n";
    for (const auto& [m, fs] : j["sobol"].items())
      for (const auto& [f, v] : fs.items()) {
        char numbers[120];
        std::snprintf(numbers, sizeof numbers, "S1 %7.4f [%7.4f, %7.4f]  ST %7.4f [%7.4f, %7.4f]\n",
                      v["first"].get<double>(), v["first_95"][0].get<double>(), v["first_95"][1].get<double>(),
                      v["total"].get<double>(), v["total_95"][0].get<double>(), v["total_95"][1].get<double>());
        out << "  " << pad(m, report::longest(metrics), true) << "  " << pad(f, factor_width, true) << "  " << numbers;
      }
  }

  // Charts: per metric, its mean against each factor's position in its range.
  for (size_t k = 0; k < metrics.size(); ++k) {
    const std::string& m = metrics[k];
    Chart c;
    c.title = "main effects on " + m;
    c.x_label = "factor position, lowest level or value (0) to highest (1) [-]";
    c.set_y(m, problem.metric_unit(m));
    for (const auto& fs : spec.factors) {
      const auto& me = j["main_effects"][fs.factor.name][m];
      Series s{fs.factor.name, me["positions"].get<std::vector<double>>(), me["means"].get<std::vector<double>>(),
               Series::Style::line};
      c.series.push_back(std::move(s));
    }
    const std::string file = dir + "main_effects_" + m + ".svg";
    if (write_svg(c, file)) charts.push_back(file);
  }

  // The status map: where designs fail, and how, over the first two factors.
  if (spec.factors.size() >= 2) {
    const FactorSpec &fx = spec.factors[0], &fy = spec.factors[1];
    Chart c;
    c.title = "outcomes over " + fx.factor.name + " and " + fy.factor.name + " (an outcome over " +
              std::to_string(kMaxDrawnPoints) + ": one per " + std::to_string(kMapCells) + " x " +
              std::to_string(kMapCells) + " cell)";
    c.set_x(fx.factor.name, unit_of(fx));
    c.set_y(fy.factor.name, unit_of(fy));
    for (auto& m : status_map(store_file, spec))  // labelled with its count in the whole store
      c.series.push_back({m.outcome + " (" + std::to_string(m.count) + ")", std::move(m.x), std::move(m.y),
                          Series::Style::markers});
    if (write_svg(c, dir + "status_map.svg")) charts.push_back(dir + "status_map.svg");
  }

  // Into the store, for scripts: one JSON document.
  db.exec("create table if not exists summary(key TEXT PRIMARY KEY, value TEXT)");
  Statement put(db, "insert or replace into summary(key, value) values ('summary', ?)");
  put.bind(1, j.dump());
  put.step();
  return j;
}

}  // namespace opt::doe
