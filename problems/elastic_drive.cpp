#include "problems/elastic_drive.hpp"

#include <cmath>
#include <numbers>

#include "mech/drive_dynamics.hpp"
#include "problems/model_problem.hpp"

namespace problems {
namespace {

using opt::Dimension;

const std::vector<opt::VariableSpec> kVariables = {
    {"stiffness", Dimension::dimensionless},  // c [N m / rad]
    {"damping", Dimension::dimensionless},    // k [N m s / rad]
    {"rod_length", Dimension::length},
    {"phase_shift", Dimension::angle},
};

// "coupling" metrics on the side chosen by coupling_side.
const std::vector<MetricSpec> kMetrics = {
    {"peak_coupling_torque", "N m"},  // max |c theta + k theta'| over the steady cycle
    {"rms_coupling_torque", "N m"},   // time RMS over the steady cycle
    {"min_coupling_torque", "N m"},
    {"max_coupling_torque", "N m"},
    {"mean_speed", "rad/s"},          // crank, steady cycle
    {"speed_irregularity", ""},       // (w2max - w2min) / w2mean
    {"motor_torque_min", "N m"},      // motor shaft
    {"motor_torque_max", "N m"},
    {"motor_speed_min", "rad/s"},     // motor shaft
    {"motor_speed_max", "rad/s"},
    {"mean_motor_power", "W"},
    {"mean_resistance_power", "W"},
    {"mean_damping_power", "W"},
    {"energy_balance_error", ""},     // |P_motor - P_res - P_damping| / P_motor
    {"largest_multiplier", ""},       // of the steady orbit (< 1: it attracts; docs/config.md)
    {"startup_peak_coupling_torque", "N m"},  // start-up transient
    {"time_to_steady", "s"},          // start-up: every revolution's peak within 1% after it
};

struct Model {
  mech::ElasticDrive drive;
  mech::OdeOptions ode;
  bool motor_side = false;   // report coupling torques on the motor shaft (crank / (u eta))
  double start_speed = 0;    // crank speed at the start [rad/s]; 0: from rest
  double warmup = 0;         // start-up seconds whose end is the first guess (0: rigid estimate)
  double startup_time = 5.0; // start-up transient length [s]
  bool startup_curves = false;
};

class ElasticDriveProblem : public TabledProblem {
 public:
  ElasticDriveProblem(Model m, std::vector<opt::Variable> vars)
      : TabledProblem("elastic_drive", kMetrics, std::move(vars)), m_(std::move(m)) {}

  bool provides_gradients() const override { return false; }

  opt::Evaluation evaluate(const Eigen::VectorXd& x, const std::vector<std::string>& wanted,
                           bool) const override {
    const mech::ElasticDrive d = drive(x);
    auto want = [&](const char* n) {
      return wanted.empty() || std::find(wanted.begin(), wanted.end(), n) != wanted.end();
    };
    opt::Evaluation e;
    auto put = [&](const char* n, double v) {
      if (want(n)) e.metrics[n] = {v, {}};
    };
    const auto s = mech::steady_by_shooting(d, m_.ode, 0, m_.warmup, m_.start_speed);
    if (s.status != mech::Status::ok) {
      e.status = mech::to_string(s.status);
      return e;
    }
    const double side = m_.motor_side ? 1.0 / (d.gear_ratio * d.drive_efficiency) : 1.0;
    put("peak_coupling_torque", s.coupling_peak * side);
    put("rms_coupling_torque", s.coupling_rms * side);
    put("min_coupling_torque", s.coupling_min * side);
    put("max_coupling_torque", s.coupling_max * side);
    put("mean_speed", s.mean_speed);
    put("speed_irregularity", s.speed_irregularity);
    put("motor_torque_min", s.motor_torque_min);
    put("motor_torque_max", s.motor_torque_max);
    put("motor_speed_min", s.motor_speed_min);
    put("motor_speed_max", s.motor_speed_max);
    put("mean_motor_power", s.mean_motor_power);
    put("mean_resistance_power", s.mean_resistance_power);
    put("mean_damping_power", s.mean_damping_power);
    put("energy_balance_error",
        std::abs(s.mean_motor_power - s.mean_resistance_power - s.mean_damping_power) /
            std::max(std::abs(s.mean_motor_power), 1e-12));
    put("largest_multiplier", s.largest_multiplier);
    if (want("startup_peak_coupling_torque") || want("time_to_steady")) {
      const auto st = mech::simulate_startup(d, m_.ode, m_.startup_time, 1e-3, &s, m_.start_speed);
      if (st.status != mech::Status::ok) {  // e.g. too_many_steps: no partial start-up figures
        e.status = mech::to_string(st.status);
        return e;
      }
      put("startup_peak_coupling_torque", st.peak_coupling * side);
      put("time_to_steady", st.time_to_steady);
    }
    return e;
  }

