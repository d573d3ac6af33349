// The chain on lanes (mech/linkage: solve_lanes, lane_loads through
// drive_point), which a cycle mean's Gauss nodes take kLanes at a time,
// against the scalar chain at each lane's angle: every point's position
// and transfer functions, the driving torque (its loads' branches taken
// lane by lane: a `when`'s stroke, a law's contact, a table's row, an
// opposing load's and a friction's sign) and the energy, on every shipped
// linkage and a slider-crank with a table over the crank angle; on
// LaneDual<2> against DualN<2>, their design derivatives too. A mean's
// nodes take the crank's direction by the angle sum with its phase's from
// the quadrature's cosine and sine (simd.hpp's sincos), the scalar chain
// the C library's cosine and sine of the whole angle: the two agree to
// 1e-12 of each quantity's scale. From the crank angle's own cosine and
// sine (the grid's form), a lane is the scalar chain's bits; so every
// metric is the same bits with or without its gradient.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "mech/linkage/dynamics.hpp"
#include "opt/config.hpp"
#include "opt/registry.hpp"
#include "problems/linkage/description.hpp"
#include "paths.hpp"

namespace {

using mech::Lanes;
using mech::linkage::Chain;
using mech::linkage::State;

// The lane form at angles phi of the chain with values v (S0: double or
// DualN<2>) against the scalar's at each lane.
template <class S0>
void expect_lanes_equal_scalars(const Chain& c, const std::vector<S0>& v, const Lanes& phi, const std::string& what) {
  using L = mech::lanes_of<S0>;
  mech::linkage::LaneSolver<S0> lanes(c, v.data());
  Lanes cp, sp;
  mech::sincos(phi, sp, cp);
  const State<L>& sl = lanes.at(phi, cp, sp);
  const auto dl = mech::linkage::drive_point(c, lanes.v.data(), sl);
  State<S0> ss;
  ss.resize(c);
  auto same = [&](const L& lane, const S0& scalar, int j, double scale, const std::string& name) {
    EXPECT_NEAR(mech::lane_value(lane, j), mech::value(scalar), 1e-12 * scale) << what << " " << name << " lane " << j;
    if constexpr (mech::is_dual<S0>) {
      for (int i = 0; i < 2; ++i)
        EXPECT_NEAR(lane.d[i][j], scalar.derivatives()[i], 1e-12 * scale) << what << " d" << name << "/dv" << i;
    }
  };
  for (int j = 0; j < mech::kLanes; ++j) {
    ASSERT_TRUE(mech::linkage::solve(c, v.data(), S0(phi[j]), ss)) << what;
    const auto ds = mech::linkage::drive_point(c, v.data(), ss);
    for (size_t p = 0; p < c.point_names().size(); ++p) {
      const auto &a = sl.point[p], &b = ss.point[p];
      const std::string name = c.point_names()[p];
      same(a.x.v, b.x.v, j, 1, name + ".x"), same(a.y.v, b.y.v, j, 1, name + ".y");
      same(a.x.d, b.x.d, j, 1, name + ".x'"), same(a.y.dd, b.y.dd, j, 1, name + ".y''");
    }
    const double torque_scale = 1 + std::abs(mech::value(ds.torque));
    const double energy_scale = 1 + std::abs(mech::value(ds.energy));
    same(dl.torque, ds.torque, j, torque_scale, "torque");
    same(dl.energy, ds.energy, j, energy_scale, "energy");
  }
}

template <class S0>
std::vector<S0> seeded(const Chain& c) {
  std::vector<S0> v(c.defaults().begin(), c.defaults().end());
  if constexpr (mech::is_dual<S0>) {
    // Seed the first two lengths: they move every joint after them.
    int seeded = 0;
    for (size_t i = 0; i < v.size() && seeded < 2; ++i)
      if (c.value_names()[i].find(".length") != std::string::npos) v[i].derivatives()[seeded++] = 1;
  }
  return v;
}

void expect_lanes(const Chain& c, const std::string& what) {
  // Angles off the grid and off each other's symmetries, two blocks.
  for (const Lanes& phi : {Lanes(Lanes::Raw{0.3, 1.7, 3.1, 5.5}), Lanes(Lanes::Raw{0.9, 2.4, 4.0, 6.1})}) {
    expect_lanes_equal_scalars(c, seeded<double>(c), phi, what);
    expect_lanes_equal_scalars(c, seeded<mech::DualN<2>>(c), phi, what + " (DualN<2>)");
  }
}

TEST(LinkageLanes, EveryShippedLinkageAtFourAnglesAtOnce) {
  int n = 0;
  for (const auto& f : std::filesystem::directory_iterator(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage")) {
    const auto d = problems::linkage::read_description(opt::ConfigNode::load(f.path().string()));
    expect_lanes(d.chain, f.path().filename().string());
    ++n;
  }
  EXPECT_GE(n, 10);
}

// The grid's form (solve_lanes_exact: checked, the crank angle's own
// cosine and sine, pc = 1, ps = 0): every lane the same bits as solve at its angle,
// margins, torque and energy too (the lanes take the C library's sin, cos,
// exp, atan2 and sqrt lane by lane, the same operations in the same order).
TEST(LinkageLanes, TheGridsLanesAreTheScalarChainsBits) {
  for (const auto& f : std::filesystem::directory_iterator(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage")) {
    const auto d = problems::linkage::read_description(opt::ConfigNode::load(f.path().string()));
    const Chain& c = d.chain;
    const std::vector<double>& v = c.defaults();
    mech::linkage::LaneSolver<double> lanes(c, v.data());
    State<double> ss;
    ss.resize(c);
    for (int k = 0; k < 16; k += mech::kLanes) {
      Lanes phi;
      for (int j = 0; j < mech::kLanes; ++j) phi[j] = 2 * std::numbers::pi * (k + j) / 16;
      ASSERT_TRUE(mech::linkage::solve_lanes_exact(c, lanes.v.data(), phi, lanes.st));
      const auto dl = mech::linkage::drive_point(c, lanes.v.data(), lanes.st);
      for (int j = 0; j < mech::kLanes; ++j) {
        ASSERT_TRUE(mech::linkage::solve(c, v.data(), phi[j], ss));
        const auto ds = mech::linkage::drive_point(c, v.data(), ss);
        const std::string at = f.path().filename().string() + " at grid point " + std::to_string(k + j);
        for (size_t p = 0; p < ss.point.size(); ++p)
          for (auto [a, b] : {std::pair{lanes.st.point[p].x, ss.point[p].x}, {lanes.st.point[p].y, ss.point[p].y}}) {
            EXPECT_EQ(a.v[j], b.v) << at << " " << c.point_names()[p];
            EXPECT_EQ(a.d[j], b.d) << at << " " << c.point_names()[p];
            EXPECT_EQ(a.dd[j], b.dd) << at << " " << c.point_names()[p];
          }
        for (size_t g = 0; g < ss.margin.size(); ++g) EXPECT_EQ(lanes.st.margin[g][j], ss.margin[g]) << at;
        EXPECT_EQ(dl.torque[j], ds.torque) << at;
        EXPECT_EQ(dl.energy[j], ds.energy) << at;
      }
    }
  }
}

// Jets of lower order (kinematics.hpp's LaneVelocity: velocities alone;
// LanePosition: positions alone) leave the values and their design
// derivatives as the full jets give them, bit for bit (forward mode: no
// value reads a derivative in phi), and the derivatives they drop 0. A
// second block solved without placing the ground again (ground false) is
// the same bits as one solved afresh.
TEST(LinkageLanes, LowerOrderJetsKeepTheValuesBits) {
  using L = mech::LaneDual<2>;
  using V = mech::linkage::velocity_lanes<L>;
  using P = mech::linkage::position_lanes<L>;
  static_assert(mech::linkage::kJetOrder<L> == 2 && mech::linkage::kJetOrder<V> == 1 &&
                mech::linkage::kJetOrder<P> == 0);
  int n = 0;
  for (const auto& f : std::filesystem::directory_iterator(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage")) {
    const auto d = problems::linkage::read_description(opt::ConfigNode::load(f.path().string()));
    const Chain& c = d.chain;
    const mech::linkage::LaneSolver<mech::DualN<2>> lanes(c, seeded<mech::DualN<2>>(c).data());
    const std::vector<V> vv(lanes.v.begin(), lanes.v.end());
    const std::vector<P> pv(lanes.v.begin(), lanes.v.end());
    State<L> sl, fresh;
    State<V> sv;
    State<P> sp;
    for (auto* st : {&sl, &fresh}) st->resize(c);
    sv.resize(c), sp.resize(c);
    bool first = true;
    for (const Lanes& phi : {Lanes(Lanes::Raw{0.3, 1.7, 3.1, 5.5}), Lanes(Lanes::Raw{0.9, 2.4, 4.0, 6.1})}) {
      mech::linkage::solve_lanes_at<L, false>(c, lanes.v.data(), L(phi), sl, first);
      mech::linkage::solve_lanes_at<L, false>(c, lanes.v.data(), L(phi), fresh);
      mech::linkage::solve_lanes_at<V, false>(c, vv.data(), V(L(phi)), sv, first);
      mech::linkage::solve_lanes_at<P, false>(c, pv.data(), P(L(phi)), sp, first);
      first = false;
      const std::string at = f.path().filename().string() + " at " + std::to_string(phi[0]);
      auto same = [&](const Lanes& a, const Lanes& b, const std::string& what) {
        for (int j = 0; j < mech::kLanes; ++j) EXPECT_EQ(a[j], b[j]) << at << " " << what << " lane " << j;
      };
      auto same_dual = [&](const L& a, const L& b, const std::string& what) {
        same(a.v, b.v, what);
        for (int i = 0; i < 2; ++i) same(a.d[i], b.d[i], what + " d/dv" + std::to_string(i));
      };
      for (size_t p = 0; p < c.point_names().size(); ++p) {
        const std::string name = c.point_names()[p];
        for (int k = 0; k < 2; ++k) {
          const auto& full = k ? sl.point[p].y : sl.point[p].x;
          const auto& afresh = k ? fresh.point[p].y : fresh.point[p].x;
          const auto& vel = k ? sv.point[p].y : sv.point[p].x;
          const auto& pos = k ? sp.point[p].y : sp.point[p].x;
          const std::string what = name + (k ? ".y" : ".x");
          same_dual(full.v, afresh.v, what), same_dual(full.d, afresh.d, what + "'");
          same_dual(full.dd, afresh.dd, what + "''");
          same_dual(vel.v, full.v, what + " (velocities)"), same_dual(vel.d, full.d, what + "' (velocities)");
          same_dual(pos.v, full.v, what + " (positions)");
          same_dual(vel.dd, L(0.0), what + "'' (velocities)");
          same_dual(pos.d, L(0.0), what + "' (positions)"), same_dual(pos.dd, L(0.0), what + "'' (positions)");
        }
      }
    }
    ++n;
  }
  EXPECT_GE(n, 10);
}

TEST(LinkageLanes, ATableOverTheCrankAngleRowByLane) {
  const auto d = problems::linkage::read_description(opt::ConfigNode::parse(
      "problem: linkage\nmodel:\n"
      "  ground: {O: [0 m, 0 m], S0: [0 m, 0 m]}\n"
      "  crank: {link: crank, pivot: O, joint: A, phase: 10 deg, speed: 60 rpm, sense: cw}\n"
      "  links: {crank: {length: 0.2 m}, rod: {length: 0.8 m},\n"
      "          ram: {mass: 10 kg, line: {fixed_to: ground, through: S0, angle: 0 deg}}}\n"
      "  groups: [{type: RRP, links: [rod, ram], from: A, joint: B, branch: 1}]\n"
      "  loads: {cut: {link: ram, table: {over: crank_angle, unit: [deg, N],\n"
      "                rows: [[30, 0], [120, -800], [200, -100], [300, 400]]}}}\n"
      "  outputs: [ram]\n",
      "<table over the crank angle>"));
  expect_lanes(d.chain, "table over the crank angle");
}

}  // namespace

// A value is the same bits with or without its gradient (a driver's line
// search that asks for the value alone would read a difference as slope):
// every metric of every shipped linkage with variables, at its start.
TEST(LinkageLanes, AValueIsTheSameBitsWithOrWithoutItsGradient) {
  int checked = 0;
  for (const auto& f : std::filesystem::directory_iterator(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage")) {
    const auto p = opt::make_problem(opt::ConfigNode::load(f.path().string()));
    if (p->variables().empty()) continue;
    const Eigen::VectorXd x = p->initial_point();
    const opt::Evaluation plain = p->evaluate(x, opt::MetricSet::all(), false);
    const opt::Evaluation with = p->evaluate(x, opt::MetricSet::all(), true);
    ASSERT_TRUE(plain.ok()) << f.path() << ": " << plain.message;
    ASSERT_TRUE(with.ok()) << f.path() << ": " << with.message;
    for (size_t m = 0; m < p->metric_names().size(); ++m) {
      const auto id = static_cast<opt::MetricId>(m);
      if (!plain.has(id)) continue;
      EXPECT_EQ(plain[id].value, with[id].value) << f.path().filename() << " " << p->metric_names()[m];
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}
