// The cycle helpers of libmech/include/mech/cycle.hpp: Brent's root finder
// and the sign-change scan (roots.hpp) and the batched maxima search
// (cycle_maxima.hpp), against closed forms; and the twin drive's peaks
// searched together in lanes against the same search evaluated one angle
// at a time with scalar (Dual) evaluations.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "mech/cycle.hpp"
#include "mech/twin_slider_crank.hpp"

namespace {

using mech::kTwoPi;

TEST(Cycle, RoundHalfAwayIsStdRound) {
  // The maxima search's kink copies use it instead of libm's call: the same
  // value as std::round everywhere (halves, the doubles next to them,
  // negative zero, huge values, infinities), and NaN for NaN.
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> xs = {0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 0.49999999999999994, -0.49999999999999994,
                            std::nextafter(0.5, 1.0), 4503599627370495.5, -4503599627370495.5, 1e300, -1e300, inf,
                            -inf, std::numeric_limits<double>::denorm_min()};
  std::mt19937_64 gen(11);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int i = 0; i < 100000; ++i) xs.push_back(u(gen));
  for (double x : xs) {
    const double want = std::round(x), got = mech::round_half_away(x);
    EXPECT_EQ(got, want) << x;
    EXPECT_EQ(std::signbit(got), std::signbit(want)) << x;
  }
  EXPECT_TRUE(std::isnan(mech::round_half_away(std::numeric_limits<double>::quiet_NaN())));
}

TEST(Cycle, AHugePhaseShiftKeepsTheDeadCentresOnTheCircle) {
  // A phase shift of -1e308 rad (a fuzzed DOE factor's bound) put slider
  // 2's dead centres far outside [0, 2 pi): the maxima search indexed its
  // grid with them and crashed. They are wrapped exactly now, and the cycle
  // metrics come out finite (this test also runs under ASan and UBSan).
  for (const double shift : {-1e308, 1e300, -4.5e15, 1e17}) {
    mech::TwinDrive<double> d{0.2, 0.8, shift, 0.05, 10.0, 1000, 80, 0.9, 3562};
    d.resistance = mech::Resistance::opposes_motion;
    ASSERT_EQ(mech::check(d), mech::Status::ok);
    const int n = mech::auto_cycle_points(d);
    for (double c : mech::dead_centres(d, n)) {
      EXPECT_GE(c, 0.0) << shift;
      EXPECT_LT(c, kTwoPi) << shift;
    }
    const auto m = mech::cycle_metrics(d, n);
    EXPECT_TRUE(std::isfinite(m.peak_total_moment) && std::isfinite(m.rms_total_moment) && std::isfinite(m.k1))
        << shift;
  }
  EXPECT_EQ(mech::wrap_angle(1.0), 1.0);
  EXPECT_EQ(mech::wrap_angle(-1.0), -1.0 + kTwoPi);
  EXPECT_TRUE(std::isnan(mech::wrap_angle(std::numeric_limits<double>::quiet_NaN())));
  EXPECT_TRUE(std::isnan(mech::wrap_angle(std::numeric_limits<double>::infinity())));
}

TEST(Cycle, BrentFindsPiOverTwo) {
  // cos on [1, 2] vanishes at pi/2: the root to within a couple of ulps.
  int evaluations = 0;
  const double root = mech::brent_root([&](double x) { return ++evaluations, std::cos(x); }, 1.0, 2.0,
                                       std::cos(1.0), std::cos(2.0));
  EXPECT_NEAR(root, M_PI / 2, 4.5e-16);
  EXPECT_LT(evaluations, 12);
}

// The lane search on cos over [1, 2]: pi / 2 to a couple of ulps in three
// steps of two points (Brent's search above takes up to eleven
// evaluations, one a step); at a bracket's end in a few; on a jump, where
// interpolation is no help, it ends on the jump like bisection, to within
// 2.5 rel_tol |x|.
TEST(Cycle, LaneRootSearchConvergesInTwoStepsAndEndsOnAJump) {
  auto run = [](auto&& g, double a, double b, double x3, int& steps) {
    mech::LaneRootSearch s(a, b, g(a), g(b), x3, std::isnan(x3) ? NAN : g(x3));
    for (steps = 0; !s.done(); ++steps) {
      std::vector<double> gs;
      for (double x : s.xs()) gs.push_back(g(x));
      s.feed(gs);
    }
    return s.root();
  };
  int steps = 0;
  auto cosine = [](double x) { return std::cos(x); };
  EXPECT_NEAR(run(cosine, 1.0, 2.0, 2.5, steps), M_PI / 2, 4.5e-16);
  EXPECT_LE(steps, 3);
  EXPECT_NEAR(run(cosine, 1.0, 2.0, NAN, steps), M_PI / 2, 4.5e-16);  // from the bracket alone
  EXPECT_LE(steps, 3);
  // A root at the bracket's end (|g| there at roundoff, as where a grid
  // point sits on a maximum): found in a few steps, not by thirds.
  auto at_end = [](double x) { return 1e-17 + 0.18 * (M_PI - x); };
  EXPECT_NEAR(run(at_end, M_PI, M_PI + 0.5, NAN, steps), M_PI, 2.5 * 4.4e-16 * M_PI);
  EXPECT_LE(steps, 3);
  auto jump = [](double x) { return x < 0.3 ? 1.0 : -1.0; };
  EXPECT_NEAR(run(jump, 0.0, 1.0, NAN, steps), 0.3, 2.5 * 4.4e-16 * 0.3);
  EXPECT_LT(steps, 60);
}

