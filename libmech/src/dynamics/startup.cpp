#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "internal.hpp"

namespace mech {
namespace dynamics {

// Appends one sample of a trajectory; returns its coupling moment (none in
// the rigid drive).
double append(Trajectory& tr, const ElasticDrive& d, double t, double phi2, double theta, double w1,
              double w2) {
  const double m = d.fidelity == DriveFidelity::rigid ? 0.0 : coupling_moment(d, theta, w1, w2);
  tr.t.push_back(t);
  tr.phi2.push_back(phi2);
  tr.theta.push_back(theta);
  tr.w1.push_back(w1);
  tr.w2.push_back(w2);
  tr.coupling.push_back(m);
  tr.motor_torque.push_back(d.motor.torque(w1 * d.gear_ratio));
  return m;
}

// The state (theta, w1, w2) where a start-up from `w0` last crossed a whole
// revolution of the crank after t seconds; false if it stalled or never turned.
bool startup_guess(const ElasticDrive& d, const OdeOptions& o, double t, double w0,
                   double* guess) {
  const Startup st = simulate_startup(d, o, t, 1e-3, nullptr, w0);
  const Trajectory& tr = st.trajectory;
  if (st.status != Status::ok || tr.phi2.back() < kTwoPi) return false;
  const double target = kTwoPi * std::floor(tr.phi2.back() / kTwoPi);
  size_t i = tr.phi2.size() - 1;
  while (i > 0 && tr.phi2[i - 1] >= target) --i;
  const double a = (target - tr.phi2[i - 1]) / (tr.phi2[i] - tr.phi2[i - 1]);
  guess[0] = tr.theta[i - 1] + a * (tr.theta[i] - tr.theta[i - 1]);
  guess[1] = tr.w1[i - 1] + a * (tr.w1[i] - tr.w1[i - 1]);
  guess[2] = tr.w2[i - 1] + a * (tr.w2[i] - tr.w2[i - 1]);
  return guess[2] > 0;
}

}  // namespace dynamics

using namespace dynamics;

Startup simulate_startup(const ElasticDrive& d, const OdeOptions& o, double t_end, double dt_out,
                         const SteadyCycle* steady, double initial_speed) {
  Startup out;
  const double y0[4] = {0, 0, initial_speed, initial_speed};
  const PhaseRotation shift(d.phase_shift);
  auto f = [&](double, const double* y, double* dy) {
    drive_rhs(d, shift, y, dy);
    return 0;
  };
  auto j = [&](double, const double* y, double* J) {
    autodiff_jacobian<4>(4, y, [&](const DualN<4>* yy, DualN<4>* dy) { drive_rhs(d, shift, yy, dy); }, J);
  };
  Integrator in(4, f, j, o, 0.0, y0);
  Trajectory& tr = out.trajectory;
  auto record = [&](double t, const double* y) {
    const double m = append(tr, d, t, y[1], y[0] - y[1], y[2], y[3]);
    out.peak_coupling = std::max(out.peak_coupling, std::abs(m));
  };
  record(0, y0);
  const int n = static_cast<int>(std::ceil(t_end / dt_out));
  for (int k = 1; k <= n; ++k) {
    const double t = std::min(t_end, k * dt_out);
    out.status = in.advance(t);
    if (out.status != Status::ok) {
      out.message = std::string("start-up integration stopped at t = ") + std::to_string(tr.t.back());
      break;
    }
    record(t, in.y());
  }
  out.steps = in.steps();
  out.final_speed = tr.w2.back();
  if (steady && steady->status == Status::ok && out.status == Status::ok) {
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
