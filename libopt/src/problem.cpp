#include "opt/problem.hpp"

#include <algorithm>

namespace opt {

Eigen::VectorXd Problem::initial_point(bool clamp) const {
  const auto& v = variables();
  Eigen::VectorXd x(v.size());
  for (size_t i = 0; i < v.size(); ++i)
    x[i] = clamp ? std::clamp(v[i].initial, v[i].lower, v[i].upper) : v[i].initial;
  return x;
}

Eigen::VectorXd Problem::lower_bounds() const {
  const auto& v = variables();
  Eigen::VectorXd x(v.size());
  for (size_t i = 0; i < v.size(); ++i) x[i] = v[i].lower;
  return x;
}

Eigen::VectorXd Problem::upper_bounds() const {
  const auto& v = variables();
  Eigen::VectorXd x(v.size());
  for (size_t i = 0; i < v.size(); ++i) x[i] = v[i].upper;
  return x;
}

bool Problem::has_metric(const std::string& name) const {
  const auto names = metric_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace opt
