// Private declarations shared by the drive dynamics (libmech/src/dynamics):
// the SUNDIALS integrator wrapper (integrator.cpp), the periodic steady state
// by shooting (shooting.cpp) and the start-up transient (startup.cpp).
#pragma once
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nonlinearsolver.h>
#include <sundials/sundials_nvector.h>

#include <algorithm>
#include <exception>
#include <functional>
#include <initializer_list>
#include <memory>
#include <numbers>
#include <string>
#include <type_traits>

#include "mech/deadline.hpp"
#include "mech/drive_dynamics.hpp"

namespace mech::dynamics {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr int kStall = 1;  // recoverable-error code a right-hand side returns when the crank stops
constexpr int kMaxStates = 18;  // the largest system integrated (the orbit with its sensitivities)
constexpr int kMaxRhs = 9;      // the most components an autodiff Jacobian differentiates

// SUNDIALS prints its warnings and errors to stderr by default; every outcome
// is a status here, so they are silenced.
void silent(int, const char*, const char*, char*, void*);

// SUNDIALS set-up calls (create, init, set options): a failure (null, or a
// flag other than success) throws std::runtime_error naming the call; the
// public entry points record it as evaluation_error.
void setup(int flag, const char* call);
template <class P>
P setup(P made, const char* call) {
  if (!made) setup(-1, call);
  return made;
}

// Runs the body of a SUNDIALS callback (right-hand side, Jacobian, KINSOL
// residual): no C++ exception may cross the library's C frames, so one is
// kept in `error` and the library gets -1, its unrecoverable-error flag.
// Whoever called the solver rethrows it once the solver has returned
// (Integrator::evolve, newton in shooting.cpp), and the public entry points
// record it as evaluation_error. Calls mech::callback_hook first (tests).
template <class F>
int guarded(const char* callback, std::exception_ptr& error, F&& body) noexcept {
  try {
    if (callback_hook) callback_hook(callback);
    check_deadline();
    return body();
  } catch (...) {
    error = std::current_exception();
    return -1;
  }
}

// check(d), then the options and the run's settings (a time span, a
// tolerance, a count): ok, or invalid_parameter / cannot_assemble with the
// reason in `why`.
Status check_run(const ElasticDrive& d, const OdeOptions& o, std::initializer_list<DomainCheck> settings,
                 std::string& why);

// A public entry point (steady_by_shooting, steady_by_cycles,
// simulate_startup): the inputs checked first, then `body`. An exception
// from it (a failed SUNDIALS set-up, or one a callback kept and its solver's
// caller rethrew) becomes the status evaluation_error with its message, a
// MachineFailure its own status: none leaves libmech.
template <class Result, class F>
Result entry_point(const ElasticDrive& d, const OdeOptions& o, std::initializer_list<DomainCheck> settings,
                   F&& body) {
  Result r;
  try {
    r.status = check_run(d, o, settings, r.message);
    return r.status == Status::ok ? body() : r;
  } catch (const TimedOut& e) {
    r.message = e.what();
    r.status = Status::timed_out;
    return r;
  } catch (const MachineFailure& e) {
    r.message = e.what();
    r.status = e.status;
    return r;
  } catch (const std::exception& e) {
    r.message = e.what();
  } catch (...) {
    r.message = "unknown exception";
  }
  r.status = Status::evaluation_error;
  return r;
}

// Owners of SUNDIALS objects.
template <auto Free>
struct Freed {
  template <class P>
  void operator()(P p) const { Free(p); }
};
inline void free_context(SUNContext c) { SUNContext_Free(&c); }
using Context = std::unique_ptr<std::remove_pointer_t<SUNContext>, Freed<free_context>>;
using Vector = std::unique_ptr<std::remove_pointer_t<N_Vector>, Freed<N_VDestroy>>;
using Matrix = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, Freed<SUNMatDestroy>>;
using LinearSolver = std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, Freed<SUNLinSolFree>>;
using NonlinearSolver = std::unique_ptr<std::remove_pointer_t<SUNNonlinearSolver>, Freed<SUNNonlinSolFree>>;
using Memory = std::unique_ptr<void, void (*)(void*)>;  // CVODE, ARKODE or KINSOL memory

// One SUNDIALS context per integration (they are cheap and not thread-shared).
Context new_context();
// A serial vector of n components (fused operations on), a dense n x n
// matrix, and the dense direct solver of A x = b with x like y.
Vector new_vector(int n, SUNContext ctx);
Matrix new_matrix(int n, SUNContext ctx);
LinearSolver new_dense_solver(N_Vector y, SUNMatrix A, SUNContext ctx);

// y' = f(t, y) with an optional dense Jacobian, on CVODE (BDF, Adams; Newton
// with a dense direct solver) or ARKODE ERKStep (explicit, no Jacobian).
// The extrema the callers want are located on the dense output: no root
// functions.
class Integrator {
 public:
  using Rhs = std::function<int(double, const double*, double*)>;
  using Jac = std::function<void(double, const double*, double*)>;  // row-major n x n

