// Slider-crank balanced by a fixed circular cam and springs: the main
// mechanism of the two-storey sawmill frame 2R63 (seed 004, Pasika 2017).
// The crank is a slotted arm; a block sliding in the slot carries the crank
// pin A and a roller on a fixed circular cam of radius l1 centred at
// C = (-a, 0), so |OA| = r(phi) varies (eq. 1) and the slider moves nearly by
// the cosine law; springs parallel to the stroke then cancel the slider's
// inertia. The original mechanism is the plain slider-crank (r = l1, no cam,
// no springs): `cam = false`.
//
// Frame: crank axis O at the origin, x along the stroke toward the slider,
// phi = 0 with the crank toward the slider (outer dead centre). The slider B
// runs on the x axis; its travel s = x0 - x_B grows toward the crank. The
// crank turns at constant speed w (kinetostatics); the crank and the block
// are massless. Positions are exact and their angle derivatives closed forms
// (the paper's approximate kinematics (2) and (5) are not used); forces by
// Newton-Euler, checked against the power balance. Design and readings:
// docs/design/balanced_slider_crank.md. Units: SI, radians.
#pragma once
#include <array>
#include <cmath>
#include <vector>

#include "mech/autodiff.hpp"
#include "mech/cycle.hpp"
#include "mech/status.hpp"

namespace mech {

// Which way gravity acts: across the stroke (the paper's eq. 3), not at all,
// or along it toward the crank (a vertical frame with the crank below).
enum class Gravity { perpendicular, none, along_stroke };
inline constexpr double kStandardGravity = 9.81;  // [m/s^2], the paper's g

template <class S>
struct BalancedSliderCrank {
  S crank_length;    // l1 [m] > 0: the original crank and the cam's radius; stroke 2 l1
  S cam_offset;      // a [m] in [0, l1): the cam centre C = (-a, 0); unused without the cam
  S rod_length;      // L [m] > l1 + a
  S stroke_origin;   // x0 [m]: s = x0 - x_B (l1 + l2 of the original: s = 0 at its outer dead centre)
  S rod_mass;        // m2 [kg] >= 0
  S rod_inertia;     // I_S2 [kg m^2] >= 0, about the rod's centre of mass
  S rod_centre;      // k = |A S2| / L in [0, 1]
  S slider_mass;     // m3 [kg] >= 0
  S spring_rate;     // c [N/m] >= 0
  S spring_neutral;  // s0 [m]: the springs push the slider by c (s - s0) along +x
  S crank_speed;     // w [rad/s] > 0, constant
  Gravity gravity = Gravity::perpendicular;
  bool cam = true;   // false: the original mechanism (pin fixed on the crank, r = l1)

