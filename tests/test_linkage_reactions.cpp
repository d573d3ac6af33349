// The joint reactions group by group (mech/linkage/reactions.hpp) against
// what they must satisfy without reference to how they are solved:
// - the crank's moment equation gives the driving torque the virtual power
//   gives (dynamics.hpp), to round-off, on every shipped linkage config and
//   on a mechanism that has every kind of force and joint (gravity, masses,
//   a slider on a line carried by a moving link, a guide with an offset,
//   friction between two links, an opposing torque, a table force, a
//   spring between two moving points and one to the ground, an efficiency);
// - a massless wedge under a constant force F on its ram: the block on
//   the wedge's line at alpha presses the ram along the line's normal, so
//   the pin carries F / cos(alpha), the ram's guide F tan(alpha), the
//   block's line -F / cos(alpha), and the crank's torque is -F times the
//   ram's ds/dphi;
// - a massless centred slider-crank under a constant force F on its ram:
//   the rod is a two-force member, so every pin carries F / cos(beta) along
//   the rod, the guide F tan(beta), and the crank's torque is F times the
//   ram's ds/dphi (beta: the rod's angle to the line, sin beta = r sin(phi) / l).
// - a peak reaction where a load switches off moves with the design, and
//   one just before the switch is found (their gradients against a
//   central difference);
// - a peak torque, pin force and guide force at a force table's row moves
//   with the design (a massless slider-crank: their gradients in closed
//   form).
// The reactions themselves are checked against an independent global
// Newton-Euler solve in test_linkage_reference.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "mech/linkage/reactions.hpp"
#include "opt/config.hpp"
#include "opt/registry.hpp"
#include "problems/linkage/description.hpp"
#include "paths.hpp"

