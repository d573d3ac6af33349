// balanced_slider_crank: the main mechanism of the two-storey sawmill frame
// 2R63 balanced by a fixed circular cam and springs (seed 004), against the
// original plain slider-crank: the cosine-law error of the slider's motion,
// the balancing torque, the crank-bearing and cam forces, the rod's force and
// the shaking force on the frame. Defaults: the paper's data and improved
// design. Design and readings: docs/design/balanced_slider_crank.md.
#include <array>
#include <cmath>
#include <numbers>
#include <optional>

#include "mech/balanced_slider_crank.hpp"
#include "mech/cycle.hpp"
#include "opt/parameters.hpp"
#include "problems/model_problem.hpp"

namespace problems {
namespace {

// The model values: the rows of kTable.
struct R {
  enum Id : int {
    cam_offset, rod_length, spring_rate, spring_neutral, crank_length, original_rod_length, crank_speed, rod_mass,
    rod_inertia, rod_centre_of_mass, slider_mass, gravity, springs_carry_weight, cycle_points
  };
};

const std::vector<opt::Parameter> kTable = opt::table(
    "balanced_slider_crank",
    {
     {R::cam_offset, variable("cam_offset", Dimension::length, kNonNegative,
         "a: the cam centre from the crank axis, away from the slider (paper: 0.0365 S)", "seed 004 eq. (1)"),
         0.0365 * 0.6}, // a = 0.0365 S
     {R::rod_length, variable("rod_length", Dimension::length, kPositive,
         "L = l2s, the improved rod (> l1 + a); auto: original_rod_length + cam_offset, keeping s(0) = 0",
         "seed 004 eq. (2)").or_auto(), 0},
     {R::spring_rate, variable("spring_rate", Dimension::linear_stiffness, kPositive,
         "c of the springs parallel to the stroke; auto: m3 w^2, the slider fully balanced",
         "seed 004 (text)").or_auto(), 0},
     {R::spring_neutral, variable("spring_neutral", Dimension::length, kAnyValue,
         "where the springs are free: slider travel s0 minus mid-stroke S/2", ""), 0},
     {R::crank_length, quantity("crank_length", Dimension::length, kPositive,
         "l1: the original crank and the cam's radius; S = 2 l1", "seed 004 eq. (1)"), 0.3},
     {R::original_rod_length, quantity("original_rod_length", Dimension::length, kPositive,
         "l2, the original rod (> l1)", "seed 004 eq. (2)"), 2.0},
     {R::crank_speed, quantity("crank_speed", Dimension::angular_speed, kPositive, "n, constant (kinetostatics)",
         "seed 004 (2R63)"), 320 * std::numbers::pi / 30},
     {R::rod_mass, quantity("rod_mass", Dimension::mass, kNonNegative, "m2", "seed 004 eq. (3)"), 150},
     {R::rod_inertia, quantity("rod_inertia", Dimension::inertia, kNonNegative,
         "I_S2 about the rod's centre of mass; 0.5 as printed is 1% of a uniform 2 m bar's 51.1 (flagged)",
         "seed 004 eq. (3)"), 0.5},
     {R::rod_centre_of_mass, quantity("rod_centre_of_mass", Dimension::dimensionless, {0, 1, false, false},
         "|A S2| / L, from the crank pin (not printed: mid-length)", ""), 0.5},
     {R::slider_mass, quantity("slider_mass", Dimension::mass, kNonNegative, "m3, the saw frame", "seed 004 eq. (3)"),
         600},
     {R::gravity, choice("gravity", {"perpendicular", "none", "along_stroke"},
         "across the stroke (the paper's eq. 3), none, or along it toward the crank (a vertical frame)",
         "seed 004 eq. (3)"), 0},
     {R::springs_carry_weight, choice("springs_carry_weight", {"no", "yes"},
         "along_stroke: shift s0 by m3 g / c so the springs hold the frame", ""), 0},
     {R::cycle_points, whole("cycle_points", {8, 100000, false, false}, "grid points per revolution for the extrema",
         ""), 72}
    });

// The metrics, in the order of kMetrics (their MetricIds).
struct M {
  enum Id : int {
    displacement_deviation,
    velocity_deviation,
    acceleration_deviation,
    peak_balancing_torque,
    original_peak_balancing_torque,
    peak_torque_ratio,
    torque_ratio_1,
    torque_ratio_2,
    torque_ratio_3,
    torque_ratio_4,
    mean_dynamic_coefficient,
    peak_support_reaction,
    original_peak_support_reaction,
    support_reaction_ratio,
    peak_cam_force,
    max_cam_pressure_angle,
    peak_rod_force,
    peak_rod_inertia_force,
    peak_shaking_force,
    original_peak_shaking_force,
    energy_swing,
    original_energy_swing,
    rod_length,
    min_cam_force,
    max_cam_force,
  };
};

const std::vector<MetricSpec> kMetrics = {
    {M::displacement_deviation, "displacement_deviation", ""},  // max |s - s_c| / (S/2), s_c = S/2 (1 - cos phi)
    {M::velocity_deviation, "velocity_deviation", ""},          // max |v - v_c| / (w S/2)
    {M::acceleration_deviation, "acceleration_deviation", ""},  // max |a - a_c| / (w^2 S/2)
    {M::peak_balancing_torque, "peak_balancing_torque", "N m"},  // max |M_b|, eq. (4)
    {M::original_peak_balancing_torque, "original_peak_balancing_torque", "N m"},
    {M::peak_torque_ratio, "peak_torque_ratio", ""},  // original over improved
    {M::torque_ratio_1, "torque_ratio_1", ""},  // n_d: |M_b| extreme of the original over the improved's,
    {M::torque_ratio_2, "torque_ratio_2", ""},  // one per quarter turn (max, min, max, min)
    {M::torque_ratio_3, "torque_ratio_3", ""},
    {M::torque_ratio_4, "torque_ratio_4", ""},
    {M::mean_dynamic_coefficient, "mean_dynamic_coefficient", ""},  // k_d: ratio of the means of the four |extremes|
    {M::peak_support_reaction, "peak_support_reaction", "N"},       // max |R_O|, the crank bearing
    {M::original_peak_support_reaction, "original_peak_support_reaction", "N"},
    {M::support_reaction_ratio, "support_reaction_ratio", ""},  // original over improved
    {M::peak_cam_force, "peak_cam_force", "N"},                 // max |N_c|
    {M::max_cam_pressure_angle, "max_cam_pressure_angle", "rad"},  // max |nu|, tan nu = r'/r
    {M::peak_rod_force, "peak_rod_force", "N"},                 // max |F_A|, the rod's pin force
    {M::peak_rod_inertia_force, "peak_rod_inertia_force", "N"},  // max m2 |a_S2|
    {M::peak_shaking_force, "peak_shaking_force", "N"},          // max |m2 a_S2 + m3 a_B|, on the frame
    {M::original_peak_shaking_force, "original_peak_shaking_force", "N"},
    {M::energy_swing, "energy_swing", "J"},  // max - min of kinetic + potential energy: the flywheel's work
    {M::original_energy_swing, "original_energy_swing", "J"},
    {M::rod_length, "rod_length", "m"},  // L (l2s)
    // N_c over the cycle, signed along the cam's outward normal (< 0: toward
    // its centre): one sign all round (max < 0 or min > 0), the roller keeps
    // to one side of the cam track and a one-sided cam suffices
    {M::min_cam_force, "min_cam_force", "N"},
    {M::max_cam_force, "max_cam_force", "N"},
};

template <class S>
using Mechanism = mech::BalancedSliderCrank<S>;

// Cycle quantities q(mechanism, its point at an angle), each on any scalar.
auto torque = [](const auto&, const auto& p) { return p.torque; };
auto support = [](const auto&, const auto& p) { return mech::hypot2(p.bearing_x, p.bearing_y); };
auto cam = [](const auto&, const auto& p) { return p.cam; };
auto pressure = [](const auto&, const auto& p) { return p.pressure_angle; };
auto rod_force = [](const auto&, const auto& p) { return mech::hypot2(p.pin_x, p.pin_y); };
auto rod_inertia = [](const auto&, const auto& p) { return p.rod_inertia; };
auto shaking = [](const auto&, const auto& p) { return mech::hypot2(p.inertia_x, p.inertia_y); };
auto energy = [](const auto& m, const auto& p) { return mech::mechanical_energy(m, p.k); };
template <int i>
auto deviation = [](const auto& m, const auto& p) {
  const auto d = mech::cosine_law_deviation(m, p.k);
  return i == 0 ? d.v : i == 1 ? d.d : d.dd;
};

// |q| and -q as cycle quantities.
template <class Q>
auto absolute(Q q) {
  return [q](const auto& m, const auto& p) {
    using std::abs;
    const auto v = q(m, p);
    return decltype(v)(abs(v));
  };
}
template <class Q>
auto negative(Q q) {
  return [q](const auto& m, const auto& p) {
    const auto v = q(m, p);
    return decltype(v)(-v);
  };
}

// q as a function of the crank angle, g(mechanism, phi).
template <class Q>
auto at_angle(Q q) {
  return [q](const auto& m, const auto& phi) { return q(m, mech::balanced_point(m, phi)); };
}

// One mechanism's points on the n-point grid, computed once for every
// quantity's search, and the refined maximum of a quantity from them.
template <class S>
struct CycleGrid {
  CycleGrid(const mech::BalancedSliderCrank<S>& m, int n)
      : model(m), md(m.template cast<double>()), mv(m.template cast<mech::Dual>()) {
    for (int k = 0; k < n; ++k) points.push_back(mech::balanced_point(md, mech::kTwoPi * k / n));
  }
  // q at its refined cycle maximum (Danskin: the gradient at that fixed angle).
  template <class Q>
  S peak(const Q& q) const {
    std::vector<double> v;
    for (const auto& p : points) v.push_back(q(md, p));
    const double phi = mech::global_max_angle(
        v, [&](double a) { return at_angle(q)(md, a); }, [&](double a) { return at_angle(q)(mv, mech::seed(a)).d; });
    return at_angle(q)(model, S(phi));
  }
  const mech::BalancedSliderCrank<S>& model;
  mech::BalancedSliderCrank<double> md;
  mech::BalancedSliderCrank<mech::Dual> mv;
  std::vector<mech::BalancedPoint<double>> points;
};

class BalancedSliderCrankProblem : public ModelProblem<BalancedSliderCrankProblem> {
 public:
  // `given`: the values as the config gave them (rod_length auto: 0).
  BalancedSliderCrankProblem(opt::Values<double> values, std::vector<opt::Variable> vars,
                             const opt::Values<double>& given)
      : ModelProblem("balanced_slider_crank", kMetrics, kTable, std::move(values), std::move(vars)),
        rod_auto_(given[R::rod_length] == 0) {
    for (const auto& v : variables()) rod_auto_ = rod_auto_ && v.name != kTable[R::rod_length].name;
  }

