// The elastic drive on a linkage (mech/linkage/machine.hpp,
// docs/design/linkage.md section 9): seed 001's twin slider-crank written
// as a linkage against the hand-written drive (an independent
// implementation: closed-form slider-cranks, mech/elastic_drive.hpp) at
// the paper's design, in its exact kinematics and with the carts' rollers
// as opposing forces; a `when` load against the slider-crank's closed
// form; the machine's failures; the elastic_drive problem's
// `model.machine`.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "mech/drive_dynamics.hpp"
#include "mech/linkage/machine.hpp"
#include "opt/config.hpp"
#include "opt/problem.hpp"
#include "opt/registry.hpp"
#include "problems/linkage/description.hpp"
#include "paths.hpp"

namespace {

using mech::Status;
using mech::linkage::LinkageMachine;
using problems::linkage::Description;

constexpr double kPi = std::numbers::pi;
constexpr double kStart = 10.686;  // synchronous crank speed 104.72 / 9.8

// The drive's twin slider-crank as a linkage (the config says how).
const std::string kTwin = std::string(MECHOPT_SOURCE_DIR) + "/configs/elastic_drive/linkage_twin.yaml";

Description description(const std::string& yaml) {
  return problems::linkage::read_model(opt::ConfigNode::parse(yaml, "<machine>"));
}
Description twin() { return problems::linkage::read_model(opt::ConfigNode::load(kTwin).at("model").at("machine")); }

// The hand-written drive the linkage describes: the configs' scene
// (configs/elastic_drive/*.yaml) in the exact kinematics, without the
// guides' friction, so that the carts' resistance is the rollers'
// horizontal force against their motion.
mech::ElasticDrive hand_written() {
  mech::ElasticDrive d;
  d.roller_horizontal = 3562;
  d.roller_vertical = d.cart_weight;
  d.guide_friction = 0;
  d.resistance_opposes_motion = true;
  d.kinematics = mech::Kinematics::exact;
  return d;
}

// Each number to this fraction of its largest magnitude over the cycle:
// the two sides compute the same functions by other formulas (the
// slider-crank's closed form and its derivatives by hand; a circle-line
// intersection on jets, and on a Dual in phi for the slopes), so they
// agree to round-off (measured: the values to 8e-16, their slopes in phi2
// to 2e-15).
constexpr double kSameFunction = 1e-12;

TEST(LinkageDrive, MechanismStateEqualsTheHandWrittenDrives) {
  const Description d = twin();
  const LinkageMachine machine(d.chain, d.chain.defaults());
  const mech::ElasticDrive a = hand_written();
  mech::ElasticDrive b = a;
  b.machine = &machine;
  const mech::PhaseRotation shift(a.phase_shift);
  // The scales: each quantity's largest magnitude over a revolution.
  double scale[3] = {};
  for (int k = 0; k < 720; ++k) {
    const auto m = mech::mechanism_state(a, 2 * kPi * k / 720, 1.0, shift);
    scale[0] = std::max(scale[0], std::abs(m.inertia));
    scale[1] = std::max(scale[1], std::abs(m.half_inertia_derivative));
    scale[2] = std::max(scale[2], std::abs(m.resistance));
  }
  using D3 = mech::DualN<3>;
  for (int k = -97; k <= 2 * 97; ++k) {
    const double phi = 2 * kPi * k / 97 + 0.01;
    for (double w : {-10.0, -1e-3, -2e-4, 0.0, 3e-4, 1e-3, 0.5, 10.5}) {
      SCOPED_TRACE("phi2 = " + std::to_string(phi) + ", w2 = " + std::to_string(w));
      const auto x = mech::mechanism_state(a, phi, w, shift), y = mech::mechanism_state(b, phi, w, shift);
      EXPECT_NEAR(y.inertia, x.inertia, kSameFunction * scale[0]);
      EXPECT_NEAR(y.half_inertia_derivative, x.half_inertia_derivative, kSameFunction * scale[1]);
      EXPECT_NEAR(y.resistance, x.resistance, kSameFunction * scale[2]);
      // The start-up's Jacobian seeds phi2 (here with w2 as well): the
      // linkage's slopes in phi2 come from its chain on a Dual in phi.
      const D3 p(phi, 3, 0), v(w, 3, 2);
      const auto xd = mech::mechanism_state(a, p, v, shift), yd = mech::mechanism_state(b, p, v, shift);
      const std::pair<const D3*, const D3*> pairs[] = {{&xd.inertia, &yd.inertia},
                                                       {&xd.half_inertia_derivative, &yd.half_inertia_derivative},
                                                       {&xd.resistance, &yd.resistance}};
      for (int i = 0; i < 3; ++i) {
        const D3 &want = *pairs[i].first, &got = *pairs[i].second;
        EXPECT_NEAR(got.value(), want.value(), kSameFunction * scale[i]);
        // d/dphi2 on the same scale per radian; d/dw2 (the resistance's
        // only) that over kRestSpeed, the tanh's slope at rest.
        for (int j = 0; j < 3; ++j)
          EXPECT_NEAR(got.derivatives()[j], want.derivatives()[j],
                      kSameFunction * scale[i] / (j == 2 ? mech::kRestSpeed : 1.0))
              << "quantity " << i << ", derivative " << j;
      }
    }
  }
}

// Both drives integrate functions equal to 1e-15, yet not the same bits:
// the integrators' steps and Newton iterations part, and the results differ
// by the integration's own error. The shooting accepts a periodic start to
// 100 rtol (kPeriodicTol) and a start-up's peak is sampled every 1 ms, so
// at rtol = 1e-8 (the configs') they agree to 1e-6 relative (measured: the
// steady metrics to 3e-7 with BDF, 2e-9 with ERK; the start-up's peak to
// 5e-7); at rtol = 1e-12 to 3e-9 (measured: 2e-10, but ERK's least
// coupling moment 1e-9: the extrema are found on the dense output, of
// lower order than the steps). The difference shrinks with the tolerance:
// no difference of the models is left.
struct Tolerance {
  double rtol, same;
};
constexpr Tolerance kIntegrations[] = {{1e-8, 1e-6}, {1e-12, 3e-9}};

void expect_close(double got, double want, double tolerance, const char* what) {
  EXPECT_NEAR(got, want, tolerance * std::max(std::abs(want), 1.0)) << what;
}

TEST(LinkageDrive, SteadyStateAndStartupEqualTheHandWrittenDrives) {
  const Description d = twin();
  const LinkageMachine machine(d.chain, d.chain.defaults());
  mech::ElasticDrive a = hand_written(), b = a;
  b.machine = &machine;
  for (const Tolerance& t : kIntegrations)
    for (auto method : {mech::OdeMethod::bdf, mech::OdeMethod::erk}) {
      SCOPED_TRACE((method == mech::OdeMethod::bdf ? "bdf, rtol " : "erk, rtol ") + std::to_string(t.rtol));
      mech::OdeOptions o;
      o.method = method;
      o.rtol = o.atol = t.rtol;
      const auto x = mech::steady_by_shooting(a, o, 0, 0, kStart), y = mech::steady_by_shooting(b, o, 0, 0, kStart);
      ASSERT_EQ(x.status, Status::ok) << x.message;
      ASSERT_EQ(y.status, Status::ok) << y.message;
      const std::pair<double mech::SteadyCycle::*, const char*> metrics[] = {
          {&mech::SteadyCycle::coupling_peak, "peak"},
          {&mech::SteadyCycle::coupling_rms, "rms"},
          {&mech::SteadyCycle::coupling_min, "min"},
          {&mech::SteadyCycle::coupling_max, "max"},
          {&mech::SteadyCycle::mean_speed, "mean speed"},
          {&mech::SteadyCycle::speed_irregularity, "irregularity"},
          {&mech::SteadyCycle::mean_motor_power, "motor power"},
          {&mech::SteadyCycle::mean_resistance_power, "resistance power"},
          {&mech::SteadyCycle::w20, "w2(0)"}};
      for (const auto& [m, name] : metrics) expect_close(y.*m, x.*m, t.same, name);
      // The start-up (BDF's Newton matrix takes the machine's slopes in phi2).
      const auto sx = mech::simulate_startup(a, o, 2.0, 1e-3, &x, kStart);
      const auto sy = mech::simulate_startup(b, o, 2.0, 1e-3, &y, kStart);
      ASSERT_EQ(sx.status, Status::ok) << sx.message;
      ASSERT_EQ(sy.status, Status::ok) << sy.message;
      expect_close(sy.peak_coupling, sx.peak_coupling, t.same, "start-up peak");
      expect_close(sy.final_speed, sx.final_speed, t.same, "final speed");
      EXPECT_EQ(sy.time_to_steady, sx.time_to_steady);
    }
}

// A slider-crank (r = 0.1 m, l = 0.4 m, a centred line through the crank's
// pivot) with a 1 kg m^2 crank and a 20 kg slider, pushed by 1000 N on its
// forward stroke only and braked by 300 N on its return: the torque
// against the drive is -F x'(phi) where the load acts, x' = -r sin(phi) -
// r^2 sin(phi) cos(phi) / sqrt(l^2 - r^2 sin^2(phi)); turning back (w2 <
// 0) each acts on the other half of the cycle (its stroke in time), the
// braking against the actual motion.
constexpr const char* kStrokes = R"(
ground: {O: [0 m, 0 m]}
crank: {link: crank, pivot: O, joint: A, speed: 1 rad/s}
links:
  crank: {length: 0.1 m, mass: 0 kg, inertia: 1 kg m^2}
  rod: {length: 0.4 m}
  ram: {mass: 20 kg, line: {fixed_to: ground, through: O, angle: 0 deg}}
groups:
  - {type: RRP, links: [rod, ram], from: A, joint: B, branch: 1}
loads:
  push: {link: ram, force: 1000 N, when: forward}
  brake: {link: ram, force: 300 N, opposing: true, when: return}
)";

