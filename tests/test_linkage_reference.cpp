// The general linkage against an independent reference: tests/ref/
// linkage_ref.py reads the same configs (a Watt II six-bar, a Stephenson III
// six-bar with a position-dependent process force, a Whitworth shaper with
// a forward-stroke cutting force, a wedge press whose PRP group pins a
// block on the wedge's line to a ram) and solves them another way: every link's
// pose from the loop-closure equations by Newton at 30 digits, the transfer
// functions from the constraint Jacobian's linear systems, the driving
// torque by virtual power and by a global Newton-Euler solve (they agree to
// ~1e-29; every joint's reaction comes out of that solve), maxima refined
// to ~1e-27 rad. Its output, tests/ref/linkage_ref.json, is read here:
// positions, transfer functions, slider coordinates, link rates, the
// driving torque, the kinetic energy, the joint reactions and the shaking
// force and moment at five crank angles, and the cycle maxima. Run it
// again with (a few minutes)
//   /usr/bin/python3 tests/ref/linkage_ref.py configs/linkage/watt2_sixbar.yaml
//     configs/linkage/stephenson3_sixbar.yaml configs/linkage/whitworth_shaper.yaml
//     configs/linkage/wedge_press.yaml > tests/ref/linkage_ref.json
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "mech/linkage/reactions.hpp"
#include "opt/registry.hpp"
#include "problems/linkage/description.hpp"
#include "cli.hpp"

