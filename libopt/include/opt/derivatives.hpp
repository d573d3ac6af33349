// Derivative checker: every metric's gradient (autodiff, as the drivers get
// it) against central differences, and the same for every local maximum a
// driver's epigraph rows use.
#pragma once
#include <string>
#include <vector>

#include "opt/problem.hpp"

namespace opt {

struct DerivativeCheck {
  std::string metric;    // "name" or "name[peak k]" for local maxima
  std::string variable;
  double value = 0, autodiff = 0, central = 0;
  double error = 0;      // |autodiff - central| / max(1, |value|)
  bool ok = false;
};

// Central differences with step h = rel_step * max(1, |x_i|): truncation
// ~h^2 |f'''|, roundoff ~eps |f| / h; with rel_step = 1e-6 both stay near
// 1e-10 relative, so tol = 1e-7 leaves a margin. Where f''' is large (a
// peak whose angle moves fast with the design) the difference's
// Richardson extrapolation with h / 2 is the second estimate: a gradient
// passes when it agrees with either. x must be feasible.
std::vector<DerivativeCheck> check_derivatives(const Problem& p, const Eigen::VectorXd& x,
                                               double rel_step = 1e-6, double tol = 1e-7);

}  // namespace opt