TEST(LinkageDrive, AWhenLoadActsOnItsStrokeInTime) {
  const Description d = description(kStrokes);
  const LinkageMachine m(d.chain, d.chain.defaults());
  const double r = 0.1, l = 0.4;
  for (int k = 0; k < 64; ++k) {
    const double phi = 2 * kPi * (k + 0.3) / 64, s = std::sin(phi), c = std::cos(phi);
    const double xp = -r * s - r * r * s * c / std::sqrt(l * l - r * r * s * s);
    // Turning forward the slider runs along +x where x' > 0; back, where x' < 0.
    const double forward = (xp > 0 ? -1000 * xp : 0.0) + (xp < 0 ? 300 * std::abs(xp) : 0.0);
    const double back = (xp < 0 ? -1000 * xp : 0.0) + (xp > 0 ? -300 * std::abs(xp) : 0.0);
    const mech::MachinePoint p = m.state(phi, false);
    EXPECT_NEAR(p.fixed.v + p.opposing.v, forward, 1e-12 * 1000 * r);
    EXPECT_NEAR(p.fixed.v - p.opposing.v, back, 1e-12 * 1000 * r);
    mech::ElasticDrive drive;
    drive.machine = &m;
    const mech::PhaseRotation shift(0);
    EXPECT_NEAR(mech::mechanism_state(drive, phi, 10.0, shift).resistance, forward, 1e-12 * 1000 * r);
    EXPECT_NEAR(mech::mechanism_state(drive, phi, -10.0, shift).resistance, back, 1e-12 * 1000 * r);
    EXPECT_NEAR(mech::mechanism_state(drive, phi, 0.0, shift).resistance, (forward + back) / 2, 1e-12 * 1000 * r);
  }
}

