// Every metric of every problem: the autodiff gradient the drivers use
// against central differences, at designs away from ties of the maxima.
#include <gtest/gtest.h>

#include <cmath>

#include "opt/config.hpp"
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
  const auto e = p->evaluate(x, {}, true);
  ASSERT_TRUE(e.ok()) << e.status;
  ASSERT_GE(e.metrics.size(), p->metric_names().size() - 1);  // synthesis_margin: synthesis only
  for (int i = 0; i < x.size(); ++i) {
    // h = 1e-6 of the variable's scale: truncation ~1e-12 |f'''|, roundoff
    // ~eps |f| / h ~ 1e-10 |f|; maxima add the refined angle's error
    // (~1e-15): 1e-7 relative to max(1, |f|) leaves a margin.
    const double h = 1e-6 * std::max(1.0, std::abs(x[i]));
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    const auto ep = p->evaluate(xp, {}, false), em = p->evaluate(xm, {}, false);
    for (const auto& [name, v] : e.metrics) {
      const double fd = (ep.at(name) - em.at(name)) / (2 * h);
      EXPECT_NEAR(v.gradient[i], fd, 1e-7 * std::max(1.0, std::abs(v.value)))
          << name << " d/d" << p->variables()[i].name;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllProblems, Gradients, ::testing::ValuesIn(kCases),
                         [](const auto& info) { return info.param.name; });

}  // namespace
