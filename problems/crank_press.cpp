// crank_press: the crank-lever brick press of seed 003, exercise 7 (eqs
// 7.1-7.8, Tables 7.1-7.2): pressing force from the pressure law, the
// crankshaft torque at the guide's tabulated angle and its true maximum over
// the pressing stroke, and the drive power. The readings the guide leaves
// open are choices named as in docs/design/crank_press.md.
#include <cmath>
#include <numbers>
#include <string>

#include "mech/crank_press.hpp"
#include "opt/parameters.hpp"
#include "problems/model_problem.hpp"

namespace problems {
namespace {

// Table 7.1 [m]: r, l_sh, l, l_p of the presses SM-816 and MS-152.
struct Preset {
  double r, l_sh, l, l_p;
};
constexpr Preset kPresets[] = {{0.200, 0.500, 0.290, 1.156}, {0.200, 0.550, 0.275, 1.050}};

// The model values: the rows of kTable. Lengths at 0 (auto) are the press's
// (Table 7.1); a stroke held (not 0) makes the pusher arm follow it.
struct R {
  enum Id : int {
    crank_radius, rod_length, pusher_arm, lever_arm, stroke, press, depth, pressure_factor, pressure_exponent,
    depth_unit, euler, bricks, brick_area, tabulated_angle, crank_speed, efficiency, overload_factor,
    overload_factor_max, pressing_end, lever, lever_pivot, force, stroke_points
  };
};

const std::vector<opt::Parameter> kTable = opt::table(
    "crank_press",
    {
    {R::crank_radius, variable("crank_radius", Dimension::length, kPositive, "r; auto: the press's",
        "seed 003 Table 7.1").or_auto(), 0},
    {R::rod_length, variable("rod_length", Dimension::length, kPositive, "l_sh, connecting rod; auto: the press's",
        "seed 003 eq. (7.5)").or_auto(), 0},
    {R::pusher_arm, variable("pusher_arm", Dimension::length, kPositive,
        "l, lever pivot to the piston pusher; auto: the press's, or S l_p / (2 r) with a stroke",
        "seed 003 eq. (7.3)").or_auto(), 0},
    {R::lever_arm, variable("lever_arm", Dimension::length, kPositive,
        "l_p, lever pivot to the rod joint; auto: the press's", "seed 003 eq. (7.3)").or_auto(), 0},
    {R::stroke, quantity("stroke", Dimension::length, kPositive,
        "piston stroke held: the pusher arm follows, l = S l_p / (2 r); auto: not held", "S = 2 r l / l_p").or_auto(),
        0},
    {R::press, choice("press", {"SM-816", "MS-152"}, "the press of Table 7.1 giving the lengths left at auto",
        "seed 003 Table 7.1"), 0},
    {R::depth, quantity("depth", Dimension::length, kPositive, "h, compaction depth at the end of the stroke",
        "seed 003 eq. (7.2), Table 7.2"), 0.020},
    {R::pressure_factor, quantity("pressure_factor", Dimension::pressure, kPositive, "a of p = a e^(b h)",
        "seed 003 eq. (7.2), Table 7.2"), 0.035e6},
    {R::pressure_exponent, quantity("pressure_exponent", Dimension::dimensionless, kNonNegative,
        "b of p = a e^(b h), per depth_unit", "seed 003 eq. (7.2)"), 1.4},
    {R::depth_unit, choice("depth_unit", {"cm", "mm"}, "unit of h in e^(b h); mm as printed gives 1e10-1e28 MPa",
        "seed 003 eq. (7.2)"), 0},
    {R::euler, choice("euler", {"exact", "2.72"}, "the base of e^(b h): e, or the guide's 2.72", "seed 003 eq. (7.2)"),
        0},
    {R::bricks, whole("bricks", {1, 1000, false, false}, "m, bricks pressed at once", "seed 003 eq. (7.1), Table 7.2"),
        4},
    {R::brick_area, quantity("brick_area", Dimension::dimensionless, kPositive,
        "F, pressed face of one brick, in m^2 (a plain number)", "seed 003 eq. (7.1)"), 0.03},
    {R::tabulated_angle, quantity("tabulated_angle", Dimension::angle, {0, std::numbers::pi, true, true},
        "phi of Table 7.2, where the guide takes the torque", "seed 003 eq. (7.5), Table 7.2"),
        120 * std::numbers::pi / 180},
    {R::crank_speed, quantity("crank_speed", Dimension::angular_speed, kPositive, "omega",
        "seed 003 eq. (7.8), Table 7.2"), 20.7},
    {R::efficiency, quantity("efficiency", Dimension::dimensionless, {0, 1, true, false}, "eta of the drive",
        "seed 003 eq. (7.8)"), 0.8},
    {R::overload_factor, quantity("overload_factor", Dimension::dimensionless, kPositive,
        "motor overload factor (\"b\" of 7.8), low end of 1.5-1.8: the larger motor", "seed 003 eq. (7.8)"), 1.5},
    {R::overload_factor_max, quantity("overload_factor_max", Dimension::dimensionless, kPositive,
        "motor overload factor, high end", "seed 003 eq. (7.8)"), 1.8},
    {R::pressing_end, choice("pressing_end", {"inner", "outer"},
        "dead centre ending the pressing: inner (the rod pulls, the sign of 7.6) or outer", "seed 003 eq. (7.6)"), 0},
    {R::lever, choice("lever", {"slider", "four_bar"}, "rod end on a line (7.3)-(7.6), or on the lever's arc",
        "seed 003 eq. (7.3)"), 0},
    {R::lever_pivot, choice("lever_pivot", {"none", "same_side", "opposite_side"},
        "four_bar (required): the lever pivot on the crank pin's side of the dead-centre line, or opposite", ""), 0},
    {R::force, choice("force", {"constant", "pressure_law"},
        "the final pressure over the whole compaction (the guide), or (7.2) at the current depth",
        "seed 003 eqs (7.1)-(7.2)").fidelity({"constant", "pressure_law"}), 1},
    {R::stroke_points, whole("stroke_points", {4, 100000, false, false},
        "grid cells over the pressing stroke for the peak torque", ""), 64}
    });

// b [1/m]: 1.4 per depth unit, and e^(b d) as 2.72^(b d) with `euler: 2.72`.
double exponent_per_m(const opt::Values<double>& v) {
  return v[R::pressure_exponent] / (v[R::depth_unit] == 0 ? 0.01 : 0.001) *
         (v[R::euler] == 0 ? 1.0 : std::log(2.72));
}

// The metrics, in the order of kMetrics (their MetricIds).
struct M {
  enum Id : int {
    stroke,
    max_pressure,
    max_pressing_force,
    tabulated_crank_torque,
    tabulated_drive_power,
    peak_crank_torque,
    peak_torque_angle,
    compaction_start_angle,
    mean_pressing_torque,
    peak_drive_power,
    peak_drive_power_max_overload,
    max_rod_angle,
    lever_half_swing,
    assembly_margin,
    pusher_arm,
  };
};

const std::vector<MetricSpec> kMetrics = {
    {M::stroke, "stroke", "m"},                                // S_k = 2 r l / l_p
    {M::max_pressure, "max_pressure", "Pa"},                   // (7.2) at h
    {M::max_pressing_force, "max_pressing_force", "N"},        // (7.1) Q at h
    {M::tabulated_crank_torque, "tabulated_crank_torque", "N m"},  // the guide: Q at h, (7.3)-(7.7) at Table 7.2's phi
    {M::tabulated_drive_power, "tabulated_drive_power", "W"},  // (7.8) of it, overload_factor
    {M::peak_crank_torque, "peak_crank_torque", "N m"},        // max over [phi_c, pi] for the chosen force
    {M::peak_torque_angle, "peak_torque_angle", "rad"},
    {M::compaction_start_angle, "compaction_start_angle", "rad"},  // phi_c: the piston meets the mass
    {M::mean_pressing_torque, "mean_pressing_torque", "N m"},  // mean over [phi_c, pi]: work / (pi - phi_c)
    {M::peak_drive_power, "peak_drive_power", "W"},            // (7.8) M_max w / (eta k), k = overload_factor
    {M::peak_drive_power_max_overload, "peak_drive_power_max_overload", "W"},  // k = overload_factor_max
    {M::max_rod_angle, "max_rod_angle", "rad"},                // asin(r / l_sh), (7.5) at phi = 90 deg
    {M::lever_half_swing, "lever_half_swing", "rad"},          // asin(r / l_p)
    {M::assembly_margin, "assembly_margin", "m"},              // slider l_sh - r; four_bar the Grashof margin
    {M::pusher_arm, "pusher_arm", "m"},                        // l (follows the stroke when held)
};

class CrankPressProblem : public ModelProblem<CrankPressProblem> {
 public:
  CrankPressProblem(opt::Values<double> values, std::vector<opt::Variable> vars)
      : ModelProblem("crank_press", kMetrics, kTable, std::move(values), std::move(vars)) {}

