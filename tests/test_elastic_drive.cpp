// The elastic drive (seed 001) on SUNDIALS: motor and inertia closed forms,
// physics identities of the steady cycle, the two steady-state methods
// against each other, limits, and the failures reported as statuses.
#include <gtest/gtest.h>

#include <cmath>

#include "mech/drive_dynamics.hpp"
#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "problems/registry.hpp"

namespace {

using mech::DynamicsStatus;

// The scene of configs/elastic_drive/*.yaml: seed 001's drive with seed
// 000's cart force and a start at synchronous speed.
mech::ElasticDrive scene(double k = 2000) {
  mech::ElasticDrive d;
  d.damping = k;
  d.roller_horizontal = 3562;
  d.roller_vertical = d.cart_weight;
  d.resistance_opposes_motion = true;
  return d;
}
constexpr double kStart = 10.686;  // synchronous crank speed 104.72 / 9.8

TEST(InductionMotor, KlossFormulaAndCriticalSlip) {
  const mech::InductionMotor m;
  // eq. (27a): s_kr = s_n (lambda + sqrt(lambda^2 - 1)) = 0.025 (2 + sqrt 3) = 0.0933 (paper).
  EXPECT_NEAR(mech::InductionMotor::critical_slip_from(0.025, 2.0), 0.0933, 5e-5);
  EXPECT_NEAR(m.torque(m.synchronous_speed * (1 - m.critical_slip)), m.critical_torque, 1e-9);
  EXPECT_EQ(m.torque(m.synchronous_speed), 0.0);
  EXPECT_LT(m.torque(m.synchronous_speed * 1.01), 0.0);  // generator above synchronous speed
}

TEST(ElasticDrive, MotorSideInertiaIsEquation1) {
  const mech::ElasticDrive d;
  EXPECT_NEAR(d.motor_side_inertia(), (0.138 + 0.32) * 1.2 * 9.8 * 9.8, 1e-12);
}

TEST(SteadyCycle, EnergyBalanceAndPeriodicity) {
  // Over a periodic cycle the motor's work equals the resistance's plus the
  // damper's (the kinetic and elastic energies return): 1e-5 relative, the
  // integration and trapezoidal-dissipation error at rtol 1e-8 and 720 samples.
  const auto s = mech::steady_by_shooting(scene(), {}, 720, 3.0, kStart);
  ASSERT_EQ(s.status, DynamicsStatus::ok) << s.message;
  EXPECT_NEAR(s.mean_motor_power, s.mean_resistance_power + s.mean_damping_power, 1e-5 * s.mean_motor_power);
  EXPECT_LT(s.residual, 1e-5);
  EXPECT_NEAR(s.cycle.coupling.front(), s.cycle.coupling.back(), 1e-4 * s.coupling_peak);
}

TEST(SteadyCycle, ShootingAndCycleByCycleFindTheSameOrbit) {
  const auto a = mech::steady_by_shooting(scene(), {}, 720, 3.0, kStart);
  mech::OdeOptions o;
  const auto b = mech::steady_by_cycles(scene(), o, 400, 1e-7);
  ASSERT_EQ(a.status, DynamicsStatus::ok) << a.message;
  ASSERT_EQ(b.status, DynamicsStatus::ok) << b.message;
  // Both solve to ~1e-7 of the state (tolerances 100 rtol): 1e-5 relative.
  EXPECT_NEAR(a.w20, b.w20, 1e-5 * a.w20);
  EXPECT_NEAR(a.coupling_peak, b.coupling_peak, 1e-5 * a.coupling_peak);
  EXPECT_NEAR(a.coupling_rms, b.coupling_rms, 1e-5 * a.coupling_rms);
  EXPECT_GT(b.iterations, a.iterations);  // revolutions against Newton steps
}

TEST(SteadyCycle, StiffCouplingApproachesTheRigidDrive) {
  // As c grows the twist vanishes and the two masses move together.
  auto e = scene(2000);
  e.stiffness = 1e7;
  e.damping = 2 * std::sqrt(1e7 * 40.0);  // near critical damping of the elastic mode
  auto r = scene();
  r.fidelity = mech::DriveFidelity::rigid;
  const auto se = mech::steady_by_shooting(e, {}, 720, 2.0, kStart);
  const auto sr = mech::steady_by_shooting(r, {}, 720, 2.0, kStart);
  ASSERT_EQ(se.status, DynamicsStatus::ok) << se.message;
  ASSERT_EQ(sr.status, DynamicsStatus::ok) << sr.message;
  EXPECT_NEAR(se.mean_speed, sr.mean_speed, 1e-3 * sr.mean_speed);
  EXPECT_NEAR(se.mean_motor_power, sr.mean_motor_power, 1e-2 * sr.mean_motor_power);
}

TEST(SteadyCycle, CouplingLoadFallsWithDampingAndFlattens) {
  // The paper's trend (Figs 7-8): peak and RMS coupling torque fall steeply
  // from k = 200 to about 6000 and flatten after.
  double peak[3], rms[3];
  const double ks[3] = {500, 6000, 10000};
  for (int i = 0; i < 3; ++i) {
    const auto s = mech::steady_by_shooting(scene(ks[i]), {}, 720, 3.0, kStart);
    ASSERT_EQ(s.status, DynamicsStatus::ok) << s.message;
    peak[i] = s.coupling_peak;
    rms[i] = s.coupling_rms;
  }
  EXPECT_GT(peak[0], peak[1]);
  EXPECT_GT(peak[1], peak[2]);
  EXPECT_GT(rms[0] - rms[1], 5 * (rms[1] - rms[2]));  // the knee
}

TEST(Failures, ThePrintedLoadStallsTheMotor) {
  // Rollers of 4 x 7962 N need several kN m at the crank; the 11 kW motor
  // gives at most 2 M_kr u eta ~ 1.9 kN m there.
  mech::ElasticDrive d;
  d.resistance_opposes_motion = true;
  const auto s = mech::steady_by_shooting(d, {}, 720, 3.0, kStart);
  EXPECT_EQ(s.status, DynamicsStatus::stalled) << s.message;
}

TEST(Failures, StepLimitIsAStatus) {
  mech::OdeOptions o;
  o.max_steps = 20;
  const auto st = mech::simulate_startup(scene(), o, 1.0, 1e-3, nullptr, kStart);
  EXPECT_EQ(st.status, DynamicsStatus::too_many_steps);
}

TEST(Failures, ExplicitMethodFailsOnAStiffCouplingWhereBdfDoesNot) {
  // c = 1e9 (critically damped) puts the elastic mode near 5000 rad/s against
  // a 0.6 s revolution: the explicit method's stability limit costs ~5700
  // steps for one second (measured), BDF ~700. A budget of 2000 separates them.
  auto d = scene();
  d.stiffness = 1e9;
  d.damping = 2 * std::sqrt(1e9 * 40.0);
  mech::OdeOptions bdf, erk;
  bdf.max_steps = erk.max_steps = 2000;
  erk.method = mech::OdeMethod::erk;
  const auto a = mech::simulate_startup(d, bdf, 1.0, 1e-2, nullptr, kStart);
  const auto b = mech::simulate_startup(d, erk, 1.0, 1e-2, nullptr, kStart);
  EXPECT_EQ(a.status, DynamicsStatus::ok) << a.message;
  EXPECT_EQ(b.status, DynamicsStatus::too_many_steps) << b.message;
}

TEST(ElasticDriveProblem, GradientDriversRefuse) {
  const auto p = problems::make_problem(opt::ConfigNode::parse(
      "problem: elastic_drive\nvariables: {damping: {min: 200, max: 10000}}\n", "<t>"));
  opt::DriverOptions o;
  o.algorithm = "LD_SLSQP";
  const auto r = opt::NloptDriver(o).minimize(*p, {"rms_coupling_torque"}, {}, p->initial_point());
  EXPECT_EQ(r.status, opt::DriverStatus::invalid_arguments);
  EXPECT_NE(r.message.find("derivative-free"), std::string::npos);
}

}  // namespace
