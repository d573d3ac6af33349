// NLopt behind the Driver interface (C API: return codes map one to one onto
// DriverStatus). Gradients come from the problem (autodiff), never from finite
// differences. Exceptions thrown inside callbacks are caught at the C boundary,
// the solver is stopped, and the exception is re-thrown after it returns.
#include <nlopt.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <stdexcept>

#include "opt/driver.hpp"

namespace opt {

std::string to_string(DriverStatus s) {
  switch (s) {
    case DriverStatus::converged: return "converged";
    case DriverStatus::max_evaluations: return "max_evaluations";
    case DriverStatus::max_time: return "max_time";
    case DriverStatus::infeasible: return "infeasible";
    case DriverStatus::failure: return "failure";
    case DriverStatus::invalid_arguments: return "invalid_arguments";
  }
  return "unknown";
}

std::vector<std::string> nlopt_algorithms() {
  return {"LN_COBYLA", "LN_BOBYQA",   "LN_NELDERMEAD", "LN_SBPLX",  "LD_SLSQP",
          "LD_MMA",    "LD_CCSAQ",    "LD_LBFGS",      "GN_DIRECT_L", "GN_DIRECT",
          "GN_ISRES",  "G_MLSL_LDS"};
}

bool algorithm_uses_gradient(const std::string& a) { return a.size() > 1 && a[1] == 'D'; }

bool algorithm_is_global(const std::string& a) { return !a.empty() && a[0] == 'G'; }

bool algorithm_supports_constraints(const std::string& a) {
  return a == "LN_COBYLA" || a == "LD_SLSQP" || a == "LD_MMA" || a == "LD_CCSAQ" ||
         a == "GN_ISRES";
}

bool algorithm_supports_equalities(const std::string& a) {
  return a == "LN_COBYLA" || a == "LD_SLSQP" || a == "GN_ISRES";
}

namespace {

struct Context {
  const Problem* problem;
  const Objective* objective;
  double objective_scale;  // the objective is passed to NLopt divided by |f(x0)|
  std::vector<Constraint> constraints;  // user constraints, then implicit ones
  std::vector<std::string> wanted;
  bool record_history;
  // Cache of the last evaluation: NLopt asks for the objective and each
  // constraint at the same x one after the other.
  Eigen::VectorXd last_x;
  bool last_has_gradient = false;
  Evaluation last;
  Result* result;
  nlopt_opt opt;
  std::exception_ptr error;

