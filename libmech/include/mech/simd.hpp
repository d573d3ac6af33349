// Lanes: kLanes doubles computed as one, for the cycle loops (the same
// quantity at kLanes crank angles). A GCC/Clang vector type behind the
// arithmetic the model templates use (+ - * /, sqrt, abs), so a kernel
// written for a scalar S runs on Lanes unchanged; the compiler maps it to
// the target's SIMD registers (SSE2: two instructions per operation, AVX:
// one). Each lane is computed exactly as the scalar code computes it: no
// fused multiply-adds (-ffp-contract=off) and the same IEEE operations, so a
// value does not depend on its lane or on the machine's vector width.
//
// sincos(Lanes): fdlibm's kernels (__kernel_sin, __kernel_cos: minimax
// polynomials on [-pi/4, pi/4], under 1 ulp) after a three-part Cody-Waite
// reduction by pi/2; lanes beyond |x| = 2^19 pi/2 (or not finite) take
// std::sin and std::cos.
//
// LaneDual<N>: the lane form of the dual numbers (autodiff.hpp), so the
// same loops carry design derivatives.
#pragma once
#include <array>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "mech/autodiff.hpp"
#include "mech/inline.hpp"

namespace mech {

inline constexpr int kLanes = 4;

struct Lanes {
  using Raw = double __attribute__((vector_size(kLanes * sizeof(double))));
  Raw v;
  Lanes() : v(Raw{}) {}
  Lanes(double x) : v(Raw{} + x) {}  // NOLINT: a constant in every lane
  Lanes(Raw r) : v(r) {}             // NOLINT
  double operator[](int i) const { return v[i]; }
  double& operator[](int i) { return v[i]; }
  Lanes operator-() const { return Lanes(-v); }
  Lanes& operator+=(const Lanes& o) { v += o.v; return *this; }
  Lanes& operator-=(const Lanes& o) { v -= o.v; return *this; }
  Lanes& operator*=(const Lanes& o) { v *= o.v; return *this; }
  Lanes& operator/=(const Lanes& o) { v /= o.v; return *this; }
};
inline Lanes operator+(const Lanes& a, const Lanes& b) { return Lanes(a.v + b.v); }
inline Lanes operator-(const Lanes& a, const Lanes& b) { return Lanes(a.v - b.v); }
inline Lanes operator*(const Lanes& a, const Lanes& b) { return Lanes(a.v * b.v); }
inline Lanes operator/(const Lanes& a, const Lanes& b) { return Lanes(a.v / b.v); }
inline Lanes operator+(const Lanes& a, double b) { return Lanes(a.v + b); }
inline Lanes operator+(double a, const Lanes& b) { return Lanes(a + b.v); }
inline Lanes operator-(const Lanes& a, double b) { return Lanes(a.v - b); }
inline Lanes operator-(double a, const Lanes& b) { return Lanes(a - b.v); }
inline Lanes operator*(const Lanes& a, double b) { return Lanes(a.v * b); }
inline Lanes operator*(double a, const Lanes& b) { return Lanes(a * b.v); }
inline Lanes operator/(const Lanes& a, double b) { return Lanes(a.v / b); }
inline Lanes operator/(double a, const Lanes& b) { return Lanes(a / b.v); }

MECH_INLINE Lanes sqrt(const Lanes& a) {
  Lanes r;
  for (int i = 0; i < kLanes; ++i) r[i] = std::sqrt(a[i]);
  return r;
}
MECH_INLINE Lanes abs(const Lanes& a) {
  Lanes r;
  for (int i = 0; i < kLanes; ++i) r[i] = std::abs(a[i]);
  return r;
}
inline double sum(const Lanes& a) {
  double s = 0;
  for (int i = 0; i < kLanes; ++i) s += a[i];
  return s;
}

// Lanes k0, k0 + 1, ..., k0 + kLanes - 1.
inline Lanes iota(double k0) {
  static_assert(kLanes == 4);
  return Lanes(Lanes::Raw{0.0, 1.0, 2.0, 3.0} + k0);
}

namespace detail {
// fdlibm's __kernel_sin (S1..S6) and __kernel_cos (C1..C6) at r + y, |r|
// <= pi/4 (y: the reduction's tail, |y| < ulp(r)).
template <class V>
MECH_INLINE void sincos_kernels(const V& r, const V& y, V& sr, V& cr) {
  const V z = r * r, v = z * r;
  const V ps = 8.33333333332248946124e-03 +
               z * (-1.98412698298579493134e-04 +
                    z * (2.75573137070700676789e-06 +
                         z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)));
  sr = r - ((z * (0.5 * y - v * ps) - y) - v * -1.66666666666666324348e-01);
  const V pc = z * (4.16666666666666019037e-02 +
                    z * (-1.38888888888741095749e-03 +
                         z * (2.48015872894767294178e-05 +
                              z * (-2.75573143513906633035e-07 +
                                   z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))));
  const V hz = 0.5 * z, w = 1.0 - hz;
  cr = w + (((1.0 - w) - hz) + (z * pc - r * y));
}

// sin and cos of x, a double or a Lanes::Raw: the same operations either
// way (see the header comment), valid for |x| <= kReducedRange.
inline constexpr double kReducedRange = 823549.6551353541;  // 2^19 pi / 2
template <class V>
MECH_INLINE void sincos_reduced(const V& x, V& sin_x, V& cos_x) {
  // pi/2 in three 33-bit parts (fdlibm's pio2_1, pio2_2, pio2_3): q * part
  // is exact for |q| < 2^20.
  constexpr double kTwoOverPi = 6.36619772367581382433e-01, kP1 = 1.57079632673412561417e+00,
                   kP2 = 6.07710050630396597660e-11, kP3 = 2.02226624871116645580e-21,
                   kP3t = 8.47842766036889956997e-32,  // pi/2 - kP1 - kP2 - kP3
                   kRound = 6755399441055744.0;        // 1.5 * 2^52: adding it rounds to an integer
  const V q = (x * kTwoOverPi + kRound) - kRound;
  // r + y = x - q pi/2 to about 2^-100 relative: each part's product is
  // exact, each subtraction's rounding error is carried in y.
  const V t = x - q * kP1, w1 = q * kP2, w2 = q * kP3;
  const V r1 = t - w1, r = r1 - w2;
  const V y = (((t - r1) - w1) + ((r1 - r) - w2)) - q * kP3t;
  V s0, c0;
  sincos_kernels(r, y, s0, c0);
  // Quadrant q mod 4: 0 (s, c), 1 (c, -s), 2 (-s, -c), 3 (-c, s).
  const V m = q - 4.0 * ((q * 0.25 + kRound) - kRound);  // in {-2, -1, 0, 1, 2}
  const auto odd = (m == 1.0) | (m == -1.0);
  const auto sin_negative = (m == 2.0) | (m == -2.0) | (m == -1.0);
  const auto cos_negative = (m == 2.0) | (m == -2.0) | (m == 1.0);
  const V s1 = odd ? c0 : s0, c1 = odd ? s0 : c0;
  sin_x = sin_negative ? V(-s1) : s1;
  cos_x = cos_negative ? V(-c1) : c1;
}
}  // namespace detail

