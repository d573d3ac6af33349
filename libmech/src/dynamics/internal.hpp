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
#include <functional>
#include <numbers>

#include "mech/drive_dynamics.hpp"

namespace mech::dynamics {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr int kStall = 1;  // recoverable-error code a right-hand side returns when the crank stops
constexpr int kMaxStates = 18;  // the largest system integrated (the orbit with its sensitivities)
constexpr int kMaxRhs = 9;      // the most components an autodiff Jacobian differentiates

// SUNDIALS prints its warnings and errors to stderr by default; every outcome
// is a status here, so they are silenced.
void silent(int, const char*, const char*, char*, void*);

// One SUNDIALS context per integration (they are cheap and not thread-shared).
struct Context {
  SUNContext ctx = nullptr;
  Context();
  ~Context();
};

// y' = f(t, y) with an optional dense Jacobian, on CVODE (BDF, Adams; Newton
// with a dense direct solver) or ARKODE ERKStep (explicit, no Jacobian).
class Integrator {
 public:
  using Rhs = std::function<int(double, const double*, double*)>;
  using Jac = std::function<void(double, const double*, double*)>;  // row-major n x n

  // atol: one absolute tolerance per component (nullptr: o.atol for all).
  Integrator(int n, Rhs f, Jac j, const OdeOptions& o, double t0, const double* y0,
             const double* atol = nullptr);
  ~Integrator();
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;

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

  Context ctx_;
  int n_;
  Rhs f_;
  Jac j_;
  double reached_ = 0;
  OdeMethod method_;
  long max_steps_;
  N_Vector y_ = nullptr, atol_ = nullptr, work_ = nullptr;
  double* y_data_ = nullptr;
  void* mem_ = nullptr;
  SUNMatrix A_ = nullptr;
  SUNLinearSolver LS_ = nullptr;
  SUNNonlinearSolver NLS_ = nullptr;
  bool stalled_ = false;
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

// Appends one sample of a trajectory; returns its coupling moment (none in
// the rigid drive).
double append(Trajectory& tr, const ElasticDrive& d, double t, double phi2, double theta, double w1,
              double w2);

// The state (theta, w1, w2) where a start-up from `w0` last crossed a whole
// revolution of the crank after t seconds; false if it stalled or never turned.
bool startup_guess(const ElasticDrive& d, const OdeOptions& o, double t, double w0,
                   double* guess);

}  // namespace mech::dynamics
