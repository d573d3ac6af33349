#include "opt/problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace opt {
namespace {

// Marks the AVX registers' upper halves clean (vzeroupper) when a model
// hands back to code built without AVX: SQLite, NLopt, Ipopt, the C++
// runtime. GCC 12 at -O3 -mavx2 can leave them in use: the conveyor's
// Grashof sort packs four lengths into a ymm register and calls the sort's
// out-of-line loop with no vzeroupper, then returns assuming the callee
// cleaned. Until the next vzeroupper every SSE instruction of that code
// waits on the upper halves: the conveyor DOE's row inserts took twice as
// long after a failed design (docs/performance.md, "Writing the rows").
void leave_avx() {
#ifdef __AVX__
  __builtin_ia32_vzeroupper();
#endif
}

}  // namespace

std::string Constraint::text() const {
  char b[32];
  std::snprintf(b, sizeof b, "%g", bound);
  return metric + relation() + b;
}

void Evaluation::join_gradients(const Evaluation& chunk, int first, int n) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!has(static_cast<MetricId>(i))) continue;
    Eigen::VectorXd& g = values[i].gradient;
    const Eigen::VectorXd& c = chunk.values[i].gradient;
    const int m = std::min(static_cast<int>(c.size()), n - first);
    if (&chunk == this) {
      const Eigen::VectorXd head = c.head(m);
      g.setZero(n);
      g.head(m) = head;
    } else {
      g.segment(first, m) = c.head(m);
    }
  }
}

bool Evaluation::has(const std::string& name) const {
  if (!names) return false;
  const auto it = std::find(names->begin(), names->end(), name);
  return it != names->end() && has(static_cast<MetricId>(it - names->begin()));
}

double Evaluation::at(const std::string& name) const {
  if (!has(name)) throw std::out_of_range("metric " + name + " was not computed");
  return (*this)[static_cast<MetricId>(std::find(names->begin(), names->end(), name) - names->begin())].value;
}

Evaluation Problem::evaluate(const Eigen::VectorXd& x, const MetricSet& wanted, bool gradient) const {
  Evaluation e;
  evaluate(x, wanted, gradient, e);
  return e;
}

void Problem::evaluate(const Eigen::VectorXd& x, const MetricSet& wanted, bool gradient, Evaluation& e) const {
  const std::unique_ptr<Workspace> ws = make_workspace();
  evaluate(x, wanted, gradient, e, *ws);
}

void Problem::evaluate(const Eigen::VectorXd& x, const MetricSet& wanted, bool gradient, Evaluation& e,
                       Workspace& ws) const {
  if (!x.allFinite()) {  // a driver's step past every scale (bounds near 1e308): no model sees it
    int i = 0;
    while (std::isfinite(x[i])) ++i;
    if (e.names.get() != &metric_names()) e.names = shared_metric_names();
    e.status = Status::non_finite;
    e.message = "variable " + variables()[static_cast<size_t>(i)].name + " is not finite";
    e.computed = MetricSet();
    return;
  }
  evaluate_model_with(x, wanted, gradient, e, ws);
  leave_avx();
  if (e.names.get() != &metric_names()) e.names = shared_metric_names();  // no reference count churn per design
  for (MetricId i = 0; i < static_cast<MetricId>(e.values.size()); ++i) {
    if (!e.has(i)) continue;
    const MetricValue& m = e[i];
    if (std::isfinite(m.value) && m.gradient.allFinite()) continue;
    // Metrics stay defined where the design is not (implicit constraints)
    // and may be kept; a non-finite one never is.
    if (e.ok())
      e.message = (*e.names)[static_cast<size_t>(i)] +
                  (std::isfinite(m.value) ? " has a non-finite gradient" : " is not finite");
    e.status = e.ok() ? Status::non_finite : e.status;
    e.computed = MetricSet();
    return;
  }
}

Evaluation Problem::evaluate(const Eigen::VectorXd& x, const std::vector<std::string>& wanted,
                             bool gradient) const {
  return evaluate(x, wanted.empty() ? MetricSet::all() : metric_set(wanted), gradient);
}

nlohmann::json Problem::record() const {
  nlohmann::json j = settings();
  if (resolved.empty()) return j;
  if (!j.is_object()) j = {{"settings", j}};
  for (const auto& [key, value] : resolved.items()) j[key] = value;
  return j;
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

MetricId Problem::metric_id(const std::string& name) const {
  const auto& names = metric_names();
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<MetricId>(it - names.begin());
}

MetricSet Problem::metric_set(const std::vector<std::string>& names) const {
  MetricSet s;
  for (const auto& n : names) s.add(checked_id(n));
  return s;
}

MetricId Problem::checked_id(const std::string& metric) const {
  const MetricId i = metric_id(metric);
  if (i < 0) throw std::invalid_argument(name() + " has no metric " + metric);
  return i;
}

Objective Problem::bind(Objective o) const {
  o.id = checked_id(o.metric);
  return o;
}

std::vector<Constraint> Problem::bind(std::vector<Constraint> cs) const {
  for (auto& k : cs) k.id = checked_id(k.metric);
  return cs;
}

}  // namespace opt
