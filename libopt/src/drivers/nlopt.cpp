// NLopt behind the Driver interface (C API: return codes map one to one onto
// DriverStatus): the algorithms mechopt offers and what each takes, the
// callbacks, and phase 1 of every driver's start (restore_feasibility).
// Gradients come from the problem (autodiff), never from finite
// differences. Exceptions thrown inside callbacks are caught at the C
// boundary, the solver is stopped, and the exception is re-thrown after it
// returns.
#include "opt/drivers/nlopt.hpp"

#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <optional>
#include <stdexcept>

#include "core/text.hpp"
#include "opt/stationarity.hpp"

namespace opt {

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// What an NLopt algorithm takes, from NLopt's documentation
// (doc/docs/NLopt_Algorithms.md): derivatives, nonlinear constraints, finite
// bounds (every global algorithm), a least dimension; and NLopt's enum for
// it, since NLopt's own lookup by name (nlopt_algorithm_from_string, a
// compare against each of its ~50 names) cost 0.15 us a run.
struct Algorithm {
  const char* name;
  nlopt_algorithm id;
  bool gradient;    // needs exact gradients
  bool inequality;  // nonlinear inequality constraints
  bool equality;    // nonlinear equality constraints
  bool global;      // global search: needs finite bounds on every variable
  bool random;      // draws from NLopt's random-number generator (then seeded)
  int min_variables;
};

constexpr Algorithm kAlgorithms[] = {
    {"LN_COBYLA", NLOPT_LN_COBYLA, false, true, true, false, false, 1},
    {"LN_BOBYQA", NLOPT_LN_BOBYQA, false, false, false, false, false, 1},
    {"LN_NEWUOA_BOUND", NLOPT_LN_NEWUOA_BOUND, false, false, false, false, false, 2},  // "NEWUOA requires n >= 2"
    {"LN_NELDERMEAD", NLOPT_LN_NELDERMEAD, false, false, false, false, false, 1},
    {"LN_SBPLX", NLOPT_LN_SBPLX, false, false, false, false, false, 1},
    {"LD_SLSQP", NLOPT_LD_SLSQP, true, true, true, false, false, 1},
    {"LD_MMA", NLOPT_LD_MMA, true, true, false, false, false, 1},
    {"LD_CCSAQ", NLOPT_LD_CCSAQ, true, true, false, false, false, 1},
    {"LD_LBFGS", NLOPT_LD_LBFGS, true, false, false, false, false, 1},
    {"GN_DIRECT_L", NLOPT_GN_DIRECT_L, false, false, false, true, false, 1},
    {"GN_DIRECT", NLOPT_GN_DIRECT, false, false, false, true, false, 1},
    {"GN_ISRES", NLOPT_GN_ISRES, false, true, true, true, true, 1},
    // Multistart: bounds only; gradients as its local_algorithm needs them.
    {"G_MLSL_LDS", NLOPT_G_MLSL_LDS, false, false, false, true, true, 1},
};

const Algorithm* find_algorithm(const std::string& name) {
  for (const auto& a : kAlgorithms)
    if (name == a.name) return &a;
  return nullptr;
}

template <class F>
bool has(const std::string& algorithm, F property) {
  const Algorithm* a = find_algorithm(algorithm);
  return a && property(*a);
}

}  // namespace

std::string nlopt_algorithm_incompatibility(const std::string& name, const Problem& p,
                                            const std::vector<Constraint>& constraints) {
  const Algorithm* a = find_algorithm(name);
  if (!a) return "is not an NLopt algorithm mechopt offers (" + text::join(nlopt_algorithms()) + ")";
  if (a->gradient && !p.provides_gradients())
    return "needs exact gradients, and " + p.name() + " has none: it takes derivative-free algorithms only";
  const int n = static_cast<int>(p.variables().size());
  if (n < a->min_variables)
    return "needs at least " + std::to_string(a->min_variables) + " variables, and the problem has " +
           std::to_string(n);
  if (a->global)
    for (const auto& v : p.variables())
      if (!std::isfinite(v.lower) || !std::isfinite(v.upper))
        return "is a global search and needs finite bounds, and " + v.name + " has none";
  for (const auto& k : constraints) {
    if (k.equal && !a->equality) return "takes no equality constraints (" + k.text() + ")";
    if (!k.equal && !a->inequality) return "takes no inequality constraints (" + k.text() + ")";
  }
  return "";
}