  opt::CycleCurves cycle_curves(const Eigen::VectorXd& x, int) const override {
    const mech::ElasticDrive d = drive(x);
    const double side = m_.motor_side ? 1.0 / (d.gear_ratio * d.drive_efficiency) : 1.0;
    opt::CycleCurves c{{"time", "coupling_torque", "crank_speed", "motor_speed"}, {}};
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
    const auto& d = m_.drive;
    return {{"model",
             {{"motor", {{"synchronous_speed", d.motor.synchronous_speed},
                         {"critical_torque", d.motor.critical_torque},
                         {"critical_slip", d.motor.critical_slip},
                         {"rotor_inertia", d.motor.rotor_inertia}}},
              {"coupling_inertia", d.coupling_inertia}, {"gear_ratio", d.gear_ratio},
              {"gearbox_factor", d.gearbox_factor}, {"drive_efficiency", d.drive_efficiency},
              {"stiffness", d.stiffness}, {"damping", d.damping},
              {"crank_radius", d.crank_radius}, {"rod_length", d.rod_length},
              {"phase_shift", d.phase_shift}, {"layout", d.same_side ? "same_side" : "opposed"},
              {"cart_mass", d.cart_mass}, {"rod_mass", d.rod_mass}, {"crank_inertia", d.crank_inertia},
              {"roller_horizontal", d.roller_horizontal}, {"roller_vertical", d.roller_vertical},
              {"cart_weight", d.cart_weight}, {"guide_friction", d.guide_friction},
              {"resistance", d.resistance_opposes_motion ? "opposes_motion" : "signed"},
              {"coupling_side", m_.motor_side ? "motor" : "crank"},
              {"start_speed", m_.start_speed}, {"warmup", m_.warmup},
              {"motor_side_inertia", d.motor_side_inertia()}}},
            {"fidelity",
             {{"drive", d.fidelity == mech::DriveFidelity::rigid ? "rigid" : "elastic"},
              {"kinematics", d.kinematics == mech::Kinematics::exact ? "exact" : "binomial"}}},
            {"numerics",
             {{"method", m_.ode.method == mech::OdeMethod::bdf     ? "bdf"
                         : m_.ode.method == mech::OdeMethod::adams ? "adams"
                                                                   : "erk"},
              {"rtol", m_.ode.rtol}, {"atol", m_.ode.atol}, {"max_steps", m_.ode.max_steps},
              {"steady_state", "shooting over one revolution in the crank angle: one revolution from "
                               "the first guess (rigid estimate, or the start-up after warmup "
                               "seconds), then KINSOL Newton with the monodromy matrix if it "
                               "does not repeat; extrema by root finding"}}},
            {"units", "SI at the crank axis (motor_* on the motor shaft)"}};
  }

 private:
  mech::ElasticDrive drive(const Eigen::VectorXd& x) const {
    mech::ElasticDrive d = m_.drive;
    for (size_t i = 0; i < variables().size(); ++i) {
      const std::string& n = variables()[i].name;
      if (n == "stiffness") d.stiffness = x[i];
      else if (n == "damping") d.damping = x[i];
      else if (n == "rod_length") d.rod_length = x[i];
      else d.phase_shift = x[i];
    }
    return d;
  }

