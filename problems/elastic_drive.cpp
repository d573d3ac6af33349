#include "problems/elastic_drive.hpp"
#include "problems/registry.hpp"

#include <cmath>
#include <numbers>

#include "mech/drive_dynamics.hpp"
#include "opt/parameters.hpp"
#include "problems/model_problem.hpp"

namespace problems {
namespace {


// The metrics, in the order of kMetrics (their MetricIds); "coupling"
// metrics on the side chosen by coupling_side.
struct M {
  enum Id : int {
    peak_coupling_torque,
    rms_coupling_torque,
    min_coupling_torque,
    max_coupling_torque,
    mean_crank_speed,
    speed_irregularity,
    min_motor_torque,
    max_motor_torque,
    min_motor_speed,
    max_motor_speed,
    mean_motor_power,
    mean_resistance_power,
    mean_damping_power,
    energy_balance_error,
    largest_multiplier,
    peak_startup_coupling_torque,
    time_to_steady,
  };
};

const std::vector<MetricSpec> kMetrics = {
    {M::peak_coupling_torque, "peak_coupling_torque", "N m"},  // max |c theta + k theta'| over the steady cycle
    {M::rms_coupling_torque, "rms_coupling_torque", "N m"},   // time RMS over the steady cycle
    {M::min_coupling_torque, "min_coupling_torque", "N m"},
    {M::max_coupling_torque, "max_coupling_torque", "N m"},
    {M::mean_crank_speed, "mean_crank_speed", "rad/s", "mean_speed"},          // crank, steady cycle
    {M::speed_irregularity, "speed_irregularity", ""},       // (w2max - w2min) / w2mean
    {M::min_motor_torque, "min_motor_torque", "N m", "motor_torque_min"},      // motor shaft
    {M::max_motor_torque, "max_motor_torque", "N m", "motor_torque_max"},
    {M::min_motor_speed, "min_motor_speed", "rad/s", "motor_speed_min"},     // motor shaft
    {M::max_motor_speed, "max_motor_speed", "rad/s", "motor_speed_max"},
    {M::mean_motor_power, "mean_motor_power", "W"},
    {M::mean_resistance_power, "mean_resistance_power", "W"},
    {M::mean_damping_power, "mean_damping_power", "W"},
    {M::energy_balance_error, "energy_balance_error", ""},     // |P_motor - P_res - P_damping| / P_motor
    {M::largest_multiplier, "largest_multiplier", ""},       // of the steady orbit (< 1: it attracts; docs/config.md)
    {M::peak_startup_coupling_torque, "peak_startup_coupling_torque", "N m", "startup_peak_coupling_torque"},  // start-up transient
    {M::time_to_steady, "time_to_steady", "s"},          // start-up: every revolution's peak within 1% after it
};

struct Model {
  mech::ElasticDrive drive;
  mech::OdeOptions ode;
  bool motor_side = false;   // report coupling torques on the motor shaft (crank / (u eta))
  double start_speed = 0;    // crank speed at the start [rad/s]; 0: from rest
  double warmup = 0;         // start-up seconds whose end is the first guess (0: rigid estimate)
  double startup_time = 5.0; // start-up transient length [s]
  bool startup_curves = false;
  double nominal_slip = 0.025, overload_ratio = 2.0;  // eq. (27a), when critical_slip is not given
};

const opt::Domain kFraction{0, 1, true, false};

// The variables first, in the order of the switch in drive().
const opt::ParameterTable<Model> kTable = {
    {variable("stiffness", Dimension::rotational_stiffness, kPositive, "c, coupling stiffness at the crank axis",
              "seed 001 eq. (29)"),
     MECHOPT_STORED_AT(m.drive.stiffness)},
    {variable("damping", Dimension::rotational_damping, kNonNegative, "k, coupling damping at the crank axis",
              "seed 001 eq. (40)"),
     MECHOPT_STORED_AT(m.drive.damping)},
    {variable("rod_length", Dimension::length, kPositive, "l (l <= r: cannot_assemble)", "seed 001 eq. (36)"),
     MECHOPT_STORED_AT(m.drive.rod_length)},
    {variable("phase_shift", Dimension::angle, kAnyValue, "crank 2 leads crank 1 by this angle", "seed 001 eq. (37)"),
     MECHOPT_STORED_AT(m.drive.phase_shift)},
    {quantity("motor.synchronous_speed", Dimension::angular_speed, kPositive, "w0, motor shaft (4A160S6U3)",
              "seed 001 eq. (27)"),
     MECHOPT_STORED_AT(m.drive.motor.synchronous_speed)},
    {quantity("motor.critical_torque", Dimension::torque, kPositive, "M_kr, motor shaft", "seed 001 eq. (27)"),
     MECHOPT_STORED_AT(m.drive.motor.critical_torque)},
    {quantity("motor.critical_slip", Dimension::dimensionless, kFraction,
              "s_kr (default: from nominal_slip and overload_ratio; give one or the other)", "seed 001 eq. (27a)"),
     MECHOPT_STORED_AT(m.drive.motor.critical_slip)},
    {quantity("motor.nominal_slip", Dimension::dimensionless, {0, 1, true, true}, "s_n, for s_kr", "seed 001 eq. (27a)"),
     MECHOPT_STORED_AT(m.nominal_slip)},
    {quantity("motor.overload_ratio", Dimension::dimensionless, {1, HUGE_VAL, true, false}, "lambda, for s_kr",
              "seed 001 eq. (27a)"),
     MECHOPT_STORED_AT(m.overload_ratio)},
    {quantity("motor.rotor_inertia", Dimension::inertia, kNonNegative, "J_p, motor shaft", "seed 001 eq. (1)"),
     MECHOPT_STORED_AT(m.drive.motor.rotor_inertia)},
    {quantity("coupling_inertia", Dimension::inertia, kNonNegative, "J_m, motor shaft", "seed 001 eq. (1)"),
     MECHOPT_STORED_AT(m.drive.coupling_inertia)},
    {quantity("gear_ratio", Dimension::dimensionless, kPositive, "u", "seed 001 eq. (1)"),
     MECHOPT_STORED_AT(m.drive.gear_ratio)},
    {quantity("gearbox_factor", Dimension::dimensionless, {1, HUGE_VAL, false, false},
              "delta: gearbox inertia reduced to the motor shaft (unstated in the paper)", "seed 001 eq. (1)"),
     MECHOPT_STORED_AT(m.drive.gearbox_factor)},
    {quantity("drive_efficiency", Dimension::dimensionless, kFraction, "eta_n (unstated in the paper)", "seed 001 eq. (1)"),
     MECHOPT_STORED_AT(m.drive.drive_efficiency)},
    {quantity("crank_radius", Dimension::length, kPositive, "r", "seed 001 eq. (36)"),
     MECHOPT_STORED_AT(m.drive.crank_radius)},
    {choice("layout", {"opposed", "same_side"}, "second slider mirrored, or on the same side as the first",
            "seed 001 eq. (37)"),
     MECHOPT_STORED_AT(m.drive.same_side)},
    {choice("kinematics", {"exact", "binomial"}, "exact slider-crank, or the binomial series", "seed 001 eqs (36)-(39)"),
     MECHOPT_STORED_AT(m.drive.kinematics)},
    {quantity("cart_mass", Dimension::mass, kNonNegative, "m'_B, each cart", "seed 001 eq. (3)"),
     MECHOPT_STORED_AT(m.drive.cart_mass)},
    {quantity("rod_mass", Dimension::mass, kNonNegative, "m_sh, each rod: half at the pin, half at the cart",
              "seed 001 eqs (2)-(3)"),
     MECHOPT_STORED_AT(m.drive.rod_mass)},
    {quantity("crank_inertia", Dimension::inertia, kNonNegative, "J'_k, each crank about its axis (unstated: 0)",
              "seed 001 eq. (2)"),
     MECHOPT_STORED_AT(m.drive.crank_inertia)},
    {quantity("roller_horizontal", Dimension::force, kNonNegative,
              "F_01 + F_02 per cart (seed 000's F_B; the printed 2 x 7962 N stall the motor)", "seed 001 eq. (12)"),
     MECHOPT_STORED_AT(m.drive.roller_horizontal)},
    {quantity("roller_vertical", Dimension::force, kNonNegative, "R_01 + R_02 per cart", "seed 001 eq. (13)"),
     MECHOPT_STORED_AT(m.drive.roller_vertical)},
    {quantity("cart_weight", Dimension::force, kNonNegative, "G per cart", "seed 001 eq. (13)"),
     MECHOPT_STORED_AT(m.drive.cart_weight)},
    {quantity("guide_friction", Dimension::dimensionless, kNonNegative, "f_np of the cart guides", "seed 001 eq. (12)"),
     MECHOPT_STORED_AT(m.drive.guide_friction)},
    {choice("resistance", {"signed", "opposes_motion"},
            "as printed (signed), or opposing the crank's motion (regularised over 1e-3 rad/s)",
            "seed 001 eqs (18)-(20)"),
     MECHOPT_STORED_AT(m.drive.resistance_opposes_motion)},
    {choice("fidelity", {"rigid", "elastic"}, "one rigid mass, or two masses joined by the coupling", "seed 001 eq. (29)")
         .fidelity({"rigid", "elastic"}),
     MECHOPT_STORED_AT(m.drive.fidelity)},
    {choice("coupling_side", {"crank", "motor"},
            "coupling torques reported at the crank, or on the motor shaft (divided by u eta)", ""),
     MECHOPT_STORED_AT(m.motor_side)},
    {quantity("start_speed", Dimension::angular_speed, kNonNegative, "crank speed at the start of a start-up (0: rest)", ""),
     MECHOPT_STORED_AT(m.start_speed)},
    {quantity("warmup", Dimension::time, kNonNegative,
              "start-up seconds whose last revolution is the steady state's first guess (0: the rigid estimate)", ""),
     MECHOPT_STORED_AT(m.warmup)},
    {quantity("startup_time", Dimension::time, kPositive, "length of the start-up transient", ""),
     MECHOPT_STORED_AT(m.startup_time)},
    {choice("curves", {"steady", "startup"}, "what cycle.svg and cycle.csv show", ""),
     MECHOPT_STORED_AT(m.startup_curves)},
    {choice("ode.method", {"bdf", "adams", "erk"},
            "CVODE BDF (stiff), CVODE Adams (functional iteration) or ARKODE Dormand-Prince 5(4)", ""),
     MECHOPT_STORED_AT(m.ode.method)},
    {quantity("ode.rtol", Dimension::dimensionless, {0, 1, true, true}, "relative tolerance", ""),
     MECHOPT_STORED_AT(m.ode.rtol)},
    {quantity("ode.atol", Dimension::dimensionless, kPositive,
              "absolute tolerance (steady state: relative to each state's scale)", ""),
     MECHOPT_STORED_AT(m.ode.atol)},
    {whole("ode.max_steps", {10, 100000000, false, false}, "step budget of one whole integration", ""),
     MECHOPT_STORED_AT(m.ode.max_steps)},
};

class ElasticDriveProblem : public TabledProblem {
 public:
  ElasticDriveProblem(Model m, std::vector<opt::Variable> vars)
      : TabledProblem("elastic_drive", kMetrics, std::move(vars)), m_(std::move(m)),
        slots_(opt::variable_rows(kTable, variables())) {}

