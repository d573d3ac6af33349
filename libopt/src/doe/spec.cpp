// The `doe` study's keys: factors from the problem's parameter table, the
// sampler and its settings, explicit points. Every value is checked against
// its row's domain where it is written.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "opt/doe/batch.hpp"
#include "opt/run_spec.hpp"
#include "opt/units.hpp"

namespace opt::doe {
namespace {

const Parameter& row_named(const ConfigNode& at, const std::vector<Parameter>& table, const std::string& name) {
  for (const auto& p : table)
    if (p.name == name) return p;
  std::string names;
  for (const auto& p : table) names += (names.empty() ? "" : ", ") + p.name;
  at.fail("no model value '" + name + "' in this problem; factors are model keys: " + names);
}

// One level of row p: an option name, a whole number or a quantity, in its domain.
double level(const ConfigNode& n, const Parameter& p) {
  if (!p.choices.empty()) return static_cast<double>(std::find(p.choices.begin(), p.choices.end(),
                                                               n.choice(p.choices)) - p.choices.begin());
  return read_parameter(n, p);
}

Factor levels_factor(const std::string& name, const ConfigNode& list, const Parameter& p) {
  Factor f;
  f.name = name;
  f.kind = p.choices.empty() ? Factor::Kind::levels : Factor::Kind::categorical;
  for (const auto& item : list.items()) {
    f.levels.push_back(level(item, p));
    if (!p.choices.empty()) f.labels.push_back(p.choices[static_cast<size_t>(f.levels.back())]);
  }
  if (f.levels.empty()) list.fail("expected at least one level");
  return f;
}

FactorSpec parse_factor(const std::string& name, const ConfigNode& n, const Parameter& p, bool factorial) {
  FactorSpec s{{}, p, false};
  if (n.is_sequence()) {
    s.factor = levels_factor(name, n, p);
  } else {
    n.allow_only({"min", "max", "count", "step", "levels"});
    if (n.has("levels")) {
      if (n.has("min") || n.has("max")) n.fail("expected either levels or min and max, not both");
      s.factor = levels_factor(name, n.at("levels"), p);
    } else {
      if (!p.choices.empty() || p.integer)
        n.fail("expected a list of levels for '" + name + "' (" + domain_text(p) + "), e.g. [a, b]");
      Factor& f = s.factor;
      f.name = name;
      f.lower = read_parameter(n.at("min"), p);
      f.upper = read_parameter(n.at("max"), p);
      if (!(f.upper > f.lower)) n.at("max").fail("expected max > min");
      if (n.has("count") && n.has("step")) n.fail("expected count or step, not both");
      if (n.has("count")) f.count = n.at("count").integer(2, 1000000);
      if (n.has("step")) {
        const double step = n.at("step").quantity(p.dimension);
        if (!(step > 0)) n.at("step").fail("expected a step > 0");
        const double k = (f.upper - f.lower) / step;
        if (k > 1e6) n.at("step").fail("more than 10^6 levels");
        if (std::abs(k - std::round(k)) > 1e-9 * std::max(1.0, k))
          n.at("step").fail("expected a step that divides max - min evenly");
        f.count = static_cast<int>(std::round(k)) + 1;
      }
      if (factorial && f.count == 0) n.fail("a factorial design needs count or step (or levels) for a range");
    }
  }
  // Through x only if the factor varies (a variable's bounds need min < max).
  const auto& lv = s.factor.levels;
  const bool spread = s.factor.kind == Factor::Kind::range ||
                      (s.factor.kind == Factor::Kind::levels &&
                       *std::min_element(lv.begin(), lv.end()) < *std::max_element(lv.begin(), lv.end()));
  s.through_x = p.variable && spread;
  return s;
}

// Explicit points: a list of maps {factor: value} or a CSV file whose header
// names the factors ("rod_length" or "rod_length [mm]"); cells may carry units.
std::vector<std::vector<double>> parse_points(const ConfigNode& n, const std::vector<FactorSpec>& factors) {
  std::vector<std::vector<double>> rows;
  for (const auto& item : n.items()) {
    item.allow_only([&] {
      std::vector<std::string> names;
      for (const auto& f : factors) names.push_back(f.factor.name);
      return names;
    }());
    std::vector<double> row;
    for (const auto& f : factors) row.push_back(level(item.at(f.factor.name), f.parameter));
    rows.push_back(std::move(row));
  }
  if (rows.empty()) n.fail("expected at least one point");
  return rows;
}

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string c; std::getline(ss, c, ',');) {
    const auto a = c.find_first_not_of(" \t\r"), b = c.find_last_not_of(" \t\r");
    cells.push_back(a == std::string::npos ? "" : c.substr(a, b - a + 1));
  }
  return cells;
}

