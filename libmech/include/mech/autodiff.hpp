// Forward-mode autodiff scalars used by every model: exact first derivatives
// with respect to N design variables. One variable (and every angle
// derivative) uses Dual, a plain value-and-slope pair; 2 to 4
// (opt/model_problem.hpp) Eigen's AutoDiffScalar with N fixed at compile
// time (no heap use); beyond, chunks of four, one evaluation each. DualX
// carries a derivative vector sized at run time (a problem's local maxima).
#pragma once
#include <Eigen/Core>
#include <cmath>
#include <type_traits>
#include <unsupported/Eigen/AutoDiff>

namespace mech {

template <int N>
using DualN = Eigen::AutoDiffScalar<Eigen::Matrix<double, N, 1>>;
using DualX = Eigen::AutoDiffScalar<Eigen::VectorXd>;

// A number with its derivative along one direction (the crank angle: where
// a cycle quantity peaks): a plain pair of doubles. Eigen's
// AutoDiffScalar<Matrix<double, 1, 1>> spent ~10x the instructions of the
// double evaluation on its expression templates.
struct Dual {
  double v = 0, d = 0;  // value, derivative
  Dual() = default;
  Dual(double value, double slope = 0) : v(value), d(slope) {}  // NOLINT: constants convert
  double value() const { return v; }
  Dual operator-() const { return {-v, -d}; }
  Dual& operator+=(const Dual& o) { v += o.v; d += o.d; return *this; }
  Dual& operator-=(const Dual& o) { v -= o.v; d -= o.d; return *this; }
  Dual& operator*=(const Dual& o) { d = d * o.v + v * o.d; v *= o.v; return *this; }
  Dual& operator/=(const Dual& o) { v /= o.v; d = (d - v * o.d) / o.v; return *this; }
  Dual& operator*=(double k) { v *= k; d *= k; return *this; }
  Dual& operator/=(double k) { v /= k; d /= k; return *this; }
};
inline Dual operator+(Dual a, const Dual& b) { return a += b; }
inline Dual operator-(Dual a, const Dual& b) { return a -= b; }
inline Dual operator*(Dual a, const Dual& b) { return a *= b; }
inline Dual operator/(Dual a, const Dual& b) { return a /= b; }
inline Dual operator+(Dual a, double k) { a.v += k; return a; }
inline Dual operator+(double k, Dual a) { a.v += k; return a; }
inline Dual operator-(Dual a, double k) { a.v -= k; return a; }
inline Dual operator-(double k, const Dual& a) { return {k - a.v, -a.d}; }
inline Dual operator*(Dual a, double k) { return a *= k; }
inline Dual operator*(double k, Dual a) { return a *= k; }
inline Dual operator/(Dual a, double k) { return a /= k; }
inline Dual operator/(double k, const Dual& a) { const double q = k / a.v; return {q, -q * a.d / a.v}; }
inline bool operator<(const Dual& a, const Dual& b) { return a.v < b.v; }
inline bool operator>(const Dual& a, const Dual& b) { return a.v > b.v; }
inline bool operator<=(const Dual& a, const Dual& b) { return a.v <= b.v; }
inline bool operator>=(const Dual& a, const Dual& b) { return a.v >= b.v; }
inline Dual sqrt(const Dual& a) { const double r = std::sqrt(a.v); return {r, a.d / (2 * r)}; }
inline Dual exp(const Dual& a) { const double e = std::exp(a.v); return {e, e * a.d}; }
inline Dual abs(const Dual& a) { return a.v < 0 ? -a : a; }
inline Dual cos(const Dual& a) { return {std::cos(a.v), -std::sin(a.v) * a.d}; }
inline Dual sin(const Dual& a) { return {std::sin(a.v), std::cos(a.v) * a.d}; }
inline Dual asin(const Dual& a) { return {std::asin(a.v), a.d / std::sqrt(1 - a.v * a.v)}; }
inline Dual acos(const Dual& a) { return {std::acos(a.v), -a.d / std::sqrt(1 - a.v * a.v)}; }
inline Dual atan2(const Dual& y, const Dual& x) {
  return {std::atan2(y.v, x.v), (x.v * y.d - y.v * x.d) / (x.v * x.v + y.v * y.v)};
}
// atan2 on any scalar. Eigen's on an AutoDiffScalar returns a derivative
// vector sized at run time (a heap allocation) whatever its arguments'
// size; this keeps theirs.
template <class S>
S atan2_of(const S& y, const S& x) {
  using std::atan2;
  if constexpr (std::is_same_v<S, double> || std::is_same_v<S, Dual> || !requires { y.value(); }) {
    return atan2(y, x);  // (lanes too: simd.hpp's)
  } else {
    const double yv = y.value(), xv = x.value();
    S out = (y * xv - x * yv) / (xv * xv + yv * yv);
    out.value() = std::atan2(yv, xv);
    return out;
  }
}

// The derivatives of a scalar as a vector (one entry for a Dual).
inline Eigen::VectorXd gradient(const Dual& x) { return Eigen::VectorXd::Constant(1, x.d); }
template <class D>
Eigen::VectorXd gradient(const Eigen::AutoDiffScalar<D>& x) { return x.derivatives(); }
// The same into `out`, whose storage is reused when its size fits.
inline void gradient_into(const Dual& x, Eigen::VectorXd& out) {
  out.resize(1);
  out[0] = x.d;
}
template <class D>
void gradient_into(const Eigen::AutoDiffScalar<D>& x, Eigen::VectorXd& out) { out = x.derivatives(); }

inline double value(double x) { return x; }
inline double value(const Dual& x) { return x.v; }
template <class D>
double value(const Eigen::AutoDiffScalar<D>& x) { return x.value(); }

template <class S>
inline constexpr bool is_dual = !std::is_same_v<S, double>;

// A DualN<N> equal to x whose derivative is the unit vector of variable i.
template <int N>
DualN<N> seed(double x, int i) { return DualN<N>(x, N, i); }
// The angle phi as a Dual of slope 1: f(seed(phi)).d is df/dphi.
inline Dual seed(double phi) { return {phi, 1.0}; }

}  // namespace mech
