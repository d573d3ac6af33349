#include "mech/drive_dynamics.hpp"

#include <arkode/arkode_erkstep.h>
#include <cvodes/cvodes.h>
#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>

namespace mech {

const char* to_string(DynamicsStatus s) {
  switch (s) {
    case DynamicsStatus::ok: return "ok";
    case DynamicsStatus::too_many_steps: return "too_many_steps";
    case DynamicsStatus::solver_failure: return "solver_failure";
    case DynamicsStatus::stalled: return "stalled";
    case DynamicsStatus::no_periodic_orbit: return "no_periodic_orbit";
  }
  return "unknown";
}

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr int kStall = 1;  // recoverable-error code a right-hand side returns when the crank stops

// SUNDIALS prints its warnings and errors to stderr by default; every outcome
// is a status here, so they are silenced.
void silent(int, const char*, const char*, char*, void*) {}

// One SUNDIALS context per integration (they are cheap and not thread-shared).
struct Context {
  SUNContext ctx = nullptr;
  Context() {
    if (SUNContext_Create(nullptr, &ctx) != 0) throw std::runtime_error("SUNContext_Create failed");
  }
  ~Context() { SUNContext_Free(&ctx); }
};

// y' = f(t, y) with an optional dense Jacobian, on CVODE (BDF, Adams; Newton
// with a dense direct solver) or ARKODE ERKStep (explicit, no Jacobian).
class Integrator {
 public:
  using Rhs = std::function<int(double, const double*, double*)>;
  using Jac = std::function<void(double, const double*, double*)>;  // row-major n x n

  Integrator(int n, Rhs f, Jac j, const OdeOptions& o, double t0, const double* y0)
      : n_(n), f_(std::move(f)), j_(std::move(j)), method_(o.method), max_steps_(o.max_steps) {
    y_ = N_VNew_Serial(n, ctx_.ctx);
    std::copy(y0, y0 + n, N_VGetArrayPointer(y_));
    if (method_ == OdeMethod::erk) {
      mem_ = ERKStepCreate(rhs, t0, y_, ctx_.ctx);
      ERKStepSStolerances(mem_, o.rtol, o.atol);
      ERKStepSetUserData(mem_, this);
      ERKStepSetMaxNumSteps(mem_, o.max_steps);
      ERKStepSetErrHandlerFn(mem_, silent, nullptr);
    } else {
      mem_ = CVodeCreate(method_ == OdeMethod::bdf ? CV_BDF : CV_ADAMS, ctx_.ctx);
      CVodeInit(mem_, rhs, t0, y_);
      CVodeSStolerances(mem_, o.rtol, o.atol);
      CVodeSetUserData(mem_, this);
      CVodeSetMaxNumSteps(mem_, o.max_steps);
      CVodeSetErrHandlerFn(mem_, silent, nullptr);
      A_ = SUNDenseMatrix(n, n, ctx_.ctx);
      LS_ = SUNLinSol_Dense(y_, A_, ctx_.ctx);
      CVodeSetLinearSolver(mem_, LS_, A_);
      if (j_) CVodeSetJacFn(mem_, jac);
    }
  }
  ~Integrator() {
    if (method_ == OdeMethod::erk) ERKStepFree(&mem_);
    else CVodeFree(&mem_);
    if (LS_) SUNLinSolFree(LS_);
    if (A_) SUNMatDestroy(A_);
    N_VDestroy(y_);
  }
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;

  // Advances to t (interpolated output); the state is in y(). max_steps
  // bounds the whole integration, not one call.
  DynamicsStatus advance(double t) {
    const long left = max_steps_ - steps();
    if (left <= 0) return DynamicsStatus::too_many_steps;
    if (method_ == OdeMethod::erk) ERKStepSetMaxNumSteps(mem_, left);
    else CVodeSetMaxNumSteps(mem_, left);
    double reached = 0;
    const int flag = method_ == OdeMethod::erk ? ERKStepEvolve(mem_, t, y_, &reached, ARK_NORMAL)
                                               : CVode(mem_, t, y_, &reached, CV_NORMAL);
    if (flag >= 0) return DynamicsStatus::ok;
    if (stalled_) return DynamicsStatus::stalled;
    if (flag == CV_TOO_MUCH_WORK) return DynamicsStatus::too_many_steps;  // == ARK_TOO_MUCH_WORK
    return DynamicsStatus::solver_failure;
  }
  const double* y() const { return N_VGetArrayPointer(y_); }
  long steps() const {
    long s = 0;
    if (method_ == OdeMethod::erk) ERKStepGetNumSteps(mem_, &s);
    else CVodeGetNumSteps(mem_, &s);
    return s;
  }

