// roller_forming: the roller-forming machine of seed 003, exercise 6 (eqs
// 6.1-6.12, Table 6.1): roller size, the least layer the rollers bite, the
// roller length, the hopper outlet, the cart stroke and the crank radius of
// the cart drive (seed 000's centred slider-crank, stroke 2 r), the
// productivity and the compaction power. The readings the guide leaves open
// are choices named as in docs/design/crank_press.md, section 9.
#include <cmath>
#include <numbers>
#include <string>

#include "mech/roller_forming.hpp"
#include "opt/parameters.hpp"
#include "problems/model_problem.hpp"

namespace problems {
namespace {

// Table 6.1: L, B, H [m], v_f, v_p [m/s], passes N.
struct Variant {
  double L, B, H, v_f, v_p;
  int passes;
};
constexpr Variant kTable61[] = {
    {3.0, 2.0, 0.10, 0.004, 0.23, 8},  {4.0, 2.0, 0.10, 0.003, 0.24, 10}, {4.0, 1.5, 0.08, 0.002, 0.25, 6},
    {4.0, 1.2, 0.08, 0.003, 0.26, 6},  {4.5, 1.0, 0.10, 0.004, 0.27, 8},  {4.0, 1.0, 0.12, 0.005, 0.24, 10},
    {4.5, 1.2, 0.12, 0.004, 0.28, 10}, {4.0, 1.4, 0.10, 0.003, 0.29, 8},  {4.0, 1.4, 0.12, 0.002, 0.25, 8},
    {5.0, 1.2, 0.10, 0.005, 0.26, 10}, {4.5, 1.0, 0.10, 0.003, 0.27, 8},  {5.0, 1.0, 0.10, 0.004, 0.28, 10},
    {3.0, 2.0, 0.12, 0.005, 0.23, 10}, {5.0, 1.2, 0.12, 0.003, 0.26, 10}, {4.0, 1.2, 0.10, 0.002, 0.28, 8},
    {4.5, 1.0, 0.12, 0.004, 0.29, 10}, {5.0, 1.2, 0.10, 0.003, 0.24, 8},  {4.5, 1.4, 0.12, 0.004, 0.25, 10},
    {4.0, 1.2, 0.12, 0.002, 0.26, 10}, {5.0, 1.4, 0.10, 0.005, 0.27, 6},  {4.0, 1.4, 0.10, 0.004, 0.28, 8},
    {4.5, 1.4, 0.10, 0.003, 0.26, 8},  {5.0, 1.2, 0.12, 0.004, 0.24, 10}, {3.0, 1.5, 0.12, 0.003, 0.25, 10},
};
constexpr int kVariants = static_cast<int>(std::size(kTable61));

// The model values: the rows of kTable. The product values at 0 (auto) are
// the variant's; the other defaults are libmech's.
struct R {
  enum Id : int {
    roller_ratio, gap, variant, product_length, width, thickness, forming_speed, cart_speed, passes, friction,
    mix_friction, stage_factor, pass_time, feed_time, outlet_safety, internal_friction_angle, initial_shear_stress,
    mix_density, gravity, initial_factor, initial_share, setup_time, sleeve_flow, rollers, stop_time, contact_factor,
    elastic_modulus, poisson_ratio, feed_exponent, remaining_length
  };
};

const mech::RollerForming kDefault{};

// Quantities without a dimension of their own are plain SI numbers, their unit in the doc line.
const std::vector<opt::Parameter> kTable = opt::table(
    "roller_forming",
    {
    {R::roller_ratio, variable("roller_ratio", Dimension::dimensionless, {1.1, HUGE_VAL, false, false},
        "R_p / H, roller radius over product thickness; the guide's rule R/H >= 1.1", "seed 003 ex. 6, step 1"), 1.1},
    {R::gap, variable("gap", Dimension::length, kPositive,
        "delta, between a hopper sleeve and a roller (printed 0.01...0.2)", "seed 003 eq. (6.4)"), 0.015},
    {R::variant, whole("variant", {0, kVariants, false, false},
        "Table 6.1 row giving the product values left at auto; 0: none", "seed 003 Table 6.1"), 1},
    {R::product_length, quantity("product_length", Dimension::length, kPositive, "L; auto: the variant's",
        "seed 003 Table 6.1").or_auto(), kDefault.L},
    {R::width, quantity("width", Dimension::length, kPositive, "B, product width; auto: the variant's",
        "seed 003 Table 6.1").or_auto(), kDefault.B},
    {R::thickness, quantity("thickness", Dimension::length, kPositive, "H (h of 6.2, 6.6, 6.7); auto: the variant's",
        "seed 003 Table 6.1").or_auto(), kDefault.H},
    {R::forming_speed, quantity("forming_speed", Dimension::dimensionless, kPositive,
        "v_f, form speed, in m/s; auto: the variant's", "seed 003 eqs (6.2), (6.9), Table 6.1").or_auto(),
        kDefault.v_f},
    {R::cart_speed, quantity("cart_speed", Dimension::dimensionless, kPositive,
        "v_p, roller cart speed, in m/s; auto: the variant's", "seed 003 eqs (6.8), (6.10), Table 6.1").or_auto(),
        kDefault.v_p},
    {R::passes, whole("passes", {1, 1000, false, false}, "N, roller passes (n_P of 6.8); auto: the variant's",
        "seed 003 eqs (6.1), (6.8), Table 6.1").or_auto(), kDefault.passes},
    {R::friction, quantity("friction", Dimension::dimensionless, kPositive, "f, steel on concrete",
        "seed 003 eqs (6.1), (6.10)"), kDefault.f},
    {R::mix_friction, quantity("mix_friction", Dimension::dimensionless, kPositive, "f1, mix on mix",
        "seed 003 eq. (6.1)"), kDefault.f1},
    {R::stage_factor, quantity("stage_factor", Dimension::dimensionless, kPositive,
        "k1 of (6.1), processing stage; N > 3: 0.3-0.45", "seed 003 eq. (6.1)"), kDefault.k1},
    {R::pass_time, quantity("pass_time", Dimension::time, kPositive, "t_pr, one pass of the rollers (5-8 s)",
        "seed 003 eq. (6.3)"), kDefault.t_pass},
    {R::feed_time, quantity("feed_time", Dimension::time, kNonNegative,
        "t_zas, mix feed from the sleeves per pass (0.5-1 s)", "seed 003 eq. (6.3)"), kDefault.t_feed},
    {R::outlet_safety, quantity("outlet_safety", Dimension::dimensionless, kPositive,
        "k1 of (6.5), uncertain mix properties (1-1.6)", "seed 003 eq. (6.5)"), kDefault.k1_safety},
    {R::internal_friction_angle, quantity("internal_friction_angle", Dimension::angle, {0, std::numbers::pi / 2, false,
        false}, "alpha1, internal friction in the hopper", "seed 003 eq. (6.5)"), kDefault.alpha1},
    {R::initial_shear_stress, quantity("initial_shear_stress", Dimension::pressure, kPositive, "tau0 of the mix",
        "seed 003 eq. (6.5)"), kDefault.tau0},
    {R::mix_density, quantity("mix_density", Dimension::dimensionless, kPositive, "rho0, mix in the hopper, in kg/m^3",
        "seed 003 eq. (6.5)"), kDefault.rho0},
    {R::gravity, quantity("gravity", Dimension::dimensionless, kPositive, "g, in m/s^2", "seed 003 eq. (6.5)"),
        kDefault.g},
    {R::initial_factor, quantity("initial_factor", Dimension::dimensionless, kPositive,
        "(1.4-1.6) of (6.6): the initial length's volume with the sleeve core", "seed 003 eq. (6.6)"),
        kDefault.initial_factor},
    {R::initial_share, quantity("initial_share", Dimension::dimensionless, kNonNegative,
        "(0.4-0.6) of (6.6): the sleeve core over the initial length's volume", "seed 003 eq. (6.6)"),
        kDefault.initial_share},
    {R::setup_time, quantity("setup_time", Dimension::time, kNonNegative,
        "t1, setting the machine over an empty form (60-80 s)", "seed 003 eq. (6.6)"), kDefault.t1},
    {R::sleeve_flow, quantity("sleeve_flow", Dimension::dimensionless, kPositive,
        "V_C, mix flow from one sleeve, in m^3/s", "seed 003 eq. (6.7)"), kDefault.V_C},
    {R::rollers, whole("rollers", {1, 100, false, false}, "n_p, rollers on the cart; n_p + 1 sleeves",
        "seed 003 eqs (6.7), (6.10)"), kDefault.rollers},
    {R::stop_time, quantity("stop_time", Dimension::time, kNonNegative, "t_ost, stop at each end of the stroke",
        "seed 003 eq. (6.8)"), kDefault.t_stop},
    {R::contact_factor, quantity("contact_factor", Dimension::dimensionless, {0, 0.5, true, false},
        "theta, roller-mix interaction (0.1-0.5)", "seed 003 eqs (6.10)-(6.12)"), kDefault.theta},
    {R::elastic_modulus, quantity("elastic_modulus", Dimension::pressure, kPositive, "E of the mix (2-3e6 Pa)",
        "seed 003 eq. (6.12)"), kDefault.E},
    {R::poisson_ratio, quantity("poisson_ratio", Dimension::dimensionless, {0, 0.5, false, true},
        "nu of the mix (0.25-0.35)", "seed 003 eq. (6.12)"), kDefault.nu},
    {R::feed_exponent, choice("feed_exponent", {"negative", "as_printed"},
        "sign of (6.1)'s exponent; as printed the layer exceeds H and (6.5) has no solution", "seed 003 eq. (6.1)"), 0},
    {R::remaining_length, choice("remaining_length", {"product_minus_roller", "printed"},
        "L_ost of (6.6), (6.9): L - L_p, or the guide's 0.2-0.5 m at 0.35 m", "seed 003 eqs (6.6), (6.9)"), 0}
    });

// libmech's inputs from the model values (the variant's product values filled in).
mech::RollerForming inputs(const opt::Values<double>& v) {
  mech::RollerForming c;
  c.L = v[R::product_length], c.B = v[R::width], c.H = v[R::thickness];
  c.v_f = v[R::forming_speed], c.v_p = v[R::cart_speed], c.passes = static_cast<int>(v[R::passes]);
  c.f = v[R::friction], c.f1 = v[R::mix_friction], c.k1 = v[R::stage_factor];
  c.t_pass = v[R::pass_time], c.t_feed = v[R::feed_time], c.k1_safety = v[R::outlet_safety];
  c.alpha1 = v[R::internal_friction_angle], c.tau0 = v[R::initial_shear_stress], c.rho0 = v[R::mix_density];
  c.g = v[R::gravity], c.initial_factor = v[R::initial_factor], c.initial_share = v[R::initial_share];
  c.t1 = v[R::setup_time], c.V_C = v[R::sleeve_flow], c.rollers = static_cast<int>(v[R::rollers]);
  c.t_stop = v[R::stop_time], c.theta = v[R::contact_factor], c.E = v[R::elastic_modulus], c.nu = v[R::poisson_ratio];
  c.feed = static_cast<mech::FeedExponent>(v[R::feed_exponent]);
  c.remaining = static_cast<mech::RemainingLength>(v[R::remaining_length]);
  return c;
}

// The metrics, in the order of kMetrics (their MetricIds).
struct M {
  enum Id : int {
    roller_radius,
    min_layer,
    roller_length,
    outlet_width,
    outlet_denominator,
    cart_stroke,
    crank_radius,
    cycle_time,
    productivity,
    capture_angle,
    compaction_power,
    crank_speed,
  };
};

const std::vector<MetricSpec> kMetrics = {
    {M::roller_radius, "roller_radius", "m"},             // R_p = (R_p/H) H
    {M::min_layer, "min_layer", "m"},                     // (6.1) h_n,min
    {M::roller_length, "roller_length", "m"},             // (6.2) L_p
    {M::outlet_width, "outlet_width", "m"},               // (6.5) a, its least value
    {M::outlet_denominator, "outlet_denominator", "Pa"},  // (6.5) L_p rho0 g - 2 tau0 (2 + sin alpha1)
    {M::cart_stroke, "cart_stroke", "m"},                 // (6.4) L_X
    {M::crank_radius, "crank_radius", "m"},               // L_X / 2: the cart drive's crank (seed 000)
    {M::cycle_time, "cycle_time", "s"},                   // (6.8) t3
    {M::productivity, "productivity", "m^3/s"},           // (6.6)
    {M::capture_angle, "capture_angle", "rad"},           // cos phi = 1 - h_n,min / R_p
    {M::compaction_power, "compaction_power", "W/m"},     // (6.10) as printed: F of (6.12) is per length
    // pi v_p / L_X: the cart drive's crank speed at which the cart's mean
    // speed over a revolution (2 L_X per turn) is v_p of Table 6.1
    {M::crank_speed, "crank_speed", "rad/s"},
};

class RollerFormingProblem : public ModelProblem<RollerFormingProblem> {
 public:
  RollerFormingProblem(opt::Values<double> values, std::vector<opt::Variable> vars)
      : ModelProblem("roller_forming", kMetrics, kTable, std::move(values), std::move(vars)),
        c_(inputs(this->values())) {}

