// mech::Dual, the value-and-slope number of the angle derivatives: each
// operation's slope against the closed-form derivative.
#include <gtest/gtest.h>

#include <cmath>

#include "mech/autodiff.hpp"

namespace {

using mech::Dual;

// f(x) = (3 - x) * sqrt(x) / (1 + x^2) + sin(x) cos(2 x) - asin(x / 4) + acos(x / 5) + atan2(x, 2 - x) + |x - 3|
Dual f(const Dual& x) {
  return (3.0 - x) * sqrt(x) / (1.0 + x * x) + sin(x) * cos(2.0 * x) - asin(x / 4.0) + acos(x / 5.0) +
         atan2(x, 2.0 - x) + abs(x - 3.0);
}

// Its derivative, by hand.
double df(double x) {
  const double u = (3 - x) * std::sqrt(x), v = 1 + x * x;
  const double du = -std::sqrt(x) + (3 - x) / (2 * std::sqrt(x)), dv = 2 * x;
  return (du * v - u * dv) / (v * v) + std::cos(x) * std::cos(2 * x) - 2 * std::sin(x) * std::sin(2 * x) -
         0.25 / std::sqrt(1 - x * x / 16) - 0.2 / std::sqrt(1 - x * x / 25) +
         2.0 / ((2 - x) * (2 - x) + x * x) + (x < 3 ? -1.0 : 1.0);
}

TEST(Dual, SlopesMatchClosedFormDerivatives) {
  for (double x : {0.3, 1.1, 2.5, 3.7}) {
    const Dual y = f(mech::seed(x));
    EXPECT_NEAR(y.d, df(x), 1e-14 * (1 + std::abs(df(x)))) << "x = " << x;
    EXPECT_EQ(y.v, f(Dual(x)).v);  // the value does not depend on the slope
  }
}

TEST(Dual, CompoundOperatorsAgreeWithBinaryOnes) {
  const Dual a{1.7, 0.3}, b{-0.4, 2.1};
  Dual c = a;
  c *= b;
  c /= a + b;
  c -= 2.0 * b;
  c += a / 3.0;
  const Dual d = a * b / (a + b) - 2.0 * b + a / 3.0;
  EXPECT_DOUBLE_EQ(c.v, d.v);
  EXPECT_DOUBLE_EQ(c.d, d.d);
  // d/dt of (k / a) with a' = 0.3: -k a' / a^2.
  EXPECT_DOUBLE_EQ((5.0 / a).d, -5.0 * 0.3 / (1.7 * 1.7));
}

}  // namespace