  // atol: one absolute tolerance per component (nullptr: o.atol for all).
  Integrator(int n, Rhs f, Jac j, const OdeOptions& o, double t0, const double* y0,
             const double* atol = nullptr);

  // Advances to t (interpolated output); the state is in y(). max_steps
  // bounds the whole integration, not one call.
  Status advance(double t) { return evolve(t, false); }

  // One internal step, never past `stop`; the state is in y() at time(), and
  // dense() interpolates within the step just taken.
  Status step(double stop);
  void dense(double t, double* out);
  const double* y() const { return y_data_; }
  double time() const { return reached_; }
  long steps() const;

 private:
  Status evolve(double t, bool one_step);
  static int rhs(double t, N_Vector y, N_Vector dy, void* data);
  static int jac(double t, N_Vector y, N_Vector, SUNMatrix J, void* data, N_Vector, N_Vector,
                 N_Vector);

  int n_;
  Rhs f_;
  Jac j_;
  double reached_ = 0;
  OdeMethod method_;
  long max_steps_;
  bool stalled_ = false;
  std::exception_ptr error_;  // from a callback, rethrown by evolve
  // Freed in reverse order: the solver's memory first, the context last.
  Context ctx_;
  Vector y_, atol_, work_;
  double* y_data_ = nullptr;
  Matrix A_;
  LinearSolver LS_;
  NonlinearSolver NLS_;
  Memory mem_{nullptr, nullptr};
};

// Dense Jacobian of a templated right-hand side g(y, dy) of the first M of
// n components by forward autodiff, row-major n x n (columns M..n-1 zero:
// quadratures do not feed back).
template <int M, class G>
void autodiff_jacobian(int n, const double* y, G&& g, double* J) {
  using D = DualN<M>;
  D yd[M], dd[kMaxRhs];
  for (int i = 0; i < M; ++i) yd[i] = D(y[i], M, i);
  g(yd, dd);
  std::fill(J, J + n * n, 0.0);
  for (int r = 0; r < n && r < kMaxRhs; ++r)
    for (int c = 0; c < M; ++c) J[r * n + c] = dd[r].derivatives()[c];
}

// The coupling moment c theta + k (w1 - w2) of a sample (none in the rigid drive).
double sample_coupling(const ElasticDrive& d, double theta, double w1, double w2);

// Appends one sample of a trajectory; returns its coupling moment.
double append(Trajectory& tr, const ElasticDrive& d, double t, double phi2, double theta, double w1,
              double w2);

// The state (theta, w1, w2) where a start-up from `w0` last crossed a whole
// revolution of the crank, upward, within t seconds: ok; stalled if it never
// completed one or turned back below it; or the start-up's own failure.
// `why` says which.
Status startup_guess(const ElasticDrive& d, const OdeOptions& o, double t, double w0, double* guess,
                     std::string& why);

}  // namespace mech::dynamics
