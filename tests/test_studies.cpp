// Studies: the epsilon-constraint Pareto front on a case whose front is
// known — along the conveyor's l_CO1 family the peak moment falls and the
// pressure angle rises between the two single-objective optima, so the front
// is that segment of the family.
#include <gtest/gtest.h>

#include <sstream>

#include "opt/study.hpp"
#include "opt/registry.hpp"

namespace {

TEST(Pareto, ConveyorFrontIsTheFamilyBetweenTheTwoOptima) {
  const auto root = opt::ConfigNode::parse(R"(
problem: conveyor_swing
variables: {l_co1: {min: 0.9 m, max: 2.4 m}}
study: {type: pareto, objectives: [peak_crank_torque, max_pressure_angle], points: 5,
        driver: {library: nlopt, algorithm: LD_SLSQP, xtol_rel: 1e-10}}
)", "<pareto>");
  const auto p = opt::make_problem(root);
  opt::RunSpec spec = opt::parse_run(root, *p);
  spec.output_directory = testing::TempDir() + "/pareto";
  std::ostringstream log;
  const auto j = opt::run_study(*p, spec, log);
  const auto& pts = j["pareto"]["points"];
  ASSERT_EQ(pts.size(), 5u);
  double prev_f1 = HUGE_VAL, prev_f2 = -HUGE_VAL;
  for (const auto& pt : pts) {
    ASSERT_EQ(pt["status"], "converged") << log.str();
    const double f1 = pt["peak_crank_torque"], f2 = pt["max_pressure_angle"];
    // Non-dominated and ordered: as the bound on f2 loosens, f1 falls.
    EXPECT_LT(f1, prev_f1);
    EXPECT_GT(f2, prev_f2);
    EXPECT_LE(f2, pt["epsilon"].get<double>() + 1e-9);
    prev_f1 = f1, prev_f2 = f2;
  }
  // The loose end is the least peak (tools/reference_seed002.json).
  EXPECT_NEAR(pts.back()["peak_crank_torque"].get<double>(), 98310.834286910226, 1e-6 * 98310.8);
  // The tight end is the least pressure angle, found by its own optimisation.
  EXPECT_NEAR(pts.front()["max_pressure_angle"].get<double>(),
              j["pareto"]["optimum_max_pressure_angle"]["max_pressure_angle"].get<double>(), 1e-9);
}

TEST(Pareto, NeedsTwoDifferentObjectives) {
  const auto root = opt::ConfigNode::parse(R"(
problem: conveyor_swing
variables: {l_co1: {min: 0.9 m, max: 2.4 m}}
study: {type: pareto, objectives: [peak_crank_torque]}
)", "<pareto>");
  const auto p = opt::make_problem(root);
  EXPECT_THROW(opt::parse_run(root, *p), opt::ConfigError);
}

}  // namespace

// Nothing non-finite is reported as ok: a metric (or a gradient) that comes
// out NaN or infinite makes the design non_finite, with no metrics.
#include "opt/model_problem.hpp"
#include "test_problems.hpp"

