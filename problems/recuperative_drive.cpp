#include "problems/recuperative_drive.hpp"

#include <cmath>
#include <numbers>

#include "mech/twin_slider_crank.hpp"
#include "opt/parameters.hpp"
#include "opt/study.hpp"
#include "problems/model_problem.hpp"

namespace problems {
namespace {


// Ratio (r + |e|)/l kept at most this far from the dead point (ratio 1), where
// the rod can no longer reach the slider and velocities become unbounded.
constexpr double kMaxCrankRodRatio = 0.99;

// The model values: the rows of kTable; the defaults are seed 000's data at
// 100 rpm (the speed Table 1 was computed at; docs/reproduction.md).
struct R {
  enum Id : int {
    rod_length, phase_shift, crank_radius, offset, crank_speed, cart_mass, rod_mass_per_length, efficiency,
    cart_resistance, layout, resistance, kinematics, rod, cycle_points
  };
};

const std::vector<opt::Parameter> kTable = opt::table(
    "recuperative_drive",
    {
     {R::rod_length, variable("rod_length", Dimension::length, kPositive,
         "connecting-rod length l (l <= r + |e|: cannot_assemble)", "seed 000 eq. (1)"), 0.8},
     {R::phase_shift, variable("phase_shift", Dimension::angle, kAnyValue, "crank 2 leads crank 1 by this angle",
         "seed 000 eq. (9)"), std::numbers::pi / 2},
     {R::crank_radius, variable("crank_radius", Dimension::length, kPositive, "crank radius r", "seed 000 eq. (1)"),
         0.2},
     {R::offset, variable("offset", Dimension::length, kAnyValue, "offset e of both slider axes (seed 000: 0)", ""),
         0.0},
     {R::crank_speed, quantity("crank_speed", Dimension::angular_speed, kPositive,
         "crank speed w (Table 1 needs 100 rpm, not the printed 10.5 rad/s)", "seed 000 eq. (1)"),
         100 * std::numbers::pi / 30},
     {R::cart_mass, quantity("cart_mass", Dimension::mass, kPositive,
         "m, each cart (> 0: T_min = 4 m r^2 w^2 / pi^2 divides k2, k3)", "seed 000 eqs (9), (14)"), 1000},
     {R::rod_mass_per_length, quantity("rod_mass_per_length", Dimension::linear_density, kNonNegative, "q",
         "seed 000 eq. (10)"), 80},
     {R::efficiency, quantity("efficiency", Dimension::dimensionless, {0, 1, true, false},
         "eta of the crank-to-cart transmission", "seed 000 eq. (16)"), 0.9},
     {R::cart_resistance, quantity("cart_resistance", Dimension::force, kNonNegative, "F_B, the force to move one cart",
         "seed 000 eq. (16)"), 3562},
     {R::layout, choice("layout", {"opposed", "same_side"},
         "second slider mirrored (seed 000 eq. 2) or on the same side (seed 001 eq. 38)", "seed 000 eq. (2)"), 0},
     {R::resistance, choice("resistance", {"signed", "opposes_motion"},
         "F_B with the sign of the cart velocity (as printed), or always opposing the cart's motion",
         "seed 000 eq. (16)"), 0},
     {R::kinematics, choice("fidelity.kinematics", {"exact", "binomial"},
         "exact slider-crank, or the binomial series of seed 001 eqs (36)-(39)", "seed 000 eqs (1)-(8)"), 0},
     {R::rod, choice("fidelity.rod", {"point_masses", "full"},
         "rod as its mass at its centre, or with its rotational inertia q l^3/12 added",
         "seed 000 eq. (10)").fidelity({"point_masses", "full"}), 0},
     {R::cycle_points, whole("cycle_points", {4, 100000, false, false},
         "grid points per revolution; auto: 45/acosh(l/(r+|e|)), at least 16 (~1e-13 relative)", "").or_auto(), 0}
    });

// The metrics, in the order of kMetrics (their MetricIds).
struct M {
  enum Id : int {
    peak_kinetic_energy,
    mean_kinetic_energy,
    least_mean_kinetic_energy,
    k1,
    k2,
    k3,
    peak_crank_torque,
    mean_crank_torque,
    rms_crank_torque,
    crank_rod_ratio,
  };
};

const std::vector<MetricSpec> kMetrics = {
    {M::peak_kinetic_energy, "peak_kinetic_energy", "J"},        // T_max, eqs (11), (15)
    {M::mean_kinetic_energy, "mean_kinetic_energy", "J"},        // T_cp, eq. (12)
    {M::least_mean_kinetic_energy, "least_mean_kinetic_energy", "J"},  // T_min, eq. (14)
    {M::k1, "k1", ""},                          // T_max / T_cp, eq. (15)
    {M::k2, "k2", ""},                          // T_cp / T_min
    {M::k3, "k3", ""},                          // T_max / T_min
    {M::peak_crank_torque, "peak_crank_torque", "N m", "peak_total_moment"},        // max |M| over the cycle, eq. (21)
    {M::mean_crank_torque, "mean_crank_torque", "N m", "mean_total_moment"},
    {M::rms_crank_torque, "rms_crank_torque", "N m", "rms_total_moment"},
    {M::crank_rod_ratio, "crank_rod_ratio", ""},             // (r + |e|) / l
};

class RecuperativeDrive : public ModelProblem<RecuperativeDrive> {
 public:
  RecuperativeDrive(opt::Values<double> values, std::vector<opt::Variable> vars)
      : ModelProblem("recuperative_drive", kMetrics, kTable, std::move(values), std::move(vars)),
        cycle_points_(static_cast<int>(this->values()[R::cycle_points])) {}

  std::vector<opt::Constraint> implicit_constraints() const override {
    return {{"crank_rod_ratio", true, kMaxCrankRodRatio}};
  }