namespace {

const std::string kSource = MECHOPT_SOURCE_DIR;

nlohmann::json reference() {
  std::ifstream in(kSource + "/tests/ref/linkage_ref.json");
  return nlohmann::json::parse(in);
}

double num(const nlohmann::json& j) { return std::stod(j.get<std::string>()); }

class Reference : public testing::TestWithParam<std::string> {};

TEST_P(Reference, StatesAtFiveCrankAngles) {
  const auto ref = reference()["configs"][GetParam()];
  const auto root = opt::ConfigNode::load(kSource + "/configs/linkage/" + GetParam() + ".yaml");
  const problems::linkage::Description d = problems::linkage::read_description(root);
  const auto& c = d.chain;
  mech::linkage::State<double> st;
  st.resize(c);
  const double w = c.defaults()[static_cast<size_t>(c.crank().speed)];
  for (const auto& [deg, at] : ref["at_deg"].items()) {
    SCOPED_TRACE(GetParam() + " at " + deg + " deg");
    const double phi = std::stod(deg) * std::numbers::pi / 180;
    ASSERT_TRUE(mech::linkage::solve(c, c.defaults().data(), phi, st));
    for (const auto& [name, p] : at["points"].items()) {
      const auto& q = st.point[static_cast<size_t>(c.find_point(name))];
      EXPECT_NEAR(q.x.v, num(p["x"]), 1e-13) << name;
      EXPECT_NEAR(q.y.v, num(p["y"]), 1e-13) << name;
      EXPECT_NEAR(q.x.d, num(p["dx"]), 1e-13) << name;
      EXPECT_NEAR(q.y.d, num(p["dy"]), 1e-13) << name;
      EXPECT_NEAR(q.x.dd, num(p["ddx"]), 1e-12) << name;
      EXPECT_NEAR(q.y.dd, num(p["ddy"]), 1e-12) << name;
    }
    for (const auto& [name, l] : at["links"].items()) {
      const auto t = st.angle(c.find_link(name));
      EXPECT_NEAR(std::remainder(t.v - num(l["angle"]), 2 * std::numbers::pi), 0, 1e-13) << name;
      EXPECT_NEAR(t.d, num(l["d"]), 1e-12) << name;
      EXPECT_NEAR(t.dd, num(l["dd"]), 1e-11) << name;
    }
    for (const auto& [name, s] : at["sliders"].items()) {
      const auto& x = st.slide[static_cast<size_t>(c.find_link(name))];
      EXPECT_NEAR(x.v, num(s["s"]), 1e-13) << name;
      EXPECT_NEAR(x.d, num(s["d"]), 1e-13) << name;
      EXPECT_NEAR(x.dd, num(s["dd"]), 1e-12) << name;
    }
    const auto p = mech::linkage::drive_point(c, c.defaults().data(), st);
    const double torque = num(at["drive_torque_virtual_power"]);
    EXPECT_NEAR(p.torque, torque, 1e-12 * std::max(1.0, std::abs(torque)));
    const double energy = num(at["kinetic_energy"]);
    EXPECT_NEAR(p.energy * w * w, energy, 1e-12 * std::max(1.0, energy));
    // The reactions group by group against the reference's global solve
    // (its reaction keys: POINT_LINK, its slides by the slider's name), to
    // 1e-12 of the largest.
    const mech::linkage::Joints j(c);
    mech::linkage::Reactions<double> r;
    r.resize(j, c);
    mech::linkage::reactions(c, j, c.defaults().data(), st, r);
    EXPECT_NEAR(r.torque, num(at["drive_torque_newton_euler"]), 1e-12 * std::max(1.0, std::abs(torque)));
    double scale = 1;
    for (const auto& [key, f] : at["reactions"].items()) scale = std::max(scale, std::hypot(num(f["x"]), num(f["y"])));
    ASSERT_EQ(at["reactions"].size(), j.pins.size());
    for (size_t i = 0; i < j.pins.size(); ++i) {
      const std::string key = c.point_names()[static_cast<size_t>(j.pins[i].point)] + "_" +
                              c.links()[static_cast<size_t>(j.pins[i].link)].name;
      ASSERT_TRUE(at["reactions"].contains(key)) << key;
      EXPECT_NEAR(r.x[i], num(at["reactions"][key]["x"]), 1e-12 * scale) << key;
      EXPECT_NEAR(r.y[i], num(at["reactions"][key]["y"]), 1e-12 * scale) << key;
    }
    ASSERT_EQ(at["slides"].size(), j.slides.size());
    for (size_t i = 0; i < j.slides.size(); ++i) {
      const auto& f = at["slides"][c.links()[static_cast<size_t>(j.slides[i])].name];
      EXPECT_NEAR(r.normal[i], num(f["normal"]), 1e-12 * scale) << i;
      EXPECT_NEAR(r.couple[i], num(f["couple"]), 1e-12 * scale) << i;  // N m; forces times ~1 m
    }
    EXPECT_NEAR(r.shaking_x, num(at["shaking_force"]["x"]), 1e-12 * scale);
    EXPECT_NEAR(r.shaking_y, num(at["shaking_force"]["y"]), 1e-12 * scale);
    EXPECT_NEAR(r.shaking_m, num(at["shaking_moment"]), 1e-12 * scale);
  }
}

TEST_P(Reference, CycleMaxima) {
  const auto ref = reference()["configs"][GetParam()];
  const auto p = opt::make_problem(opt::ConfigNode::load(kSource + "/configs/linkage/" + GetParam() + ".yaml"));
  const auto e = p->evaluate(p->initial_point(), opt::MetricSet::all(), false);
  ASSERT_TRUE(e.ok()) << e.message;
  auto expect = [&](const std::string& metric, double value) {
    EXPECT_NEAR(e.at(metric), value, 1e-12 * std::max(1.0, std::abs(value))) << metric;
  };
  for (const auto& [name, o] : ref["outputs"].items()) {
    expect(name + "_stroke", num(o["stroke"]));
    expect(name + "_peak_velocity", num(o["peak_velocity"]["value"]));
    expect(name + "_peak_acceleration", num(o["peak_acceleration"]["value"]));
    expect(name + "_time_ratio", num(o["time_ratio"]));
    for (const char* end : {"max", "min"}) {  // a rocker's angle: the same up to whole turns
      const double r = num(o[end]["value"]), turns = o["unit"] == "m" ? 0.0 : 2 * std::numbers::pi;
      const double ours = e.at(name + "_" + end);
      EXPECT_NEAR(turns > 0 ? std::remainder(ours - r, turns) : ours - r, 0, 1e-12 * std::max(1.0, std::abs(r)))
          << name << "_" << end;
    }
  }
  const auto& cycle = ref["cycle"];
  expect("peak_drive_torque", num(cycle["peak_drive_torque"]["value"]));
  expect("peak_kinetic_energy", num(cycle["peak_kinetic_energy"]["value"]));
  expect("mean_kinetic_energy", num(cycle["mean_kinetic_energy"]));
  const double rms = num(cycle["rms_drive_torque"]);
  expect("rms_drive_torque", rms);
  // The mean torque is the loads' work a revolution over 2 pi: zero for
  // the six-bars (gravity and the cushion are conservative, the rocker's
  // torque does no net work), to round-off of the torque's scale.
  EXPECT_NEAR(e.at("mean_drive_torque"), num(cycle["mean_drive_torque"]), 1e-12 * rms);
  double top = -1, least = 10;
  for (const auto& [group, a] : cycle["max_pressure_angle"].items()) top = std::max(top, num(a["value"]));
  for (const auto& [group, a] : cycle["min_transmission_angle"].items()) least = std::min(least, num(a["value"]));
  if (top >= 0) expect("max_pressure_angle", top);
  if (least < 10) expect("min_transmission_angle", least);
  for (const auto& [key, a] : cycle["peak_reaction"].items()) expect(key + "_peak_reaction", num(a["value"]));
  expect("peak_shaking_force", num(cycle["peak_shaking_force"]["value"]));
  expect("peak_shaking_moment", num(cycle["peak_shaking_moment"]["value"]));
}

// `mechopt kinematics` prints the same state the reference has.
TEST(Kinematics, PrintsTheStateAtTheAskedAngles) {
  const auto ref = reference()["configs"]["whitworth_shaper"]["at_deg"];
  const auto r = cli::run("kinematics " + kSource + "/configs/linkage/whitworth_shaper.yaml --angles '0, 37 deg'");
  ASSERT_TRUE(r.exited(0)) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  ASSERT_EQ(j["angles"].size(), 2u);
  const double w = j["crank_speed"];
  for (const auto& [i, deg] : {std::pair{0, "0"}, {1, "37"}}) {
    const auto& a = j["angles"][static_cast<size_t>(i)];
    const auto& at = ref[deg];
    EXPECT_NEAR(a["drive_torque"].get<double>(), num(at["drive_torque_virtual_power"]), 1e-9);
    EXPECT_NEAR(a["points"]["C"]["x"].get<double>(), num(at["points"]["C"]["x"]), 1e-13);
    EXPECT_NEAR(a["points"]["C"]["vx"].get<double>(), num(at["points"]["C"]["dx"]) * w, 1e-12);
    EXPECT_NEAR(a["sliders"]["ram"]["acceleration"].get<double>(), num(at["sliders"]["ram"]["dd"]) * w * w, 1e-11);
    EXPECT_NEAR(a["reactions"]["O4_lever"]["y"].get<double>(), num(at["reactions"]["O4_lever"]["y"]), 1e-9);
    EXPECT_NEAR(a["slides"]["ram"]["normal"].get<double>(), num(at["slides"]["ram"]["normal"]), 1e-9);
    EXPECT_NEAR(a["shaking_moment"].get<double>(), num(at["shaking_moment"]), 1e-9);
  }
  const auto wrong = cli::run("kinematics " + kSource + "/configs/slider_crank/stroke.yaml");
  EXPECT_TRUE(wrong.exited(2));
  EXPECT_NE(wrong.output.find("key 'problem': kinematics takes a `problem: linkage` config"), std::string::npos)
      << wrong.output;
}

INSTANTIATE_TEST_SUITE_P(Linkages, Reference,
                         testing::Values("watt2_sixbar", "stephenson3_sixbar", "whitworth_shaper", "wedge_press"));

}  // namespace
