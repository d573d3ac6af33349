// Every metric of every problem: the autodiff gradient the drivers use
// against central differences, at designs away from ties of the maxima.
#include <gtest/gtest.h>

#include <cmath>

#include "opt/config.hpp"
#include "opt/derivatives.hpp"
#include "problems/registry.hpp"

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
  const auto p = problems::make_problem(opt::ConfigNode::parse(GetParam().yaml, GetParam().name));
  const Eigen::VectorXd x = p->initial_point();
  ASSERT_TRUE(p->evaluate(x, {}, false).ok());
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

}  // namespace
