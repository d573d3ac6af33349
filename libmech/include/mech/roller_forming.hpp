// Roller-forming machine (seed 003, exercise 6, eqs 6.1-6.12): a cart with
// n_p compacting rollers runs back and forth over a form fed from a hopper.
// The chain sizes the roller (R_p from R/H), the least layer the rollers
// bite (6.1), the roller length (6.2)-(6.3), the hopper outlet (6.5), the
// cart stroke (6.4), the productivity (6.6)-(6.9) and the compaction power
// (6.10)-(6.12). Closed form throughout; docs/design/crank_press.md,
// section 9, names every reading and every value chosen from a range.
#pragma once
#include <cmath>
#include <numbers>

#include "mech/autodiff.hpp"
#include "mech/status.hpp"

namespace mech {

enum class FeedExponent { negative, as_printed };  // the sign of (6.1)'s exponent
enum class RemainingLength { product_minus_roller, printed };  // L_ost in (6.6), (6.9)

// The guide's "L_ost = 0.2-0.5 m", at its middle (remaining_length: printed).
inline constexpr double kPrintedRemainingLength = 0.35;

// Everything but the design values R_p/H and delta, which may be variables.
struct RollerForming {
  // Product and run (Table 6.1).
  double L = 0;      // product length [m]
  double B = 0;      // product width [m]
  double H = 0;      // product thickness (h of 6.2, 6.6, 6.7) [m]
  double v_f = 0;    // form speed [m/s]
  double v_p = 0;    // cart speed [m/s]
  int passes = 0;    // N of (6.1), n_P of (6.8)
  // Chosen constants (the guide's ranges, docs/design/crank_press.md).
  double f = 0.35, f1 = 0.58;             // friction steel-concrete, mix-mix (6.1), (6.10)
  double k1 = 0.375;                      // processing stage, N > 3 (6.1)
  double t_pass = 6.5, t_feed = 0.75;     // t_pr, t_zas (6.3) [s]
  double k1_safety = 1.3;                 // k1 of (6.5): uncertain mix properties
  double alpha1 = std::numbers::pi / 6;   // internal friction angle in the hopper [rad]
  double tau0 = 300, rho0 = 2400, g = 9.81;  // [Pa], [kg/m^3], [m/s^2]
  double initial_factor = 1.5, initial_share = 0.5;  // (6.6)
  double t1 = 70, V_C = 0.002;            // set-up time [s], sleeve flow [m^3/s] (6.6), (6.7)
  int rollers = 4;                        // n_p; n_PP = n_p + 1 sleeves (6.7)
  double t_stop = 2;                      // stop at each end of the stroke [s] (6.8)
  double theta = 0.3, E = 2.5e6, nu = 0.3;  // (6.10)-(6.12)
  FeedExponent feed = FeedExponent::negative;
  RemainingLength remaining = RemainingLength::product_minus_roller;
};

template <class S>
struct RollerFormingResult {
  Status status = Status::ok;
  const char* message = "";
  // Up to (6.5): set whenever the inputs are valid.
  S R_p, h_min, L_p, denominator;
  // From (6.5) on: set when status is ok.
  S a, L_X, t3, productivity, capture_angle, power;
};

// atan((f + f1)/(1 - f f1)) of (6.1), the angle the rollers bite at; equal to
// atan f + atan f1 while f f1 < 1.
inline double bite_angle(double f, double f1) { return std::atan((f + f1) / (1 - f * f1)); }

// The chain for roller_ratio = R_p/H (at least 1.1) and delta, the gap
// between a hopper sleeve and a roller (6.4) [m].
template <class S>
RollerFormingResult<S> roller_forming(const RollerForming& m, const S& roller_ratio, const S& delta) {
  using std::acos;
  using std::sin;
  RollerFormingResult<S> r;
  r.R_p = roller_ratio * m.H;                                            // R/H >= 1.1
  const double sign = m.feed == FeedExponent::negative ? -1.0 : 1.0;
  const double expo = sign * (m.passes - 1) / (m.k1 * m.passes);
  r.h_min = r.R_p * (1 - std::cos(bite_angle(m.f, m.f1))) * std::exp(expo);  // (6.1)
  const double t_pf = m.t_pass - m.t_feed;                               // (6.3)
  r.L_p = m.v_f * t_pf * m.H / r.h_min;                                  // (6.2)
  const double k = 2 + std::sin(m.alpha1);
  r.denominator = r.L_p * (m.rho0 * m.g) - 2 * m.tau0 * k;               // (6.5), below the line
  if (!(value(r.denominator) > 0)) {
    r.status = Status::invalid_parameter;
    r.message = "(6.5) denominator <= 0: no outlet width exists";
    return r;
  }
  r.a = 2 * m.tau0 * k * m.k1_safety * r.L_p / r.denominator;            // (6.5), its least value
  r.L_X = 2.0 * r.R_p + r.a + 2.0 * delta;                               // (6.4)
  const S L_rest = m.remaining == RemainingLength::printed ? S(kPrintedRemainingLength) : S(m.L - r.L_p);
  if (!(value(L_rest) > 0)) {
    r.status = Status::invalid_parameter;
    r.message = "remaining length L - L_p <= 0: the roller is longer than the product";
    return r;
  }
  const S t2 = r.L_p * (m.H * m.B / (m.V_C * (m.rollers + 1)));          // (6.7), h_sp = H
  r.t3 = (r.L_X / m.v_p + m.t_stop) * double(m.passes);                  // (6.8), n_P = N
  const S t4 = L_rest / m.v_f;                                           // (6.9), L_6 read as L_ost
  r.productivity = m.initial_factor * r.L_p * m.B * m.H / (m.t1 + t2 + r.t3) +
                   (L_rest - m.initial_share * r.L_p) * m.B * m.H / t4;  // (6.6)
  r.capture_angle = acos(1.0 - r.h_min / r.R_p);                         // the fed layer: cos phi = 1 - h/R
  const S s = sin(r.capture_angle);
  const S l_k = r.R_p * s / (1 - m.theta);                               // (6.11)
  const S F = r.L_p * m.E * s * s * (1 - m.theta) / (14.14 * (1 - m.nu * m.nu) * m.theta);  // (6.12) [N/m]
  r.power = (1 - 2 * m.theta) / (3.0 * r.R_p) * F * (2.0 * l_k + 3 * m.f * r.R_p) * (m.v_p * m.rollers);  // (6.10)
  return r;
}

}  // namespace mech
