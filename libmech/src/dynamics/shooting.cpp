// The periodic steady state of the elastic drive: one revolution integrated
// in the crank angle (quadratures, extrema by root finding, variational
// equations), shooting on it with KINSOL, its Floquet multipliers, and
// revolution after revolution as the fallback.
#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>
#include <utility>

#include "internal.hpp"

namespace mech {
namespace dynamics {
namespace {

// The periodicity residual of a revolution carries the revolution's global
// integration error, measured at 10-400 rtol on these drives (scaled states):
// Newton aims at kPeriodicTol rtol and, where that noise stops its line
// search, accepts kNoiseTol rtol (the start is then as good as the
// integration that defines it).
constexpr double kPeriodicTol = 100, kNoiseTol = 1000;

// The system in the crank angle phi2 as the independent variable, over one
// revolution: z = (theta, w1, w2 | t, int M dt, int M^2 dt, int P_motor dt,
// int P_res dt, int P_damping dt | S), where M is the coupling moment and S
// (optional, row-major 3 x 3) the sensitivity d z(phi2) / d z(0) of the
// first three: the variational equations S' = (df/dz) S, integrated with the
// orbit so that one revolution gives both the shooting residual and its exact
// Jacobian (the monodromy matrix S(2 pi) - I).
constexpr int kOrbit = 3, kQuadratures = 6, kPlain = kOrbit + kQuadratures;
constexpr int kSensitive = kPlain + kOrbit * kOrbit;

// dz = f(phi2, z) for the orbit and (with `quadratures`) the quadratures:
// reads z[0..2] only.
template <class S>
void angle_rhs(const ElasticDrive& d, const PhaseRotation& shift, double phi2, const S* z, S* dz,
               bool quadratures = true) {
  const S theta = z[0], w1 = z[1], w2 = z[2];
  const auto m = mechanism_state(d, S(phi2), w2, shift);
  S a1, a2;
  const S drive = accelerations(d, m, theta, w1, w2, a1, a2);
  const S inv = 1.0 / w2, slip = w1 - w2;
  dz[0] = slip * inv;
  dz[1] = a1 * inv;
  dz[2] = a2 * inv;
  if (!quadratures) return;
  const S coupling = coupling_moment(d, theta, w1, w2);
  dz[3] = inv;
  dz[4] = coupling * inv;
  dz[5] = coupling * coupling * inv;
  dz[6] = drive * w1 * inv;
  dz[7] = m.resistance;  // P_res dt = M_res w2 dt = M_res dphi2
  dz[8] = d.damping * slip * slip * inv;
}

// Right-hand side with the variational equations: one evaluation in DualN<3>
// whose derivative parts carry the rows of S gives f and (df/dz) S together.
void sensitive_rhs(const ElasticDrive& d, const PhaseRotation& shift, double phi2, const double* z,
                   double* dz) {
  using D = DualN<kOrbit>;
  D zz[kPlain], dd[kPlain];
  for (int i = 0; i < kPlain; ++i) zz[i] = D(z[i]);
  for (int i = 0; i < kOrbit; ++i)
    zz[i].derivatives() << z[kPlain + 3 * i], z[kPlain + 3 * i + 1], z[kPlain + 3 * i + 2];
  angle_rhs(d, shift, phi2, zz, dd);
  for (int i = 0; i < kPlain; ++i) dz[i] = dd[i].value();
  for (int i = 0; i < kOrbit; ++i)
    for (int j = 0; j < kOrbit; ++j) dz[kPlain + 3 * i + j] = dd[i].derivatives()[j];
}

// Smallest and largest value seen.
struct Range {
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  void add(double v) { lo = std::min(lo, v), hi = std::max(hi, v); }
};

struct Revolution {
  Status status = Status::ok;
  double end[kSensitive] = {};  // z at phi2 = 2 pi (quadratures unless bare, S with sensitivities)
  Range coupling, w1, w2;       // over the revolution: at its ends and interior extrema
  long steps = 0;
};

// What a revolution records besides its end state.
struct Record {
  bool extrema = true;          // the ranges of the coupling moment and both speeds
  bool sensitivities = false;   // S(2 pi)
  int samples = 0;              // samples of the trajectory into `out`, at equal steps of phi2
  Trajectory* out = nullptr;
};

// Integrates one revolution from (theta, w1, w2), recording what `rec` asks.
// The absolute tolerance is o.atol times each state's `scale` (twist, speeds).
// The extrema of the coupling moment and both speeds are roots of their
// slopes, located on the integrator's dense output step by step: exact to
// the integration's accuracy, with no sampling.
Revolution revolution(const ElasticDrive& d, const OdeOptions& o, const double* scale,
                      const double* start, const Record& rec) {
  const bool sensitivities = rec.sensitivities;
  Trajectory* out = rec.out;
  // Only the orbit's three states when nothing but the end is wanted.
  const bool bare = !rec.extrema && !out && !sensitivities;
  const int n = sensitivities ? kSensitive : bare ? kOrbit : kPlain;
  const PhaseRotation shift(d.phase_shift);
  double z0[kSensitive] = {start[0], start[1], start[2]};
  for (int i = 0; i < kOrbit; ++i) z0[kPlain + 4 * i] = 1.0;  // S(0) = I
  auto f = [&](double phi2, const double* z, double* dz) {
    if (!(z[2] > 1e-3)) return kStall;  // the crank stopped: no motion in phi2
    if (sensitivities) sensitive_rhs(d, shift, phi2, z, dz);
    else angle_rhs(d, shift, phi2, z, dz, !bare);
    return 0;
  };
  // Newton matrix of the implicit methods: df/dz of the orbit and the
  // quadratures, and the same 3 x 3 block on each column of S (the second
  // derivatives left out: they only slow the corrector, never the answer).
  // The right-hand side reads only the orbit's states (nothing feeds back),
  // so only they are differentiated, and the quadratures' rows exist only
  // when they are integrated (n > 3): z has n components, no more.
  auto j = [&](double phi2, const double* z, double* J) {
    autodiff_jacobian<kOrbit>(
        n, z,
        [&](const DualN<kOrbit>* zz, DualN<kOrbit>* dz) { angle_rhs(d, shift, phi2, zz, dz, n > kOrbit); },
        J);
    for (int c = 0; c < (sensitivities ? kOrbit : 0); ++c)  // column c of S: rows kPlain + 3 i + c
      for (int i = 0; i < kOrbit; ++i)
        for (int k = 0; k < kOrbit; ++k) J[(kPlain + 3 * i + c) * n + kPlain + 3 * k + c] = J[i * n + k];
  };
  // Only the orbit's own error sets the steps: the quadratures (as CVODES
  // does by default) and S (it only steers Newton) are left out of the
  // error test by a huge absolute tolerance. The test's RMS norm averages
  // over all n components, so the tolerances shrink by sqrt(3 / n) to keep
  // the orbit's own.
  const double shrink = std::sqrt(static_cast<double>(kOrbit) / n);
  OdeOptions tight = o;
  tight.rtol *= shrink;
  double atol[kSensitive];
  std::fill(atol, atol + n, 1e30);
  for (int i = 0; i < kOrbit; ++i) atol[i] = o.atol * scale[i] * shrink;
  Integrator in(n, f, j, tight, 0.0, z0, atol);
  Revolution r;
  // Watched quantities: w1, w2 and the coupling moment, and their slopes in
  // phi2 (from the right-hand side).
  auto watched = [&](double phi2, const double* z, double* v, double* g) {
    double dz[kPlain];
    angle_rhs(d, shift, phi2, z, dz, false);
    v[0] = z[1], v[1] = z[2], v[2] = coupling_moment(d, z[0], z[1], z[2]);
    g[0] = dz[1], g[1] = dz[2], g[2] = d.stiffness * dz[0] + d.damping * (dz[1] - dz[2]);
  };
  Range* ranges[3] = {&r.w1, &r.w2, &r.coupling};
  auto add = [&](const double* v) {
    for (int i = 0; i < 3; ++i) ranges[i]->add(v[i]);
  };
  auto record = [&](double phi2, const double* z) { append(*out, d, z[3], phi2, z[0], z[1], z[2]); };
  double v0[3], g0[3], v1[3], g1[3], z[kSensitive];
  watched(0.0, z0, v0, g0);
  add(v0);
  if (out) *out = Trajectory{}, record(0.0, z0);
  if (!rec.extrema && !out) {
    r.status = in.advance(kTwoPi);
  } else {
    // Step by step: an extremum lies where a slope changes sign within a
    // step; Illinois (regula falsi) on the dense output finds it. Its value
    // hardly depends on the root's position (an error e in phi2 changes it by
    // v'' e^2 / 2), so a few iterations reach the integration's accuracy.
    double a = 0;
    int sample = 1;
    while (a < kTwoPi && (r.status = in.step(kTwoPi)) == Status::ok) {
      const double b = in.time();
      watched(b, in.y(), v1, g1);
      for (int i = 0; i < 3 && rec.extrema; ++i) {
        if (!(g0[i] * g1[i] < 0)) continue;
        double lo = a, hi = b, glo = g0[i], ghi = g1[i], v[3] = {v1[0], v1[1], v1[2]}, g[3];
        int side = 0;
        for (int it = 0; it < 8 && hi - lo > 1e-12; ++it) {
          const double t = hi - ghi * (hi - lo) / (ghi - glo);
          in.dense(t, z);
          watched(t, z, v, g);
          if (g[i] == 0) break;
          if ((g[i] < 0) == (glo < 0)) lo = t, glo = g[i], ghi *= side == -1 ? 0.5 : 1.0, side = -1;
          else hi = t, ghi = g[i], glo *= side == 1 ? 0.5 : 1.0, side = 1;
        }
        ranges[i]->add(v[i]);
      }
      for (; out && sample <= rec.samples && kTwoPi * sample / rec.samples <= b; ++sample) {
        const double phi2 = kTwoPi * sample / rec.samples;
        if (sample == rec.samples) std::copy(in.y(), in.y() + n, z);
        else in.dense(phi2, z);
        record(phi2, z);
      }
      a = b;
      std::copy(g1, g1 + 3, g0);
    }
  }
  std::copy(in.y(), in.y() + n, r.end);
  watched(kTwoPi, r.end, v1, g1);
  add(v1);
  r.steps = in.steps();
  return r;
}

// The mean and the largest magnitude of the resistance moment over a
// revolution (72 points: they only start the search and check the stall).
struct ResistanceSummary {
  double mean = 0, largest = 0;
};
ResistanceSummary resistance_summary(const ElasticDrive& d) {
  ResistanceSummary r;
  const PhaseRotation shift(d.phase_shift);
  const int n = 72;
  for (int k = 0; k < n; ++k) {
    const double m = mechanism_state(d, kTwoPi * k / n, 1.0, shift).resistance;
    r.mean += m / n;
    r.largest = std::max(r.largest, std::abs(m));
  }
  return r;
}

// Rigid estimate of the steady speed: the motor moment balances the mean
// resistance (bisection on the crank speed below synchronous speed).
double rigid_speed_estimate(const ElasticDrive& d, double mean) {
  const double w0 = d.motor.synchronous_speed / d.gear_ratio;
  double lo = w0 * (1 - d.motor.critical_slip), hi = w0;  // the stable branch of the motor curve
  for (int i = 0; i < 80; ++i) {
    const double mid = 0.5 * (lo + hi);
    (d.motor_moment(mid) > mean ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The rigid estimate of the orbit's start (theta, w1, w2): the static twist
// under the mean resistance, and the speed at which the motor balances it.
void rigid_guess(const ElasticDrive& d, double mean, double* z) {
  z[0] = d.fidelity == DriveFidelity::rigid ? 0.0 : mean / d.stiffness;
  z[1] = z[2] = rigid_speed_estimate(d, mean);
}

// Scale of the twist theta: the largest resistance moment over c.
double twist_scale(const ElasticDrive& d, const ResistanceSummary& r) {
  return std::max(r.largest, 1.0) / d.stiffness;
}

// Metrics of the orbit that starts at `start` from its revolution r (and the
// sampled cycle, if any).
void fill_metrics(const ElasticDrive& d, const double* start, const Revolution& r, Trajectory cycle,
                  SteadyCycle& s) {
  s.theta0 = start[0], s.w10 = start[1], s.w20 = start[2];
  s.cycle = std::move(cycle);
  s.period = r.end[3];
  s.mean_speed = kTwoPi / s.period;
  s.coupling_rms = std::sqrt(r.end[5] / s.period);
  s.mean_motor_power = r.end[6] / s.period;
  s.mean_resistance_power = r.end[7] / s.period;
  s.mean_damping_power = r.end[8] / s.period;
  s.coupling_min = r.coupling.lo;
  s.coupling_max = r.coupling.hi;
  s.coupling_peak = std::max(std::abs(s.coupling_min), std::abs(s.coupling_max));
  s.speed_irregularity = (r.w2.hi - r.w2.lo) / s.mean_speed;
  s.motor_speed_min = r.w1.lo * d.gear_ratio;
  s.motor_speed_max = r.w1.hi * d.gear_ratio;
  // Kloss's torque falls with speed on the stable branch the motor runs on.
  const double a = d.motor.torque(s.motor_speed_min), b = d.motor.torque(s.motor_speed_max);
  s.motor_torque_min = std::min(a, b);
  s.motor_torque_max = std::max(a, b);
}

// Largest modulus of the eigenvalues of the monodromy matrix in r: 3 x 3, or
// for the rigid drive (theta = 0, w1 = w2 = w) the scalar d w2(2 pi) / d w.
double largest_multiplier(const Revolution& r, bool rigid) {
  const double* S = r.end + kPlain;
  if (rigid) return std::abs(S[7] + S[8]);
  Eigen::Matrix3d m;
  for (int i = 0; i < kOrbit; ++i)
    for (int j = 0; j < kOrbit; ++j) m(i, j) = S[3 * i + j];
  return m.eigenvalues().cwiseAbs().maxCoeff();
}

// The periodic problem: unknowns u (3 elastic, 1 rigid) give the start
// z(0) = P u; the residual is F = R (z(2 pi) - z(0)) with R = P^-1 on the
// orbit's scales, and its Jacobian R (S(2 pi) - I) P. Every evaluation
// finds its revolution's extrema, so the last one gives the metrics.
struct Shooting {
  const ElasticDrive* d = nullptr;
  const OdeOptions* o = nullptr;
  int n = 0;                // unknowns
  double scale[3] = {};   // of theta, w1, w2
  double P[3][3] = {};  // start = P u
  double R[3][3] = {};  // F = R (end - start)
  long steps = 0;
  Status failure = Status::ok;
  double u[3] = {}, start[3] = {};  // the last evaluation's
  Revolution last;
  bool valid = false, sensitive = false;
  double multiplier = 0;  // largest of the last Jacobian's monodromy matrix
  std::exception_ptr error;  // thrown in a KINSOL callback

  // One revolution from P x; with sensitivities (twice the cost of a plain
  // revolution) only when a Jacobian is asked for.
  bool evaluate(const double* x, bool with_jacobian) {
    if (valid && std::equal(x, x + n, u) && (sensitive || !with_jacobian)) return true;
    std::copy(x, x + n, u);
    for (int i = 0; i < kOrbit; ++i) {
      start[i] = 0;
      for (int k = 0; k < n; ++k) start[i] += P[i][k] * x[k];
    }
    sensitive = with_jacobian;
    last = revolution(*d, *o, scale, start, {.sensitivities = sensitive});
    steps += last.steps;
    valid = last.status == Status::ok;
    if (!valid) failure = last.status;
    if (valid && sensitive) multiplier = largest_multiplier(last, n == 1);
    return valid;
  }
  void residual(double* f) const {
    for (int i = 0; i < n; ++i) {
      f[i] = 0;
      for (int k = 0; k < kOrbit; ++k) f[i] += R[i][k] * (last.end[k] - start[k]);
    }
  }
  double jacobian(int i, int j) const {  // (R (S - I) P)_ij
    double v = 0;
    for (int a = 0; a < kOrbit; ++a)
      for (int b = 0; b < kOrbit; ++b)
        v += R[i][a] * (last.end[kPlain + 3 * a + b] - (a == b)) * P[b][j];
    return v;
  }
};

int shooting_residual(N_Vector u, N_Vector F, void* data) {
  auto& s = *static_cast<Shooting*>(data);
  return guarded("residual", s.error, [&] {
    if (!s.evaluate(N_VGetArrayPointer(u), false)) return 1;  // recoverable: KINSOL's line search backs off
    s.residual(N_VGetArrayPointer(F));
    return 0;
  });
}

int shooting_jacobian(N_Vector u, N_Vector, SUNMatrix J, void* data, N_Vector, N_Vector) {
  auto& s = *static_cast<Shooting*>(data);
  return guarded("newton_jacobian", s.error, [&] {
    if (!s.evaluate(N_VGetArrayPointer(u), true)) return 1;
    for (int i = 0; i < s.n; ++i)
      for (int j = 0; j < s.n; ++j) SM_ELEMENT_D(J, i, j) = s.jacobian(i, j);
    return 0;
  });
}

// KINSOL (Newton, line search, the exact Jacobian) on the shooting problem
// from x, left at its last iterate; returns KINSOL's flag. What a callback
// threw is rethrown once KINSOL has returned.
int newton(Shooting& sh, double* x, double ftol, int& iterations) {
  const Context ctx = new_context();
  const Vector u = new_vector(sh.n, ctx.get()), ones = new_vector(sh.n, ctx.get());
  std::copy(x, x + sh.n, N_VGetArrayPointer(u.get()));
  N_VConst(1.0, ones.get());
  const Matrix J = new_matrix(sh.n, ctx.get());
  const LinearSolver LS = new_dense_solver(u.get(), J.get(), ctx.get());
  const Memory kin(setup(KINCreate(ctx.get()), "KINCreate"), [](void* m) { KINFree(&m); });
  void* k = kin.get();
  setup(KINInit(k, shooting_residual, u.get()), "KINInit");
  setup(KINSetUserData(k, &sh), "KINSetUserData");
  setup(KINSetErrHandlerFn(k, silent, nullptr), "KINSetErrHandlerFn");
  setup(KINSetLinearSolver(k, LS.get(), J.get()), "KINSetLinearSolver");
  setup(KINSetJacFn(k, shooting_jacobian), "KINSetJacFn");
  setup(KINSetFuncNormTol(k, ftol), "KINSetFuncNormTol");
  setup(KINSetScaledStepTol(k, ftol), "KINSetScaledStepTol");  // a step this small is inside the noise
  setup(KINSetNumMaxIters(k, 50), "KINSetNumMaxIters");
  // A fresh Jacobian every iteration: quadratic convergence, and the last
  // one gives the orbit's multipliers.
  setup(KINSetMaxSetupCalls(k, 1), "KINSetMaxSetupCalls");
  const int flag = KINSol(k, u.get(), KIN_LINESEARCH, ones.get(), ones.get());
  if (sh.error) std::rethrow_exception(std::exchange(sh.error, nullptr));
  long iters = 0;
  setup(KINGetNumNonlinSolvIters(k, &iters), "KINGetNumNonlinSolvIters");
  iterations = static_cast<int>(iters);
  std::copy(N_VGetArrayPointer(u.get()), N_VGetArrayPointer(u.get()) + sh.n, x);
  return flag;
}

// Revolution after revolution from `start` until the state repeats.
SteadyCycle cycles_from(const ElasticDrive& d, const OdeOptions& o, double theta_scale, double* start,
                        int max_cycles, double tol, int samples) {
  SteadyCycle s;
  const double scale[3] = {theta_scale, start[2], start[2]};
  for (s.iterations = 1; s.iterations <= max_cycles; ++s.iterations) {
    const Revolution r = revolution(d, o, scale, start, {.extrema = false});
    s.steps += r.steps;
    if (r.status != Status::ok) {
      s.status = r.status;
      s.message = "integration failed in revolution " + std::to_string(s.iterations);
      return s;
    }
    double change = 0;
    for (int i = 0; i < kOrbit; ++i)
      change = std::max(change, std::abs(r.end[i] - start[i]) / scale[i]);
    std::copy(r.end, r.end + kOrbit, start);
    if (change <= tol) {
      Trajectory cycle;
      const Revolution last = revolution(
          d, o, scale, start,
          {.sensitivities = true, .samples = samples, .out = samples > 0 ? &cycle : nullptr});
      s.steps += last.steps;
      s.residual = change;
      s.largest_multiplier = largest_multiplier(last, d.fidelity == DriveFidelity::rigid);
      fill_metrics(d, start, last, std::move(cycle), s);
      return s;
    }
  }
  s.status = Status::not_converged;
  s.message = "the state still changed after " + std::to_string(max_cycles) + " revolutions";
  return s;
}

// Newton (KINSOL, line search, the exact Jacobian from the variational
// equations) on the periodicity residual from `guess`.
SteadyCycle shoot_from(const ElasticDrive& d, const OdeOptions& o, int samples, double theta_scale,
                       const double* guess) {
  SteadyCycle s;
  const bool rigid = d.fidelity == DriveFidelity::rigid;
  const double w = guess[2];
  // Unknowns scaled to order one: theta by the twist the largest resistance
  // moment gives, speeds by w; rigid: the one speed (theta = 0, w1 = w2).
  Shooting sh;
  sh.d = &d, sh.o = &o, sh.n = rigid ? 1 : kOrbit;
  sh.scale[0] = theta_scale, sh.scale[1] = sh.scale[2] = w;
  if (rigid) {
    sh.P[1][0] = sh.P[2][0] = w;
    sh.R[0][2] = 1 / w;
  } else {
    for (int i = 0; i < kOrbit; ++i) sh.P[i][i] = sh.scale[i], sh.R[i][i] = 1 / sh.scale[i];
  }
  // A drive's orbit attracts: one revolution from the guess brings it most of
  // the way (for a well-damped coupling, all of it), so Newton starts there.
  const Revolution r0 = revolution(d, o, sh.scale, guess, {.extrema = false});
  sh.steps = r0.steps;
  double x0[3], f0 = 0;  // the start of the second revolution, the first's residual
  for (int i = 0; i < sh.n; ++i) {
    double from = 0;
    x0[i] = 0;
    for (int k = 0; k < kOrbit; ++k) x0[i] += sh.R[i][k] * r0.end[k], from += sh.R[i][k] * guess[k];
    f0 = std::max(f0, std::abs(x0[i] - from));
  }
  // The residual carries the integrator's error (~rtol) of a revolution.
  const double ftol = kPeriodicTol * o.rtol;
  double f[3] = {};
  int flag = 0;
  // Often the second revolution already repeats: no Jacobian needed. Its
  // residual over the first's bounds the largest multiplier (the map's
  // contraction) unless the first residual is itself down in the noise: then
  // the second takes the sensitivities for the exact multiplier.
  const bool guess_periodic = f0 <= kNoiseTol * o.rtol;
  bool converged = r0.status == Status::ok && sh.evaluate(x0, guess_periodic);
  // The two revolutions from the guess are what a machine would run: if one
  // fails (stall, step budget, solver), so does every other way to the orbit.
  const Status from_guess = r0.status != Status::ok ? r0.status : sh.failure;
  if (converged) {
    double f1 = 0;
    sh.residual(f);
    for (int i = 0; i < sh.n; ++i) f1 = std::max(f1, std::abs(f[i]));
    converged = f1 <= ftol;
    if (!guess_periodic) sh.multiplier = f1 / f0;
  }
  if (!converged && r0.status == Status::ok && sh.valid) {
    flag = newton(sh, x0, ftol, s.iterations);
    // Stopped by a tiny step or a failed line search: accepted if the
    // residual is within the noise.
    const bool noise_limited = flag == KIN_STEP_LT_STPTOL || flag == KIN_LINESEARCH_NONCONV;
    converged = (flag >= 0 || noise_limited) && sh.evaluate(x0, false);
    sh.residual(f);
    for (int i = 0; i < sh.n; ++i)
      converged = converged && (!noise_limited || std::abs(f[i]) <= kNoiseTol * o.rtol);
  }
  s.steps = sh.steps;
  if (!converged) {
    s.status = from_guess != Status::ok ? from_guess : Status::not_converged;
    const std::string trial =
        sh.failure != Status::ok ? ", a trial revolution: " + std::string(to_string(sh.failure)) : "";
    s.message = from_guess != Status::ok
                    ? "the integration from the first guess failed: " + std::string(to_string(from_guess))
                    : "shooting did not converge (KINSOL flag " + std::to_string(flag) + trial + ")";
    return s;
  }
  s.residual = 0;
  for (int i = 0; i < sh.n; ++i) s.residual = std::max(s.residual, std::abs(f[i]));
  s.largest_multiplier = sh.multiplier;
  Trajectory cycle;  // resampled only when asked for (curves, charts)
  if (samples > 0) {
    const Revolution r =
        revolution(d, o, sh.scale, sh.start, {.extrema = false, .samples = samples, .out = &cycle});
    s.steps += r.steps;
  }
  fill_metrics(d, sh.start, sh.last, std::move(cycle), s);
  return s;
}

// steady_by_shooting once its inputs are checked.
SteadyCycle shooting(const ElasticDrive& d, const OdeOptions& o, int samples, double warmup,
                     double initial_speed) {
  const ResistanceSummary res = resistance_summary(d);
  const double mean = res.mean, theta_scale = twist_scale(d, res);
  const double most = d.motor_moment(d.motor.synchronous_speed / d.gear_ratio * (1 - d.motor.critical_slip));
  if (mean > most) {
    // Over a periodic cycle the motor's mean moment (per crank angle) must
    // cover the resistance's; Kloss's curve never exceeds its critical torque.
    SteadyCycle s;
    s.status = Status::stalled;
    s.message = "the mean resistance " + std::to_string(mean) + " N m exceeds the motor's largest moment " +
                std::to_string(most) + " N m at the crank";
    return s;
  }
  double guess[3];
  rigid_guess(d, mean, guess);
  if (warmup > 0) {
    SteadyCycle s;
    if ((s.status = startup_guess(d, o, warmup, initial_speed, guess, s.message)) != Status::ok) return s;
  }
  SteadyCycle s = shoot_from(d, o, samples, theta_scale, guess);
  // An integration from the guess that fails (stall, step budget, solver)
  // would fail again revolution by revolution: that is the answer.
  if (s.status != Status::ok && s.status != Status::not_converged) return s;
  if (s.status == Status::ok && s.largest_multiplier < 1) return s;
  // Newton failed (a poor start near a resonance) or found an orbit the
  // machine cannot hold (a multiplier outside the unit circle): integrate
  // revolution after revolution from the guess instead, which follows the
  // orbit the machine itself settles on.
  const std::string why =
      s.status == Status::ok
          ? "shooting found an unstable orbit (multiplier " + std::to_string(s.largest_multiplier) + ")"
          : "shooting failed: " + s.message;
  SteadyCycle c = cycles_from(d, o, theta_scale, guess, 300, kNoiseTol * o.rtol, samples);
  c.steps += s.steps;
  c.message =
      why + (c.status == Status::ok ? "; found by integrating revolutions" : "; " + c.message);
  return c;
}

}  // namespace
}  // namespace dynamics

using namespace dynamics;

SteadyCycle steady_by_shooting(const ElasticDrive& d, const OdeOptions& o, int samples,
                               double warmup, double initial_speed) {
  return entry_point<SteadyCycle>(
      d, o,
      {{"samples", double(samples), samples >= 0},
       {"warm-up time", warmup, warmup >= 0 && std::isfinite(warmup)},
       {"initial speed", initial_speed, initial_speed >= 0 && std::isfinite(initial_speed)}},
      [&] { return shooting(d, o, samples, warmup, initial_speed); });
}

SteadyCycle steady_by_cycles(const ElasticDrive& d, const OdeOptions& o, int max_cycles, double tol,
                             int samples) {
  return entry_point<SteadyCycle>(
      d, o,
      {{"samples", double(samples), samples >= 0},
       {"revolutions", double(max_cycles), max_cycles >= 1},
       {"tolerance", tol, tol > 0 && std::isfinite(tol)}},
      [&] {
        const ResistanceSummary res = resistance_summary(d);
        double start[3];
        rigid_guess(d, res.mean, start);
        return cycles_from(d, o, twist_scale(d, res), start, max_cycles, tol, samples);
      });
}

}  // namespace mech