  // The lever's rules, and the lengths left at auto: the press's (Table
  // 7.1), the pusher arm the stroke's when one is held.
  static void resolve(opt::Values<double>& v, const opt::ConfigNode& root) {
    const opt::ConfigNode model = root.has("model") ? root.at("model") : root;
    if ((v[R::lever] == 1) != (v[R::lever_pivot] != 0))
      model.fail(v[R::lever] == 1 ? "lever: four_bar needs lever_pivot: same_side or opposite_side"
                                  : "lever_pivot goes with lever: four_bar");
    if (v[R::stroke] > 0 && v[R::pusher_arm] > 0)
      model.fail("pusher_arm follows the stroke held (l = S l_p / (2 r)): give one of them");
    const Preset& p = kPresets[static_cast<int>(v[R::press])];
    for (auto [row, preset] : {std::pair{R::crank_radius, p.r}, {R::rod_length, p.l_sh}, {R::lever_arm, p.l_p},
                               {R::pusher_arm, p.l}})
      if (v[row] == 0) v[row] = preset;
    if (v[R::stroke] > 0) v[R::pusher_arm] = v[R::stroke] * v[R::lever_arm] / (2 * v[R::crank_radius]);
  }
  static void check_variables(const std::vector<opt::Variable>& vars, const opt::Values<double>& v,
                              const opt::ConfigNode& root) {
    for (const auto& var : vars)
      if (var.name == "pusher_arm" && v[R::stroke] > 0)
        root.at("variables").at(var.name).fail("the pusher arm follows the stroke held (l = S l_p / (2 r))");
  }

