// Two-mass elastic drive of the recuperative roller-forming installation
// (seed 001): an induction motor (Kloss, eq. 27) with its coupling and
// gearbox reduced to the crank axis (J_p1, eq. 1) drives, through stiffness c
// and damping k, the twin slider-crank with angle-dependent reduced inertia
// J_p2(phi2) (eq. 9) against the carts' resistance (eqs 12-20). Equations of
// motion (29), with damping (40):
//   J_p1 phi1'' = M_p1(phi1') - c (phi1 - phi2) - k (phi1' - phi2')
//   J_p2 phi2'' + J_p2'/2 phi2'^2 = c (phi1 - phi2) + k (phi1' - phi2') - M_p2(phi2)
// The rigid fidelity joins both masses (one degree of freedom). With a
// `machine` (mech/machine.hpp: any linkage, mech/linkage/machine.hpp) the
// drive turns that machine instead: J_p2, J_p2' / 2 and M_p2 are its own.
// Units: SI at the crank axis (rad, rad/s, N m, kg m^2) unless noted.
#pragma once
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>

#include "mech/autodiff.hpp"
#include "mech/machine.hpp"
#include "mech/slider_crank.hpp"
#include "mech/status.hpp"

namespace mech {

// Induction motor by Kloss's formula, eq. (27), on the motor shaft:
// M = 2 M_kr s s_kr / (s^2 + s_kr^2) with slip s = 1 - w / w0 (the printed
// (29)/(40) lost a fraction bar; this is (27)). Critical slip from the nominal
// slip and overload ratio, eq. (27a): s_kr = s_n (lambda + sqrt(lambda^2 - 1)).
struct InductionMotor {
  double synchronous_speed = 104.72;  // w0 [rad/s], motor shaft
  double critical_torque = 215.4;     // M_kr [N m]
  double critical_slip = 0.09330127018922193;  // s_kr from eq. (27a): 0.025 (2 + sqrt 3); printed 0.0933
  double rotor_inertia = 0.138;       // J_p [kg m^2]

  template <class S>
  S torque(const S& motor_speed) const {
    const S s = 1.0 - motor_speed / synchronous_speed;
    return 2.0 * critical_torque * s * critical_slip / (s * s + critical_slip * critical_slip);
  }
  static double critical_slip_from(double nominal_slip, double overload) {
    return nominal_slip * (overload + std::sqrt(overload * overload - 1.0));  // eq. (27a)
  }
};

enum class DriveFidelity { rigid, elastic };

// The crank speed over which a resistance that opposes the motion turns
// from one sign to the other: sign(w2) regularised as tanh(w2 / kRestSpeed),
// so that the right-hand side stays smooth through rest at a start-up (no
// chattering there) [rad/s].
constexpr double kRestSpeed = 1e-3;

struct ElasticDrive {
  InductionMotor motor;
  double coupling_inertia = 0.32;    // J_m [kg m^2], motor shaft
  double gear_ratio = 9.8;           // u
  double gearbox_factor = 1.2;       // delta: gearbox inertia reduced to the motor shaft (unstated)
  double drive_efficiency = 0.9;     // eta_n (unstated)
  double stiffness = 110000;         // c [N m / rad], at the crank axis
  double damping = 2000;             // k [N m s / rad]
  // Mechanism (seed 001: same-side layout, binomial kinematics (36)-(39)).
  double crank_radius = 0.2, rod_length = 0.8, phase_shift = 1.5707963267948966;
  bool same_side = true;
  Kinematics kinematics = Kinematics::binomial;
  double cart_mass = 1000;           // m'_B [kg], each cart
  double rod_mass = 64;              // m_sh [kg], each rod: half at the pin, half at the cart, eq. (2)-(3)
  double crank_inertia = 0;          // J'_k [kg m^2], each crank about its axis (unstated)
  // Cart resistance, eqs (12)-(13): per cart, rollers' horizontal and vertical
  // forces (sums of the two rollers), weight and guide friction.
  double roller_horizontal = 2 * 7962.0;  // F_011 + F_012 [N]
  double roller_vertical = 2 * 9740.0;    // R_011 + R_012 [N]
  double cart_weight = 10124.9;           // G [N]
  double guide_friction = 0.008;          // f_np
  bool resistance_opposes_motion = false; // false: eq. (18)-(20) as printed (signed)
  DriveFidelity fidelity = DriveFidelity::elastic;
  // The driven machine instead of the twin slider-crank above (whose
  // numbers are then not read), or none. Not owned: it outlives the
  // drive's integrations, and one machine serves one thread (its state()
  // keeps scratch).
  const Machine* machine = nullptr;

