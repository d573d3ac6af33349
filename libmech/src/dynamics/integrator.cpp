#include <arkode/arkode_erkstep.h>
#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <stdexcept>

#include "internal.hpp"

namespace mech::dynamics {

void silent(int, const char*, const char*, char*, void*) {}

Context::Context() {
  if (SUNContext_Create(nullptr, &ctx) != 0) throw std::runtime_error("SUNContext_Create failed");
}
Context::~Context() { SUNContext_Free(&ctx); }

Integrator::Integrator(int n, Rhs f, Jac j, const OdeOptions& o, double t0, const double* y0,
                       const double* atol)
    : n_(n), f_(std::move(f)), j_(std::move(j)), method_(o.method), max_steps_(o.max_steps) {
  y_ = N_VNew_Serial(n, ctx_.ctx);
  // Fused vector operations: a stage combination is one loop, not a chain
  // of pairwise sums (the per-call overhead dominates on these few states).
  N_VEnableFusedOps_Serial(y_, SUNTRUE);
  y_data_ = N_VGetArrayPointer(y_);
  std::copy(y0, y0 + n, y_data_);
  atol_ = N_VNew_Serial(n, ctx_.ctx);
  work_ = N_VNew_Serial(n, ctx_.ctx);
  if (atol) std::copy(atol, atol + n, N_VGetArrayPointer(atol_));
  else N_VConst(o.atol, atol_);
  if (method_ == OdeMethod::erk) {
    mem_ = ERKStepCreate(rhs, t0, y_, ctx_.ctx);
    ERKStepSVtolerances(mem_, o.rtol, atol_);
    ERKStepSetTableNum(mem_, ARKODE_DORMAND_PRINCE_7_4_5);  // order 5 with a 4th-order error estimate
    ERKStepSetUserData(mem_, this);
    ERKStepSetMaxNumSteps(mem_, o.max_steps);
    ERKStepSetErrHandlerFn(mem_, silent, nullptr);
  } else {
    mem_ = CVodeCreate(method_ == OdeMethod::bdf ? CV_BDF : CV_ADAMS, ctx_.ctx);
    CVodeInit(mem_, rhs, t0, y_);
    CVodeSVtolerances(mem_, o.rtol, atol_);
    CVodeSetUserData(mem_, this);
    CVodeSetMaxNumSteps(mem_, o.max_steps);
    CVodeSetErrHandlerFn(mem_, silent, nullptr);
    if (method_ == OdeMethod::adams) {
      // Adams is for non-stiff motion: functional (fixed-point) iteration,
      // no Jacobian or linear solve (as LSODA does in its non-stiff mode).
      NLS_ = SUNNonlinSol_FixedPoint(y_, 0, ctx_.ctx);
      CVodeSetNonlinearSolver(mem_, NLS_);
    } else {
      A_ = SUNDenseMatrix(n, n, ctx_.ctx);
      LS_ = SUNLinSol_Dense(y_, A_, ctx_.ctx);
      CVodeSetLinearSolver(mem_, LS_, A_);
      if (j_) CVodeSetJacFn(mem_, jac);
    }
  }
}

Integrator::~Integrator() {
  if (method_ == OdeMethod::erk) ERKStepFree(&mem_);
  else CVodeFree(&mem_);
  if (LS_) SUNLinSolFree(LS_);
  if (NLS_) SUNNonlinSolFree(NLS_);
  if (A_) SUNMatDestroy(A_);
  N_VDestroy(y_);
  N_VDestroy(atol_);
  N_VDestroy(work_);
}

Status Integrator::step(double stop) {
  if (method_ == OdeMethod::erk) ERKStepSetStopTime(mem_, stop);
  else CVodeSetStopTime(mem_, stop);
  return evolve(stop, true);
}

void Integrator::dense(double t, double* out) {
  if (method_ == OdeMethod::erk) ERKStepGetDky(mem_, t, 0, work_);
  else CVodeGetDky(mem_, t, 0, work_);
  std::copy(N_VGetArrayPointer(work_), N_VGetArrayPointer(work_) + n_, out);
}

long Integrator::steps() const {
  long s = 0;
  if (method_ == OdeMethod::erk) ERKStepGetNumSteps(mem_, &s);
  else CVodeGetNumSteps(mem_, &s);
  return s;
}

Status Integrator::evolve(double t, bool one_step) {
  const long left = max_steps_ - steps();
  if (left <= 0) return Status::too_many_steps;
  if (method_ == OdeMethod::erk) ERKStepSetMaxNumSteps(mem_, left);
  else CVodeSetMaxNumSteps(mem_, left);
  const int flag = method_ == OdeMethod::erk
                       ? ERKStepEvolve(mem_, t, y_, &reached_, one_step ? ARK_ONE_STEP : ARK_NORMAL)
                       : CVode(mem_, t, y_, &reached_, one_step ? CV_ONE_STEP : CV_NORMAL);
  if (flag >= 0) return Status::ok;
  if (stalled_) return Status::stalled;
  if (flag == CV_TOO_MUCH_WORK) return Status::too_many_steps;  // == ARK_TOO_MUCH_WORK
  return Status::integration_failed;
}

int Integrator::rhs(double t, N_Vector y, N_Vector dy, void* data) {
  auto* self = static_cast<Integrator*>(data);
  const int r = self->f_(t, N_VGetArrayPointer(y), N_VGetArrayPointer(dy));
  if (r == kStall) self->stalled_ = true;
  return r;
}

int Integrator::jac(double t, N_Vector y, N_Vector, SUNMatrix J, void* data, N_Vector, N_Vector,
                    N_Vector) {
  auto* self = static_cast<Integrator*>(data);
  double m[kMaxStates * kMaxStates];
  self->j_(t, N_VGetArrayPointer(y), m);
  for (int r = 0; r < self->n_; ++r)
    for (int c = 0; c < self->n_; ++c) SM_ELEMENT_D(J, r, c) = m[r * self->n_ + c];
  return 0;
}

}  // namespace mech::dynamics