  nlohmann::json settings() const override {
    const opt::Values<double>& v = values();
    nlohmann::json model = model_json();
    const double p = v[R::pressure_factor] * std::exp(exponent_per_m(v) * v[R::depth]);
    model["derived"] = {{"pressure_exponent_per_m", exponent_per_m(v)}, {"max_pressure", p}};
    nlohmann::json warnings = nlohmann::json::array();
    if (!(p >= 6e6 && p <= 40e6))
      warnings.push_back("p_out_of_law_range: p = " + std::to_string(p / 1e6) +
                         " MPa lies outside 6-40 MPa, where the guide states b = 1.4");
    return {{"model", model},
            {"warnings", warnings},
            {"assumptions",
             {"quasi-static and frictionless: M = Q ds/dphi (virtual work)",
              "force zero before the piston meets the mass (phi < phi_c)"}},
            {"numerics",
             {{"peak", "grid over [phi_c, pi] + Brent root of dM/dphi, against M(phi_c); Danskin gradients, "
                       "with d(phi_c)/dx when the peak is at phi_c"},
              {"mean", "128-point Gauss-Legendre over [phi_c, pi]"}}}};
  }

  template <class S>
  void evaluate_model(const opt::Values<S>& v, MetricSink<S>& out) const {
    using std::asin;
    using std::exp;
    const mech::CrankPress<S> k = press(v);
    if (const mech::Status st = mech::check(k); st != mech::Status::ok) {
      out.result.status = st;
      if (st == mech::Status::invalid_parameter && mech::value(k.h) >= mech::value(mech::press_stroke(k)))
        out.result.message = "compaction depth h is not below the stroke 2 r l / l_p";
      return;
    }
    out.put(M::stroke, mech::press_stroke(k));
    out.put(M::pusher_arm, k.l);
    out.put(M::max_rod_angle, asin(k.r / k.l_sh));
    out.put(M::lever_half_swing, asin(k.r / k.l_p));
    out.put(M::assembly_margin, mech::assembly_margin(k));
    const S q = k.area * k.a * exp(k.b * k.h);  // (7.1)-(7.2) at h
    out.put(M::max_pressure, S(k.a * exp(k.b * k.h)));
    out.put(M::max_pressing_force, q);
    const opt::Values<double>& c = values();
    const double drive = c[R::crank_speed] / c[R::efficiency];  // (7.8) N = M w / (eta k)
    const S guide = q * mech::piston_motion(k, S(c[R::tabulated_angle])).ds;
    out.put(M::tabulated_crank_torque, guide);
    out.put(M::tabulated_drive_power, S(guide * (drive / c[R::overload_factor])));
    if (!out.want_any(M::peak_crank_torque, M::peak_torque_angle, M::compaction_start_angle, M::mean_pressing_torque,
                      M::peak_drive_power, M::peak_drive_power_max_overload))
      return;
    const auto kd = k.template cast<double>();
    const double phi_c = mech::compaction_start(kd);
    const double phi_peak = mech::peak_torque_angle(kd, phi_c, static_cast<int>(c[R::stroke_points]));
    const S phi_cs = mech::compaction_start(k, phi_c);
    // Danskin: the peak's gradient at its fixed angle, or with phi_c's motion
    // when the peak is at the compaction start.
    const S peak = mech::pressing_torque(k, phi_peak == phi_c ? phi_cs : S(phi_peak));
    out.put(M::peak_crank_torque, peak);
    if (out.want(M::peak_torque_angle))
      out.put(M::peak_torque_angle, phi_peak == phi_c ? phi_cs : mech::peak_angle(k, phi_peak));
    out.put(M::compaction_start_angle, phi_cs);
    if (out.want(M::mean_pressing_torque)) out.put(M::mean_pressing_torque, mech::mean_pressing_torque(k, phi_cs));
    out.put(M::peak_drive_power, S(peak * (drive / c[R::overload_factor])));
    out.put(M::peak_drive_power_max_overload, S(peak * (drive / c[R::overload_factor_max])));
  }

