#include "problems/conveyor_swing.hpp"
#include "problems/registry.hpp"

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

// The config's values (SI); `mech` is derived from them by derive().
struct Model {
  int design = 0;                    // 0 synthesis, 1 free_links
  double gx = 1.0, gy = 2.2;         // a, b
  double swing_angle = 32 * std::numbers::pi / 180;  // 2 theta
  double axis_angle = 0;             // mid-swing axis O1C direction
  double coupler_offset = 1.0;       // l_CB
  double l_co1 = 1.2;
  double crank = 0, coupler = 0, rocker = 0;  // 0 (auto): from the synthesis at l_co1
  int branch = 0;                    // 0 (auto): from the synthesis; 1: +1; 2: -1
  double crank_speed = 12, rod_mass_per_length = 200, platform_mass = 3200;
  double cg_along = 1.2, cg_across = 1.0;
  double platform_inertia = 0;       // 0 (auto): eq. (11), m3 d^2
  double friction = 0.01, bearing_diameter = 0.3, platform_weight = 32000;
  int cycle_points = 48;
  mech::SwingMechanism<double> mech;
  bool synthesis() const { return design == 0; }
  double half_swing() const { return swing_angle / 2; }
};


// The variables first, in the order of the switch in design().
const opt::ParameterTable<Model> kTable = {
    {variable("l_co1", Dimension::length, kPositive, "l_CO1, distance of C from O1 along the axis (design: synthesis)",
              "seed 002 eq. (3)"),
     MECHOPT_STORED_AT(m.l_co1)},
    {variable("crank_length", Dimension::length, kPositive, "l1 (design: free_links); auto: the synthesis at l_co1",
              "seed 002 eq. (2)").or_auto(),
     MECHOPT_STORED_AT(m.crank)},
    {variable("coupler_length", Dimension::length, kPositive, "l2 (design: free_links); auto: the synthesis at l_co1",
              "seed 002 eq. (2)").or_auto(),
     MECHOPT_STORED_AT(m.coupler)},
    {variable("rocker_length", Dimension::length, kPositive, "l3 (design: free_links); auto: hypot(l_co1, coupler_offset)",
              "seed 002 eq. (3)").or_auto(),
     MECHOPT_STORED_AT(m.rocker)},
    {choice("design", {"synthesis", "free_links"}, "the paper's family (l1, l2, l3 from l_co1) or free link lengths",
            "seed 002 eqs (2)-(3)"),
     MECHOPT_STORED_AT(m.design)},
    {quantity("frame_x", Dimension::length, kAnyValue, "a: the crank pivot O from O1 (l4 = hypot(a, b); not both 0)",
              "seed 002 eq. (1)"),
     MECHOPT_STORED_AT(m.gx)},
    {quantity("frame_y", Dimension::length, kAnyValue, "b: the crank pivot O from O1", "seed 002 eq. (1)"),
     MECHOPT_STORED_AT(m.gy)},
    {quantity("swing_angle", Dimension::angle, {0, std::numbers::pi, true, true}, "2 theta, the rocker's swing (synthesis)",
              "seed 002 eq. (2)"),
     MECHOPT_STORED_AT(m.swing_angle)},
    {quantity("axis_angle", Dimension::angle, kAnyValue, "direction of the mid-swing axis O1C (parallel to a)", ""),
     MECHOPT_STORED_AT(m.axis_angle)},
    {quantity("coupler_offset", Dimension::length, kAnyValue, "l_CB: B off the axis toward O; l3 = hypot(l_CO1, l_CB)",
              "seed 002 eq. (3)"),
     MECHOPT_STORED_AT(m.coupler_offset)},
    {choice("branch", {"auto", "1", "-1"}, "assembly branch: B left or right of the line O1-A; auto: the synthesis'", ""),
     MECHOPT_STORED_AT(m.branch)},
    {quantity("crank_speed", Dimension::angular_speed, kPositive, "w1, constant", "seed 002 (w1 = 12 rad/s)"),
     MECHOPT_STORED_AT(m.crank_speed)},
    {quantity("rod_mass_per_length", Dimension::linear_density, kNonNegative, "m_n of crank and coupler", "seed 002 eq. (10)"),
     MECHOPT_STORED_AT(m.rod_mass_per_length)},
    {quantity("platform_mass", Dimension::mass, kNonNegative, "m3", "seed 002 eq. (11)"),
     MECHOPT_STORED_AT(m.platform_mass)},
    {quantity("platform_cg_along", Dimension::length, kAnyValue, "d: the platform's centre of mass from O1, along the axis",
              "seed 002 eq. (11)"),
     MECHOPT_STORED_AT(m.cg_along)},
    {quantity("platform_cg_across", Dimension::length, kAnyValue, "c: the platform's centre of mass, across the axis",
              "seed 002 eq. (11)"),
     MECHOPT_STORED_AT(m.cg_across)},
    {quantity("platform_inertia", Dimension::inertia, kPositive, "J_s3 about the centre of mass; auto: m3 d^2",
              "seed 002 eq. (11)").or_auto(),
     MECHOPT_STORED_AT(m.platform_inertia)},
    {quantity("friction_coefficient", Dimension::dimensionless, kNonNegative, "f of M_c = f G D / 2", "seed 002 eq. (7)"),
     MECHOPT_STORED_AT(m.friction)},
    {quantity("bearing_diameter", Dimension::length, kNonNegative, "D of M_c = f G D / 2", "seed 002 eq. (7)"),
     MECHOPT_STORED_AT(m.bearing_diameter)},
    {quantity("platform_weight", Dimension::force, kNonNegative, "G of M_c = f G D / 2", "seed 002 eq. (7)"),
     MECHOPT_STORED_AT(m.platform_weight)},
    {whole("cycle_points", {8, 100000, false, false}, "grid points per revolution for maxima and kinks", ""),
     MECHOPT_STORED_AT(m.cycle_points)},
};

