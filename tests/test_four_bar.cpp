// Four-bar linkage and the conveyor swing mechanism: closed forms, limiting
// cases, finite-difference checks, the two kinetostatic methods, failures.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mech/conveyor_swing.hpp"
#include "mech/four_bar.hpp"

namespace {

using mech::FourBar;
using mech::FourBarPoint;
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;

// Seed 002's variant 1: synthesis at l_CO1 = 1.2 m.
FourBar<double> variant(double l_co1) {
  return mech::synthesize_crank_rocker<double>(1.0, 2.2, l_co1, 1.0, 0.0, 16 * kDeg).linkage;
}

mech::SwingMechanism<double> swing(const FourBar<double>& k) {
  // Seed 002 data: w1 = 12 rad/s, m_n = 200 kg/m, m3 = 3200 kg, J_s3 = m3 d^2
  // (eq. 11, d = 1.2 m), |O1S3| = hypot(1.2, 1.0), M_c = 0.01 * 32000 * 0.3 / 2.
  return {k, 12.0, 200.0, 3200.0, 3200 * 1.44, std::hypot(1.2, 1.0), 48.0};
}

TEST(FourBar, ParallelogramTurnsTheRockerWithTheCrank) {
  // l1 = l3, l2 = l4: the rocker copies the crank (theta3 = phi, w3 = 1,
  // alpha3 = 0) and the coupler translates (w2 = alpha2 = 0) on the open branch.
  const double gx = 0.3, gy = 1.1, l = 0.5;
  for (int branch : {1, -1}) {
    const FourBar<double> k{l, std::hypot(gx, gy), l, gx, gy, branch};
    int copies = 0;
    for (double phi = 0.2; phi < 6.2; phi += 0.5) {
      FourBarPoint<double> p;
      ASSERT_TRUE(mech::four_bar_point(k, phi, p));
      if (std::abs(std::remainder(p.theta3() - phi, 2 * kPi)) > 1e-9) continue;
      ++copies;
      EXPECT_NEAR(p.w3, 1.0, 1e-12);
      EXPECT_NEAR(p.alpha3, 0.0, 1e-12);
      EXPECT_NEAR(p.w2, 0.0, 1e-12);
      EXPECT_NEAR(p.alpha2, 0.0, 1e-12);
    }
    // The open parallelogram lies on one branch on either side of the frame line.
    EXPECT_GT(copies, 0) << "branch " << branch;
  }
}

TEST(FourBar, AnAngleWhereTheLoopCannotCloseGivesNaN) {
  // Crank 1, coupler 0.5, rocker 0.5, crank pivot at (2, 0) from O1: at
  // phi = 0 the crank pin is 3 from O1, beyond l2 + l3 = 1, so no B closes
  // the loop. Everything past the crank is NaN, not what p held before.
  const FourBar<double> k{1.0, 0.5, 0.5, 2.0, 0.0, 1};
  FourBarPoint<double> p;
  p.e2 = p.e3 = p.B = {0.25, 0.5};
  p.w2 = p.w3 = p.alpha2 = p.alpha3 = 0.5;
  ASSERT_FALSE(mech::four_bar_point(k, 0.0, p));
  for (double v : {p.B.x, p.B.y, p.e2.x, p.e2.y, p.e3.x, p.e3.y, p.w2, p.w3, p.alpha2, p.alpha3})
    EXPECT_TRUE(std::isnan(v));
  EXPECT_TRUE(std::isnan(mech::pressure_angle(p)));
  EXPECT_DOUBLE_EQ(p.A.x, 3.0) << "the crank pin is still where the crank puts it";
}

TEST(FourBar, TransferFunctionsAreDerivativesOfPositions) {
  // Central differences, h = 1e-5 rad: truncation ~h^2 |theta'''| ~ 1e-9.
  const auto k = variant(1.4);
  const double h = 1e-5;
  for (double phi = 0.1; phi < 6.3; phi += 0.4) {
    FourBarPoint<double> p, pp, pm;
    ASSERT_TRUE(mech::four_bar_point(k, phi, p));
    mech::four_bar_point(k, phi + h, pp);
    mech::four_bar_point(k, phi - h, pm);
    EXPECT_NEAR(p.w2, (pp.theta2() - pm.theta2()) / (2 * h), 1e-8);
    EXPECT_NEAR(p.w3, (pp.theta3() - pm.theta3()) / (2 * h), 1e-8);
    EXPECT_NEAR(p.alpha2, (pp.w2 - pm.w2) / (2 * h), 1e-8);
    EXPECT_NEAR(p.alpha3, (pp.w3 - pm.w3) / (2 * h), 1e-8);
    // Loop closure: |AB| = l2 and |O1B| = l3.
    EXPECT_NEAR(std::hypot(p.B.x - p.A.x, p.B.y - p.A.y), k.coupler, 1e-13);
    EXPECT_NEAR(std::hypot(p.B.x, p.B.y), k.rocker, 1e-13);
  }
}

TEST(FourBar, GrashofClasses) {
  using G = mech::GrashofClass;
  EXPECT_EQ(mech::grashof(1, 3, 3, 3.5), G::crank_rocker);   // s + l = 4.5 < 6
  EXPECT_EQ(mech::grashof(2, 3, 3.5, 1), G::double_crank);   // frame shortest
  EXPECT_EQ(mech::grashof(3, 2.5, 1, 3.5), G::rocker_crank); // rocker shortest
  EXPECT_EQ(mech::grashof(3, 1, 3.5, 2.5), G::double_rocker);// coupler shortest
  EXPECT_EQ(mech::grashof(2, 3, 3.5, 6), G::non_grashof);    // 8 > 6.5
  EXPECT_EQ(mech::grashof(1, 2, 1, 2), G::change_point);     // 3 = 3
  // Seed 002 eq. (4) agrees with the general form on the paper's variants.
  for (double l_co1 : {1.2, 1.4, 1.6, 1.8}) {
    const auto k = variant(l_co1);
    EXPECT_TRUE(mech::grashof_seed002(k.crank, k.coupler, k.rocker, k.frame()));
    EXPECT_EQ(mech::grashof(k.crank, k.coupler, k.rocker, k.frame()), G::crank_rocker);
  }
}

TEST(FourBar, SynthesisGivesTheRequestedSwingAndTimeRatio) {
  // The dead centres of the synthesised linkage are B' and B'' themselves:
  // the swing is 2 theta = 32 deg to roundoff, and K from a dense search of
  // the rocker's reversals equals eq. (5).
  for (double l_co1 : {1.0, 1.2, 1.5, 1.8, 2.4}) {
    const auto syn = mech::synthesize_crank_rocker<double>(1.0, 2.2, l_co1, 1.0, 0.0, 16 * kDeg);
    ASSERT_TRUE(syn.ok);
    const auto dc = mech::dead_centres(syn.linkage);
    EXPECT_NEAR(std::abs(dc.theta3_folded - dc.theta3_extended), 32 * kDeg, 1e-12);
    EXPECT_NEAR(mech::time_ratio(dc), (kPi + syn.beta) / (kPi - syn.beta), 1e-12);
    // Rocker reversals by a 1e5-point search of w3 sign changes.
    std::vector<double> rev;
    double prev = 0;
    for (int i = 0; i <= 100000; ++i) {
      FourBarPoint<double> p;
      mech::four_bar_point(syn.linkage, 2 * kPi * i / 100000, p);
      if (i > 0 && (p.w3 > 0) != (prev > 0)) rev.push_back(2 * kPi * i / 100000);
      prev = p.w3;
    }
    ASSERT_EQ(rev.size(), 2u);
    const double a = rev[1] - rev[0], b = 2 * kPi - a;
    EXPECT_NEAR(std::max(a, b) / std::min(a, b), mech::time_ratio(dc), 1e-3);  // grid: 6e-5 rad
  }
}

TEST(FourBar, SynthesisFailsWhenExtremesStraddleTheFrameLine) {
  // l_CO1 = 0.6 m (the paper's variant 0): B' and B'' lie on both sides of
  // O1O, so no crank-rocker has them as dead centres. The lengths of Table 1
  // give a linkage that swings 13.04 deg, not 32.
  const auto syn = mech::synthesize_crank_rocker<double>(1.0, 2.2, 0.6, 1.0, 0.0, 16 * kDeg);
  EXPECT_FALSE(syn.ok);
  EXPECT_LT(syn.side_margin, 0.0);
  const auto dc = mech::dead_centres(syn.linkage);
  EXPECT_NEAR(std::abs(dc.theta3_folded - dc.theta3_extended) / kDeg, 13.04, 0.01);
}

TEST(SwingMechanism, PowerBalanceEqualsEnergyDerivative) {
  // Method 1 (power balance with the acceleration formulas) against method 2
  // (angle derivative of the kinetic energy by autodiff, first-order
  // kinematics only): 1e-9 relative.
  for (double l_co1 : {1.2, 1.5, 1.8}) {
    const auto m = swing(variant(l_co1));
    const auto md = m.cast<mech::Dual>();
    for (double phi = 0.05; phi < 6.3; phi += 0.25) {
      FourBarPoint<mech::Dual> p;
      ASSERT_TRUE(mech::four_bar_point(md.linkage, mech::seed(phi), p));
      const double dT = 144.0 * mech::swing_energy_per_w2(md, p).d;
      const double Mi = mech::swing_point(m, phi).inertia;
      EXPECT_NEAR(Mi, dT, 1e-9 * std::max(1.0, std::abs(dT))) << "phi = " << phi;
    }
  }
}

TEST(SwingMechanism, MaximaAreRefinedBeyondTheGrid) {
  // Refined maxima agree with a 1e5-point search to its resolution and are
  // never below it.
  const auto m = swing(variant(1.5));
  const auto r = mech::swing_metrics(m, 48);
  double peak = 0, pressure = 0;
  for (int i = 0; i < 100000; ++i) {
    const auto p = mech::swing_point(m, 2 * kPi * i / 100000);
    peak = std::max(peak, std::abs(p.moment()));
    pressure = std::max(pressure, mech::pressure_angle(p.kinematics));
  }
  EXPECT_GE(r.peak_moment, peak - 1e-6);
  EXPECT_NEAR(r.peak_moment, peak, 1e-6 * peak + 1.0);  // (6e-5)^2 |M''| / 8
  EXPECT_GE(r.max_pressure_angle, pressure - 1e-12);
  EXPECT_NEAR(r.max_pressure_angle, pressure, 1e-8);
}

TEST(SwingMechanism, MeansConvergeDespiteKinks) {
  // |M| and the friction term have kinks; piecewise Gauss-Legendre makes 48
  // points agree with 480 to 1e-10.
  const auto m = swing(variant(1.4));
  const auto a = mech::swing_metrics(m, 48), b = mech::swing_metrics(m, 480);
  EXPECT_NEAR(a.mean_abs_moment, b.mean_abs_moment, 1e-10 * b.mean_abs_moment);
  EXPECT_NEAR(a.rms_moment, b.rms_moment, 1e-10 * b.rms_moment);
}

// Adaptive Simpson's rule of g over [a, b] to an absolute tolerance: the
// independent reference for the cycle means below (no kinks, no poles, no
// Gauss rule known to it; it refines wherever g is hard to integrate).
template <class G>
double adaptive_simpson(const G& g, double a, double b, double tol) {
  struct Step {
    static double run(const G& g, double a, double b, double fa, double fm, double fb, double whole, double tol,
                      int depth) {
      const double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
      const double flm = g(lm), frm = g(rm);
      const double left = (m - a) / 6 * (fa + 4 * flm + fm), right = (b - m) / 6 * (fm + 4 * frm + fb);
      // Converged, or an interval so short that roundoff is all that is left.
      if (depth <= 0 || std::abs(left + right - whole) <= 15 * tol || b - a < 1e-7)
        return left + right + (left + right - whole) / 15;
      return run(g, a, m, fa, flm, fm, left, tol / 2, depth - 1) + run(g, m, b, fm, frm, fb, right, tol / 2, depth - 1);
    }
  };
  const double fa = g(a), fb = g(b), fm = g(0.5 * (a + b));
  return Step::run(g, a, b, fa, fm, fb, (b - a) / 6 * (fa + 4 * fm + fb), tol, 60);
}

TEST(SwingMechanism, MeansNearAToggleAreResolved) {
  // Variant 1.4 with the rocker lengthened until the loop nearly toggles at
  // full stretch: |O1A| = l4 + l1 reaches l2 + l3 at a crank angle
  // acosh(1 + q) = width off the real axis (mech::toggle_poles), and the
  // inertia moment peaks ever more sharply there. The 48-point cycle's
  // means against adaptive Simpson on the scalar model: evenly spread Gauss
  // nodes were 1e-3 to 1e-2 off at these widths (0.26% median at widths
  // 0.03-0.1 over the conveyor DOE's box, and at 1e-3 the grid missed the
  // spike: mean |M| a third of the truth); Gauss nodes counted from the
  // pole's Bernstein ellipse, panels halved toward it where one would need
  // too many, and a grid of four points a width hold them to 1e-11. The peak is checked
  // against a dense scan.
  for (const double width : {0.3, 0.1, 0.01, 0.001}) {
    auto m = swing(variant(1.4));
    auto& k = m.linkage;
    const double l4 = k.frame();
    k.rocker = std::sqrt((l4 + k.crank) * (l4 + k.crank) + 2 * k.crank * l4 * (std::cosh(width) - 1)) - k.coupler;
    ASSERT_EQ(mech::check(m), mech::Status::ok) << width;
    ASSERT_NEAR(mech::toggle_poles(k)[0].width, width, 1e-9 * width);
    const auto r = mech::swing_metrics(m, 48);
    auto moment = [&](double phi) { return mech::swing_point(m, phi).moment(); };
    auto square = [&](double phi) { return moment(phi) * moment(phi); };
    auto magnitude = [&](double phi) { return std::abs(moment(phi)); };
    // To 1e-14 of each integral's size (from a first pass to 1e-6 of the peak's).
    auto integral = [&](const auto& g, double peak) {
      const double rough = adaptive_simpson(g, 0, 2 * kPi, 1e-6 * peak * 2 * kPi);
      return adaptive_simpson(g, 0, 2 * kPi, 1e-14 * std::abs(rough)) / (2 * kPi);
    };
    const double mean_square = integral(square, r.peak_moment * r.peak_moment);
    const double mean_abs = integral(magnitude, r.peak_moment);
    // At width 1e-3 the model itself is the limit: the transmission's sine
    // is about 1e-3 at the spike, and M there carries roundoff of about
    // eps / 1e-6; quadratures of 2^20 Gauss panels of the scalar model
    // scatter by 2e-11 and differ from this one by 2e-10.
    const double tol = width >= 0.01 ? 1e-11 : 1e-9;
    EXPECT_NEAR(r.rms_moment, std::sqrt(mean_square), tol * std::sqrt(mean_square)) << "width " << width;
    EXPECT_NEAR(r.mean_abs_moment, mean_abs, tol * mean_abs) << "width " << width;
    double scanned = 0;  // a scan with a step of width / 100 around the pole
    const double pole = mech::toggle_poles(k)[0].phi;
    for (int i = -2000; i <= 2000; ++i) scanned = std::max(scanned, magnitude(pole + i * width / 100));
    EXPECT_GE(r.peak_moment, scanned * (1 - 1e-12)) << "width " << width;
    EXPECT_LE(r.peak_moment, scanned * (1 + 1e-3)) << "width " << width;
  }
}

TEST(SwingMechanism, FrictionAloneHasClosedFormMean) {
  // Massless links: M = M_c |w3|, whose cycle mean is M_c * 2 * swing / (2 pi).
  auto m = swing(variant(1.6));
  m.rod_mass_per_length = 0;
  m.platform_mass = 0;
  m.platform_inertia = 0;
  const auto r = mech::swing_metrics(m, 48);
  EXPECT_NEAR(r.mean_abs_moment, 48.0 * 2 * 32 * kDeg / (2 * kPi), 1e-12);
}

TEST(SwingMechanism, InfeasibleLinkagesAreStatuses) {
  auto m = swing(variant(1.4));
  m.linkage.crank = 3.0;  // longest link: s + l > p + q
  EXPECT_EQ(mech::check(m), mech::Status::not_grashof);
  m = swing(variant(1.4));
  m.linkage.coupler = 10;  // the loop cannot close anywhere
  EXPECT_EQ(mech::check(m), mech::Status::cannot_assemble);
  // Coupler shortest, 0.5 + 2.417 < 1.5 + 1.6: Grashof, but a double rocker,
  // so the crank meets a toggle before a full turn.
  m.linkage = {1.5, 0.5, 1.6, 1.0, 2.2, 1};
  EXPECT_EQ(mech::grashof(1.5, 0.5, 1.6, m.linkage.frame()), mech::GrashofClass::double_rocker);
  EXPECT_EQ(mech::check(m), mech::Status::toggle_in_cycle);
  m.linkage.crank = -0.1;
  EXPECT_EQ(mech::check(m), mech::Status::invalid_parameter);
}

}  // namespace
