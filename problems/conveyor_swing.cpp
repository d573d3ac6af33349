#include "problems/conveyor_swing.hpp"
#include "problems/registry.hpp"

#include <cmath>
#include <numbers>

#include "mech/conveyor_swing.hpp"
#include "problems/model_problem.hpp"

namespace problems {
namespace {

using opt::Dimension;

// Margins [m] kept from a toggle inside the cycle and from a synthesis whose
// extreme positions straddle the frame line: the moment grows without bound
// as either vanishes.
constexpr double kMinMargin = 1e-3;

const std::vector<opt::VariableSpec> kVariables = {
    {"l_co1", Dimension::length, opt::kPositive},           // synthesis: distance of C from O1 along the axis
    {"crank_length", Dimension::length, opt::kPositive},    // free_links: l1
    {"coupler_length", Dimension::length, opt::kPositive},  // free_links: l2
    {"rocker_length", Dimension::length, opt::kPositive},   // free_links: l3
};

const std::vector<MetricSpec> kMetrics = {
    {"peak_moment", "N m"},         // max |M| over the cycle, eq. (6)
    {"mean_abs_moment", "N m"},     // cycle mean of |M|
    {"rms_moment", "N m"},
    {"max_pressure_angle", "rad"},  // max over the cycle, [gamma]_max of Table 2
    {"time_ratio", ""},             // K_w, eq. (5)
    {"swing_angle", "rad"},         // rocker swing between dead centres (2 theta)
    {"crank_length", "m"},          // l1
    {"coupler_length", "m"},        // l2
    {"rocker_length", "m"},         // l3
    {"frame_length", "m"},          // l4, eq. (1)
    {"grashof_margin", "m"},        // p + q - s - l: >= 0 for a fully turning link
    {"rotation_margin", "m"},       // > 0: the crank turns fully (no toggle in the cycle)
    {"synthesis_margin", "m"},      // > 0: B', B'' on one side of O1O (synthesis mode)
};

struct Model {
  bool synthesis = true;
  double gx = 1.0, gy = 2.2;         // a, b
  double half_swing = 16 * std::numbers::pi / 180;
  double axis_angle = 0;             // mid-swing axis O1C direction
  double coupler_offset = 1.0;       // l_CB
  double l_co1 = 1.2;
  mech::SwingMechanism<double> mech;
  int cycle_points = 48;
  // Free-links mode starts from (and takes its branch from) this synthesis.
};

class ConveyorSwing : public ModelProblem<ConveyorSwing> {
 public:
  ConveyorSwing(Model model, std::vector<opt::Variable> vars)
      : ModelProblem("conveyor_swing", kMetrics, std::move(vars)), model_(std::move(model)) {}

  std::vector<opt::Constraint> implicit_constraints() const override {
    std::vector<opt::Constraint> c = {{"rotation_margin", false, kMinMargin}};
    if (model_.synthesis) c.push_back({"synthesis_margin", false, kMinMargin});
    return c;
  }

  nlohmann::json settings() const override {
    const auto& m = model_.mech;
    return {{"model",
             {{"design", model_.synthesis ? "synthesis" : "free_links"},
              {"frame_x", model_.gx}, {"frame_y", model_.gy},
              {"swing_angle", 2 * model_.half_swing}, {"axis_angle", model_.axis_angle},
              {"coupler_offset", model_.coupler_offset}, {"l_co1", model_.l_co1},
              {"crank_length", m.linkage.crank}, {"coupler_length", m.linkage.coupler},
              {"rocker_length", m.linkage.rocker}, {"branch", m.linkage.branch},
              {"crank_speed", m.crank_speed}, {"rod_mass_per_length", m.rod_mass_per_length},
              {"platform_mass", m.platform_mass}, {"platform_inertia", m.platform_inertia},
              {"platform_cg_radius", m.platform_cg_radius},
              {"friction_moment", m.friction_moment}}},
            {"assumptions",
             {"swing plane horizontal: gravity does no work (the thrust bearing of eq. 7 carries G)",
              "crank turns at constant speed: its own inertia costs no moment",
              "platform inertia about O1 = J_s3 + m3 |O1S3|^2 (parallel axes)"}},
            {"numerics",
             {{"cycle_points", model_.cycle_points},
              {"means", "Gauss-Legendre between kinks (zeros of M, rocker reversals)"},
              {"maximum", "every grid local maximum refined by Brent on the autodiff angle derivative"},
              {"max_gradient", "Danskin: gradient at the maximising angle"}}},
            {"units", "SI (m, rad, rad/s, kg, N, N m)"}};
  }

