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
#include "problems/registry.hpp"

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

struct Model {
  double roller_ratio = 1.1, gap = 0.015;  // the design values, rows 0-1 of kTable
  int variant = 1;                         // 0: none, the product values are required
  mech::RollerForming c;                   // the product values 0 (auto): the variant's
  int feed_exponent = 0, remaining_length = 0;
};

// Quantities without a dimension of their own are plain SI numbers, their unit in the doc line.
const opt::ParameterTable<Model> kTable = {
    {variable("roller_ratio", Dimension::dimensionless, {1.1, HUGE_VAL, false, false},
              "R_p / H, roller radius over product thickness; the guide's rule R/H >= 1.1", "seed 003 ex. 6, step 1"),
     MECHOPT_STORED_AT(m.roller_ratio)},
    {variable("gap", Dimension::length, kPositive, "delta, between a hopper sleeve and a roller (printed 0.01...0.2)",
              "seed 003 eq. (6.4)"),
     MECHOPT_STORED_AT(m.gap)},
    {whole("variant", {0, kVariants, false, false}, "Table 6.1 row giving the product values left at auto; 0: none",
           "seed 003 Table 6.1"),
     MECHOPT_STORED_AT(m.variant)},
    {quantity("product_length", Dimension::length, kPositive, "L; auto: the variant's", "seed 003 Table 6.1").or_auto(),
     MECHOPT_STORED_AT(m.c.L)},
    {quantity("width", Dimension::length, kPositive, "B, product width; auto: the variant's", "seed 003 Table 6.1")
         .or_auto(),
     MECHOPT_STORED_AT(m.c.B)},
    {quantity("thickness", Dimension::length, kPositive, "H (h of 6.2, 6.6, 6.7); auto: the variant's",
              "seed 003 Table 6.1")
         .or_auto(),
     MECHOPT_STORED_AT(m.c.H)},
    {quantity("forming_speed", Dimension::dimensionless, kPositive, "v_f, form speed, in m/s; auto: the variant's",
              "seed 003 eqs (6.2), (6.9), Table 6.1")
         .or_auto(),
     MECHOPT_STORED_AT(m.c.v_f)},
    {quantity("cart_speed", Dimension::dimensionless, kPositive, "v_p, roller cart speed, in m/s; auto: the variant's",
              "seed 003 eqs (6.8), (6.10), Table 6.1")
         .or_auto(),
     MECHOPT_STORED_AT(m.c.v_p)},
    {whole("passes", {1, 1000, false, false}, "N, roller passes (n_P of 6.8); auto: the variant's",
           "seed 003 eqs (6.1), (6.8), Table 6.1")
         .or_auto(),
     MECHOPT_STORED_AT(m.c.passes)},
    {quantity("friction", Dimension::dimensionless, kPositive, "f, steel on concrete", "seed 003 eqs (6.1), (6.10)"),
     MECHOPT_STORED_AT(m.c.f)},
    {quantity("mix_friction", Dimension::dimensionless, kPositive, "f1, mix on mix", "seed 003 eq. (6.1)"),
     MECHOPT_STORED_AT(m.c.f1)},
    {quantity("stage_factor", Dimension::dimensionless, kPositive, "k1 of (6.1), processing stage; N > 3: 0.3-0.45",
              "seed 003 eq. (6.1)"),
     MECHOPT_STORED_AT(m.c.k1)},
    {quantity("pass_time", Dimension::time, kPositive, "t_pr, one pass of the rollers (5-8 s)", "seed 003 eq. (6.3)"),
     MECHOPT_STORED_AT(m.c.t_pass)},
    {quantity("feed_time", Dimension::time, kNonNegative, "t_zas, mix feed from the sleeves per pass (0.5-1 s)",
              "seed 003 eq. (6.3)"),
     MECHOPT_STORED_AT(m.c.t_feed)},
    {quantity("outlet_safety", Dimension::dimensionless, kPositive, "k1 of (6.5), uncertain mix properties (1-1.6)",
              "seed 003 eq. (6.5)"),
     MECHOPT_STORED_AT(m.c.k1_safety)},
    {quantity("internal_friction_angle", Dimension::angle, {0, std::numbers::pi / 2, false, false},
              "alpha1, internal friction in the hopper", "seed 003 eq. (6.5)"),
     MECHOPT_STORED_AT(m.c.alpha1)},
    {quantity("initial_shear_stress", Dimension::pressure, kPositive, "tau0 of the mix", "seed 003 eq. (6.5)"),
     MECHOPT_STORED_AT(m.c.tau0)},
    {quantity("mix_density", Dimension::dimensionless, kPositive, "rho0, mix in the hopper, in kg/m^3",
              "seed 003 eq. (6.5)"),
     MECHOPT_STORED_AT(m.c.rho0)},
    {quantity("gravity", Dimension::dimensionless, kPositive, "g, in m/s^2", "seed 003 eq. (6.5)"),
     MECHOPT_STORED_AT(m.c.g)},
    {quantity("initial_factor", Dimension::dimensionless, kPositive,
              "(1.4-1.6) of (6.6): the initial length's volume with the sleeve core", "seed 003 eq. (6.6)"),
     MECHOPT_STORED_AT(m.c.initial_factor)},
    {quantity("initial_share", Dimension::dimensionless, kNonNegative,
              "(0.4-0.6) of (6.6): the sleeve core over the initial length's volume", "seed 003 eq. (6.6)"),
     MECHOPT_STORED_AT(m.c.initial_share)},
    {quantity("setup_time", Dimension::time, kNonNegative, "t1, setting the machine over an empty form (60-80 s)",
              "seed 003 eq. (6.6)"),
     MECHOPT_STORED_AT(m.c.t1)},
    {quantity("sleeve_flow", Dimension::dimensionless, kPositive, "V_C, mix flow from one sleeve, in m^3/s",
              "seed 003 eq. (6.7)"),
     MECHOPT_STORED_AT(m.c.V_C)},
    {whole("rollers", {1, 100, false, false}, "n_p, rollers on the cart; n_p + 1 sleeves",
           "seed 003 eqs (6.7), (6.10)"),
     MECHOPT_STORED_AT(m.c.rollers)},
    {quantity("stop_time", Dimension::time, kNonNegative, "t_ost, stop at each end of the stroke", "seed 003 eq. (6.8)"),
     MECHOPT_STORED_AT(m.c.t_stop)},
    {quantity("contact_factor", Dimension::dimensionless, {0, 0.5, true, false},
              "theta, roller-mix interaction (0.1-0.5)", "seed 003 eqs (6.10)-(6.12)"),
     MECHOPT_STORED_AT(m.c.theta)},
    {quantity("elastic_modulus", Dimension::pressure, kPositive, "E of the mix (2-3e6 Pa)", "seed 003 eq. (6.12)"),
     MECHOPT_STORED_AT(m.c.E)},
    {quantity("poisson_ratio", Dimension::dimensionless, {0, 0.5, false, true}, "nu of the mix (0.25-0.35)",
              "seed 003 eq. (6.12)"),
     MECHOPT_STORED_AT(m.c.nu)},
    {choice("feed_exponent", {"negative", "as_printed"},
            "sign of (6.1)'s exponent; as printed the layer exceeds H and (6.5) has no solution", "seed 003 eq. (6.1)"),
     MECHOPT_STORED_AT(m.feed_exponent)},
    {choice("remaining_length", {"product_minus_roller", "printed"},
            "L_ost of (6.6), (6.9): L - L_p, or the guide's 0.2-0.5 m at 0.35 m", "seed 003 eqs (6.6), (6.9)"),
     MECHOPT_STORED_AT(m.remaining_length)},
};

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
  RollerFormingProblem(Model m, std::vector<opt::Variable> vars)
      : ModelProblem("roller_forming", kMetrics, std::move(vars)), m_(std::move(m)),
        slots_(opt::variable_rows(kTable, variables())) {}

  nlohmann::json settings() const override {
    nlohmann::json model = opt::parameters_json(opt::parameters(kTable, m_));
    const double bite = mech::bite_angle(m_.c.f, m_.c.f1);
    model["derived"] = {{"bite_angle_deg", bite * 180 / std::numbers::pi},
                        {"forming_time_per_pass", m_.c.t_pass - m_.c.t_feed}};
    nlohmann::json warnings = nlohmann::json::array();
    warnings.push_back(
        "compaction_power_per_length: (6.12) gives F = L_p E sin^2(phi)(1 - theta)/(14.14 (1 - nu^2) theta) "
        "in Pa m = N/m, so N of (6.10) comes out in W/m; its number is reported as printed");
    if (m_.feed_exponent == 1)
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
  void evaluate_model(const std::vector<S>& x, MetricSink<S>& out) const {
    S design[2] = {S(m_.roller_ratio), S(m_.gap)};  // rows 0-1 of kTable
    for (size_t i = 0; i < x.size(); ++i) design[slots_[i]] = x[i];
    const auto r = mech::roller_forming(m_.c, design[0], design[1]);
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
    out.put(M::crank_speed, S(std::numbers::pi * m_.c.v_p / r.L_X));
  }

 private:
  Model m_;
  std::vector<int> slots_;  // table row of each variable
};

