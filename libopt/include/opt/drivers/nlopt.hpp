// NLopt behind the Driver interface (drivers/nlopt.cpp), and the algorithms
// mechopt offers from it.
#pragma once
#include <string>
#include <vector>

#include "opt/driver.hpp"

namespace opt {

// The NLopt algorithms mechopt offers, for help text and config checks, and
// what each takes (NLopt's algorithm documentation, doc/docs/NLopt_Algorithms.md).
std::vector<std::string> nlopt_algorithms();
bool algorithm_uses_gradient(const std::string& algorithm);
bool algorithm_is_global(const std::string& algorithm);
bool algorithm_supports_constraints(const std::string& algorithm);  // nonlinear inequalities
bool algorithm_supports_equalities(const std::string& algorithm);

// The NLopt algorithm used when options.algorithm is empty: LD_SLSQP for a
// problem with exact gradients (constraints of both kinds, curvature model),
// LN_COBYLA without (derivative-free, constraints of both kinds).
std::string default_algorithm(const Problem& problem);

// Why one NLopt algorithm cannot take the problem, or "": its own rules
// (derivatives, variables, finite bounds, kinds of constraint), without the
// local algorithm G_MLSL_LDS is given.
std::string nlopt_algorithm_incompatibility(const std::string& algorithm, const Problem& problem,
                                            const std::vector<Constraint>& constraints);

class NloptDriver : public ConfiguredDriver {
 public:
  using ConfiguredDriver::ConfiguredDriver;
  Result minimize(const Problem& problem, const Objective& objective, const std::vector<Constraint>& constraints,
                  const Eigen::VectorXd& x0) const override;
  std::string incompatibility(const Problem& problem, const std::vector<Constraint>& constraints) const override;
};

}  // namespace opt