// The factors and rows of a points file; a header cell "name [unit]" gives
// the unit of its column's bare numbers.
void parse_points_file(const ConfigNode& n, const std::vector<Parameter>& table, DoeSpec& s) {
  const std::string file = relative_to(n.file(), n.text());
  std::ifstream in(file);
  if (!in) n.fail("cannot read the points file '" + file + "'");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> units;
  for (auto& h : split_csv(line)) {
    std::string unit;
    if (const auto b = h.find('['); b != std::string::npos) {
      unit = h.substr(b + 1, h.find(']') - b - 1);
      h = h.substr(0, h.find_last_not_of(' ', b - 1) + 1);
    }
    const Parameter& p = row_named(n, table, h);
    s.factors.push_back({{}, p, false});
    s.factors.back().factor.name = h;
    units.push_back(unit);
  }
  for (int lineno = 2; std::getline(in, line); ++lineno) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto cells = split_csv(line);
    const std::string where = file + ":" + std::to_string(lineno);
    if (cells.size() != s.factors.size())
      throw ConfigError(where + ": expected " + std::to_string(s.factors.size()) + " cells, got " +
                        std::to_string(cells.size()));
    std::vector<double> row;
    for (size_t j = 0; j < cells.size(); ++j) {
      const bool bare = cells[j].find_first_not_of("0123456789.eE+- ") == std::string::npos;
      const std::string text = bare && !units[j].empty() ? cells[j] + " " + units[j] : cells[j];
      const ConfigNode cell(YAML::Node(text), where, s.factors[j].factor.name);
      row.push_back(level(cell, s.factors[j].parameter));
    }
    s.rows.push_back(std::move(row));
  }
  if (s.rows.empty()) n.fail("the points file '" + file + "' has no rows");
}

// A list's factors span its rows: a range over the values (categorical for a choice).
void factors_from_rows(DoeSpec& s) {
  for (size_t j = 0; j < s.factors.size(); ++j) {
    FactorSpec& f = s.factors[j];
    const Parameter& p = f.parameter;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const auto& r : s.rows) lo = std::min(lo, r[j]), hi = std::max(hi, r[j]);
    if (!p.choices.empty()) {
      f.factor.kind = Factor::Kind::categorical;
      for (size_t k = 0; k < p.choices.size(); ++k) f.factor.levels.push_back(static_cast<double>(k));
      f.factor.labels = p.choices;
    } else {
      f.factor.kind = Factor::Kind::range;
      f.factor.lower = lo;
      f.factor.upper = hi > lo ? hi : lo + 1;  // a constant column: any span holds it
    }
    f.through_x = p.variable && p.choices.empty() && hi > lo;
  }
}

// refine: {best: K, driver: {...}} (the driver: as `study.driver` of an
// optimize study; default: the problem's default algorithm).
void parse_refine(const ConfigNode& n, DoeSpec& s) {
  n.allow_only({"best", "driver"});
  s.refine_best = static_cast<int>(n.at("best").integer(1, 10000));
  if (n.has("driver")) s.refine_driver = parse_driver(n.at("driver"));
  if (s.objective.metric.empty()) n.fail("refine optimises the objective: add objective: {minimize: METRIC}");
  if (std::none_of(s.factors.begin(), s.factors.end(), [](const FactorSpec& f) { return f.through_x; }))
    n.fail("refine varies the factors that are design variables (with a range), and this study has none");
  nlohmann::json cons = nlohmann::json::array();
  for (const auto& c : s.constraints) cons.push_back({c.metric, c.relation(), c.bound});
  s.refine_settings = {{"driver", n.has("driver") ? n.at("driver").to_json() : nlohmann::json()},
                       {"objective", {s.objective.metric, s.objective.maximize ? "maximize" : "minimize"}},
                       {"constraints", cons}};
}

}  // namespace