  template <class S>
  void evaluate_model(const std::vector<S>& x, MetricSink<S>& out) const {
    using std::abs;
    const Design<S> d = design(x);
    const auto& k = d.mech.linkage;
    if (model_.synthesis) out.put("synthesis_margin", d.synthesis_margin);
    out.put("crank_length", k.crank);
    out.put("coupler_length", k.coupler);
    out.put("rocker_length", k.rocker);
    out.put("frame_length", k.frame());
    out.put("rotation_margin", mech::rotation_margin(k));
    out.put("grashof_margin", grashof_margin(k));
    if (const mech::Status st = d.status(); st != mech::Status::ok) {
      out.result.status = std::string(mech::to_string(st));
      return;
    }
    const auto dc = mech::dead_centres(k);
    out.put("swing_angle", abs(dc.theta3_folded - dc.theta3_extended));
    out.put("time_ratio", mech::time_ratio(dc));
    if (!out.want_any("peak_moment", "mean_abs_moment", "rms_moment", "max_pressure_angle")) return;
    const bool means = out.want_any("mean_abs_moment", "rms_moment");
    const auto r = mech::swing_metrics(d.mech, model_.cycle_points, means);
    out.put("peak_moment", r.peak_moment);
    if (means) {
      out.put("mean_abs_moment", r.mean_abs_moment);
      out.put("rms_moment", r.rms_moment);
    }
    out.put("max_pressure_angle", r.max_pressure_angle);
  }

  opt::CycleCurves cycle_curves(const Eigen::VectorXd& x, int n) const override {
    const Design<double> d = design(std::vector<double>(x.data(), x.data() + x.size()));
    if (d.status() != mech::Status::ok) return {};
    opt::CycleCurves c{{"crank_angle", "balancing_moment", "inertia_moment", "friction_moment",
                        "pressure_angle", "rocker_angle"}, {}};
    for (int i = 0; i <= n; ++i) {
      const double phi = mech::kTwoPi * i / n;
      const auto p = mech::swing_point(d.mech, phi);
      c.add_row({phi, p.moment(), p.inertia, p.friction, mech::pressure_angle(p.kinematics),
                 p.kinematics.theta3()});
    }
    return c;
  }

  std::vector<opt::MetricValue> local_maxima(const Eigen::VectorXd& x,
                                             const std::string& metric) const override {
    if (design(std::vector<double>(x.data(), x.data() + x.size())).status() != mech::Status::ok)
      return {};
    auto model_at = [&](const auto& xs) { return design(xs).mech; };
    const int n = model_.cycle_points;
    if (metric == "peak_moment")
      return cycle_local_maxima(x, n, model_at, [](const auto& m, const auto& phi) {
        using std::abs;
        return std::decay_t<decltype(phi)>(abs(mech::swing_point(m, phi).moment()));
      });
    if (metric == "max_pressure_angle")
      return cycle_local_maxima(x, n, model_at, [](const auto& m, const auto& phi) {
        mech::FourBarPoint<std::decay_t<decltype(phi)>> p;
        mech::four_bar_point(m.linkage, phi, p);
        return mech::pressure_angle(p);
      });
    return {};
  }

 private:
  // The mechanism at design x: synthesised from l_co1, or with free links.
  template <class S>
  struct Design {
    mech::SwingMechanism<S> mech;
    bool synthesis_ok = true;
    S synthesis_margin{0.0};
    mech::Status status() const {
      return synthesis_ok ? mech::check(mech) : mech::Status::synthesis_failed;
    }
  };

  template <class S>
  Design<S> design(const std::vector<S>& x) const {
    Design<S> d{model_.mech.template cast<S>()};
    S l_co1(model_.l_co1);
    for (size_t i = 0; i < x.size(); ++i) {
      const std::string& n = variables()[i].name;
      if (n == "l_co1") l_co1 = x[i];
      else if (n == "crank_length") d.mech.linkage.crank = x[i];
      else if (n == "coupler_length") d.mech.linkage.coupler = x[i];
      else d.mech.linkage.rocker = x[i];
    }
    if (model_.synthesis) {
      const auto syn = mech::synthesize_crank_rocker<S>(S(model_.gx), S(model_.gy), l_co1,
                                                        S(model_.coupler_offset), model_.axis_angle,
                                                        S(model_.half_swing));
      d.mech.linkage = syn.linkage;
      d.synthesis_ok = syn.ok;
      d.synthesis_margin = syn.side_margin;
    }
    return d;
  }

  template <class S>
  static S grashof_margin(const mech::FourBar<S>& k) {
    S l[4] = {k.crank, k.coupler, k.rocker, k.frame()};
    std::sort(l, l + 4, [](const S& a, const S& b) { return mech::value(a) < mech::value(b); });
    return (l[1] + l[2]) - (l[0] + l[3]);
  }