  Model m_;
};

}  // namespace

const std::vector<opt::VariableSpec>& elastic_drive_variables() { return kVariables; }

std::unique_ptr<opt::Problem> make_elastic_drive(const opt::ConfigNode& root) {
  Model m;
  auto& d = m.drive;
  if (root.has("model")) {
    const opt::ConfigNode n = root.at("model");
    n.allow_only({"motor", "coupling_inertia", "gear_ratio", "gearbox_factor", "drive_efficiency",
                  "stiffness", "damping", "crank_radius", "rod_length", "phase_shift", "layout",
                  "kinematics", "cart_mass", "rod_mass", "crank_inertia", "roller_horizontal",
                  "roller_vertical", "cart_weight", "guide_friction", "resistance", "fidelity",
                  "coupling_side", "start_speed", "warmup", "startup_time", "curves", "ode"});
    if (n.has("motor")) {
      const opt::ConfigNode mo = n.at("motor");
      mo.allow_only({"synchronous_speed", "critical_torque", "critical_slip", "nominal_slip",
                     "overload_ratio", "rotor_inertia"});
      d.motor.synchronous_speed = mo.quantity_or("synchronous_speed", Dimension::angular_speed,
                                                 d.motor.synchronous_speed, opt::kPositive);
      d.motor.critical_torque = mo.quantity_or("critical_torque", Dimension::dimensionless,
                                               d.motor.critical_torque, opt::kPositive);
      d.motor.rotor_inertia = mo.quantity_or("rotor_inertia", Dimension::dimensionless,
                                             d.motor.rotor_inertia, opt::kNonNegative);
      if (mo.has("critical_slip") && (mo.has("nominal_slip") || mo.has("overload_ratio")))
        mo.fail("give critical_slip, or nominal_slip with overload_ratio (eq. 27a), not both");
      d.motor.critical_slip = mo.quantity_or("critical_slip", Dimension::dimensionless,
                                             d.motor.critical_slip, {0, 1, true, false});
      if (mo.has("nominal_slip") || mo.has("overload_ratio")) {
        const double sn = mo.at("nominal_slip").number(), lam = mo.at("overload_ratio").number();
        if (!(sn > 0 && sn < 1)) mo.at("nominal_slip").fail("expected a slip in (0, 1)");
        if (!(lam > 1)) mo.at("overload_ratio").fail("expected an overload ratio > 1");
        d.motor.critical_slip = mech::InductionMotor::critical_slip_from(sn, lam);
      }
    }
    d.coupling_inertia = n.quantity_or("coupling_inertia", Dimension::dimensionless, d.coupling_inertia, opt::kNonNegative);
    d.gear_ratio = n.quantity_or("gear_ratio", Dimension::dimensionless, d.gear_ratio, opt::kPositive);
    d.gearbox_factor = n.quantity_or("gearbox_factor", Dimension::dimensionless, d.gearbox_factor, {1, HUGE_VAL, false, false});
    d.drive_efficiency = n.quantity_or("drive_efficiency", Dimension::dimensionless, d.drive_efficiency, {0, 1, true, false});
    d.stiffness = n.quantity_or("stiffness", Dimension::dimensionless, d.stiffness, opt::kPositive);
    d.damping = n.quantity_or("damping", Dimension::dimensionless, d.damping, opt::kNonNegative);
    d.crank_radius = n.quantity_or("crank_radius", Dimension::length, d.crank_radius, opt::kPositive);
    d.rod_length = n.quantity_or("rod_length", Dimension::length, d.rod_length, opt::kPositive);
    d.phase_shift = n.quantity_or("phase_shift", Dimension::angle, d.phase_shift);
    if (n.has("layout")) d.same_side = n.at("layout").choice({"same_side", "opposed"}) == "same_side";
    if (n.has("kinematics"))
      d.kinematics = n.at("kinematics").choice({"binomial", "exact"}) == "exact" ? mech::Kinematics::exact
                                                                               : mech::Kinematics::binomial;
    d.cart_mass = n.quantity_or("cart_mass", Dimension::mass, d.cart_mass, opt::kNonNegative);
    d.rod_mass = n.quantity_or("rod_mass", Dimension::mass, d.rod_mass, opt::kNonNegative);
    d.crank_inertia = n.quantity_or("crank_inertia", Dimension::dimensionless, d.crank_inertia, opt::kNonNegative);
    d.roller_horizontal = n.quantity_or("roller_horizontal", Dimension::force, d.roller_horizontal, opt::kNonNegative);
    d.roller_vertical = n.quantity_or("roller_vertical", Dimension::force, d.roller_vertical, opt::kNonNegative);
    d.cart_weight = n.quantity_or("cart_weight", Dimension::force, d.cart_weight, opt::kNonNegative);
    d.guide_friction = n.quantity_or("guide_friction", Dimension::dimensionless, d.guide_friction, opt::kNonNegative);
    if (n.has("resistance"))
      d.resistance_opposes_motion = n.at("resistance").choice({"signed", "opposes_motion"}) == "opposes_motion";
    if (n.has("fidelity"))
      d.fidelity = n.at("fidelity").choice({"elastic", "rigid"}) == "rigid" ? mech::DriveFidelity::rigid
                                                                          : mech::DriveFidelity::elastic;
    if (n.has("coupling_side")) m.motor_side = n.at("coupling_side").choice({"crank", "motor"}) == "motor";
    m.start_speed = n.quantity_or("start_speed", Dimension::angular_speed, m.start_speed, opt::kNonNegative);
    m.warmup = n.quantity_or("warmup", Dimension::time, m.warmup, opt::kNonNegative);
    m.startup_time = n.quantity_or("startup_time", Dimension::time, m.startup_time, opt::kPositive);
    if (n.has("curves")) m.startup_curves = n.at("curves").choice({"steady", "startup"}) == "startup";
    if (n.has("ode")) {
      const opt::ConfigNode o = n.at("ode");
      o.allow_only({"method", "rtol", "atol", "max_steps"});
      if (o.has("method")) {
        const std::string me = o.at("method").choice({"bdf", "adams", "erk"});
        m.ode.method = me == "bdf" ? mech::OdeMethod::bdf : me == "adams" ? mech::OdeMethod::adams : mech::OdeMethod::erk;
      }
      m.ode.rtol = o.quantity_or("rtol", Dimension::dimensionless, m.ode.rtol, {0, 1, true, true});
      m.ode.atol = o.quantity_or("atol", Dimension::dimensionless, m.ode.atol, opt::kPositive);
      if (o.has("max_steps")) m.ode.max_steps = o.at("max_steps").integer(10, 100000000);
    }
  }
  const std::map<std::string, double> values = {{"stiffness", d.stiffness}, {"damping", d.damping},
                                                {"rod_length", d.rod_length}, {"phase_shift", d.phase_shift}};
  auto vars = opt::parse_variables(root, kVariables, values);
  return std::make_unique<ElasticDriveProblem>(std::move(m), std::move(vars));
}

}  // namespace problems
