// Forward-mode autodiff scalars used by every model: exact first derivatives
// with respect to N design variables (N fixed at compile time, so there is no
// heap use and one variable costs one derivative, not kMaxDerivatives).
#pragma once
#include <Eigen/Core>
#include <type_traits>
#include <unsupported/Eigen/AutoDiff>

namespace mech {

inline constexpr int kMaxDerivatives = 4;
template <int N>
using DualN = Eigen::AutoDiffScalar<Eigen::Matrix<double, N, 1>>;
using Dual = DualN<1>;  // derivative along one direction (e.g. the crank angle)

inline double value(double x) { return x; }
template <class D>
double value(const Eigen::AutoDiffScalar<D>& x) { return x.value(); }

template <class S>
inline constexpr bool is_dual = !std::is_same_v<S, double>;

// A DualN<N> equal to x whose derivative is the unit vector of variable i.
template <int N = 1>
DualN<N> seed(double x, int i = 0) { return DualN<N>(x, N, i); }

}  // namespace mech
