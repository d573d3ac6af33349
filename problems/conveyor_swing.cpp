#include "problems/conveyor_swing.hpp"

#include <cmath>
#include <numbers>

#include "mech/conveyor_swing.hpp"
#include "opt/parameters.hpp"
#include "problems/model_problem.hpp"

namespace problems {
namespace {


// Margins [m] kept from a toggle inside the cycle and from a synthesis whose
// extreme positions straddle the frame line: the moment grows without bound
// as either vanishes.
constexpr double kMinMargin = 1e-3;

// The metrics, in the order of kMetrics (their MetricIds).
struct M {
  enum Id : int {
    peak_crank_torque,
    mean_abs_crank_torque,
    rms_crank_torque,
    max_pressure_angle,
    time_ratio,
    swing_angle,
    crank_length,
    coupler_length,
    rocker_length,
    frame_length,
    grashof_margin,
    rotation_margin,
    synthesis_margin,
  };
};

const std::vector<MetricSpec> kMetrics = {
    {M::peak_crank_torque, "peak_crank_torque", "N m", "peak_moment"},         // max |M| over the cycle, eq. (6)
    {M::mean_abs_crank_torque, "mean_abs_crank_torque", "N m", "mean_abs_moment"},     // cycle mean of |M|
    {M::rms_crank_torque, "rms_crank_torque", "N m", "rms_moment"},
    {M::max_pressure_angle, "max_pressure_angle", "rad"},  // max over the cycle, [gamma]_max of Table 2
    {M::time_ratio, "time_ratio", ""},             // K_w, eq. (5)
    {M::swing_angle, "swing_angle", "rad"},         // rocker swing between dead centres (2 theta)
    {M::crank_length, "crank_length", "m"},          // l1
    {M::coupler_length, "coupler_length", "m"},        // l2
    {M::rocker_length, "rocker_length", "m"},         // l3
    {M::frame_length, "frame_length", "m"},          // l4, eq. (1)
    {M::grashof_margin, "grashof_margin", "m"},        // p + q - s - l: >= 0 for a fully turning link
    {M::rotation_margin, "rotation_margin", "m"},       // > 0: the crank turns fully (no toggle in the cycle)
    {M::synthesis_margin, "synthesis_margin", "m"},      // > 0: B', B'' on one side of O1O (synthesis mode)
};

// The model values: the rows of kTable. Link lengths and the branch at 0
// (auto) come from the synthesis at l_co1 (eqs 2-3).
struct R {
  enum Id : int {
    l_co1, crank_length, coupler_length, rocker_length, design, frame_x, frame_y, swing_angle, axis_angle,
    coupler_offset, branch, crank_speed, rod_mass_per_length, platform_mass, platform_cg_along, platform_cg_across,
    platform_inertia, friction_coefficient, bearing_diameter, platform_weight, cycle_points
  };
};

const std::vector<opt::Parameter> kTable = opt::table(
    "conveyor_swing",
    {
     {R::l_co1, variable("l_co1", Dimension::length, kPositive,
         "l_CO1, distance of C from O1 along the axis (design: synthesis)", "seed 002 eq. (3)"), 1.2},
     {R::crank_length, variable("crank_length", Dimension::length, kPositive,
         "l1 (design: free_links); auto: the synthesis at l_co1", "seed 002 eq. (2)").or_auto(), 0},
     {R::coupler_length, variable("coupler_length", Dimension::length, kPositive,
         "l2 (design: free_links); auto: the synthesis at l_co1", "seed 002 eq. (2)").or_auto(), 0},
     {R::rocker_length, variable("rocker_length", Dimension::length, kPositive,
         "l3 (design: free_links); auto: hypot(l_co1, coupler_offset)", "seed 002 eq. (3)").or_auto(), 0},
     {R::design, choice("design", {"synthesis", "free_links"},
         "the paper's family (l1, l2, l3 from l_co1) or free link lengths", "seed 002 eqs (2)-(3)"), 0},
     {R::frame_x, quantity("frame_x", Dimension::length, kAnyValue,
         "a: the crank pivot O from O1 (l4 = hypot(a, b); not both 0)", "seed 002 eq. (1)"), 1.0},
     {R::frame_y, quantity("frame_y", Dimension::length, kAnyValue, "b: the crank pivot O from O1", "seed 002 eq. (1)"),
         2.2},
     {R::swing_angle, quantity("swing_angle", Dimension::angle, {0, std::numbers::pi, true, true},
         "2 theta, the rocker's swing (synthesis)", "seed 002 eq. (2)"), 32 * std::numbers::pi / 180},
     {R::axis_angle, quantity("axis_angle", Dimension::angle, kAnyValue,
         "direction of the mid-swing axis O1C (parallel to a)", ""), 0},
     {R::coupler_offset, quantity("coupler_offset", Dimension::length, kAnyValue,
         "l_CB: B off the axis toward O; l3 = hypot(l_CO1, l_CB)", "seed 002 eq. (3)"), 1.0},
     {R::branch, choice("branch", {"auto", "1", "-1"},
         "assembly branch: B left or right of the line O1-A; auto: the synthesis'", ""), 0},
     {R::crank_speed, quantity("crank_speed", Dimension::angular_speed, kPositive, "w1, constant",
         "seed 002 (w1 = 12 rad/s)"), 12},
     {R::rod_mass_per_length, quantity("rod_mass_per_length", Dimension::linear_density, kNonNegative,
         "m_n of crank and coupler", "seed 002 eq. (10)"), 200},
     {R::platform_mass, quantity("platform_mass", Dimension::mass, kNonNegative, "m3", "seed 002 eq. (11)"), 3200},
     {R::platform_cg_along, quantity("platform_cg_along", Dimension::length, kAnyValue,
         "d: the platform's centre of mass from O1, along the axis", "seed 002 eq. (11)"), 1.2},
     {R::platform_cg_across, quantity("platform_cg_across", Dimension::length, kAnyValue,
         "c: the platform's centre of mass, across the axis", "seed 002 eq. (11)"), 1.0},
     {R::platform_inertia, quantity("platform_inertia", Dimension::inertia, kPositive,
         "J_s3 about the centre of mass; auto: m3 d^2", "seed 002 eq. (11)").or_auto(), 0},
     {R::friction_coefficient, quantity("friction_coefficient", Dimension::dimensionless, kNonNegative,
         "f of M_c = f G D / 2", "seed 002 eq. (7)"), 0.01},
     {R::bearing_diameter, quantity("bearing_diameter", Dimension::length, kNonNegative, "D of M_c = f G D / 2",
         "seed 002 eq. (7)"), 0.3},
     {R::platform_weight, quantity("platform_weight", Dimension::force, kNonNegative, "G of M_c = f G D / 2",
         "seed 002 eq. (7)"), 32000},
     {R::cycle_points, whole("cycle_points", {8, 100000, false, false},
         "grid points per revolution for maxima and kinks", ""), 48}
    });

bool synthesis(const opt::Values<double>& v) { return v[R::design] == 0; }

// The synthesis at l_co1 (eqs 2-3) from the values v, any scalar.
template <class S>
mech::Synthesis<S> synthesized(const opt::Values<double>& c, const opt::Values<S>& v) {
  return mech::synthesize_crank_rocker<S>(v[R::frame_x], v[R::frame_y], v[R::l_co1], v[R::coupler_offset],
                                          c[R::axis_angle], S(c[R::swing_angle] / 2));
}

// What the config's values fix beyond the lengths: the assembly branch (the
// synthesis' when auto), the platform's inertia (11) and centre-of-mass
// radius, and the friction moment (7).
struct Fixed {
  int branch;
  double platform_inertia, platform_cg_radius, friction_moment;
};

Fixed fixed(const opt::Values<double>& v) {
  const int auto_branch = synthesized(v, v).linkage.branch;
  const double d = v[R::platform_cg_along];
  return {v[R::branch] == 0 ? auto_branch : v[R::branch] == 1 ? 1 : -1,
          v[R::platform_inertia] > 0 ? v[R::platform_inertia] : v[R::platform_mass] * d * d,
          std::hypot(d, v[R::platform_cg_across]),
          v[R::friction_coefficient] * v[R::platform_weight] * v[R::bearing_diameter] / 2};
}

class ConveyorSwing : public ModelProblem<ConveyorSwing> {
 public:
  ConveyorSwing(opt::Values<double> values, std::vector<opt::Variable> vars)
      : ModelProblem("conveyor_swing", kMetrics, kTable, std::move(values), std::move(vars)),
        fixed_(fixed(this->values())) {}

