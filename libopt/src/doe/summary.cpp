// Summaries of a store (docs/doe.md, "Summaries"): failures by status, the
// best feasible sample per objective, main effects of each factor on each
// summarised metric, and Sobol' indices for a saltelli design; assembled as
// JSON from the store's reads and the statistics, printed, and charted.
#include <algorithm>
#include <cstdio>
#include <optional>
#include <ostream>
#include <variant>

#include "core/text.hpp"
#include "doe/evaluator.hpp"
#include "doe/summary_reads.hpp"
#include "opt/chart.hpp"
#include "opt/display_units.hpp"
#include "opt/doe/batch.hpp"
#include "report/report.hpp"

namespace opt::doe {
namespace {

// `text` right-aligned in `width` columns (left-aligned when `left`).
std::string pad(const std::string& text, size_t width, bool left = false) {
  const std::string fill(width > text.size() ? width - text.size() : 0, ' ');
  return left ? text + fill : fill + text;
}

// The SI unit of a factor's values; none for an option's name.
std::string unit_of(const FactorSpec& f) { return f.factor.labels.empty() ? si_unit(f.parameter.dimension) : ""; }

// The store's columns of `metrics`, in order.
std::vector<std::string> metric_columns(const DoeSpec& spec, const std::vector<std::string>& metrics) {
  std::vector<std::string> columns;
  for (const auto& m : metrics) columns.push_back(metric_column(spec, m));
  return columns;
}

// The names of the factors, in order.
std::vector<std::string> factor_names(const DoeSpec& spec) {
  std::vector<std::string> names;
  for (const auto& fs : spec.factors) names.push_back(fs.factor.name);
  return names;
}

// "failures": by status, with one message each; "feasible": how many samples are.
void add_counts(nlohmann::json& j, const sql::Db& db, const std::string& where) {
  j["failures"] = nlohmann::json::object();
  for (const Failures& f : failures_by_status(db))
    j["failures"][f.status] = {{"count", f.count}, {"example", f.example}};
  j["feasible"] = count_samples(db, where);
}

// "best": the best feasible sample per objective (or, without one, per metric summarised, minimised).
void add_best(nlohmann::json& j, const sql::Db& db, const DoeSpec& spec, const std::vector<std::string>& metrics,
              const std::string& where) {
  std::vector<std::pair<std::string, bool>> goals;  // metric, maximise
  if (!spec.objective.metric.empty()) goals.push_back({spec.objective.metric, spec.objective.maximize});
  else
    for (const auto& m : metrics) goals.push_back({m, false});
  for (const auto& [m, maximize] : goals) {
    const std::optional<BestSample> best = best_sample(db, spec, m, maximize, where);
    if (!best) continue;
    nlohmann::json b = {{"metric", m}, {"maximize", maximize}, {"index", best->index}};
    for (size_t f = 0; f < spec.factors.size(); ++f)
      b["factors"][spec.factors[f].factor.name] =
          std::visit([](const auto& v) { return nlohmann::json(v); }, best->factors[f]);
    b["value"] = best->value;
    j["best"].push_back(b);
  }
}

// "main_effects": per factor and metric the metric's mean per level (or
// bin), with the groups' positions and counts and the means' range. Over
// every evaluated design, constraints met or not: a constraint met in part
// of a factor's range only would cut that factor's curve there.
void add_main_effects(nlohmann::json& j, const sql::Db& db, const DoeSpec& spec,
                      const std::vector<std::string>& metrics) {
  const std::vector<std::string> columns = metric_columns(spec, metrics);
  const std::vector<Effect> effects =
      main_effects(spec.factors, effect_groups(db, spec.factors, columns, "status = 'ok'"), columns.size());
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
}

// "sobol": per metric and factor the Sobol' indices of a saltelli design, with their 95% intervals.
void add_sobol(nlohmann::json& j, const sql::Db& db, const DoeSpec& spec, const std::vector<std::string>& metrics,
               const std::string& where) {
  const std::vector<std::string> columns = metric_columns(spec, metrics);
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

// Prints the feasible count, the failures and the best samples, in the units the charts show.
void print_counts(std::ostream& out, const nlohmann::json& j, const DoeSpec& spec, const Problem& problem) {
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
}

// Prints the main effects' ranges: a row per factor, a column per metric, in the units the charts show.
void print_main_effects(std::ostream& out, const nlohmann::json& j, const DoeSpec& spec,
                        const std::vector<std::string>& metrics, const Problem& problem) {
  if (metrics.empty()) return;
  const std::vector<std::string> names = factor_names(spec);
  const size_t factor_width = report::longest(names, 6);
  out << "main effects (max - min of the metric's mean over a factor's levels or 10 bins):\n  "
      << pad("factor", factor_width, true);
  std::vector<std::string> head;
  for (const auto& m : metrics) head.push_back(shown_label(m, problem.metric_unit(m)));
  for (const auto& h : head) out << "  " << pad(h, std::max<size_t>(12, h.size()));
  out << "\n";
  for (const auto& f : names) {
    out << "  " << pad(f, factor_width, true);
    for (size_t m = 0; m < metrics.size(); ++m) {
      const double range = j["main_effects"][f][metrics[m]]["range"].get<double>();
      out << "  " << pad(text::fmt(range * shown_unit(problem.metric_unit(metrics[m])).scale),
                         std::max<size_t>(12, head[m].size()));
    }
    out << "\n";
  }
}

// Prints the Sobol' indices, if any: a row per metric and factor.
void print_sobol(std::ostream& out, const nlohmann::json& j, const DoeSpec& spec,
                 const std::vector<std::string>& metrics) {
  if (!j.contains("sobol")) return;
  const size_t factor_width = report::longest(factor_names(spec), 6);
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

// Writes main_effects_METRIC.svg per metric: its mean against each factor's position in its range.
void chart_main_effects(const nlohmann::json& j, const DoeSpec& spec, const std::vector<std::string>& metrics,
                        const Problem& problem, const std::string& dir, std::vector<std::string>& charts) {
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
}

// Writes status_map.svg: where designs fail, and how, over the first two factors.
void chart_status_map(const std::string& store_file, const DoeSpec& spec, const std::string& dir,
                      std::vector<std::string>& charts) {
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

}  // namespace

nlohmann::json summarize(const std::string& store_file, const DoeSpec& spec, const std::vector<std::string>& metrics,
                         const Problem& problem, const std::string& dir, std::ostream& out,
                         std::vector<std::string>& charts) {
  sql::Db db(store_file, SQLITE_OPEN_READWRITE);
  const std::string where = feasible_where(spec);
  nlohmann::json j;
  add_counts(j, db, where);
  add_best(j, db, spec, metrics, where);
  add_main_effects(j, db, spec, metrics);
  if (spec.sampler == "saltelli") add_sobol(j, db, spec, metrics, where);
  print_counts(out, j, spec, problem);
  print_main_effects(out, j, spec, metrics, problem);
  print_sobol(out, j, spec, metrics);
  chart_main_effects(j, spec, metrics, problem, dir, charts);
  if (spec.factors.size() >= 2) chart_status_map(store_file, spec, dir, charts);
  save_summary(db, j);  // for scripts: one JSON document
  return j;
}

}  // namespace opt::doe
