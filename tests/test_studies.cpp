// Studies: the epsilon-constraint Pareto front on a case whose front is
// known — along the conveyor's l_CO1 family the peak moment falls and the
// pressure angle rises between the two single-objective optima, so the front
// is that segment of the family.
#include <gtest/gtest.h>

#include <sstream>

#include "opt/study.hpp"
#include "problems/registry.hpp"

namespace {

TEST(Pareto, ConveyorFrontIsTheFamilyBetweenTheTwoOptima) {
  const auto root = opt::ConfigNode::parse(R"(
problem: conveyor_swing
variables: {l_co1: {min: 0.9 m, max: 2.4 m}}
study: {type: pareto, objectives: [peak_moment, max_pressure_angle], points: 5,
        driver: {library: nlopt, algorithm: LD_SLSQP, xtol_rel: 1e-10}}
)", "<pareto>");
  const auto p = problems::make_problem(root);
  opt::RunSpec spec = opt::parse_run(root, *p);
  spec.output_directory = testing::TempDir() + "/pareto";
  std::ostringstream log;
  const auto j = opt::run_study(*p, spec, log);
  const auto& pts = j["pareto"]["points"];
  ASSERT_EQ(pts.size(), 5u);
  double prev_f1 = HUGE_VAL, prev_f2 = -HUGE_VAL;
  for (const auto& pt : pts) {
    ASSERT_EQ(pt["status"], "converged") << log.str();
    const double f1 = pt["peak_moment"], f2 = pt["max_pressure_angle"];
    // Non-dominated and ordered: as the bound on f2 loosens, f1 falls.
    EXPECT_LT(f1, prev_f1);
    EXPECT_GT(f2, prev_f2);
    EXPECT_LE(f2, pt["epsilon"].get<double>() + 1e-9);
    prev_f1 = f1, prev_f2 = f2;
  }
  // The loose end is the least peak (tools/reference_seed002.json).
  EXPECT_NEAR(pts.back()["peak_moment"].get<double>(), 98310.834286910226, 1e-6 * 98310.8);
  // The tight end is the least pressure angle, found by its own optimisation.
  EXPECT_NEAR(pts.front()["max_pressure_angle"].get<double>(),
              j["pareto"]["optimum_max_pressure_angle"]["max_pressure_angle"].get<double>(), 1e-9);
}

TEST(Pareto, NeedsTwoDifferentObjectives) {
  const auto root = opt::ConfigNode::parse(R"(
problem: conveyor_swing
variables: {l_co1: {min: 0.9 m, max: 2.4 m}}
study: {type: pareto, objectives: [peak_moment]}
)", "<pareto>");
  const auto p = problems::make_problem(root);
  EXPECT_THROW(opt::parse_run(root, *p), opt::ConfigError);
}

}  // namespace

// Nothing non-finite is reported as ok: a metric (or a gradient) that comes
// out NaN or infinite makes the design non_finite, with no metrics.
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
  const auto fine = p.evaluate(Eigen::VectorXd::Constant(1, 0.5), {}, true);
  EXPECT_EQ(fine.status, "ok");
  EXPECT_EQ(fine.metrics.size(), 2u);
  const auto value = p.evaluate(Eigen::VectorXd::Constant(1, 0.1), {}, false);
  EXPECT_EQ(value.status, "non_finite");
  EXPECT_TRUE(value.metrics.empty());
  EXPECT_EQ(value.message, "hole is not finite");
  const auto gradient = p.evaluate(Eigen::VectorXd::Constant(1, 0.9), {}, true);
  EXPECT_EQ(gradient.status, "non_finite");
  EXPECT_EQ(gradient.message, "hole has a non-finite gradient");
}

}  // namespace
