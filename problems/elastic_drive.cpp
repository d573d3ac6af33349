#include "problems/elastic_drive.hpp"

#include <cmath>
#include <memory>
#include <numbers>
#include <type_traits>

#include "mech/drive_dynamics.hpp"
#include "mech/linkage/machine.hpp"
#include "opt/parameters.hpp"
#include "problems/linkage/description.hpp"
#include "problems/linkage/kinks.hpp"
#include "problems/model_problem.hpp"

namespace problems {
namespace {

using linkage::Description;

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

// The model values: the rows of kTable. The defaults are libmech's seed 001
// drive with the assumptions its text leaves open (docs/reproduction.md):
// the printed roller loads (2 x 7962 N per cart) stall the 11 kW motor, so
// the carts take seed 000's F_B = 3562 N with the vertical forces balanced,
// the resistance opposes the motion, and a start-up begins at the motor's
// synchronous speed (Kloss's starting torque cannot start the load).
struct R {
  enum Id : int {
    stiffness, damping, rod_length, phase_shift, motor_synchronous_speed, motor_critical_torque, motor_critical_slip,
    motor_nominal_slip, motor_overload_ratio, motor_rotor_inertia, coupling_inertia, gear_ratio, gearbox_factor,
    drive_efficiency, crank_radius, layout, kinematics, cart_mass, rod_mass, crank_inertia, roller_horizontal,
    roller_vertical, cart_weight, guide_friction, resistance, fidelity, coupling_side, start_speed, warmup,
    startup_time, curves, ode_method, ode_rtol, ode_atol, ode_max_steps
  };
};

const mech::ElasticDrive kDrive{};
const mech::OdeOptions kOde{};
const opt::Domain kFraction{0, 1, true, false};

const std::vector<opt::Parameter> kTable = opt::table(
    "elastic_drive",
    {
     {R::stiffness, variable("stiffness", Dimension::rotational_stiffness, kPositive,
         "c, coupling stiffness at the crank axis", "seed 001 eq. (29)"), kDrive.stiffness},
     {R::damping, variable("damping", Dimension::rotational_damping, kNonNegative,
         "k, coupling damping at the crank axis", "seed 001 eq. (40)"), kDrive.damping},
     {R::rod_length, variable("rod_length", Dimension::length, kPositive, "l (l <= r: cannot_assemble)",
         "seed 001 eq. (36)"), kDrive.rod_length},
     {R::phase_shift, variable("phase_shift", Dimension::angle, kAnyValue, "crank 2 leads crank 1 by this angle",
         "seed 001 eq. (37)"), kDrive.phase_shift},
     {R::motor_synchronous_speed, quantity("motor.synchronous_speed", Dimension::angular_speed, kPositive,
         "w0, motor shaft (4A160S6U3)", "seed 001 eq. (27)"), kDrive.motor.synchronous_speed},
     {R::motor_critical_torque, quantity("motor.critical_torque", Dimension::torque, kPositive, "M_kr, motor shaft",
         "seed 001 eq. (27)"), kDrive.motor.critical_torque},
     {R::motor_critical_slip, quantity("motor.critical_slip", Dimension::dimensionless, kFraction,
         "s_kr (default: from nominal_slip and overload_ratio; give one or the other)", "seed 001 eq. (27a)"),
         mech::InductionMotor::critical_slip_from(0.025, 2.0)},
     {R::motor_nominal_slip, quantity("motor.nominal_slip", Dimension::dimensionless, {0, 1, true, true},
         "s_n, for s_kr", "seed 001 eq. (27a)"), 0.025},
     {R::motor_overload_ratio, quantity("motor.overload_ratio", Dimension::dimensionless, {1, HUGE_VAL, true, false},
         "lambda, for s_kr", "seed 001 eq. (27a)"), 2.0},
     {R::motor_rotor_inertia, quantity("motor.rotor_inertia", Dimension::inertia, kNonNegative, "J_p, motor shaft",
         "seed 001 eq. (1)"), kDrive.motor.rotor_inertia},
     {R::coupling_inertia, quantity("coupling_inertia", Dimension::inertia, kNonNegative, "J_m, motor shaft",
         "seed 001 eq. (1)"), kDrive.coupling_inertia},
     {R::gear_ratio, quantity("gear_ratio", Dimension::dimensionless, kPositive, "u", "seed 001 eq. (1)"),
         kDrive.gear_ratio},
     {R::gearbox_factor, quantity("gearbox_factor", Dimension::dimensionless, {1, HUGE_VAL, false, false},
         "delta: gearbox inertia reduced to the motor shaft (unstated in the paper)", "seed 001 eq. (1)"),
         kDrive.gearbox_factor},
     {R::drive_efficiency, quantity("drive_efficiency", Dimension::dimensionless, kFraction,
         "eta_n (unstated in the paper)", "seed 001 eq. (1)"), kDrive.drive_efficiency},
     {R::crank_radius, quantity("crank_radius", Dimension::length, kPositive, "r", "seed 001 eq. (36)"),
         kDrive.crank_radius},
     {R::layout, choice("layout", {"opposed", "same_side"}, "second slider mirrored, or on the same side as the first",
         "seed 001 eq. (37)"), static_cast<int>(kDrive.same_side)},
     {R::kinematics, choice("kinematics", {"exact", "binomial"}, "exact slider-crank, or the binomial series",
         "seed 001 eqs (36)-(39)"), static_cast<int>(kDrive.kinematics)},
     {R::cart_mass, quantity("cart_mass", Dimension::mass, kNonNegative, "m'_B, each cart", "seed 001 eq. (3)"),
         kDrive.cart_mass},
     {R::rod_mass, quantity("rod_mass", Dimension::mass, kNonNegative,
         "m_sh, each rod: half at the pin, half at the cart", "seed 001 eqs (2)-(3)"), kDrive.rod_mass},
     {R::crank_inertia, quantity("crank_inertia", Dimension::inertia, kNonNegative,
         "J'_k, each crank about its axis (unstated: 0)", "seed 001 eq. (2)"), kDrive.crank_inertia},
     {R::roller_horizontal, quantity("roller_horizontal", Dimension::force, kNonNegative,
         "F_01 + F_02 per cart (seed 000's F_B; the printed 2 x 7962 N stall the motor)", "seed 001 eq. (12)"), 3562},
     {R::roller_vertical, quantity("roller_vertical", Dimension::force, kNonNegative, "R_01 + R_02 per cart",
         "seed 001 eq. (13)"), 10124.9},
     {R::cart_weight, quantity("cart_weight", Dimension::force, kNonNegative, "G per cart", "seed 001 eq. (13)"),
         kDrive.cart_weight},
     {R::guide_friction, quantity("guide_friction", Dimension::dimensionless, kNonNegative, "f_np of the cart guides",
         "seed 001 eq. (12)"), kDrive.guide_friction},
     {R::resistance, choice("resistance", {"signed", "opposes_motion"},
         "as printed (signed), or opposing the crank's motion (regularised over 1e-3 rad/s)", "seed 001 eqs (18)-(20)"),
         1},
     {R::fidelity, choice("fidelity", {"rigid", "elastic"}, "one rigid mass, or two masses joined by the coupling",
         "seed 001 eq. (29)").fidelity({"rigid", "elastic"}), static_cast<int>(kDrive.fidelity)},
     {R::coupling_side, choice("coupling_side", {"crank", "motor"},
         "coupling torques reported at the crank, or on the motor shaft (divided by u eta)", ""), 0},
     {R::start_speed, quantity("start_speed", Dimension::angular_speed, kNonNegative,
         "crank speed at the start of a start-up (0: rest)", ""), 10.686},
     {R::warmup, quantity("warmup", Dimension::time, kNonNegative,
         "start-up seconds whose last revolution is the steady state's first guess (0: the rigid estimate)", ""), 0},
     {R::startup_time, quantity("startup_time", Dimension::time, kPositive, "length of the start-up transient", ""),
         5.0},
     {R::curves, choice("curves", {"steady", "startup"}, "what cycle.svg and cycle.csv show", ""), 0},
     {R::ode_method, choice("ode.method", {"bdf", "adams", "erk"},
         "CVODE BDF (stiff), CVODE Adams (functional iteration) or ARKODE Dormand-Prince 5(4)", ""), kOde.method},
     {R::ode_rtol, quantity("ode.rtol", Dimension::dimensionless, {0, 1, true, true}, "relative tolerance", ""),
         kOde.rtol},
     {R::ode_atol, quantity("ode.atol", Dimension::dimensionless, kPositive,
         "absolute tolerance (steady state: relative to each state's scale)", ""), kOde.atol},
     {R::ode_max_steps, whole("ode.max_steps", {10, 100000000, false, false}, "step budget of one whole integration",
         ""), kOde.max_steps}
    });

// The rows of the twin slider-crank and its carts, which a `machine`
// replaces (a config that gives both is an error at the row's key).
constexpr R::Id kTwinRows[] = {R::rod_length,   R::phase_shift, R::crank_radius, R::layout,
                               R::kinematics,   R::cart_mass,   R::rod_mass,     R::crank_inertia,
                               R::roller_horizontal, R::roller_vertical, R::cart_weight, R::guide_friction,
                               R::resistance};

// libmech's drive from the model values.
mech::ElasticDrive drive_of(const opt::Values<double>& v) {
  mech::ElasticDrive d;
  d.stiffness = v[R::stiffness];
  d.damping = v[R::damping];
  d.rod_length = v[R::rod_length];
  d.phase_shift = v[R::phase_shift];
  d.motor.synchronous_speed = v[R::motor_synchronous_speed];
  d.motor.critical_torque = v[R::motor_critical_torque];
  d.motor.critical_slip = v[R::motor_critical_slip];
  d.motor.rotor_inertia = v[R::motor_rotor_inertia];
  d.coupling_inertia = v[R::coupling_inertia];
  d.gear_ratio = v[R::gear_ratio];
  d.gearbox_factor = v[R::gearbox_factor];
  d.drive_efficiency = v[R::drive_efficiency];
  d.crank_radius = v[R::crank_radius];
  d.same_side = v[R::layout] != 0;
  d.kinematics = static_cast<mech::Kinematics>(v[R::kinematics]);
  d.cart_mass = v[R::cart_mass];
  d.rod_mass = v[R::rod_mass];
  d.crank_inertia = v[R::crank_inertia];
  d.roller_horizontal = v[R::roller_horizontal];
  d.roller_vertical = v[R::roller_vertical];
  d.cart_weight = v[R::cart_weight];
  d.guide_friction = v[R::guide_friction];
  d.resistance_opposes_motion = v[R::resistance] != 0;
  d.fidelity = static_cast<mech::DriveFidelity>(v[R::fidelity]);
  return d;
}

mech::OdeOptions ode_of(const opt::Values<double>& v) {
  mech::OdeOptions o;
  o.method = static_cast<mech::OdeMethod>(v[R::ode_method]);
  o.rtol = v[R::ode_rtol];
  o.atol = v[R::ode_atol];
  o.max_steps = static_cast<long>(v[R::ode_max_steps]);
  return o;
}

// On double only (no autodiff through SUNDIALS): a TabledProblem with its
// own evaluate_model_at. With a machine its table is kTable and then the
// machine description's rows, each under `machine.`.
class ElasticDriveProblem : public TabledProblem {
 public:
  ElasticDriveProblem(std::vector<opt::Parameter> table, opt::Values<double> values, std::vector<opt::Variable> vars,
                      std::shared_ptr<const Description> machine)
      : TabledProblem("elastic_drive", kMetrics, std::move(table), std::move(values), std::move(vars)),
        machine_(std::move(machine)), ode_(ode_of(this->values())), motor_side_(this->values()[R::coupling_side] != 0),
        startup_curves_(this->values()[R::curves] != 0), start_speed_(this->values()[R::start_speed]),
        warmup_(this->values()[R::warmup]), startup_time_(this->values()[R::startup_time]) {}