  bool provides_gradients() const override { return false; }

  opt::Evaluation evaluate_model_at(const Eigen::VectorXd& x, const opt::MetricSet& wanted,
                                    bool) const override {
    const mech::ElasticDrive d = drive(x);
    opt::Evaluation e;
    MetricSink<double> out(wanted, e);
    auto put = [&](M::Id id, double v) { out.put(id, v); };
    const auto s = mech::steady_by_shooting(d, m_.ode, 0, m_.warmup, m_.start_speed);
    if (s.status != mech::Status::ok) {
      e.status = s.status;
      e.message = s.message;
      return e;
    }
    const double side = m_.motor_side ? 1.0 / (d.gear_ratio * d.drive_efficiency) : 1.0;
    put(M::peak_coupling_torque, s.coupling_peak * side);
    put(M::rms_coupling_torque, s.coupling_rms * side);
    put(M::min_coupling_torque, s.coupling_min * side);
    put(M::max_coupling_torque, s.coupling_max * side);
    put(M::mean_crank_speed, s.mean_speed);
    put(M::speed_irregularity, s.speed_irregularity);
    put(M::min_motor_torque, s.motor_torque_min);
    put(M::max_motor_torque, s.motor_torque_max);
    put(M::min_motor_speed, s.motor_speed_min);
    put(M::max_motor_speed, s.motor_speed_max);
    put(M::mean_motor_power, s.mean_motor_power);
    put(M::mean_resistance_power, s.mean_resistance_power);
    put(M::mean_damping_power, s.mean_damping_power);
    put(M::energy_balance_error,
        std::abs(s.mean_motor_power - s.mean_resistance_power - s.mean_damping_power) /
            std::max(std::abs(s.mean_motor_power), 1e-12));
    put(M::largest_multiplier, s.largest_multiplier);
    if (out.want_any(M::peak_startup_coupling_torque, M::time_to_steady)) {
      const auto st = mech::simulate_startup(d, m_.ode, m_.startup_time, 1e-3, &s, m_.start_speed);
      if (st.status != mech::Status::ok) {  // e.g. too_many_steps: no partial start-up figures
        e.status = st.status;
        e.message = st.message;
        return e;
      }
      put(M::peak_startup_coupling_torque, st.peak_coupling * side);
      put(M::time_to_steady, st.time_to_steady);
    }
    return e;
  }

