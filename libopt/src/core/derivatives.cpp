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
  // Two estimates, each with its own error: the central difference at h
  // (truncation h^2 |f'''| / 6: large where a peak's angle moves fast with
  // the design) and its Richardson extrapolation with h/2 (truncation
  // O(h^4), round-off about 2.7 times the central one's). The gradient
  // passes when it agrees with either; the nearer is reported.
  auto record_both = [&](const std::string& metric, int i, double value, double ad, const double (&f)[4],
                         double h) {
    const double central = (f[0] - f[1]) / (2 * h);
    const double richardson = (4 * (f[2] - f[3]) / h - central) / 3;
    record(metric, i, value, ad, std::abs(ad - central) <= std::abs(ad - richardson) ? central : richardson);
  };
  for (int i = 0; i < x.size(); ++i) {
    const double h = rel_step * std::max(1.0, std::abs(x[i]));
    Eigen::VectorXd xs[4] = {x, x, x, x};  // x + h, x - h, x + h/2, x - h/2
    xs[0][i] += h, xs[1][i] -= h, xs[2][i] += h / 2, xs[3][i] -= h / 2;
    Evaluation es[4];
    for (int k = 0; k < 4; ++k) es[k] = p.evaluate(xs[k], MetricSet::all(), false);
    for (MetricId m = 0; m < static_cast<MetricId>(p.metric_names().size()); ++m) {
      if (!e.has(m) || !es[0].has(m) || !es[1].has(m) || !es[2].has(m) || !es[3].has(m)) continue;
      const std::string& name = p.metric_names()[static_cast<size_t>(m)];
      const double f[4] = {es[0][m].value, es[1][m].value, es[2][m].value, es[3][m].value};
      record_both(name, i, e[m].value, e[m].gradient[i], f, h);
      // Local maxima (epigraph rows): each peak's gradient at its fixed
      // angle against the change of the re-refined peak value.
      const auto peaks = p.local_maxima(x, m);
      if (peaks.empty()) continue;
      std::vector<MetricValue> ps[4];
      bool same = true;
      for (int k = 0; k < 4; ++k) {
        ps[k] = p.local_maxima(xs[k], m);
        same = same && ps[k].size() == peaks.size();
      }
      if (!same) continue;
      for (size_t k = 0; k < peaks.size(); ++k) {
        const double f[4] = {ps[0][k].value, ps[1][k].value, ps[2][k].value, ps[3][k].value};
        record_both(name + "[peak " + std::to_string(k) + "]", i, peaks[k].value, peaks[k].gradient[i], f, h);
      }
    }
  }
  return out;
}

}  // namespace opt
