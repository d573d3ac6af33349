// Every metric of every problem: the autodiff gradient the drivers use
// against central differences, at every shipped config's start point (the
// registry's problems, each required to ship one), and at further designs
// away from ties of the maxima.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "opt/config.hpp"
#include "opt/derivatives.hpp"
#include "opt/registry.hpp"
#include "paths.hpp"

namespace {

struct Case {
  std::string name, yaml;
};

const Case kCases[] = {
    {"recuperative_signed_point_masses", R"(
problem: recuperative_drive
model: {rod_length: 0.7 m, phase_shift: 80 deg, offset: 0.03 m, cycle_points: 64,
        resistance: signed, fidelity: {rod: point_masses}}
variables: {rod_length: {min: 0.5 m, max: 1.5 m}, phase_shift: {min: 0 deg, max: 180 deg},
            crank_radius: {min: 0.1 m, max: 0.3 m}, offset: {min: -0.1 m, max: 0.1 m}})"},
    {"recuperative_opposing_full_binomial", R"(
problem: recuperative_drive
model: {rod_length: 0.7 m, phase_shift: 80 deg, offset: 0.03 m, resistance: opposes_motion,
        fidelity: {rod: full, kinematics: binomial}}
variables: {rod_length: {min: 0.5 m, max: 1.5 m}, phase_shift: {min: 0 deg, max: 180 deg},
            crank_radius: {min: 0.1 m, max: 0.3 m}, offset: {min: -0.1 m, max: 0.1 m}})"},
    {"conveyor_synthesis", R"(
problem: conveyor_swing
model: {l_co1: 1.3 m}
variables: {l_co1: {min: 0.9 m, max: 2.4 m}})"},
    {"conveyor_free_links", R"(
problem: conveyor_swing
model: {design: free_links, l_co1: 1.4 m, crank_length: 0.45 m}
variables: {crank_length: {min: 0.3 m, max: 1.6 m}, coupler_length: {min: 0.3 m, max: 1.6 m},
            rocker_length: {min: 0.3 m, max: 3 m}})"},
};

class Gradients : public ::testing::TestWithParam<Case> {};

TEST_P(Gradients, MatchCentralDifferences) {
  const auto p = opt::make_problem(opt::ConfigNode::parse(GetParam().yaml, GetParam().name));
  const Eigen::VectorXd x = p->initial_point();
  ASSERT_TRUE(p->evaluate(x, opt::MetricSet::all(), false).ok());
  // opt::check_derivatives (also `mechopt check-derivatives`): h = 1e-6 of
  // each variable's scale, 1e-7 relative to max(1, |f|).
  const auto checks = opt::check_derivatives(*p, x);
  size_t metrics = 0, peaks = 0;
  for (const auto& c : checks) {
    EXPECT_TRUE(c.ok) << c.metric << " d/d" << c.variable << ": autodiff " << c.autodiff
                      << ", central " << c.central << ", error " << c.error;
    (c.metric.find("[peak") == std::string::npos ? metrics : peaks)++;
  }
  EXPECT_GE(metrics, (p->metric_names().size() - 1) * x.size());  // synthesis_margin: synthesis only
  EXPECT_GT(peaks, 0u) << "every problem has cycle maxima with epigraph rows";
}

INSTANTIATE_TEST_SUITE_P(AllProblems, Gradients, ::testing::ValuesIn(kCases),
                         [](const auto& info) { return info.param.name; });

// configs/**/*.yaml that free variables, relative to configs/.
std::vector<std::string> configs_with_variables() {
  namespace fs = std::filesystem;
  const fs::path root = fs::path(MECHOPT_SOURCE_DIR) / "configs";
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.path().extension() != ".yaml") continue;
    const auto c = opt::ConfigNode::load(e.path().string());
    if (c.has("variables") && c.at("variables").is_map()) out.push_back(fs::relative(e.path(), root).string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string config_path(const std::string& relative) {
  return std::string(MECHOPT_SOURCE_DIR) + "/configs/" + relative;
}

// opt::check_derivatives at the start point of every shipped config that
// frees variables of a problem with gradients: every metric the design has,
// d/d every variable (h = 1e-6 of each variable's scale, 1e-7 relative to
// max(1, |f|)), and the epigraph rows of its cycle maxima. Every registered
// problem with gradients must ship such a config.
TEST(ShippedConfigs, GradientsMatchCentralDifferences) {
  std::set<std::string> checked_problems, with_gradients;
  for (const auto& entry : opt::registry())
    if (entry.summary.rfind("test only", 0) != 0) with_gradients.insert(entry.name);  // not this binary's own
  for (const auto& config : configs_with_variables()) {
    SCOPED_TRACE(config);
    const auto p = opt::make_problem(opt::ConfigNode::load(config_path(config)));
    if (!p->provides_gradients()) {
      with_gradients.erase(p->name());
      continue;
    }
    const Eigen::VectorXd x = p->initial_point();
    const auto e = p->evaluate(x, opt::MetricSet::all(), false);
    ASSERT_TRUE(e.ok()) << "the start point fails";
    std::set<std::string> checked;
    for (const auto& c : opt::check_derivatives(*p, x)) {
      EXPECT_TRUE(c.ok) << c.metric << " d/d" << c.variable << ": autodiff " << c.autodiff << ", central "
                        << c.central << ", error " << c.error;
      checked.insert(c.metric);
    }
    for (const auto& m : p->metric_names()) {
      if (e.has(p->metric_id(m))) {
        EXPECT_TRUE(checked.count(m)) << m << " has a value but no gradient check";
      }
    }
    checked_problems.insert(p->name());
  }
  for (const auto& name : with_gradients)
    EXPECT_TRUE(checked_problems.count(name)) << name << ": no config in configs/ frees a variable";
}

}  // namespace

// Autodiff for any number of design variables: a test-only problem,
// registered like every other, frees six values of the twin drive (beyond
// the four a fixed-size derivative vector carries). The gradient of
// T_min = 4 m r^2 w^2 / pi^2 (seed 000 eq. 14) has a closed form; every
// metric is also checked against central differences.
#include <numbers>

#include "mech/twin_slider_crank.hpp"
#include "opt/model_problem.hpp"

namespace {

std::vector<opt::Parameter> six_parameters() {
  using opt::Dimension;
  std::vector<opt::Parameter> p = {
      opt::variable("rod_length", Dimension::length, opt::kPositive, "l", ""),
      opt::variable("phase_shift", Dimension::angle, opt::kAnyValue, "dphi", ""),
      opt::variable("crank_radius", Dimension::length, opt::kPositive, "r", ""),
      opt::variable("offset", Dimension::length, opt::kAnyValue, "e", ""),
      opt::variable("cart_mass", Dimension::mass, opt::kPositive, "m", ""),
      opt::variable("crank_speed", Dimension::angular_speed, opt::kPositive, "w", "")};
  const double values[] = {0.8, 1.5, 0.2, 0.02, 1000, 10};
  for (size_t i = 0; i < p.size(); ++i) p[i].value = values[i];
  return p;
}

class SixVariables : public opt::ModelProblem<SixVariables> {
 public:
  enum Metric { mean, least };
  explicit SixVariables(std::vector<opt::Variable> v)
      : ModelProblem("six_variables", {{mean, "mean_kinetic_energy", "J"}, {least, "least_mean_kinetic_energy", "J"}},
                     std::move(v)) {}
  template <class S>
  void evaluate_model(const std::vector<S>& x, opt::MetricSink<S>& out) const {
    mech::TwinDrive<S> d = mech::TwinDrive<double>{0.2, 0.8, 1.5, 0, 10, 1000, 80, 0.9, 3562}.cast<S>();
    d.rod_length = x[0], d.phase_shift = x[1], d.crank_radius = x[2], d.offset = x[3];
    d.cart_mass = x[4], d.crank_speed = x[5];
    out.put(mean, mech::mean_kinetic_energy(d, 64));
    out.put(least, mech::least_mean_kinetic_energy(d));
  }
  nlohmann::json settings() const override { return {}; }
};

const opt::Registration kSix{
    {"six_variables", "test only: six variables of the twin drive", six_parameters(),
     [](const opt::ConfigNode& root) -> std::unique_ptr<opt::Problem> {
       return std::make_unique<SixVariables>(opt::parse_variables(root, six_parameters()));
     }}};

TEST(Gradients, SixVariablesThroughTheRegistry) {
  const auto p = opt::make_problem(opt::ConfigNode::parse(R"(
problem: six_variables
variables: {rod_length: {min: 0.5 m, max: 1.5 m}, phase_shift: {min: 0 deg, max: 180 deg},
            crank_radius: {min: 0.1 m, max: 0.3 m}, offset: {min: -0.1 m, max: 0.1 m},
            cart_mass: {min: 500 kg, max: 2000 kg}, crank_speed: {min: 5 rad/s, max: 15 rad/s}})",
                                                               "<six>"));
  ASSERT_EQ(p->variables().size(), 6u);
  const Eigen::VectorXd x = p->initial_point();
  const auto e = p->evaluate(x, opt::MetricSet::all(), true);
  ASSERT_TRUE(e.ok());
  const double m = 1000, r = 0.2, w = 10, pi2 = std::numbers::pi * std::numbers::pi;
  const Eigen::VectorXd& g = e[p->metric_id("least_mean_kinetic_energy")].gradient;
  ASSERT_EQ(g.size(), 6);
  constexpr double kTol = 1e-12;  // relative: closed forms, a few roundings
  EXPECT_NEAR(e.at("least_mean_kinetic_energy") / (4 * m * r * r * w * w / pi2), 1, kTol);
  EXPECT_NEAR(g[2] / (8 * m * r * w * w / pi2), 1, kTol);  // d/dr
  EXPECT_NEAR(g[4] / (4 * r * r * w * w / pi2), 1, kTol);  // d/dm
  EXPECT_NEAR(g[5] / (8 * m * r * r * w / pi2), 1, kTol);  // d/dw
  EXPECT_EQ(g[0], 0);
  EXPECT_EQ(g[1], 0);
  EXPECT_EQ(g[3], 0);
  for (const auto& c : opt::check_derivatives(*p, x))
    EXPECT_TRUE(c.ok) << c.metric << " d/d" << c.variable << ": autodiff " << c.autodiff
                      << ", central " << c.central;
}

}  // namespace