TEST(Cycle, SignChangesSplitIntoEqualParts) {
  // df = -(x - 0.4)(x - 0.55)(x - 0.7): + to - at 0.4 and 0.7 (maxima of
  // f), - to + at 0.55. Eight equal parts of [0, 1] put each in a part of
  // its own, so both maxima are found. (Taking each part as a fraction of
  // what was left gave the parts [0.344, 0.590] and [0.590, 0.795]: the
  // first holds 0.4 and 0.55, df > 0 at both its ends, and 0.4 was missed.)
  auto df = [](double x) { return -(x - 0.4) * (x - 0.55) * (x - 0.7); };
  std::vector<double> roots;
  mech::sign_changes(df, 0.0, 1.0, df(0.0), df(1.0), 8, roots);
  ASSERT_EQ(roots.size(), 2u);
  EXPECT_NEAR(roots[0], 0.4, 1e-15);
  EXPECT_NEAR(roots[1], 0.7, 1e-15);
}

// f = cos(phi - a) + b cos(2 (phi - a)): for |b| < 1/4 its only maximum is
// at phi = a (f' = -sin(u) (1 + 4 b cos u), u = phi - a).
struct Bump {
  double a, b;
  double f(double phi) const { return std::cos(phi - a) + b * std::cos(2 * (phi - a)); }
  double df(double phi) const { return -std::sin(phi - a) - 2 * b * std::sin(2 * (phi - a)); }
  std::vector<double> grid(int n) const {
    std::vector<double> v(n);
    for (int k = 0; k < n; ++k) v[k] = f(kTwoPi * k / n);
    return v;
  }
};

TEST(Cycle, MaximaSearchedTogetherOrAloneAgree) {
  const Bump bumps[3] = {{1.234, 0.1}, {5.9, -0.2}, {0.01, 0.05}};
  const int n = 24;
  std::vector<double> grids[3];
  std::vector<mech::CycleMaxSearch> together;
  for (int i = 0; i < 3; ++i) {
    grids[i] = bumps[i].grid(n);
    together.push_back({.v = grids[i], .maxima = {}});
  }
  int batches = 0;
  mech::find_cycle_maxima(std::span(together), [&](std::span<mech::AngleQuery> qs) {
    ++batches;
    for (auto& q : qs) q.out = q.slope ? bumps[q.fn].df(q.phi) : bumps[q.fn].f(q.phi);
  });
  for (int i = 0; i < 3; ++i) {
    const Bump& b = bumps[i];
    // The closed form, and the same search alone (one angle at a time).
    EXPECT_NEAR(together[i].phi, b.a, 2e-15) << i;
    const double alone = mech::global_max_angle(grids[i], [&](double p) { return b.f(p); },
                                                [&](double p) { return b.df(p); });
    EXPECT_EQ(together[i].phi, alone) << i;
    ASSERT_EQ(together[i].maxima.size(), 1u);
  }
  EXPECT_LT(batches, 12);  // the three root searches ran side by side
}

// Given the angles where f stands still (Bump: u = 0, its maximum, and u =
// pi, its minimum), a search asks f at those whose grid cell reaches the
// grid's top, and no slope: the maximum at a, the minimum's far below.
TEST(Cycle, KnownStationaryAnglesNeedNoRootSearch) {
  const Bump bumps[2] = {{1.234, 0.1}, {6.2, -0.2}};
  for (const Bump& b : bumps) {
    const std::vector<double> grid = b.grid(24);
    const double known[2] = {mech::wrap_angle(b.a), mech::wrap_angle(b.a + std::numbers::pi)};
    mech::CycleMaxSearch s{.v = grid, .known = known, .maxima = {}};
    int slopes = 0, values = 0;
    mech::find_cycle_maxima(std::span(&s, 1), [&](std::span<mech::AngleQuery> qs) {
      for (auto& q : qs) {
        ++(q.slope ? slopes : values);
        q.out = q.slope ? b.df(q.phi) : b.f(q.phi);
      }
    });
    EXPECT_EQ(slopes, 0);
    EXPECT_EQ(values, 1);
    EXPECT_EQ(s.phi, known[0]);
    EXPECT_EQ(s.value, b.f(known[0]));
    ASSERT_EQ(s.maxima.size(), 1u);
  }
}