  const Evaluation& at(unsigned n, const double* x, bool gradient) {
    Eigen::Map<const Eigen::VectorXd> xv(x, n);
    if (last_x.size() == n && last_x == xv && (last_has_gradient || !gradient)) return last;
    last = problem->evaluate(xv, wanted, gradient);
    last_x = xv;
    last_has_gradient = gradient;
    return last;
  }
};

// Objective or constraint value with its gradient; +inf (and a zero gradient)
// where the design is infeasible, so the algorithm steps back.
double metric_value(Context& c, unsigned n, const double* x, double* grad,
                    const std::string& metric, double sign, double shift) {
  const Evaluation& e = c.at(n, x, grad != nullptr);
  const auto it = e.metrics.find(metric);
  if (it == e.metrics.end()) {
    if (grad) std::fill(grad, grad + n, 0.0);
    return std::numeric_limits<double>::infinity();
  }
  if (grad)
    for (unsigned i = 0; i < n; ++i) grad[i] = sign * it->second.gradient[i];
  return sign * it->second.value - shift;
}

double objective_cb(unsigned n, const double* x, double* grad, void* data) {
  auto& c = *static_cast<Context*>(data);
  try {
    const double sign = c.objective->maximize ? -1.0 : 1.0;
    const double f = metric_value(c, n, x, grad, c.objective->metric, sign / c.objective_scale, 0.0);
    Result& r = *c.result;
    ++r.evaluations;
    if (!c.last.ok()) ++r.infeasible_evaluations;
    if (c.record_history)
      r.history.push_back({r.evaluations, c.last.status, Eigen::Map<const Eigen::VectorXd>(x, n),
                           c.last.ok() ? sign * f * c.objective_scale
                                       : std::numeric_limits<double>::quiet_NaN()});
    return f;
  } catch (...) {
    c.error = std::current_exception();
    nlopt_force_stop(c.opt);
    return 0.0;
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
    return metric_value(c, n, x, grad, k.metric, k.upper ? 1.0 : -1.0,
                        k.upper ? k.bound : -k.bound);
  } catch (...) {
    c.error = std::current_exception();
    nlopt_force_stop(c.opt);
    return 0.0;
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

// Phase 1 for a start where the model cannot be evaluated: minimise the
// squared violation of the implicit constraints (defined everywhere, exact
// gradients), each pushed inside by a margin of 1e-3 of its bound's scale,
// with SLSQP inside the bounds. Returns the evaluations it took.
struct Restoration {
  const Problem* problem;
  std::vector<Constraint> constraints;
  std::vector<std::string> wanted;
  int evaluations = 0;
  std::exception_ptr error;
  nlopt_opt opt;
};

double violation_cb(unsigned n, const double* x, double* grad, void* data) {
  auto& r = *static_cast<Restoration*>(data);
  try {
    ++r.evaluations;
    const Evaluation e = r.problem->evaluate(Eigen::Map<const Eigen::VectorXd>(x, n), r.wanted,
                                             grad != nullptr);
    double f = 0;
    if (grad) std::fill(grad, grad + n, 0.0);
    for (const auto& k : r.constraints) {
      const auto& m = e.metrics.at(k.metric);
      const double g = k.g(m.value) + 1e-3 * std::max(1.0, std::abs(k.bound));
      if (g <= 0) continue;
      f += g * g;
      if (grad)
        for (unsigned i = 0; i < n; ++i) grad[i] += 2 * g * (k.upper ? 1.0 : -1.0) * m.gradient[i];
    }
    return f;
  } catch (...) {
    r.error = std::current_exception();
    nlopt_force_stop(r.opt);
    return 0.0;
  }
}

int restore_feasibility(const Problem& problem, Eigen::VectorXd& x) {
  Restoration r{&problem, problem.implicit_constraints(), {}, 0, nullptr, nullptr};
  for (const auto& k : r.constraints) r.wanted.push_back(k.metric);
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

}  // namespace

namespace detail {

std::string restore_start(const Problem& problem, const Objective& objective, Eigen::VectorXd& x,
                          Result& result) {
  const Evaluation e0 = problem.evaluate(x, {objective.metric}, false);
  if (e0.ok() || !problem.provides_gradients()) return "";  // phase 1 needs the margins' gradients
  const int used = restore_feasibility(problem, x);
  result.evaluations += used;
  const bool ok = problem.evaluate(x, {objective.metric}, false).ok();
  return "; the start was infeasible (" + e0.status + "), phase 1 " +
         (ok ? "restored it" : "could not restore it") + " in " + std::to_string(used) +
         " evaluations";
}

double objective_scale(const Problem& problem, const Objective& objective, const Eigen::VectorXd& x) {
  const Evaluation e = problem.evaluate(x, {objective.metric}, false);
  if (!e.ok() || !e.metrics.count(objective.metric)) return 1.0;
  const double f = std::abs(e.at(objective.metric));
  return std::isfinite(f) && f > 0 ? f : 1.0;
}

void finish(const Problem& problem, const Objective& objective,
            const std::vector<Constraint>& constraints, Result& result) {
  std::vector<std::string> wanted{objective.metric};
  for (const auto& k : constraints) wanted.push_back(k.metric);
  const Evaluation e = problem.evaluate(result.x, wanted, false);
  if (!e.ok()) {
    result.status = DriverStatus::infeasible;
    result.message += "; final design infeasible: " + e.status;
    result.objective = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  result.objective = e.at(objective.metric);
  for (const auto& k : constraints) {
    result.constraint_values.push_back(e.at(k.metric));
    if (k.violation(e.at(k.metric)) > 1e-6 * std::max(1.0, std::abs(k.bound)) &&
        result.status == DriverStatus::converged) {
      result.status = DriverStatus::infeasible;
      result.message += "; constraint " + k.metric + " violated at the final design";
    }
  }
}

}  // namespace detail

std::unique_ptr<Driver> make_driver(const DriverOptions& options) {
  std::unique_ptr<Driver> d;
  if (options.library == "ipopt") d = std::make_unique<IpoptDriver>(options);
  else d = std::make_unique<NloptDriver>(options);
  if (options.polish) return std::make_unique<ChainDriver>(std::move(d), make_driver(*options.polish));
  return d;
}

Result ChainDriver::minimize(const Problem& problem, const Objective& objective,
                             const std::vector<Constraint>& constraints,
                             const Eigen::VectorXd& x0) const {
  Result a = first_->minimize(problem, objective, constraints, x0);
  if (a.status == DriverStatus::invalid_arguments) return a;  // never skip the first stage silently
  const bool usable = a.x.size() == x0.size() && problem.evaluate(a.x, {}, false).ok();
  Result b = then_->minimize(problem, objective, constraints, usable ? a.x : x0);
  b.message = a.library + " " + a.algorithm + " (" + std::to_string(a.evaluations) +
              " evaluations): " + a.message + "; then " + b.library + " " + b.algorithm + ": " +
              b.message;
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

Result NloptDriver::minimize(const Problem& problem, const Objective& objective,
                             const std::vector<Constraint>& constraints,
                             const Eigen::VectorXd& x0) const {
  Result result;
  result.library = "nlopt";
  result.algorithm = options_.algorithm;
  const auto start = std::chrono::steady_clock::now();
  const unsigned n = static_cast<unsigned>(x0.size());
  const nlopt_algorithm alg = nlopt_algorithm_from_string(options_.algorithm.c_str());
  if (static_cast<int>(alg) < 0) {
    result.status = DriverStatus::invalid_arguments;
    result.message = "unknown NLopt algorithm '" + options_.algorithm + "'";
    return result;
  }
  const bool constrained_alg = algorithm_supports_constraints(options_.algorithm);
  if ((algorithm_uses_gradient(options_.algorithm) ||
       (options_.algorithm == "G_MLSL_LDS" && algorithm_uses_gradient(options_.local_algorithm))) &&
      !problem.provides_gradients()) {
    result.status = DriverStatus::invalid_arguments;
    result.message = problem.name() + " has no exact gradients; use a derivative-free algorithm (LN_COBYLA, LN_BOBYQA, GN_DIRECT_L, GN_ISRES)";
    return result;
  }
  const bool has_equality = std::any_of(constraints.begin(), constraints.end(),
                                        [](const Constraint& k) { return k.equal; });
  if (has_equality && !algorithm_supports_equalities(options_.algorithm)) {
    result.status = DriverStatus::invalid_arguments;
    result.message = options_.algorithm +
                     " takes no equality constraints; use LD_SLSQP, LN_COBYLA, GN_ISRES or Ipopt";
    return result;
  }
  if (!constraints.empty() && !constrained_alg) {
    result.status = DriverStatus::invalid_arguments;
    result.message = options_.algorithm +
                     " handles bound constraints only; use LN_COBYLA, LD_SLSQP, LD_MMA or "
                     "LD_CCSAQ for metric constraints";
    return result;
  }

  Eigen::VectorXd x = x0;
  const std::string restored = detail::restore_start(problem, objective, x, result);
  const double scale = detail::objective_scale(problem, objective, x);
  Context c{&problem, &objective, scale, constraints, {}, options_.record_history, {}, false, {},
            &result, nullptr, nullptr};
  // Implicit constraints keep the model evaluable; algorithms that take only
  // bounds see an infinite objective there instead.
  if (constrained_alg)
    for (const auto& k : problem.implicit_constraints()) c.constraints.push_back(k);
  c.wanted.push_back(objective.metric);
  for (const auto& k : c.constraints) c.wanted.push_back(k.metric);

  nlopt_opt opt = nlopt_create(alg, n);
  c.opt = opt;
  const Eigen::VectorXd lb = problem.lower_bounds(), ub = problem.upper_bounds();
  nlopt_set_lower_bounds(opt, lb.data());
  nlopt_set_upper_bounds(opt, ub.data());
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
  nlopt_set_maxtime(opt, options_.max_seconds);
  if (options_.algorithm == "G_MLSL_LDS") {  // multistart: local searches from a low-discrepancy sequence
    nlopt_opt local = nlopt_create(nlopt_algorithm_from_string(options_.local_algorithm.c_str()), n);
    nlopt_set_xtol_rel(local, options_.xtol_rel);
    nlopt_set_local_optimizer(opt, local);
    nlopt_destroy(local);  // NLopt keeps its own copy
  }

  nlopt_srand(options_.seed);
  double f = 0;
  const nlopt_result code = nlopt_optimize(opt, x.data(), &f);
  nlopt_destroy(opt);
  if (c.error) std::rethrow_exception(c.error);

  result.status = map_status(code);
  result.message = std::string("NLopt: ") + nlopt_result_to_string(code) + restored;
  result.x = x;
  detail::finish(problem, objective, constraints, result);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace opt
