// Ipopt behind the Driver interface (drivers/ipopt.cpp): interior point,
// L-BFGS Hessian, exact gradients, maxima over the cycle as epigraph rows.
#pragma once
#include <string>
#include <vector>

#include "opt/driver.hpp"

namespace opt {

class IpoptDriver : public ConfiguredDriver {
 public:
  using ConfiguredDriver::ConfiguredDriver;
  Result minimize(const Problem& problem, const Objective& objective, const std::vector<Constraint>& constraints,
                  const Eigen::VectorXd& x0) const override;
  std::string incompatibility(const Problem& problem, const std::vector<Constraint>& constraints) const override;
};

}  // namespace opt