  // s_kr: given, or from nominal_slip and overload_ratio (eq. 27a), not
  // both; with a machine, no row of the twin slider-crank.
  static void resolve(opt::Values<double>& v, const opt::ConfigNode& root) {
    if (root.has("model") && root.at("model").has("machine"))
      for (const R::Id r : kTwinRows)
        if (root.at("model").has(kTable[r].name))
          root.at("model").at(kTable[r].name).fail("the machine replaces the twin slider-crank, whose value this is");
    const bool motor = root.has("model") && root.at("model").has("motor");
    auto has = [&](const char* k) { return motor && root.at("model").at("motor").has(k); };
    if (has("critical_slip") && (has("nominal_slip") || has("overload_ratio")))
      root.at("model").at("motor").fail("give critical_slip, or nominal_slip with overload_ratio (eq. 27a), not both");
    if (!has("critical_slip"))
      v[R::motor_critical_slip] =
          mech::InductionMotor::critical_slip_from(v[R::motor_nominal_slip], v[R::motor_overload_ratio]);
  }

  bool provides_gradients() const override { return false; }

  opt::Evaluation evaluate_model_at(const Eigen::VectorXd& x, const opt::MetricSet& wanted,
                                    bool) const override {
    return with_drive(x, [&](const mech::ElasticDrive& d) { return evaluate(d, wanted); });
  }