namespace {

using mech::linkage::Joints;
using mech::linkage::Reactions;
using mech::linkage::State;
using problems::linkage::Description;

constexpr double kPi = std::numbers::pi;
const std::string kSource = MECHOPT_SOURCE_DIR;

Description read(const std::string& yaml) {
  return problems::linkage::read_description(opt::ConfigNode::parse(yaml, "<reactions>"));
}

// A massless centred slider-crank, crank 0.2 m, rod 0.8 m, 60 rpm, its ram
// under the load `press` (its keys after the link), then `after` (the
// config's keys after the model).
std::string massless_slider_crank(const std::string& press, const std::string& after = "") {
  return "problem: linkage\nmodel:\n"
         "  ground: {O: [0 m, 0 m]}\n"
         "  crank: {link: crank, pivot: O, joint: A, phase: 0 deg, speed: 60 rpm}\n"
         "  links:\n"
         "    crank: {length: 0.2 m}\n"
         "    rod: {length: 0.8 m}\n"
         "    ram: {line: {fixed_to: ground, through: O, angle: 0 deg}}\n"
         "  groups:\n"
         "    - {type: RRP, links: [rod, ram], from: A, joint: B, branch: 1}\n"
         "  loads:\n"
         "    press: {link: ram, " +
         press + "}\n" + after;
}

// Newton-Euler's torque against virtual power's at 72 crank angles: equal
// to 1e-12 of the largest.
void expect_torques_agree(const Description& d, const std::string& name) {
  const auto& c = d.chain;
  const Joints j(c);
  State<double> st;
  st.resize(c);
  Reactions<double> r;
  r.resize(j, c);
  const double* v = c.defaults().data();
  double scale = 1;
  std::vector<std::pair<double, double>> torques;
  for (int i = 0; i < 72; ++i) {
    const double phi = 2 * kPi * (i + 0.37) / 72;
    ASSERT_TRUE(mech::linkage::solve(c, v, phi, st)) << name << " at " << phi;
    mech::linkage::reactions(c, j, v, st, r);
    const double m = mech::linkage::drive_point(c, v, st).torque;
    torques.emplace_back(m, r.torque);
    scale = std::max(scale, std::abs(m));
  }
  for (size_t i = 0; i < torques.size(); ++i)
    EXPECT_NEAR(torques[i].second, torques[i].first, 1e-12 * scale) << name << " at point " << i;
}

TEST(LinkageReactions, TorqueEqualsVirtualPowerOnEveryConfig) {
  int n = 0;
  for (const auto& f : std::filesystem::directory_iterator(kSource + "/configs/linkage")) {
    const Description d = problems::linkage::read_description(opt::ConfigNode::load(f.path().string()));
    if (!d.has_dynamics()) continue;
    expect_torques_agree(d, f.path().filename().string());
    ++n;
  }
  EXPECT_GE(n, 5);
}

// A crank-rocker whose rocker carries a slider's line, a rod from the
// crank pin driving that slider, a second crank-driven guide with an
// offset, and a shoe sliding on a line the first slider carries (turning
// with the rocker), pinned to a ram on a line the guide carries (a PRP
// group: both its lines' forces reach the torque): every joint type, every
// force.
TEST(LinkageReactions, TorqueEqualsVirtualPowerWithEveryForce) {
  const Description d = read(
      "problem: linkage\nmodel:\n"
      "  gravity: on\n"
      "  ground: {O: [0 m, 0 m], O4: [0.3 m, 0 m], Q: [-0.25 m, 0.05 m], G0: [0.1 m, -0.4 m]}\n"
      "  crank: {link: crank, pivot: O, joint: A, phase: 10 deg, speed: 90 rpm}\n"
      "  links:\n"
      "    crank: {length: 0.1 m, mass_per_length: 20 kg/m, points: {K: [0.05 m, 0.03 m]}}\n"
      "    coupler: {length: 0.4 m, mass: 3 kg, cg: [0.2 m, 0.02 m], inertia: 0.05 kg m^2}\n"
      "    rocker: {length: 0.3 m, mass: 4 kg, cg: [0.1 m, 0 m], inertia: 0.04 kg m^2,\n"
      "             points: {E: [0.15 m, 0 m]}}\n"
      "    rod: {length: 0.45 m, mass_per_length: 8 kg/m}\n"
      "    sleeve: {mass: 1.5 kg, inertia: 0.01 kg m^2, line: {fixed_to: rocker, through: E, angle: 0 deg, offset: 0.01 m}}\n"
      "    block: {mass: 0.8 kg}\n"
      "    arm: {length: 0.4 m, offset: 0.02 m, mass: 2 kg, cg: [0.1 m, 0.01 m], inertia: 0.03 kg m^2}\n"
      "    shoe: {mass: 0.6 kg, inertia: 0.004 kg m^2, line: {fixed_to: sleeve, through: S, angle: 60 deg, offset: 0.02 m}}\n"
      "    ram2: {mass: 2.5 kg, line: {fixed_to: arm, through: Q, angle: 45 deg, offset: -0.01 m}}\n"
      "  groups:\n"
      "    - {type: RRR, links: [coupler, rocker], from: [A, O4], joint: B, branch: 1}\n"
      "    - {type: RRP, links: [rod, sleeve], from: A, joint: S, branch: 1}\n"
      "    - {type: RPR, links: [block, arm], from: K, pivot: Q}\n"
      "    - {type: PRP, links: [shoe, ram2], joint: P2}\n"
      "  loads:\n"
      "    bearing: {at: B, friction_torque: 4 N m}\n"
      "    drag: {link: rocker, torque: 30 N m, opposing: true}\n"
      "    work: {link: sleeve, table: {over: position, unit: [m, N], rows: [[-0.5, 200], [0, -100], [0.5, 300]]},\n"
      "           efficiency: 0.85}\n"
      "    brake: {link: arm, torque: -12 N m, when: forward}\n"
      "    stamp: {link: ram2, force: -150 N, when: forward}\n"
      "    scrape: {link: shoe, force: 40 N, opposing: true}\n"
      "    hinge: {at: P2, friction_torque: 1.5 N m}\n"
      "  springs:\n"
      "    tie: {between: [S, K], rate: 2 kN/m, free_length: 0.3 m}\n"
      "    anchor: {between: [B, G0], rate: 1 kN/m, free_length: 0.5 m}\n"
      "    return: {between: [P2, K], rate: 0.5 kN/m, free_length: 0.4 m}\n");
  expect_torques_agree(d, "every force");
}

TEST(LinkageReactions, MasslessWedgePressesAlongTheNormal) {
  const double F = -2000, alpha = -20 * kPi / 180;  // a force down on the ram
  const Description d = read(
      "problem: linkage\nmodel:\n"
      "  ground: {O: [0 m, 0 m], R: [0.6 m, 0.1 m]}\n"
      "  crank: {link: crank, pivot: O, joint: A, phase: 0 deg, speed: 60 rpm}\n"
      "  links:\n"
      "    crank: {length: 0.08 m}\n"
      "    rod: {length: 0.35 m}\n"
      "    wedge: {line: {fixed_to: ground, through: O, angle: 0 deg}}\n"
      "    block: {line: {fixed_to: wedge, through: C, angle: -20 deg, offset: 0.04 m}}\n"
      "    ram: {line: {fixed_to: ground, through: R, angle: 90 deg}}\n"
      "  groups:\n"
      "    - {type: RRP, links: [rod, wedge], from: A, joint: C, branch: 1}\n"
      "    - {type: PRP, links: [block, ram], joint: B}\n"
      "  loads:\n"
      "    press: {link: ram, force: -2 kN}\n");
  const auto& c = d.chain;
  const Joints j(c);
  ASSERT_EQ(j.pins.size(), 4u);    // O on the crank, A and C on the rod, B on the ram
  ASSERT_EQ(j.slides.size(), 3u);  // the wedge, the block, the ram
  ASSERT_EQ(c.point_names()[static_cast<size_t>(j.pins[3].point)] + "_" + c.links()[static_cast<size_t>(j.pins[3].link)].name,
            "B_ram");
  State<double> st;
  st.resize(c);
  Reactions<double> re;
  re.resize(j, c);
  const double pin = std::abs(F) / std::cos(alpha);
  for (int i = 0; i < 24; ++i) {
    const double phi = 2 * kPi * (i + 0.25) / 24;
    ASSERT_TRUE(mech::linkage::solve(c, c.defaults().data(), phi, st));
    mech::linkage::reactions(c, j, c.defaults().data(), st, re);
    // On the ram from the block: along the block's line's normal n1 =
    // (-sin alpha, cos alpha), N1 n1 with N1 = -F / cos(alpha).
    EXPECT_NEAR(re.x[3], -F * -std::sin(alpha) / std::cos(alpha), 1e-12 * pin) << phi;
    EXPECT_NEAR(re.y[3], -F, 1e-12 * pin) << phi;
    EXPECT_NEAR(std::hypot(re.x[3], re.y[3]), pin, 1e-12 * pin) << phi;
    EXPECT_NEAR(re.normal[1], -F / std::cos(alpha), 1e-12 * pin) << phi;  // the block on the wedge's line
    EXPECT_NEAR(re.normal[2], F * std::tan(alpha), 1e-12 * pin) << phi;   // the ram on its line, n2 = -x
    for (int k : {1, 2}) EXPECT_NEAR(re.couple[static_cast<size_t>(k)], 0, 1e-12 * pin) << phi;
    const double ds = st.slide[static_cast<size_t>(c.find_link("ram"))].d;
    EXPECT_NEAR(re.torque, -F * ds, 1e-12 * pin) << phi;
  }
}

TEST(LinkageReactions, TwoForceRodOfAMasslessSliderCrank) {
  const double r = 0.2, l = 0.8, F = -1500;  // a force against +x on the ram
  const Description d = read(massless_slider_crank("force: -1500 N"));
  const auto& c = d.chain;
  const Joints j(c);
  ASSERT_EQ(j.pins.size(), 3u);  // O on the crank, A and B on the rod
  ASSERT_EQ(j.slides.size(), 1u);
  State<double> st;
  st.resize(c);
  Reactions<double> re;
  re.resize(j, c);
  for (int i = 0; i < 24; ++i) {
    const double phi = 2 * kPi * (i + 0.25) / 24;
    ASSERT_TRUE(mech::linkage::solve(c, c.defaults().data(), phi, st));
    mech::linkage::reactions(c, j, c.defaults().data(), st, re);
    const double beta = std::asin(r * std::sin(phi) / l);
    const double rod = std::abs(F) / std::cos(beta);
    for (size_t p = 0; p < 3; ++p) EXPECT_NEAR(std::hypot(re.x[p], re.y[p]), rod, 1e-12 * rod) << p << " at " << phi;
    // F < 0 pushes the ram back toward the crank: the rod is in
    // compression, so the crank pin pushes it along B - A.
    const double ax = std::cos(beta), ay = -std::sin(beta);  // (B - A) / l
    EXPECT_NEAR(re.x[1] * ax + re.y[1] * ay, rod, 1e-12 * rod) << phi;
    EXPECT_NEAR(std::abs(re.normal[0]), std::abs(F) * std::abs(std::tan(beta)), 1e-12 * rod) << phi;
    EXPECT_NEAR(re.couple[0], 0, 1e-12 * rod) << phi;
    // x_B = r cos(phi) + l cos(beta): dx_B/dphi = -r sin(phi) (1 + r cos(phi) / (l cos(beta))).
    const double xb_d = -r * std::sin(phi) * (1 + r * std::cos(phi) / (l * std::cos(beta)));
    EXPECT_NEAR(re.torque, -F * xb_d, 1e-12 * rod) << phi;
  }
}

}  // namespace