  nlohmann::json settings() const override {
    return {{"model", model_json()},
            {"numerics",
             {{"cycle_points", cycle_points_ ? nlohmann::json(cycle_points_)
                                                   : nlohmann::json("auto: 45/acosh(l/(r+|e|)), >= 16")},
              {"maximum", "grid bracket + Brent root of the angle derivative (autodiff)"},
              {"max_gradient", "Danskin: gradient at the maximising angle"}}},
            {"units", "SI (m, rad, rad/s, kg, N, J, N m)"}};
  }

  opt::CycleCurves cycle_curves(const Eigen::VectorXd& x, int n) const override {
    const auto d = drive(values_at(x));
    if (mech::check(d) != mech::Status::ok) return {};
    // The chart: the crank moments (the energy stays in cycle.csv).
    opt::CycleCurves c{{"crank_angle", "kinetic_energy", "total_moment", "inertia_moment", "static_moment"},
                       {"rad", "J", "N m", "N m", "N m"},
                       2};
    for (int i = 0; i <= n; ++i) {
      const double phi = mech::kTwoPi * i / n;
      const auto p = mech::drive_point(d, phi);
      c.add_row({phi, p.kinetic_energy, p.total_moment(), p.inertia_moment, p.static_moment});
    }
    return c;
  }

  std::vector<opt::MetricValue> local_maxima(const Eigen::VectorXd& x, opt::MetricId metric) const override {
    if (metric != M::peak_kinetic_energy && metric != M::peak_crank_torque) return {};
    const auto d = drive(values_at(x));
    if (mech::check(d) != mech::Status::ok) return {};
    auto model_at = [&](const auto& v) { return drive(v); };
    const int n = points(d);
    if (metric == M::peak_kinetic_energy)
      return cycle_local_maxima(x, n, model_at, [](const auto& dr, const auto& phi) {
        return std::decay_t<decltype(phi)>(mech::drive_point(dr, phi).kinetic_energy);
      });
    return cycle_local_maxima(x, n, model_at, [](const auto& dr, const auto& phi) {  // peak_crank_torque
      using std::abs;
      return std::decay_t<decltype(phi)>(abs(mech::drive_point(dr, phi).total_moment()));
    });
  }

  template <class S>
  int points(const mech::TwinDrive<S>& d) const {
    return cycle_points_ ? cycle_points_ : mech::auto_cycle_points(d);
  }

  template <class S>
  mech::TwinDrive<S> drive(const opt::Values<S>& v) const {
    const opt::Values<double>& c = values();
    return {v[R::crank_radius], v[R::rod_length], v[R::phase_shift], v[R::offset], v[R::crank_speed],
            v[R::cart_mass], v[R::rod_mass_per_length], v[R::efficiency], v[R::cart_resistance],
            static_cast<mech::Layout>(c[R::layout]), static_cast<mech::Kinematics>(c[R::kinematics]),
            static_cast<mech::RodModel>(c[R::rod]), static_cast<mech::Resistance>(c[R::resistance])};
  }

  // An evaluation's scratch: the values and the cycle computations' lists.
  struct Workspace : opt::ModelWorkspace {
    mech::CycleScratch cycle;
  };

  template <class S>
  void evaluate_model(const opt::Values<S>& v, MetricSink<S>& out, Workspace& ws) const {
    const mech::TwinDrive<S> d = drive(v);
    using std::abs;
    out.put(M::crank_rod_ratio, (d.crank_radius + abs(d.offset)) / d.rod_length);  // defined everywhere
    if (const mech::Status st = mech::check(d); st != mech::Status::ok) {
      out.result.status = st;
      return;
    }
    mech::CycleNeeds needs;
    needs.peak_energy = out.want_any(M::peak_kinetic_energy, M::k1, M::k3);
    needs.moments = out.want_any(M::peak_crank_torque, M::mean_crank_torque, M::rms_crank_torque);
    const bool need_cycle = needs.peak_energy || needs.moments ||
                            out.want_any(M::mean_kinetic_energy, M::k2);
    if (!need_cycle) {
      out.put(M::least_mean_kinetic_energy, mech::least_mean_kinetic_energy(d));
      return;
    }
    const int n = points(d);
    if (!needs.peak_energy && !needs.moments) {  // the fast path: the cycle mean alone
      const S mean = mech::mean_kinetic_energy(d, n);
      const S least = mech::least_mean_kinetic_energy(d);
      out.put(M::mean_kinetic_energy, mean);
      out.put(M::least_mean_kinetic_energy, least);
      out.put(M::k2, mean / least);
      return;
    }
    const auto m = mech::cycle_metrics(d, n, ws.cycle, needs);
    out.put(M::mean_kinetic_energy, m.mean_kinetic_energy);
    out.put(M::least_mean_kinetic_energy, m.least_mean_kinetic_energy);
    out.put(M::k2, m.k2);
    if (needs.peak_energy) {
      out.put(M::peak_kinetic_energy, m.peak_kinetic_energy);
      out.put(M::k1, m.k1);
      out.put(M::k3, m.k3);
    }
    if (needs.moments) {
      out.put(M::peak_crank_torque, m.peak_total_moment);
      out.put(M::mean_crank_torque, m.mean_total_moment);
      out.put(M::rms_crank_torque, m.rms_total_moment);
    }
  }

 private:
  int cycle_points_;  // 0: auto
};

}  // namespace

std::unique_ptr<opt::Problem> make_recuperative_drive(const opt::ConfigNode& root) {
  return opt::make_tabled<RecuperativeDrive>(root, kTable);
}

const opt::Registered<RecuperativeDrive> kRegistration{
    "recuperative_drive", "twin slider-crank recuperative drive of a roller forming installation (seed 000)", kTable};

}  // namespace problems
