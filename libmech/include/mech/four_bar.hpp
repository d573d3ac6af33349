// Four-bar linkage driven by its crank: position analysis on either assembly
// branch, angular velocities and accelerations as transfer functions of the
// crank angle (per unit crank speed), pressure angle, Grashof classification,
// dead-centre (extreme) positions, time-ratio coefficient (seed 002 eq. 5) and
// crank-rocker synthesis from two extreme positions (seed 002 eqs 1-3).
//
// Frame: rocker pivot O1 at the origin, crank pivot O at (gx, gy) (seed 002:
// (a, b)). Crank OA = l1 at angle theta1 = phi, coupler AB = l2 at theta2,
// rocker O1B = l3 at theta3, frame OO1 = l4 = hypot(gx, gy) (eq. 1).
// Units: metres, radians; w = dtheta/dphi, alpha = d2theta/dphi2.
#pragma once
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "mech/autodiff.hpp"
#include "mech/cycle.hpp"
#include "mech/simd.hpp"
#include "mech/status.hpp"

namespace mech {

template <class S>
struct Vec2 {
  S x, y;
};

template <class S>
struct FourBar {
  S crank, coupler, rocker;  // l1, l2, l3 [m], each > 0
  S gx, gy;                  // crank pivot O relative to the rocker pivot O1 [m]
  int branch = 1;            // +1 / -1: B left / right of the line from O1 to A

