// Is a design where a maximum over the cycle has equal peaks an optimum, or
// only a kink the optimiser stopped on? Is the objective flat around a
// design a derivative-free optimiser stopped at? (docs/drivers.md, "Kinks"
// and "Plateaus")
#include "opt/stationarity.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>


namespace opt {

namespace {

// argmin |sum_i l_i p_i + sum_k m_k c_k| over l >= 0, sum l = 1, m >= 0:
// the point of the hull of the pieces' gradients plus the cone of the
// active constraints' gradients nearest to 0. Exact, by every support set
// (a handful of generators: 2^count small systems): on its support the minimum solves
// [B'B e; e' 0] [w; nu] = [0; 1] (e: 1 on pieces), and the least over the
// supports whose solution has no negative weight is the minimum.
Eigen::VectorXd min_norm_point(const std::vector<Eigen::VectorXd>& pieces, const std::vector<Eigen::VectorXd>& cone) {
  const int p = static_cast<int>(pieces.size()), m = p + static_cast<int>(cone.size());
  double best = std::numeric_limits<double>::infinity();
  Eigen::VectorXd point;
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
    if (const Eigen::VectorXd v = B * w; v.norm() < best) {
      best = v.norm();
      point = v;
    }
  }
  return point;
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

// The directions the active bounds and constraints at x forbid (or, given
// `held`, the bounds and the constraints it marks), in the variables' scales
// and of unit length (any positive multiple spans the same cone), from e, an
// evaluation at x with the constraints' gradients. None when an active
// constraint has no gradient (cannot tell).
std::optional<std::vector<Eigen::VectorXd>> active_cone(const Problem& problem,
                                                        const std::vector<Constraint>& constraints,
                                                        const Evaluation& e, const Eigen::VectorXd& x,
                                                        const Eigen::VectorXd& scale,
                                                        const std::vector<char>& held = {}) {
  const auto& vars = problem.variables();
  std::vector<Eigen::VectorXd> cone;
  for (int j = 0; j < x.size(); ++j) {
    const double room = 1e-9 * scale[j];
    if (x[j] - vars[j].lower <= room) cone.push_back(-Eigen::VectorXd::Unit(x.size(), j));
    if (vars[j].upper - x[j] <= room) cone.push_back(Eigen::VectorXd::Unit(x.size(), j));
  }
  for (std::size_t i = 0; i < constraints.size(); ++i) {
    const Constraint& k = constraints[i];
    const MetricValue& v = e[k.id];
    if (!(held.empty() ? k.active(v.value) : held[i])) continue;
    if (v.gradient.size() != x.size()) return std::nullopt;
    Eigen::VectorXd a = v.gradient.cwiseProduct(scale);
    if (const double n = a.norm(); n > 0) a /= n;
    if (k.upper || k.equal) cone.push_back(a);
    if (!k.upper || k.equal) cone.push_back(-a);
  }
  return cone;
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

namespace {

// The distance from 0 to the hull of the objective's pieces plus the cone of
// the active bounds and constraints at x, over the largest piece (variables
// scaled by their ranges): the pieces are the gradients of the peaks within
// 1e-6 of the top for a minimised maximum over the cycle with at least
// `least_peaks` of them, else (least_peaks 0) the objective's gradient.
// None where that cannot be told (no gradients, more than a handful of
// generators, an evaluation that fails).
std::optional<KinkCheck> first_order(const Problem& problem, const Objective& objective,
                                     const std::vector<Constraint>& constraints, const Eigen::VectorXd& x,
                                     int least_peaks) {
  const Eigen::VectorXd scale = variable_scales(problem, x);  // gradients of lengths and angles compare
  std::vector<Eigen::VectorXd> pieces;
  if (!objective.maximize) {
    const std::vector<MetricValue> maxima = problem.local_maxima(x, objective.id);
    double top = -std::numeric_limits<double>::infinity();
    for (const auto& v : maxima) top = std::max(top, v.value);
    for (const auto& v : maxima)
      if (v.value >= top - 1e-6 * std::abs(top) && v.gradient.size() == x.size())
        pieces.push_back(v.gradient.cwiseProduct(scale));
  }
  if (static_cast<int>(pieces.size()) < least_peaks) return std::nullopt;
  MetricSet wanted;
  for (const auto& k : constraints) wanted.add(k.id);
  if (pieces.empty()) wanted.add(objective.id);
  Evaluation e;
  if (!constraints.empty() || pieces.empty()) {
    e = problem.evaluate(x, wanted, true);
    if (!e.ok()) return std::nullopt;
  }
  if (pieces.empty()) {
    if (e[objective.id].gradient.size() != x.size()) return std::nullopt;
    pieces.push_back((objective.maximize ? -1.0 : 1.0) * e[objective.id].gradient.cwiseProduct(scale));
  }
  double largest = 0;
  for (const auto& g : pieces) largest = std::max(largest, g.norm());
  if (!std::isfinite(largest)) return std::nullopt;
  if (largest == 0) return KinkCheck{static_cast<int>(pieces.size()), 0.0};  // stationary outright
  const auto cone = active_cone(problem, constraints, e, x, scale);
  if (!cone || pieces.size() + cone->size() > 12) return std::nullopt;  // not a handful: not checked
  for (auto& g : pieces) g /= largest;  // the systems stay well scaled
  return KinkCheck{static_cast<int>(pieces.size()), min_norm_point(pieces, *cone).norm()};
}

}  // namespace

std::optional<KinkCheck> check_kink(const Problem& problem, const Objective& objective,
                                    const std::vector<Constraint>& constraints, const Eigen::VectorXd& x) {
  if (objective.maximize) return std::nullopt;  // maximising a maximum: its kinks are troughs
  return first_order(problem, objective, constraints, x, 2);
}

std::optional<double> kkt_measure(const Problem& problem, const Objective& objective,
                                  const std::vector<Constraint>& constraints, const Eigen::VectorXd& x) {
  if (!problem.provides_gradients()) return std::nullopt;
  MetricSet wanted;
  for (const auto& k : constraints) wanted.add(k.id);
  if (!constraints.empty()) {
    const Evaluation e = problem.evaluate(x, wanted, false);
    if (!e.ok()) return std::nullopt;
    for (const auto& k : constraints)
      if (!k.met(e[k.id].value)) return std::nullopt;
  }
  const auto check = first_order(problem, objective, constraints, x, 0);
  return check ? std::optional<double>(check->measure) : std::nullopt;
}

std::optional<SlopeCheck> check_slope(const Problem& problem, const Objective& objective,
                                      const std::vector<Constraint>& constraints, const Eigen::VectorXd& x,
                                      double f, const Evaluation* at_x) {
  if (!problem.provides_gradients() || !std::isfinite(f)) return std::nullopt;
  std::vector<MetricId> ids{objective.id};
  for (const auto& k : constraints) ids.push_back(k.id);
  MetricSet wanted;
  for (MetricId i : ids) wanted.add(i);
  const auto has_gradients = [&](const Evaluation& e) {
    return e.ok() && std::all_of(ids.begin(), ids.end(), [&](MetricId i) {
             return e.has(i) && e[i].gradient.size() == x.size();
           });
  };
  const bool given = at_x && has_gradients(*at_x);
  Evaluation fresh;
  if (!given) problem.evaluate(x, wanted, true, fresh);
  const Evaluation& e = given ? *at_x : fresh;
  if (!has_gradients(e)) return std::nullopt;
  const Eigen::VectorXd scale = variable_scales(problem, x);
  const double sign = objective.maximize ? -1 : 1;
  const Eigen::VectorXd g = sign * e[objective.id].gradient.cwiseProduct(scale);
  if (!g.allFinite() || !(g.norm() > 0)) return std::nullopt;
  // The step, as a fraction of the ranges: kSlopeStep, or less where that
  // would change f by more than kSlopeReach of itself (to first order: the
  // step times the gradient's 1-norm in the scaled variables).
  const double spread = g.lpNorm<1>();
  const double step = std::abs(f) > 0 ? std::min(kSlopeStep, kSlopeReach * std::abs(f) / spread) : kSlopeStep;
  const double least = kSlopeChange * std::abs(f);
  // The constraints held: the active ones, then each one a probe broke.
  std::vector<char> held(constraints.size());
  for (std::size_t i = 0; i < constraints.size(); ++i) held[i] = constraints[i].active(e[constraints[i].id].value);
  // r: the least combination of the pieces (gradients over their largest
  // norm `size`) less what the active bounds and held constraints hold (0 at
  // a KKT point; at a kink, where no direction lowers every piece). Along
  // d = -r / max|r_j| no variable moves by more than t of its range, and to
  // first order every piece falls by t |r|^2 / max|r_j| or more: the promise.
  auto residual = [&](const std::vector<Eigen::VectorXd>& pieces, double size) -> std::optional<Eigen::VectorXd> {
    const auto cone = active_cone(problem, constraints, e, x, scale, held);
    if (!cone || pieces.size() + cone->size() > 12) return std::nullopt;  // not a handful: not checked
    return pieces.size() == 1 && cone->empty() ? Eigen::VectorXd(size * pieces[0])
                                               : Eigen::VectorXd(size * min_norm_point(pieces, *cone));
  };
  auto promises = [&](const std::optional<Eigen::VectorXd>& r) {
    const double top = r && r->size() ? r->cwiseAbs().maxCoeff() : 0.0;
    return top > 0 && step * r->squaredNorm() / top > least;
  };
  // More pieces and more held constraints only bring r nearer 0: where the
  // gradient alone promises nothing, nothing will (and the peaks are not needed).
  if (!promises(residual({g / g.norm()}, g.norm()))) return std::nullopt;
  // The objective's pieces: its gradient; for a maximum over the cycle, the
  // gradient of every peak the step could lift to the top (within the step
  // times the two gradients' 1-norms of it).
  std::vector<Eigen::VectorXd> pieces;
  const std::vector<MetricValue> maxima =
      objective.maximize ? std::vector<MetricValue>{} : problem.local_maxima(x, objective.id);
  const auto highest = std::max_element(maxima.begin(), maxima.end(),
                                        [](const MetricValue& a, const MetricValue& b) { return a.value < b.value; });
  for (const auto& v : maxima) {
    if (v.gradient.size() != x.size()) continue;
    const Eigen::VectorXd gp = v.gradient.cwiseProduct(scale);
    if (highest->value - v.value <= step * (spread + gp.lpNorm<1>())) pieces.push_back(gp);
  }
  if (pieces.empty()) pieces.push_back(g);
  double size = 0;
  for (const auto& gp : pieces) {
    if (!gp.allFinite()) return std::nullopt;
    size = std::max(size, gp.norm());
  }
  for (auto& gp : pieces) gp /= size;  // well scaled systems
  const Eigen::VectorXd lower = problem.lower_bounds(), upper = problem.upper_bounds();
  // -r is tangent to the held constraints: the step leaves an equality, or
  // a held inequality bent away from it, at second order; a few Gauss-Newton
  // corrections with their Jacobian at x (y -= A' (A A')^-1 h over the
  // equalities and the held inequalities the step broke) bring it back.
  auto correct = [&](Eigen::VectorXd& y, Evaluation& ey) {
    for (int pass = 0; pass < 4 && ey.ok(); ++pass) {
      std::vector<Eigen::VectorXd> rows;
      std::vector<double> h;  // metric - bound
      for (std::size_t i = 0; i < constraints.size(); ++i) {
        const Constraint& k = constraints[i];
        const double over = k.g(ey[k.id].value);
        if (k.equal || (held[i] && over > 0)) rows.push_back(e[k.id].gradient), h.push_back(k.upper ? over : -over);
      }
      if (rows.empty()) return;
      Eigen::MatrixXd A(rows.size(), x.size());
      for (std::size_t i = 0; i < rows.size(); ++i) A.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
      const Eigen::VectorXd hv = Eigen::Map<const Eigen::VectorXd>(h.data(), static_cast<Eigen::Index>(h.size()));
      y = (y - A.transpose() * (A * A.transpose()).completeOrthogonalDecomposition().solve(hv)).cwiseMax(lower).cwiseMin(upper);
      ey = problem.evaluate(y, wanted, false);
    }
  };
  while (true) {
    const auto rr = residual(pieces, size);
    if (!promises(rr)) return std::nullopt;
    const Eigen::VectorXd& r = *rr;
    const double top = r.cwiseAbs().maxCoeff();
    bool broke = false;
    for (double t : {step, step / 10}) {
      Eigen::VectorXd y = (x - (t / top) * r.cwiseProduct(scale)).cwiseMax(lower).cwiseMin(upper);
      Evaluation ey = problem.evaluate(y, wanted, false);
      correct(y, ey);
      if (!ey.ok() || !std::isfinite(ey[objective.id].value)) continue;
      bool feasible = true;
      for (std::size_t i = 0; i < constraints.size(); ++i)
        if (!constraints[i].met(ey[constraints[i].id].value)) {
          feasible = false;
          broke = broke || !held[i];
          held[i] = 1;
        }
      if (const double fy = ey[objective.id].value; feasible && sign * (f - fy) > least) return SlopeCheck{t, fy};
    }
    if (!broke) return std::nullopt;  // no feasible step lowers f, and no new constraint to hold
  }
}

}  // namespace opt