  // The values left at auto: L = l2 + a, c = m3 w^2.
  static void resolve(opt::Values<double>& v, const opt::ConfigNode&) {
    if (v[R::rod_length] == 0) v[R::rod_length] = v[R::original_rod_length] + v[R::cam_offset];
    if (v[R::spring_rate] == 0) v[R::spring_rate] = v[R::slider_mass] * v[R::crank_speed] * v[R::crank_speed];
  }

  nlohmann::json settings() const override {
    return {{"model", model_json()},
            {"assumptions",
             {"crank turns at constant speed (kinetostatics); crank and sliding block massless",
              "cam: circle of radius l1 centred at (-a, 0); frictionless slot and roller",
              "original: the plain slider-crank l1, l2, no cam, no springs"}},
            {"numerics",
             {{"cycle_points", static_cast<int>(values()[R::cycle_points])},
              {"extrema", "grid bracket + Brent root of the angle derivative; Danskin gradients"}}},
            {"units", "SI (m, rad, rad/s, kg, N, N m, J)"}};
  }

  // The improved mechanism at design x.
  template <class S>
  Mechanism<S> improved(const opt::Values<S>& v) const {
    const opt::Values<double>& c = values();
    const S& a = v[R::cam_offset];
    const S& rate = v[R::spring_rate];
    const S rod = rod_auto_ ? S(c[R::original_rod_length] + a) : v[R::rod_length];
    S s0 = c[R::crank_length] + v[R::spring_neutral];
    if (c[R::springs_carry_weight] == 1 && gravity() == mech::Gravity::along_stroke && mech::value(rate) > 0)
      s0 = s0 - c[R::slider_mass] * mech::kStandardGravity / rate;
    return {v[R::crank_length], a, rod, S(c[R::crank_length] + c[R::original_rod_length]), v[R::rod_mass],
            v[R::rod_inertia], v[R::rod_centre_of_mass], v[R::slider_mass], rate, s0, v[R::crank_speed],
            gravity(), true};
  }

