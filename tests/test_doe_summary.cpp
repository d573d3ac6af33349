// DOE summaries against closed forms: the Ishigami function's Sobol'
// indices (Ishigami & Homma 1990; Saltelli et al., Global Sensitivity
// Analysis, 2008, eq. 4.34), the slider-crank's stroke 2r for main effects,
// and the best feasible sample of a factorial under a constraint.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include "cli.hpp"
#include "opt/doe/store.hpp"
#include "opt/doe/batch.hpp"
#include "opt/model_problem.hpp"
#include "opt/registry.hpp"

namespace {

// f = sin x1 + a sin^2 x2 + b x3^4 sin x1, x in [-pi, pi]^3, a = 7, b = 0.1.
std::vector<opt::Parameter> ishigami_parameters() {
  std::vector<opt::Parameter> p;
  for (const char* n : {"x1", "x2", "x3"}) p.push_back(opt::variable(n, opt::Dimension::dimensionless, opt::kAnyValue, n, ""));
  return p;
}

class Ishigami : public opt::ModelProblem<Ishigami> {
 public:
  enum Metric { f };
  explicit Ishigami(std::vector<opt::Variable> v) : ModelProblem("ishigami", {{f, "f", ""}}, std::move(v)) {}
  template <class S>
  void evaluate_model(const std::vector<S>& x, opt::MetricSink<S>& out) const {
    using std::sin;
    out.put(f, sin(x[0]) + 7 * sin(x[1]) * sin(x[1]) + 0.1 * x[2] * x[2] * x[2] * x[2] * sin(x[0]));
  }
  nlohmann::json settings() const override { return {}; }
};

const opt::Registration kIshigami{
    {"ishigami", "test only: the Ishigami function", ishigami_parameters(),
     [](const opt::ConfigNode& root) -> std::unique_ptr<opt::Problem> {
       return std::make_unique<Ishigami>(opt::parse_variables(root, ishigami_parameters()));
     }}};

nlohmann::json run(const std::string& yaml, const std::string& dir, std::string& printed,
                   opt::doe::DoeSpec* spec_out = nullptr) {
  const auto root = opt::ConfigNode::parse(yaml, "<summary>");
  const auto p = opt::make_problem(root);
  std::vector<opt::Parameter> table;
  for (const auto& e : opt::registry())
    if (e.name == p->name()) table = e.parameters;
  opt::doe::DoeSpec spec = opt::doe::parse_doe(root, table, *p);
  const auto run = opt::parse_run(root, *p);
  spec.objective = run.objective;
  spec.constraints = run.constraints;
  opt::doe::BatchOptions o;
  o.output_directory = dir;
  o.progress = "none";
  std::ostringstream out, err;
  const auto j = opt::doe::run_batch(root, opt::make_problem, spec, o, out, err);
  printed = out.str();
  if (spec_out) *spec_out = spec;
  return j;
}

// Analytic indices for a = 7, b = 0.1: V = a^2/8 + b pi^4/5 + b^2 pi^8/18 + 1/2,
// V1 = (1 + b pi^4/5)^2 / 2, V2 = a^2/8, V13 = b^2 pi^8 (1/18 - 1/50).
TEST(DoeSummary, SobolIndicesOfIshigami) {
  const double pi = std::numbers::pi, a = 7, b = 0.1;
  const double v1 = 0.5 * std::pow(1 + b * std::pow(pi, 4) / 5, 2), v2 = a * a / 8,
               v13 = b * b * std::pow(pi, 8) * (1.0 / 18 - 1.0 / 50), v = v1 + v2 + v13;
  const double s1[3] = {v1 / v, v2 / v, 0}, st[3] = {(v1 + v13) / v, v2 / v, v13 / v};
  std::string printed;
  const auto j = run(R"(problem: ishigami
study:
  type: doe
  sampler: saltelli
  samples: 32768
  seed: 3
  factors: {x1: {min: -3.141592653589793, max: 3.141592653589793},
            x2: {min: -3.141592653589793, max: 3.141592653589793},
            x3: {min: -3.141592653589793, max: 3.141592653589793}}
)", cli::fresh_dir("doe_ishigami"), printed);
  ASSERT_EQ(j["run_status"], "complete");
  const auto& idx = j["summary"]["sobol"]["f"];
  for (int k = 0; k < 3; ++k) {
    const auto& x = idx["x" + std::to_string(k + 1)];
    EXPECT_EQ(x["rows"], 32768);
    // 2^15 base rows (at 2^14 the first-order intervals are 0.021-0.022
    // wide on a side): every 95% interval is at most 0.02 wide on each side
    // and holds the analytic value.
    for (const char* kind : {"first", "total"}) {
      const double exact = kind[0] == 'f' ? s1[k] : st[k];
      const auto& ci = x[std::string(kind) + "_95"];
      EXPECT_LE(ci[1].get<double>() - x[kind].get<double>(), 0.02) << kind << " x" << k + 1;
      EXPECT_LE(x[kind].get<double>() - ci[0].get<double>(), 0.02) << kind << " x" << k + 1;
      EXPECT_LE(ci[0].get<double>(), exact) << kind << " x" << k + 1;
      EXPECT_GE(ci[1].get<double>(), exact) << kind << " x" << k + 1;
    }
  }
  EXPECT_NE(printed.find("Sobol' indices"), std::string::npos) << printed;
}

// Stroke = 2r: main effects are over every design that assembles, the
// constraint met or not, so crank_radius (0.1 to 0.2 m) moves the stroke by
// 0.2 m and rod_length not at all (nor the binomial series, exact at the dead centres); the least peak acceleration r w^2 (1 + r/l) is at the
// smallest r and largest l, among designs with stroke >= 0.25 m.
TEST(DoeSummary, MainEffectsAndBestFeasibleSample) {
  std::string printed;
  const auto j = run(R"(problem: slider_crank
objective: {minimize: peak_slider_acceleration}
constraints: {stroke: {min: 0.25 m}}
study:
  type: doe
  factors:
    crank_radius: [0.1 m, 0.15 m, 0.2 m]
    rod_length: {min: 0.8 m, max: 1.2 m, count: 3}
    kinematics: [exact, binomial]
)", cli::fresh_dir("doe_effects"), printed);
  const auto& s = j["summary"];
  EXPECT_EQ(s["feasible"], 12) << "stroke >= 0.25 m: r = 0.15 and 0.2 m";
  EXPECT_NEAR(s["main_effects"]["crank_radius"]["stroke"]["range"].get<double>(), 0.2, 1e-12);
  EXPECT_NEAR(s["main_effects"]["kinematics"]["stroke"]["range"].get<double>(), 0, 1e-12);
  EXPECT_NEAR(s["main_effects"]["rod_length"]["stroke"]["range"].get<double>(), 0, 1e-12);
  EXPECT_EQ(s["main_effects"]["kinematics"]["stroke"]["groups"], (std::vector<std::string>{"binomial", "exact"}));
  const auto& best = s["best"][0];
  EXPECT_EQ(best["metric"], "peak_slider_acceleration");
  EXPECT_DOUBLE_EQ(best["factors"]["crank_radius"].get<double>(), 0.15);
  EXPECT_NEAR(best["factors"]["rod_length"].get<double>(), 1.2, 1e-15);
  const double w = 100 * std::numbers::pi / 30;
  EXPECT_NEAR(best["value"].get<double>(), 0.15 * w * w * (1 + 0.15 / 1.2), 1e-6);
  EXPECT_FALSE(j["charts"].empty());
}

// The status map: the outcome of every sample over the first two factors.
// A slider-crank assembles only with the rod longer than the crank (l > r,
// no offset), and its stroke is 2 r: of the 3 x 3 grid, r >= l fails in 3
// designs, and of the 6 that assemble only r = 0.6 m meets stroke >= 0.9 m.
TEST(DoeSummary, StatusMapCountsEveryOutcome) {
  std::string printed;
  opt::doe::DoeSpec spec;
  const std::string dir = cli::fresh_dir("doe_status_map");
  const auto j = run(R"(problem: slider_crank
constraints: {stroke: {min: 0.9 m}}
study:
  type: doe
  factors:
    crank_radius: [0.2 m, 0.4 m, 0.6 m]
    rod_length: [0.3 m, 0.5 m, 0.7 m]
)", dir, printed, &spec);
  EXPECT_EQ(j["summary"]["failures"]["cannot_assemble"]["count"], 3);
  std::ifstream in(dir + "/status_map.svg");
  const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* label : {"cannot_assemble (3)", "constraint not met (5)", "feasible (1)"})
    EXPECT_NE(svg.find(std::string(">") + label + "<"), std::string::npos) << label;
  EXPECT_NE(svg.find("crank_radius [m]"), std::string::npos);
  EXPECT_NE(svg.find("rod_length [m]"), std::string::npos);
  for (const auto& m : opt::doe::status_map(dir + "/store.sqlite", spec))  // so few: every one drawn
    EXPECT_EQ(static_cast<std::int64_t>(m.x.size()), m.count) << m.outcome;
}

