// One driver interface for every optimisation library: minimise an objective
// metric of a Problem under metric constraints, and report a Result with an
// enum status, never an exception for an optimiser outcome; what every
// driver shares (driver.cpp). The drivers: opt/drivers/nlopt.hpp,
// ipopt.hpp, line.hpp; the checks of a converged run: opt/stationarity.hpp.
#pragma once
#include <Eigen/Core>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "opt/problem.hpp"

namespace opt {

// Only `converged` is a success. The three stops (max_evaluations, max_time,
// interrupted) leave the best design found so far in Result::x, not an
// optimum; the message says which limit stopped the run.
enum class DriverStatus {
  converged,          // a tolerance was met
  max_evaluations,    // stopped on the evaluation (Ipopt: iteration) limit
  max_time,           // stopped on the wall-clock limit max_seconds
  interrupted,        // stopped on a stop request (SIGINT/SIGTERM, opt::stop_requested())
  infeasible,         // finished, but the final design violates a constraint
  failure,            // the library gave up (roundoff, bad derivatives, ...)
  invalid_arguments,  // the driver cannot take the problem (see driver_incompatibility)
  stopped_on_kink,    // met a tolerance where a maximum over the cycle has equal peaks, not at an optimum (check_kink)
  stopped_on_plateau, // a derivative-free algorithm met a tolerance where the objective does not change (flat_variables)
  stopped_on_slope,   // a local algorithm met a tolerance where the objective still falls along a feasible direction (check_slope)
};
// The status as one word, for result files and tables ("max_time", ...).
std::string to_string(DriverStatus s);

struct DriverOptions {
  std::string library = "nlopt";
  // NLopt algorithm; empty: the problem's default (default_algorithm).
  std::string algorithm;
  double xtol_rel = 1e-12;
  double ftol_rel = 0;
  int max_evaluations = 2000;
  double max_seconds = 60;  // wall clock, checked after every evaluation (every library)
  double constraint_tol = 1e-9;
  bool record_history = true;
  // Ipopt
  double tol = 1e-10;         // KKT tolerance
  int max_iterations = 3000;
  int print_level = 0;        // 0 silent .. 12
  bool epigraph = true;       // maxima over the cycle as smooth rows (see drivers/ipopt.cpp)
  // The KKT systems' solver: "dense" (Bunch-Kaufman on the assembled
  // matrix, for mechopt's few-variable problems; drivers/ipopt_dense_solver.cpp) or
  // "mumps" (Ipopt's own).
  std::string linear_solver = "dense";
  // NLopt's random algorithms (GN_ISRES) draw from this seed: runs repeat.
  unsigned long seed = 1;
  // NLopt G_MLSL_LDS: the local algorithm of each search
  std::string local_algorithm = "LD_LBFGS";
  // A local driver run from the first driver's answer (global-then-local).
  std::shared_ptr<const DriverOptions> polish;
  // pagmo (a pareto study's evolutionary front; algorithm nsga2, moead or
  // nspso): the population's size and the generations it evolves, from `seed`.
  int population = 100;
  int generations = 100;
};

struct HistoryRow {
  int evaluation;
  Status status;
  Eigen::VectorXd x;
  double objective;  // NaN when the design was infeasible
};

struct Result {
  DriverStatus status = DriverStatus::failure;
  std::string message;
  Eigen::VectorXd x;  // always sized like x0: the start point when the driver did no work
  double objective = 0;
  std::vector<double> constraint_values;  // metric values of the constraints at x
  int evaluations = 0;
  int infeasible_evaluations = 0;
  int iterations = 0;  // Ipopt's iterations; 0 for libraries that do not count them
  double seconds = 0;
  std::string library, algorithm;
  std::vector<HistoryRow> history;
  // A converged optimum: a tolerance was met at a feasible design.
  bool success() const { return status == DriverStatus::converged; }
  // Stopped by a limit or a stop request before converging: x is the best
  // design found so far (feasible or not: check the constraint values).
  bool stopped() const {
    return status == DriverStatus::max_evaluations || status == DriverStatus::max_time ||
           status == DriverStatus::interrupted;
  }
};

class Driver {
 public:
  virtual ~Driver() = default;
  virtual Result minimize(const Problem& problem, const Objective& objective,
                          const std::vector<Constraint>& constraints,
                          const Eigen::VectorXd& x0) const = 0;
  // Why this driver, as configured, cannot solve the problem under these
  // constraints (derivatives, number of variables, bounds, kinds of
  // constraint), naming itself first; "" when it can. Each driver declares
  // its own (Drake's ProgramAttributesSatisfied); any objective metric is
  // accepted by every driver.
  virtual std::string incompatibility(const Problem& problem,
                                      const std::vector<Constraint>& constraints) const = 0;
};

// A library's driver, configured by DriverOptions (opt/drivers/).
class ConfiguredDriver : public Driver {
 public:
  explicit ConfiguredDriver(DriverOptions options) : options_(std::move(options)) {}