  // The product values left at auto (0): the variant's row; and the rules
  // of (6.1) and (6.3).
  static void resolve(opt::Values<double>& v, const opt::ConfigNode& root) {
    const opt::ConfigNode model = root.has("model") ? root.at("model") : root;
    const int variant = static_cast<int>(v[R::variant]);
    const Variant row = variant > 0 ? kTable61[variant - 1] : Variant{};
    for (auto [r, row_value] : {std::pair{R::product_length, row.L}, {R::width, row.B}, {R::thickness, row.H},
                                {R::forming_speed, row.v_f}, {R::cart_speed, row.v_p},
                                {R::passes, static_cast<double>(row.passes)}}) {
      if (v[r] != 0) continue;
      if (variant == 0) model.fail(kTable[r].name + ": required with variant 0 (no Table 6.1 row)");
      v[r] = row_value;
    }
    if (!(v[R::friction] * v[R::mix_friction] < 1))
      model.fail("friction x mix_friction must be below 1 for the bite angle of (6.1)");
    if (!(v[R::pass_time] > v[R::feed_time]))
      model.fail("pass_time must exceed feed_time: (6.3) t_pf = t_pr - t_zas > 0");
  }

  nlohmann::json settings() const override {
    nlohmann::json model = model_json();
    const double bite = mech::bite_angle(c_.f, c_.f1);
    model["derived"] = {{"bite_angle_deg", bite * 180 / std::numbers::pi},
                        {"forming_time_per_pass", c_.t_pass - c_.t_feed}};
    nlohmann::json warnings = nlohmann::json::array();
    warnings.push_back(
        "compaction_power_per_length: (6.12) gives F = L_p E sin^2(phi)(1 - theta)/(14.14 (1 - nu^2) theta) "
        "in Pa m = N/m, so N of (6.10) comes out in W/m; its number is reported as printed");
    if (c_.feed == mech::FeedExponent::as_printed)
      warnings.push_back("feed_exponent_as_printed: e^(+(N-1)/(k1 N)) makes the least layer exceed H and "
                         "(6.5)'s denominator negative: no outlet width exists");
    return {{"model", model},
            {"warnings", warnings},
            {"assumptions",
             {"R_p = (R_p/H) H, the guide's R/H >= 1.1 at its least by default",
              "(6.5) a at its least value (the inequality's bound)",
              "L_X = 2 R_p + a + 2 delta (6.4); the cart drive's crank radius L_X / 2 (centred slider-crank)",
              "the cart drive's crank speed pi v_p / L_X: the cart's mean speed over a turn is v_p",
              "(6.7) h_sp = H, n_PP = n_p + 1; (6.8) n_P = N; (6.9) L_6 read as L_ost",
              "capture angle from the fed layer: cos phi = 1 - h_n,min / R_p",
              "compaction_power in W/m: (6.10) as printed with the force per length of (6.12)"}}};
  }