// sin and cos of every lane (see the header comment).
inline void sincos(const Lanes& x, Lanes& s, Lanes& c) {
  detail::sincos_reduced(x.v, s.v, c.v);
  for (int i = 0; i < kLanes; ++i)
    if (!(std::abs(x[i]) <= detail::kReducedRange)) s[i] = std::sin(x[i]), c[i] = std::cos(x[i]);
}

// The same where every |x| < 0.78 (< pi/4: no reduction, q = 0, the tail
// y = +0 exactly): the kernels alone, the same bits as sincos.
inline void sincos_small(const Lanes& x, Lanes& s, Lanes& c) { detail::sincos_kernels(x.v, Lanes::Raw{}, s.v, c.v); }

// The same for one angle: the same bits as in a lane.
MECH_INLINE void sincos(double x, double& s, double& c) {
  if (std::abs(x) <= detail::kReducedRange) {
    detail::sincos_reduced(x, s, c);
  } else {
    s = std::sin(x);
    c = std::cos(x);
  }
}

// A value and N derivatives, kLanes at a time: the lane form of Dual (N = 1)
// and DualN<N>. Its values are computed exactly as Lanes computes them, so a
// model's value is the same bits with or without its gradient.
template <int N>
struct LaneDual {
  Lanes v;
  std::array<Lanes, N> d{};
  LaneDual() = default;
  // Constants convert. Always inlined for N = 1 (the angle slopes of the
  // maxima searches: out of line in the recuperative problem's translation
  // unit, a DOE design costs half as much again); not for N > 1, where
  // inlining them too makes GCC spill in the two-variable gradient loop
  // (2.8 times slower, bench_recuperative).
  MECH_FORCE_INLINE LaneDual(double x) requires(N == 1) : v(x) {}        // NOLINT
  MECH_FORCE_INLINE LaneDual(const Lanes& x) requires(N == 1) : v(x) {}  // NOLINT
  LaneDual(double x) requires(N != 1) : v(x) {}                                 // NOLINT
  LaneDual(const Lanes& x) requires(N != 1) : v(x) {}                           // NOLINT
  LaneDual operator-() const {
    LaneDual r(-v);
    for (int i = 0; i < N; ++i) r.d[i] = -d[i];
    return r;
  }
  // Sum, quotient, square root and absolute value: always inlined for N = 1
  // (left out of line in the recuperative problem's translation unit, they
  // cost a DOE design 3%, the model alone 6%); for N > 1 forcing them made
  // the two-variable gradient loop 2.8 times slower (GCC's spills).
  MECH_FORCE_INLINE LaneDual& operator+=(const LaneDual& o) requires(N == 1) { return add(o); }
  LaneDual& operator+=(const LaneDual& o) requires(N != 1) { return add(o); }
  LaneDual& operator-=(const LaneDual& o) { return *this += -o; }
  MECH_FORCE_INLINE friend LaneDual operator+(LaneDual a, const LaneDual& b) requires(N == 1) { return a.add(b); }
  friend LaneDual operator+(LaneDual a, const LaneDual& b) requires(N != 1) { return a.add(b); }
  friend LaneDual operator-(LaneDual a, const LaneDual& b) { return a -= b; }
  // Always inlined: in a translation unit with many model instantiations
  // GCC's growth limits left it out of line, and the two-variable cycle mean
  // with its gradient ran 0.44 us instead of 0.31 (bench_recuperative).
  MECH_FORCE_INLINE friend LaneDual operator*(const LaneDual& a, const LaneDual& b) {
    LaneDual r(a.v * b.v);
    for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * b.v + a.v * b.d[i];
    return r;
  }
  // With a constant (a model's 0.5, 1 / 12, 2 r, ...): the derivative scales,
  // no product with a zero derivative; the same bits as the constant made a
  // LaneDual, as Dual's own rules.
  MECH_FORCE_INLINE friend LaneDual operator*(const LaneDual& a, double k) {
    LaneDual r(a.v * k);
    for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * k;
    return r;
  }
  MECH_FORCE_INLINE friend LaneDual operator*(double k, const LaneDual& a) {
    LaneDual r(k * a.v);
    for (int i = 0; i < N; ++i) r.d[i] = k * a.d[i];
    return r;
  }
  MECH_FORCE_INLINE friend LaneDual operator/(const LaneDual& a, double k) {
    LaneDual r(a.v / k);
    for (int i = 0; i < N; ++i) r.d[i] = a.d[i] / k;
    return r;
  }
  MECH_FORCE_INLINE friend LaneDual operator/(double k, const LaneDual& b) {
    LaneDual r(k / b.v);
    for (int i = 0; i < N; ++i) r.d[i] = (0.0 - r.v * b.d[i]) / b.v;
    return r;
  }
  MECH_FORCE_INLINE friend LaneDual operator/(const LaneDual& a, const LaneDual& b) requires(N == 1) { return quotient(a, b); }
  friend LaneDual operator/(const LaneDual& a, const LaneDual& b) requires(N != 1) { return quotient(a, b); }
  MECH_FORCE_INLINE friend LaneDual sqrt(const LaneDual& a) requires(N == 1) { return root(a); }
  friend LaneDual sqrt(const LaneDual& a) requires(N != 1) { return root(a); }
  MECH_FORCE_INLINE friend LaneDual abs(const LaneDual& a) requires(N == 1) { return magnitude(a); }
  friend LaneDual abs(const LaneDual& a) requires(N != 1) { return magnitude(a); }