std::vector<std::string> nlopt_algorithms() {
  std::vector<std::string> out;
  for (const auto& a : kAlgorithms) out.push_back(a.name);
  return out;
}

bool algorithm_uses_gradient(const std::string& a) {
  return has(a, [](const Algorithm& x) { return x.gradient; });
}
bool algorithm_is_global(const std::string& a) {
  return has(a, [](const Algorithm& x) { return x.global; });
}
bool algorithm_supports_constraints(const std::string& a) {
  return has(a, [](const Algorithm& x) { return x.inequality; });
}
bool algorithm_supports_equalities(const std::string& a) {
  return has(a, [](const Algorithm& x) { return x.equality; });
}

std::string default_algorithm(const Problem& problem) {
  return problem.provides_gradients() ? "LD_SLSQP" : "LN_COBYLA";
}

std::string NloptDriver::incompatibility(const Problem& p, const std::vector<Constraint>& constraints) const {
  const std::string name = options_.algorithm.empty() ? default_algorithm(p) : options_.algorithm;
  if (std::string why = nlopt_algorithm_incompatibility(name, p, constraints); !why.empty())
    return name + " " + why;
  if (name != "G_MLSL_LDS") return "";
  if (algorithm_is_global(options_.local_algorithm))
    return "G_MLSL_LDS needs a local (L*) local_algorithm, not " + options_.local_algorithm;
  // The local searches see the objective and the bounds only.
  if (std::string why = nlopt_algorithm_incompatibility(options_.local_algorithm, p, {}); !why.empty())
    return "G_MLSL_LDS's local_algorithm " + options_.local_algorithm + " " + why;
  return "";
}

namespace {

// The value a callback returns for a design the model cannot evaluate, whose
// metrics are not finite, or (for an algorithm without nonlinear
// constraints) that violates an implicit constraint; its gradient is zero.
// Finite, so that no algorithm's arithmetic meets inf or NaN; far above any
// objective (passed divided by its value at the start) or constraint, so
// every algorithm steps back from it.
constexpr double kInfeasibleValue = 1e30;

struct Context {
  const Problem* problem;
  const Objective* objective;
  double objective_scale;  // the objective is passed to NLopt divided by |f(x0)|
  std::vector<Constraint> constraints;  // user constraints, then implicit ones
  std::vector<Constraint> barrier;      // implicit constraints an algorithm cannot take
  MetricSet wanted;
  bool record_history;
  detail::StopCheck* stop;
  Result* result;
  nlopt_opt opt = nullptr;
  std::exception_ptr error;
  // The last evaluation: NLopt asks for the objective and each constraint at
  // the same x one after the other.
  detail::EvaluationAt last;
  bool last_has_gradient = false;
  bool last_usable = false;  // ok, and inside the barrier
  // A local run stops where the objective's gradient is zero to its
  // roundoff and no constraint is active (stationary_to_roundoff): x there.
  bool watch_gradient = false;
  Eigen::VectorXd lower, upper, range;
  std::optional<Eigen::VectorXd> stationary;
  std::optional<double> first_change;  // the first gradient's largest |g_i| range_i
  double least = std::numeric_limits<double>::infinity();  // the least f at a design inside every constraint
  // The library stepped to a non-finite design (its scaling overflowed:
  // bounds near 1e308), where it would spin to its evaluation limit.
  bool non_finite_step = false;

