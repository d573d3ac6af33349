// What every driver shares (opt/driver.hpp): the capability message, the
// stop check, the start and the final report, the chain and make_driver.
#include "opt/driver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>

#include "opt/drivers/ipopt.hpp"
#include "opt/drivers/line.hpp"
#include "opt/drivers/nlopt.hpp"
#include "opt/interrupt.hpp"
#include "core/text.hpp"
#include "opt/stationarity.hpp"

namespace opt {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

}  // namespace

std::string to_string(DriverStatus s) {
  switch (s) {
    case DriverStatus::converged: return "converged";
    case DriverStatus::max_evaluations: return "max_evaluations";
    case DriverStatus::max_time: return "max_time";
    case DriverStatus::interrupted: return "interrupted";
    case DriverStatus::infeasible: return "infeasible";
    case DriverStatus::failure: return "failure";
    case DriverStatus::invalid_arguments: return "invalid_arguments";
    case DriverStatus::stopped_on_kink: return "stopped_on_kink";
    case DriverStatus::stopped_on_plateau: return "stopped_on_plateau";
    case DriverStatus::stopped_on_slope: return "stopped_on_slope";
  }
  return "unknown";
}

std::string driver_incompatibility(const DriverOptions& options, const Problem& problem,
                                   const Objective& objective,
                                   const std::vector<Constraint>& constraints) {
  (void)objective;  // every driver takes any metric as its objective
  const std::string why = make_driver(options)->incompatibility(problem, constraints);
  if (why.empty()) return "";
  std::vector<std::string> can;
  for (const auto& a : nlopt_algorithms())
    if (nlopt_algorithm_incompatibility(a, problem, constraints).empty()) can.push_back(a);
  for (const char* library : {"ipopt", "line"}) {
    DriverOptions other;
    other.library = library;
    if (make_driver(other)->incompatibility(problem, constraints).empty())
      can.push_back(std::string("library: ") + library);
  }
  return why + "; algorithms that can take this problem: " + (can.empty() ? "none" : text::join(can));
}