  // The frame's rule, and the link lengths left at auto: the synthesis'.
  static void resolve(opt::Values<double>& v, const opt::ConfigNode& root) {
    if (!(std::hypot(v[R::frame_x], v[R::frame_y]) > 0))
      root.at("model").fail("frame_x and frame_y place the crank pivot on the rocker pivot");
    const mech::FourBar<double> syn = synthesized(v, v).linkage;
    for (auto [row, length] : {std::pair{R::crank_length, syn.crank}, {R::coupler_length, syn.coupler},
                               {R::rocker_length, syn.rocker}})
      if (!(v[row] > 0)) v[row] = length;
  }
  // l_co1 is the synthesis' variable; the link lengths free_links'.
  static void check_variables(const std::vector<opt::Variable>& vars, const opt::Values<double>& v,
                              const opt::ConfigNode& root) {
    for (const auto& var : vars) {
      const bool synthesis_var = var.name == "l_co1";
      if (synthesis_var != synthesis(v))
        root.at("variables").at(var.name).fail(
            std::string("variable '") + var.name + "' belongs to design: " +
            (synthesis_var ? "synthesis" : "free_links") + ", but the model has design: " +
            (synthesis(v) ? "synthesis" : "free_links"));
    }
  }

  std::vector<opt::Constraint> implicit_constraints() const override {
    std::vector<opt::Constraint> c = {{"rotation_margin", false, kMinMargin}};
    if (synthesis(values())) c.push_back({"synthesis_margin", false, kMinMargin});
    return c;
  }

