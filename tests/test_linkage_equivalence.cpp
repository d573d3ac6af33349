// The general linkage gives the hand-written problems' numbers: the same
// mechanism described in configs/linkage/ and evaluated by `linkage`
// against the hand-written problem's config, at the config's design and at
// 100 random designs (a fixed seed, in a box wider than the configs' bounds
// so that some designs cannot assemble): the same status, the metrics to
// 1e-12 relative, their gradients to 1e-12 of the largest component. The
// two sides share no kinematics: the hand-written slider-crank is seed
// 000's eqs (1)-(8); the linkage is its RRP group's closed form on jets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "opt/registry.hpp"

namespace {

std::unique_ptr<opt::Problem> load(const std::string& config) {
  return opt::make_problem(opt::ConfigNode::load(std::string(MECHOPT_SOURCE_DIR) + "/configs/" + config));
}

// One pair of metrics, the hand-written's name and the linkage's, and how
// the linkage's reads as the hand-written's.
struct Same {
  std::string hand, general;
  enum class As { is, complement, larger_ratio } as = As::is;
};

// The linkage's metric value v (gradient g) as the hand-written defines it:
// itself; pi/2 - v (a pressure angle from a transmission angle); or the
// larger of v and 1 / v (a time ratio that is at least 1).
opt::MetricValue as_hand(Same::As as, opt::MetricValue m) {
  if (as == Same::As::complement) return {std::numbers::pi / 2 - m.value, -m.gradient};
  if (as == Same::As::larger_ratio && m.value < 1)
    return {1 / m.value, -m.gradient / (m.value * m.value)};
  return m;
}

// Evaluates both at x (the hand-written problem's variables) and x_general
// = map(x), and compares.
template <class Map>
void expect_same(const opt::Problem& hand, const opt::Problem& general, const std::vector<Same>& metrics,
                 const Eigen::VectorXd& x, Map&& map, const std::string& where) {
  SCOPED_TRACE(where);
  std::vector<std::string> hn, gn;
  for (const auto& m : metrics) hn.push_back(m.hand), gn.push_back(m.general);
  const opt::Evaluation h = hand.evaluate(x, hn, true);
  Eigen::MatrixXd jacobian;  // d x_general / d x
  const Eigen::VectorXd xg = map(x, jacobian);
  const opt::Evaluation g = general.evaluate(xg, gn, true);
  // The four-bar's own statuses (not Grashof, a toggle inside the cycle)
  // are the general chain's cannot_assemble: its group fails somewhere.
  const mech::Status hs = h.status == mech::Status::not_grashof || h.status == mech::Status::toggle_in_cycle
                              ? mech::Status::cannot_assemble
                              : h.status;
  ASSERT_EQ(mech::to_string(hs), mech::to_string(g.status)) << h.message << " | " << g.message;
  if (!h.ok()) return;
  for (const auto& m : metrics) {
    const auto& a = h[hand.metric_id(m.hand)];
    const opt::MetricValue b = as_hand(m.as, g[general.metric_id(m.general)]);
    EXPECT_NEAR(b.value, a.value, 1e-12 * std::max(1.0, std::abs(a.value))) << m.hand;
    // The general gradient in the hand-written variables: J^T g.
    const Eigen::VectorXd gb = jacobian.transpose() * b.gradient;
    const double scale = std::max(1e-300, a.gradient.cwiseAbs().maxCoeff());
    for (int i = 0; i < x.size(); ++i)
      EXPECT_NEAR(gb[i], a.gradient[i], 1e-12 * std::max({scale, std::abs(a.value), 1.0})) << m.hand << " d/dx" << i;
  }
}

// slider_crank's variables (crank_radius, rod_length, offset) are the
// linkage's (ground.S0.y, links.crank.length, links.rod.length) with the
// slider axis at y = -offset.
TEST(LinkageEquivalence, SliderCrank) {
  const auto hand = load("slider_crank/stroke.yaml");
  const auto general = load("linkage/slider_crank.yaml");
  // The linkage's variables sit in its table's order: S0's y, then the lengths.
  ASSERT_EQ(general->variables()[0].name, "ground.S0.y");
  ASSERT_EQ(general->variables()[1].name, "links.crank.length");
  ASSERT_EQ(general->variables()[2].name, "links.rod.length");
  const std::vector<Same> metrics = {{"stroke", "ram_stroke"},
                                     {"peak_slider_acceleration", "ram_peak_acceleration"},
                                     {"max_pressure_angle", "max_pressure_angle"}};
  auto map = [](const Eigen::VectorXd& x, Eigen::MatrixXd& j) {  // (r, l, e) -> (-e, r, l)
    j = Eigen::MatrixXd::Zero(3, 3);
    j(0, 2) = -1, j(1, 0) = 1, j(2, 1) = 1;
    Eigen::VectorXd g(3);
    g << -x[2], x[0], x[1];
    return g;
  };
  expect_same(*hand, *general, metrics, hand->initial_point(), map, "the config's design");
  std::mt19937_64 rng(34);
  std::uniform_real_distribution<double> r(0.1, 0.9), l(0.5, 1.2), e(-0.1, 0.1);
  int infeasible = 0;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d x(r(rng), l(rng), e(rng));
    if (!(x[0] + std::abs(x[2]) < x[1])) ++infeasible;
    expect_same(*hand, *general, metrics, x, map, "random design " + std::to_string(i));
  }
  EXPECT_GT(infeasible, 5);  // the statuses were compared where the rod cannot reach, too
}

}  // namespace

