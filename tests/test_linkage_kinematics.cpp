// The general linkage's kinematics (mech/linkage): each group's closed form
// on second-order jets, checked against
// - the hand-written slider-crank (seed 000 eqs 1-8) and four-bar
//   (four_bar.hpp's loop closure projected on the links), independent code;
// - the constraint equations every group keeps, differentiated once and
//   twice in the crank angle (|B - P|^2 = a^2 gives (B-P).(B'-P') = 0 and
//   (B-P).(B''-P'') + |B'-P'|^2 = 0, and likewise for a point on a line):
//   the jets' derivatives satisfy the groups' linear velocity and
//   acceleration equations;
// - central differences of the positions in the crank angle and in a
//   design value (the design derivative of a Dual).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mech/four_bar.hpp"
#include "mech/linkage/kinematics.hpp"
#include "mech/slider_crank.hpp"

namespace {

using mech::linkage::Chain;
using mech::linkage::Jet;
using mech::linkage::State;
using mech::linkage::Vec;

constexpr double kPi = std::numbers::pi;

// A slider-crank: crank r about O, rod l to a ram on the x axis shifted to
// y = -e (slider_crank.hpp's frame), the ram ahead (sigma = +1).
struct SliderCrankChain {
  Chain c;
  int ram, rod, crank;
  SliderCrankChain(double r, double l, double e, int branch = 1) {
    const int O = c.ground("O", c.value("ground.O.x", 0), c.value("ground.O.y", 0));
    const int S0 = c.ground("S0", c.value("ground.S0.x", 0), c.value("ground.S0.y", -e));
    crank = c.link("crank");
    c.set_length(crank, c.value("links.crank.length", r));
    rod = c.link("rod");
    c.set_length(rod, c.value("links.rod.length", l));
    ram = c.link("ram");
    c.set_line(ram, mech::linkage::kNone, S0, c.value("links.ram.line.angle", 0), mech::linkage::kNone);
    const int A = c.crank(crank, O, "A", c.value("crank.phase", 0), c.value("crank.speed", 10), 1);
    c.rrp(rod, ram, A, "B", branch);
  }
};

template <class S = double>
State<S> solved(const Chain& c, const std::vector<S>& v, S phi) {
  State<S> st;
  st.resize(c);
  EXPECT_TRUE(mech::linkage::solve(c, v.data(), phi, st)) << "group " << st.failed;
  return st;
}

TEST(LinkageKinematics, SliderCrankMatchesTheClosedForm) {
  for (double e : {0.0, 0.05, -0.08}) {
    const double r = 0.2, l = 0.8;
    SliderCrankChain m(r, l, e);
    const mech::SliderCrank<double> k{r, l, e, 1};
    for (int i = 0; i < 24; ++i) {
      const double phi = 2 * kPi * i / 24 + 0.01;
      const auto st = solved(m.c, m.c.defaults(), phi);
      const auto p = mech::slider_crank_point(k, phi);
      const Jet<double>& s = st.slide[m.ram];
      EXPECT_NEAR(s.v, p.x, 1e-15);
      EXPECT_NEAR(s.d, p.dx, 1e-14);
      EXPECT_NEAR(s.dd, p.ddx, 1e-14);
      EXPECT_NEAR(st.angle(m.rod).d, p.dbeta, 1e-14) << "rod angle rate";
      EXPECT_NEAR(st.point[m.c.find_point("B")].y.v, -e, 1e-15);  // the pin stays on its line
    }
  }
}

// A four-bar as four_bar.hpp draws it: rocker pivot O1 at the origin, crank
// pivot O at (gx, gy); its branch +1 puts B left of O1 -> A, the RRR group
// from [O1, A] with the same branch.
TEST(LinkageKinematics, FourBarMatchesFourBarHpp) {
  for (int branch : {1, -1}) {
    const mech::FourBar<double> fb{0.25, 1.3, 1.56, 1.0, 2.2, branch};
    Chain c;
    const int O1 = c.ground("O1", c.value("x", 0), c.value("y", 0));
    const int O = c.ground("O", c.value("x", fb.gx), c.value("y", fb.gy));
    const int crank = c.link("crank"), coupler = c.link("coupler"), rocker = c.link("rocker");
    c.set_length(crank, c.value("l1", fb.crank));
    c.set_length(coupler, c.value("l2", fb.coupler));
    c.set_length(rocker, c.value("l3", fb.rocker));
    const int A = c.crank(crank, O, "A", c.value("phase", 0), c.value("speed", 12), 1);
    const int B = c.rrr(rocker, coupler, O1, A, "B", branch);
    for (int i = 0; i < 36; ++i) {
      const double phi = 2 * kPi * i / 36 + 0.003;
      const auto st = solved(c, c.defaults(), phi);
      mech::FourBarPoint<double> p;
      ASSERT_TRUE(mech::four_bar_point(fb, phi, p));
      EXPECT_NEAR(st.point[B].x.v, p.B.x, 1e-14);
      EXPECT_NEAR(st.point[B].y.v, p.B.y, 1e-14);
      EXPECT_NEAR(st.axis[coupler].x.v, p.e2.x, 1e-14);
      EXPECT_NEAR(st.axis[rocker].y.v, p.e3.y, 1e-14);
      EXPECT_NEAR(st.angle(coupler).d, p.w2, 1e-13);
      EXPECT_NEAR(st.angle(rocker).d, p.w3, 1e-13);
      EXPECT_NEAR(st.angle(coupler).dd, p.alpha2, 1e-12);
      EXPECT_NEAR(st.angle(rocker).dd, p.alpha3, 1e-12);
      EXPECT_NEAR(st.margin[0], std::abs(mech::cross(p.e3, p.e2)), 1e-14);  // sin of the angle at B
    }
  }
}

// A six-bar using every group type: a crank-shaper (RPR: block at the
// crank pin on a guide about O4), a coupler point on the guide, an RRR
// dyad from it to a ground pivot, and an RRP rod from a point of that dyad
// to a slider on a line fixed to the guide (a moving line).
struct EveryGroup {
  Chain c;
  int guide, block, rod, ram, link3, link4, A, D, B, E, C;
  EveryGroup() {
    const int O2 = c.ground("O2", c.value("O2.x", 0), c.value("O2.y", 0));
    const int O4 = c.ground("O4", c.value("O4.x", 0.05), c.value("O4.y", -0.35));
    const int O6 = c.ground("O6", c.value("O6.x", 0.3), c.value("O6.y", 0.6));
    const int crank = c.link("crank");
    c.set_length(crank, c.value("crank.length", 0.15));
    block = c.link("block");
    guide = c.link("guide");
    c.set_guide_offset(guide, c.value("guide.offset", 0.02));
    D = c.local_point(guide, "D", c.value("D.u", 0.7), c.value("D.v", 0.01));
    link3 = c.link("link3");
    c.set_length(link3, c.value("link3.length", 0.5));
    link4 = c.link("link4");
    c.set_length(link4, c.value("link4.length", 0.4));
    E = c.local_point(link4, "E", c.value("E.u", 0.25), c.value("E.v", 0.08));
    rod = c.link("rod");
    c.set_length(rod, c.value("rod.length", 1.0));
    ram = c.link("ram");
    c.set_line(ram, guide, O4, c.value("ram.line.angle", 0.3), c.value("ram.line.offset", 0.05));
    A = c.crank(crank, O2, "A", c.value("phase", 0.2), c.value("speed", 8), -1);
    c.rpr(block, guide, A, O4);
    B = c.rrr(link3, link4, D, O6, "B", 1);
    C = c.rrp(rod, ram, E, "C", 1);
  }
};

template <class S>
Vec<S> at(const State<S>& st, int p) {
  return st.point[static_cast<size_t>(p)];
}

// (X - Y).(X - Y) constant: its first and second derivatives vanish.
void expect_rigid(const State<double>& st, int x, int y) {
  const Vec<double> d = at(st, x) - at(st, y);
  const Jet<double> l2 = mech::linkage::dot(d, d);
  const double scale = std::max(1.0, l2.v);
  EXPECT_NEAR(l2.d / scale, 0, 1e-14);
  EXPECT_NEAR(l2.dd / scale, 0, 1e-13);
}

TEST(LinkageKinematics, JetsKeepEveryGroupsConstraints) {
  EveryGroup m;
  const Chain& c = m.c;
  for (int i = 0; i < 48; ++i) {
    const double phi = 2 * kPi * i / 48;
    const auto st = solved(c, c.defaults(), phi);
    expect_rigid(st, m.B, m.D);                 // link3
    expect_rigid(st, m.B, c.find_point("O6"));  // link4
    expect_rigid(st, m.E, m.B);                 // E on link4
    expect_rigid(st, m.C, m.E);                 // rod
    expect_rigid(st, m.D, c.find_point("O4"));  // D on the guide
    // The block's pin A on the guide's line: (A - O4) x u = -offset, held
    // at every order (u the guide's axis).
    const Vec<double> d = at(st, m.A) - at(st, c.find_point("O4"));
    const Jet<double> side = mech::linkage::cross(d, st.axis[m.guide]);
    EXPECT_NEAR(side.v, -0.02, 1e-15);
    EXPECT_NEAR(side.d, 0, 1e-14);
    EXPECT_NEAR(side.dd, 0, 1e-13);
    // The ram's pin C on its moving line (through O4 at 0.3 rad in the
    // guide's frame, 0.05 to its left): the same, in the line's frame.
    const Vec<double> dc = at(st, m.C) - at(st, c.find_point("O4"));
    const Jet<double> across = mech::linkage::cross(st.axis[m.ram], dc);
    EXPECT_NEAR(across.v, 0.05, 1e-15);
    EXPECT_NEAR(across.d, 0, 1e-14);
    EXPECT_NEAR(across.dd, 0, 1e-13);
    // The ram's axis is the guide's turned by the line's angle.
    EXPECT_NEAR(st.angle(m.ram).d, st.angle(m.guide).d, 1e-14);
    EXPECT_NEAR(st.angle(m.ram).dd, st.angle(m.guide).dd, 1e-13);
  }
}

// d/dphi and d2/dphi2 of every point against central differences of the
// positions (step 1e-4: truncation ~1e-9 of the second difference).
TEST(LinkageKinematics, TransferFunctionsMatchDifferences) {
  EveryGroup m;
  const Chain& c = m.c;
  const double h = 1e-4;
  for (double phi : {0.1, 1.3, 2.9, 4.4, 5.8}) {
    const auto s0 = solved(c, c.defaults(), phi), sp = solved(c, c.defaults(), phi + h),
               sm = solved(c, c.defaults(), phi - h);
    for (size_t p = 0; p < c.point_names().size(); ++p) {
      const double vx = (sp.point[p].x.v - sm.point[p].x.v) / (2 * h);
      const double ax = (sp.point[p].x.v - 2 * s0.point[p].x.v + sm.point[p].x.v) / (h * h);
      EXPECT_NEAR(s0.point[p].x.d, vx, 1e-7) << c.point_names()[p];
      EXPECT_NEAR(s0.point[p].x.dd, ax, 1e-5) << c.point_names()[p];
    }
  }
}

// A design derivative rides in the scalar: a Dual seeded on the rod's
// length against central differences of the rebuilt positions.
TEST(LinkageKinematics, DesignDerivativesMatchDifferences) {
  EveryGroup m;
  const Chain& c = m.c;
  const int slot = 14;  // rod.length
  ASSERT_EQ(c.value_names()[slot], "rod.length");
  std::vector<mech::Dual> v(c.defaults().begin(), c.defaults().end());
  v[slot].d = 1;
  const double phi = 2.2, h = 1e-6;
  const auto st = solved<mech::Dual>(c, v, mech::Dual(phi));
  auto moved = [&](double dl) {
    std::vector<double> w = c.defaults();
    w[slot] += dl;
    return solved(c, w, phi);
  };
  const auto sp = moved(h), sm = moved(-h);
  const int C = m.C;
  EXPECT_NEAR(st.point[C].x.v.d, (sp.point[C].x.v - sm.point[C].x.v) / (2 * h), 1e-8);
  EXPECT_NEAR(st.point[C].y.d.d, (sp.point[C].y.d - sm.point[C].y.d) / (2 * h), 1e-7);
  EXPECT_NEAR(st.point[C].x.dd.d, (sp.point[C].x.dd - sm.point[C].x.dd) / (2 * h), 1e-6);
}

// The RPR group alone: with no offset the guide points at the block, the
// block's coordinate is |A - O4| (the crank-shaper's closed form).
TEST(LinkageKinematics, GuideWithoutOffsetPointsAtTheBlock) {
  Chain c;
  const int O2 = c.ground("O2", c.value("a", 0), c.value("b", 0));
  const int O4 = c.ground("O4", c.value("c", 0), c.value("d", -0.3));
  const int crank = c.link("crank"), block = c.link("block"), guide = c.link("guide");
  c.set_length(crank, c.value("r", 0.12));
  const int A = c.crank(crank, O2, "A", c.value("phase", 0), c.value("speed", 1), 1);
  c.rpr(block, guide, A, O4);
  for (double phi : {0.0, 1.0, 2.5, 4.0}) {
    const auto st = solved(c, c.defaults(), phi);
    const double ax = 0.12 * std::cos(phi), ay = 0.12 * std::sin(phi) + 0.3;
    EXPECT_NEAR(st.angle(guide).v, std::atan2(ay, ax), 1e-15);
    EXPECT_NEAR(st.slide[block].v, std::hypot(ax, ay), 1e-15);
    // d/dphi of atan2(ay, ax) = (ax ay' - ay ax') / |.|^2
    const double dax = -0.12 * std::sin(phi), day = 0.12 * std::cos(phi);
    EXPECT_NEAR(st.angle(guide).d, (ax * day - ay * dax) / (ax * ax + ay * ay), 1e-15);
  }
}

TEST(LinkageKinematics, AGroupThatCannotAssembleIsNamed) {
  SliderCrankChain m(0.2, 0.15, 0.0);  // the rod shorter than the crank: no pin past |sin phi| > 0.75
  State<double> st;
  st.resize(m.c);
  EXPECT_TRUE(mech::linkage::solve(m.c, m.c.defaults().data(), 0.1, st));
  EXPECT_FALSE(mech::linkage::solve(m.c, m.c.defaults().data(), kPi / 2, st));
  EXPECT_EQ(st.failed, 0);
  EXPECT_EQ(m.c.group_name(0), "RRP (rod, ram)");
}

TEST(LinkageKinematics, TheChainRefusesABadOrder) {
  Chain c;
  const int O = c.ground("O", c.value("x", 0), c.value("y", 0));
  const int crank = c.link("crank"), l2 = c.link("l2"), l3 = c.link("l3");
  c.set_length(crank, c.value("r", 0.1));
  c.set_length(l2, c.value("a", 0.5));
  c.set_length(l3, c.value("b", 0.5));
  const int later = c.local_point(l3, "P", c.value("u", 0.1), c.value("v", 0));
  EXPECT_THROW(c.rrr(l2, l3, O, O, "B", 1), std::invalid_argument);  // no crank yet
  const int A = c.crank(crank, O, "A", c.value("phase", 0), c.value("speed", 1), 1);
  EXPECT_THROW(c.rrr(l2, l3, A, later, "B", 1), std::invalid_argument);  // P is on l3, not yet solved
  EXPECT_THROW(c.ground("A", 0, 1), std::invalid_argument);               // a name twice
  EXPECT_NO_THROW(c.rrr(l2, l3, A, O, "B", 1));
  EXPECT_THROW(c.rrr(l2, l3, A, O, "C", 1), std::invalid_argument);  // a link solved twice
}

}  // namespace