  S frame() const {
    using std::sqrt;
    return sqrt(gx * gx + gy * gy);
  }
  template <class F>
  auto map(F&& f) const -> FourBar<decltype(f(crank))> {
    return {f(crank), f(coupler), f(rocker), f(gx), f(gy), branch};
  }
  template <class T>
  FourBar<T> cast() const {
    return map([](const S& x) { return T(value(x)); });
  }
};

// Link directions and their first and second transfer functions at one
// crank angle. Directions are kept as unit vectors (no trig per point); the
// angles are there on demand.
template <class S>
struct FourBarPoint {
  Vec2<S> A, B;          // crank pin and rocker pin positions
  Vec2<S> e1, e2, e3;    // unit vectors along crank OA, coupler AB, rocker O1B
  S w2, w3;              // dtheta2/dphi, dtheta3/dphi
  S alpha2, alpha3;      // d2theta2/dphi2, d2theta3/dphi2
  S theta2() const { using std::atan2; return atan2(e2.y, e2.x); }
  S theta3() const { using std::atan2; return atan2(e3.y, e3.x); }
};

template <class S>
S cross(const Vec2<S>& a, const Vec2<S>& b) { return a.x * b.y - a.y * b.x; }
template <class S>
S dot(const Vec2<S>& a, const Vec2<S>& b) { return a.x * b.x + a.y * b.y; }

// Position, velocity and acceleration analysis at crank angle phi; false when
// the loop cannot close there (|O1A| outside [|l2 - l3|, l2 + l3]) or sits
// exactly at a toggle (coupler and rocker collinear), and then everything
// past the crank is NaN: a caller that reads it anyway gets NaN, never
// stale memory.
// The same from c = cos(phi), s = sin(phi) (a grid or a quadrature rule has them).
template <class S>
bool four_bar_point(const FourBar<S>& m, const S& c, const S& s, FourBarPoint<S>& p) {
  using std::sqrt;
  p.e1 = {c, s};
  p.A = {m.gx + m.crank * p.e1.x, m.gy + m.crank * p.e1.y};
  // B: intersection of the circles (O1, l3) and (A, l2).
  const S d2 = p.A.x * p.A.x + p.A.y * p.A.y;
  const S along = (m.rocker * m.rocker - m.coupler * m.coupler + d2) / (2.0 * d2);  // fraction of O1A
  const S h2 = m.rocker * m.rocker / d2 - along * along;  // (height / |O1A|)^2
  auto fail = [&] {
    const S nan(std::numeric_limits<double>::quiet_NaN());
    p.B = p.e2 = p.e3 = {nan, nan};
    p.w2 = p.w3 = p.alpha2 = p.alpha3 = nan;
    return false;
  };
  if (!positive_everywhere(h2)) return fail();
  const S h = double(m.branch) * sqrt(h2);
  p.B = {along * p.A.x - h * p.A.y, along * p.A.y + h * p.A.x};
  p.e2 = {(p.B.x - p.A.x) / m.coupler, (p.B.y - p.A.y) / m.coupler};
  p.e3 = {p.B.x / m.rocker, p.B.y / m.rocker};
  // Loop closure O + l1 e1 + l2 e2 - l3 e3 = O1, differentiated once and twice
  // in phi and projected on e2 and e3; sin(ti - tj) = cross(ej, ei),
  // cos(ti - tj) = dot(ei, ej).
  const S s23 = cross(p.e3, p.e2);
  if (zero_somewhere(s23)) return fail();
  const S c12 = dot(p.e1, p.e2), c13 = dot(p.e1, p.e3), c23 = dot(p.e2, p.e3);
  p.w3 = m.crank * cross(p.e1, p.e2) / (m.rocker * s23);
  p.w2 = m.crank * cross(p.e1, p.e3) / (m.coupler * s23);
  p.alpha3 = (-m.crank * c12 - m.coupler * p.w2 * p.w2 + m.rocker * p.w3 * p.w3 * c23) /
             (m.rocker * s23);
  p.alpha2 = -(m.crank * c13 + m.coupler * p.w2 * p.w2 * c23 - m.rocker * p.w3 * p.w3) /
             (m.coupler * s23);
  return true;
}

template <class S>
bool four_bar_point(const FourBar<S>& m, const S& phi, FourBarPoint<S>& p) {
  using std::cos;
  using std::sin;
  return four_bar_point(m, S(cos(phi)), S(sin(phi)), p);
}

// Pressure angle at the rocker: between the coupler force (along AB) and the
// velocity of B (normal to O1B); 0 is ideal, pi/2 a toggle.
template <class S>
S pressure_angle(const FourBarPoint<S>& p) {
  using std::abs;
  using std::asin;
  return asin(abs(dot(p.e2, p.e3)));
}

enum class GrashofClass {
  crank_rocker,   // s + l < p + q, crank shortest: the crank turns fully
  double_crank,   // s + l < p + q, frame shortest
  rocker_crank,   // s + l < p + q, rocker shortest (the crank only rocks)
  double_rocker,  // s + l < p + q, coupler shortest
  change_point,   // s + l = p + q: the linkage passes a toggle with all links collinear
  non_grashof,    // s + l > p + q: no link turns fully
};

inline const char* to_string(GrashofClass g) {
  switch (g) {
    case GrashofClass::crank_rocker: return "crank_rocker";
    case GrashofClass::double_crank: return "double_crank";
    case GrashofClass::rocker_crank: return "rocker_crank";
    case GrashofClass::double_rocker: return "double_rocker";
    case GrashofClass::change_point: return "change_point";
    case GrashofClass::non_grashof: return "non_grashof";
  }
  return "unknown";
}

// Grashof's criterion, general form: with s and l the shortest and longest
// links and p, q the others, some link turns fully iff s + l <= p + q.
inline GrashofClass grashof(double l1, double l2, double l3, double l4, double tol = 1e-12) {
  const double links[4] = {l1, l2, l3, l4};
  int is = 0;
  double s = l1, l = l1, sum = 0;
  for (int i = 0; i < 4; ++i) {
    sum += links[i];
    if (links[i] < s) s = links[i], is = i;
    l = std::max(l, links[i]);
  }
  const double margin = (sum - s - l) - (s + l);
  if (std::abs(margin) <= tol * sum) return GrashofClass::change_point;
  if (margin < 0) return GrashofClass::non_grashof;
  switch (is) {
    case 0: return GrashofClass::crank_rocker;
    case 3: return GrashofClass::double_crank;
    case 2: return GrashofClass::rocker_crank;
    default: return GrashofClass::double_rocker;
  }
}

// Seed 002 eq. (4) as printed, for a crank-rocker with frame l4 and rocker l3:
// l1 < l2, l1 + l2 < l3 + l4, l2 - l1 > l4 - l3.
inline bool grashof_seed002(double l1, double l2, double l3, double l4) {
  return l1 < l2 && l1 + l2 < l3 + l4 && l2 - l1 > l4 - l3;
}

// How far the crank is from losing its full turn: |O1A| spans
// [|l4 - l1|, l4 + l1] over a revolution and the loop closes only for
// |O1A| in [|l2 - l3|, l2 + l3]. Positive: the crank turns fully with that
// margin [m]; zero or negative: a toggle lies inside the cycle.
template <class S>
S rotation_margin(const FourBar<S>& m) {
  using std::abs;
  const S l4 = m.frame();
  const S outer = (m.coupler + m.rocker) - (l4 + m.crank);
  const S inner = abs(l4 - m.crank) - abs(m.coupler - m.rocker);
  return outer < inner ? outer : inner;
}

// How near the loop comes to a toggle, in the crank angle: |O1A|^2 = l4^2 +
// l1^2 + 2 l1 l4 cos(phi - phi_O), with phi_O the direction from O1 to O, is
// largest at phi_O and smallest at phi_O + pi, and equals (l2 + l3)^2 (resp.
// (l2 - l3)^2), a toggle, at phi_O +- i acosh(1 + q) with q = ((l2 + l3)^2 -
// (l4 + l1)^2) / (2 l1 l4) (resp. phi_O + pi +- i acosh(1 + q), q = ((l4 -
// l1)^2 - (l2 - l3)^2) / (2 l1 l4)): the singularities of the transfer
// functions nearest the real axis, which a quadrature over the cycle must
// resolve. Needs a full turn (both q > 0).
template <class S>
std::array<NearPole, 2> toggle_poles(const FourBar<S>& m) {
  const double l1 = value(m.crank), l2 = value(m.coupler), l3 = value(m.rocker), gx = value(m.gx), gy = value(m.gy);
  const double l4 = std::sqrt(gx * gx + gy * gy), phi_o = std::atan2(gy, gx);
  const double outer = ((l2 + l3) * (l2 + l3) - (l4 + l1) * (l4 + l1)) / (2 * l1 * l4);
  const double inner = ((l4 - l1) * (l4 - l1) - (l2 - l3) * (l2 - l3)) / (2 * l1 * l4);
  return {NearPole{wrap_angle(phi_o), std::acosh(1 + outer)},
          NearPole{wrap_angle(phi_o + std::numbers::pi), std::acosh(1 + inner)}};
}

// The rocker's extreme positions (crank and coupler collinear, seed 002
// Fig. 2): crank angles of the extended (|OB| = l2 + l1) and folded
// (|OB| = l2 - l1) dead centres and the rocker angles there. Needs a full turn.
template <class S>
struct DeadCentres {
  S phi_extended, phi_folded;
  S theta3_extended, theta3_folded;
};

template <class S>
DeadCentres<S> dead_centres(const FourBar<S>& m) {
  using std::atan2;
  using std::sqrt;
  DeadCentres<S> out;
  // B where |OB| = r: circle (O, r) with circle (O1, l3), on the branch side.
  auto pin = [&](const S& r, S& phi, S& theta3, double sign) {
    const S d2 = m.gx * m.gx + m.gy * m.gy;
    const S along = (m.rocker * m.rocker - r * r + d2) / (2.0 * d2);  // from O1 toward O
    const S h = sqrt(m.rocker * m.rocker / d2 - along * along);
    // B = along * O + h * perp(O) * side, with the side matching the branch.
    const S bx = along * m.gx - sign * h * m.gy, by = along * m.gy + sign * h * m.gx;
    theta3 = atan2(by, bx);
    phi = atan2(by - m.gy, bx - m.gx);
  };
  // A lies on the line OB (between O and B when extended, beyond O when
  // folded), so cross(O1A, O1B) = (positive factor) * cross(O1O, O1B): in both
  // positions B is on the branch side of the line O1-O as well.
  pin(m.coupler + m.crank, out.phi_extended, out.theta3_extended, m.branch);
  pin(m.coupler - m.crank, out.phi_folded, out.theta3_folded, m.branch);
  out.phi_folded += std::numbers::pi;  // the crank points away from B when folded
  return out;
}

// Time-ratio coefficient K = (pi + beta) / (pi - beta), eq. (5), with beta the
// angle between OB' and OB'' (the crank's two dead-centre lines).
template <class S>
S time_ratio(const DeadCentres<S>& dc) {
  using std::abs;
  using std::atan2;
  using std::cos;
  using std::sin;
  const S diff = dc.phi_folded - std::numbers::pi - dc.phi_extended;
  const S beta = abs(atan2(sin(diff), cos(diff)));
  return (std::numbers::pi + beta) / (std::numbers::pi - beta);
}

// Crank-rocker synthesis from the two extreme rocker positions (eqs 1-3):
// B at distance `along` on the mid-swing axis (direction axis_angle from O1)
// and `across` off it toward O, swung by +-half_swing about O1; then
// l1 = (|OB'| - |OB''|)/2, l2 = (|OB'| + |OB''|)/2, l3 = |O1B| (eq. 3).
template <class S>
struct Synthesis {
  bool ok = false;  // false: no crank (|OB'| = |OB''|) or B', B'' on two sides of O1O
  FourBar<S> linkage;
  S beta;           // angle between OB' and OB'' [rad]
  // Least distance of B' and B'' from the line O1O on the branch side [m].
  // Both dead centres of one assembly branch lie on the same side of that
  // line (see dead_centres), so a crank-rocker through B' and B'' needs > 0.
  S side_margin;
};

template <class S>
Synthesis<S> synthesize_crank_rocker(const S& gx, const S& gy, const S& along, const S& across,
                                     double axis_angle, const S& half_swing) {
  using std::abs;
  using std::acos;
  using std::cos;
  using std::sin;
  using std::sqrt;
  Synthesis<S> out;
  const double ux = std::cos(axis_angle), uy = std::sin(axis_angle);
  // Unit normal to the axis on O's side.
  const double side = (ux * value(gy) - uy * value(gx)) >= 0 ? 1.0 : -1.0;
  const S bx = along * ux - side * across * uy, by = along * uy + side * across * ux;
  auto rotate = [&](const S& t, S& x, S& y) {
    x = cos(t) * bx - sin(t) * by;
    y = sin(t) * bx + cos(t) * by;
  };
  S b1x, b1y, b2x, b2y;
  rotate(half_swing, b1x, b1y);
  rotate(-half_swing, b2x, b2y);
  const S v1x = b1x - gx, v1y = b1y - gy, v2x = b2x - gx, v2y = b2y - gy;
  const S d1 = sqrt(v1x * v1x + v1y * v1y), d2 = sqrt(v2x * v2x + v2y * v2y);
  const S far = d1 > d2 ? d1 : d2, near = d1 > d2 ? d2 : d1;
  out.linkage.crank = (far - near) / 2.0;
  out.linkage.coupler = (far + near) / 2.0;
  out.linkage.rocker = sqrt(bx * bx + by * by);
  out.linkage.gx = gx;
  out.linkage.gy = gy;
  S cb = (v1x * v2x + v1y * v2y) / (d1 * d2);
  if (cb > 1.0) cb = S(1.0);
  out.beta = acos(cb);
  // Branch: B' (the extended position, the farther one) sits on this side of O1O.
  const S fx = d1 > d2 ? b1x : b2x, fy = d1 > d2 ? b1y : b2y;
  out.linkage.branch = (value(gx) * value(fy) - value(gy) * value(fx)) >= 0 ? 1 : -1;
  const S l4 = out.linkage.frame();
  const S side1 = double(out.linkage.branch) * (gx * b1y - gy * b1x) / l4;
  const S side2 = double(out.linkage.branch) * (gx * b2y - gy * b2x) / l4;
  out.side_margin = side1 < side2 ? side1 : side2;
  out.ok = value(out.linkage.crank) > 1e-12 * value(far) && value(out.side_margin) > 0;
  return out;
}

}  // namespace mech