namespace {

// conveyor_swing's free links (crank, coupler, rocker lengths) are the
// linkage's links.*.length in the same order.
TEST(LinkageEquivalence, ConveyorSwing) {
  const auto hand = load("conveyor_swing/free_links.yaml");
  const auto general = load("linkage/conveyor_swing.yaml");
  ASSERT_EQ(general->variables()[0].name, "links.crank.length");
  ASSERT_EQ(general->variables()[2].name, "links.rocker.length");
  using As = Same::As;
  const std::vector<Same> metrics = {{"peak_crank_torque", "peak_drive_torque"},
                                     {"mean_abs_crank_torque", "mean_abs_drive_torque"},
                                     {"rms_crank_torque", "rms_drive_torque"},
                                     {"swing_angle", "rocker_stroke"},
                                     {"max_pressure_angle", "min_transmission_angle", As::complement},
                                     {"time_ratio", "rocker_time_ratio", As::larger_ratio},
                                     {"grashof_margin", "rocker_coupler_grashof_margin"}};
  auto map = [](const Eigen::VectorXd& x, Eigen::MatrixXd& j) {
    j = Eigen::MatrixXd::Identity(3, 3);
    return x;
  };
  expect_same(*hand, *general, metrics, hand->initial_point(), map, "the config's design");
  std::mt19937_64 rng(34);
  std::uniform_real_distribution<double> link(0.3, 1.6), rocker(0.3, 3.0);
  int ok = 0;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d x(link(rng), link(rng), rocker(rng));
    ok += hand->evaluate(x, {"peak_crank_torque"}, false).ok();
    expect_same(*hand, *general, metrics, x, map, "random design " + std::to_string(i));
  }
  EXPECT_GT(ok, 10);  // metrics were compared, not only statuses
  EXPECT_LT(ok, 90);
}

}  // namespace