namespace {

// A peak reaction at a load's switch moves with the design: the four-bar
// press's crank bearing peaks where the pressing force (forward only)
// stops at the inner dead centre, a jump of the force, not a stationary
// point. The lever's pivot peaks just before it (0.2 deg), a smooth
// maximum the switch must not hide: the switch is a kink of its search.
// Each gradient in the crank's length against a central difference (both
// peaks are smooth in it there: equal slopes either side, measured).
TEST(LinkageReactions, PeakAtASwitchMovesWithTheDesign) {
  const auto root = opt::ConfigNode::load(kSource + "/configs/linkage/crank_press_four_bar.yaml");
  YAML::Node over;
  over["variables"]["links.crank.length"]["min"] = "0.15 m";
  over["variables"]["links.crank.length"]["max"] = "0.25 m";
  const auto p = opt::make_problem(root.with(over, "<press>"));
  const Eigen::VectorXd x = p->initial_point();
  for (const std::string metric : {"O_crank_peak_reaction", "C_lever_peak_reaction"}) {
    const auto e = p->evaluate(x, {metric}, true);
    ASSERT_TRUE(e.ok()) << e.message;
    const double h = 1e-5;
    auto at = [&](double r) { return p->evaluate(Eigen::VectorXd::Constant(1, r), {metric}, false).at(metric); };
    const double fd = (at(x[0] + h) - at(x[0] - h)) / (2 * h);
    const double ad = e[p->metric_id(metric)].gradient[0];
    EXPECT_NEAR(ad, fd, 1e-4 * std::abs(fd)) << metric;
  }
}

// A peak at a table's row moves with the design: a massless centred
// slider-crank (crank r, rod l) under a force table over the ram's
// position, a sharp triangle to F at x, peaks in the torque, the pins'
// forces and the guide's where the ram crosses x (once each stroke, equal
// by symmetry): a kink of each, not a stationary point. There r cos(phi) =
// A = (x^2 + r^2 - l^2) / (2 x), r sin(phi) = N = sqrt(r^2 - A^2) and,
// with D = x^2 + l^2 - r^2, the rod's cos(beta) = (x - A) / l = D / (2 x l)
// and |ds/dphi| = N x / (x - A) = 2 x^2 N / D: the torque |F| 2 x^2 N / D,
// each pin |F| / cos(beta) = |F| 2 x l / D, the guide |F| tan(beta) =
// |F| 2 x N / D, their gradients in r and l in closed form (each peak's
// slope in phi is not zero at the row: Danskin at a fixed crank angle
// would leave out the row's motion).
TEST(LinkageReactions, PeakAtATableRowMovesWithTheDesign) {
  const double r = 0.2, l = 0.8, x = 0.85, F = 2000;
  const auto p = opt::make_problem(opt::ConfigNode::parse(
      massless_slider_crank("table: {over: position, unit: [m, N], rows: [[0.83, 0], [0.85, -2000], [0.87, 0]]}",
                            "variables:\n"
                            "  links.crank.length: {min: 0.1 m, max: 0.3 m}\n"
                            "  links.rod.length: {min: 0.6 m, max: 1 m}\n"),
      "<row>"));
  const double A = (x * x + r * r - l * l) / (2 * x), N = std::sqrt(r * r - A * A), D = x * x + l * l - r * r;
  // d/dr and d/dl of A, N and D.
  const double dA[2] = {r / x, -l / x}, dD[2] = {-2 * r, 2 * l};
  const double dN[2] = {(r - A * dA[0]) / N, -A * dA[1] / N};
  const double torque = F * 2 * x * x * N / D, pin = F * 2 * x * l / D;
  double d_torque[2], d_pin[2];
  for (int i = 0; i < 2; ++i) {
    d_torque[i] = F * 2 * x * x * (dN[i] * D - N * dD[i]) / (D * D);
    d_pin[i] = F * 2 * x * ((i == 1) * D - l * dD[i]) / (D * D);
  }
  const std::vector<std::string> pins = {"O_crank_peak_reaction", "A_rod_peak_reaction", "B_rod_peak_reaction"};
  std::vector<std::string> metrics = pins;
  metrics.insert(metrics.end(), {"peak_drive_torque", "ram_peak_guide_force"});
  const auto e = p->evaluate(p->initial_point(), metrics, true);
  ASSERT_TRUE(e.ok()) << e.message;
  auto expect = [&](const std::string& m, double value, const double* grad) {
    EXPECT_NEAR(e.at(m), value, 1e-12 * value) << m;
    for (int i = 0; i < 2; ++i)
      EXPECT_NEAR(e[p->metric_id(m)].gradient[i], grad[i], 1e-9 * std::abs(grad[i])) << m << " in variable " << i;
  };
  expect("peak_drive_torque", torque, d_torque);
  for (const std::string& m : pins) expect(m, pin, d_pin);
  const double d_guide[2] = {d_torque[0] / x, d_torque[1] / x};  // the guide's: the torque's over x
  expect("ram_peak_guide_force", torque / x, d_guide);
}

}  // namespace