std::unique_ptr<opt::Problem> make(const opt::ConfigNode& root) {
  Model m;
  opt::read_parameters(root, kTable, m);
  const opt::ConfigNode model = root.has("model") ? root.at("model") : root;
  // The product values left at auto (0) come from the variant's row.
  mech::RollerForming& c = m.c;
  const Variant v = m.variant > 0 ? kTable61[m.variant - 1] : Variant{};
  auto fill = [&](auto& value, auto row_value, const char* key) {
    if (value != 0) return;
    if (m.variant == 0) model.fail(std::string(key) + ": required with variant 0 (no Table 6.1 row)");
    value = row_value;
  };
  fill(c.L, v.L, "product_length");
  fill(c.B, v.B, "width");
  fill(c.H, v.H, "thickness");
  fill(c.v_f, v.v_f, "forming_speed");
  fill(c.v_p, v.v_p, "cart_speed");
  fill(c.passes, v.passes, "passes");
  if (!(c.f * c.f1 < 1)) model.fail("friction x mix_friction must be below 1 for the bite angle of (6.1)");
  if (!(c.t_pass > c.t_feed)) model.fail("pass_time must exceed feed_time: (6.3) t_pf = t_pr - t_zas > 0");
  c.feed = static_cast<mech::FeedExponent>(m.feed_exponent);
  c.remaining = static_cast<mech::RemainingLength>(m.remaining_length);
  auto vars = opt::parse_variables(root, opt::parameters(kTable, m));
  return std::make_unique<RollerFormingProblem>(std::move(m), std::move(vars));
}

const Registration kRegistration{
    {"roller_forming",
     "roller-forming machine: roller, hopper outlet, cart stroke and crank radius, productivity (seed 003 ex. 6)",
     opt::parameters(kTable, Model{}), make}};

}  // namespace
}  // namespace problems
