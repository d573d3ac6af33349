// The start-up transient in time from phi = 0: the two-mass drive, eqs (29)
// and (40), sampled at equal steps; the samples kept for charts are bounded
// and the peak and the time to the steady state are found on the fly, so
// memory does not grow with the time span and the step budget bounds the work.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "internal.hpp"

namespace mech {
namespace dynamics {
namespace {

// Columns of a trajectory in the order `append` writes a sample.
std::array<std::vector<double>*, 7> columns(Trajectory& tr) {
  return {&tr.t, &tr.phi2, &tr.theta, &tr.w1, &tr.w2, &tr.coupling, &tr.motor_torque};
}

// Keeps every other sample (the first, third, ...).
void halve(Trajectory& tr) {
  for (std::vector<double>* c : columns(tr)) {
    for (size_t i = 0; 2 * i < c->size(); ++i) (*c)[i] = (*c)[2 * i];
    c->resize((c->size() + 1) / 2);
  }
}

// Integrates from phi = 0 with both masses at w0, calling sample(t, y) with
// y = (phi1, phi2, w1, w2) at t = 0, dt_out, 2 dt_out, ..., t_end until the
// integration stops; returns its status and steps.
template <class Sample>
Status run(const ElasticDrive& d, const OdeOptions& o, double t_end, double dt_out, double w0,
           Sample&& sample, long& steps) {
  const double y0[4] = {0, 0, w0, w0};
  const PhaseRotation shift(d.phase_shift);
  auto f = [&](double, const double* y, double* dy) {
    drive_rhs(d, shift, y, dy);
    return 0;
  };
  auto j = [&](double, const double* y, double* J) {
    autodiff_jacobian<4>(4, y, [&](const DualN<4>* yy, DualN<4>* dy) { drive_rhs(d, shift, yy, dy); }, J);
  };
  Integrator in(4, f, j, o, 0.0, y0);
  sample(0.0, y0);
  Status status = Status::ok;
  const double n = std::ceil(t_end / dt_out);  // a double: 1e9 s in 1 ms steps overflows an int
  for (double k = 1; k <= n && status == Status::ok; ++k) {
    const double t = std::min(t_end, k * dt_out);
    if ((status = in.advance(t)) == Status::ok) sample(t, in.y());
  }
  steps = in.steps();
  return status;
}

Startup startup(const ElasticDrive& d, const OdeOptions& o, double t_end, double dt_out,
                const SteadyCycle* steady, double w0) {
  Startup out;
  Trajectory& tr = out.trajectory;
  double last[5] = {};  // the last sample: t, phi2, theta, w1, w2
  long seen = 0, stride = 1;  // samples so far; every stride-th is kept
  // Revolution by revolution, the peak |coupling| against the steady one:
  // `since` is the start of the run of revolutions within 1% of it that
  // lasts to the end (0: from the start; -1: the last one was off).
  const bool timed = steady && steady->status == Status::ok;
  const double target = timed ? steady->coupling_peak : 0;
  double peak = 0, start = 0, since = 0;
  long rev = 0, revolutions = 0;
  auto sample = [&](double t, const double* y) {
    const double phi2 = y[1], theta = y[0] - y[1], m = sample_coupling(d, theta, y[2], y[3]);
    out.peak_coupling = std::max(out.peak_coupling, std::abs(m));
    const auto r = static_cast<long>(std::floor(phi2 / kTwoPi));
    if (r != rev) {  // a revolution ended at the previous sample
      ++revolutions;
      if (std::abs(peak - target) > 0.01 * target) since = -1;
      else if (since < 0) since = start;
      rev = r, peak = 0, start = t;
    }
    peak = std::max(peak, std::abs(m));
    if (seen++ % stride == 0) {
      append(tr, d, t, phi2, theta, y[2], y[3]);
      if (tr.t.size() == static_cast<size_t>(kStartupSamples)) halve(tr), stride *= 2;
    }
    last[0] = t, last[1] = phi2, last[2] = theta, last[3] = y[2], last[4] = y[3];
  };
  out.status = run(d, o, t_end, dt_out, w0, sample, out.steps);
  if (tr.t.back() != last[0]) append(tr, d, last[0], last[1], last[2], last[3], last[4]);  // the end
  out.final_speed = last[4];
  if (out.status != Status::ok)
    out.message = "start-up integration stopped at t = " + std::to_string(last[0]);
  else if (timed)
    out.time_to_steady = revolutions > 0 ? since : -1;
  return out;
}

}  // namespace

double sample_coupling(const ElasticDrive& d, double theta, double w1, double w2) {
  return d.fidelity == DriveFidelity::rigid ? 0.0 : coupling_moment(d, theta, w1, w2);
}

double append(Trajectory& tr, const ElasticDrive& d, double t, double phi2, double theta, double w1,
              double w2) {
  const double m = sample_coupling(d, theta, w1, w2);
  const double row[7] = {t, phi2, theta, w1, w2, m, d.motor.torque(w1 * d.gear_ratio)};
  const auto c = columns(tr);
  for (size_t i = 0; i < c.size(); ++i) c[i]->push_back(row[i]);
  return m;
}

Status startup_guess(const ElasticDrive& d, const OdeOptions& o, double t, double w0, double* guess,
                     std::string& why) {
  // The last upward crossing of a multiple of 2 pi between two samples
  // (1 ms apart), interpolated linearly. The first sample is at phi2 = 0.
  double prev[4] = {}, level = 0, at = 0;  // prev: phi2, theta, w1, w2 at time `at`
  auto sample = [&](double time, const double* y) {
    const double now[4] = {y[1], y[0] - y[1], y[2], y[3]};
    const double l = kTwoPi * std::floor(now[0] / kTwoPi);
    if (l >= kTwoPi && prev[0] < l) {
      const double a = (l - prev[0]) / (now[0] - prev[0]);
      for (int i = 0; i < 3; ++i) guess[i] = prev[i + 1] + a * (now[i + 1] - prev[i + 1]);
      level = l;
    }
    std::copy(now, now + 4, prev);
    at = time;
  };
  long steps = 0;
  if (const Status s = run(d, o, t, 1e-3, w0, sample, steps); s != Status::ok) {
    why = "the warm-up start-up (" + detail::text(t) + " s) stopped at t = " + detail::text(at) + " s";
    return s;
  }
  if (level == 0 || level != kTwoPi * std::floor(prev[0] / kTwoPi) || !(guess[2] > 0)) {
    why = "the start-up did not complete a revolution in " + detail::text(t) + " s";
    return Status::stalled;
  }
  return Status::ok;
}

}  // namespace dynamics

using namespace dynamics;

Startup simulate_startup(const ElasticDrive& d, const OdeOptions& o, double t_end, double dt_out,
                         const SteadyCycle* steady, double initial_speed) {
  return entry_point<Startup>(d, o,
                              {{"start-up time", t_end, t_end > 0 && std::isfinite(t_end)},
                               {"output step", dt_out, dt_out > 0 && std::isfinite(dt_out)},
                               {"initial speed", initial_speed, initial_speed >= 0 && std::isfinite(initial_speed)}},
                              [&] { return startup(d, o, t_end, dt_out, steady, initial_speed); });
}

}  // namespace mech
