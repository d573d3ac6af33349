// The line driver (drivers/line.cpp).
#pragma once
#include <string>
#include <vector>

#include "opt/driver.hpp"

namespace opt {

// One variable within finite bounds, no constraints of the user's, an exact
// derivative (`library: line`): downhill from the start to the bound or to
// the derivative's sign change, refined by Brent's method.
class LineDriver : public ConfiguredDriver {
 public:
  using ConfiguredDriver::ConfiguredDriver;
  Result minimize(const Problem& problem, const Objective& objective, const std::vector<Constraint>& constraints,
                  const Eigen::VectorXd& x0) const override;
  std::string incompatibility(const Problem& problem, const std::vector<Constraint>& constraints) const override;
};

}  // namespace opt