 private:
  MECH_FORCE_INLINE LaneDual& add(const LaneDual& o) {
    v += o.v;
    for (int i = 0; i < N; ++i) d[i] += o.d[i];
    return *this;
  }
  MECH_FORCE_INLINE static LaneDual quotient(const LaneDual& a, const LaneDual& b) {
    LaneDual r(a.v / b.v);
    for (int i = 0; i < N; ++i) r.d[i] = (a.d[i] - r.v * b.d[i]) / b.v;
    return r;
  }
  MECH_FORCE_INLINE static LaneDual root(const LaneDual& a) {
    LaneDual r(mech::sqrt(a.v));
    for (int i = 0; i < N; ++i) r.d[i] = a.d[i] / (2.0 * r.v);
    return r;
  }
  MECH_FORCE_INLINE static LaneDual magnitude(const LaneDual& a) {
    Lanes sign;
    for (int j = 0; j < kLanes; ++j) sign[j] = a.v[j] < 0 ? -1.0 : 1.0;
    LaneDual r(mech::abs(a.v));
    for (int i = 0; i < N; ++i) r.d[i] = sign * a.d[i];
    return r;
  }
};

// The lane form of a scalar type (double: Lanes; Dual, DualN<N>: LaneDual);
// void where there is none (DualX: the scalar loops serve it). broadcast:
// one scalar in every lane; sum: the lanes' sum; lane: lane j as a scalar.
template <class S>
struct LaneForm {
  using type = void;
};
template <>
struct LaneForm<double> {
  using type = Lanes;
  static Lanes broadcast(double x) { return Lanes(x); }
  static double sum(const Lanes& a) { return mech::sum(a); }
  static double lane(const Lanes& a, int j) { return a[j]; }
};
template <>
struct LaneForm<Dual> {
  using type = LaneDual<1>;
  static type broadcast(const Dual& x) {
    type r(x.v);
    r.d[0] = Lanes(x.d);
    return r;
  }
  static Dual sum(const type& a) { return {mech::sum(a.v), mech::sum(a.d[0])}; }
  static Dual lane(const type& a, int j) { return {a.v[j], a.d[0][j]}; }
};
template <int N>
  requires(N > 0)  // not DualX
