// The SUNDIALS integrator wrapper: context, CVODE (BDF, Adams) and ARKODE
// ERKStep set-up and options, dense output, and the error handling at the
// library's boundary (checked set-up calls, guarded callbacks).
#include <arkode/arkode_erkstep.h>
#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "internal.hpp"

namespace mech::dynamics {

void silent(int, const char*, const char*, char*, void*) {}

void setup(int flag, const char* call) {
  if (flag != 0)
    throw std::runtime_error(std::string("SUNDIALS set-up failed: ") + call + " returned " +
                             std::to_string(flag));
}

Status check_run(const ElasticDrive& d, const OdeOptions& o, std::initializer_list<DomainCheck> settings,
                 std::string& why) {
  Status s = check(d, &why);
  if (s == Status::ok)
    s = first_invalid({{"ode rtol", o.rtol, o.rtol > 0 && o.rtol < 1},
                       {"ode atol", o.atol, o.atol > 0 && std::isfinite(o.atol)},
                       {"ode max_steps", double(o.max_steps), o.max_steps > 0}},
                      &why);
  return s == Status::ok ? first_invalid(settings, &why) : s;
}

Context new_context() {
  SUNContext c = nullptr;
  setup(SUNContext_Create(nullptr, &c), "SUNContext_Create");
  return Context(c);
}

Vector new_vector(int n, SUNContext ctx) {
  Vector v(setup(N_VNew_Serial(n, ctx), "N_VNew_Serial"));
  // Fused vector operations: a stage combination is one loop, not a chain
  // of pairwise sums (the per-call overhead dominates on these few states).
  setup(N_VEnableFusedOps_Serial(v.get(), SUNTRUE), "N_VEnableFusedOps_Serial");
  return v;
}

Matrix new_matrix(int n, SUNContext ctx) {
  return Matrix(setup(SUNDenseMatrix(n, n, ctx), "SUNDenseMatrix"));
}

LinearSolver new_dense_solver(N_Vector y, SUNMatrix A, SUNContext ctx) {
  return LinearSolver(setup(SUNLinSol_Dense(y, A, ctx), "SUNLinSol_Dense"));
}

Integrator::Integrator(int n, Rhs f, Jac j, const OdeOptions& o, double t0, const double* y0,
                       const double* atol)
    : n_(n), f_(std::move(f)), j_(std::move(j)), method_(o.method), max_steps_(o.max_steps),
      ctx_(new_context()) {
  if (n < 1 || n > kMaxStates) throw std::logic_error("Integrator: " + std::to_string(n) + " states");
  SUNContext ctx = ctx_.get();
  y_ = new_vector(n, ctx);
  atol_ = new_vector(n, ctx);
  work_ = new_vector(n, ctx);
  y_data_ = N_VGetArrayPointer(y_.get());
  std::copy(y0, y0 + n, y_data_);
  if (atol) std::copy(atol, atol + n, N_VGetArrayPointer(atol_.get()));
  else N_VConst(o.atol, atol_.get());
  if (method_ == OdeMethod::erk) {
    mem_ = Memory(setup(ERKStepCreate(rhs, t0, y_.get(), ctx), "ERKStepCreate"),
                  [](void* m) { ERKStepFree(&m); });
    void* m = mem_.get();
    setup(ERKStepSVtolerances(m, o.rtol, atol_.get()), "ERKStepSVtolerances");
    // Order 5 with a 4th-order error estimate.
    setup(ERKStepSetTableNum(m, ARKODE_DORMAND_PRINCE_7_4_5), "ERKStepSetTableNum");
    setup(ERKStepSetUserData(m, this), "ERKStepSetUserData");
    setup(ERKStepSetMaxNumSteps(m, o.max_steps), "ERKStepSetMaxNumSteps");
    setup(ERKStepSetErrHandlerFn(m, silent, nullptr), "ERKStepSetErrHandlerFn");
    return;
  }
  mem_ = Memory(setup(CVodeCreate(method_ == OdeMethod::bdf ? CV_BDF : CV_ADAMS, ctx), "CVodeCreate"),
                [](void* m) { CVodeFree(&m); });
  void* m = mem_.get();
  setup(CVodeInit(m, rhs, t0, y_.get()), "CVodeInit");
  setup(CVodeSVtolerances(m, o.rtol, atol_.get()), "CVodeSVtolerances");
  setup(CVodeSetUserData(m, this), "CVodeSetUserData");
  setup(CVodeSetMaxNumSteps(m, o.max_steps), "CVodeSetMaxNumSteps");
  setup(CVodeSetErrHandlerFn(m, silent, nullptr), "CVodeSetErrHandlerFn");
  if (method_ == OdeMethod::adams) {
    // Adams is for non-stiff motion: functional (fixed-point) iteration,
    // no Jacobian or linear solve (as LSODA does in its non-stiff mode).
    NLS_ = NonlinearSolver(setup(SUNNonlinSol_FixedPoint(y_.get(), 0, ctx), "SUNNonlinSol_FixedPoint"));
    setup(CVodeSetNonlinearSolver(m, NLS_.get()), "CVodeSetNonlinearSolver");
  } else {
    A_ = new_matrix(n, ctx);
    LS_ = new_dense_solver(y_.get(), A_.get(), ctx);
    setup(CVodeSetLinearSolver(m, LS_.get(), A_.get()), "CVodeSetLinearSolver");
    if (j_) setup(CVodeSetJacFn(m, jac), "CVodeSetJacFn");
  }
}

Status Integrator::step(double stop) {
  if (method_ == OdeMethod::erk) setup(ERKStepSetStopTime(mem_.get(), stop), "ERKStepSetStopTime");
  else setup(CVodeSetStopTime(mem_.get(), stop), "CVodeSetStopTime");
  return evolve(stop, true);
}

void Integrator::dense(double t, double* out) {
  if (method_ == OdeMethod::erk) setup(ERKStepGetDky(mem_.get(), t, 0, work_.get()), "ERKStepGetDky");
  else setup(CVodeGetDky(mem_.get(), t, 0, work_.get()), "CVodeGetDky");
  std::copy(N_VGetArrayPointer(work_.get()), N_VGetArrayPointer(work_.get()) + n_, out);
}

long Integrator::steps() const {
  long s = 0;
  if (method_ == OdeMethod::erk) setup(ERKStepGetNumSteps(mem_.get(), &s), "ERKStepGetNumSteps");
  else setup(CVodeGetNumSteps(mem_.get(), &s), "CVodeGetNumSteps");
  return s;
}

Status Integrator::evolve(double t, bool one_step) {
  const long left = max_steps_ - steps();
  if (left <= 0) return Status::too_many_steps;
  void* m = mem_.get();
  if (method_ == OdeMethod::erk) setup(ERKStepSetMaxNumSteps(m, left), "ERKStepSetMaxNumSteps");
  else setup(CVodeSetMaxNumSteps(m, left), "CVodeSetMaxNumSteps");
  const int flag = method_ == OdeMethod::erk
                       ? ERKStepEvolve(m, t, y_.get(), &reached_, one_step ? ARK_ONE_STEP : ARK_NORMAL)
                       : CVode(m, t, y_.get(), &reached_, one_step ? CV_ONE_STEP : CV_NORMAL);
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));  // a callback threw
  if (flag >= 0) return Status::ok;
  if (stalled_) return Status::stalled;
  if (flag == CV_TOO_MUCH_WORK) return Status::too_many_steps;  // == ARK_TOO_MUCH_WORK
  return Status::integration_failed;
}

int Integrator::rhs(double t, N_Vector y, N_Vector dy, void* data) {
  auto* self = static_cast<Integrator*>(data);
  return guarded("rhs", self->error_, [&] {
    const int r = self->f_(t, N_VGetArrayPointer(y), N_VGetArrayPointer(dy));
    if (r == kStall) self->stalled_ = true;
    return r;
  });
}

int Integrator::jac(double t, N_Vector y, N_Vector, SUNMatrix J, void* data, N_Vector, N_Vector,
                    N_Vector) {
  auto* self = static_cast<Integrator*>(data);
  return guarded("jacobian", self->error_, [&] {
    double m[kMaxStates * kMaxStates];
    self->j_(t, N_VGetArrayPointer(y), m);
    for (int r = 0; r < self->n_; ++r)
      for (int c = 0; c < self->n_; ++c) SM_ELEMENT_D(J, r, c) = m[r * self->n_ + c];
    return 0;
  });
}

}  // namespace mech::dynamics