TEST(LinkageDrive, AMachineThatCannotRunIsAStatus) {
  mech::ElasticDrive drive = hand_written();
  // A lone slider without a crank inertia stops dead at each dead centre:
  // its reduced inertia m x'^2 vanishes there.
  const Description lone = description(
      "ground: {O: [0 m, 0 m]}\n"
      "crank: {link: crank, pivot: O, joint: A, speed: 1 rad/s, phase: 10 deg}\n"
      "links:\n  crank: {length: 0.2 m}\n  rod: {length: 0.8 m}\n"
      "  cart: {mass: 1000 kg, line: {fixed_to: ground, through: O, angle: 0 deg}}\n"
      "groups:\n  - {type: RRP, links: [rod, cart], from: A, joint: B, branch: 1}\n");
  const LinkageMachine still(lone.chain, lone.chain.defaults());
  drive.machine = &still;
  auto s = mech::steady_by_shooting(drive, {}, 0, 0, kStart);
  EXPECT_EQ(s.status, Status::invalid_parameter);
  EXPECT_NE(s.message.find("inertia vanishes"), std::string::npos) << s.message;
  // The twin with rods shorter than the crank (as a design may set them).
  const Description d = twin();
  std::vector<double> v = d.chain.defaults();
  for (const char* rod : {"links.rod1.length", "links.rod2.length"})
    for (size_t i = 0; i < v.size(); ++i)
      if (d.chain.value_names()[i] == rod) v[i] = 0.15;
  const LinkageMachine short_rods(d.chain, v);
  drive.machine = &short_rods;
  s = mech::steady_by_shooting(drive, {}, 0, 0, kStart);
  EXPECT_EQ(s.status, Status::cannot_assemble);
  EXPECT_NE(s.message.find("RRP (rod2, cart2) cannot assemble at crank angle 0 deg"), std::string::npos) << s.message;
  EXPECT_EQ(mech::simulate_startup(drive, {}, 1.0, 1e-3).status, Status::cannot_assemble);
}

