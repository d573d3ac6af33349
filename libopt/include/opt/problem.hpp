// The Problem interface: named design variables with bounds and units, and
// named metrics (objectives and constraints are metrics picked by name)
// evaluated with a status and exact gradients where the model provides them.
#pragma once
#include <Eigen/Core>
#include <bitset>
#include <cmath>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mech/status.hpp"
#include "opt/units.hpp"

namespace opt {

struct Variable {
  std::string name;
  Dimension dimension = Dimension::dimensionless;  // values are SI: m, rad, ...
  double lower = 0, upper = 0;
  double initial = 0;
  Domain domain = kAnyValue;  // of the model value (the bounds lie in it)
};

struct MetricValue {
  double value = 0;
  Eigen::VectorXd gradient;  // d value / d x, empty when not asked for
};

// The one design status, from libmech (names only where results are written).
using Status = mech::Status;

// A metric by its position in Problem::metric_names(): resolved from its name
// once, when a driver or study starts, never per evaluation.
using MetricId = int;

// A set of metrics by id (a problem has at most kMax metrics).
class MetricSet {
 public:
  static constexpr int kMax = 64;
  static MetricSet all() {
    MetricSet s;
    s.bits_.set();
    return s;
  }
  void add(MetricId i) { bits_.set(static_cast<size_t>(i)); }
  bool contains(MetricId i) const { return bits_.test(static_cast<size_t>(i)); }

 private:
  std::bitset<kMax> bits_;
};

// Metrics at one design. status is ok or the reason the design is infeasible
// (e.g. cannot_assemble); no metric is computed unless ok, except metrics
// that stay defined everywhere (such as the implicit constraints below).
// Values sit by MetricId: no map and no string per evaluation.
struct Evaluation {
  Status status = Status::ok;
  std::string message;               // why, when the status alone does not say
  std::vector<MetricValue> values;   // by MetricId; meaningful where computed
  MetricSet computed;
  // The problem's metric names, shared: an evaluation may outlive its problem.
  std::shared_ptr<const std::vector<std::string>> names;

