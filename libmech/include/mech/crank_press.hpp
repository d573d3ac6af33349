// Crank-lever brick press (seed 003, exercise 7, eqs 7.1-7.8): a crank of
// radius r drives, through a connecting rod l_sh, a lever pivoted between its
// rod arm l_p and its pusher arm l; the pusher drives the piston that
// compacts m bricks. Quasi-static and frictionless: the crankshaft torque is
// the pressing force times the piston's travel per radian (virtual work),
// which for the guide's reading (lever as a slider, pressing ends at the
// inner dead centre) is eq. (7.6) times r exactly. docs/design/crank_press.md
// derives every reading; phi runs from the dead centre that starts the
// working half-turn (phi = 0) to the one that ends it (phi = pi).
#pragma once
#include <cmath>
#include <numbers>
#include <vector>

#include "mech/autodiff.hpp"
#include "mech/cycle.hpp"
#include "mech/status.hpp"

namespace mech {

enum class PressingEnd { inner, outer };         // the dead centre that ends the pressing (design doc, finding 4)
enum class PressLever { slider, four_bar };      // rod end on a line (the guide) or on the lever's arc
enum class LeverPivot { same_side, opposite_side };  // four-bar: the lever pivot against the crank pin's side
enum class PressForce { constant, pressure_law };    // the final pressure throughout (the guide), or (7.2) at depth

template <class S>
struct CrankPress {
  S r;     // crank radius [m]
  S l_sh;  // connecting rod [m]
  S l;     // lever arm from the pivot to the piston pusher [m]
  S l_p;   // lever arm from the pivot to the rod joint [m]
  S h;     // compaction depth at the end of the stroke [m]
  S a;     // pressure-law factor [Pa]
  S b;     // pressure-law exponent [1/m]
  S area;  // pressed area, m bricks x face F [m^2]
  PressingEnd end = PressingEnd::inner;
  PressLever lever = PressLever::slider;
  LeverPivot pivot = LeverPivot::same_side;
  PressForce force = PressForce::pressure_law;