 private:
  static int rhs(double t, N_Vector y, N_Vector dy, void* data) {
    auto* self = static_cast<Integrator*>(data);
    const int r = self->f_(t, N_VGetArrayPointer(y), N_VGetArrayPointer(dy));
    if (r == kStall) self->stalled_ = true;
    return r;
  }
  static int jac(double t, N_Vector y, N_Vector, SUNMatrix J, void* data, N_Vector, N_Vector,
                 N_Vector) {
    auto* self = static_cast<Integrator*>(data);
    std::vector<double> m(self->n_ * self->n_);
    self->j_(t, N_VGetArrayPointer(y), m.data());
    for (int r = 0; r < self->n_; ++r)
      for (int c = 0; c < self->n_; ++c) SM_ELEMENT_D(J, r, c) = m[r * self->n_ + c];
    return 0;
  }

  Context ctx_;
  int n_;
  Rhs f_;
  Jac j_;
  OdeMethod method_;
  long max_steps_;
  N_Vector y_ = nullptr;
  void* mem_ = nullptr;
  SUNMatrix A_ = nullptr;
  SUNLinearSolver LS_ = nullptr;
  bool stalled_ = false;
};

// Dense Jacobian of a templated right-hand side g(y, dy) of the first m
// components by forward autodiff (columns m..n-1 of the extended system are
// zero: quadratures do not feed back).
template <int M, class G>
void autodiff_jacobian(int n, const double* y, G&& g, double* J) {
  using D = DualN<M>;
  D yd[M], dd[8];
  for (int i = 0; i < M; ++i) yd[i] = D(y[i], M, i);
  g(yd, dd);
  std::fill(J, J + n * n, 0.0);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < M; ++c) J[r * n + c] = dd[r].derivatives()[c];
}

// The system in the crank angle phi2 as independent variable, over one
// revolution: z = (theta, w1, w2, t, int M dt, int M^2 dt, int P_motor dt,
// int P_res dt). Unknowns of the periodic problem: the first three.
constexpr int kAngleStates = 8;

template <class S>
void angle_rhs(const ElasticDrive& d, double phi2, const S* z, S* dz) {
  const S w1 = z[1], w2 = z[2];
  S y[4] = {S(phi2) + z[0], S(phi2), w1, w2}, dy[4];
  drive_rhs(d, y, dy);
  const S inv = 1.0 / w2;
  dz[0] = (w1 - w2) * inv;
  dz[1] = dy[2] * inv;
  dz[2] = dy[3] * inv;
  dz[3] = inv;
  const S coupling = d.stiffness * z[0] + d.damping * (w1 - w2);
  dz[4] = coupling * inv;
  dz[5] = coupling * coupling * inv;
  dz[6] = d.motor_moment(w1) * w1 * inv;
  dz[7] = mechanism_state(d, S(phi2), w2).resistance;  // P_res dt = M_res w2 dt = M_res dphi2
}

struct Revolution {
  DynamicsStatus status = DynamicsStatus::ok;
  double end[kAngleStates] = {};
  long steps = 0;
};