  opt::CycleCurves cycle_curves(const Eigen::VectorXd& x, int) const override {
    return with_drive(x, [&](const mech::ElasticDrive& d) { return curves(d); });
  }

  nlohmann::json settings() const override {
    nlohmann::json model = model_json();
    if (machine_)
      for (const R::Id r : kTwinRows) model.erase(kTable[r].name);  // not read
    model["derived"] = {{"motor_side_inertia", drive_of(values()).motor_side_inertia()}};
    nlohmann::json numerics = {
        {"steady_state", "shooting over one revolution in the crank angle: one revolution from "
                         "the first guess (rigid estimate, or the start-up after warmup "
                         "seconds), then KINSOL Newton with the monodromy matrix if it "
                         "does not repeat; extrema by root finding"}};
    if (machine_)
      numerics["machine"] = "the linkage of model.machine solved at every crank angle the integration asks "
                            "(on a Dual in phi where the Jacobian needs slopes): J_p2, J_p2'/2 and M_p2 "
                            "are its own; its crank speed is not read";
    return {{"model", model}, {"numerics", numerics}, {"units", "SI at the crank axis (motor_* on the motor shaft)"}};
  }

 private:
  // f(d) with libmech's drive at x: with a machine, the linkage at the
  // machine's rows (a law's contact placed where its depth says) drives it.
  template <class F>
  std::invoke_result_t<F, const mech::ElasticDrive&> with_drive(const Eigen::VectorXd& x, F&& f) const {
    const opt::Values<double> v = values_at(x);
    mech::ElasticDrive d = drive_of(v);
    if (!machine_) return f(d);
    std::vector<double> mv(v.begin() + static_cast<long>(kTable.size()), v.end()), plain, grid;
    if (!machine_->derived.empty()) {
      mech::linkage::State<double> sd;
      sd.resize(machine_->chain);
      linkage::placed(machine_->chain, machine_->mean_points(), mv, plain, grid, sd);
    }
    const mech::linkage::LinkageMachine m(machine_->chain, std::move(mv), machine_->mean_points());
    d.machine = &m;
    return f(d);
  }