struct LaneForm<DualN<N>> {
  using type = LaneDual<N>;
  static type broadcast(const DualN<N>& x) {
    type r(x.value());
    for (int i = 0; i < N; ++i) r.d[i] = Lanes(x.derivatives()[i]);
    return r;
  }
  static DualN<N> sum(const type& a) {
    Eigen::Matrix<double, N, 1> g;
    for (int i = 0; i < N; ++i) g[i] = mech::sum(a.d[i]);
    return DualN<N>(mech::sum(a.v), g);
  }
  static DualN<N> lane(const type& a, int j) {
    Eigen::Matrix<double, N, 1> g;
    for (int i = 0; i < N; ++i) g[i] = a.d[i][j];
    return DualN<N>(a.v[j], g);
  }
};
template <class S>
using lanes_of = typename LaneForm<S>::type;
template <class S>
inline constexpr bool has_lanes = !std::is_void_v<lanes_of<S>>;

// Whether x > 0 in every lane (a scalar: whether it is), and whether some
// lane of x is 0: the checks a model makes where a point may not exist.
template <class S>
bool positive_everywhere(const S& x) { return value(x) > 0; }
inline bool positive_everywhere(const Lanes& x) {
  for (int i = 0; i < kLanes; ++i)
    if (!(x[i] > 0)) return false;
  return true;
}
template <int N>
bool positive_everywhere(const LaneDual<N>& x) { return positive_everywhere(x.v); }
template <class S>
bool zero_somewhere(const S& x) { return value(x) == 0; }
inline bool zero_somewhere(const Lanes& x) {
  for (int i = 0; i < kLanes; ++i)
    if (x[i] == 0) return true;
  return false;
}
template <int N>
bool zero_somewhere(const LaneDual<N>& x) { return zero_somewhere(x.v); }

inline double lane_value(const Lanes& a, int j) { return a[j]; }
template <int N>
double lane_value(const LaneDual<N>& a, int j) { return a.v[j]; }
inline const Lanes& lane_values(const Lanes& a) { return a; }
template <int N>
const Lanes& lane_values(const LaneDual<N>& a) { return a.v; }

// kLanes doubles from `from` (any alignment).
MECH_INLINE Lanes load_lanes(const double* from) {
  Lanes a;
  std::memcpy(&a.v, from, sizeof a.v);
  return a;
}

// std::max lane by lane (b where a < b, else a).
MECH_INLINE Lanes max(const Lanes& a, const Lanes& b) { return Lanes(a.v < b.v ? b.v : a.v); }

// 1 in each lane where x > 0, else 0 (also for NaN); and each lane's sign
// as double((x > 0) - (x < 0)): no lane written alone (a vector read back
// from four scalar stores stalls).
MECH_INLINE Lanes step(const Lanes& x) { return Lanes(x.v > 0 ? Lanes::Raw{} + 1.0 : Lanes::Raw{}); }
MECH_INLINE Lanes sign_of(const Lanes& x) { return step(x) - step(-x); }

// Whether a < b in every lane (false where a or b is NaN).
MECH_INLINE bool all_below(const Lanes& a, double b) {
  const auto m = a.v < b;
  bool all = true;
  for (int j = 0; j < kLanes; ++j) all &= m[j] != 0;
  return all;
}