// Integrates one revolution from (theta, w1, w2); with `out`, samples it.
Revolution revolution(const ElasticDrive& d, const OdeOptions& o, const double* start, int samples,
                      Trajectory* out) {
  double z0[kAngleStates] = {start[0], start[1], start[2], 0, 0, 0, 0, 0};
  if (d.fidelity == DriveFidelity::rigid) z0[0] = 0, z0[1] = z0[2];
  auto f = [&](double phi2, const double* z, double* dz) {
    if (!(z[2] > 1e-3)) return kStall;  // the crank stopped: no motion in phi2
    angle_rhs(d, phi2, z, dz);
    return 0;
  };
  auto j = [&](double phi2, const double* z, double* J) {
    autodiff_jacobian<3>(kAngleStates, z,
                         [&](const DualN<3>* zz, DualN<3>* dz) {
                           DualN<3> full[kAngleStates];
                           for (int i = 0; i < 3; ++i) full[i] = zz[i];
                           for (int i = 3; i < kAngleStates; ++i) full[i] = DualN<3>(z[i]);
                           angle_rhs(d, phi2, full, dz);
                         },
                         J);
  };
  Integrator in(kAngleStates, f, j, o, 0.0, z0);
  Revolution r;
  const int n = out ? samples : 1;
  auto record = [&](double phi2, const double* z) {
    if (!out) return;
    out->phi2.push_back(phi2);
    out->t.push_back(z[3]);
    out->theta.push_back(z[0]);
    out->w1.push_back(z[1]);
    out->w2.push_back(z[2]);
    out->coupling.push_back(coupling_moment(d, z[0], z[1], z[2]));
    out->motor_torque.push_back(d.motor.torque(z[1] * d.gear_ratio));
  };
  record(0.0, z0);
  for (int k = 1; k <= n; ++k) {
    const double phi2 = kTwoPi * k / n;
    r.status = in.advance(phi2);
    if (r.status != DynamicsStatus::ok) break;
    record(phi2, in.y());
  }
  std::copy(in.y(), in.y() + kAngleStates, r.end);
  r.steps = in.steps();
  return r;
}