namespace {

// An RPP group, a scotch yoke: the crank's pin A = r (cos t, sin t) slides
// in a slot at beta to a slider on a line through (0, h) at angle alpha;
// solving A - T = s u + t w by Cramer's rule in the line's frame, with
// A's coordinates x' = A - T along u and y' across it: s = x' - y' cot
// beta. For alpha = 0 and beta = 90 deg s = r cos t, s' = -r sin t, s'' =
// -r cos t; otherwise the jets against central differences of s.
TEST(LinkageKinematics, ScotchYokeMatchesTheClosedForm) {
  for (const double beta : {kPi / 2, 1.1}) {
    for (const double alpha : {0.0, 0.4}) {
      const double r = 0.3, h = 0.05;
      Chain c;
      const int O = c.ground("O", c.value("ground.O.x", 0), c.value("ground.O.y", 0));
      const int T = c.ground("T", c.value("ground.T.x", 0), c.value("ground.T.y", h));
      const int crank = c.link("crank"), block = c.link("block"), yoke = c.link("yoke");
      c.set_length(crank, c.value("links.crank.length", r));
      c.set_line(yoke, mech::linkage::kNone, T, c.value("links.yoke.line.angle", alpha), mech::linkage::kNone);
      c.set_slot(yoke, c.value("links.yoke.slot", beta));
      const int A = c.crank(crank, O, "A", c.value("crank.phase", 0), c.value("crank.speed", 10), 1);
      const int P = c.rpp(block, yoke, A, "P");
      auto s_at = [&](double t) {
        const double x = r * std::cos(t), y = r * std::sin(t) - h;
        const double along = x * std::cos(alpha) + y * std::sin(alpha);
        const double across = -x * std::sin(alpha) + y * std::cos(alpha);
        return along - across / std::tan(beta);
      };
      for (const double t : {0.0, 0.7, 2.0, 4.4}) {
        const State<double> st = solved(c, c.defaults(), t);
        const Jet<double>& s = st.slide[static_cast<size_t>(yoke)];
        EXPECT_NEAR(s.v, s_at(t), 1e-15);
        const double d = 1e-4;
        EXPECT_NEAR(s.d, (s_at(t + d) - s_at(t - d)) / (2 * d), 1e-8);
        EXPECT_NEAR(s.dd, (s_at(t + d) - 2 * s_at(t) + s_at(t - d)) / (d * d), 1e-6);
        if (alpha == 0 && beta == kPi / 2) {
          EXPECT_NEAR(s.d, -r * std::sin(t), 1e-15);
          EXPECT_NEAR(s.dd, -r * std::cos(t), 1e-15);
        }
        // P is on the line, A on the slot through P, the block turns with the yoke.
        const Vec<double>& p = st.point[static_cast<size_t>(P)];
        EXPECT_NEAR(p.x.v, s.v * std::cos(alpha), 1e-15);
        EXPECT_NEAR(p.y.v, h + s.v * std::sin(alpha), 1e-15);
        const Vec<double>& a = st.point[static_cast<size_t>(A)];
        const Vec<double>& w = st.axis[static_cast<size_t>(block)];
        EXPECT_NEAR((a.x.v - p.x.v) * w.y.v - (a.y.v - p.y.v) * w.x.v, 0, 1e-15);
        EXPECT_NEAR(std::atan2(w.y.v, w.x.v), alpha + beta, 1e-15);
        EXPECT_NEAR(st.margin[0], std::abs(std::sin(beta)), 1e-15);
      }
    }
  }
}

}  // namespace