  Model model_;
};

}  // namespace

std::unique_ptr<opt::Problem> make_conveyor_swing(const opt::ConfigNode& root) {
  Model m;
  double rod = 200, platform = 3200, cg_along = 1.2, cg_across = 1.0, speed = 12;
  double friction = 0.01, diameter = 0.3, weight = 32000;
  double inertia = -1;  // eq. (11) by default
  double crank = 0, coupler = 0, rocker = 0;
  int branch = 0;  // 0: from the synthesis at l_co1
  if (root.has("model")) {
    const opt::ConfigNode n = root.at("model");
    n.allow_only({"design", "frame_x", "frame_y", "swing_angle", "axis_angle", "coupler_offset",
                  "l_co1", "crank_length", "coupler_length", "rocker_length", "branch",
                  "crank_speed", "rod_mass_per_length", "platform_mass", "platform_cg_along",
                  "platform_cg_across", "platform_inertia", "friction_coefficient",
                  "bearing_diameter", "platform_weight", "cycle_points"});
    if (n.has("design")) m.synthesis = n.at("design").choice({"synthesis", "free_links"}) == "synthesis";
    m.gx = n.quantity_or("frame_x", Dimension::length, m.gx);
    m.gy = n.quantity_or("frame_y", Dimension::length, m.gy);
    m.half_swing = 0.5 * n.quantity_or("swing_angle", Dimension::angle, 2 * m.half_swing,
                                       {0, std::numbers::pi, true, true});
    m.axis_angle = n.quantity_or("axis_angle", Dimension::angle, m.axis_angle);
    m.coupler_offset = n.quantity_or("coupler_offset", Dimension::length, m.coupler_offset);
    m.l_co1 = n.quantity_or("l_co1", Dimension::length, m.l_co1, opt::kPositive);
    crank = n.quantity_or("crank_length", Dimension::length, 0, opt::kPositive);
    coupler = n.quantity_or("coupler_length", Dimension::length, 0, opt::kPositive);
    rocker = n.quantity_or("rocker_length", Dimension::length, 0, opt::kPositive);
    if (n.has("branch")) branch = n.at("branch").choice({"1", "-1"}) == "1" ? 1 : -1;
    speed = n.quantity_or("crank_speed", Dimension::angular_speed, speed, opt::kPositive);
    rod = n.quantity_or("rod_mass_per_length", Dimension::linear_density, rod, opt::kNonNegative);
    platform = n.quantity_or("platform_mass", Dimension::mass, platform, opt::kNonNegative);
    cg_along = n.quantity_or("platform_cg_along", Dimension::length, cg_along);
    cg_across = n.quantity_or("platform_cg_across", Dimension::length, cg_across);
    if (n.has("platform_inertia")) {
      const opt::ConfigNode k = n.at("platform_inertia");
      inertia = k.number();
      if (!(inertia >= 0)) k.fail("expected a moment of inertia >= 0 in kg m^2, got '" + k.text() + "'");
    }
    friction = n.quantity_or("friction_coefficient", Dimension::dimensionless, friction, opt::kNonNegative);
    diameter = n.quantity_or("bearing_diameter", Dimension::length, diameter, opt::kNonNegative);
    weight = n.quantity_or("platform_weight", Dimension::force, weight, opt::kNonNegative);
    if (n.has("cycle_points")) m.cycle_points = n.at("cycle_points").integer(8, 100000);
    if (!(std::hypot(m.gx, m.gy) > 0)) n.fail("frame_x and frame_y place the crank pivot on the rocker pivot");
  }
  // The paper's synthesis at l_co1 gives the default lengths and the branch.
  const auto syn = mech::synthesize_crank_rocker<double>(m.gx, m.gy, m.l_co1, m.coupler_offset,
                                                         m.axis_angle, m.half_swing);
  mech::FourBar<double> k = syn.linkage;
  if (crank > 0) k.crank = crank;
  if (coupler > 0) k.coupler = coupler;
  if (rocker > 0) k.rocker = rocker;
  if (branch != 0) k.branch = branch;
  m.mech = {k, speed, rod, platform, inertia >= 0 ? inertia : platform * cg_along * cg_along,
            std::hypot(cg_along, cg_across), friction * weight * diameter / 2};  // eqs (7), (11)

  const std::map<std::string, double> values = {{"l_co1", m.l_co1},
                                                {"crank_length", k.crank},
                                                {"coupler_length", k.coupler},
                                                {"rocker_length", k.rocker}};
  auto vars = opt::parse_variables(root, kVariables, values);
  for (const auto& v : vars) {
    const bool synthesis_var = v.name == "l_co1";
    if (synthesis_var != m.synthesis)
      root.at("variables").at(v.name).fail(
          std::string("variable '") + v.name + "' belongs to design: " +
          (synthesis_var ? "synthesis" : "free_links") + ", but the model has design: " +
          (m.synthesis ? "synthesis" : "free_links"));
  }
  return std::make_unique<ConveyorSwing>(std::move(m), std::move(vars));
}

const Registration kRegistration{
    {"conveyor_swing", "crank-rocker swing mechanism of a radial-rotary conveyor (seed 002)", kVariables, make_conveyor_swing}};

}  // namespace problems