  bool ok() const { return status == Status::ok; }
  bool has(MetricId i) const { return i >= 0 && computed.contains(i); }
  const MetricValue& operator[](MetricId i) const { return values[static_cast<size_t>(i)]; }
  void set(MetricId i, MetricValue v) { slot(i) = std::move(v); }
  // Metric i, marked computed, to be written in place (its gradient's
  // storage reused from an earlier evaluation of the same size).
  [[gnu::always_inline]] MetricValue& slot(MetricId i) {  // ten a design: inline
    if (values.size() <= static_cast<size_t>(i)) [[unlikely]] make_room(i);
    computed.add(i);
    return values[static_cast<size_t>(i)];
  }
  // Ready for a new evaluation: status ok, no message, nothing computed
  // (the values' storage is kept).
  void clear() {
    status = Status::ok;
    message.clear();
    computed = MetricSet();
  }
  void make_room(MetricId i) { values.resize(static_cast<size_t>(i) + 1); }
  // Columns first, first + 1, ... of every computed metric's gradient (n
  // columns in all) from `chunk`'s gradients, which hold those columns
  // alone: a forward-mode pass over some of the variables. chunk may be
  // this evaluation itself (its gradients are then widened to n).
  void join_gradients(const Evaluation& chunk, int first, int n);
  // By name, for reports and tests (a search over the names).
  bool has(const std::string& name) const;
  double at(const std::string& name) const;  // std::out_of_range unless computed
};

// A metric kept below, above or at a bound: metric <= bound (upper),
// metric >= bound (!upper), or metric == bound (equal, with upper set).
struct Constraint {
  std::string metric;
  bool upper = true;
  double bound = 0;
  bool equal = false;
  MetricId id = -1;  // of `metric`, set where a driver starts (Problem::metric_id)
  // Signed violation: g(x) <= 0, or g(x) == 0 for an equality.
  double g(double v) const { return upper ? v - bound : bound - v; }
  double violation(double v) const { return equal ? std::abs(g(v)) : std::max(0.0, g(v)); }
  // How far from the bound a value still counts as on it: 1e-6 of the
  // bound's size, at least 1e-6.
  double tolerance() const { return 1e-6 * std::max(1.0, std::abs(bound)); }
  bool met(double v) const { return violation(v) <= tolerance(); }
  // An equality, or an inequality at its bound (within tolerance()) or past it.
  bool active(double v) const { return equal || !(g(v) < -tolerance()); }
  const char* relation() const { return equal ? " = " : upper ? " <= " : " >= "; }
  std::string text() const;  // "metric <= bound", the bound as %g
};

struct Objective {
  std::string metric;
  bool maximize = false;
  MetricId id = -1;  // of `metric`, set where a driver starts (Problem::metric_id)
};

// Quantities over one crank revolution (or the part of it a problem works
// on), for cycle.svg and cycle.csv: column 0 is the abscissa (the crank
// angle [rad], or time [s]); every column has its SI unit ("rad", "J",
// "N m", "N", "m", ...). The chart draws the `primary` column and every
// other column in its unit on one axis.
struct CycleCurves {
  CycleCurves() = default;
  CycleCurves(std::vector<std::string> names_, std::vector<std::string> units_, size_t primary_ = 1)
      : names(std::move(names_)), units(std::move(units_)), primary(primary_) {}
  std::vector<std::string> names;
  std::vector<std::string> units;  // one per column
  std::vector<std::vector<double>> columns;
  size_t primary = 1;
  void add_row(std::initializer_list<double> row) {
    columns.resize(names.size());
    size_t i = 0;
    for (double v : row) columns[i++].push_back(v);
  }
  // The columns the chart draws: primary first, then the others in its unit.
  std::vector<size_t> plotted() const {
    std::vector<size_t> out;
    if (primary >= names.size() || units.size() != names.size()) return out;
    out.push_back(primary);
    for (size_t k = 1; k < names.size(); ++k)
      if (k != primary && units[k] == units[primary]) out.push_back(k);
    return out;
  }
};

// Scratch space for one evaluation at a time: what a problem's evaluation
// reuses from one design to the next (a values vector, a cycle search's
// lists), made by Problem::make_workspace and owned by whoever evaluates (a
// driver run, a DOE worker thread). The problem stays immutable and shared;
// two evaluations under way at once (two threads, or a linked problem inside
// another's evaluation) each have their own.
struct Workspace {
  virtual ~Workspace() = default;
};

class Problem {
 public:
  virtual ~Problem() = default;
  virtual std::string name() const = 0;
  virtual const std::vector<Variable>& variables() const = 0;
  // Every metric this problem can compute, objectives and constraints alike;
  // a metric's MetricId is its position here.
  virtual const std::vector<std::string>& metric_names() const = 0;
  // The same, shared with the evaluations (a copy unless a problem keeps one).
  virtual std::shared_ptr<const std::vector<std::string>> shared_metric_names() const {
    return std::make_shared<const std::vector<std::string>>(metric_names());
  }
  // The current name of a metric once called `old`, or "" (configs written
  // with the old name still run, with a notice).
  virtual std::string renamed_metric(const std::string& old) const {
    (void)old;
    return "";
  }
  // SI unit of a metric for printing, e.g. "J", "N m", "" for ratios.
  virtual std::string metric_unit(const std::string& metric) const = 0;
  // Constraints that keep the model evaluable (e.g. the rod must reach the
  // slider): defined everywhere, added by every driver.
  virtual std::vector<Constraint> implicit_constraints() const { return {}; }
  // Evaluates the metrics in `wanted` at x, with gradients if asked. Never
  // lies: a design whose metrics (or gradients) come out NaN or infinite has
  // status non_finite and no metrics.
  Evaluation evaluate(const Eigen::VectorXd& x, const MetricSet& wanted, bool gradient) const;
  // The same into `out`, reusing its storage, with `ws` (from this problem's
  // make_workspace) as scratch: a driver's loop over designs then allocates
  // nothing per evaluation. The overloads without a workspace make one per
  // call (reports, tests).
  void evaluate(const Eigen::VectorXd& x, const MetricSet& wanted, bool gradient, Evaluation& out,
                Workspace& ws) const;
  void evaluate(const Eigen::VectorXd& x, const MetricSet& wanted, bool gradient, Evaluation& out) const;
  // A workspace for evaluate: the problem's own type (a plain Workspace when
  // the problem keeps no scratch).
  virtual std::unique_ptr<Workspace> make_workspace() const { return std::make_unique<Workspace>(); }
  // The same by names (all metrics if empty), for reports and tests.
  Evaluation evaluate(const Eigen::VectorXd& x, const std::vector<std::string>& wanted, bool gradient) const;
  // Curves over one crank revolution at x, at n + 1 angles from 0 to 2 pi
  // (or over the problem's working part of it, or its time span); empty when
  // the design is infeasible or the problem has none.
  virtual CycleCurves cycle_curves(const Eigen::VectorXd& x, int n) const {
    (void)x, (void)n;
    return {};
  }
  // The mechanism drawn at x as an SVG document, `label` naming the design
  // (mechanism.svg, beside cycle.svg); "" when the problem draws none.
  virtual std::string mechanism_svg(const Eigen::VectorXd& x, const std::string& label) const {
    (void)x, (void)label;
    return "";
  }
  // For a metric that is a maximum over the crank cycle: every local maximum
  // at x, each the integrand at one refined angle with its gradient taken at
  // that fixed angle (the local maximum's exact gradient, by the envelope
  // theorem), sorted by angle. Empty when the metric is not such a maximum or
  // x is infeasible. Drivers use it for epigraph formulations.
  virtual std::vector<MetricValue> local_maxima(const Eigen::VectorXd& x, MetricId metric) const {
    (void)x, (void)metric;
    return {};
  }
  // False when the metrics have no exact gradients (e.g. ODE-based ones):
  // gradient drivers then refuse the problem with a clear status.
  virtual bool provides_gradients() const { return true; }
  // Fidelity, numerical settings and fixed model values, for result files.
  virtual nlohmann::json settings() const = 0;
  // How opt::make_problem settled the config's open values, for the
  // record: "links" (model values taken from other configs' results: each
  // one's key, file, metric, value and the linked problem's record) and
  // "fidelity" (each `auto` level: the one chosen and why).
  nlohmann::json resolved = nlohmann::json::object();
  // settings() with `resolved`'s entries: what result files and a DOE's
  // config hash record.
  nlohmann::json record() const;