  opt::Evaluation evaluate(const mech::ElasticDrive& d, const opt::MetricSet& wanted) const {
    opt::Evaluation e;
    MetricSink<double> out(wanted, e);
    auto put = [&](M::Id id, double v) { out.put(id, v); };
    const auto s = mech::steady_by_shooting(d, ode_, 0, warmup_, start_speed_);
    if (s.status != mech::Status::ok) {
      e.status = s.status;
      e.message = s.message;
      return e;
    }
    const double side = motor_side_ ? 1.0 / (d.gear_ratio * d.drive_efficiency) : 1.0;
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
      const auto st = mech::simulate_startup(d, ode_, startup_time_, 1e-3, &s, start_speed_);
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

  opt::CycleCurves curves(const mech::ElasticDrive& d) const {
    const double side = motor_side_ ? 1.0 / (d.gear_ratio * d.drive_efficiency) : 1.0;
    opt::CycleCurves c{{"time", "coupling_torque", "crank_speed", "motor_speed"}, {"s", "N m", "rad/s", "rad/s"}};
    mech::Trajectory tr;
    if (startup_curves_) {
      const auto st = mech::simulate_startup(d, ode_, startup_time_, 2e-3, nullptr, start_speed_);
      if (st.status != mech::Status::ok) return {};
      tr = st.trajectory;
    } else {
      const auto s = mech::steady_by_shooting(d, ode_, 720, warmup_, start_speed_);
      if (s.status != mech::Status::ok) return {};
      tr = s.cycle;
    }
    for (size_t i = 0; i < tr.t.size(); ++i)
      c.add_row({tr.t[i], tr.coupling[i] * side, tr.w2[i], tr.w1[i] * d.gear_ratio});
    return c;
  }

  std::shared_ptr<const Description> machine_;  // the driven linkage (model.machine), or none
  mech::OdeOptions ode_;
  bool motor_side_;      // coupling torques on the motor shaft (crank / (u eta))
  bool startup_curves_;  // cycle.csv shows the start-up
  double start_speed_;   // crank speed at the start [rad/s]; 0: from rest
  double warmup_;        // start-up seconds whose end is the first guess (0: rigid estimate)
  double startup_time_;  // start-up transient length [s]
};

// The description under model.machine, or none; one without masses is an
// error there (the drive divides by its inertia).
std::shared_ptr<const Description> machine_of(const opt::ConfigNode& root) {
  if (!root.has("model") || !root.at("model").has("machine")) return nullptr;
  const opt::ConfigNode m = root.at("model").at("machine");
  auto d = std::make_shared<const Description>(linkage::read_model(m));
  if (!d->has_mass)
    m.fail("the drive's machine needs " + std::string(linkage::kNeedsMasses) + ": this description has none");
  return d;
}

// kTable, then the machine's rows (if any) under `machine.`.
std::vector<opt::Parameter> table_of(const Description* machine) {
  std::vector<opt::Parameter> t = kTable;
  if (machine)
    for (opt::Parameter p : machine->table) {
      p.name = "machine." + p.name;
      t.push_back(std::move(p));
    }
  return t;
}

}  // namespace

std::unique_ptr<opt::Problem> make_elastic_drive(const opt::ConfigNode& root) {
  std::shared_ptr<const Description> machine = machine_of(root);
  std::vector<opt::Parameter> table = table_of(machine.get());
  opt::Values<double> v = opt::read_values(root, kTable, {"machine"});
  ElasticDriveProblem::resolve(v, root);
  if (machine) v.insert(v.end(), machine->chain.defaults().begin(), machine->chain.defaults().end());
  std::vector<opt::Variable> vars = opt::parse_variables(root, opt::with_values(table, v));
  if (machine) {
    for (const auto& var : vars)
      for (const R::Id r : kTwinRows)
        if (var.name == kTable[r].name)
          root.at("variables").at(var.name).fail("the machine replaces the twin slider-crank, whose value this is");
    linkage::check_derived_not_free(*machine, root, vars, "machine.");
  }
  return std::make_unique<ElasticDriveProblem>(std::move(table), std::move(v), std::move(vars), std::move(machine));
}

namespace {
const opt::Registration kRegistration{
    {"elastic_drive",
     "two-mass elastic drive with an induction motor, on SUNDIALS (seed 001): the twin slider-crank, or any "
     "linkage as model.machine (docs/linkage.md)",
     kTable, make_elastic_drive, [](const opt::ConfigNode& root) { return table_of(machine_of(root).get()); }}};
}  // namespace

}  // namespace problems
