// Forward-mode autodiff scalar used by every model: exact first derivatives
// with respect to at most kMaxDerivatives design variables, no heap use.
#pragma once
#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

namespace mech {

inline constexpr int kMaxDerivatives = 4;
using Gradient = Eigen::Matrix<double, kMaxDerivatives, 1>;
using Dual = Eigen::AutoDiffScalar<Gradient>;

inline double value(double x) { return x; }
inline double value(const Dual& x) { return x.value(); }

// A Dual equal to x whose derivative is the unit vector of variable i.
inline Dual seed(double x, int i) { return Dual(x, kMaxDerivatives, i); }

}  // namespace mech
