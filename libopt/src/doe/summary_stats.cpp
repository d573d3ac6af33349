// The statistics of a summary over numbers the store's reads hand them: a
// main effect's groups and means, Sobol' indices with bootstrap intervals,
// and the status map's cells. Memory grows with the groups and cells, not
// with the store.
#include "doe/summary_stats.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <numeric>

#include "opt/chart.hpp"
#include "opt/doe/random.hpp"

namespace opt::doe {
namespace {

constexpr int kBins = 10;          // a continuous factor's main effect: means over 10 equal bins
constexpr int kMaxLevels = 50;     // more levels than this are binned too
constexpr int kBootstrap = 200;    // resamples for the Sobol' indices' 95% intervals

// A REAL as SQLite writes it as text ("0.1", "800.0").
std::string sql_text(double x) {
  char text[40];
  sqlite3_snprintf(sizeof text, text, "%!.15g", x);
  return text;
}

bool binned(const Factor& f) { return f.kind == Factor::Kind::range && (f.count == 0 || f.count > kMaxLevels); }

void add(Group& g, const std::vector<double>& v) {
  if (g.sum.empty()) g.sum.assign(v.size(), 0.0), g.values.assign(v.size(), 0);
  ++g.rows;
  for (std::size_t m = 0; m < v.size(); ++m)
    if (!std::isnan(v[m])) g.sum[m] += v[m], ++g.values[m];
}

// The span of a factor's values: its range, or its levels' (a categorical
// factor's levels are its options' indices).
std::pair<double, double> extent(const Factor& f) {
  if (f.kind == Factor::Kind::range || f.levels.empty()) return {f.lower, f.upper};
  const auto [lo, hi] = std::minmax_element(f.levels.begin(), f.levels.end());
  return {*lo, *hi};
}

// The cell of v among kMapCells equal parts of [lo, hi] (v finite).
int map_cell(double v, std::pair<double, double> span) {
  const auto [lo, hi] = span;
  if (!(hi > lo)) return 0;
  return static_cast<int>(std::clamp(std::floor((v - lo) / (hi - lo) * kMapCells), 0.0, kMapCells - 1.0));
}

constexpr auto kAll = static_cast<std::int64_t>(kMaxDrawnPoints);

}  // namespace

void add_value(FactorGroups& groups, const Factor& f, double x, const std::vector<double>& v) {
  if (std::isnan(x)) return;
  if (binned(f)) x = std::clamp(std::trunc((x - f.lower) / ((f.upper - f.lower) / kBins)), 0.0, kBins - 1.0);
  add(groups.by_value[x], v);
}

void add_option(FactorGroups& groups, const std::string& name, const std::vector<double>& v) {
  add(groups.by_name[name], v);
}

std::vector<Effect> main_effects(const std::vector<FactorSpec>& factors, const std::vector<FactorGroups>& groups,
                                 std::size_t metrics) {
  const std::size_t nf = factors.size();
  std::vector<Effect> out(nf);
  for (std::size_t j = 0; j < nf; ++j) {
    const Factor& f = factors[j].factor;
    Effect& e = out[j];
    e.means.resize(metrics);
    auto put = [&](const std::string& name, double position, const Group& g) {
      e.groups.push_back(name);
      e.position.push_back(position);
      e.counts.push_back(g.rows);
      for (std::size_t m = 0; m < metrics; ++m)
        e.means[m].push_back(g.values[m] ? g.sum[m] / double(g.values[m]) : NAN);
    };
    const double w = (f.upper - f.lower) / kBins;
    for (const auto& [x, g] : groups[j].by_value)
      put(binned(f) ? "[" + sql_text(f.lower + x * w) + ", " + sql_text(f.lower + (x + 1) * w) + ")"
                    : sql_text(x),
          binned(f) ? (x + 0.5) / kBins : 0, g);
    for (const auto& [name, g] : groups[j].by_name) put(name, 0, g);
    if (!binned(f))  // levels and options: evenly by rank
      for (size_t g = 0; g < e.groups.size(); ++g)
        e.position[g] = e.groups.size() > 1 ? static_cast<double>(g) / static_cast<double>(e.groups.size() - 1) : 0.5;
  }
  return out;
}

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

MapCells::MapCells(const Factor& fx, const Factor& fy) : span_x_(extent(fx)), span_y_(extent(fy)) {}

void MapCells::add(std::string_view outcome, std::int64_t index, double x, double y) {
  auto at = outcomes_.find(outcome);
  if (at == outcomes_.end()) at = outcomes_.try_emplace(std::string(outcome)).first;
  Outcome& o = at->second;
  if (++o.count <= kAll) o.x.push_back(x), o.y.push_back(y);
  if (!std::isfinite(x) || !std::isfinite(y)) return;
  if (o.picks.empty()) o.picks.resize(kMapCells * kMapCells);
  Pick& p = o.picks[static_cast<size_t>(map_cell(x, span_x_) * kMapCells + map_cell(y, span_y_))];
  const std::uint64_t hash = philox_bits(0, static_cast<std::uint64_t>(index), 0, domain::status_map);
  if (hash < p.hash) p = {hash, x, y};
}

std::vector<MapSeries> MapCells::series() {
  std::vector<MapSeries> out;
  for (auto& [name, o] : outcomes_) {
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

}  // namespace opt::doe