namespace {

TEST(Evaluate, NonFiniteMetricIsAStatusNotAValue) {
  const auto nan = std::numeric_limits<double>::quiet_NaN();
  testing_problems::Analytic p(
      "nan", {{"x", opt::Dimension::dimensionless, 0, 1, 0.5}},
      {{"finite", [](const Eigen::VectorXd& x) { return opt::MetricValue{x[0], Eigen::VectorXd::Ones(1)}; }},
       {"hole", [&](const Eigen::VectorXd& x) {
          return opt::MetricValue{x[0] < 0.25 ? nan : 1.0, Eigen::VectorXd::Constant(1, x[0] > 0.75 ? HUGE_VAL : 0)};
        }}});
  const auto fine = p.evaluate(Eigen::VectorXd::Constant(1, 0.5), opt::MetricSet::all(), true);
  EXPECT_EQ(fine.status, mech::Status::ok);
  EXPECT_TRUE(fine.has("finite") && fine.has("hole"));
  const auto value = p.evaluate(Eigen::VectorXd::Constant(1, 0.1), opt::MetricSet::all(), false);
  EXPECT_EQ(value.status, mech::Status::non_finite);
  EXPECT_FALSE(value.has("finite") || value.has("hole"));
  EXPECT_EQ(value.message, "hole is not finite");
  const auto gradient = p.evaluate(Eigen::VectorXd::Constant(1, 0.9), opt::MetricSet::all(), true);
  EXPECT_EQ(gradient.status, mech::Status::non_finite);
  EXPECT_EQ(gradient.message, "hole has a non-finite gradient");
}

// An evaluation written into one reused for other designs (what the drivers
// and the DOE workers do, to allocate nothing per design) is the fresh
// evaluation's every bit: status, message, which metrics, values, gradients,
// and no gradient left from an earlier design when none was asked for.
void expect_same(const opt::Evaluation& reused, const opt::Evaluation& fresh) {
  EXPECT_EQ(reused.status, fresh.status);
  EXPECT_EQ(reused.message, fresh.message);
  ASSERT_TRUE(reused.names && fresh.names);
  ASSERT_EQ(*reused.names, *fresh.names);
  for (opt::MetricId i = 0; i < static_cast<opt::MetricId>(fresh.names->size()); ++i) {
    ASSERT_EQ(reused.has(i), fresh.has(i)) << (*fresh.names)[i];
    if (!fresh.has(i)) continue;
    EXPECT_EQ(reused[i].value, fresh[i].value) << (*fresh.names)[i];
    ASSERT_EQ(reused[i].gradient.size(), fresh[i].gradient.size()) << (*fresh.names)[i];
    for (Eigen::Index j = 0; j < fresh[i].gradient.size(); ++j)
      EXPECT_EQ(reused[i].gradient[j], fresh[i].gradient[j]) << (*fresh.names)[i];
  }
}

TEST(Evaluate, IntoAReusedEvaluationEqualsAFreshOne) {
  const auto p = opt::make_problem(opt::ConfigNode::parse(
      "problem: recuperative_drive\n"
      "variables: {rod_length: {min: 0.1 m, max: 1.5 m}, phase_shift: {min: 0 deg, max: 180 deg}}\n",
      "<reuse>"));
  struct Step {
    double rod_length, phase_shift;
    bool gradient;
    std::vector<std::string> metrics;
  };
  const std::vector<Step> steps = {
      {0.8, 1.5, true, {}},                            // every metric, with gradients
      {0.1, 1.5, false, {}},                           // the rod cannot reach: cannot_assemble
      {0.7, 1.0, true, {"mean_kinetic_energy"}},       // fewer metrics than before
      {0.7, 1.0, false, {}},                           // values alone after gradients
      {0.9, 2.0, true, {"k1", "crank_rod_ratio"}}};
  opt::Evaluation reused;
  for (const Step& s : steps) {
    const Eigen::Vector2d x(s.rod_length, s.phase_shift);
    const opt::MetricSet wanted = s.metrics.empty() ? opt::MetricSet::all() : p->metric_set(s.metrics);
    p->evaluate(x, wanted, s.gradient, reused);
    expect_same(reused, p->evaluate(x, wanted, s.gradient));
  }
  EXPECT_EQ(reused.status, mech::Status::ok);
  // A problem without its own in-place evaluation, through a non-finite design.
  const auto nan = std::numeric_limits<double>::quiet_NaN();
  testing_problems::Analytic a(
      "hole", {{"x", opt::Dimension::dimensionless, 0, 1, 0.5}},
      {{"hole", [&](const Eigen::VectorXd& x) {
          return opt::MetricValue{x[0] < 0.25 ? nan : x[0], Eigen::VectorXd::Ones(1)};
        }}});
  opt::Evaluation b;
  for (double x : {0.5, 0.1, 0.6}) {
    a.evaluate(Eigen::VectorXd::Constant(1, x), opt::MetricSet::all(), true, b);
    expect_same(b, a.evaluate(Eigen::VectorXd::Constant(1, x), opt::MetricSet::all(), true));
  }
}

// Metrics travel by id: the id a problem puts a value under is the row of
// its metric table, checked when the problem is built, and a name resolves
// to the same id everywhere.
class Misordered : public opt::TabledProblem {
 public:
  enum Metric { a, b };
  explicit Misordered(bool swap)
      : TabledProblem("misordered", {{swap ? b : a, "a", ""}, {swap ? a : b, "b", ""}}, {}) {}
  nlohmann::json settings() const override { return {}; }

 protected:
  opt::Evaluation evaluate_model_at(const Eigen::VectorXd&, const opt::MetricSet& wanted, bool) const override {
    opt::Evaluation e;
    if (wanted.contains(b)) e.set(b, {2.0, {}});
    return e;
  }
};

TEST(Evaluate, MetricIdsFollowTheTable) {
  EXPECT_THROW(Misordered(true), std::logic_error);
  const Misordered p(false);
  EXPECT_EQ(p.metric_id("b"), 1);
  EXPECT_EQ(p.metric_id("c"), -1);
  EXPECT_THROW(p.metric_set({"c"}), std::invalid_argument);
  const auto e = p.evaluate(Eigen::VectorXd(), std::vector<std::string>{"b"}, false);
  EXPECT_TRUE(e.has("b"));
  EXPECT_FALSE(e.has("a"));
  EXPECT_EQ(e.at("b"), 2.0);
  EXPECT_THROW(e.at("a"), std::out_of_range);
  EXPECT_FALSE(p.evaluate(Eigen::VectorXd(), p.metric_set({"a"}), false).has("b")) << "not wanted, not computed";
}

}  // namespace