TEST(Cycle, TwinDrivePeaksInLanesEqualTheScalarSearch) {
  // cycle_metrics searches the peaks of T and |M| together, four angles an
  // evaluation (|M|'s slope from third-order transfer functions, in lanes).
  // The same search one angle at a time with scalar evaluations must give
  // the same angles, bit for bit, over random designs of both resistance
  // models.
  std::mt19937_64 gen(11);
  std::uniform_real_distribution<double> u(0, 1);
  int checked = 0;
  for (int i = 0; i < 3000; ++i) {
    mech::TwinDrive<double> d{0.1 + 0.2 * u(gen), 0.3 + 1.3 * u(gen), M_PI * u(gen), -0.1 + 0.2 * u(gen),
                              100 * M_PI / 30, 1000, 80, 0.9, 3562};
    d.resistance = i % 2 ? mech::Resistance::opposes_motion : mech::Resistance::signed_velocity;
    if (mech::check(d) != mech::Status::ok) continue;
    const int n = mech::auto_cycle_points(d);
    const auto m = mech::cycle_metrics(d, n);
    const double cd = std::cos(d.phase_shift), sd = std::sin(d.phase_shift);
    auto at = [&](double c, double s) { return mech::drive_point(d, c, s, cd, sd); };
    auto at_angle = [&](double phi) {
      double c, s;
      mech::sincos(phi, s, c);
      return at(c, s);
    };
    std::vector<double> T(n), dT(n), M(n);  // the grid, from the same cosines
    mech::for_each_grid_block(n, [&](int k, int lanes, const mech::Lanes& c, const mech::Lanes& s) {
      for (int j = 0; j < lanes; ++j) {
        const auto p = at(c[j], s[j]);
        T[k + j] = p.kinetic_energy, dT[k + j] = p.inertia_moment, M[k + j] = std::abs(p.total_moment());
      }
    });
    auto dabsM = [&](double phi) {
      double c, s;
      mech::sincos(phi, s, c);
      const auto p = mech::drive_point_slope(d, c, s, cd, sd);
      return mech::flip_where_negative(p.moment_slope, p.total_moment());
    };
    const std::vector<double> kinks =
        d.resistance == mech::Resistance::opposes_motion ? mech::dead_centres(d, n) : std::vector<double>{};
    EXPECT_EQ(m.phi_peak_energy, mech::global_max_angle(
                                     T, [&](double p) { return at_angle(p).kinetic_energy; },
                                     [&](double p) { return at_angle(p).inertia_moment; }, {}, dT))
        << i;
    EXPECT_EQ(m.phi_peak_moment,
              mech::global_max_angle(M, [&](double p) { return std::abs(at_angle(p).total_moment()); }, dabsM, kinks))
        << i;
    ++checked;
  }
  EXPECT_GT(checked, 1500);
}

TEST(Cycle, MeansResolveANearPoleFromItsBernsteinEllipse) {
  // f = w / ((phi - c)^2 + w^2) has poles at c +- i w; its integral over
  // [0, 2 pi] is atan((2 pi - c) / w) + atan(c / w). With the pole given,
  // each Gauss panel takes its nodes from the ellipse through it and the
  // mean is right to the integrand's own roundoff down to w = 1e-8; without it, 96 nodes a
  // revolution are far off once w is small. A pole on the axis (w = 0, the
  // integral diverges) must still end, with a finite answer.
  const double c = 2.0;
  auto mean_of = [&](double w, bool give_pole) {
    const mech::NearPole pole[1] = {{c, w}};
    auto f = [&](double phi, double, double) { return w / ((phi - c) * (phi - c) + w * w); };
    return mech::piecewise_means<double>(f, {0.0}, 96, give_pole ? std::span(pole) : std::span<const mech::NearPole>())
        .mean;
  };
  for (const double w : {1.0, 1e-2, 1e-4, 1e-8}) {
    const double exact = (std::atan((kTwoPi - c) / w) + std::atan(c / w)) / kTwoPi;
    // The integrand itself is ill-conditioned near the pole: a node's
    // phi - c carries roundoff of ulp(c), so f there is off by about
    // eps c / w of itself, which bounds any quadrature.
    const double tol = std::max(1e-14, 10 * std::numeric_limits<double>::epsilon() * c / w);
    EXPECT_NEAR(mean_of(w, true), exact, tol * exact) << "w " << w;
    if (w <= 1e-2) {
      EXPECT_GT(std::abs(mean_of(w, false) - exact), 1e-3 * exact) << "w " << w;
    }
  }
  EXPECT_TRUE(std::isfinite(mean_of(0.0, true)));
}

}  // namespace