namespace detail {

// The limit against the kernel's coarse monotonic clock (a tick of 4 ms here,
// read from memory: 3 ns a check against 23-47 ns for the precise one, which
// a run of 8 evaluations read some 20 times).
static double coarse_seconds() {
#ifdef CLOCK_MONOTONIC_COARSE
  timespec t;
  clock_gettime(CLOCK_MONOTONIC_COARSE, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
#else
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
#endif
}

StopCheck::StopCheck(double max_seconds)
    : start_(std::chrono::steady_clock::now()), coarse_start_(coarse_seconds()), max_seconds_(max_seconds) {}

bool StopCheck::operator()() {
  if (!reason && stop_requested()) reason = DriverStatus::interrupted;
  // The coarse clock's elapsed time can run up to a tick ahead of the true
  // one (its start read just before a tick): the limit it reports is
  // confirmed on the precise clock, so a run never stops before it.
  if (!reason && coarse_seconds() - coarse_start_ >= max_seconds_ && seconds() >= max_seconds_)
    reason = DriverStatus::max_time;
  return reason.has_value();
}

double StopCheck::seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

Result no_work(DriverStatus status, std::string message, const Eigen::VectorXd& x0) {
  Result r;
  r.status = status;
  r.message = std::move(message);
  r.x = x0;
  r.objective = kNan;
  return r;
}

std::string stop_message(DriverStatus s, const DriverOptions& o) {
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%g", o.max_seconds);
  const std::string best = " before converging: the best design so far, not an optimum";
  switch (s) {
    case DriverStatus::max_evaluations:
      return o.library == "ipopt"
                 ? "stopped on the iteration limit (max_iterations " + std::to_string(o.max_iterations) + ")" + best
                 : "stopped on the evaluation limit (max_evaluations " + std::to_string(o.max_evaluations) + ")" + best;
    case DriverStatus::max_time:
      return std::string("stopped on the time limit (max_seconds ") + seconds + " s, wall clock)" + best;
    case DriverStatus::interrupted: return "interrupted by a stop request (SIGINT/SIGTERM)" + best;
    default: return "";
  }
}


Bound::Bound(const Problem& problem, const Objective& objective_named, const std::vector<Constraint>& constraints_named)
    : objective(problem.bind(objective_named)),
      constraints(problem.bind(constraints_named)),
      implicit(problem.bind(problem.implicit_constraints())) {
  wanted.add(objective.id);
  for (const auto& k : constraints) wanted.add(k.id);
  for (const auto& k : implicit) wanted.add(k.id);
}

std::vector<Constraint> Bound::all() const {
  std::vector<Constraint> out = constraints;
  out.insert(out.end(), implicit.begin(), implicit.end());
  return out;
}

Start prepare_start(const Problem& problem, const Bound& b, Eigen::VectorXd& x, Result& result, StopCheck& stop,
                    bool inside_implicit, EvaluationAt* first) {
  MetricSet wanted;  // the objective and the implicit constraints
  wanted.add(b.objective.id);
  for (const auto& k : b.implicit) wanted.add(k.id);
  const bool gradient = first && problem.provides_gradients();
  // Usable: the model can evaluate x, and (when asked) x satisfies the implicit constraints.
  auto usable = [&](const Evaluation& e) {
    return e.ok() && (!inside_implicit || std::none_of(b.implicit.begin(), b.implicit.end(), [&](const auto& k) {
                        return k.g(e[k.id].value) > 0;
                      }));
  };
  // x's evaluation (into `first`, with gradients, when given); a start is
  // judged on the values alone, as without `first`: where only a gradient
  // fails, they are evaluated again without (and the run's first call
  // meets the failed gradient, as it would have).
  EvaluationAt here;
  EvaluationAt& at = first ? *first : here;
  Evaluation values;
  auto evaluate = [&]() -> const Evaluation& {
    at.x = x;
    at.evaluate(problem, wanted, gradient);
    if (at.e.ok() || !gradient) return at.e;
    problem.evaluate(x, wanted, false, values, at.workspace(problem));
    return values;
  };
  Start s;
  const Evaluation* e = &evaluate();
  if (!usable(*e) && problem.provides_gradients()) {  // phase 1 needs the margins' gradients
    const std::string before = e->ok() ? "outside the problem's own constraints" : std::string(mech::to_string(e->status));
    const int used = restore_feasibility(problem, x, stop);
    result.evaluations += used;
    e = &evaluate();
    s.note = "; the start was infeasible (" + before + "), phase 1 " +
             (usable(*e) ? "restored it" : "could not restore it") + " in " + std::to_string(used) +
             " evaluations";
  }
  stop();
  const MetricId f_id = b.objective.id;
  const double f = e->ok() && e->has(f_id) ? std::abs((*e)[f_id].value) : 0.0;
  s.scale = std::isfinite(f) && f > 0 ? f : 1.0;
  return s;
}

void finish(const Problem& problem, const Bound& b, Result& result, const EvaluationAt* last) {
  const std::vector<Constraint>& implicit = b.implicit;
  const std::vector<Constraint>& constraints = b.constraints;
  const Objective& objective = b.objective;
  std::vector<MetricId> ids{objective.id};
  for (const auto& k : constraints) ids.push_back(k.id);
  for (const auto& k : implicit) ids.push_back(k.id);
  const MetricSet& wanted = b.wanted;
  const bool reuse = last && last->x.size() == result.x.size() && last->x == result.x &&
                     (!last->e.ok() || std::all_of(ids.begin(), ids.end(), [&](MetricId i) {
                       return last->e.has(i);
                     }));
  if (!reuse && result.status == DriverStatus::interrupted) {  // no new evaluation after a stop request
    result.objective = kNan;
    result.message += "; the final design was not evaluated again";
    return;
  }
  Evaluation fresh;
  if (!reuse) problem.evaluate(result.x, wanted, false, fresh);
  const Evaluation& e = reuse ? last->e : fresh;
  const bool converged = result.status == DriverStatus::converged;
  if (!e.ok()) {
    if (converged) result.status = DriverStatus::infeasible;
    result.message += "; final design infeasible: " + std::string(mech::to_string(e.status));
    if (result.evaluations > 0 && result.infeasible_evaluations == result.evaluations)
      result.message += "; all " + std::to_string(result.evaluations) + " evaluations were infeasible";
    result.objective = kNan;
    return;
  }
  result.objective = e[objective.id].value;
  bool feasible = true;
  for (const auto& k : constraints) {
    result.constraint_values.push_back(e[k.id].value);
    if (!k.met(e[k.id].value)) {
      feasible = false;
      if (converged) result.status = DriverStatus::infeasible;
      result.message += "; constraint " + k.metric + " violated at the final design";
    }
  }
  for (const auto& k : implicit)
    if (!k.met(e[k.id].value)) {
      feasible = false;
      if (converged) result.status = DriverStatus::infeasible;
      result.message += "; the problem's own constraint " + k.text() + " violated at the final design";
    }
  if (result.status == DriverStatus::infeasible && feasible) {
    // The library said infeasible (Ipopt: its restoration phase failed) at a
    // design that meets every constraint: the library failed, the problem
    // is not shown infeasible.
    result.status = DriverStatus::failure;
    result.message += "; but the final design meets every constraint, so the problem is not shown infeasible";
  }
  if (result.status != DriverStatus::converged) return;
  const bool nlopt = result.library == "nlopt";
  if (nlopt && !algorithm_uses_gradient(result.algorithm)) {
    const std::vector<int> flat = flat_variables(problem, objective, result.x, result.objective);
    std::string names;
    for (int j : flat) names += (names.empty() ? "" : ", ") + problem.variables()[j].name;
    if (!flat.empty() && flat.size() == static_cast<std::size_t>(result.x.size())) {
      result.status = DriverStatus::stopped_on_plateau;
      result.message += "; stopped on a plateau, not at an optimum: " + objective.metric +
                        " does not change when any variable (" + names +
                        ") moves by 0.1% of its range, so the algorithm's steps shrank for want of a better " +
                        "point (does the model use these variables at this level of detail?)";
      return;
    }
    if (!flat.empty())
      result.message += "; " + objective.metric + " does not change with " + names +
                        " here (0.1% of its range either way): the optimum is not unique in it";
  }
  const std::vector<Constraint> all = b.all();
  const auto kink = check_kink(problem, objective, all, result.x);
  if (kink && kink->measure > kKinkTolerance) {
    char measure[32];
    std::snprintf(measure, sizeof measure, "%.2g", kink->measure);
    result.status = DriverStatus::stopped_on_kink;
    result.message += "; stopped on a kink, not at an optimum: " + std::to_string(kink->peaks) + " peaks of " +
                      objective.metric + " over the cycle are equal here and they can still all descend together " +
                      "(stationarity measure " + measure + ", 0 at an optimum); LD_SLSQP, or ipopt with " +
                      "epigraph: true, reach such optima";
    return;
  }
  // A kink that passed is an optimum; a global algorithm's answer is polished,
  // not checked; the line driver ends on a bracket where the derivative turns
  // from falling to rising (or on a bound it falls toward): a minimum by construction.
  if (kink || result.library == "line" || (nlopt && algorithm_is_global(result.algorithm))) return;
  if (const auto slope = check_slope(problem, objective, all, result.x, result.objective, &e)) {
    char text[160];
    std::snprintf(text, sizeof text, "a step of %.2g%% of the variables' ranges takes it from %.10g to %.10g",
                  100 * slope->step, result.objective, slope->value);
    result.status = DriverStatus::stopped_on_slope;
    result.message += "; stopped on a slope, not at an optimum: " + objective.metric + " still " +
                      (objective.maximize ? "rises" : "falls") + " along a direction the bounds and constraints " +
                      "allow (" + text + "); LD_SLSQP or ipopt reach such optima";
  }
}

}  // namespace detail

std::unique_ptr<Driver> make_driver(const DriverOptions& options) {
  std::unique_ptr<Driver> d;
  if (options.library == "ipopt") d = std::make_unique<IpoptDriver>(options);
  else if (options.library == "line") d = std::make_unique<LineDriver>(options);
  else d = std::make_unique<NloptDriver>(options);
  if (options.polish) return std::make_unique<ChainDriver>(std::move(d), make_driver(*options.polish));
  return d;
}

Result ChainDriver::minimize(const Problem& problem, const Objective& objective,
                             const std::vector<Constraint>& constraints,
                             const Eigen::VectorXd& x0) const {
  Result a = first_->minimize(problem, objective, constraints, x0);
  // Never skip the first stage silently, and never start the second after a stop request.
  if (a.status == DriverStatus::invalid_arguments || a.status == DriverStatus::interrupted) return a;
  const bool usable = a.x.size() == x0.size() && problem.evaluate(a.x, MetricSet::all(), false).ok();
  Result b = then_->minimize(problem, objective, constraints, usable ? a.x : x0);
  b.message = a.library + " " + a.algorithm + " (" + std::to_string(a.evaluations) + " evaluations, " +
              to_string(a.status) + "): " + a.message + "; then " + b.library + " " + b.algorithm +
              ": " + b.message;
  b.library = a.library + "+" + b.library;
  b.algorithm = a.algorithm + "+" + b.algorithm;
  b.evaluations += a.evaluations;
  b.infeasible_evaluations += a.infeasible_evaluations;
  b.seconds += a.seconds;
  for (auto& h : b.history) h.evaluation += a.evaluations;
  a.history.insert(a.history.end(), b.history.begin(), b.history.end());
  b.history = std::move(a.history);
  return b;
}

std::string ChainDriver::incompatibility(const Problem& problem, const std::vector<Constraint>& constraints) const {
  if (std::string why = first_->incompatibility(problem, constraints); !why.empty()) return why;
  const std::string why = then_->incompatibility(problem, constraints);
  return why.empty() ? "" : "polish: " + why;
}

}  // namespace opt