  // The variables' initial values, clamped into their bounds for drivers;
  // unclamped, the model's values as written (for `mechopt eval`).
  Eigen::VectorXd initial_point(bool clamp = true) const;
  Eigen::VectorXd lower_bounds() const;
  Eigen::VectorXd upper_bounds() const;
  bool has_metric(const std::string& name) const { return metric_id(name) >= 0; }
  // The id of a metric, or -1.
  MetricId metric_id(const std::string& name) const;
  // The ids of metrics by name (std::invalid_argument naming an unknown one).
  MetricSet metric_set(const std::vector<std::string>& names) const;
  // The objective or constraints with their metrics' ids set (std::invalid_argument naming an unknown metric).
  Objective bind(Objective o) const;
  std::vector<Constraint> bind(std::vector<Constraint> cs) const;

 protected:
  MetricId checked_id(const std::string& metric) const;
  // The model's evaluation behind evaluate().
  virtual Evaluation evaluate_model_at(const Eigen::VectorXd& x, const MetricSet& wanted,
                                       bool gradient) const = 0;
  // The same into `out` (cleared first), for models that reuse its storage.
  virtual void evaluate_model_into(const Eigen::VectorXd& x, const MetricSet& wanted, bool gradient,
                                   Evaluation& out) const {
    out = evaluate_model_at(x, wanted, gradient);
  }
  // The same with `ws`, made by this problem's make_workspace, as scratch.
  virtual void evaluate_model_with(const Eigen::VectorXd& x, const MetricSet& wanted, bool gradient,
                                   Evaluation& out, Workspace& ws) const {
    (void)ws;
    evaluate_model_into(x, wanted, gradient, out);
  }
};

}  // namespace opt
