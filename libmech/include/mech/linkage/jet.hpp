// Second-order jets in the crank angle: a value with its first and second
// derivatives in phi (forward mode), on any scalar S of the models (double,
// or a dual carrying design derivatives, or a Dual in phi for a third
// derivative). Positions of a linkage computed on jets carry their transfer
// functions exactly: velocity = speed * d, acceleration = speed^2 * dd at
// constant crank speed. docs/design/linkage.md, section 3.
#pragma once
#include <cmath>
#include <type_traits>

#include "mech/inline.hpp"

namespace mech::linkage {

template <class S>
struct Jet {
  S v, d, dd;  // f, df/dphi, d2f/dphi2
};

// The highest derivative in phi that jets on S carry (those above it left
// 0): 2, or what a scalar type says (kinematics.hpp's LaneVelocity, 1:
// velocities at about half the products; LanePosition, 0: positions alone).
template <class S>
inline constexpr int kJetOrder = 2;

template <class S>
MECH_INLINE Jet<S> constant(const S& x) {
  return {x, S(0.0), S(0.0)};
}

template <class S>
MECH_INLINE Jet<S> operator+(const Jet<S>& a, const Jet<S>& b) {
  if constexpr (kJetOrder<S> == 0) return constant(S(a.v + b.v));
  if constexpr (kJetOrder<S> == 1) return {S(a.v + b.v), S(a.d + b.d), S(0.0)};
  return {S(a.v + b.v), S(a.d + b.d), S(a.dd + b.dd)};
}
template <class S>
MECH_INLINE Jet<S> operator-(const Jet<S>& a, const Jet<S>& b) {
  if constexpr (kJetOrder<S> == 0) return constant(S(a.v - b.v));
  if constexpr (kJetOrder<S> == 1) return {S(a.v - b.v), S(a.d - b.d), S(0.0)};
  return {S(a.v - b.v), S(a.d - b.d), S(a.dd - b.dd)};
}
template <class S>
MECH_INLINE Jet<S> operator-(const Jet<S>& a) {
  if constexpr (kJetOrder<S> == 0) return constant(S(-a.v));
  return {S(-a.v), S(-a.d), S(-a.dd)};
}
// (f g)'' = f'' g + 2 f' g' + f g''
template <class S>
MECH_INLINE Jet<S> operator*(const Jet<S>& a, const Jet<S>& b) {
  if constexpr (kJetOrder<S> == 0) return constant(S(a.v * b.v));
  if constexpr (kJetOrder<S> == 1) return {S(a.v * b.v), S(a.d * b.v + a.v * b.d), S(0.0)};
  return {S(a.v * b.v), S(a.d * b.v + a.v * b.d), S(a.dd * b.v + 2.0 * (a.d * b.d) + a.v * b.dd)};
}
// A jet times a constant (a number converts to S: S is not deduced from it).
template <class S>
MECH_INLINE Jet<S> operator*(const Jet<S>& a, const std::type_identity_t<S>& k) {
  if constexpr (kJetOrder<S> == 0) return constant(S(a.v * k));
  if constexpr (kJetOrder<S> == 1) return {S(a.v * k), S(a.d * k), S(0.0)};
  return {S(a.v * k), S(a.d * k), S(a.dd * k)};
}
template <class S>
MECH_INLINE Jet<S> operator*(const std::type_identity_t<S>& k, const Jet<S>& a) {
  return a * k;
}
// q = a / b: q' = (a' - q b') / b, q'' = (a'' - 2 q' b' - q b'') / b, each
// times 1 / b (one quotient: a lane dual's costs 1 + N divisions, a
// product none), at every order (the same bits).
template <class S>
MECH_INLINE Jet<S> operator/(const Jet<S>& a, const Jet<S>& b) {
  const S ib = S(1.0 / b.v), q = a.v * ib;
  if constexpr (kJetOrder<S> == 0) return constant(q);
  const S dq = (a.d - q * b.d) * ib;
  if constexpr (kJetOrder<S> == 1) return {q, dq, S(0.0)};
  return {q, dq, S((a.dd - 2.0 * (dq * b.d) - q * b.dd) * ib)};
}
template <class S>
MECH_INLINE Jet<S> operator/(const Jet<S>& a, const std::type_identity_t<S>& k) {
  if constexpr (kJetOrder<S> == 0) return constant(S(a.v / k));
  if constexpr (kJetOrder<S> == 1) return {S(a.v / k), S(a.d / k), S(0.0)};
  return {S(a.v / k), S(a.d / k), S(a.dd / k)};
}
// r = sqrt(a): 2 r r' = a', 2 (r r'' + r'^2) = a'', each times 1 / (2 r)
// (one quotient).
template <class S>
MECH_INLINE Jet<S> sqrt(const Jet<S>& a) {
  using std::sqrt;
  const S r = sqrt(a.v);
  if constexpr (kJetOrder<S> == 0) return constant(r);
  const S ih = S(1.0 / (2.0 * r)), dr = a.d * ih;
  if constexpr (kJetOrder<S> == 1) return {r, dr, S(0.0)};
  return {r, dr, S((a.dd - 2.0 * (dr * dr)) * ih)};
}
template <class S>
MECH_INLINE Jet<S> sin(const Jet<S>& a) {
  using std::cos;
  using std::sin;
  const S s = sin(a.v), c = cos(a.v);
  return {s, S(c * a.d), S(c * a.dd - s * (a.d * a.d))};
}
template <class S>
MECH_INLINE Jet<S> cos(const Jet<S>& a) {
  using std::cos;
  using std::sin;
  const S s = sin(a.v), c = cos(a.v);
  return {c, S(-(s * a.d)), S(-(s * a.dd) - c * (a.d * a.d))};
}

// A plane vector of jets (a point's position with its transfer functions,
// or a link's unit x axis).
template <class S>
struct Vec {
  Jet<S> x, y;
};

template <class S>
MECH_INLINE Vec<S> operator+(const Vec<S>& a, const Vec<S>& b) {
  return {a.x + b.x, a.y + b.y};
}
template <class S>
MECH_INLINE Vec<S> operator-(const Vec<S>& a, const Vec<S>& b) {
  return {a.x - b.x, a.y - b.y};
}
template <class S>
MECH_INLINE Vec<S> operator*(const Jet<S>& k, const Vec<S>& a) {
  return {k * a.x, k * a.y};
}
template <class S>
MECH_INLINE Vec<S> operator*(const std::type_identity_t<S>& k, const Vec<S>& a) {
  return {a.x * k, a.y * k};
}
template <class S>
MECH_INLINE Vec<S> operator/(const Vec<S>& a, const Jet<S>& k) {
  return {a.x / k, a.y / k};
}
template <class S>
MECH_INLINE Vec<S> operator/(const Vec<S>& a, const std::type_identity_t<S>& k) {
  return {a.x / k, a.y / k};
}
template <class S>
MECH_INLINE Jet<S> dot(const Vec<S>& a, const Vec<S>& b) {
  return a.x * b.x + a.y * b.y;
}
template <class S>
MECH_INLINE Jet<S> cross(const Vec<S>& a, const Vec<S>& b) {
  return a.x * b.y - a.y * b.x;
}
// a turned by +90 degrees
template <class S>
MECH_INLINE Vec<S> rot90(const Vec<S>& a) {
  return {-a.y, a.x};
}

// The angle of a unit vector e with its transfer functions: e' = t' n and
// e'' = t'' n - t'^2 e (n = rot90(e)), so t' = e x e' and t'' = e x e''.
// The value is atan2's, in (-pi, pi].
template <class S>
MECH_INLINE Jet<S> angle_of(const Vec<S>& e) {
  using std::atan2;
  return {S(atan2(e.y.v, e.x.v)), S(e.x.v * e.y.d - e.y.v * e.x.d), S(e.x.v * e.y.dd - e.y.v * e.x.dd)};
}
// ... its rates only (t', t''; the value left 0): what energies and powers
// need, without the atan2.
template <class S>
MECH_INLINE Jet<S> angle_rates(const Vec<S>& e) {
  return {S(0.0), S(e.x.v * e.y.d - e.y.v * e.x.d), S(e.x.v * e.y.dd - e.y.v * e.x.dd)};
}

}  // namespace mech::linkage