  // The original mechanism: no cam, no springs.
  template <class S>
  Mechanism<S> original() const {
    const opt::Values<double>& c = values();
    const S l1(c[R::crank_length]);
    return {l1, S(0.0), S(c[R::original_rod_length]), S(c[R::crank_length] + c[R::original_rod_length]),
            S(c[R::rod_mass]), S(c[R::rod_inertia]), S(c[R::rod_centre_of_mass]), S(c[R::slider_mass]), S(0.0), l1,
            S(c[R::crank_speed]), gravity(), false};
  }

  template <class S>
  void evaluate_model(const opt::Values<S>& v, MetricSink<S>& out) const {
    const Mechanism<S> imp = improved(v), orig = original<S>();
    out.put(M::rod_length, imp.rod_length);
    for (const auto* m : {&imp, &orig}) {
      if (const mech::Status st = mech::check(*m); st != mech::Status::ok) {
        out.result.status = st;
        return;
      }
    }
    const int n = static_cast<int>(values()[R::cycle_points]);
    const CycleGrid<S> gi(imp, n);
    std::optional<CycleGrid<S>> go;  // the original's, when a metric needs it
    auto of = [&](const Mechanism<S>& m) -> const CycleGrid<S>& {
      if (&m == &imp) return gi;
      if (!go) go.emplace(orig, n);
      return *go;
    };
    auto peak = [&](const Mechanism<S>& m, const auto& q) { return of(m).peak(q); };
    out.put(M::displacement_deviation, peak(imp, absolute(deviation<0>)));
    out.put(M::velocity_deviation, peak(imp, absolute(deviation<1>)));
    out.put(M::acceleration_deviation, peak(imp, absolute(deviation<2>)));
    const bool torques = out.want_any(M::peak_torque_ratio, M::torque_ratio_1, M::torque_ratio_2, M::torque_ratio_3,
                                      M::torque_ratio_4, M::mean_dynamic_coefficient);
    if (torques || out.want_any(M::peak_balancing_torque, M::original_peak_balancing_torque)) {
      const S peak_imp = peak(imp, absolute(torque)), peak_orig = peak(orig, absolute(torque));
      out.put(M::peak_balancing_torque, peak_imp);
      out.put(M::original_peak_balancing_torque, peak_orig);
      out.put(M::peak_torque_ratio, peak_orig / peak_imp);
    }
    if (torques) {
      const auto at_imp = mech::quarter_torque_extremum_angles(imp, n);
      const auto at_orig = mech::quarter_torque_extremum_angles(orig, n);
      S sum_imp(0.0), sum_orig(0.0);
      for (int i = 0; i < 4; ++i) {
        const S e_imp = at_angle(absolute(torque))(imp, S(at_imp[i]));
        const S e_orig = at_angle(absolute(torque))(orig, S(at_orig[i]));
        out.put(M::torque_ratio_1 + i, S(e_orig / e_imp));
        sum_imp += e_imp;
        sum_orig += e_orig;
      }
      out.put(M::mean_dynamic_coefficient, S(sum_orig / sum_imp));
    }
    if (out.want_any(M::peak_support_reaction, M::original_peak_support_reaction, M::support_reaction_ratio)) {
      const S r_imp = peak(imp, support), r_orig = peak(orig, support);
      out.put(M::peak_support_reaction, r_imp);
      out.put(M::original_peak_support_reaction, r_orig);
      out.put(M::support_reaction_ratio, S(r_orig / r_imp));
    }
    if (out.want(M::peak_cam_force)) out.put(M::peak_cam_force, peak(imp, absolute(cam)));
    if (out.want(M::min_cam_force)) out.put(M::min_cam_force, S(-peak(imp, negative(cam))));
    if (out.want(M::max_cam_force)) out.put(M::max_cam_force, peak(imp, cam));
    if (out.want(M::max_cam_pressure_angle)) out.put(M::max_cam_pressure_angle, peak(imp, absolute(pressure)));
    if (out.want(M::peak_rod_force)) out.put(M::peak_rod_force, peak(imp, rod_force));
    if (out.want(M::peak_rod_inertia_force)) out.put(M::peak_rod_inertia_force, peak(imp, rod_inertia));
    if (out.want(M::peak_shaking_force)) out.put(M::peak_shaking_force, peak(imp, shaking));
    if (out.want(M::original_peak_shaking_force)) out.put(M::original_peak_shaking_force, peak(orig, shaking));
    auto swing = [&](const Mechanism<S>& m) { return S(peak(m, energy) + peak(m, negative(energy))); };
    if (out.want(M::energy_swing)) out.put(M::energy_swing, swing(imp));
    if (out.want(M::original_energy_swing)) out.put(M::original_energy_swing, swing(orig));
  }