  nlohmann::json settings() const override {
    const Fixed& m = fixed_;
    nlohmann::json model = model_json();
    model["derived"] = {{"branch", m.branch}, {"platform_inertia", m.platform_inertia},
                        {"platform_cg_radius", m.platform_cg_radius}, {"friction_moment", m.friction_moment}};
    return {{"model", model},
            {"assumptions",
             {"swing plane horizontal: gravity does no work (the thrust bearing of eq. 7 carries G)",
              "crank turns at constant speed: its own inertia costs no moment",
              "platform inertia about O1 = J_s3 + m3 |O1S3|^2 (parallel axes)"}},
            {"numerics",
             {{"cycle_points", cycle_points()},
              {"means", "Gauss-Legendre between kinks (zeros of M, rocker reversals)"},
              {"maximum", "every grid local maximum refined by Brent on the autodiff angle derivative"},
              {"max_gradient", "Danskin: gradient at the maximising angle"}}},
            {"units", "SI (m, rad, rad/s, kg, N, N m)"}};
  }

  // An evaluation's scratch: the values and the cycle computations' lists.
  struct Workspace : opt::ModelWorkspace {
    mech::CycleScratch cycle;
  };

  template <class S>
  void evaluate_model(const opt::Values<S>& v, MetricSink<S>& out, Workspace& ws) const {
    using std::abs;
    const Design<S> d = design(v);
    const auto& k = d.mech.linkage;
    if (synthesis(values())) out.put(M::synthesis_margin, d.synthesis_margin);
    out.put(M::crank_length, k.crank);
    out.put(M::coupler_length, k.coupler);
    out.put(M::rocker_length, k.rocker);
    out.put(M::frame_length, k.frame());
    out.put(M::rotation_margin, mech::rotation_margin(k));
    out.put(M::grashof_margin, grashof_margin(k));
    if (const mech::Status st = d.status(); st != mech::Status::ok) {
      out.result.status = st;
      return;
    }
    const auto dc = mech::dead_centres(k);
    out.put(M::swing_angle, abs(dc.theta3_folded - dc.theta3_extended));
    out.put(M::time_ratio, mech::time_ratio(dc));
    if (!out.want_any(M::peak_crank_torque, M::mean_abs_crank_torque, M::rms_crank_torque, M::max_pressure_angle)) return;
    const bool means = out.want_any(M::mean_abs_crank_torque, M::rms_crank_torque);
    const auto r = mech::swing_metrics(d.mech, cycle_points(), ws.cycle, means);
    out.put(M::peak_crank_torque, r.peak_moment);
    if (means) {
      out.put(M::mean_abs_crank_torque, r.mean_abs_moment);
      out.put(M::rms_crank_torque, r.rms_moment);
    }
    out.put(M::max_pressure_angle, r.max_pressure_angle);
  }