  template <class T>
  BalancedSliderCrank<T> cast() const {
    return {T(value(crank_length)), T(value(cam_offset)),  T(value(rod_length)),  T(value(stroke_origin)),
            T(value(rod_mass)),     T(value(rod_inertia)), T(value(rod_centre)),  T(value(slider_mass)),
            T(value(spring_rate)),  T(value(spring_neutral)), T(value(crank_speed)), gravity, cam};
  }
  double gravity_x() const { return gravity == Gravity::along_stroke ? -kStandardGravity : 0.0; }
  double gravity_y() const { return gravity == Gravity::perpendicular ? -kStandardGravity : 0.0; }
};

// Why a design cannot run: a value outside its domain, or a rod that cannot
// reach the slider axis (L <= l1 + a), or a cam the crank pin cannot follow
// (a >= l1: r(pi/2) = 0).
template <class S>
Status check(const BalancedSliderCrank<S>& m) {
  const double l1 = value(m.crank_length), a = m.cam ? value(m.cam_offset) : 0.0;
  const double k = value(m.rod_centre);
  if (!(l1 > 0 && a >= 0 && value(m.rod_length) > 0 && value(m.rod_mass) >= 0 && value(m.rod_inertia) >= 0 &&
        k >= 0 && k <= 1 && value(m.slider_mass) >= 0 && value(m.spring_rate) >= 0 &&
        std::isfinite(value(m.spring_neutral)) && std::isfinite(value(m.stroke_origin)) &&
        value(m.crank_speed) > 0))
    return Status::invalid_parameter;
  if (!(a < l1 && value(m.rod_length) > l1 + a)) return Status::cannot_assemble;
  return Status::ok;
}

// A function of the crank angle with its first two phi-derivatives.
template <class S>
struct Jet {
  S v, d, dd;
};

template <class S>
Jet<S> operator*(const Jet<S>& f, const Jet<S>& g) {
  return {f.v * g.v, f.d * g.v + f.v * g.d, f.dd * g.v + 2.0 * f.d * g.d + f.v * g.dd};
}

template <class S>
Jet<S> jet_sqrt(const Jet<S>& u) {
  using std::sqrt;
  const S r = sqrt(u.v), d = u.d / (2.0 * r);
  return {r, d, (u.dd - 2.0 * d * d) / (2.0 * r)};
}

// Crank-pin radius on the cam, r = -a cos(phi) + sqrt(l1^2 - a^2 sin^2 phi), and its derivatives: seed 004 eq. (1).
template <class S>
Jet<S> cam_radius(const BalancedSliderCrank<S>& m, const S& c, const S& s) {
  if (!m.cam) return {m.crank_length, S(0.0), S(0.0)};
  const S& a = m.cam_offset;
  const Jet<S> as{a * s, a * c, -a * s}, as2 = as * as;
  const Jet<S> q = jet_sqrt(Jet<S>{m.crank_length * m.crank_length - as2.v, -as2.d, -as2.dd});
  return {q.v - a * c, q.d + a * s, q.dd + a * c};
}

// Positions of the joints and their phi-derivatives (velocities are w d, accelerations w^2 dd).
template <class S>
struct BalancedKinematics {
  S c, s_phi;           // cos phi, sin phi
  Jet<S> r, ax, ay;     // crank-pin radius and the pin A
  Jet<S> bx;            // the slider B on the x axis
  Jet<S> phi2;          // rod angle, sin phi2 = -r sin(phi) / L
  Jet<S> gx, gy;        // the rod's centre of mass S2 = A + k (B - A)
  S s;                  // slider travel x0 - x_B
};

// Exact kinematics at crank angle phi: seed 004 eqs (1)-(2), positions from
// the geometry, derivatives in closed form. check(m) must be ok.
template <class S>
BalancedKinematics<S> balanced_kinematics(const BalancedSliderCrank<S>& m, const S& phi) {
  using std::cos;
  using std::sin;
  BalancedKinematics<S> k;
  k.c = cos(phi);
  k.s_phi = sin(phi);
  const Jet<S> cj{k.c, -k.s_phi, -k.c}, sj{k.s_phi, k.c, -k.s_phi};
  k.r = cam_radius(m, k.c, k.s_phi);
  k.ax = k.r * cj;
  k.ay = k.r * sj;
  const Jet<S> ay2 = k.ay * k.ay;
  const Jet<S> D = jet_sqrt(Jet<S>{m.rod_length * m.rod_length - ay2.v, -ay2.d, -ay2.dd});  // L cos phi2
  k.bx = {k.ax.v + D.v, k.ax.d + D.d, k.ax.dd + D.dd};
  using std::asin;
  k.phi2 = {asin(-k.ay.v / m.rod_length), -k.ay.d / D.v, -(k.ay.dd * D.v - k.ay.d * D.d) / (D.v * D.v)};
  const S& kk = m.rod_centre;
  k.gx = {k.ax.v + kk * D.v, k.ax.d + kk * D.d, k.ax.dd + kk * D.dd};
  k.gy = {(1.0 - kk) * k.ay.v, (1.0 - kk) * k.ay.d, (1.0 - kk) * k.ay.dd};
  k.s = m.stroke_origin - k.bx.v;
  return k;
}

// Joint forces and the balancing torque at one crank angle.
template <class S>
struct BalancedPoint {
  BalancedKinematics<S> k;
  S spring;               // spring force on the slider along +x, c (s - s0)
  S pin_x, pin_y;         // F_A: force of the crank (or block) on the rod at A
  S guide;                // N3: the guide's force on the slider (y)
  S cam;                  // N_c: the cam's force on the block along its outward normal (< 0: toward C)
  S pressure_angle;       // nu: the cam normal against the slot, tan nu = r'/r
  S bearing_x, bearing_y; // R_O: the bearing's force on the crank
  S torque;               // M_b: the balancing (driving) torque on the crank, eq. (4)
  S slider_residual;      // m3 a_Bx - spring: what the rod still gives the slider along x
  S inertia_x, inertia_y; // -(m2 a_S2 + m3 a_B): the shaking force on the frame
  S rod_inertia;          // m2 |a_S2|
};

// Kinetostatics by force analysis at crank angle phi: seed 004 eqs (3)-(4)
// (docs/design/balanced_slider_crank.md section 4). check(m) must be ok.
template <class S>
BalancedPoint<S> balanced_point(const BalancedSliderCrank<S>& m, const S& phi) {
  using std::atan2;
  using std::sqrt;
  BalancedPoint<S> p;
  p.k = balanced_kinematics(m, phi);
  const auto& k = p.k;
  const S w2 = m.crank_speed * m.crank_speed;
  const double gx = m.gravity_x(), gy = m.gravity_y();
  const S agx = w2 * k.gx.dd, agy = w2 * k.gy.dd, ab = w2 * k.bx.dd, eps2 = w2 * k.phi2.dd;
  p.spring = m.spring_rate * (k.s - m.spring_neutral);
  p.slider_residual = m.slider_mass * ab - p.spring;
  // Slider along x, then the rod's forces and moment about S2.
  const S fbx = -(p.slider_residual - m.slider_mass * gx);
  p.pin_x = m.rod_mass * (agx - gx) - fbx;
  const S py = m.rod_mass * (agy - gy);
  const S asx = k.ax.v - k.gx.v, asy = k.ay.v - k.gy.v, bsy = -k.gy.v;
  const S fby = (m.rod_inertia * eps2 - asx * py + asy * p.pin_x + bsy * fbx) / (k.bx.v - k.ax.v);
  p.pin_y = py - fby;
  p.guide = fby - m.slider_mass * gy;
  if (!m.cam) {
    p.cam = S(0.0);
    p.pressure_angle = S(0.0);
    p.torque = k.ax.v * p.pin_y - k.ay.v * p.pin_x;
    p.bearing_x = p.pin_x;
    p.bearing_y = p.pin_y;
  } else {
    // Massless block: -F_A + T e_t (the slot) + N_c n (the cam) = 0.
    const S nx = (k.ax.v + m.cam_offset) / m.crank_length, ny = k.ay.v / m.crank_length;
    const S n_r = nx * k.c + ny * k.s_phi, n_t = ny * k.c - nx * k.s_phi;
    const S f_r = p.pin_x * k.c + p.pin_y * k.s_phi, f_t = p.pin_y * k.c - p.pin_x * k.s_phi;
    p.cam = f_r / n_r;
    const S t = f_t - p.cam * n_t;
    p.pressure_angle = atan2(S(-n_t), n_r);
    p.torque = k.r.v * t;  // eq. (4): M = R14 r
    p.bearing_x = -t * k.s_phi;
    p.bearing_y = t * k.c;
  }
  p.inertia_x = -(m.rod_mass * agx + m.slider_mass * ab);
  p.inertia_y = -m.rod_mass * agy;
  p.rod_inertia = m.rod_mass * sqrt(agx * agx + agy * agy);
  return p;
}

template <class S>
S hypot2(const S& x, const S& y) {
  using std::sqrt;
  return sqrt(x * x + y * y);
}

// The balancing torque by the power balance, the paper's eq. (5) corrected
// (with omega_2 and the springs): M_b w = dT/dt - P_springs - P_gravity.
template <class S>
S power_balance_torque(const BalancedSliderCrank<S>& m, const BalancedKinematics<S>& k) {
  const S w = m.crank_speed;
  const double gx = m.gravity_x(), gy = m.gravity_y();
  const S spring = m.spring_rate * (k.s - m.spring_neutral);
  const S per_w3 = m.rod_mass * (k.gx.dd * k.gx.d + k.gy.dd * k.gy.d) + m.rod_inertia * k.phi2.dd * k.phi2.d +
                   m.slider_mass * k.bx.dd * k.bx.d;
  const S per_w = -spring * k.bx.d - m.rod_mass * (gx * k.gx.d + gy * k.gy.d) - m.slider_mass * gx * k.bx.d;
  return w * w * per_w3 + per_w;
}

// Kinetic plus potential energy (springs and gravity) [J]: its swing over a
// revolution is what a flywheel must absorb.
template <class S>
S mechanical_energy(const BalancedSliderCrank<S>& m, const BalancedKinematics<S>& k) {
  const S w2 = m.crank_speed * m.crank_speed, e = k.s - m.spring_neutral;
  const S kinetic = m.rod_mass * (k.gx.d * k.gx.d + k.gy.d * k.gy.d) + m.rod_inertia * k.phi2.d * k.phi2.d +
                    m.slider_mass * k.bx.d * k.bx.d;
  return 0.5 * (w2 * kinetic + m.spring_rate * e * e) -
         m.rod_mass * (m.gravity_x() * k.gx.v + m.gravity_y() * k.gy.v) - m.slider_mass * m.gravity_x() * k.bx.v;
}

// The deviations of the slider's travel and its first two phi-derivatives
// from the cosine law s_c = l1 (1 - cos phi), relative to S/2 = l1 (the
// same as v / (w S/2) and a / (w^2 S/2)).
template <class S>
Jet<S> cosine_law_deviation(const BalancedSliderCrank<S>& m, const BalancedKinematics<S>& k) {
  const S& l1 = m.crank_length;
  return {(k.s - l1 * (1.0 - k.c)) / l1, (-k.bx.d - l1 * k.s_phi) / l1, (-k.bx.dd - l1 * k.c) / l1};
}

// Angles of the balancing torque's extremes compared by the paper's n_d
// (seed 004, after eq. 5): the largest M_b in the first and third quarter
// turns, the least in the second and fourth (each mechanism of the paper
// has one local extremum in each; a quarter without one gives its end).
// Local extrema on an n-point grid refined by Brent. check(m) must be ok.
template <class S>
std::array<double, 4> quarter_torque_extremum_angles(const BalancedSliderCrank<S>& m, int n) {
  auto torque = [](const auto& k, const auto& phi) { return balanced_point(k, phi).torque; };
  auto minus_torque = [&](const auto& k, const auto& phi) {
    const auto t = torque(k, phi);
    return decltype(t)(-t);
  };
  const auto md = m.template cast<double>();
  const std::vector<double> found[2] = {cycle_max_angles(md, n, torque), cycle_max_angles(md, n, minus_torque)};
  std::array<double, 4> out{};
  for (int i = 0; i < 4; ++i) {
    const double sign = i % 2 ? -1.0 : 1.0, lo = i * kTwoPi / 4, hi = (i + 1) * kTwoPi / 4;
    double best = lo;
    auto consider = [&](double phi) {
      if (sign * torque(md, phi) > sign * torque(md, best)) best = phi;
    };
    consider(hi);
    for (double phi : found[i % 2])
      if (phi >= lo && phi <= hi) consider(phi);
    out[i] = best;
  }
  return out;
}

}  // namespace mech
