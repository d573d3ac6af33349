// The switches of an opposing load taken in closed form (kinks.hpp's
// output_stops: a crank-driven slider's dead centres, a crank-rocker's
// limits), against the zeros of the output's rate found another way: the
// chain solved on a 720-point grid and every sign change of the rate
// bisected to the last bit. Offset and tilted lines, both branches, both
// senses, a phase, a driving point off the crank's axis, and the rocker's
// group written either way round.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "mech/linkage/kinematics.hpp"
#include "problems/linkage/kinks.hpp"

namespace {

using mech::linkage::Chain;
using mech::linkage::Load;
using mech::linkage::State;

constexpr double kTwoPi = 2 * std::numbers::pi;

// The zeros in [0, 2 pi) of rate(state), by bisection from a 720-point grid.
template <class Rate>
std::vector<double> bisected_zeros(const Chain& c, Rate&& rate) {
  State<double> st;
  st.resize(c);
  auto at = [&](double phi) {
    EXPECT_TRUE(mech::linkage::solve(c, c.defaults().data(), phi, st)) << phi;
    return rate(st);
  };
  const int n = 720;
  std::vector<double> out;
  for (int k = 0; k < n; ++k) {
    double a = kTwoPi * k / n, b = kTwoPi * (k + 1) / n, ga = at(a);
    if ((ga < 0) == (at(b) < 0)) continue;
    while (true) {
      const double m = 0.5 * (a + b);
      if (m <= a || m >= b) break;
      const double gm = at(m);
      ((gm < 0) == (ga < 0) ? a : b) = m;
      if ((gm < 0) == (ga < 0)) ga = gm;
    }
    out.push_back(std::fmod(a, kTwoPi));
  }
  return out;
}

// An opposing load of kind k on link (against `other`'s rotation where set).
Load opposing(Load::Kind k, int link, int other = mech::linkage::kNone) {
  Load l;
  l.kind = k, l.link = link, l.other = other, l.opposing = true;
  return l;
}

// output_stops' angles, sorted; false where it gives none.
bool closed_stops(const Chain& c, const Load& l, std::vector<double>& out) {
  double at[4];
  int m = 0;
  if (!problems::linkage::output_stops(c, c.defaults().data(), l, at, m)) return false;
  out.assign(at, at + m);
  std::sort(out.begin(), out.end());
  return true;
}

void expect_same_angles(const std::vector<double>& got, const std::vector<double>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < got.size(); ++i)
    EXPECT_NEAR(std::remainder(got[i] - want[i], kTwoPi), 0.0, 4e-15) << "zero " << i;
}

// A slider-crank: crank r about O at (0.03, -0.02), the rod l driven from
// the crank's point (u, w) in its frame (the joint A where w = 0 and u =
// r), the ram on a line through T at `angle`, offset `offset` to its left.
Chain slider_crank(double r, double u, double w, double l, double angle, double offset, int branch, int sense,
                   double phase, int& ram) {
  Chain c;
  const int O = c.ground("O", c.value("O.x", 0.03), c.value("O.y", -0.02));
  const int T = c.ground("T", c.value("T.x", 0.1), c.value("T.y", 0.04));
  const int crank = c.link("crank");
  c.set_length(crank, c.value("crank.length", r));
  const int rod = c.link("rod");
  c.set_length(rod, c.value("rod.length", l));
  ram = c.link("ram");
  c.set_line(ram, mech::linkage::kNone, T, c.value("ram.angle", angle), c.value("ram.offset", offset));
  const int A = c.crank(crank, O, "A", c.value("phase", phase), c.value("speed", 10), sense);
  const int P = w == 0 && u == r ? A : c.local_point(crank, "P", c.value("P.u", u), c.value("P.w", w));
  c.rrp(rod, ram, P, "B", branch);
  return c;
}

TEST(LinkageKinks, ASliderCranksDeadCentresInClosedForm) {
  int cases = 0;
  for (const double offset : {0.0, 0.05, -0.08})
    for (const double angle : {0.0, 0.4, -2.5})
      for (const int branch : {1, -1})
        for (const int sense : {1, -1})
          for (const bool off_axis : {false, true}) {
            const double r = 0.2, u = off_axis ? 0.05 : r, w = off_axis ? 0.17 : 0.0;
            int ram = 0;
            const Chain c = slider_crank(r, u, w, 0.75, angle, offset, branch, sense, 0.7 * sense, ram);
            const Load l = opposing(Load::Kind::force, ram);
            std::vector<double> got;
            ASSERT_TRUE(closed_stops(c, l, got));
            const auto want = bisected_zeros(c, [&](const State<double>& st) { return st.slide[ram].d; });
            EXPECT_EQ(want.size(), 2u);
            expect_same_angles(got, want);
            ++cases;
          }
  EXPECT_EQ(cases, 72);
}

// A crank-rocker: crank 0.1 about O, coupler 0.35 from its joint A to B,
// rocker 0.3 from B to the ground pivot Q at (0.32, 0.05); `forward`: the
// group written RRR(coupler, rocker) from A and Q, else RRR(rocker,
// coupler) from Q and A.
Chain crank_rocker(bool forward, int branch, int sense, int& rocker) {
  Chain c;
  const int O = c.ground("O", c.value("O.x", 0), c.value("O.y", 0));
  const int Q = c.ground("Q", c.value("Q.x", 0.32), c.value("Q.y", 0.05));
  const int crank = c.link("crank");
  c.set_length(crank, c.value("crank.length", 0.1));
  const int coupler = c.link("coupler");
  c.set_length(coupler, c.value("coupler.length", 0.35));
  rocker = c.link("rocker");
  c.set_length(rocker, c.value("rocker.length", 0.3));
  const int A = c.crank(crank, O, "A", c.value("phase", 0.3), c.value("speed", 10), sense);
  if (forward) c.rrr(coupler, rocker, A, Q, "B", branch);
  else c.rrr(rocker, coupler, Q, A, "B", branch);
  return c;
}

TEST(LinkageKinks, ACrankRockersLimitsInClosedForm) {
  for (const bool forward : {true, false})
    for (const int branch : {1, -1})
      for (const int sense : {1, -1}) {
        int rocker = 0;
        const Chain c = crank_rocker(forward, branch, sense, rocker);
        const Load l = opposing(Load::Kind::torque, rocker);
        std::vector<double> got;
        ASSERT_TRUE(closed_stops(c, l, got));
        const auto want = bisected_zeros(c, [&](const State<double>& st) { return st.rates(rocker).d; });
        EXPECT_EQ(want.size(), 2u);
        expect_same_angles(got, want);
      }
}

TEST(LinkageKinks, OtherSwitchesAreLeftToTheSearch) {
  int rocker = 0;
  const Chain c = crank_rocker(true, 1, 1, rocker);
  std::vector<double> got;
  // The coupler's rate (no closed form), a friction between two links.
  EXPECT_FALSE(closed_stops(c, opposing(Load::Kind::torque, 1), got));
  EXPECT_FALSE(closed_stops(c, opposing(Load::Kind::friction, rocker, 1), got));
}

}  // namespace
