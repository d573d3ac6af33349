// The slider_crank problem against closed forms. With offset e the slider's
// extreme positions are where crank and rod are collinear, so the stroke is
// sqrt((l + r)^2 - e^2) - sqrt((l - r)^2 - e^2); the rod's largest angle to
// the slider axis is asin((r + |e|) / l); without offset and with r/l < 1/4
// the peak acceleration is at the outer dead centre, r w^2 (1 + r/l).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "opt/derivatives.hpp"
#include "opt/registry.hpp"

namespace {

std::unique_ptr<opt::Problem> slider_crank(const std::string& model) {
  return opt::make_problem(opt::ConfigNode::parse(
      "problem: slider_crank\nmodel: {" + model + "}\n"
      "variables: {crank_radius: {min: 0.1 m, max: 0.4 m}, rod_length: {min: 0.5 m, max: 2 m},\n"
      "            offset: {min: -0.2 m, max: 0.2 m}}\n",
      "<slider_crank>"));
}

constexpr double kTol = 1e-12;  // relative: extrema refined to machine precision

TEST(SliderCrankProblem, StrokeAndPressureAngleWithOffset) {
  const double r = 0.25, l = 0.9, e = 0.07;
  const auto p = slider_crank("crank_radius: 0.25 m, rod_length: 0.9 m, offset: 0.07 m");
  const auto m = p->evaluate(p->initial_point(), opt::MetricSet::all(), false);
  ASSERT_TRUE(m.ok());
  const double stroke = std::sqrt((l + r) * (l + r) - e * e) - std::sqrt((l - r) * (l - r) - e * e);
  EXPECT_NEAR(m.at("stroke") / stroke, 1, kTol);
  EXPECT_NEAR(m.at("max_pressure_angle") / std::asin((r + e) / l), 1, kTol);
}

TEST(SliderCrankProblem, PeakAccelerationWithoutOffset) {
  const double r = 0.2, l = 1.0, w = 10;
  const auto p = slider_crank("crank_radius: 0.2 m, rod_length: 1 m, crank_speed: 10 rad/s");
  const auto m = p->evaluate(p->initial_point(), opt::MetricSet::all(), false);
  ASSERT_TRUE(m.ok());
  EXPECT_NEAR(m.at("stroke") / (2 * r), 1, kTol);
  EXPECT_NEAR(m.at("peak_slider_acceleration") / (r * w * w * (1 + r / l)), 1, kTol);
}

TEST(SliderCrankProblem, GradientsAndTheDeadPoint) {
  const auto p = slider_crank("crank_radius: 0.25 m, rod_length: 0.9 m, offset: 0.07 m");
  for (const auto& c : opt::check_derivatives(*p, p->initial_point()))
    EXPECT_TRUE(c.ok) << c.metric << " d/d" << c.variable << ": " << c.autodiff << " vs " << c.central;
  // r + |e| >= l: the rod cannot reach the slider axis at every crank angle.
  const auto q = slider_crank("crank_radius: 0.3 m, rod_length: 0.5 m, offset: 0.2 m");
  EXPECT_EQ(q->evaluate(q->initial_point(false), opt::MetricSet::all(), false).status, mech::Status::cannot_assemble);
}

}  // namespace