 protected:
  DriverOptions options_;
};

// Can the driver of `options` (and its polish and local algorithm) take this
// problem? "" if so; otherwise one message naming the algorithm, why it
// cannot, and the algorithms that can. Checked before any evaluation: by
// every driver's minimize (status invalid_arguments) and by the config reader.
std::string driver_incompatibility(const DriverOptions& options, const Problem& problem,
                                   const Objective& objective,
                                   const std::vector<Constraint>& constraints);

// Runs `first`, then `then` from first's answer: a global search handing
// over to a local one. Evaluations and time add up; the status is then's.
// A first stage that stopped on its evaluation or time limit still hands its
// best design over (global searches usually end that way); one that was
// refused or interrupted ends the chain with its own status.
class ChainDriver : public Driver {
 public:
  ChainDriver(std::unique_ptr<Driver> first, std::unique_ptr<Driver> then)
      : first_(std::move(first)), then_(std::move(then)) {}
  Result minimize(const Problem& problem, const Objective& objective,
                  const std::vector<Constraint>& constraints,
                  const Eigen::VectorXd& x0) const override;
  // The first stage's reason, else the second's after "polish: ".
  std::string incompatibility(const Problem& problem, const std::vector<Constraint>& constraints) const override;

 private:
  std::unique_ptr<Driver> first_, then_;
};

// The driver for options.library ("nlopt", "ipopt" or "line"), chained to
// options.polish when set.
std::unique_ptr<Driver> make_driver(const DriverOptions& options);

namespace detail {
// Shared by the drivers.

// The wall-clock limit and the stop request, polled by the drivers' callbacks
// around every evaluation: once `reason` is set the driver evaluates no more
// and stops its library (the evaluation under way finishes).
class StopCheck {
 public:
  explicit StopCheck(double max_seconds);
  // True when the run must stop now; sets reason (max_time or interrupted).
  // The time limit is read from a coarse clock (a few ms a tick) and
  // confirmed on the precise one: a run never stops before max_seconds.
  bool operator()();
  double seconds() const;  // since the start, precise
  std::optional<DriverStatus> reason;

 private:
  std::chrono::steady_clock::time_point start_;
  double coarse_start_;
  double max_seconds_;
};

// An evaluation with its design, so that the final report can reuse it, and
// the workspace of the evaluations into it: a run's evaluations reuse both.
struct EvaluationAt {
  Eigen::VectorXd x;
  Evaluation e;
  // e = the problem's evaluation at x, into e's storage, with the kept
  // workspace (made on the first call, and again for another problem).
  void evaluate(const Problem& problem, const MetricSet& wanted, bool gradient) {
    problem.evaluate(x, wanted, gradient, e, workspace(problem));
  }
  // The kept workspace (made as by evaluate), for another evaluation of the
  // same problem into other storage.
  Workspace& workspace(const Problem& problem) {
    if (!ws || of != &problem) ws = problem.make_workspace(), of = &problem;
    return *ws;
  }

 private:
  std::unique_ptr<Workspace> ws;
  const Problem* of = nullptr;
};

// A run's objective and constraints with their metric ids, bound once a run
// (std::invalid_argument naming an unknown metric): the user's constraints,
// the problem's own (implicit) ones, and every metric the three need.
struct Bound {
  Bound(const Problem& problem, const Objective& objective, const std::vector<Constraint>& constraints);
  std::vector<Constraint> all() const;  // the user's, then the implicit ones
  Objective objective;
  std::vector<Constraint> constraints, implicit;
  MetricSet wanted;
};

// The start of a run, from one evaluation at x. If the model cannot be
// evaluated there (or, with inside_implicit, x violates an implicit
// constraint), x moves into the region of the implicit constraints (phase 1:
// SLSQP on their squared violation) and `note` says so. `scale` is
// |f(x)| of the objective (1 if not finite or zero): the drivers pass the
// objective divided by it, since SLSQP in particular fails on badly scaled
// objectives (a peak moment of 1.5e5 N m stops it at its first step).
// That evaluation is of the objective and the implicit constraints; with
// `first`, it has their gradients where the problem has them and is left
// there (at the start x) for the driver's first call, which then costs
// nothing.
struct Start {
  std::string note;
  double scale = 1;
};
Start prepare_start(const Problem& problem, const Bound& bound, Eigen::VectorXd& x, Result& result,
                    StopCheck& stop, bool inside_implicit = false, EvaluationAt* first = nullptr);

// The final report at result.x: the objective and constraint values, status
// `infeasible` when a converged run ends at a design that violates a
// constraint (the problem's implicit ones included) or that the model cannot
// evaluate. Reuses `last` when it was evaluated at result.x; an interrupted
// run evaluates nothing more (its objective is then NaN).
void finish(const Problem& problem, const Bound& bound, Result& result, const EvaluationAt* last = nullptr);

// A result that did no work: the start point, a NaN objective, a status.
Result no_work(DriverStatus status, std::string message, const Eigen::VectorXd& x0);

// The message of a run that stopped before converging: which limit, and that
// x is the best design so far rather than an optimum.
std::string stop_message(DriverStatus s, const DriverOptions& options);

// Phase 1 (prepare_start): moves x into the region of the problem's implicit
// constraints by SLSQP on their squared violation, each pushed inside by a
// margin of 1e-3 of its bound's scale, within the bounds; returns the
// evaluations it took (drivers/nlopt.cpp).
int restore_feasibility(const Problem& problem, Eigen::VectorXd& x, StopCheck& stop);
}  // namespace detail

}  // namespace opt