// Whether a == b in every lane (false where a lane is NaN).
MECH_INLINE bool all_equal(const Lanes& a, const Lanes& b) {
  const auto m = a.v == b.v;
  bool all = true;
  for (int j = 0; j < kLanes; ++j) all &= m[j] != 0;
  return all;
}

// The first m lanes of a into out[0..m) (all kLanes: one vector store).
MECH_INLINE void store_lanes(double* out, const Lanes& a, int m) {
  if (m == kLanes) std::memcpy(out, &a.v, sizeof a.v);
  else
    for (int j = 0; j < m; ++j) out[j] = a[j];
}

// a with its lanes from m on set to zero (a itself for a full block, the
// grid's every block but a last partial one: inline, no copy).
inline Lanes first_lanes(Lanes a, int m) {
  for (int j = m; j < kLanes; ++j) a[j] = 0.0;
  return a;
}
template <int N>
LaneDual<N> first_lanes_slow(LaneDual<N> a, int m) {
  a.v = first_lanes(a.v, m);
  for (auto& d : a.d) d = first_lanes(d, m);
  return a;
}
template <int N>
MECH_INLINE LaneDual<N> first_lanes(const LaneDual<N>& a, int m) {
  return m >= kLanes ? a : first_lanes_slow(a, m);
}

// Whether S is a lane type (Lanes, LaneDual): kLanes values of a scalar.
template <class S>
inline constexpr bool is_lanes = false;
template <>
inline constexpr bool is_lanes<Lanes> = true;
template <int N>
inline constexpr bool is_lanes<LaneDual<N>> = true;

// The functions the linkage chain takes of its numbers, every lane as the
// C library computes it (so a lane of the chain is the same bits as the
// scalar chain at its angle): sin, cos, exp, atan2, with their derivatives
// on LaneDual.
inline void lane_sincos(const Lanes& x, Lanes& s, Lanes& c) {
  for (int i = 0; i < kLanes; ++i) s[i] = std::sin(x[i]), c[i] = std::cos(x[i]);
}
inline Lanes sin(const Lanes& x) {
  Lanes s, c;
  lane_sincos(x, s, c);
  return s;
}
inline Lanes cos(const Lanes& x) {
  Lanes s, c;
  lane_sincos(x, s, c);
  return c;
}
inline Lanes exp(const Lanes& x) {
  Lanes r;
  for (int i = 0; i < kLanes; ++i) r[i] = std::exp(x[i]);
  return r;
}
inline Lanes atan2(const Lanes& y, const Lanes& x) {
  Lanes r;
  for (int i = 0; i < kLanes; ++i) r[i] = std::atan2(y[i], x[i]);
  return r;
}
// sin (odd) or cos of a, with its derivatives.
template <int N>
LaneDual<N> sin_or_cos(const LaneDual<N>& a, bool odd) {
  Lanes s, c;
  lane_sincos(a.v, s, c);
  LaneDual<N> r(odd ? s : c);
  const Lanes slope = odd ? c : -s;
  for (int i = 0; i < N; ++i) r.d[i] = slope * a.d[i];
  return r;
}
template <int N>
LaneDual<N> sin(const LaneDual<N>& a) {
  return sin_or_cos(a, true);
}
template <int N>
LaneDual<N> cos(const LaneDual<N>& a) {
  return sin_or_cos(a, false);
}
template <int N>
LaneDual<N> exp(const LaneDual<N>& a) {
  LaneDual<N> r(exp(a.v));
  for (int i = 0; i < N; ++i) r.d[i] = r.v * a.d[i];
  return r;
}
template <int N>
LaneDual<N> atan2(const LaneDual<N>& y, const LaneDual<N>& x) {
  LaneDual<N> r(atan2(y.v, x.v));
  const Lanes r2 = x.v * x.v + y.v * y.v;
  for (int i = 0; i < N; ++i) r.d[i] = (x.v * y.d[i] - y.v * x.d[i]) / r2;
  return r;
}

// x where `on` is nonzero, 0 in the other lanes (no 0 * inf there).
inline Lanes where(const Lanes& on, const Lanes& x) { return Lanes(on.v != 0 ? x.v : Lanes::Raw{}); }
template <int N>
LaneDual<N> where(const Lanes& on, LaneDual<N> x) {
  x.v = where(on, x.v);
  for (auto& d : x.d) d = where(on, d);
  return x;
}

}  // namespace mech
