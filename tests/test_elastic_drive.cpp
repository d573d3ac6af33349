// The elastic drive (seed 001) on SUNDIALS: motor and inertia closed forms,
// physics identities of the steady cycle, the two steady-state methods
// against each other, limits, and the failures reported as statuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "mech/drive_dynamics.hpp"
#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "opt/drivers/nlopt.hpp"
#include "opt/registry.hpp"

namespace {

using mech::Status;

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

TEST(Status, NamesInTheEnumsOrderReadBack) {
  // The names result files carry (docs/config.md), written out here rather
  // than taken from the code under test.
  const char* names[] = {"ok", "cannot_assemble", "invalid_parameter", "not_grashof",
                         "toggle_in_cycle", "synthesis_failed", "stalled", "too_many_steps",
                         "integration_failed", "not_converged", "non_finite", "timed_out", "evaluation_error",
                         "singular_position"};
  for (int i = 0; i < 14; ++i) {
    const auto s = static_cast<Status>(i);
    EXPECT_EQ(mech::to_string(s), names[i]);
    EXPECT_EQ(mech::status_from_string(names[i]), s) << names[i];
  }
  EXPECT_EQ(mech::to_string(Status::not_converged), "not_converged");  // was no_periodic_orbit
  EXPECT_FALSE(mech::status_from_string("no_periodic_orbit"));
  EXPECT_FALSE(mech::status_from_string("solver_failure"));
  EXPECT_FALSE(mech::status_from_string(""));
  EXPECT_FALSE(mech::status_from_string("OK"));
}

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

mech::OdeOptions tolerance(double rtol, mech::OdeMethod m = mech::OdeMethod::bdf) {
  mech::OdeOptions o;
  o.method = m;
  o.rtol = o.atol = rtol;
  return o;
}

TEST(SteadyCycle, EnergyBalanceAndPeriodicity) {
  // Over a periodic cycle the motor's work equals the resistance's plus the
  // damper's (the kinetic and elastic energies return). All three are
  // quadratures of the same integration: 1e-6 relative at rtol 1e-8.
  const auto s = mech::steady_by_shooting(scene(), {}, 720, 0, kStart);
  ASSERT_EQ(s.status, Status::ok) << s.message;
  EXPECT_NEAR(s.mean_motor_power, s.mean_resistance_power + s.mean_damping_power, 1e-6 * s.mean_motor_power);
  EXPECT_LT(s.residual, 100 * 1e-8);
  ASSERT_EQ(s.cycle.coupling.size(), 721u);
  EXPECT_NEAR(s.cycle.coupling.front(), s.cycle.coupling.back(), 1e-5 * s.coupling_peak);
}

TEST(SteadyCycle, PeakAgreesWithAnIndependentReference) {
  // bench/peer_elastic.py writes the same model independently in Python:
  // scipy Radau at rtol 1e-12, extrema located as events, checked there
  // against the maximum of 200 001 dense samples: 2184.2681705 N m.
  for (auto m : {mech::OdeMethod::bdf, mech::OdeMethod::erk}) {
    const auto s = mech::steady_by_shooting(scene(), tolerance(1e-10, m), 0, 0, kStart);
    ASSERT_EQ(s.status, Status::ok) << s.message;
    EXPECT_NEAR(s.coupling_peak, 2184.2681705, 2e-8 * 2184.27);
  }
}

TEST(SteadyCycle, ExtremaFromRootsBoundDenseSamples) {
  // The extrema come from roots of the slopes on the integrator's dense
  // output, not from samples. 20 000 samples of the same trajectory (the
  // same steps, the same dense output) lie inside the extrema and reach them
  // within the sampling error (M'' h^2 / 8, h = 3.1e-4 rad: ~1e-6 relative).
  // Loose steps (ERK, rtol 1e-6: ~0.07 rad) make the root search work.
  const auto s = mech::steady_by_shooting(scene(), tolerance(1e-6, mech::OdeMethod::erk), 20000, 0, kStart);
  ASSERT_EQ(s.status, Status::ok) << s.message;
  ASSERT_EQ(s.cycle.coupling.size(), 20001u);
  const auto [lo, hi] = std::minmax_element(s.cycle.coupling.begin(), s.cycle.coupling.end());
  EXPECT_LE(*hi, s.coupling_max + 1e-9 * s.coupling_peak);
  EXPECT_GE(*lo, s.coupling_min - 1e-9 * s.coupling_peak);
  EXPECT_NEAR(*hi, s.coupling_max, 1e-6 * s.coupling_peak);
  EXPECT_NEAR(*lo, s.coupling_min, 1e-6 * s.coupling_peak);
  const auto [wlo, whi] = std::minmax_element(s.cycle.w2.begin(), s.cycle.w2.end());
  EXPECT_NEAR((*whi - *wlo) / s.mean_speed, s.speed_irregularity, 1e-6);
}

TEST(SteadyCycle, ShootingAndCycleByCycleFindTheSameOrbit) {
  const auto a = mech::steady_by_shooting(scene(), {}, 0, 0, kStart);
  const auto b = mech::steady_by_cycles(scene(), {}, 400, 1e-7);
  ASSERT_EQ(a.status, Status::ok) << a.message;
  ASSERT_EQ(b.status, Status::ok) << b.message;
  EXPECT_NEAR(a.w20, b.w20, 1e-6 * a.w20);
  EXPECT_NEAR(a.coupling_peak, b.coupling_peak, 1e-6 * a.coupling_peak);
  EXPECT_NEAR(a.coupling_rms, b.coupling_rms, 1e-6 * a.coupling_rms);
}

TEST(SteadyCycle, StartupGuessReachesTheSameOrbit) {
  // The orbit found from the rigid estimate is the one a 3 s start-up from
  // synchronous speed settles on.
  const auto a = mech::steady_by_shooting(scene(), {}, 0, 0, kStart);
  const auto b = mech::steady_by_shooting(scene(), {}, 0, 3.0, kStart);
  ASSERT_EQ(a.status, Status::ok) << a.message;
  ASSERT_EQ(b.status, Status::ok) << b.message;
  EXPECT_NEAR(a.coupling_peak, b.coupling_peak, 1e-6 * a.coupling_peak);
  EXPECT_NEAR(a.w20, b.w20, 1e-6 * a.w20);
}

TEST(SteadyCycle, MultiplierPredictsHowFastRevolutionsSettle) {
  // A soft, undamped coupling (c = 3000, k = 50) leaves the map weakly
  // contracting, so shooting needs Newton and reports the multiplier mu of
  // its monodromy matrix. Independently, integrating revolution after
  // revolution shrinks the change by mu each time: going from a 1e-4 to a
  // 1e-8 change takes ln(1e-4) / ln(mu) more revolutions (+-2 for the
  // transient's other modes).
  auto d = scene(50);
  d.stiffness = 3000;
  const auto s = mech::steady_by_shooting(d, tolerance(1e-10), 0, 0, kStart);
  ASSERT_EQ(s.status, Status::ok) << s.message;
  EXPECT_GT(s.iterations, 0);
  ASSERT_GT(s.largest_multiplier, 0.1);
  ASSERT_LT(s.largest_multiplier, 0.9);
  const auto coarse = mech::steady_by_cycles(d, tolerance(1e-10), 400, 1e-4);
  const auto fine = mech::steady_by_cycles(d, tolerance(1e-10), 400, 1e-8);
  ASSERT_EQ(fine.status, Status::ok) << fine.message;
  EXPECT_NEAR(fine.iterations - coarse.iterations, std::log(1e-4) / std::log(s.largest_multiplier), 2.0);
  EXPECT_NEAR(fine.largest_multiplier, s.largest_multiplier, 1e-6);
  EXPECT_NEAR(fine.coupling_peak, s.coupling_peak, 1e-6 * s.coupling_peak);
}

TEST(SteadyCycle, StiffCouplingApproachesTheRigidDrive) {
  // As c grows the twist vanishes and the two masses move together.
  auto e = scene(2000);
  e.stiffness = 1e7;
  e.damping = 2 * std::sqrt(1e7 * 40.0);  // near critical damping of the elastic mode
  auto r = scene();
  r.fidelity = mech::DriveFidelity::rigid;
  const auto se = mech::steady_by_shooting(e, {}, 0, 0, kStart);
  const auto sr = mech::steady_by_shooting(r, {}, 0, 0, kStart);
  ASSERT_EQ(se.status, Status::ok) << se.message;
  ASSERT_EQ(sr.status, Status::ok) << sr.message;
  EXPECT_NEAR(se.mean_speed, sr.mean_speed, 1e-3 * sr.mean_speed);
  // The rigid drive's map is one-dimensional (the speed): its multiplier,
  // exact from the sensitivities when the first guess is already periodic
  // (a 2 s start-up), lies inside the unit circle: no fallback.
  const auto warm = mech::steady_by_shooting(r, {}, 0, 2.0, kStart);
  ASSERT_EQ(warm.status, Status::ok) << warm.message;
  EXPECT_GT(warm.largest_multiplier, 0.0);
  EXPECT_LT(warm.largest_multiplier, 1.0);
  EXPECT_TRUE(warm.message.empty()) << warm.message;
  EXPECT_NEAR(warm.mean_speed, sr.mean_speed, 1e-6 * sr.mean_speed);
  EXPECT_NEAR(se.mean_motor_power, sr.mean_motor_power, 1e-2 * sr.mean_motor_power);
}

TEST(SteadyCycle, CouplingLoadFallsWithDampingAndFlattens) {
  // The paper's trend (Figs 7-8): peak and RMS coupling torque fall steeply
  // from k = 200 to about 6000 and flatten after.
  double peak[3], rms[3];
  const double ks[3] = {500, 6000, 10000};
  for (int i = 0; i < 3; ++i) {
    const auto s = mech::steady_by_shooting(scene(ks[i]), {}, 0, 0, kStart);
    ASSERT_EQ(s.status, Status::ok) << s.message;
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
  const auto s = mech::steady_by_shooting(d, {}, 0, 0, kStart);
  EXPECT_EQ(s.status, Status::stalled) << s.message;
  EXPECT_NE(s.message.find("exceeds the motor's largest moment"), std::string::npos) << s.message;
  // The start-up itself stalls too (the guess from it fails the same way).
  EXPECT_EQ(mech::steady_by_shooting(d, {}, 0, 3.0, kStart).status, Status::stalled);
}

TEST(Failures, StepLimitIsAStatus) {
  mech::OdeOptions o;
  o.max_steps = 20;
  const auto st = mech::simulate_startup(scene(), o, 1.0, 1e-3, nullptr, kStart);
  EXPECT_EQ(st.status, Status::too_many_steps);
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
  EXPECT_EQ(a.status, Status::ok) << a.message;
  EXPECT_EQ(b.status, Status::too_many_steps) << b.message;
}

TEST(Failures, FunctionalIterationExhaustsItsBudgetOnAStiffDampedCoupling) {
  // The method map's failing cell (docs/performance.md): c = 1e10, critically
  // damped. Adams' fixed-point corrector converges only on steps below the
  // elastic mode's time scale (~1/15 000 s) and runs out of a 20 000-step
  // budget; BDF's Newton corrector takes the slow motion's steps.
  auto d = scene();
  d.stiffness = 1e10;
  d.damping = 2 * std::sqrt(1e10 * 40.0);
  mech::OdeOptions adams = tolerance(1e-8, mech::OdeMethod::adams), bdf = tolerance(1e-8);
  adams.max_steps = bdf.max_steps = 20000;
  const auto a = mech::steady_by_shooting(d, adams, 0, 0, kStart);
  const auto b = mech::steady_by_shooting(d, bdf, 0, 0, kStart);
  EXPECT_EQ(a.status, Status::too_many_steps) << a.message;
  EXPECT_EQ(b.status, Status::ok) << b.message;
}

TEST(Failures, NoPeriodicOrbitWithinTheRevolutionsAllowedIsAStatus) {
  // Two revolutions from the rigid estimate cannot settle to 1e-12.
  const auto s = mech::steady_by_cycles(scene(), {}, 2, 1e-12);
  EXPECT_EQ(s.status, Status::not_converged) << s.message;
  EXPECT_NE(s.message.find("2 revolutions"), std::string::npos) << s.message;
}

// Odd inputs are typed statuses before any integration (check()).

TEST(Inputs, RodNoLongerThanItsCrankCannotAssemble) {
  // At psi = 90 deg the pin is r above the slider axis: a rod of l <= r
  // cannot reach it (it used to integrate and report 'stalled').
  for (double l : {0.15, 0.2}) {
    auto d = scene();
    d.rod_length = l;  // crank_radius 0.2
    EXPECT_EQ(mech::check(d), Status::cannot_assemble) << l;
    const auto s = mech::steady_by_shooting(d, {}, 0, 0, kStart);
    EXPECT_EQ(s.status, Status::cannot_assemble) << s.message;
    EXPECT_NE(s.message.find("rod_length"), std::string::npos) << s.message;
    EXPECT_EQ(mech::steady_by_shooting(d, {}, 0, 3.0, kStart).status, Status::cannot_assemble);
    EXPECT_EQ(mech::steady_by_cycles(d, {}).status, Status::cannot_assemble);
    EXPECT_EQ(mech::simulate_startup(d, {}, 1.0, 1e-3).status, Status::cannot_assemble);
  }
  auto d = scene();
  d.rod_length = 0.2000001;  // just longer: assembles
  EXPECT_EQ(mech::check(d), Status::ok);
}

TEST(Inputs, NonPhysicalParametersAreInvalid) {
  // What bounds and grid values may bring: each is invalid_parameter, named
  // in the message, before the integrator sees it.
  using D = mech::ElasticDrive;
  const double nan = std::nan(""), inf = HUGE_VAL;
  const struct {
    const char* name;
    double D::*field;
    double value;
  } bad[] = {{"stiffness", &D::stiffness, -1000},          {"stiffness", &D::stiffness, 0},
             {"stiffness", &D::stiffness, nan},            {"stiffness", &D::stiffness, inf},
             {"damping", &D::damping, -1},                 {"damping", &D::damping, nan},
             {"cart_mass", &D::cart_mass, -1},             {"cart_mass", &D::cart_mass, nan},
             {"rod_mass", &D::rod_mass, -64},              {"drive_efficiency", &D::drive_efficiency, 0},
             {"drive_efficiency", &D::drive_efficiency, 1.5}, {"drive_efficiency", &D::drive_efficiency, -0.9},
             {"rod_length", &D::rod_length, inf},          {"rod_length", &D::rod_length, -0.8},
             {"phase_shift", &D::phase_shift, nan},        {"gear_ratio", &D::gear_ratio, 0},
             {"gearbox_factor", &D::gearbox_factor, 0.5}};
  for (const auto& [name, field, v] : bad) {
    auto d = scene();
    d.*field = v;
    std::string why;
    EXPECT_EQ(mech::check(d, &why), Status::invalid_parameter) << name << " = " << v;
    EXPECT_NE(why.find(name), std::string::npos) << why;
    const auto s = mech::steady_by_shooting(d, {}, 0, 0, kStart);
    EXPECT_EQ(s.status, Status::invalid_parameter) << name << " = " << v << ": " << s.message;
    EXPECT_EQ(mech::simulate_startup(d, {}, 1.0, 1e-3).status, Status::invalid_parameter) << name;
  }
  auto slip = scene();
  slip.motor.critical_slip = 1;  // Kloss's curve needs 0 < s_kr < 1
  EXPECT_EQ(mech::check(slip), Status::invalid_parameter);
  // The domains' closed ends are physical: no damping, an ideal gearbox,
  // massless carts (the rods still carry inertia).
  auto d = scene();
  d.damping = 0;
  d.drive_efficiency = 1;
  d.cart_mass = 0;
  EXPECT_EQ(mech::check(d), Status::ok);
  // Neither side of the coupling may lose all its inertia (eqs 1, 9).
  d.rod_mass = 0;
  EXPECT_EQ(mech::check(d), Status::invalid_parameter);
  d = scene();
  d.motor.rotor_inertia = d.coupling_inertia = 0;
  EXPECT_EQ(mech::check(d), Status::invalid_parameter);
}

TEST(Inputs, InvalidRunSettingsAreInvalid) {
  mech::OdeOptions o;
  o.rtol = 0;
  EXPECT_EQ(mech::steady_by_shooting(scene(), o, 0, 0, kStart).status, Status::invalid_parameter);
  o = {};
  o.atol = std::nan("");
  EXPECT_EQ(mech::simulate_startup(scene(), o, 1.0, 1e-3).status, Status::invalid_parameter);
  o = {};
  o.max_steps = 0;
  EXPECT_EQ(mech::steady_by_cycles(scene(), o).status, Status::invalid_parameter);
  const auto st = mech::simulate_startup(scene(), {}, 1.0, 0.0);  // ceil(1 / 0) samples
  EXPECT_EQ(st.status, Status::invalid_parameter);
  EXPECT_NE(st.message.find("output step"), std::string::npos) << st.message;
  EXPECT_EQ(mech::simulate_startup(scene(), {}, std::nan(""), 1e-3).status, Status::invalid_parameter);
  EXPECT_EQ(mech::steady_by_shooting(scene(), {}, 0, -1.0, kStart).status, Status::invalid_parameter);
  EXPECT_EQ(mech::steady_by_cycles(scene(), {}, 0).status, Status::invalid_parameter);
}

TEST(ElasticDriveProblem, GridValueOutsideTheDomainIsInvalidParameter) {
  // The config rejects such bounds (tests/repro/bounds_bypass_domain_negative_stiffness.yaml);
  // a design handed to the problem directly with c = -1000 is still a status.
  const auto p = opt::make_problem(opt::ConfigNode::parse(
      "problem: elastic_drive\nvariables: {stiffness: {min: 1000, max: 1e6}}\n", "<t>"));
  EXPECT_EQ(p->evaluate(Eigen::VectorXd::Constant(1, -1000.0), opt::MetricSet::all(), false).status, mech::Status::invalid_parameter);
}

// No C++ exception crosses a SUNDIALS callback: a throwing callback (here a
// test hook, mech::callback_hook) ends its solver with the library's
// unrecoverable flag, and the entry point returns evaluation_error.

struct Injected {
  static inline std::string target;  // the callback that throws ("" : none)
  static inline long after = 0;      // calls of it that pass first
  static inline std::set<std::string> seen;
  static void hook(const char* callback) {
    seen.insert(callback);
    if (target == callback && after-- <= 0) throw std::runtime_error("injected failure in " + target);
  }
  Injected(std::string t, long n) {
    target = std::move(t), after = n, seen.clear();
    mech::callback_hook = hook;
  }
  ~Injected() { mech::callback_hook = nullptr; }
};

// The soft, lightly damped coupling whose shooting needs KINSOL (see
// MultiplierPredictsHowFastRevolutionsSettle).
mech::ElasticDrive newton_scene() {
  auto d = scene(50);
  d.stiffness = 3000;
  return d;
}

TEST(CallbackFailures, EveryCallbackIsGuarded) {
  {
    const Injected none("", 0);
    ASSERT_EQ(mech::steady_by_shooting(newton_scene(), tolerance(1e-10), 0, 0, kStart).status, Status::ok);
    EXPECT_EQ(Injected::seen, (std::set<std::string>{"rhs", "jacobian", "residual", "newton_jacobian"}));
  }
  for (const char* target : {"rhs", "jacobian", "residual", "newton_jacobian"})
    for (long after : {0L, 2L}) {  // the first call, or a later one (5 residuals, 4 Newton Jacobians in all)
      const Injected fault(target, after);
      const auto s = mech::steady_by_shooting(newton_scene(), tolerance(1e-10), 0, 0, kStart);
      EXPECT_EQ(s.status, Status::evaluation_error) << target << " " << after << ": " << s.message;
      EXPECT_EQ(s.message, std::string("injected failure in ") + target);
    }
  // The explicit and Adams integrators' right-hand sides; the start-up's.
  for (auto m : {mech::OdeMethod::erk, mech::OdeMethod::adams}) {
    const Injected fault("rhs", 100);
    EXPECT_EQ(mech::steady_by_shooting(scene(), tolerance(1e-8, m), 0, 0, kStart).status,
              Status::evaluation_error);
  }
  {
    const Injected fault("rhs", 100);
    const auto st = mech::simulate_startup(scene(), {}, 1.0, 1e-3, nullptr, kStart);
    EXPECT_EQ(st.status, Status::evaluation_error) << st.message;
  }
  // Nothing is left behind: the same run without the fault is as before.
  const auto a = mech::steady_by_shooting(newton_scene(), tolerance(1e-10), 0, 0, kStart);
  ASSERT_EQ(a.status, Status::ok) << a.message;
  EXPECT_GT(a.iterations, 0);
}

TEST(CallbackFailures, AnythingThrownIsRecorded) {
  mech::callback_hook = [](const char*) { throw 42; };
  const auto s = mech::steady_by_cycles(scene(), {});
  mech::callback_hook = nullptr;
  EXPECT_EQ(s.status, Status::evaluation_error);
  EXPECT_EQ(s.message, "unknown exception");
}

// Memory and work stay bounded whatever the time span.

TEST(Startup, HugeTimeSpanEndsOnTheStepBudgetSmall) {
  // 1e9 s at 1 ms used to allocate 1e12 samples (std::bad_alloc) or, past
  // an int's range, to return at once with a wrong 'ok'. The default budget
  // of 1e5 steps (~150 s of motion) ends it (0.1-0.2 s in Release; the work
  // is bounded by the step count, not timed here); the samples kept (7
  // doubles each) stay within the cap of 100 000, i.e. under 6 MB.
  const auto st = mech::simulate_startup(scene(), {}, 1e9, 1e-3, nullptr, kStart);
  EXPECT_EQ(st.status, Status::too_many_steps) << st.message;
  EXPECT_EQ(st.steps, 100000);
  EXPECT_LE(st.trajectory.t.size(), 100000u);
  EXPECT_LE(st.trajectory.t.capacity(), 200000u);
  EXPECT_GT(st.trajectory.t.back(), 10.0);  // it did run
  EXPECT_GT(st.peak_coupling, 0.0);
  // The warm-up of the steady state likewise, with the start-up's status.
  const auto s = mech::steady_by_shooting(scene(), {}, 0, 1e9, kStart);
  EXPECT_EQ(s.status, Status::too_many_steps) << s.message;
  EXPECT_NE(s.message.find("warm-up"), std::string::npos) << s.message;
}

TEST(Startup, KeptSamplesAreDecimatedEvenlyAndTheMetricsUseThemAll) {
  // 15 s at 0.1 ms is 150 001 samples, past the cap of 100 000: every other
  // one is kept (75 001, 0.2 ms apart, ending at 15 s). The peak and the time
  // to steady come from all samples: a 9 s run at the same step keeps all of
  // its 90 001 and gives the same values, exactly (the same integration up to
  // 9 s; its start-up peak and settling, ~1 s, lie well inside). The scene:
  // the signed resistance (eqs 18-20 as printed) from 5 rad/s, which takes
  // a second to settle (from synchronous speed every revolution is already
  // within 1%).
  auto d = scene();
  d.resistance_opposes_motion = false;
  const auto steady = mech::steady_by_shooting(d, {}, 0, 0, kStart);
  ASSERT_EQ(steady.status, Status::ok) << steady.message;
  const auto full = mech::simulate_startup(d, {}, 9.0, 1e-4, &steady, 5.0);
  const auto cut = mech::simulate_startup(d, {}, 15.0, 1e-4, &steady, 5.0);
  ASSERT_EQ(full.status, Status::ok) << full.message;
  ASSERT_EQ(cut.status, Status::ok) << cut.message;
  ASSERT_EQ(full.trajectory.t.size(), 90001u);
  ASSERT_EQ(cut.trajectory.t.size(), 75001u);
  for (size_t i = 0; i < cut.trajectory.t.size(); i += 997)
    EXPECT_NEAR(cut.trajectory.t[i], 2e-4 * i, 1e-9) << i;
  EXPECT_EQ(cut.trajectory.t.back(), 15.0);
  EXPECT_EQ(cut.trajectory.coupling[4500], full.trajectory.coupling[9000]);  // t = 0.9 s, the same sample
  EXPECT_EQ(cut.peak_coupling, full.peak_coupling);
  ASSERT_GT(full.time_to_steady, 0.5);
  ASSERT_LT(full.time_to_steady, 2.0);
  EXPECT_EQ(cut.time_to_steady, full.time_to_steady);
}

TEST(ElasticDriveProblem, GradientDriversRefuse) {
  const auto p = opt::make_problem(opt::ConfigNode::parse(
      "problem: elastic_drive\nvariables: {damping: {min: 200, max: 10000}}\n", "<t>"));
  opt::DriverOptions o;
  o.algorithm = "LD_SLSQP";
  const auto r = opt::NloptDriver(o).minimize(*p, {"rms_coupling_torque"}, {}, p->initial_point());
  EXPECT_EQ(r.status, opt::DriverStatus::invalid_arguments);
  EXPECT_NE(r.message.find("derivative-free"), std::string::npos);
}

}  // namespace
