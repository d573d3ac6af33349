// Forward-mode autodiff scalars used by every model: exact first derivatives
// with respect to N design variables. Up to 4 (problems/model_problem.hpp), N is fixed
// at compile time (no heap use; one variable costs one derivative); beyond,
// DualX carries a derivative vector sized at run time.
#pragma once
#include <Eigen/Core>
#include <type_traits>
#include <unsupported/Eigen/AutoDiff>

namespace mech {

template <int N>
using DualN = Eigen::AutoDiffScalar<Eigen::Matrix<double, N, 1>>;
using DualX = Eigen::AutoDiffScalar<Eigen::VectorXd>;
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
