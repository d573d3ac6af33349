#include "opt/problem.hpp"

#include <algorithm>
#include <cmath>

namespace opt {

Evaluation Problem::evaluate(const Eigen::VectorXd& x, const std::vector<std::string>& wanted,
                             bool gradient) const {
  Evaluation e = evaluate_model_at(x, wanted, gradient);
  for (const auto& [name, m] : e.metrics)
    if (!std::isfinite(m.value) || !m.gradient.allFinite()) {
      // Metrics stay defined where the design is not (implicit constraints)
      // and may be kept; a non-finite one never is.
      if (!e.ok()) return {e.status, e.message, {}};
      return {"non_finite", name + (std::isfinite(m.value) ? " has a non-finite gradient" : " is not finite"), {}};
    }
  return e;
}

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