namespace {

// recuperative_drive with the rods' rotation (fidelity.rod: full) and
// the resistance against the motion, its rod length and phase shift free:
// the linkage's two rods carry the length (rod1, rod2: the same value)
// and the second crank pin A2 the phase, [r cos psi, r sin psi] in the
// crank's frame. Its T_min, eq. (14)'s 4 m r^2 w^2 / pi^2, is the
// linkage's from the carts' strokes 2 |OA| and 2 |OA2| (lines through O).
TEST(LinkageEquivalence, RecuperativeDrive) {
  const auto hand = opt::make_problem(opt::ConfigNode::parse(R"(
problem: recuperative_drive
model: {fidelity: {rod: full}, crank_radius: 0.2 m, crank_speed: 100 rpm, cart_mass: 1000 kg,
        rod_mass_per_length: 80 kg/m, efficiency: 0.9, cart_resistance: 3562 N,
        phase_shift: 90 deg, rod_length: 0.8 m, layout: opposed, resistance: opposes_motion}
variables: {rod_length: {min: 0.5 m, max: 1.5 m}, phase_shift: {min: 0 deg, max: 360 deg}}
)", "<recuperative>"));
  const auto root = opt::ConfigNode::load(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage/recuperative_drive.yaml");
  YAML::Node over;
  for (const char* xy : {"x", "y"}) {
    over["variables"][std::string("links.crank.points.A2.") + xy]["min"] = "-0.2 m";
    over["variables"][std::string("links.crank.points.A2.") + xy]["max"] = "0.2 m";
  }
  const auto general = opt::make_problem(root.with(over, "<recuperative linkage>"));
  ASSERT_EQ(hand->variables()[0].name, "rod_length");
  ASSERT_EQ(general->variables()[0].name, "links.crank.points.A2.x");
  ASSERT_EQ(general->variables()[3].name, "links.rod2.length");
  const std::vector<Same> metrics = {{"peak_kinetic_energy", "peak_kinetic_energy"},
                                     {"mean_kinetic_energy", "mean_kinetic_energy"},
                                     {"least_mean_kinetic_energy", "least_mean_kinetic_energy"},
                                     {"k1", "k1"},
                                     {"k2", "k2"},
                                     {"k3", "k3"},
                                     {"peak_crank_torque", "peak_drive_torque"},
                                     {"mean_crank_torque", "mean_drive_torque"},
                                     {"rms_crank_torque", "rms_drive_torque"}};
  auto map = [](const Eigen::VectorXd& x, Eigen::MatrixXd& j) {  // (l, psi) -> (r cos psi, r sin psi, l, l)
    const double r = 0.2, c = std::cos(x[1]), s = std::sin(x[1]);
    j = Eigen::MatrixXd::Zero(4, 2);
    j(0, 1) = -r * s, j(1, 1) = r * c, j(2, 0) = 1, j(3, 0) = 1;
    Eigen::VectorXd g(4);
    g << r * c, r * s, x[0], x[0];
    return g;
  };
  expect_same(*hand, *general, metrics, hand->initial_point(), map, "the config's design");
  std::mt19937_64 rng(34);
  std::uniform_real_distribution<double> length(0.15, 1.5), phase(0.0, 2 * std::numbers::pi);
  int infeasible = 0;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector2d x(length(rng), phase(rng));
    infeasible += x[0] <= 0.2;
    expect_same(*hand, *general, metrics, x, map, "random design " + std::to_string(i));
  }
  EXPECT_GT(infeasible, 0);
}

}  // namespace

namespace {

// balanced_slider_crank's improved mechanism (seed 004: a fixed circular
// cam, springs) with its cam offset and springs free: the linkage's cam
// centre C = (-a, 0), its spring's rate, and its free length 8 m + s_n
// (the spring to G = (10 m, 0) is free where x_B = 2 m - s_n, the
// hand-written's s = 2.3 m - x_B at s0 = 0.3 m + s_n). The hand-written
// side solves the crank pin on the cam by eq. (1) and the forces by its
// own Newton-Euler (the block's slot and cam normals, the bearing); the
// linkage by its RRP groups and reactions group by group.
TEST(LinkageEquivalence, BalancedSliderCrank) {
  const auto hand = opt::make_problem(opt::ConfigNode::parse(R"(
problem: balanced_slider_crank
model: {crank_speed: 320 rpm, crank_length: 0.3 m, original_rod_length: 2 m, rod_length: 2.0219 m,
        rod_mass: 150 kg, rod_inertia: 0.5 kg m^2, slider_mass: 600 kg, gravity: perpendicular}
variables:
  cam_offset: {min: 0 m, max: 0.05 m, initial: 0.0219 m}
  spring_rate: {min: 100 kN/m, max: 2000 kN/m, initial: 673.765 kN/m}
  spring_neutral: {min: -0.2 m, max: 0.2 m, initial: 0 m}
)", "<balanced>"));
  const auto general = load("linkage/balanced_slider_crank.yaml");
  ASSERT_EQ(general->variables()[0].name, "ground.C.x");
  ASSERT_EQ(general->variables()[1].name, "springs.balance.rate");
  ASSERT_EQ(general->variables()[2].name, "springs.balance.free_length");
  const std::vector<Same> metrics = {{"peak_balancing_torque", "peak_drive_torque"},
                                     {"peak_support_reaction", "O_crank_peak_reaction"},
                                     {"peak_cam_force", "C_follower_peak_reaction"},
                                     {"peak_shaking_force", "peak_shaking_force"},
                                     {"energy_swing", "energy_swing"}};
  auto map = [](const Eigen::VectorXd& x, Eigen::MatrixXd& j) {  // (a, c, s_n) -> (-a, c, 8 m + s_n)
    j = Eigen::MatrixXd::Identity(3, 3);
    j(0, 0) = -1;
    Eigen::VectorXd g(3);
    g << -x[0], x[1], 8 + x[2];
    return g;
  };
  expect_same(*hand, *general, metrics, hand->initial_point(), map, "the config's design");
  std::mt19937_64 rng(34);
  std::uniform_real_distribution<double> a(0.0, 0.4), c(100e3, 2000e3), s(-0.2, 0.2);
  int infeasible = 0;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d x(a(rng), c(rng), s(rng));
    infeasible += x[0] >= 0.3;  // the cam's centre outside its circle's reach
    expect_same(*hand, *general, metrics, x, map, "random design " + std::to_string(i));
  }
  EXPECT_GT(infeasible, 5);
}

}  // namespace