  template <class S>
  void evaluate_model(const opt::Values<S>& v, MetricSink<S>& out) const {
    const auto r = mech::roller_forming(c_, v[R::roller_ratio], v[R::gap]);
    out.put(M::roller_radius, r.R_p);
    out.put(M::min_layer, r.h_min);
    out.put(M::roller_length, r.L_p);
    out.put(M::outlet_denominator, r.denominator);
    if (r.status != mech::Status::ok) {
      out.result.status = r.status;
      out.result.message = r.message;
      return;
    }
    out.put(M::outlet_width, r.a);
    out.put(M::cart_stroke, r.L_X);
    out.put(M::crank_radius, S(r.L_X / 2.0));
    out.put(M::cycle_time, r.t3);
    out.put(M::productivity, r.productivity);
    out.put(M::capture_angle, r.capture_angle);
    out.put(M::compaction_power, r.power);
    out.put(M::crank_speed, S(std::numbers::pi * c_.v_p / r.L_X));
  }

 private:
  mech::RollerForming c_;  // libmech's inputs from the model values
};

const opt::Registered<RollerFormingProblem> kRegistration{
    "roller_forming",
    "roller-forming machine: roller, hopper outlet, cart stroke and crank radius, productivity (seed 003 ex. 6)",
    kTable};

}  // namespace
}  // namespace problems