  opt::CycleCurves cycle_curves(const Eigen::VectorXd& x, int n) const override {
    const auto imp = improved(values_at(x));
    const auto orig = original<double>();
    if (mech::check(imp) != mech::Status::ok || mech::check(orig) != mech::Status::ok) return {};
    opt::CycleCurves c{{"crank_angle", "balancing_torque", "original_balancing_torque", "support_reaction",
                        "cam_force", "slider_travel"},
                       {"rad", "N m", "N m", "N", "N", "m"}};
    for (int i = 0; i <= n; ++i) {
      const double phi = mech::kTwoPi * i / n;
      const auto p = mech::balanced_point(imp, phi);
      c.add_row({phi, p.torque, mech::balanced_point(orig, phi).torque, mech::hypot2(p.bearing_x, p.bearing_y), p.cam,
                 p.k.s});
    }
    return c;
  }

  std::vector<opt::MetricValue> local_maxima(const Eigen::VectorXd& x, opt::MetricId metric) const override {
    if (mech::check(improved(values_at(x))) != mech::Status::ok) return {};
    auto model_at = [&](const auto& v) { return improved(v); };
    const int n = static_cast<int>(values()[R::cycle_points]);
    if (metric == M::peak_balancing_torque) return cycle_local_maxima(x, n, model_at, at_angle(absolute(torque)));
    if (metric == M::peak_support_reaction) return cycle_local_maxima(x, n, model_at, at_angle(support));
    if (metric == M::peak_cam_force) return cycle_local_maxima(x, n, model_at, at_angle(absolute(cam)));
    return {};
  }

 private:
  mech::Gravity gravity() const { return static_cast<mech::Gravity>(values()[R::gravity]); }

  bool rod_auto_;  // L = l2 + a (tracks a variable cam offset)
};

const opt::Registered<BalancedSliderCrankProblem> kRegistration{
    "balanced_slider_crank",
    "sawmill-frame slider-crank balanced by a fixed circular cam and springs, against the original (seed 004)",
    kTable};

}  // namespace
}  // namespace problems