// The twin's config (its machine) with `over` over it.
std::unique_ptr<opt::Problem> twin_problem(const std::string& over) {
  return opt::make_problem(opt::ConfigNode::load(kTwin).with(YAML::Load(over), "over.yaml"));
}

TEST(LinkageDrive, TheProblemTakesItsMachineFromTheConfig) {
  const auto with = twin_problem(
      "variables: {stiffness: {min: 5e4, max: 5e5}, machine.links.rod1.length: {min: 0.6 m, max: 1 m}}\n");
  const auto without = opt::make_problem(opt::ConfigNode::parse(
      "problem: elastic_drive\nmodel: {ode: {method: erk}, kinematics: exact, guide_friction: 0}\n"
      "variables: {stiffness: {min: 5e4, max: 5e5}, damping: {min: 100, max: 20000}}\n",
      "<without>"));
  // The variables in the table's order: stiffness, damping, the machine's rows.
  ASSERT_EQ(with->variables().size(), 3u);
  EXPECT_EQ(with->variables()[2].name, "machine.links.rod1.length");
  Eigen::VectorXd x(3);
  x << 150000, 3000, 0.8;
  const std::vector<std::string> metrics = {"peak_coupling_torque", "rms_coupling_torque", "mean_crank_speed"};
  const opt::Evaluation e = with->evaluate(x, metrics, false), f = without->evaluate(x.head(2), metrics, false);
  ASSERT_TRUE(e.ok()) << e.message;
  ASSERT_TRUE(f.ok()) << f.message;
  for (const auto& m : metrics)
    expect_close(e[with->metric_id(m)].value, f[without->metric_id(m)].value, kIntegrations[0].same, m.c_str());
  // The machine's rows are the drive's model values and DOE factors.
  bool found = false;
  for (const auto& row : opt::model_parameters(opt::ConfigNode::load(kTwin)))
    found = found || row.name == "machine.loads.rollers1.force";
  EXPECT_TRUE(found);
  // A longer rod moves its cart otherwise: another design, another result.
  x[2] = 1.0;
  EXPECT_NE(with->evaluate(x, metrics, false)[with->metric_id(metrics[0])].value,
            e[with->metric_id(metrics[0])].value);
}

TEST(LinkageDrive, ConfigErrorsAreLocated) {
  auto error = [](const std::function<void()>& make) -> std::string {
    try {
      make();
    } catch (const opt::ConfigError& e) {
      return e.what();
    }
    return "no error";
  };
  // A key of the twin slider-crank beside a machine.
  std::string m = error([] { twin_problem("model: {rod_length: 0.9 m}\n"); });
  EXPECT_NE(m.find("key 'model.rod_length'"), std::string::npos) << m;
  EXPECT_NE(m.find("machine replaces the twin"), std::string::npos) << m;
  m = error([] { twin_problem("variables: {rod_length: {min: 0.6 m, max: 1 m}}\n"); });
  EXPECT_NE(m.find("key 'variables.rod_length'"), std::string::npos) << m;
  // The description's own errors name their keys under model.machine.
  m = error([] { twin_problem("model: {machine: {links: {rod1: {length: -1 m}}}}\n"); });
  EXPECT_NE(m.find("key 'model.machine.links.rod1.length'"), std::string::npos) << m;
  // A machine without masses: the linkage's words, where it is written.
  m = error([] {
    opt::make_problem(opt::ConfigNode::parse(
        "problem: elastic_drive\nmodel:\n  machine:\n    ground: {O: [0 m, 0 m]}\n"
        "    crank: {link: crank, pivot: O, joint: A, speed: 1 rad/s}\n    links: {crank: {length: 0.2 m}}\n"
        "    groups: []\n",
        "drive.yaml"));
  });
  EXPECT_NE(m.find("drive.yaml:4:"), std::string::npos) << m;
  EXPECT_NE(m.find("needs masses (a link's mass or mass_per_length)"), std::string::npos) << m;
  m = error([] { opt::make_problem(opt::ConfigNode::parse("problem: elastic_drive\nmodel: {machine: 3}\n", "d.yaml")); });
  EXPECT_NE(m.find("key 'model.machine'"), std::string::npos) << m;
}

}  // namespace