  // J_p1 = (J_p + J_m) delta u^2, eq. (1).
  double motor_side_inertia() const {
    return (motor.rotor_inertia + coupling_inertia) * gearbox_factor * gear_ratio * gear_ratio;
  }
  // J_k = 2 J'_k + m_sh r^2, eq. (2); m_B = m'_B + m_sh / 2, eq. (3).
  double crank_side_constant_inertia() const {
    return 2 * crank_inertia + rod_mass * crank_radius * crank_radius;
  }
  double lumped_cart_mass() const { return cart_mass + rod_mass / 2; }
  template <class S = double>
  SliderCrank<S> mechanism(int i) const {
    return {S(crank_radius), S(rod_length), S(0.0), (i == 1 && !same_side) ? -1 : 1, kinematics};
  }
  // Driving moment of the motor reduced to the crank axis, eq. (27).
  template <class S>
  S motor_moment(const S& w1) const {
    return gear_ratio * drive_efficiency * motor.torque(S(w1 * gear_ratio));
  }
};

// A value that must lie in its domain, named for the message.
struct DomainCheck {
  const char* name;
  double value;
  bool ok;
};

namespace detail {
inline std::string text(double v) {  // %g: 1e-12 stays 1e-12
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}
}  // namespace detail

// invalid_parameter if a value lies outside its domain (`why`, if given,
// names the first), else ok.
inline Status first_invalid(std::initializer_list<DomainCheck> values, std::string* why) {
  for (const DomainCheck& v : values)
    if (!v.ok) {
      if (why) *why = std::string(v.name) + " = " + detail::text(v.value) + " is outside its domain";
      return Status::invalid_parameter;
    }
  return Status::ok;
}

// Physical domain, then assembly: invalid_parameter (a non-finite value, a
// stiffness <= 0, a negative damping, mass, inertia or force, an efficiency
// outside (0, 1], a slip outside (0, 1), a gearbox factor < 1, a side with
// no inertia), else cannot_assemble (the rod no longer than its crank: it
// cannot reach the slider axis at psi = 90 deg), else ok. With a machine,
// the motor's and the coupling's values, then the machine's own check
// (Machine::check) in place of the twin slider-crank's. `why`, if given,
// gets the reason.
inline Status check(const ElasticDrive& d, std::string* why = nullptr) {
  const auto positive = [](double v) { return v > 0 && std::isfinite(v); };
  const auto non_negative = [](double v) { return v >= 0 && std::isfinite(v); };
  const InductionMotor& m = d.motor;
  const double j1 = d.motor_side_inertia();
  Status s = first_invalid(
      {{"motor synchronous_speed", m.synchronous_speed, positive(m.synchronous_speed)},
       {"motor critical_torque", m.critical_torque, positive(m.critical_torque)},
       {"motor critical_slip", m.critical_slip, m.critical_slip > 0 && m.critical_slip < 1},
       {"motor rotor_inertia", m.rotor_inertia, non_negative(m.rotor_inertia)},
       {"coupling_inertia", d.coupling_inertia, non_negative(d.coupling_inertia)},
       {"gear_ratio", d.gear_ratio, positive(d.gear_ratio)},
       {"gearbox_factor", d.gearbox_factor, d.gearbox_factor >= 1 && std::isfinite(d.gearbox_factor)},
       {"drive_efficiency", d.drive_efficiency, d.drive_efficiency > 0 && d.drive_efficiency <= 1},
       {"stiffness", d.stiffness, positive(d.stiffness)},
       {"damping", d.damping, non_negative(d.damping)}},
      why);
  if (s != Status::ok) return s;
  if (d.machine) {
    s = first_invalid({{"motor-side inertia", j1, j1 > 0}}, why);  // J_p1, eq. (1)
    return s == Status::ok ? d.machine->check(why) : s;
  }
  const double j2 = d.crank_side_constant_inertia() + d.lumped_cart_mass();
  s = first_invalid(
      {{"crank_radius", d.crank_radius, positive(d.crank_radius)},
       {"rod_length", d.rod_length, positive(d.rod_length)},
       {"phase_shift", d.phase_shift, std::isfinite(d.phase_shift)},
       {"cart_mass", d.cart_mass, non_negative(d.cart_mass)},
       {"rod_mass", d.rod_mass, non_negative(d.rod_mass)},
       {"crank_inertia", d.crank_inertia, non_negative(d.crank_inertia)},
       {"roller_horizontal", d.roller_horizontal, non_negative(d.roller_horizontal)},
       {"roller_vertical", d.roller_vertical, non_negative(d.roller_vertical)},
       {"cart_weight", d.cart_weight, non_negative(d.cart_weight)},
       {"guide_friction", d.guide_friction, non_negative(d.guide_friction)},
       // Each side of the coupling needs inertia: J_p1 (eq. 1), and J_k or the carts (eq. 9).
       {"motor-side inertia", j1, j1 > 0},
       {"mechanism inertia", j2, j2 > 0}},
      why);
  if (s != Status::ok) return s;
  if (!assembles_over_cycle(d.mechanism(0))) {
    if (why)
      *why = "rod_length = " + detail::text(d.rod_length) + " is not longer than crank_radius = " +
             detail::text(d.crank_radius) + ": the rod cannot reach the slider axis";
    return Status::cannot_assemble;
  }
  return Status::ok;
}

// Mechanism side at crank angle phi2: J_p2 (eq. 9), J_p2'/2, and the
// resistance moment M_p2 (eqs 18-20, positive resisting the drive).
template <class S>
struct MechanismState {
  S inertia, half_inertia_derivative, resistance;
};

// cos and sin of the cranks' phase shift, computed once per integration
// rather than once per right-hand side.
struct PhaseRotation {
  double c, s;
  explicit PhaseRotation(double shift) : c(std::cos(shift)), s(std::sin(shift)) {}
};

namespace detail {
// Whether phi2 carries a derivative (the start-up's Jacobian seeds the
// crank angle; the shooting's variational equations do not: phi2 is their
// independent variable there).
inline bool moves(double) { return false; }
inline bool moves(const Dual& x) { return x.d != 0; }
template <class D>
bool moves(const Eigen::AutoDiffScalar<D>& x) { return !x.derivatives().isZero(0.0); }
}  // namespace detail

// The machine's numbers at phi2 (Machine::state) on S: each value with its
// slope times phi2's derivatives (the chain rule), the resistance fixed +
// tanh(w2 / kRestSpeed) opposing.
template <class S>
MechanismState<S> machine_state(const Machine& m, const S& phi2, const S& w2) {
  using std::tanh;
  const MachinePoint p = m.state(value(phi2), detail::moves(phi2));
  const S along = S(phi2 - value(phi2));  // phi2's derivatives, its value 0
  const auto at = [&](const Dual& x) -> S {
    if constexpr (is_dual<S>) return S(x.v + x.d * along);
    else return x.v;
  };
  const S opposing = at(p.opposing);
  return {at(p.inertia), at(p.half_slope), S(at(p.fixed) + tanh(w2 / kRestSpeed) * opposing)};
}

template <class S>
MechanismState<S> mechanism_state(const ElasticDrive& d, const S& phi2, const S& w2,
                                  const PhaseRotation& shift) {
  if (d.machine) return machine_state(*d.machine, phi2, w2);
  using std::abs;
  using std::cos;
  using std::sin;
  using std::sqrt;
  using std::tanh;
  MechanismState<S> out;
  const double mB = d.lumped_cart_mass();
  out.inertia = S(d.crank_side_constant_inertia());
  out.half_inertia_derivative = S(0.0);
  out.resistance = S(0.0);
  const double load = (d.roller_vertical - d.cart_weight) * d.guide_friction + d.roller_horizontal;
  const double lambda = d.crank_radius / d.rod_length;
  // One sine and cosine: the second crank's by rotating the first's.
  const S c0 = cos(phi2), s0 = sin(phi2);
  for (int i = 0; i < 2; ++i) {
    const S c = i == 0 ? c0 : S(c0 * shift.c - s0 * shift.s);
    const S s = i == 0 ? s0 : S(s0 * shift.c + c0 * shift.s);
    const auto p = slider_crank_point(d.template mechanism<S>(i), c, s);
    out.inertia += mB * p.dx * p.dx;
    out.half_inertia_derivative += mB * p.dx * p.ddx;
    // Rod angle beta = asin(lambda sin psi), eq. (22), and the rod force F,
    // eqs (12)-(13); sin(psi + beta) expanded.
    const S sb = lambda * s, cb = sqrt(1.0 - sb * sb);
    const S force = load / (cb - d.guide_friction * sb);
    const S moment = force * d.crank_radius * (s * cb + c * sb);  // eqs (18)-(19)
    if (d.resistance_opposes_motion)  // sign(w2), regularised (kRestSpeed)
      out.resistance += tanh(w2 / kRestSpeed) * abs(moment);
    else
      out.resistance += moment;
  }
  return out;
}

// Coupling moment c (phi1 - phi2) + k (phi1' - phi2') at the crank axis.
template <class S>
S coupling_moment(const ElasticDrive& d, const S& theta, const S& w1, const S& w2) {
  return d.stiffness * theta + d.damping * (w1 - w2);
}

// Angular accelerations (a1, a2) of the motor side and the crank at twist
// theta = phi1 - phi2 and speeds w1, w2, eqs (29), (40) (rigid: one, shared).
// Returns the motor's moment at the crank axis.
template <class S>
S accelerations(const ElasticDrive& d, const MechanismState<S>& m, const S& theta, const S& w1,
                const S& w2, S& a1, S& a2) {
  const S drive = d.motor_moment(w1);
  const S load = m.resistance + m.half_inertia_derivative * w2 * w2;
  if (d.fidelity == DriveFidelity::rigid) {
    a1 = a2 = (drive - load) / (d.motor_side_inertia() + m.inertia);
    return drive;
  }
  const S coupling = coupling_moment(d, theta, w1, w2);
  a1 = (drive - coupling) / d.motor_side_inertia();
  a2 = (coupling - load) / m.inertia;
  return drive;
}

// Time derivatives of the state (phi1, phi2, w1, w2) (rigid: phi1 = phi2,
// w1 = w2 kept equal).
template <class S>
void drive_rhs(const ElasticDrive& d, const PhaseRotation& shift, const S* y, S* dy) {
  dy[0] = y[2];
  dy[1] = y[3];
  accelerations(d, mechanism_state(d, y[1], y[3], shift), S(y[0] - y[1]), y[2], y[3], dy[2], dy[3]);
}

}  // namespace mech
