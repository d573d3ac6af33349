#include "opt/derivatives.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace opt {

std::vector<DerivativeCheck> check_derivatives(const Problem& p, const Eigen::VectorXd& x,
                                               double rel_step, double tol) {
  std::vector<DerivativeCheck> out;
  if (!p.provides_gradients()) return out;
  const Evaluation e = p.evaluate(x, MetricSet::all(), true);
  if (!e.ok()) {  // e.g. a gradient that is not finite: a failed check for each variable, never none
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const auto& v : p.variables())
      out.push_back({e.message.empty() ? std::string(mech::to_string(e.status)) : e.message, v.name, nan, nan, nan, nan, false});
    return out;
  }
  auto record = [&](const std::string& metric, int i, double value, double ad, double fd) {
    const double err = std::abs(ad - fd) / std::max(1.0, std::abs(value));
    out.push_back({metric, p.variables()[i].name, value, ad, fd, err, err <= tol});
  };
  for (int i = 0; i < x.size(); ++i) {
    const double h = rel_step * std::max(1.0, std::abs(x[i]));
    Eigen::VectorXd xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    const Evaluation ep = p.evaluate(xp, MetricSet::all(), false), em = p.evaluate(xm, MetricSet::all(), false);
    for (MetricId m = 0; m < static_cast<MetricId>(p.metric_names().size()); ++m) {
      if (!e.has(m) || !ep.has(m) || !em.has(m)) continue;
      const std::string& name = p.metric_names()[static_cast<size_t>(m)];
      record(name, i, e[m].value, e[m].gradient[i], (ep[m].value - em[m].value) / (2 * h));
      // Local maxima (epigraph rows): each peak's gradient at its fixed
      // angle against the change of the re-refined peak value.
      const auto peaks = p.local_maxima(x, m);
      const auto pp = p.local_maxima(xp, m), pm = p.local_maxima(xm, m);
      if (peaks.empty() || pp.size() != peaks.size() || pm.size() != peaks.size()) continue;
      for (size_t k = 0; k < peaks.size(); ++k)
        record(name + "[peak " + std::to_string(k) + "]", i, peaks[k].value, peaks[k].gradient[i],
               (pp[k].value - pm[k].value) / (2 * h));
    }
  }
  return out;
}

}  // namespace opt