// The printed summary shows values as a designer reads them: the best
// sample's angle in degrees with its unit, every metric's name whole with
// its unit; result.json keeps SI (radians).
TEST(DoeSummary, PrintsUnitsAndWholeNames) {
  std::string printed;
  const auto j = run(R"(problem: recuperative_drive
objective: {minimize: k1}
study:
  type: doe
  factors:
    phase_shift: [90 deg]
    rod_length: [0.8 m, 1.2 m]
  columns: [k1, least_mean_kinetic_energy, peak_crank_torque]
)", cli::fresh_dir("doe_units"), printed);
  const auto& best = j["summary"]["best"][0];
  EXPECT_NEAR(best["factors"]["phase_shift"].get<double>(), std::numbers::pi / 2, 1e-12);  // SI in result.json
  EXPECT_NE(printed.find("phase_shift = 90 deg"), std::string::npos) << printed;
  EXPECT_NE(printed.find(", rod_length = "), std::string::npos) << printed;
  for (const char* head : {"k1 [-]", "least_mean_kinetic_energy [J]", "peak_crank_torque [N m]", "phase_shift "})
    EXPECT_NE(printed.find(head), std::string::npos) << head << " in\n" << printed;
}

// The status map and the main effects draw from the whole design space. A
// slider-crank over crank radius and rod length fails to assemble where
// r >= l (a corner of the square) and meets stroke >= 0.5 m only where
// r >= 0.25 m, so three outcomes share the plane. For a Sobol' sequence (2^16
// points: drawing every 4th index, as the map once did, keeps its first two
// coordinates below half their ranges), a Latin hypercube and a factorial:
// every cell of a 10 x 10 grid over the two factors that holds samples of an
// outcome holds a drawn point of that outcome, and every factor's main-effect
// curve runs from its first tenth to its last.
TEST(DoeSummary, StatusMapAndMainEffectsCoverTheDesignSpace) {
  const char* designs[] = {"sampler: sobol\n  samples: 65536",
                           "sampler: latin_hypercube\n  samples: 65536\n  seed: 7",
                           "sampler: factorial"};
  for (const std::string design : designs) {
    const bool factorial = design == "sampler: factorial";
    const std::string dir = cli::fresh_dir("doe_map_cover");
    std::string printed;
    opt::doe::DoeSpec spec;
    const auto j = run(R"(problem: slider_crank
constraints: {stroke: {min: 0.5 m}}
study:
  type: doe
  )" + design + R"(
  factors:
    crank_radius: {min: 0.1 m, max: 0.4 m)" + (factorial ? ", count: 250" : "") + R"(}
    rod_length: {min: 0.2 m, max: 1.2 m)" + (factorial ? ", count: 262" : "") + R"(}
)", dir, printed, &spec);
    ASSERT_EQ(j["run_status"], "complete") << design;
    // Which outcomes each cell holds, from every row of the store.
    auto cell = [](double r, double l) {
      return std::min(9, static_cast<int>((r - 0.1) / 0.3 * 10)) * 10 + std::min(9, static_cast<int>((l - 0.2) / 1.0 * 10));
    };
    std::map<std::string, std::set<int>> stored, drawn;
    std::int64_t rows = 0;
    opt::doe::read_rows(dir + "/store.sqlite", [&](const opt::doe::Row& r) {
      ++rows;
      const bool stroke_met = r.status == "ok" && 2 * r.factors[0] >= 0.5 - 1e-12;
      stored[r.status != "ok" ? std::string(r.status) : stroke_met ? "feasible" : "constraint not met"].insert(
          cell(r.factors[0], r.factors[1]));
    });
    ASSERT_EQ(rows, 65536 - (factorial ? 36 : 0)) << design;
    ASSERT_EQ(stored.size(), 3u) << design;
    std::int64_t counted = 0;
    for (const auto& m : opt::doe::status_map(dir + "/store.sqlite", spec)) {
      counted += m.count;
      EXPECT_LE(m.x.size(), static_cast<size_t>(opt::doe::kMapCells * opt::doe::kMapCells));  // over 1000 each
      for (size_t i = 0; i < m.x.size(); ++i) drawn[m.outcome].insert(cell(m.x[i], m.y[i]));
    }
    EXPECT_EQ(counted, rows) << design;
    for (const auto& [outcome, cells] : stored)
      for (int c : cells)
        EXPECT_TRUE(drawn[outcome].count(c)) << design << ": " << outcome << " in cell (" << c / 10 << ", " << c % 10
                                             << ") of 10 x 10 is not drawn";
    for (const char* f : {"crank_radius", "rod_length"}) {
      const auto positions = j["summary"]["main_effects"][f]["stroke"]["positions"].get<std::vector<double>>();
      ASSERT_FALSE(positions.empty()) << design << " " << f;
      EXPECT_NEAR(positions.front(), 0.05, 1e-12) << design << " " << f;  // 250 and 262 levels: binned
      EXPECT_NEAR(positions.back(), 0.95, 1e-12) << design << " " << f;
    }
  }
}

}  // namespace
