// Slider-crank kinematics against closed forms and against central
// differences of the position (an independent check of every transfer function).
#include <gtest/gtest.h>

#include <cmath>

#include "mech/slider_crank.hpp"

namespace {

using mech::Kinematics;
using mech::SliderCrank;

// Central differences with step 1e-5 rad have truncation error ~h^2*x''' ~ 1e-10
// and roundoff ~eps/h ~ 1e-11 (lengths ~1 m): 1e-8 leaves a margin of 100.
constexpr double kFdTol = 1e-8;
constexpr double kH = 1e-5;
constexpr double kPi = 3.14159265358979323846;

double slider_x(const SliderCrank<double>& m, double psi) {
  return mech::slider_crank_point(m, psi).x;
}

// Rod angle from positions alone: direction from crank pin to slider.
double rod_angle(const SliderCrank<double>& m, double psi) {
  const double x = slider_x(m, psi);
  return std::atan2(-m.e - m.r * std::sin(psi), x - m.r * std::cos(psi));
}

TEST(SliderCrank, StrokeIsTwiceTheCrankWithoutOffset) {
  for (double l : {0.5, 0.8, 1.5}) {
    const SliderCrank<double> m{0.2, l, 0.0, 1};
    EXPECT_NEAR(slider_x(m, 0.0) - slider_x(m, kPi), 0.4, 1e-15);  // exact dead centres
    EXPECT_NEAR(slider_x(m, 0.0), l + 0.2, 1e-15);
  }
}

TEST(SliderCrank, OffsetStrokeMatchesClosedForm) {
  // Dead centres of an offset slider-crank: rod and crank collinear, so the
  // slider sits at sqrt((l+r)^2 - e^2) and sqrt((l-r)^2 - e^2) from the axis.
  const double r = 0.2, l = 0.8, e = 0.1;
  const SliderCrank<double> m{r, l, e, 1};
  double xmax = -1e9, xmin = 1e9;
  for (int k = 0; k < 20000; ++k) {
    const double psi = 2 * kPi * k / 20000;
    xmax = std::max(xmax, slider_x(m, psi));
    xmin = std::min(xmin, slider_x(m, psi));
  }
  // A 20000-point grid finds extrema to (2pi/20000)^2 * x''/2 ~ 1e-8 m.
  EXPECT_NEAR(xmax, std::sqrt((l + r) * (l + r) - e * e), 1e-8);
  EXPECT_NEAR(xmin, std::sqrt((l - r) * (l - r) - e * e), 1e-8);
}

TEST(SliderCrank, TransferFunctionsAreDerivativesOfPosition) {
  for (Kinematics kin : {Kinematics::exact, Kinematics::binomial})
    for (int sigma : {1, -1})
      for (double e : {0.0, 0.07, -0.05}) {
        const SliderCrank<double> m{0.2, 0.7, e, sigma, kin};
        for (double psi = 0.1; psi < 6.3; psi += 0.37) {
          const auto p = mech::slider_crank_point(m, psi);
          const auto pp = mech::slider_crank_point(m, psi + kH);
          const auto pm = mech::slider_crank_point(m, psi - kH);
          EXPECT_NEAR(p.dx, (pp.x - pm.x) / (2 * kH), kFdTol);
          EXPECT_NEAR(p.ddx, (pp.dx - pm.dx) / (2 * kH), kFdTol);
          EXPECT_NEAR(p.ddxs, (pp.dxs - pm.dxs) / (2 * kH), kFdTol);
          EXPECT_NEAR(p.ddys, (pp.dys - pm.dys) / (2 * kH), kFdTol);
          EXPECT_NEAR(p.ddbeta, (pp.dbeta - pm.dbeta) / (2 * kH), kFdTol);
          if (kin == Kinematics::exact) {  // binomial angles are approximate by design
            EXPECT_NEAR(p.dbeta, (rod_angle(m, psi + kH) - rod_angle(m, psi - kH)) / (2 * kH),
                        kFdTol);
          }
        }
      }
}

TEST(SliderCrank, PaperEquationsOneAndTwo) {
  // Seed 000 eq. (1) (normal) and eq. (2) (mirrored) at zero offset.
  const double r = 0.2, l = 0.6, lam = r / l;
  for (double psi = 0.0; psi < 6.3; psi += 0.5) {
    const double s = std::sin(psi), c = std::cos(psi), q = std::sqrt(1 - lam * lam * s * s);
    EXPECT_NEAR(mech::slider_crank_point(SliderCrank<double>{r, l, 0, 1}, psi).dx,
                -r * s * (1 + lam * c / q), 1e-15);
    EXPECT_NEAR(mech::slider_crank_point(SliderCrank<double>{r, l, 0, -1}, psi).dx,
                -r * s * (1 - lam * c / q), 1e-15);
    // Rod centre y velocity, eq. (3)-(4): r/2 cos(psi).
    EXPECT_NEAR(mech::slider_crank_point(SliderCrank<double>{r, l, 0, 1}, psi).dys, r / 2 * c,
                1e-16);
  }
}

TEST(SliderCrank, BinomialMatchesPaperEquation38AndErrorIsThirdOrder) {
  const double r = 0.2;
  for (double l : {0.4, 0.8, 1.6}) {
    const double lam = r / l;
    double worst = 0;
    for (double psi = 0.0; psi < 6.3; psi += 0.05) {
      const auto b = mech::slider_crank_point(SliderCrank<double>{r, l, 0, 1, Kinematics::binomial}, psi);
      // Seed 001 eq. (38) and (39).
      EXPECT_NEAR(b.dx, -r * (std::sin(psi) + lam / 2 * std::sin(2 * psi)), 1e-15);
      EXPECT_NEAR(b.ddx, -r * (std::cos(psi) + lam * std::cos(2 * psi)), 1e-15);
      const auto x = mech::slider_crank_point(SliderCrank<double>{r, l, 0, 1}, psi);
      worst = std::max(worst, std::abs(b.dx - x.dx));
    }
    // The first neglected term of the series (eq. 34) gives dx errors of order r*lam^3.
    EXPECT_LT(worst, r * lam * lam * lam);
    EXPECT_GT(worst, 0.05 * r * lam * lam * lam);
  }
}

TEST(SliderCrank, AssemblyNeedsRodLongerThanCrankPlusOffset) {
  EXPECT_TRUE(mech::assembles_over_cycle(SliderCrank<double>{0.2, 0.8, 0.1, 1}));
  EXPECT_FALSE(mech::assembles_over_cycle(SliderCrank<double>{0.2, 0.3, 0.1, 1}));
  EXPECT_FALSE(mech::assembles_over_cycle(SliderCrank<double>{0.2, 0.2, 0.0, 1}));
  EXPECT_FALSE(mech::assembles_over_cycle(SliderCrank<double>{-0.2, 0.8, 0.0, 1}));
}

}  // namespace