namespace {

// A PRP group, a wedge. A centred slider-crank (crank r about O, rod l)
// drives the wedge W along the x axis: its pin C = (x, 0),
//   x = r cos t + D, D = sqrt(l^2 - r^2 sin^2 t),
//   x' = -r sin t - r^2 sin t cos t / D,
//   x'' = -r cos t - r^2 cos 2t / D - r^4 sin^2 t cos^2 t / D^3.
// The block slides on the wedge's line through C at alpha, o1 to its left
// (u1 = (cos a, sin a), n1 = (-sin a, cos a)); the ram on a vertical ground
// line through R = (xr, yr), o2 to its left (u2 = (0, 1), n2 = (-1, 0)),
// and the two are pinned at B. B is on the ram's line, B = (xr - o2, yr +
// s2); on the block's line, B - C - o1 n1 = s1 u1: its x component gives
// s1 = X / cos a with X = xr - o2 - x + o1 sin a, its y component
//   s2 = o1 cos a + X tan a - yr,
// so s2' = -x' tan a, s2'' = -x'' tan a, s1' = -x' / cos a, s1'' = -x'' /
// cos a; and in the wedge's angle, ds2/da = -o1 sin a + o1 cos a tan a +
// X / cos^2 a = X / cos^2 a. The margin |u1 x u2| = |cos a|.
struct Wedge {
  Chain c;
  int wedge, block, ram, B;
  explicit Wedge(double alpha) {
    const int O = c.ground("O", c.value("ground.O.x", 0), c.value("ground.O.y", 0));
    const int R = c.ground("R", c.value("ground.R.x", 0.6), c.value("ground.R.y", 0.1));
    const int crank = c.link("crank"), rod = c.link("rod");
    c.set_length(crank, c.value("links.crank.length", 0.08));
    c.set_length(rod, c.value("links.rod.length", 0.35));
    wedge = c.link("wedge"), block = c.link("block"), ram = c.link("ram");
    c.set_line(wedge, mech::linkage::kNone, O, c.value("links.wedge.line.angle", 0), mech::linkage::kNone);
    const int A = c.crank(crank, O, "A", c.value("crank.phase", 0), c.value("crank.speed", 10), 1);
    const int C = c.rrp(rod, wedge, A, "C", 1);
    c.set_line(block, wedge, C, c.value("links.block.line.angle", alpha), c.value("links.block.line.offset", 0.04));
    c.set_line(ram, mech::linkage::kNone, R, c.value("links.ram.line.angle", kPi / 2),
               c.value("links.ram.line.offset", 0.02));
    B = c.prp(block, ram, "B");
  }
};

TEST(LinkageKinematics, WedgeMatchesTheClosedForm) {
  const double r = 0.08, l = 0.35, xr = 0.6, yr = 0.1, o1 = 0.04, o2 = 0.02;
  for (const double a : {-20 * kPi / 180, 0.5, 2.9}) {
    Wedge m(a);
    const double ca = std::cos(a), ta = std::tan(a);
    for (const double t : {0.0, 0.7, 2.0, 3.5, 5.1}) {
      const double sn = std::sin(t), cs = std::cos(t), D = std::sqrt(l * l - r * r * sn * sn);
      const double x = r * cs + D, dx = -r * sn - r * r * sn * cs / D,
                   ddx = -r * cs - r * r * std::cos(2 * t) / D - std::pow(r, 4) * sn * sn * cs * cs / (D * D * D);
      const double X = xr - o2 - x + o1 * std::sin(a);
      const State<double> st = solved(m.c, m.c.defaults(), t);
      const Jet<double>&s1 = st.slide[static_cast<size_t>(m.block)], &s2 = st.slide[static_cast<size_t>(m.ram)];
      EXPECT_NEAR(s2.v, o1 * ca + X * ta - yr, 1e-15);
      EXPECT_NEAR(s2.d, -dx * ta, 1e-14);
      EXPECT_NEAR(s2.dd, -ddx * ta, 1e-14);
      EXPECT_NEAR(s1.v, X / ca, 1e-15);
      EXPECT_NEAR(s1.d, -dx / ca, 1e-14);
      EXPECT_NEAR(s1.dd, -ddx / ca, 1e-14);
      const Vec<double>& b = st.point[static_cast<size_t>(m.B)];
      EXPECT_NEAR(b.x.v, xr - o2, 1e-15);
      EXPECT_NEAR(b.x.d, 0, 1e-15);
      EXPECT_NEAR(b.y.v, yr + s2.v, 1e-15);
      // Both sliders keep their lines' directions and share the pin.
      EXPECT_NEAR(st.angle(m.block).v, a, 1e-15);
      EXPECT_NEAR(st.angle(m.ram).v, kPi / 2, 1e-15);
      EXPECT_EQ(st.angle(m.block).d, 0);
      EXPECT_NEAR(st.margin[1], std::abs(ca), 1e-15);
      // The transfer functions against central differences of the positions.
      const double h = 1e-4;
      const State<double> sp = solved(m.c, m.c.defaults(), t + h), sm = solved(m.c, m.c.defaults(), t - h);
      const auto& bp = sp.point[static_cast<size_t>(m.B)];
      const auto& bm = sm.point[static_cast<size_t>(m.B)];
      EXPECT_NEAR(b.y.d, (bp.y.v - bm.y.v) / (2 * h), 1e-8);
      EXPECT_NEAR(b.y.dd, (bp.y.v - 2 * b.y.v + bm.y.v) / (h * h), 1e-5);
    }
  }
}

// The wedge's angle as a design derivative: ds2/da = X / cos^2 a, and the
// second slider's rates through the Dual against central differences.
TEST(LinkageKinematics, WedgeDesignDerivative) {
  const double a = 0.4, t = 1.3, r = 0.08, l = 0.35;
  Wedge m(a);
  const int slot = static_cast<int>(std::find(m.c.value_names().begin(), m.c.value_names().end(),
                                              "links.block.line.angle") - m.c.value_names().begin());
  std::vector<mech::Dual> v(m.c.defaults().begin(), m.c.defaults().end());
  v[static_cast<size_t>(slot)].d = 1;
  const State<mech::Dual> st = solved<mech::Dual>(m.c, v, mech::Dual(t));
  const double x = r * std::cos(t) + std::sqrt(l * l - r * r * std::sin(t) * std::sin(t));
  const double X = 0.6 - 0.02 - x + 0.04 * std::sin(a);
  const auto& s2 = st.slide[static_cast<size_t>(m.ram)];
  EXPECT_NEAR(s2.v.d, X / (std::cos(a) * std::cos(a)), 1e-14);
  auto moved = [&](double da) {
    std::vector<double> w = m.c.defaults();
    w[static_cast<size_t>(slot)] += da;
    return solved(m.c, w, t).slide[static_cast<size_t>(m.ram)];
  };
  const double h = 1e-6;
  const auto sp = moved(h), sm = moved(-h);
  EXPECT_NEAR(s2.d.d, (sp.d - sm.d) / (2 * h), 1e-8);
  EXPECT_NEAR(s2.dd.d, (sp.dd - sm.dd) / (2 * h), 1e-7);
}

// Parallel lines leave the pin no place: the block's line at 90 deg on
// the wedge and the ram's at 90 deg (the same direction to the last bit)
// cannot assemble, and the group is named. The chain refuses a PRP group
// whose slider has no line or whose line is on a link not solved before it.
TEST(LinkageKinematics, WedgeWithParallelLinesCannotAssemble) {
  Wedge m(kPi / 2);
  State<double> st;
  st.resize(m.c);
  EXPECT_FALSE(mech::linkage::solve(m.c, m.c.defaults().data(), 0.3, st));
  EXPECT_EQ(st.failed, 1);
  EXPECT_EQ(m.c.group_name(1), "PRP (block, ram)");
  Chain c;
  const int O = c.ground("O", c.value("x", 0), c.value("y", 0));
  const int crank = c.link("crank"), s1 = c.link("s1"), s2 = c.link("s2"), s3 = c.link("s3");
  c.set_length(crank, c.value("r", 0.1));
  const int A = c.crank(crank, O, "A", c.value("phase", 0), c.value("speed", 1), 1);
  c.set_line(s1, crank, A, c.value("a1", 0.3), mech::linkage::kNone);
  EXPECT_THROW(c.prp(s1, s2, "B"), std::invalid_argument);  // s2 has no line
  c.set_line(s2, s3, O, c.value("a2", 1.2), mech::linkage::kNone);
  EXPECT_THROW(c.prp(s1, s2, "B"), std::invalid_argument);  // s2's line is on s3, not solved
  c.set_line(s2, mech::linkage::kNone, O, c.value("a3", 1.2), mech::linkage::kNone);
  EXPECT_THROW(c.prp(s1, s1, "B"), std::invalid_argument);  // one slider twice
  EXPECT_NO_THROW(c.prp(s1, s2, "C"));
}

}  // namespace