  // The evaluation at x, or nullptr once the run must stop (the library is
  // then told to stop). The time and the stop request are checked before
  // and after each evaluation: the one under way always finishes.
  const detail::EvaluationAt* at(unsigned n, const double* x, bool gradient) {
    Eigen::Map<const Eigen::VectorXd> xv(x, n);
    if (last.x.size() == n && last.x == xv && (last_has_gradient || !gradient)) return &last;
    if (error || (*stop)() || (non_finite_step = !xv.allFinite())) {
      nlopt_force_stop(opt);
      return nullptr;
    }
    last.x = xv;  // storage reused: no allocation per evaluation
    last.evaluate(*problem, wanted, gradient);  // workspace reused too
    remembered(gradient);
    if ((*stop)()) nlopt_force_stop(opt);
    return &last;
  }
  // `at` the evaluation of the start (prepare_start's), as if just made.
  void remember(detail::EvaluationAt&& at, bool gradient) {
    last = std::move(at);
    remembered(gradient);
  }
  void remembered(bool gradient) {
    last_has_gradient = gradient;
    last_usable = last.e.ok() && std::none_of(barrier.begin(), barrier.end(), [&](const Constraint& k) {
                    return k.g(last.e[k.id].value) > 0;
                  });
  }
};

// Objective or constraint value with its gradient, as `sign * metric - shift`;
// kInfeasibleValue (and a zero gradient) where the run is stopping (`at` is
// null), the design is not usable or a metric is not finite.
double metric_value(const Context& c, const detail::EvaluationAt* at, unsigned n, double* grad,
                    MetricId metric, double sign, double shift) {
  const MetricValue* m = at && c.last_usable && at->e.has(metric) ? &at->e[metric] : nullptr;
  if (!m || !std::isfinite(m->value) || (grad && !(m->gradient.size() == n && m->gradient.allFinite()))) {
    if (grad) std::fill(grad, grad + n, 0.0);
    return kInfeasibleValue;
  }
  if (grad)
    for (unsigned i = 0; i < n; ++i) grad[i] = sign * m->gradient[i];
  return sign * m->value - shift;
}

// NLopt has no test on the gradient, so near a smooth optimum it keeps
// stepping on roundoff until its step tolerance is met: the rod length's
// LD_SLSQP met l* to one ulp at its 10th evaluation and went on to a point
// 1.8e-10 off at its 21st. Stationary to roundoff: each variable free to
// move along -g, over its whole range, would change f by at most
// kRoundoffSlope eps |f| (100 eps: an autodiff gradient that cancels to
// zero keeps roundoff of a few eps |f| / range), nor by more than
// kRoundoffSlope eps of the first gradient's change over the ranges (so
// that an objective far from zero whose variation is small, where the
// gradient still resolves what the value cannot, is not stopped early).
// Where the curvature over the range is of the order of f's variation, x
// is then within about 1e-14 of the range from the optimum. Constraints
// must all be inactive there (the multipliers then are zero, and the point
// is a KKT point), and f no higher than at any design seen inside them: a
// stationary point above one seen is no minimum (LD_CCSAQ stepped from
// 90 deg straight to the phase shift's bound at 180 deg, where the peak
// kinetic energy has a smooth maximum).
constexpr double kRoundoffSlope = 100 * std::numeric_limits<double>::epsilon();
bool stationary_to_roundoff(Context& c, const Evaluation& e, const double* x, const double* grad, double f) {
  double change = 0;  // |g| over the ranges
  for (Eigen::Index i = 0; i < c.range.size(); ++i) change = std::max(change, std::abs(grad[i]) * c.range[i]);
  if (!c.first_change) c.first_change = change;
  if (!(f <= c.least)) return false;
  for (const Constraint& k : c.constraints)
    if (k.active(e[k.id].value)) return false;
  const double limit = kRoundoffSlope * std::min(std::abs(f), *c.first_change);
  for (Eigen::Index i = 0; i < c.range.size(); ++i) {
    if ((x[i] <= c.lower[i] && grad[i] > 0) || (x[i] >= c.upper[i] && grad[i] < 0)) continue;  // held by a bound
    if (!(std::abs(grad[i]) * c.range[i] <= limit)) return false;
  }
  return true;
}

double objective_cb(unsigned n, const double* x, double* grad, void* data) {
  auto& c = *static_cast<Context*>(data);
  try {
    const detail::EvaluationAt* at = c.at(n, x, grad != nullptr);
    const double sign = c.objective->maximize ? -1.0 : 1.0;
    const double f = metric_value(c, at, n, grad, c.objective->id, sign / c.objective_scale, 0.0);
    if (!at) return f;  // stopping: nothing was evaluated
    Result& r = *c.result;
    ++r.evaluations;
    if (!c.last_usable) ++r.infeasible_evaluations;
    if (c.record_history)
      r.history.push_back({r.evaluations, at->e.status, at->x,
                           at->e.ok() ? at->e[c.objective->id].value : kNan});
    if (!c.last_usable || f == kInfeasibleValue) return f;
    if (grad && c.watch_gradient && stationary_to_roundoff(c, at->e, x, grad, f)) {
      c.stationary = at->x;
      nlopt_force_stop(c.opt);
    }
    const bool inside = std::all_of(c.constraints.begin(), c.constraints.end(),
                                    [&](const Constraint& k) { return k.met(at->e[k.id].value); });
    if (inside) c.least = std::min(c.least, f);
    return f;
  } catch (...) {
    c.error = std::current_exception();
    nlopt_force_stop(c.opt);
    return kInfeasibleValue;
  }
}

struct ConstraintData {
  Context* context;
  size_t index;
};

double constraint_cb(unsigned n, const double* x, double* grad, void* data) {
  auto& d = *static_cast<ConstraintData*>(data);
  Context& c = *d.context;
  try {
    const Constraint& k = c.constraints[d.index];
    return metric_value(c, c.at(n, x, grad != nullptr), n, grad, k.id, k.upper ? 1.0 : -1.0,
                        k.upper ? k.bound : -k.bound);
  } catch (...) {
    c.error = std::current_exception();
    nlopt_force_stop(c.opt);
    return kInfeasibleValue;
  }
}

DriverStatus map_status(nlopt_result r) {
  switch (r) {
    case NLOPT_SUCCESS:
    case NLOPT_STOPVAL_REACHED:
    case NLOPT_FTOL_REACHED:
    case NLOPT_XTOL_REACHED: return DriverStatus::converged;
    case NLOPT_MAXEVAL_REACHED: return DriverStatus::max_evaluations;
    case NLOPT_MAXTIME_REACHED: return DriverStatus::max_time;
    case NLOPT_INVALID_ARGS: return DriverStatus::invalid_arguments;
    default: return DriverStatus::failure;  // failure, out of memory, roundoff, forced stop
  }
}

// Phase 1 (detail::restore_feasibility): the implicit constraints are
// defined everywhere and have exact gradients.
struct Restoration {
  const Problem* problem;
  std::vector<Constraint> constraints;
  MetricSet wanted;
  detail::StopCheck* stop;
  int evaluations = 0;
  std::exception_ptr error;
  nlopt_opt opt = nullptr;
  detail::EvaluationAt last;  // the latest evaluation
};

double violation_cb(unsigned n, const double* x, double* grad, void* data) {
  auto& r = *static_cast<Restoration*>(data);
  try {
    if ((*r.stop)()) {
      nlopt_force_stop(r.opt);
      return kInfeasibleValue;
    }
    ++r.evaluations;
    r.last.x = Eigen::Map<const Eigen::VectorXd>(x, n);
    r.last.evaluate(*r.problem, r.wanted, grad != nullptr);  // storage and workspace reused
    const Evaluation& e = r.last.e;
    double f = 0;
    if (grad) std::fill(grad, grad + n, 0.0);
    for (const auto& k : r.constraints) {
      if (!e.has(k.id)) {  // not finite there (see Problem::evaluate): step back
        if (grad) std::fill(grad, grad + n, 0.0);
        return kInfeasibleValue;
      }
      const double g = k.g(e[k.id].value) + 1e-3 * std::max(1.0, std::abs(k.bound));
      if (g <= 0) continue;
      f += g * g;
      if (grad)
        for (unsigned i = 0; i < n; ++i) grad[i] += 2 * g * (k.upper ? 1.0 : -1.0) * e[k.id].gradient[i];
    }
    return f;
  } catch (...) {
    r.error = std::current_exception();
    nlopt_force_stop(r.opt);
    return kInfeasibleValue;
  }
}

}  // namespace

