// Is a design where a maximum over the cycle has equal peaks an optimum, or
// only a kink the optimiser stopped on? Is the objective flat around a
// design a derivative-free optimiser stopped at? (docs/drivers.md, "Kinks"
// and "Plateaus")
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "opt/driver.hpp"

namespace opt {

namespace {

// min |sum_i l_i p_i + sum_k m_k c_k| over l >= 0, sum l = 1, m >= 0: the
// distance from 0 to the hull of the pieces' gradients plus the cone of the
// active constraints' gradients. Exact, by every support set (a handful of
// generators: 2^count small systems): on its support the minimum solves
// [B'B e; e' 0] [w; nu] = [0; 1] (e: 1 on pieces), and the least over the
// supports whose solution has no negative weight is the minimum.
double min_norm(const std::vector<Eigen::VectorXd>& pieces, const std::vector<Eigen::VectorXd>& cone) {
  const int p = static_cast<int>(pieces.size()), m = p + static_cast<int>(cone.size());
  double best = std::numeric_limits<double>::infinity();
  for (unsigned mask = 1; mask < (1u << m); ++mask) {
    if (!(mask & ((1u << p) - 1))) continue;  // at least one piece
    std::vector<int> support;
    for (int i = 0; i < m; ++i)
      if (mask & (1u << i)) support.push_back(i);
    const int k = static_cast<int>(support.size()), n = static_cast<int>(pieces[0].size());
    Eigen::MatrixXd B(n, k);
    for (int j = 0; j < k; ++j) B.col(j) = support[j] < p ? pieces[support[j]] : cone[support[j] - p];
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(k + 1, k + 1);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(k + 1);
    K.topLeftCorner(k, k) = B.transpose() * B;
    for (int j = 0; j < k; ++j)
      if (support[j] < p) K(j, k) = K(k, j) = 1;
    rhs[k] = 1;
    const Eigen::VectorXd w = K.completeOrthogonalDecomposition().solve(rhs).head(k);
    double pieces_sum = 0;
    for (int j = 0; j < k; ++j)
      if (support[j] < p) pieces_sum += w[j];
    if ((w.array() < -1e-12).any() || std::abs(pieces_sum - 1) > 1e-9) continue;
    best = std::min(best, (B * w).norm());
  }
  return best;
}

// Each variable's range, or its size where unbounded: steps and gradients
// of lengths and angles compare in these units.
Eigen::VectorXd variable_scales(const Problem& problem, const Eigen::VectorXd& x) {
  const auto& vars = problem.variables();
  Eigen::VectorXd scale(x.size());
  for (int j = 0; j < x.size(); ++j) {
    const double range = vars[j].upper - vars[j].lower;
    scale[j] = std::isfinite(range) && range > 0 ? range : std::max(1.0, std::abs(x[j]));
  }
  return scale;
}

}  // namespace

std::vector<int> flat_variables(const Problem& problem, const Objective& objective, const Eigen::VectorXd& x,
                                double f) {
  const auto& vars = problem.variables();
  const Eigen::VectorXd scale = variable_scales(problem, x);
  MetricSet wanted;
  wanted.add(objective.id);
  std::vector<int> flat;
  for (int j = 0; j < x.size(); ++j) {
    bool moved = false, changed = false;
    for (double side : {-1.0, 1.0}) {
      Eigen::VectorXd y = x;
      y[j] += side * kPlateauStep * scale[j];
      if (y[j] < vars[j].lower || y[j] > vars[j].upper) continue;
      const Evaluation e = problem.evaluate(y, wanted, false);
      if (!e.ok() || !std::isfinite(e[objective.id].value)) continue;
      const double fy = e[objective.id].value;
      moved = true;
      changed = changed || std::abs(fy - f) > kPlateauChange * std::max(std::abs(f), std::abs(fy));
    }
    if (moved && !changed) flat.push_back(j);
  }
  return flat;
}

std::optional<KinkCheck> check_kink(const Problem& problem, const Objective& objective,
                                    const std::vector<Constraint>& constraints, const Eigen::VectorXd& x) {
  if (objective.maximize) return std::nullopt;  // maximising a maximum: its kinks are troughs
  const std::vector<MetricValue> maxima = problem.local_maxima(x, objective.id);
  if (maxima.size() < 2) return std::nullopt;
  double top = -std::numeric_limits<double>::infinity();
  for (const auto& v : maxima) top = std::max(top, v.value);
  const auto& vars = problem.variables();
  const Eigen::VectorXd scale = variable_scales(problem, x);  // gradients of lengths and angles compare
  KinkCheck out;
  std::vector<Eigen::VectorXd> pieces, cone;
  double largest = 0;
  for (const auto& v : maxima) {
    if (v.value < top - 1e-6 * std::abs(top) || v.gradient.size() != x.size()) continue;
    pieces.push_back(v.gradient.cwiseProduct(scale));
    largest = std::max(largest, pieces.back().norm());
  }
  out.peaks = static_cast<int>(pieces.size());
  if (out.peaks < 2 || !(largest > 0) || !std::isfinite(largest)) return std::nullopt;
  // Active bounds and constraints: the directions they forbid.
  for (int j = 0; j < x.size(); ++j) {
    const double room = 1e-9 * scale[j];
    if (x[j] - vars[j].lower <= room) cone.push_back(-Eigen::VectorXd::Unit(x.size(), j));
    if (vars[j].upper - x[j] <= room) cone.push_back(Eigen::VectorXd::Unit(x.size(), j));
  }
  if (!constraints.empty()) {
    MetricSet wanted;
    for (const auto& k : constraints) wanted.add(k.id);
    const Evaluation e = problem.evaluate(x, wanted, true);
    if (!e.ok()) return std::nullopt;
    for (const auto& k : constraints) {
      const MetricValue& v = e[k.id];
      if (k.g(v.value) < -1e-6 * std::max(1.0, std::abs(k.bound)) && !k.equal) continue;
      if (v.gradient.size() != x.size()) return std::nullopt;  // cannot tell
      const Eigen::VectorXd a = v.gradient.cwiseProduct(scale);
      if (k.upper || k.equal) cone.push_back(a);
      if (!k.upper || k.equal) cone.push_back(-a);
    }
  }
  if (pieces.size() + cone.size() > 12) return std::nullopt;  // not a handful: not checked
  // Pieces over their largest norm, cone directions of unit length (any
  // positive multiple spans the same cone): the systems stay well scaled.
  for (auto& g : pieces) g /= largest;
  for (auto& a : cone)
    if (const double n = a.norm(); n > 0) a /= n;
  out.measure = min_norm(pieces, cone);
  return out;
}

}  // namespace opt
