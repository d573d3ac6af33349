// One variable, bounds only, exact derivative (`library: line`): from the
// start, downhill to the bound or to a sign change of the derivative, which
// Brent's method then refines to xtol_rel. A handful of evaluations where a
// general method spends dozens; a local method, like the others: of several
// minima it finds the one downhill from the start.
#include "opt/drivers/line.hpp"

#include <cmath>
#include <limits>

#include "mech/cycle.hpp"

namespace opt {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// Thrown out of Brent's search when a limit, a stop request or an
// evaluation the model refuses ends the run.
struct Ended {
  DriverStatus status;
  std::string message;
};

}  // namespace

std::string LineDriver::incompatibility(const Problem& p, const std::vector<Constraint>& constraints) const {
  if (p.variables().size() != 1)
    return "line takes one variable, and the problem has " + std::to_string(p.variables().size());
  if (!p.provides_gradients()) return "line needs an exact derivative, and " + p.name() + " has none";
  if (!std::isfinite(p.variables()[0].lower) || !std::isfinite(p.variables()[0].upper))
    return "line needs finite bounds, and " + p.variables()[0].name + " has none";
  if (!constraints.empty()) return "line takes no constraints (" + constraints[0].text() + ")";
  return "";
}

Result LineDriver::minimize(const Problem& problem, const Objective& objective,
                            const std::vector<Constraint>& constraints, const Eigen::VectorXd& x0) const {
  detail::StopCheck stop(options_.max_seconds);
  const std::string why = driver_incompatibility(options_, problem, objective, constraints);
  Result result = detail::no_work(why.empty() ? DriverStatus::failure : DriverStatus::invalid_arguments, why, x0);
  result.library = "line";
  result.algorithm = "Brent on the derivative";
  if (!why.empty()) return result;
  const detail::Bound b(problem, objective, constraints);
  const Objective& f = b.objective;
  MetricSet wanted;
  wanted.add(f.id);
  const double sign = objective.maximize ? -1.0 : 1.0;
  const double lo = problem.lower_bounds()[0], hi = problem.upper_bounds()[0];
  detail::EvaluationAt last;
  double best_x = kNan, best_f = HUGE_VAL;
  // The derivative of the minimised function (sign x objective) at x.
  auto slope = [&](double x) {
    if (stop()) throw Ended{*stop.reason, detail::stop_message(*stop.reason, options_)};
    if (result.evaluations >= options_.max_evaluations)
      throw Ended{DriverStatus::max_evaluations, detail::stop_message(DriverStatus::max_evaluations, options_)};
    last.x = Eigen::VectorXd::Constant(1, x);
    last.evaluate(problem, wanted, true);  // storage and workspace reused
    ++result.evaluations;
    const bool ok = last.e.ok() && last.e.has(f.id);
    if (options_.record_history)
      result.history.push_back({result.evaluations, last.e.status, last.x, ok ? last.e[f.id].value : kNan});
    if (!ok) {
      ++result.infeasible_evaluations;
      throw Ended{DriverStatus::failure, "the model cannot be evaluated at " + std::to_string(x) + " (" +
                                             std::string(mech::to_string(last.e.status)) + ")"};
    }
    if (sign * last.e[f.id].value < best_f) best_f = sign * last.e[f.id].value, best_x = x;
    return sign * last.e[f.id].gradient[0];
  };
  const double x_start = std::clamp(x0[0], lo, hi);
  try {
    const double s0 = slope(x_start);
    result.x = last.x;
    if (s0 == 0) {
      result.status = DriverStatus::converged;
      result.message = "line: the derivative is zero at the start";
    } else {
      const double end = s0 < 0 ? hi : lo;  // downhill
      const double s_end = end == x_start ? s0 : slope(end);
      if (end == x_start || (s_end < 0) == (s0 < 0)) {  // still downhill at the bound
        result.x = Eigen::VectorXd::Constant(1, end);
        result.status = DriverStatus::converged;
        result.message = "line: the optimum is on the bound (the derivative keeps its sign up to it)";
      } else {
        const double x = mech::brent_root(slope, x_start, end, s0, s_end, 200, std::max(options_.xtol_rel, 4.4e-16));
        result.x = Eigen::VectorXd::Constant(1, x);
        result.status = DriverStatus::converged;
        result.message = "line: the derivative's sign change refined to xtol_rel";
        // Brent ends on its last evaluation: reuse it (finish() does too).
        // Values by the same path as the designs seen (with the gradient:
        // a model may sum in another order without it), and "lower" by more
        // than their roundoff.
        const double at_x = last.x[0] == x ? last.e[f.id].value : problem.evaluate(result.x, wanted, true)[f.id].value;
        if (best_f < sign * at_x - 1e-13 * std::abs(at_x)) {
          result.x = Eigen::VectorXd::Constant(1, best_x);  // a stationary point above a design seen: not a minimum
          result.status = DriverStatus::failure;
          result.message = "line: the derivative's zero is not a minimum (a design seen is lower); the best design seen";
        }
      }
    }
  } catch (const Ended& e) {
    result.status = e.status;
    result.message = e.message;
    result.x = std::isfinite(best_x) ? Eigen::VectorXd::Constant(1, best_x) : Eigen::VectorXd::Constant(1, x_start);
  }
  detail::finish(problem, b, result, &last);
  result.seconds = stop.seconds();
  return result;
}

}  // namespace opt