  opt::CycleCurves cycle_curves(const Eigen::VectorXd& x, int n) const override {
    const Design<double> d = design(values_at(x));
    if (d.status() != mech::Status::ok) return {};
    opt::CycleCurves c{{"crank_angle", "balancing_moment", "inertia_moment", "friction_moment",
                        "pressure_angle", "rocker_angle"},
                       {"rad", "N m", "N m", "N m", "rad", "rad"}};
    for (int i = 0; i <= n; ++i) {
      const double phi = mech::kTwoPi * i / n;
      const auto p = mech::swing_point(d.mech, phi);
      c.add_row({phi, p.moment(), p.inertia, p.friction, mech::pressure_angle(p.kinematics),
                 p.kinematics.theta3()});
    }
    return c;
  }

  std::vector<opt::MetricValue> local_maxima(const Eigen::VectorXd& x, opt::MetricId metric) const override {
    const Design<double> d = design(values_at(x));
    if (d.status() != mech::Status::ok) return {};
    auto model_at = [&](const auto& v) { return design(v).mech; };
    const int n = mech::swing_grid_points(mech::toggle_poles(d.mech.linkage), cycle_points());  // swing_metrics' grid
    if (metric == M::peak_crank_torque)
      return cycle_local_maxima(x, n, model_at, [](const auto& m, const auto& phi) {
        using std::abs;
        return std::decay_t<decltype(phi)>(abs(mech::swing_point(m, phi).moment()));
      });
    if (metric == M::max_pressure_angle)
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
  Design<S> design(const opt::Values<S>& v) const {
    const Fixed& m = fixed_;
    Design<S> d{{{v[R::crank_length], v[R::coupler_length], v[R::rocker_length], v[R::frame_x], v[R::frame_y],
                  m.branch},
                 v[R::crank_speed],
                 v[R::rod_mass_per_length],
                 v[R::platform_mass],
                 S(m.platform_inertia),
                 S(m.platform_cg_radius),
                 S(m.friction_moment)}};
    if (synthesis(values())) {
      const auto syn = synthesized(values(), v);
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

  int cycle_points() const { return static_cast<int>(values()[R::cycle_points]); }

  Fixed fixed_;
};

}  // namespace

std::unique_ptr<opt::Problem> make_conveyor_swing(const opt::ConfigNode& root) {
  return opt::make_tabled<ConveyorSwing>(root, kTable);
}

const opt::Registered<ConveyorSwing> kRegistration{
    "conveyor_swing", "crank-rocker swing mechanism of a radial-rotary conveyor (seed 002)", kTable};

}  // namespace problems
