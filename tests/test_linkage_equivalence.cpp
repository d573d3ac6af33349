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
#include "paths.hpp"

namespace {

std::unique_ptr<opt::Problem> load(const std::string& config) {
  return opt::make_problem(opt::ConfigNode::load(std::string(MECHOPT_SOURCE_DIR) + "/configs/" + config));
}

// One pair of metrics, the hand-written's name and the linkage's, and how
// the linkage's reads as the hand-written's.
struct Same {
  std::string hand, general;
  enum class As { is, complement, larger_ratio, half } as = As::is;
};

// The linkage's metric value v (gradient g) as the hand-written defines it:
// itself; pi/2 - v (a pressure angle from a transmission angle); the
// larger of v and 1 / v (a time ratio that is at least 1); or v / 2 (a
// half swing from a stroke).
opt::MetricValue as_hand(Same::As as, opt::MetricValue m) {
  if (as == Same::As::complement) return {std::numbers::pi / 2 - m.value, -m.gradient};
  if (as == Same::As::half) return {m.value / 2, m.gradient / 2};
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

namespace {

// crank_press in the readings a description expresses (lever: slider): the
// piston is the slider of a slider-crank with r and l_sh scaled by k = l /
// l_p (configs/linkage/crank_press.yaml). The hand-written variables (r,
// l_sh, l, l_p) map to the crank's and the rod's lengths; the law's depth
// at the end of the stroke is h = 20 mm on both sides. The pressing ends at
// the inner dead centre (the line toward the crank's pivot) or the outer one
// (the line away from it, the crank half a turn on); the constant force is
// the law with b = 0 and a e^(b h) for a. With `contact` instead of the
// depth, the contact is a third variable, the coordinate h short of the
// end: (r + end l_sh) k - h, end -1 inner (-(l_sh - r) k), +1 outer.
struct PressReading {
  std::string name, hand;  // the hand-written model's keys
  std::string general;     // the description's changes
  double end = 0;          // by contact: -1 inner, +1 outer; 0: by depth
};

std::unique_ptr<opt::Problem> press_linkage(const PressReading& reading) {
  YAML::Node root = YAML::LoadFile(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage/crank_press.yaml");
  root.remove("constraints");
  root["variables"] =
      YAML::Load("{links.crank.length: {min: 0.001 m, max: 1 m}, links.rod.length: {min: 0.001 m, max: 1 m}}");
  const YAML::Node over = YAML::Load(reading.general);
  for (const auto& key : over["model"]) root["model"][key.first.as<std::string>()] = key.second;
  YAML::Node press = root["model"]["loads"]["press"];
  for (const auto& key : over["load"]) press[key.first.as<std::string>()] = key.second;
  if (reading.end != 0) {
    press.remove("depth");
    press["contact"] = "0 m";
    root["variables"]["loads.press.contact"] = YAML::Load("{min: -1 m, max: 1 m}");
  }
  return opt::make_problem(opt::ConfigNode(root, "<crank_press linkage>", ""));
}

// Both press models at the paper's design and at 100 random (r, l_sh, l,
// l_p) (a fixed seed; the rod shorter than the crank in some: then
// cannot_assemble on both sides), counting the designs whose hand-written
// peak is at the contact (the torque's jump) and past it.
template <class Map>
void press_designs(const opt::Problem& hand, const opt::Problem& general, const std::vector<Same>& metrics, Map&& map,
                   int& at_contact, int& past_contact) {
  expect_same(hand, general, metrics, hand.initial_point(), map, "the paper's design");
  std::mt19937_64 rng(34);
  std::uniform_real_distribution<double> r(0.1, 0.3), lsh(0.12, 0.8), l(0.2, 0.4), lp(0.8, 1.4);
  int infeasible = 0;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector4d x(r(rng), lsh(rng), l(rng), lp(rng));
    infeasible += !(x[0] < x[1]);
    const opt::Evaluation e = hand.evaluate(x, {"peak_torque_angle", "compaction_start_angle"}, false);
    if (e.ok())
      ++(e[hand.metric_id("peak_torque_angle")].value == e[hand.metric_id("compaction_start_angle")].value
             ? at_contact
             : past_contact);
    expect_same(hand, general, metrics, x, map, "random design " + std::to_string(i));
  }
  EXPECT_GT(infeasible, 5);
}

TEST(LinkageEquivalence, CrankPress) {
  const double h = 0.020;
  const std::string outer_geometry =
      "crank: {link: crank, pivot: O, joint: A, phase: 180 deg, speed: 20.7 rad/s, sense: ccw}, "
      "links: {crank: {length: 0.05 m}, rod: {length: 0.13 m},"
      "        piston: {line: {fixed_to: ground, through: S0, angle: 0 deg}}}, "
      "groups: [{type: RRP, links: [rod, piston], from: A, joint: B, branch: 1}]";
  const std::string constant = "load: {a: " + std::to_string(0.035e6 * std::exp(140 * h)) + " Pa, b: 0 1/m}";
  const std::string inner = "{}", outer = "{model: {" + outer_geometry + "}}";
  const std::vector<PressReading> readings = {
      {"inner, pressure law", "", inner},
      {"inner, constant force", "force: constant", "{" + constant + "}"},
      {"outer, pressure law", "pressing_end: outer", outer},
      {"outer, constant force", "pressing_end: outer, force: constant",
       "{model: {" + outer_geometry + "}, " + constant + "}"},
      {"inner, pressure law, by contact", "", inner, -1},
      {"outer, pressure law, by contact", "pressing_end: outer", outer, 1},
  };
  const std::vector<Same> metrics = {{"peak_crank_torque", "peak_drive_torque"},
                                     {"stroke", "piston_stroke"},
                                     {"max_rod_angle", "max_pressure_angle"}};
  int at_contact = 0, past_contact = 0;
  for (const auto& reading : readings) {
    SCOPED_TRACE(reading.name);
    std::string model = "{press: SM-816, depth: 20 mm, pressure_factor: 0.035 MPa, bricks: 4, tabulated_angle: 120 deg,"
                        " crank_speed: 20.7 rad/s";
    if (!reading.hand.empty()) model += ", " + reading.hand;
    const auto hand = opt::make_problem(opt::ConfigNode::parse(
        "problem: crank_press\nmodel: " + model + "}\nvariables: {crank_radius: {min: 0.05 m, max: 1 m}, "
        "rod_length: {min: 0.05 m, max: 1 m}, pusher_arm: {min: 0.05 m, max: 1 m}, lever_arm: {min: 0.2 m, max: 2 m}}",
        "<crank_press>"));
    const auto general = press_linkage(reading);
    ASSERT_EQ(hand->variables()[3].name, "lever_arm");
    ASSERT_EQ(general->variables()[0].name, "links.crank.length");
    const int n = reading.end == 0 ? 2 : 3;
    ASSERT_EQ(general->variables().size(), static_cast<size_t>(n));
    const double end = reading.end;
    // (r, l_sh, l, l_p) -> (r k, l_sh k[, contact])
    auto map = [h, n, end](const Eigen::VectorXd& x, Eigen::MatrixXd& j) {
      const double r = x[0], lsh = x[1], l = x[2], lp = x[3], k = l / lp, c = r + end * lsh;
      j = Eigen::MatrixXd::Zero(n, 4);
      j(0, 0) = k, j(0, 2) = r / lp, j(0, 3) = -r * k / lp;
      j(1, 1) = k, j(1, 2) = lsh / lp, j(1, 3) = -lsh * k / lp;
      Eigen::VectorXd g(n);
      g.head(2) << r * k, lsh * k;
      if (n == 3) {
        j(2, 0) = k, j(2, 1) = end * k, j(2, 2) = c / lp, j(2, 3) = -c * k / lp;
        g[2] = c * k - h;
      }
      return g;
    };
    press_designs(*hand, *general, metrics, map, at_contact, past_contact);
  }
  // The peak where the force comes on (the torque's jump: the constant
  // force's) and past it (the pressure law's) were both compared.
  EXPECT_GT(at_contact, 100);
  EXPECT_GT(past_contact, 100);
}

}  // namespace

namespace {

// crank_press with the exact lever (lever: four_bar) in its four readings,
// configs/linkage/crank_press_four_bar.yaml: the lever's pivot C = (l_sh,
// sigma sqrt(l_p^2 - r^2)), sigma +1 for the inner end on the pin's side
// (same_side) and for the outer end on the other, -1 otherwise; the outer
// end turns the crank half a turn and the piston's line to 0 deg. The
// hand-written (r, l_sh, l, l_p) are C's coordinates, the three lengths
// and the pusher's place on the lever.
TEST(LinkageEquivalence, CrankPressFourBar) {
  struct Reading {
    std::string name, hand;
    double sigma;
    bool outer, constant;
  };
  const std::vector<Reading> readings = {
      {"inner, same side", "lever_pivot: same_side", 1, false, false},
      {"inner, opposite side", "lever_pivot: opposite_side", -1, false, false},
      {"outer, same side", "lever_pivot: same_side, pressing_end: outer", -1, true, false},
      {"outer, opposite side", "lever_pivot: opposite_side, pressing_end: outer", 1, true, false},
      {"inner, same side, constant force", "lever_pivot: same_side, force: constant", 1, false, true},
  };
  using As = Same::As;
  const std::vector<Same> metrics = {{"peak_crank_torque", "peak_drive_torque"},
                                     {"stroke", "piston_stroke"},
                                     {"lever_half_swing", "lever_stroke", As::half},
                                     {"assembly_margin", "rod_lever_grashof_margin"}};
  int at_contact = 0, past_contact = 0;
  for (const auto& reading : readings) {
    SCOPED_TRACE(reading.name);
    const auto hand = opt::make_problem(opt::ConfigNode::parse(
        "problem: crank_press\nmodel: {press: SM-816, depth: 20 mm, pressure_factor: 0.035 MPa, bricks: 4,"
        " tabulated_angle: 120 deg, crank_speed: 20.7 rad/s, lever: four_bar, " + reading.hand + "}\n"
        "variables: {crank_radius: {min: 0.05 m, max: 1 m}, rod_length: {min: 0.05 m, max: 1 m},"
        " pusher_arm: {min: 0.05 m, max: 1 m}, lever_arm: {min: 0.2 m, max: 2 m}}",
        "<crank_press four_bar>"));
    YAML::Node root = YAML::LoadFile(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage/crank_press_four_bar.yaml");
    YAML::Node model = root["model"];
    const double yc = std::sqrt(1.156 * 1.156 - 0.2 * 0.2);
    model["ground"]["C"][1] = std::to_string(reading.sigma * yc) + " m";
    if (reading.outer) {
      model["crank"]["phase"] = "180 deg";
      model["links"]["piston"]["line"]["angle"] = "0 deg";
      model["groups"][0]["near"][0] = "0.3 m";  // B at the inner dead centre, l_sh - r, at phi = 0
    }
    if (reading.constant) {
      model["loads"]["press"]["a"] = std::to_string(0.035e6 * std::exp(140 * 0.020)) + " Pa";
      model["loads"]["press"]["b"] = "0 1/m";
    }
    root["variables"] = YAML::Load(
        "{ground.C.x: {min: -2 m, max: 2 m}, ground.C.y: {min: -2 m, max: 2 m},"
        " links.crank.length: {min: 0.01 m, max: 1 m},"
        " links.rod.length: {min: 0.01 m, max: 1 m}, links.lever.length: {min: 0.1 m, max: 2 m},"
        " links.lever.points.D.x: {min: 0.01 m, max: 1 m}}");
    root["objective"] = YAML::Load("{minimize: peak_drive_torque}");
    const auto general = opt::make_problem(opt::ConfigNode(root, "<crank_press_four_bar linkage>", ""));
    ASSERT_EQ(general->variables()[1].name, "ground.C.y");
    ASSERT_EQ(general->variables()[5].name, "links.lever.points.D.x");
    const double sigma = reading.sigma;
    auto map = [sigma](const Eigen::VectorXd& x, Eigen::MatrixXd& j) {  // -> (l_sh, sigma y_c, r, l_sh, l_p, l)
      const double r = x[0], lsh = x[1], l = x[2], lp = x[3], y = std::sqrt(lp * lp - r * r);
      j = Eigen::MatrixXd::Zero(6, 4);
      j(0, 1) = 1, j(1, 0) = -sigma * r / y, j(1, 3) = sigma * lp / y;
      j(2, 0) = 1, j(3, 1) = 1, j(4, 3) = 1, j(5, 2) = 1;
      Eigen::VectorXd g(6);
      g << lsh, sigma * y, r, lsh, lp, l;
      return g;
    };
    press_designs(*hand, *general, metrics, map, at_contact, past_contact);
  }
  EXPECT_GT(at_contact, 50);  // the constant force's peaks at the contact's jump
  EXPECT_GT(past_contact, 300);
}

}  // namespace