  opt::CycleCurves cycle_curves(const Eigen::VectorXd& x, int) const override {
    const mech::ElasticDrive d = drive(x);
    const double side = m_.motor_side ? 1.0 / (d.gear_ratio * d.drive_efficiency) : 1.0;
    opt::CycleCurves c{{"time", "coupling_torque", "crank_speed", "motor_speed"}, {"s", "N m", "rad/s", "rad/s"}};
    mech::Trajectory tr;
    if (m_.startup_curves) {
      const auto st = mech::simulate_startup(d, m_.ode, m_.startup_time, 2e-3, nullptr, m_.start_speed);
      if (st.status != mech::Status::ok) return {};
      tr = st.trajectory;
    } else {
      const auto s = mech::steady_by_shooting(d, m_.ode, 720, m_.warmup, m_.start_speed);
      if (s.status != mech::Status::ok) return {};
      tr = s.cycle;
    }
    for (size_t i = 0; i < tr.t.size(); ++i)
      c.add_row({tr.t[i], tr.coupling[i] * side, tr.w2[i], tr.w1[i] * d.gear_ratio});
    return c;
  }

  nlohmann::json settings() const override {
    nlohmann::json model = opt::parameters_json(opt::parameters(kTable, m_));
    model["derived"] = {{"motor_side_inertia", m_.drive.motor_side_inertia()}};
    return {{"model", model},
            {"numerics",
             {              {"steady_state", "shooting over one revolution in the crank angle: one revolution from "
                               "the first guess (rigid estimate, or the start-up after warmup "
                               "seconds), then KINSOL Newton with the monodromy matrix if it "
                               "does not repeat; extrema by root finding"}}},
            {"units", "SI at the crank axis (motor_* on the motor shaft)"}};
  }