// Rigid estimate of the steady speed: the motor moment balances the mean
// resistance (bisection on the crank speed below synchronous speed).
double rigid_speed_estimate(const ElasticDrive& d, double* mean_resistance) {
  double mean = 0;
  const int n = 360;
  for (int k = 0; k < n; ++k) mean += mechanism_state(d, kTwoPi * k / n, 1.0).resistance / n;
  *mean_resistance = mean;
  const double w0 = d.motor.synchronous_speed / d.gear_ratio;
  double lo = w0 * (1 - d.motor.critical_slip), hi = w0;  // the stable branch of the motor curve
  for (int i = 0; i < 80; ++i) {
    const double mid = 0.5 * (lo + hi);
    (d.motor_moment(mid) > mean ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Scale of the twist theta: the largest resistance moment over c.
double twist_scale(const ElasticDrive& d) {
  double m = 0;
  for (int k = 0; k < 72; ++k)
    m = std::max(m, std::abs(mechanism_state(d, kTwoPi * k / 72, 1.0).resistance));
  return std::max(m, 1.0) / d.stiffness;
}

// Extremum of periodic samples v (the last equal to the first) refined by the
// parabola through the best sample and its neighbours.
double refined_extremum(const std::vector<double>& v, bool maximum) {
  const int n = static_cast<int>(v.size()) - 1;  // v[n] repeats v[0]
  int k = 0;
  for (int i = 1; i < n; ++i)
    if (maximum ? v[i] > v[k] : v[i] < v[k]) k = i;
  const double a = v[(k + n - 1) % n], b = v[k], c = v[(k + 1) % n];
  const double den = a - 2 * b + c;
  if (den == 0) return b;
  return b - 0.125 * (c - a) * (c - a) / den;
}

void fill_metrics(const ElasticDrive& d, const Revolution& r, SteadyCycle& s) {
  const Trajectory& c = s.cycle;
  s.period = r.end[3];
  s.mean_speed = kTwoPi / s.period;
  s.coupling_rms = std::sqrt(r.end[5] / s.period);
  s.mean_motor_power = r.end[6] / s.period;
  s.mean_resistance_power = r.end[7] / s.period;
  s.coupling_min = refined_extremum(c.coupling, false);
  s.coupling_max = refined_extremum(c.coupling, true);
  s.coupling_peak = std::max(std::abs(s.coupling_min), std::abs(s.coupling_max));
  const auto [wmin, wmax] = std::minmax_element(c.w2.begin(), c.w2.end());
  s.speed_irregularity = (*wmax - *wmin) / s.mean_speed;
  const auto [tmin, tmax] = std::minmax_element(c.motor_torque.begin(), c.motor_torque.end());
  s.motor_torque_min = *tmin;
  s.motor_torque_max = *tmax;
  const auto [mmin, mmax] = std::minmax_element(c.w1.begin(), c.w1.end());
  s.motor_speed_min = *mmin * d.gear_ratio;
  s.motor_speed_max = *mmax * d.gear_ratio;
  // Damping dissipation: k (w1 - w2)^2 averaged over time, by the trapezoidal
  // rule on the samples in phi2 (dt = dphi2 / w2).
  double diss = 0;
  for (size_t i = 1; i < c.t.size(); ++i) {
    const double a = d.damping * std::pow(c.w1[i - 1] - c.w2[i - 1], 2);
    const double b = d.damping * std::pow(c.w1[i] - c.w2[i], 2);
    diss += 0.5 * (a + b) * (c.t[i] - c.t[i - 1]);
  }
  s.mean_damping_power = diss / s.period;
}

struct ShootingData {
  const ElasticDrive* d;
  const OdeOptions* o;
  double scale[3];
  long steps = 0;
  DynamicsStatus failure = DynamicsStatus::ok;
};

int shooting_residual(N_Vector u, N_Vector F, void* data) {
  auto& s = *static_cast<ShootingData*>(data);
  const double* x = N_VGetArrayPointer(u);
  double start[3] = {x[0] * s.scale[0], x[1] * s.scale[1], x[2] * s.scale[2]};
  const Revolution r = revolution(*s.d, *s.o, start, 1, nullptr);
  s.steps += r.steps;
  if (r.status != DynamicsStatus::ok) {
    s.failure = r.status;
    return 1;  // recoverable: KINSOL's line search backs off
  }
  double* f = N_VGetArrayPointer(F);
  for (int i = 0; i < 3; ++i) f[i] = (r.end[i] - start[i]) / s.scale[i];
  return 0;
}

}  // namespace

namespace {
SteadyCycle cycles_from(const ElasticDrive& d, const OdeOptions& o, double* start, int max_cycles,
                        double tol, int samples);
}  // namespace

// The state (theta, w1, w2) where a start-up from rest last crossed a whole
// revolution of the crank; false if it stalled or never turned.
bool startup_guess(const ElasticDrive& d, const OdeOptions& o, double t, double w0,
                   double* guess) {
  const Startup st = simulate_startup(d, o, t, 1e-3, nullptr, w0);
  const Trajectory& tr = st.trajectory;
  if (st.status != DynamicsStatus::ok || tr.phi2.back() < kTwoPi) return false;
  const double target = kTwoPi * std::floor(tr.phi2.back() / kTwoPi);
  size_t i = tr.phi2.size() - 1;
  while (i > 0 && tr.phi2[i - 1] >= target) --i;
  const double a = (target - tr.phi2[i - 1]) / (tr.phi2[i] - tr.phi2[i - 1]);
  guess[0] = tr.theta[i - 1] + a * (tr.theta[i] - tr.theta[i - 1]);
  guess[1] = tr.w1[i - 1] + a * (tr.w1[i] - tr.w1[i - 1]);
  guess[2] = tr.w2[i - 1] + a * (tr.w2[i] - tr.w2[i - 1]);
  return guess[2] > 0;
}

SteadyCycle steady_by_shooting(const ElasticDrive& d, const OdeOptions& o, int samples,
                               double warmup, double initial_speed) {
  SteadyCycle s;
  double mean_res = 0;
  double w = rigid_speed_estimate(d, &mean_res);
  const bool rigid = d.fidelity == DriveFidelity::rigid;
  double guess[3] = {rigid ? 0.0 : mean_res / d.stiffness, w, w};
  if (warmup > 0 && !startup_guess(d, o, warmup, initial_speed, guess)) {
    s.status = DynamicsStatus::stalled;
    s.message = "the start-up did not complete a revolution in " +
                std::to_string(warmup) + " s";
    return s;
  }
  w = guess[2];
  // Unknowns scaled to order one: theta by the twist the largest resistance
  // moment gives, speeds by w.
  const double theta_scale = twist_scale(d);
  ShootingData data{&d, &o, {theta_scale, w, w}};
  Context ctx;
  N_Vector u = N_VNew_Serial(3, ctx.ctx), ones = N_VNew_Serial(3, ctx.ctx);
  double* x = N_VGetArrayPointer(u);
  x[0] = guess[0] / theta_scale;
  x[1] = guess[1] / w;
  x[2] = 1.0;
  N_VConst(1.0, ones);
  void* kin = KINCreate(ctx.ctx);
  KINInit(kin, shooting_residual, u);
  KINSetUserData(kin, &data);
  KINSetErrHandlerFn(kin, silent, nullptr);
  SUNMatrix J = SUNDenseMatrix(3, 3, ctx.ctx);
  SUNLinearSolver LS = SUNLinSol_Dense(u, J, ctx.ctx);
  KINSetLinearSolver(kin, LS, J);
  // The residual carries the integrator's error (~rtol): stop a little above
  // it, and difference the Jacobian with steps well above it.
  KINSetFuncNormTol(kin, 100 * o.rtol);
  KINSetScaledStepTol(kin, o.rtol);
  KINSetRelErrFunc(kin, 10 * o.rtol);
  KINSetNumMaxIters(kin, 50);
  KINSetMaxSetupCalls(kin, 1);  // a fresh Jacobian every iteration (3 x 3)
  int flag = 0;
  if (rigid) {
    // One unknown (w1 = w2, theta = 0): a secant iteration on the speed.
    double a = x[2], b = x[2] * (1.0 + 1e-3), fa = 0, fb = 0;
    auto res = [&](double v) {
      double st[3] = {0, v * w, v * w};
      const Revolution r = revolution(d, o, st, 1, nullptr);
      data.steps += r.steps;
      if (r.status != DynamicsStatus::ok) data.failure = r.status;
      return (r.end[2] - st[2]) / w;
    };
    fa = res(a);
    fb = res(b);
    for (s.iterations = 0; s.iterations < 50 && std::abs(fb) > 100 * o.rtol && fb != fa; ++s.iterations) {
      const double c = b - fb * (b - a) / (fb - fa);
      a = b, fa = fb, b = c, fb = res(b);
    }
    x[0] = 0, x[1] = x[2] = b;
    flag = std::abs(fb) <= 100 * o.rtol ? 0 : -1;
  } else {
    flag = KINSol(kin, u, KIN_LINESEARCH, ones, ones);
    long iters = 0;
    KINGetNumNonlinSolvIters(kin, &iters);
    s.iterations = static_cast<int>(iters);
  }
  double start[3] = {x[0] * theta_scale, x[1] * w, x[2] * w};
  KINFree(&kin);
  SUNLinSolFree(LS);
  SUNMatDestroy(J);
  N_VDestroy(u);
  N_VDestroy(ones);
  s.steps = data.steps;
  if (flag < 0 && data.failure != DynamicsStatus::stalled) {
    // Newton failed (a poor Jacobian near a resonance, or several orbits):
    // fall back to integrating revolution after revolution from the guess,
    // which follows the orbit the machine itself settles on.
    double from[3] = {guess[0], guess[1], guess[2]};
    SteadyCycle c = cycles_from(d, o, from, 300, 100 * o.rtol, samples);
    c.steps += s.steps;
    if (c.status == DynamicsStatus::ok) c.message = "shooting failed; found by integrating revolutions";
    return c;
  }
  if (flag < 0) {
    s.status = data.failure != DynamicsStatus::ok ? data.failure : DynamicsStatus::no_periodic_orbit;
    s.message = std::string("shooting did not converge (") +
                (rigid ? "secant" : "KINSOL flag " + std::to_string(flag)) + ")";
    if (data.failure == DynamicsStatus::stalled) s.status = DynamicsStatus::stalled;
    return s;
  }
  const Revolution r = revolution(d, o, start, samples, &s.cycle);
  s.steps += r.steps;
  if (r.status != DynamicsStatus::ok) {
    s.status = r.status;
    s.message = "the periodic orbit could not be resampled";
    return s;
  }
  s.theta0 = start[0], s.w10 = start[1], s.w20 = start[2];
  s.residual = 0;
  for (int i = 0; i < 3; ++i)
    s.residual = std::max(s.residual, std::abs(r.end[i] - start[i]) / (i == 0 ? theta_scale : w));
  fill_metrics(d, r, s);
  return s;
}

namespace {

// Revolution after revolution from `start` until the state repeats.
SteadyCycle cycles_from(const ElasticDrive& d, const OdeOptions& o, double* start, int max_cycles,
                        double tol, int samples) {
  SteadyCycle s;
  const double w = start[2];
  const double theta_scale = twist_scale(d);
  for (s.iterations = 1; s.iterations <= max_cycles; ++s.iterations) {
    const Revolution r = revolution(d, o, start, 1, nullptr);
    s.steps += r.steps;
    if (r.status != DynamicsStatus::ok) {
      s.status = r.status;
      s.message = "integration failed in revolution " + std::to_string(s.iterations);
      return s;
    }
    double change = 0;
    for (int i = 0; i < 3; ++i)
      change = std::max(change, std::abs(r.end[i] - start[i]) / (i == 0 ? theta_scale : w));
    std::copy(r.end, r.end + 3, start);
    if (change <= tol) {
      const Revolution last = revolution(d, o, start, samples, &s.cycle);
      s.steps += last.steps;
      s.theta0 = start[0], s.w10 = start[1], s.w20 = start[2];
      s.residual = change;
      fill_metrics(d, last, s);
      return s;
    }
  }
  s.status = DynamicsStatus::no_periodic_orbit;
  s.message = "the state still changed after " + std::to_string(max_cycles) + " revolutions";
  return s;
}

}  // namespace

SteadyCycle steady_by_cycles(const ElasticDrive& d, const OdeOptions& o, int max_cycles, double tol,
                             int samples) {
  double mean_res = 0;
  const double w = rigid_speed_estimate(d, &mean_res);
  double start[3] = {d.fidelity == DriveFidelity::rigid ? 0.0 : mean_res / d.stiffness, w, w};
  return cycles_from(d, o, start, max_cycles, tol, samples);
}

Startup simulate_startup(const ElasticDrive& d, const OdeOptions& o, double t_end, double dt_out,
                         const SteadyCycle* steady, double initial_speed) {
  Startup out;
  const double y0[4] = {0, 0, initial_speed, initial_speed};
  auto f = [&](double, const double* y, double* dy) {
    drive_rhs(d, y, dy);
    return 0;
  };
  auto j = [&](double, const double* y, double* J) {
    autodiff_jacobian<4>(4, y, [&](const DualN<4>* yy, DualN<4>* dy) { drive_rhs(d, yy, dy); }, J);
  };
  Integrator in(4, f, j, o, 0.0, y0);
  Trajectory& tr = out.trajectory;
  auto record = [&](double t, const double* y) {
    tr.t.push_back(t);
    tr.phi2.push_back(y[1]);
    tr.theta.push_back(y[0] - y[1]);
    tr.w1.push_back(y[2]);
    tr.w2.push_back(y[3]);
    const double m = d.fidelity == DriveFidelity::rigid ? 0.0 : coupling_moment(d, y[0] - y[1], y[2], y[3]);
    tr.coupling.push_back(m);
    tr.motor_torque.push_back(d.motor.torque(y[2] * d.gear_ratio));
    out.peak_coupling = std::max(out.peak_coupling, std::abs(m));
  };
  record(0, y0);
  const int n = static_cast<int>(std::ceil(t_end / dt_out));
  for (int k = 1; k <= n; ++k) {
    const double t = std::min(t_end, k * dt_out);
    out.status = in.advance(t);
    if (out.status != DynamicsStatus::ok) {
      out.message = std::string("start-up integration stopped at t = ") + std::to_string(tr.t.back());
      break;
    }
    record(t, in.y());
  }
  out.steps = in.steps();
  out.final_speed = tr.w2.back();
  if (steady && steady->status == DynamicsStatus::ok && out.status == DynamicsStatus::ok) {
    // Per revolution peak |coupling| against the steady one: the first
    // revolution from which all stay within 1%.
    std::vector<std::pair<double, double>> revs;  // (start time, peak)
    double peak = 0, start = 0;
    int rev = 0;
    for (size_t i = 0; i < tr.t.size(); ++i) {
      const int r = static_cast<int>(std::floor(tr.phi2[i] / kTwoPi));
      if (r != rev) {
        revs.emplace_back(start, peak);
        rev = r, peak = 0, start = tr.t[i];
      }
      peak = std::max(peak, std::abs(tr.coupling[i]));
    }
    for (size_t i = revs.size(); i-- > 0;) {
      if (std::abs(revs[i].second - steady->coupling_peak) > 0.01 * steady->coupling_peak) {
        out.time_to_steady = i + 1 < revs.size() ? revs[i + 1].first : -1;
        break;
      }
      if (i == 0) out.time_to_steady = 0;
    }
  }
  return out;
}

}  // namespace mech