// The mechanism from the config's values: the synthesis at l_co1 gives the
// link lengths and branch left at auto (eqs 2-3); inertia (11) and the
// friction moment (7).
void derive(Model& m) {
  const auto syn = mech::synthesize_crank_rocker<double>(m.gx, m.gy, m.l_co1, m.coupler_offset,
                                                         m.axis_angle, m.half_swing());
  mech::FourBar<double> k = syn.linkage;
  if (m.crank > 0) k.crank = m.crank;
  if (m.coupler > 0) k.coupler = m.coupler;
  if (m.rocker > 0) k.rocker = m.rocker;
  if (m.branch != 0) k.branch = m.branch == 1 ? 1 : -1;
  m.crank = k.crank, m.coupler = k.coupler, m.rocker = k.rocker;
  const double inertia = m.platform_inertia > 0 ? m.platform_inertia : m.platform_mass * m.cg_along * m.cg_along;
  m.mech = {k, m.crank_speed, m.rod_mass_per_length, m.platform_mass, inertia,
            std::hypot(m.cg_along, m.cg_across), m.friction * m.platform_weight * m.bearing_diameter / 2};
}

class ConveyorSwing : public ModelProblem<ConveyorSwing> {
 public:
  ConveyorSwing(Model model, std::vector<opt::Variable> vars)
      : ModelProblem("conveyor_swing", kMetrics, std::move(vars)), model_(std::move(model)),
        slots_(opt::variable_rows(kTable, variables())) {}

  std::vector<opt::Constraint> implicit_constraints() const override {
    std::vector<opt::Constraint> c = {{"rotation_margin", false, kMinMargin}};
    if (model_.synthesis()) c.push_back({"synthesis_margin", false, kMinMargin});
    return c;
  }

  nlohmann::json settings() const override {
    const auto& m = model_.mech;
    nlohmann::json model = opt::parameters_json(opt::parameters(kTable, model_));
    model["derived"] = {{"branch", m.linkage.branch}, {"platform_inertia", m.platform_inertia},
                        {"platform_cg_radius", m.platform_cg_radius}, {"friction_moment", m.friction_moment}};
    return {{"model", model},
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
    if (model_.synthesis()) out.put(M::synthesis_margin, d.synthesis_margin);
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
    const auto r = mech::swing_metrics(d.mech, model_.cycle_points, means);
    out.put(M::peak_crank_torque, r.peak_moment);
    if (means) {
      out.put(M::mean_abs_crank_torque, r.mean_abs_moment);
      out.put(M::rms_crank_torque, r.rms_moment);
    }
    out.put(M::max_pressure_angle, r.max_pressure_angle);
  }

  opt::CycleCurves cycle_curves(const Eigen::VectorXd& x, int n) const override {
    const Design<double> d = design(std::vector<double>(x.data(), x.data() + x.size()));
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
    const Design<double> d = design(std::vector<double>(x.data(), x.data() + x.size()));
    if (d.status() != mech::Status::ok) return {};
    auto model_at = [&](const auto& xs) { return design(xs).mech; };
    const int n = mech::swing_grid_points(mech::toggle_poles(d.mech.linkage), model_.cycle_points);  // swing_metrics' grid
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
  Design<S> design(const std::vector<S>& x) const {
    Design<S> d{model_.mech.template cast<S>()};
    S l_co1(model_.l_co1);
    for (size_t i = 0; i < x.size(); ++i) {
      switch (slots_[i]) {  // rows of kTable
        case 0: l_co1 = x[i]; break;
        case 1: d.mech.linkage.crank = x[i]; break;
        case 2: d.mech.linkage.coupler = x[i]; break;
        default: d.mech.linkage.rocker = x[i];
      }
    }
    if (model_.synthesis()) {
      const auto syn = mech::synthesize_crank_rocker<S>(S(model_.gx), S(model_.gy), l_co1,
                                                        S(model_.coupler_offset), model_.axis_angle,
                                                        S(model_.half_swing()));
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
  std::vector<int> slots_;  // table row of each variable
};

}  // namespace

std::unique_ptr<opt::Problem> make_conveyor_swing(const opt::ConfigNode& root) {
  Model m;
  opt::read_parameters(root, kTable, m);
  if (!(std::hypot(m.gx, m.gy) > 0))
    root.at("model").fail("frame_x and frame_y place the crank pivot on the rocker pivot");
  derive(m);
  auto vars = opt::parse_variables(root, opt::parameters(kTable, m));
  for (const auto& v : vars) {
    const bool synthesis_var = v.name == "l_co1";
    if (synthesis_var != m.synthesis())
      root.at("variables").at(v.name).fail(
          std::string("variable '") + v.name + "' belongs to design: " +
          (synthesis_var ? "synthesis" : "free_links") + ", but the model has design: " +
          (m.synthesis() ? "synthesis" : "free_links"));
  }
  return std::make_unique<ConveyorSwing>(std::move(m), std::move(vars));
}

const Registration kRegistration{
    {"conveyor_swing", "crank-rocker swing mechanism of a radial-rotary conveyor (seed 002)",
     opt::parameters(kTable, Model{}), make_conveyor_swing}};

}  // namespace problems