int detail::restore_feasibility(const Problem& problem, Eigen::VectorXd& x, StopCheck& stop) {
  Restoration r{&problem, problem.bind(problem.implicit_constraints()), {}, &stop, 0, nullptr, nullptr, {}};
  for (const auto& k : r.constraints) r.wanted.add(k.id);
  if (r.constraints.empty()) return 0;
  const unsigned n = static_cast<unsigned>(x.size());
  r.opt = nlopt_create(NLOPT_LD_SLSQP, n);
  const Eigen::VectorXd lb = problem.lower_bounds(), ub = problem.upper_bounds();
  nlopt_set_lower_bounds(r.opt, lb.data());
  nlopt_set_upper_bounds(r.opt, ub.data());
  nlopt_set_min_objective(r.opt, violation_cb, &r);
  nlopt_set_stopval(r.opt, 0.0);
  nlopt_set_xtol_rel(r.opt, 1e-12);
  nlopt_set_maxeval(r.opt, 500);
  double f = 0;
  nlopt_optimize(r.opt, x.data(), &f);
  nlopt_destroy(r.opt);
  if (r.error) std::rethrow_exception(r.error);
  return r.evaluations;
}


Result NloptDriver::minimize(const Problem& problem, const Objective& objective,
                             const std::vector<Constraint>& constraints,
                             const Eigen::VectorXd& x0) const {
  detail::StopCheck stop(options_.max_seconds);
  const std::string algorithm = options_.algorithm.empty() ? default_algorithm(problem) : options_.algorithm;
  const std::string why = driver_incompatibility(options_, problem, objective, constraints);
  Result result = detail::no_work(why.empty() ? DriverStatus::failure : DriverStatus::invalid_arguments, why, x0);
  result.library = "nlopt";
  result.algorithm = algorithm;
  if (!why.empty()) return result;

  // Implicit constraints keep the model evaluable: constraints for the
  // algorithms that take them, a barrier (kInfeasibleValue) for the others,
  // which then start inside it.
  const Algorithm& alg = *find_algorithm(algorithm);  // known: driver_incompatibility checked it
  const bool constrained_alg = alg.inequality;
  Eigen::VectorXd x = x0;
  const detail::Bound b(problem, objective, constraints);
  // A gradient algorithm's first call asks for x with gradients: prepare_start
  // makes that evaluation where the run wants no more metrics than it does.
  const bool seed = alg.gradient && b.constraints.empty();
  detail::EvaluationAt first;
  const detail::Start start = detail::prepare_start(problem, b, x, result, stop, !constrained_alg, seed ? &first : nullptr);
  Context c{&problem, &b.objective, start.scale, b.constraints, {}, b.wanted, options_.record_history,
            &stop, &result, nullptr, nullptr, {}, false, false, false, {}, {}, {}, std::nullopt, std::nullopt};
  for (const auto& k : b.implicit) (constrained_alg ? c.constraints : c.barrier).push_back(k);
  if (seed) c.remember(std::move(first), problem.provides_gradients());
  c.watch_gradient = !alg.global;
  c.lower = problem.lower_bounds(), c.upper = problem.upper_bounds();
  c.range = c.upper - c.lower;  // or, where unbounded, the start's size
  for (Eigen::Index i = 0; i < c.range.size(); ++i)
    if (!std::isfinite(c.range[i]) || !(c.range[i] > 0)) c.range[i] = std::max(1.0, std::abs(x0[i]));

  const unsigned n = static_cast<unsigned>(x0.size());
  nlopt_opt opt = nlopt_create(alg.id, n);
  c.opt = opt;
  nlopt_set_lower_bounds(opt, c.lower.data());
  nlopt_set_upper_bounds(opt, c.upper.data());
  nlopt_set_min_objective(opt, objective_cb, &c);
  std::vector<ConstraintData> cdata(c.constraints.size());
  for (size_t i = 0; i < c.constraints.size(); ++i) {
    cdata[i] = {&c, i};
    if (c.constraints[i].equal)
      nlopt_add_equality_constraint(opt, constraint_cb, &cdata[i], options_.constraint_tol);
    else
      nlopt_add_inequality_constraint(opt, constraint_cb, &cdata[i], options_.constraint_tol);
  }
  nlopt_set_xtol_rel(opt, options_.xtol_rel);
  if (options_.ftol_rel > 0) nlopt_set_ftol_rel(opt, options_.ftol_rel);
  nlopt_set_maxeval(opt, options_.max_evaluations);
  // L-BFGS and the other Luksan methods keep this many past steps (NLopt's
  // heuristic keeps up to max_evaluations of them for a few variables:
  // 2000, a 32 kB work array zeroed on every run, more time than the
  // seed-000 rod length's 8 evaluations). 20 is more than SciPy's L-BFGS-B
  // default of 10; a run of 20 steps or fewer takes the same steps.
  nlopt_set_vector_storage(opt, 20);
  // The callbacks check the wall clock around every evaluation. A global
  // algorithm's own work between evaluations (DIRECT's rectangles, MLSL's
  // local searches) can be long, so NLopt's clock watches it as well; a local
  // one's is a few small dense solves, and NLopt's check, a gettimeofday at
  // each of its stop tests (14 a run of the rod length's L-BFGS), would be
  // 6% of that run.
  if (alg.global)
    nlopt_set_maxtime(opt, std::max(options_.max_seconds - stop.seconds(), 1e-9));
  if (alg.id == NLOPT_G_MLSL_LDS) {  // multistart: local searches from a low-discrepancy sequence
    nlopt_opt local = nlopt_create(find_algorithm(options_.local_algorithm)->id, n);
    nlopt_set_xtol_rel(local, options_.xtol_rel);
    nlopt_set_local_optimizer(opt, local);
    nlopt_destroy(local);  // NLopt keeps its own copy
  }

  // Seeding costs about as much as a dozen model evaluations (NLopt's
  // Mersenne twister): only the algorithms that draw random numbers need it.
  if (alg.random) nlopt_srand(options_.seed);
  double f = 0;
  const nlopt_result code = stop.reason ? NLOPT_FORCED_STOP : nlopt_optimize(opt, x.data(), &f);
  nlopt_destroy(opt);
  if (c.error) std::rethrow_exception(c.error);

  result.status = stop.reason ? *stop.reason : c.stationary ? DriverStatus::converged : map_status(code);
  result.message = c.stationary && !stop.reason
                       ? "the objective's gradient is zero to roundoff (mechopt's test; NLopt has none)"
                       : std::string("NLopt: ") + nlopt_result_to_string(code);
  if (c.non_finite_step && !stop.reason)
    result.message = "NLopt stepped to a non-finite design (are the variables' bounds too wide for its scaling?)";
  result.x = c.stationary && !stop.reason ? *c.stationary : x;
  if (code == NLOPT_ROUNDOFF_LIMITED && !stop.reason && !c.stationary && alg.gradient && !alg.global) {
    // NLopt: "the optimization still typically returns a useful result".
    // Where the design meets the constraints and no first-order descent is
    // left, it is a KKT point: SLSQP ends so when its line search cannot
    // move along an active constraint's curve by more than roundoff.
    if (const auto measure = kkt_measure(problem, b.objective, b.all(), result.x);
        measure && *measure <= kKktTolerance) {
      char text[96];
      std::snprintf(text, sizeof text, " at a KKT point (first-order measure %.2g, mechopt's check)", *measure);
      result.status = DriverStatus::converged;
      result.message += text;
    }
  }
  result.message += start.note;
  if (result.stopped()) result.message = detail::stop_message(result.status, options_) + " (" + result.message + ")";
  detail::finish(problem, b, result, &c.last);
  result.seconds = stop.seconds();
  return result;
}

}  // namespace opt
