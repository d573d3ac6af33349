// One driver interface for every optimisation library: minimise an objective
// metric of a Problem under metric constraints, and report a Result with an
// enum status, never an exception for an optimiser outcome.
#pragma once
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "opt/problem.hpp"

namespace opt {

enum class DriverStatus {
  converged,          // a tolerance was met
  max_evaluations,    // stopped on the evaluation limit
  max_time,           // stopped on the time limit
  infeasible,         // finished, but the final design violates a constraint
  failure,            // the library gave up (roundoff, bad derivatives, ...)
  invalid_arguments,  // the library rejected the set-up (e.g. algorithm vs constraints)
};
std::string to_string(DriverStatus s);

struct DriverOptions {
  std::string library = "nlopt";
  std::string algorithm = "LD_SLSQP";
  double xtol_rel = 1e-12;
  double ftol_rel = 0;
  int max_evaluations = 2000;
  double max_seconds = 60;
  double constraint_tol = 1e-9;
  bool record_history = true;
  // Ipopt
  double tol = 1e-10;         // KKT tolerance
  int max_iterations = 3000;
  int print_level = 0;        // 0 silent .. 12
  bool epigraph = true;       // maxima over the cycle as smooth rows (see ipopt_driver.cpp)
  // NLopt's random algorithms (GN_ISRES) draw from this seed: runs repeat.
  unsigned long seed = 1;
  // NLopt G_MLSL_LDS: the local algorithm of each search
  std::string local_algorithm = "LD_LBFGS";
  // A local driver run from the first driver's answer (global-then-local).
  std::shared_ptr<const DriverOptions> polish;
};

struct HistoryRow {
  int evaluation;
  std::string status;
  Eigen::VectorXd x;
  double objective;  // NaN when the design was infeasible
};

struct Result {
  DriverStatus status = DriverStatus::failure;
  std::string message;
  Eigen::VectorXd x;
  double objective = 0;
  std::vector<double> constraint_values;  // metric values of the constraints at x
  int evaluations = 0;
  int infeasible_evaluations = 0;
  double seconds = 0;
  std::string library, algorithm;
  std::vector<HistoryRow> history;
  bool success() const {
    return status == DriverStatus::converged || status == DriverStatus::max_evaluations ||
           status == DriverStatus::max_time;
  }
};

class Driver {
 public:
  virtual ~Driver() = default;
  virtual Result minimize(const Problem& problem, const Objective& objective,
                          const std::vector<Constraint>& constraints,
                          const Eigen::VectorXd& x0) const = 0;
};

// The algorithms a library offers, for help text and config checks.
std::vector<std::string> nlopt_algorithms();
bool algorithm_uses_gradient(const std::string& algorithm);
bool algorithm_is_global(const std::string& algorithm);
bool algorithm_supports_constraints(const std::string& algorithm);
bool algorithm_supports_equalities(const std::string& algorithm);

class NloptDriver : public Driver {
 public:
  explicit NloptDriver(DriverOptions options) : options_(std::move(options)) {}
  Result minimize(const Problem& problem, const Objective& objective,
                  const std::vector<Constraint>& constraints,
                  const Eigen::VectorXd& x0) const override;

 private:
  DriverOptions options_;
};

class IpoptDriver : public Driver {
 public:
  explicit IpoptDriver(DriverOptions options) : options_(std::move(options)) {}
  Result minimize(const Problem& problem, const Objective& objective,
                  const std::vector<Constraint>& constraints,
                  const Eigen::VectorXd& x0) const override;

 private:
  DriverOptions options_;
};

// Runs `first`, then `then` from first's answer: a global search handing
// over to a local one. Evaluations and time add up; the status is then's.
class ChainDriver : public Driver {
 public:
  ChainDriver(std::unique_ptr<Driver> first, std::unique_ptr<Driver> then)
      : first_(std::move(first)), then_(std::move(then)) {}
  Result minimize(const Problem& problem, const Objective& objective,
                  const std::vector<Constraint>& constraints,
                  const Eigen::VectorXd& x0) const override;

 private:
  std::unique_ptr<Driver> first_, then_;
};

// The driver for options.library ("nlopt" or "ipopt"), chained to
// options.polish when set.
std::unique_ptr<Driver> make_driver(const DriverOptions& options);

namespace detail {
// Shared by the drivers. restore_start: if the model cannot be evaluated at
// x, moves x into the region of the implicit constraints (phase 1, SLSQP on
// their squared violation); returns a note for the message. finish: the
// final evaluation at result.x, the objective and constraint values, and the
// status `infeasible` when the final design violates a constraint.
std::string restore_start(const Problem& problem, const Objective& objective, Eigen::VectorXd& x,
                          Result& result);
void finish(const Problem& problem, const Objective& objective,
            const std::vector<Constraint>& constraints, Result& result);
// |f(x)| of the objective (1 if not finite or zero): the drivers pass the
// objective divided by it, since SLSQP in particular fails on badly scaled
// objectives (a peak moment of 1.5e5 N m stops it at its first step).
double objective_scale(const Problem& problem, const Objective& objective, const Eigen::VectorXd& x);
}  // namespace detail

}  // namespace opt
