// Dynamics of the elastic drive on SUNDIALS: the start-up transient from rest
// (CVODE BDF or Adams, ARKODE explicit Runge-Kutta), and the periodic steady
// state found directly by shooting over one crank revolution with KINSOL
// (Newton with the monodromy matrix from the variational equations), or by
// integrating cycle after cycle. Failures (too many steps, a stalled motor,
// no periodic orbit: mech::Status) are statuses, never exceptions: each
// entry point checks the design (check, elastic_drive.hpp) and its settings
// before integrating (invalid_parameter, cannot_assemble), and a failure
// inside (a SUNDIALS set-up, an exception in a callback) is evaluation_error
// with its message.
#pragma once
#include <string>
#include <vector>

#include "mech/elastic_drive.hpp"
#include "mech/status.hpp"

namespace mech {

enum class OdeMethod { bdf, adams, erk };

// bdf, adams: CVODE (BDF with Newton and a dense autodiff Jacobian; Adams
// with functional iteration, for non-stiff motion); erk: ARKODE ERKStep,
// Dormand-Prince 5(4). In the steady state atol is relative to each state's
// scale (twist: largest resistance / c; speeds: the first guess's).
struct OdeOptions {
  OdeMethod method = OdeMethod::bdf;
  double rtol = 1e-8, atol = 1e-8;
  long max_steps = 100000;  // per integration
};

// Quantities along a trajectory at output points.
struct Trajectory {
  std::vector<double> t, phi2, theta, w1, w2, coupling, motor_torque;
};

struct SteadyCycle {
  Status status = Status::ok;
  std::string message;
  double theta0 = 0, w10 = 0, w20 = 0;  // the periodic state at phi2 = 0 (mod 2 pi)
  double period = 0;                    // time of one crank revolution [s]
  double coupling_min = 0, coupling_max = 0, coupling_peak = 0, coupling_rms = 0;  // crank axis [N m]
  double mean_speed = 0;                // crank [rad/s]
  double speed_irregularity = 0;        // (w2max - w2min) / w2mean
  double motor_torque_min = 0, motor_torque_max = 0;  // motor shaft [N m]
  double motor_speed_min = 0, motor_speed_max = 0;    // motor shaft [rad/s]
  double mean_motor_power = 0, mean_resistance_power = 0, mean_damping_power = 0;  // [W]
  long steps = 0;                       // integrator steps, all revolutions
  int iterations = 0;                   // Newton iterations or revolutions
  double residual = 0;                  // |state(2 pi) - state(0)|, scaled
  // Largest modulus of the orbit's Floquet multipliers (< 1: a disturbance
  // shrinks each revolution, the orbit attracts): from the monodromy matrix
  // when Newton needed it, else the ratio of the last two revolutions'
  // periodicity residuals (an upper estimate, down to the integration noise).
  double largest_multiplier = 0;
  Trajectory cycle;                     // one revolution sampled in phi2 (when samples > 0)
};

// Periodic steady state by shooting: unknowns (theta, w1, w2) at phi2 = 0,
// residual state(2 pi) - state(0) from an integration in the crank angle.
// First guess: the rigid estimate (the motor balancing the mean resistance),
// or with warmup > 0 where a start-up from `initial_speed` (0: rest) last
// crossed phi2 = 0 mod 2 pi within `warmup` seconds. One revolution from the
// guess, then a second; if it repeats to 100 rtol (scaled) that is the orbit,
// else KINSOL (Newton, line search, exact Jacobian from the variational
// equations) continues. The metrics come from the last revolution (extrema
// by root finding); `samples` > 0 also samples the orbit into `cycle`. A
// mean resistance above the motor's largest moment is `stalled` at once.
SteadyCycle steady_by_shooting(const ElasticDrive& d, const OdeOptions& o, int samples = 720,
                               double warmup = 3.0, double initial_speed = 0);

// The same orbit by integrating revolution after revolution from the rigid
// estimate until the state repeats to `tol` (relative), at most max_cycles.
SteadyCycle steady_by_cycles(const ElasticDrive& d, const OdeOptions& o, int max_cycles = 400,
                             double tol = 1e-9, int samples = 720);

// The most samples a start-up keeps: past it, every other one is dropped
// (and every other later one skipped), so a trajectory of any length keeps
// 50 000-100 000 evenly spaced samples, and its end.
constexpr long kStartupSamples = 100000;

struct Startup {
  Status status = Status::ok;
  std::string message;
  Trajectory trajectory;       // at most kStartupSamples
  double peak_coupling = 0;    // max |coupling moment| during the run [N m]
  double time_to_steady = -1;  // first time after which every revolution's peak
                               // |coupling| stays within 1% of the steady one (-1: never)
  double final_speed = 0;      // w2 at the end [rad/s]
  long steps = 0;
};

// Start-up for t_end seconds, sampled every dt_out, from phi = 0 and both
// masses at `initial_speed` (crank axis; 0: from rest). With `steady`, also
// the time to reach it. The peak and the time to steady use every sample;
// the trajectory keeps at most kStartupSamples. The step budget bounds the
// work: a start-up too long for it ends in too_many_steps.
Startup simulate_startup(const ElasticDrive& d, const OdeOptions& o, double t_end, double dt_out,
                         const SteadyCycle* steady = nullptr, double initial_speed = 0);

// Test hook (tests only; not thread-safe): when set, every SUNDIALS callback
// (integrator right-hand side "rhs" and Jacobian "jacobian", KINSOL
// "residual" and "newton_jacobian") calls it first with its name; what it
// throws takes the callbacks' failure path (status evaluation_error).
inline void (*callback_hook)(const char* callback) = nullptr;

}  // namespace mech