DoeSpec parse_doe(const ConfigNode& root, const std::vector<Parameter>& table, const Problem& problem,
                  bool beyond_limit) {
  DoeSpec s;
  const ConfigNode st = root.at("study");
  st.allow_only({"type", "sampler", "samples", "seed", "maximin", "factors", "points", "points_file", "columns",
                 "sample_time_limit", "refine"});
  {
    const RunSpec run = parse_run(root, problem);  // objective and constraints (optional for a doe)
    s.objective = run.objective;
    s.constraints = run.constraints;
  }
  if (st.has("sample_time_limit")) {
    s.sample_seconds = st.at("sample_time_limit").quantity(Dimension::time);
    if (!(s.sample_seconds > 0)) st.at("sample_time_limit").fail("expected a time > 0, e.g. 10 s");
  }
  s.sampler = st.has("sampler") ? st.at("sampler").choice({"factorial", "random", "latin_hypercube", "sobol",
                                                            "saltelli", "list"})
              : st.has("points") || st.has("points_file") ? "list"
              : st.has("samples")                          ? "sobol"
                                                           : "factorial";
  const bool list = s.sampler == "list";
  if (list != (st.has("points") || st.has("points_file")))
    st.fail(list ? "sampler list needs points or points_file" : "points go with sampler: list");
  if (list && st.has("factors")) st.at("factors").fail("a list's factors are the keys of its points");
  if (!list && !st.has("factors")) st.fail("missing required key 'factors' (the model keys to vary)");
  const bool counted = s.sampler != "factorial" && !list;
  if (counted != st.has("samples"))
    st.fail(counted ? "sampler " + s.sampler + " needs samples: N" : "samples goes with a random or quasi-random sampler");
  if (counted) {
    const double n = st.at("samples").number();
    if (!(n >= 1 && n <= 4e18 && n == std::floor(n))) st.at("samples").fail("expected a whole number >= 1");
    s.samples = static_cast<std::int64_t>(n);
  }
  if (st.has("seed")) {
    if (s.sampler == "factorial" || list) st.at("seed").fail("a " + s.sampler + " design has no random numbers");
    s.seed = static_cast<std::uint64_t>(st.at("seed").integer(0, 2147483647));
  } else if (s.sampler == "random" || s.sampler == "latin_hypercube") {
    s.seed = 0;
  }
  if (st.has("maximin")) {
    if (s.sampler != "latin_hypercube") st.at("maximin").fail("maximin goes with sampler: latin_hypercube");
    s.maximin = st.at("maximin").boolean();
  }
  if (st.has("factors")) {
    const ConfigNode fs = st.at("factors");
    for (const auto& name : fs.keys())
      s.factors.push_back(parse_factor(name, fs.at(name), row_named(fs, table, name), s.sampler == "factorial"));
    if (s.factors.empty()) fs.fail("expected at least one factor");
  }
  if (st.has("points")) {
    const ConfigNode pts = st.at("points");
    if (pts.items().empty() || !pts.items()[0].is_map()) pts.fail("expected a list of {factor: value} maps");
    for (const auto& name : pts.items()[0].keys()) {
      s.factors.push_back({{}, row_named(pts, table, name), false});
      s.factors.back().factor.name = name;
    }
    s.rows = parse_points(pts, s.factors);
  }
  if (st.has("points_file")) {
    if (st.has("points")) st.at("points_file").fail("expected points or points_file, not both");
    parse_points_file(st.at("points_file"), table, s);
  }
  if (list) factors_from_rows(s);
  if (st.has("columns")) {
    for (const auto& c : st.at("columns").items()) {
      if (!problem.has_metric(c.text())) {
        std::string names;
        for (const auto& m : problem.metric_names()) names += (names.empty() ? "" : ", ") + m;
        c.fail("unknown metric '" + c.text() + "'; expected one of: " + names);
      }
      s.columns.push_back(c.text());
    }
  }
  if (st.has("refine")) parse_refine(st.at("refine"), s);
  std::int64_t n = 0;
  try {
    n = make_sampler(s)->size();  // sampler-specific limits (e.g. maximin's N), located at the study
  } catch (const std::invalid_argument& e) {
    st.fail(e.what());
  }
  const ConfigNode where = st.has("samples") ? st.at("samples") : st.has("factors") ? st.at("factors") : st;
  const std::string count = std::to_string(n) + " samples";
  if (n > kHardMaxSamples)
    where.fail(count + " is more than one store indexes (" + std::to_string(kHardMaxSamples) +
               "): split the study into several");
  if (n > kMaxSamples && !beyond_limit)
    where.fail(count + " is more than " + std::to_string(kMaxSamples) +
               ": --dry-run shows the time and store size it would take; --force goes ahead");
  return s;
}

std::vector<std::string> stored_metrics(const DoeSpec& spec, const Problem& problem) {
  if (spec.columns.empty()) return problem.metric_names();
  std::vector<std::string> wanted = spec.columns;
  if (!spec.objective.metric.empty()) wanted.push_back(spec.objective.metric);
  for (const auto& c : spec.constraints) wanted.push_back(c.metric);
  std::vector<std::string> out;
  for (const auto& m : problem.metric_names())
    if (std::find(wanted.begin(), wanted.end(), m) != wanted.end()) out.push_back(m);
  return out;
}

std::string metric_column(const DoeSpec& spec, const std::string& metric) {
  const bool taken = std::any_of(spec.factors.begin(), spec.factors.end(),
                                 [&](const FactorSpec& f) { return f.factor.name == metric; });
  return taken ? metric + "_metric" : metric;
}

std::unique_ptr<Sampler> make_sampler(const DoeSpec& s) {
  std::vector<Factor> f;
  for (const auto& x : s.factors) f.push_back(x.factor);
  if (s.sampler == "factorial") return factorial(f);
  if (s.sampler == "random") return uniform_random(f, s.samples, s.seed.value_or(0));
  if (s.sampler == "latin_hypercube") return latin_hypercube(f, s.samples, s.seed.value_or(0), s.maximin);
  if (s.sampler == "sobol") return sobol(f, s.samples, s.seed);
  if (s.sampler == "saltelli") return saltelli(f, s.samples, s.seed);
  return point_list(f, s.rows);
}

}  // namespace opt::doe
