// mech::Lanes and its sincos (libmech/include/mech/simd.hpp): the reference
// is the x87 long-double libm (sinl, cosl: 64-bit significands, an
// independent implementation), errors in units in the last place of the
// double result; and the twin drive's lane loops against its scalar loops
// (the same model summed in another order, the design-derivative path).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "mech/simd.hpp"
#include "mech/twin_slider_crank.hpp"

namespace {

using mech::kLanes;
using mech::Lanes;

double ulps(double got, long double exact) {
  const double rounded = static_cast<double>(exact);
  const double ulp = std::nextafter(std::abs(rounded), HUGE_VAL) - std::abs(rounded);
  return static_cast<double>(std::abs(static_cast<long double>(got) - exact) / ulp);
}

TEST(Lanes, SinCosWithinOneUlpOfTheLongDoubleLibm) {
  std::mt19937_64 gen(7);
  for (const double range : {1.0, 10.0, 1e3, 8e5}) {
    std::uniform_real_distribution<double> u(-range, range);
    double worst_sin = 0, worst_cos = 0;
    for (int i = 0; i < 200000; i += kLanes) {
      Lanes x, s, c;
      for (int j = 0; j < kLanes; ++j) x[j] = u(gen);
      mech::sincos(x, s, c);
      for (int j = 0; j < kLanes; ++j) {
        worst_sin = std::max(worst_sin, ulps(s[j], sinl(static_cast<long double>(x[j]))));
        worst_cos = std::max(worst_cos, ulps(c[j], cosl(static_cast<long double>(x[j]))));
      }
    }
    // Measured: at most 0.80 ulp (fdlibm's kernels with the reduction's tail).
    EXPECT_LT(worst_sin, 1.0) << "|x| < " << range;
    EXPECT_LT(worst_cos, 1.0) << "|x| < " << range;
  }
}

TEST(Lanes, SinCosAtSpecialAngles) {
  double s, c;
  mech::sincos(0.0, s, c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  // Every quadrant, both signs: sin is odd and cos even, bit for bit.
  for (double x = 0.1; x < 20; x += 0.37) {
    double s1, c1, s2, c2;
    mech::sincos(x, s1, c1);
    mech::sincos(-x, s2, c2);
    EXPECT_EQ(s1, -s2) << x;
    EXPECT_EQ(c1, c2) << x;
    EXPECT_NEAR(s1 * s1 + c1 * c1, 1.0, 4e-16) << x;
  }
  // Beyond the reduction's range and not finite: the library's values.
  for (const double x : {1e6, -3e7, 1e300}) {
    mech::sincos(x, s, c);
    EXPECT_EQ(s, std::sin(x)) << x;
    EXPECT_EQ(c, std::cos(x)) << x;
  }
  for (const double x : {HUGE_VAL, -HUGE_VAL, std::numeric_limits<double>::quiet_NaN()}) {
    mech::sincos(x, s, c);
    EXPECT_TRUE(std::isnan(s) && std::isnan(c)) << x;
  }
}

TEST(Lanes, ALaneDoesNotDependOnItsNeighbours) {
  // The same angle in every lane, beside others: the same bits.
  const double x = 2.3456789;
  double s0, c0;
  mech::sincos(x, s0, c0);
  for (int j = 0; j < kLanes; ++j) {
    Lanes v = mech::iota(100.0), s, c;
    v[j] = x;
    mech::sincos(v, s, c);
    EXPECT_EQ(s[j], s0);
    EXPECT_EQ(c[j], c0);
  }
}

TEST(Lanes, TwinDriveLaneLoopsAgreeWithTheScalarLoops) {
  // cycle_metrics<double> runs the grid and the Gauss nodes kLanes at a
  // time; cycle_metrics<Dual> (the design-derivative path) one angle at a
  // time with glibc's sin and cos. Same model, other rounding: the values
  // agree to a few ulps of their size. n = 30 is not a multiple of kLanes
  // (a partial last block).
  mech::TwinDrive<double> d{0.2, 0.8, 1.1, 0.03, 100 * M_PI / 30, 1000, 80, 0.9, 3562};
  d.resistance = mech::Resistance::opposes_motion;
  for (const int n : {16, 30, 64}) {
    const auto a = mech::cycle_metrics(d, n);
    const auto b = mech::cycle_metrics(d.cast<mech::Dual>(), n);
    EXPECT_NEAR(a.mean_kinetic_energy / b.mean_kinetic_energy.v, 1, 1e-14) << n;
    EXPECT_NEAR(a.peak_kinetic_energy / b.peak_kinetic_energy.v, 1, 1e-14) << n;
    EXPECT_NEAR(a.mean_total_moment, b.mean_total_moment.v, 1e-14 * a.rms_total_moment) << n;
    EXPECT_NEAR(a.rms_total_moment / b.rms_total_moment.v, 1, 1e-14) << n;
    EXPECT_NEAR(a.peak_total_moment / b.peak_total_moment.v, 1, 1e-14) << n;
    EXPECT_NEAR(mech::mean_kinetic_energy(d, n) / mech::mean_kinetic_energy(d.cast<mech::Dual>(), n).v, 1, 1e-14);
  }
}

}  // namespace