  template <class T>
  CrankPress<T> cast() const {
    return {T(value(r)), T(value(l_sh)), T(value(l)), T(value(l_p)), T(value(h)), T(value(a)),
            T(value(b)), T(value(area)), end, lever, pivot, force};
  }
};

// Piston stroke S_k = 2 r l / l_p: the rod end travels 2r, the lever scales it by l/l_p (7.3).
template <class S>
S press_stroke(const CrankPress<S>& k) {
  return 2.0 * k.r * k.l / k.l_p;
}

// |OC|, the crank axis to the four-bar lever pivot C = (l_sh, +-sqrt(l_p^2 - r^2)).
template <class S>
S lever_pivot_distance(const CrankPress<S>& k) {
  using std::sqrt;
  return sqrt(k.l_sh * k.l_sh + k.l_p * k.l_p - k.r * k.r);
}

// How far the design is from not assembling [m]: l_sh - r for the slider
// (lambda < 1, (7.5)); the Grashof margin l_sh + l_p - r - |OC| of the
// crank-rocker for the four-bar (>= 0 exactly when r <= l_sh and r <= l_p).
template <class S>
S assembly_margin(const CrankPress<S>& k) {
  return k.lever == PressLever::slider ? S(k.l_sh - k.r) : S(k.l_sh + k.l_p - k.r - lever_pivot_distance(k));
}

// The typed reason a press cannot work, or ok.
template <class S>
Status check(const CrankPress<S>& k) {
  for (const S* v : {&k.r, &k.l_sh, &k.l, &k.l_p, &k.h, &k.a, &k.area})
    if (!(value(*v) > 0)) return Status::invalid_parameter;
  if (!(value(k.b) >= 0)) return Status::invalid_parameter;
  if (!(value(k.r) < value(k.l_sh))) return Status::cannot_assemble;
  // Four-bar: then Grashof holds too, (l_sh + l_p - r)^2 - |OC|^2 = 2 (l_sh - r)(l_p - r).
  if (k.lever == PressLever::four_bar && !(value(k.r) < value(k.l_p))) return Status::cannot_assemble;
  // The compaction must start inside the working half-turn.
  if (!(value(k.h) < value(press_stroke(k)))) return Status::invalid_parameter;
  return Status::ok;
}

// Piston travel from the start of the working half-turn and its rate per radian.
template <class S>
struct PistonMotion {
  S s, ds;
};

// check(k) must be ok.
template <class S>
PistonMotion<S> piston_motion(const CrankPress<S>& k, const S& phi) {
  using std::asin;
  using std::atan2;
  using std::cos;
  using std::sin;
  using std::sqrt;
  const double e = k.end == PressingEnd::inner ? 1.0 : -1.0;  // inner: the rod pulls; outer: it pushes
  if (k.lever == PressLever::slider) {
    const S sa = k.r * sin(phi) / k.l_sh, ca = sqrt(1.0 - sa * sa);  // (7.5) sin(alpha) = r sin(phi)/l_sh
    const S x = k.r * (1.0 - cos(phi)) + e * k.l_sh * (1.0 - ca);     // rod-end travel
    const S dx = k.r * (sin(phi) * ca + e * cos(phi) * sa) / ca;      // (7.6)-(7.7) per unit P: r sin(phi +- alpha)/cos(alpha)
    const S ratio = k.l / k.l_p;                                      // (7.3) P = Q l / l_p
    return {ratio * x, ratio * dx};
  }
  // Four-bar (design doc section 5): pivot C = (l_sh, sigma y_c); both dead
  // centres of the rod end B on the x axis at l_sh -+ r.
  const double sigma = k.pivot == LeverPivot::same_side ? e : -e;
  const S yc = sqrt(k.l_p * k.l_p - k.r * k.r);
  const S th = k.end == PressingEnd::inner ? phi : S(phi + std::numbers::pi);
  const S ax = k.r * cos(th), ay = k.r * sin(th);
  const S dx = k.l_sh - ax, dy = sigma * yc - ay;  // D = C - A
  const S dd = sqrt(dx * dx + dy * dy);
  const S kk = (k.l_sh * k.l_sh - k.l_p * k.l_p - dd * dd) / (2.0 * k.l_p);
  // |B - A| = l_sh, the branch with psi near 0 (the terms named: GCC 12
  // takes AutoDiff's sum of the two for a use after free).
  const S sdy = sigma * dy, beta = atan2(sdy, dx), gamma = asin(S(kk / dd));
  const S psi = beta + gamma;
  const S sp = sin(psi), cp = cos(psi);
  const S bx = dx + k.l_p * sp, by = dy - sigma * k.l_p * cp;  // B - A
  // psi' = (B - A).A' / (l_p (B - A).(cos psi, sigma sin psi)), A' = (-A_y, A_x)
  const S dpsi = (by * ax - bx * ay) / (k.l_p * (bx * cp + sigma * by * sp));
  return {k.l * (k.r / k.l_p - e * sp), -e * k.l * cp * dpsi};
}

// Pressing force at depth d (7.1)-(7.2): Q = m F a e^{b d}; `constant`
// holds the final pressure, d = h, wherever the piston presses (the guide).
template <class S>
S pressing_force(const CrankPress<S>& k, const S& d) {
  using std::exp;
  return k.area * k.a * exp(k.b * (k.force == PressForce::constant ? k.h : d));
}

// Crankshaft torque while pressing (7.3)-(7.7): M = Q ds/dphi at depth
// d = h - (S_k - s). Valid on [phi_c, pi]; before phi_c the piston is free.
template <class S>
S pressing_torque(const CrankPress<S>& k, const S& phi) {
  const auto p = piston_motion(k, phi);
  return pressing_force(k, S(k.h - (press_stroke(k) - p.s))) * p.ds;
}

// Compaction start phi_c in (0, pi), where s(phi_c) = S_k - h, by Brent
// (s rises over the working half-turn). check(k) must be ok.
inline double compaction_start(const CrankPress<double>& k) {
  const double target = press_stroke(k) - k.h;
  auto g = [&](double phi) { return piston_motion(k, phi).s - target; };
  return brent_root(g, 0.0, std::numbers::pi, g(0.0), g(std::numbers::pi));
}

// phi_c with its design derivative, -(ds/dx - dS_k/dx)/s' (the implicit
// function theorem), from its value phi_c.
template <class S>
S compaction_start(const CrankPress<S>& k, double phi_c) {
  const auto p = piston_motion(k, S(phi_c));
  const S g = p.s - (press_stroke(k) - k.h);
  return S(phi_c) - S(g - value(g)) / value(p.ds);
}

// Angle of the largest pressing torque on [phi_c, pi]: the local maxima
// of M on an n-cell grid refined by Brent on dM/dphi, against M(phi_c) (the
// force comes on at contact, so the maximum may sit there).
inline double peak_torque_angle(const CrankPress<double>& k, double phi_c, int n) {
  const auto kv = k.cast<Dual>();
  auto dm = [&](double phi) { return pressing_torque(kv, seed(phi)).d; };
  std::vector<double> roots;
  sign_changes(dm, phi_c, std::numbers::pi, dm(phi_c), dm(std::numbers::pi), n, roots);
  double best = phi_c, top = pressing_torque(k, phi_c);
  for (double phi : roots)
    if (const double v = pressing_torque(k, phi); v > top) top = v, best = phi;
  return best;
}

// An interior peak angle phi* with its design derivative, -M_phix / M_phiphi
// (implicit function theorem on dM/dphi = 0): the exact design gradient of M
// and the exact dM/dphi, each differenced in phi over +-delta (1e-4 rad:
// truncation ~1e-9 relative, roundoff ~1e-12).
template <class S>
S peak_angle(const CrankPress<S>& k, double phi) {
  constexpr double delta = 1e-4;
  const auto kv = k.template cast<Dual>();
  const S slope = (pressing_torque(k, S(phi + delta)) - pressing_torque(k, S(phi - delta))) / (2 * delta);
  const double curvature =
      (pressing_torque(kv, seed(phi + delta)).d - pressing_torque(kv, seed(phi - delta)).d) / (2 * delta);
  return S(phi) - S(slope - value(slope)) / curvature;
}

// Mean pressing torque over [phi_c, pi] (Gauss-Legendre: M is analytic
// there), phi_c carrying its design derivative. By virtual work its
// integral is the work of the force over the piston travel h.
template <class S>
S mean_pressing_torque(const CrankPress<S>& k, const S& phi_c) {
  const S half = 0.5 * (std::numbers::pi - phi_c), mid = phi_c + half;
  S sum(0.0);
  for (const auto& [x, w] : gauss_legendre(kMaxGaussNodes)) sum += w * pressing_torque(k, S(mid + half * x));
  return 0.5 * sum;
}

}  // namespace mech