 private:
  mech::ElasticDrive drive(const Eigen::VectorXd& x) const {
    mech::ElasticDrive d = m_.drive;
    for (size_t i = 0; i < slots_.size(); ++i) {
      switch (slots_[i]) {  // rows of kTable
        case 0: d.stiffness = x[i]; break;
        case 1: d.damping = x[i]; break;
        case 2: d.rod_length = x[i]; break;
        default: d.phase_shift = x[i];
      }
    }
    return d;
  }

  Model m_;
  std::vector<int> slots_;  // table row of each variable
};

}  // namespace

// Seed 001's drive with the assumptions its text leaves open (docs/reproduction.md):
// the printed roller loads (2 x 7962 N per cart) stall the 11 kW motor, so the
// carts take seed 000's F_B = 3562 N with the vertical forces balanced, the
// resistance opposes the motion, and a start-up begins at the motor's
// synchronous speed (Kloss's starting torque cannot start the load).
Model default_model() {
  Model m;
  m.drive.roller_horizontal = 3562;
  m.drive.roller_vertical = 10124.9;
  m.drive.resistance_opposes_motion = true;
  m.start_speed = 10.686;
  m.drive.motor.critical_slip = mech::InductionMotor::critical_slip_from(m.nominal_slip, m.overload_ratio);
  return m;
}

std::unique_ptr<opt::Problem> make_elastic_drive(const opt::ConfigNode& root) {
  Model m = default_model();
  const auto given = opt::read_parameters(root, kTable, m);
  auto has = [&](const char* k) { return std::find(given.begin(), given.end(), k) != given.end(); };
  if (has("motor.critical_slip") && (has("motor.nominal_slip") || has("motor.overload_ratio")))
    root.at("model").at("motor").fail("give critical_slip, or nominal_slip with overload_ratio (eq. 27a), not both");
  if (!has("motor.critical_slip"))
    m.drive.motor.critical_slip = mech::InductionMotor::critical_slip_from(m.nominal_slip, m.overload_ratio);
  auto vars = opt::parse_variables(root, opt::parameters(kTable, m));
  return std::make_unique<ElasticDriveProblem>(std::move(m), std::move(vars));
}

const Registration kRegistration{
    {"elastic_drive", "two-mass elastic drive with an induction motor, on SUNDIALS (seed 001)",
     opt::parameters(kTable, default_model()), make_elastic_drive}};

}  // namespace problems
