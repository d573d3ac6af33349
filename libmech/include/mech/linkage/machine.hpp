// A linkage as the elastic drive's machine (mech/machine.hpp): at a crank
// angle the chain solved on doubles, or on a Dual in phi when the drive
// asks for slopes (the third order in phi that J'' / 2 and the torque's
// slope need, exact), its bodies' reduced inertia and half slope
// (dynamics.hpp's body_sums), and its static torque (the driving torque
// less its inertia share: gravity, loads, springs) split by direction:
// - fixed: gravity, springs, and the loads that act whichever way the
//   crank turns (constant, table and pressure-law sizes);
// - opposing: the opposing loads and the joints' frictions, which turn
//   against the motion (the linkage's reading is the crank turning
//   forward, so their torque there is >= 0);
// - a `when` load acts on its stroke in time: while the crank turns
//   forward where the slider's (link's) coordinate rate ds/dphi has the
//   sign `when` names, while it turns back where ds/dphi has the other;
//   its torque forward M_f and back M_b go in as (M_f + M_b) / 2 fixed and
//   (M_f - M_b) / 2 opposing, so that fixed + tanh(w2 / 1e-3) opposing is
//   M_f or M_b once the crank turns (the blend through rest is the
//   opposing loads').
// The linkage's crank speed is not read: the drive sets the speed.
#pragma once
#include <cmath>
#include <cstdio>
#include <numbers>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "mech/angles.hpp"
#include "mech/cycle_maxima.hpp"
#include "mech/linkage/dynamics.hpp"
#include "mech/machine.hpp"

namespace mech::linkage {

// Below this fraction of its largest the reduced moment of inertia counts
// as vanishing (a sum of squares touching zero, refined to its minimum,
// is zero to round-off there).
inline constexpr double kVanishingInertia = 1e-12;

class LinkageMachine : public Machine {
 public:
  // The chain (not copied: it outlives the machine) at the values v, one
  // per slot; `grid` points a revolution for its check.
  LinkageMachine(const Chain& c, std::vector<double> v, int grid = 64)
      : c_(c), v_(std::move(v)), grid_(grid) {
    for (double x : v_) vdual_.emplace_back(x);
    sd_.resize(c_);
    sdual_.resize(c_);
    reversed_ = c_.loads();
    for (Load& l : reversed_) l.when = -l.when;
  }

  MachinePoint state(double phi, bool slopes) const override {
    if (!(phi == at_ && (slopes_ || !slopes))) {
      last_ = slopes ? point(vdual_.data(), Dual(phi, 1.0), sdual_) : point(v_.data(), phi, sd_);
      at_ = phi, slopes_ = slopes;
    }
    MachinePoint p = last_;
    if (!slopes) p.inertia.d = p.half_slope.d = p.fixed.d = p.opposing.d = 0;
    return p;
  }

  // The chain assembles on the grid, and its reduced moment of inertia,
  // refined to its least over the cycle (from the grid, by its slope's
  // root), keeps above kVanishingInertia of its largest.
  Status check(std::string* why) const override {
    try {
      const int n = grid_;
      std::vector<double> neg(static_cast<size_t>(n)), slope(static_cast<size_t>(n));
      double top = 0;
      auto sums = [&](double phi) {
        solved(v_.data(), phi, sd_);
        return body_sums(c_, v_.data(), sd_);
      };
      for (int i = 0; i < n; ++i) {
        const BodySums<double> b = sums(kTwoPi * i / n);
        neg[static_cast<size_t>(i)] = -b.inertia, slope[static_cast<size_t>(i)] = -2 * b.half_slope;
        top = std::max(top, b.inertia);
      }
      CycleMaxSearch least;
      least.reset(neg, {}, slope);
      find_cycle_maxima(std::span(&least, 1), [&](std::span<AngleQuery> qs) {
        for (AngleQuery& a : qs) {
          const BodySums<double> b = sums(a.phi);
          a.out = a.slope ? -2 * b.half_slope : -b.inertia;
        }
      });
      if (-least.value > kVanishingInertia * top) return Status::ok;
      if (why)
        *why = "the machine's reduced moment of inertia vanishes (" + text(-least.value) + " kg m^2 at crank angle " +
               degrees(least.phi) + " deg, its largest " + text(top) +
               " kg m^2): give the crank, or a link that moves there, an inertia";
      return Status::invalid_parameter;
    } catch (const MachineFailure& e) {
      if (why) *why = e.what();
      return e.status;
    }
  }

 private:
  static std::string text(double x, const char* format = "%.6g") {
    char b[32];
    std::snprintf(b, sizeof b, format, x);
    return b;
  }
  static std::string degrees(double phi) { return text(phi * 180 / std::numbers::pi, "%.4g"); }
  static Dual dual(double x) { return {x, 0.0}; }
  static Dual dual(const Dual& x) { return x; }

  // The chain solved at phi, or MachineFailure naming the group.
  template <class S>
  void solved(const S* v, const S& phi, State<S>& st) const {
    if (solve(c_, v, phi, st)) return;
    throw MachineFailure(Status::cannot_assemble,
                         c_.group_name(st.failed) + " cannot assemble at crank angle " + degrees(value(phi)) + " deg");
  }

  template <class S>
  MachinePoint point(const S* v, const S& phi, State<S>& st) const {
    solved(v, phi, st);
    const BodySums<S> b = body_sums(c_, v, st);
    S fixed = S(c_.gravity() * b.weight), opposing(0.0), size(0.0), rate(0.0);
    const auto& loads = c_.loads();
    for (size_t i = 0; i < loads.size(); ++i) {
      const Load& l = loads[i];
      const bool turns = l.opposing || l.kind == Load::Kind::friction;  // against the motion
      // Its torque with the crank turning forward (the linkage's reading) ...
      const S ahead = load_action(c_, l, v, st, phi, size, rate) ? S(-(size * rate)) : S(0.0);
      if (l.when == 0) {
        (turns ? opposing : fixed) += ahead;
        continue;
      }
      // ... and back: on the other stroke, an opposing size turned with the motion.
      S back = load_action(c_, reversed_[i], v, st, phi, size, rate) ? S(-(size * rate)) : S(0.0);
      if (turns) back = -back;
      fixed += S((ahead + back) / 2.0);
      opposing += S((ahead - back) / 2.0);
    }
    for (const Spring& sp : c_.springs()) {
      const Tension<S> t = tension(sp, v, st);
      fixed += t.tension * t.length_rate;
    }
    return {dual(b.inertia), dual(b.half_slope), dual(fixed), dual(opposing)};
  }

  const Chain& c_;
  std::vector<double> v_;
  std::vector<Dual> vdual_;  // the values as Duals (their slope: the crank angle's)
  std::vector<Load> reversed_;  // each load with its `when` turned round
  int grid_;
  // Scratch of state() and check(): one machine serves one thread.
  mutable State<double> sd_;
  mutable State<Dual> sdual_;
  mutable MachinePoint last_{};  // the last point, at angle at_ (with slopes_)
  mutable double at_ = std::nan("");
  mutable bool slopes_ = false;
};

}  // namespace mech::linkage