  // The crankshaft torque over the working half-turn [0, pi] under both
  // force laws (zero while the piston is free, phi < phi_c), the configured
  // one the chart's primary, and the piston travel.
  opt::CycleCurves cycle_curves(const Eigen::VectorXd& x, int n) const override {
    mech::CrankPress<double> k = press(values_at(x));
    if (mech::check(k) != mech::Status::ok) return {};
    const double phi_c = mech::compaction_start(k);
    opt::CycleCurves c{{"crank_angle", "torque_constant_force", "torque_pressure_law", "piston_travel"},
                       {"rad", "N m", "N m", "m"},
                       k.force == mech::PressForce::constant ? 1u : 2u};
    auto torque = [&](mech::PressForce f, double phi) {
      k.force = f;
      return phi < phi_c ? 0.0 : mech::pressing_torque(k, phi);
    };
    for (int i = 0; i <= n; ++i) {
      const double phi = std::numbers::pi * i / n;
      c.add_row({phi, torque(mech::PressForce::constant, phi), torque(mech::PressForce::pressure_law, phi),
                 mech::piston_motion(k, phi).s});
    }
    return c;
  }

 private:
  template <class S>
  mech::CrankPress<S> press(const opt::Values<S>& v) const {
    const opt::Values<double>& c = values();
    const S l = c[R::stroke] > 0 ? S(c[R::stroke] * v[R::lever_arm] / (2.0 * v[R::crank_radius])) : v[R::pusher_arm];
    return {v[R::crank_radius], v[R::rod_length], l, v[R::lever_arm], v[R::depth], v[R::pressure_factor],
            S(exponent_per_m(c)), S(c[R::bricks] * c[R::brick_area]),
            static_cast<mech::PressingEnd>(c[R::pressing_end]), static_cast<mech::PressLever>(c[R::lever]),
            c[R::lever_pivot] == 2 ? mech::LeverPivot::opposite_side : mech::LeverPivot::same_side,
            static_cast<mech::PressForce>(c[R::force])};
  }
};

const opt::Registered<CrankPressProblem> kRegistration{
    "crank_press", "crank-lever brick press: pressing force, crankshaft torque and drive power (seed 003)", kTable};

}  // namespace
}  // namespace problems
