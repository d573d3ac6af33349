#include "problems/recuperative_drive.hpp"
#include "problems/registry.hpp"

#include <cmath>
#include <numbers>

#include "opt/study.hpp"
#include "problems/model_problem.hpp"

namespace problems {
namespace {

using opt::Dimension;

// Ratio (r + |e|)/l kept at most this far from the dead point (ratio 1), where
// the rod can no longer reach the slider and velocities become unbounded.
constexpr double kMaxCrankRodRatio = 0.99;

const std::vector<opt::VariableSpec> kVariables = {
    {"rod_length", Dimension::length, opt::kPositive},
    {"phase_shift", Dimension::angle},
    {"crank_radius", Dimension::length, opt::kPositive},
    {"offset", Dimension::length},
};

const std::vector<MetricSpec> kMetrics = {
    {"peak_kinetic_energy", "J"},        // T_max, eqs (11), (15)
    {"mean_kinetic_energy", "J"},        // T_cp, eq. (12)
    {"least_mean_kinetic_energy", "J"},  // T_min, eq. (14)
    {"k1", ""},                          // T_max / T_cp, eq. (15)
    {"k2", ""},                          // T_cp / T_min
    {"k3", ""},                          // T_max / T_min
    {"peak_total_moment", "N m"},        // max |M| over the cycle, eq. (21)
    {"mean_total_moment", "N m"},
    {"rms_total_moment", "N m"},
    {"crank_rod_ratio", ""},             // (r + |e|) / l
};

class RecuperativeDrive : public ModelProblem<RecuperativeDrive> {
 public:
  RecuperativeDrive(RecuperativeDriveModel model, std::vector<opt::Variable> vars)
      : ModelProblem("recuperative_drive", kMetrics, std::move(vars)), model_(std::move(model)) {}

  std::vector<opt::Constraint> implicit_constraints() const override {
    return {{"crank_rod_ratio", true, kMaxCrankRodRatio}};
  }

  nlohmann::json settings() const override {
    const auto& d = model_.drive;
    return {{"model",
             {{"crank_radius", d.crank_radius}, {"rod_length", d.rod_length},
              {"phase_shift", d.phase_shift}, {"offset", d.offset},
              {"crank_speed", d.crank_speed}, {"cart_mass", d.cart_mass},
              {"rod_mass_per_length", d.rod_mass_per_length}, {"efficiency", d.efficiency},
              {"cart_resistance", d.cart_resistance},
              {"layout", d.layout == mech::Layout::opposed ? "opposed" : "same_side"},
              {"resistance", d.resistance == mech::Resistance::signed_velocity ? "signed"
                                                                                : "opposes_motion"}}},
            {"fidelity",
             {{"kinematics", d.kinematics == mech::Kinematics::exact ? "exact" : "binomial"},
              {"rod", d.rod == mech::RodModel::full ? "full" : "point_masses"}}},
            {"numerics",
             {{"cycle_points", model_.cycle_points ? nlohmann::json(model_.cycle_points)
                                                   : nlohmann::json("auto: 45/acosh(l/(r+|e|)), >= 16")},
              {"maximum", "grid bracket + Brent root of the angle derivative (autodiff)"},
              {"max_gradient", "Danskin: gradient at the maximising angle"}}},
            {"units", "SI (m, rad, rad/s, kg, N, J, N m)"}};
  }

  opt::CycleCurves cycle_curves(const Eigen::VectorXd& x, int n) const override {
    const auto d = drive(std::vector<double>(x.data(), x.data() + x.size()));
    if (mech::check(d) != mech::Status::ok) return {};
    opt::CycleCurves c{{"crank_angle", "kinetic_energy", "total_moment", "inertia_moment",
                        "static_moment"}, {}};
    for (int i = 0; i <= n; ++i) {
      const double phi = mech::kTwoPi * i / n;
      const auto p = mech::drive_point(d, phi);
      c.add_row({phi, p.kinetic_energy, p.total_moment(), p.inertia_moment, p.static_moment});
    }
    return c;
  }

  std::vector<opt::MetricValue> local_maxima(const Eigen::VectorXd& x,
                                             const std::string& metric) const override {
    const auto d = drive(std::vector<double>(x.data(), x.data() + x.size()));
    if (mech::check(d) != mech::Status::ok) return {};
    auto model_at = [&](const auto& xs) { return drive(xs); };
    const int n = points(d);
    if (metric == "peak_kinetic_energy")
      return cycle_local_maxima(x, n, model_at, [](const auto& dr, const auto& phi) {
        return std::decay_t<decltype(phi)>(mech::drive_point(dr, phi).kinetic_energy);
      });
    if (metric == "peak_total_moment")
      return cycle_local_maxima(x, n, model_at, [](const auto& dr, const auto& phi) {
        using std::abs;
        return std::decay_t<decltype(phi)>(abs(mech::drive_point(dr, phi).total_moment()));
      });
    return {};
  }

  template <class S>
  int points(const mech::TwinDrive<S>& d) const {
    return model_.cycle_points ? model_.cycle_points : mech::auto_cycle_points(d);
  }

  template <class S>
  mech::TwinDrive<S> drive(const std::vector<S>& x) const {
    mech::TwinDrive<S> d = model_.drive.template cast<S>();
    for (size_t i = 0; i < x.size(); ++i) {
      const std::string& n = variables()[i].name;
      if (n == "rod_length") d.rod_length = x[i];
      else if (n == "phase_shift") d.phase_shift = x[i];
      else if (n == "crank_radius") d.crank_radius = x[i];
      else d.offset = x[i];
    }
    return d;
  }

  template <class S>
  void evaluate_model(const std::vector<S>& x, MetricSink<S>& out) const {
    const mech::TwinDrive<S> d = drive(x);
    using std::abs;
    out.put("crank_rod_ratio", (d.crank_radius + abs(d.offset)) / d.rod_length);  // defined everywhere
    if (const mech::Status st = mech::check(d); st != mech::Status::ok) {
      out.result.status = std::string(mech::to_string(st));
      return;
    }
    mech::CycleNeeds needs;
    needs.peak_energy = out.want_any("peak_kinetic_energy", "k1", "k3");
    needs.moments = out.want_any("peak_total_moment", "mean_total_moment", "rms_total_moment");
    const bool need_cycle = needs.peak_energy || needs.moments ||
                            out.want_any("mean_kinetic_energy", "k2");
    if (!need_cycle) {
      out.put("least_mean_kinetic_energy", mech::least_mean_kinetic_energy(d));
      return;
    }
    const int n = points(d);
    if (!needs.peak_energy && !needs.moments) {  // the fast path: the cycle mean alone
      const S mean = mech::mean_kinetic_energy(d, n);
      const S least = mech::least_mean_kinetic_energy(d);
      out.put("mean_kinetic_energy", mean);
      out.put("least_mean_kinetic_energy", least);
      out.put("k2", mean / least);
      return;
    }
    const auto m = mech::cycle_metrics(d, n, needs);
    out.put("mean_kinetic_energy", m.mean_kinetic_energy);
    out.put("least_mean_kinetic_energy", m.least_mean_kinetic_energy);
    out.put("k2", m.k2);
    if (needs.peak_energy) {
      out.put("peak_kinetic_energy", m.peak_kinetic_energy);
      out.put("k1", m.k1);
      out.put("k3", m.k3);
    }
    if (needs.moments) {
      out.put("peak_total_moment", m.peak_total_moment);
      out.put("mean_total_moment", m.mean_total_moment);
      out.put("rms_total_moment", m.rms_total_moment);
    }
  }

 private:
  RecuperativeDriveModel model_;
};

}  // namespace

RecuperativeDriveModel parse_recuperative_drive_model(const opt::ConfigNode& root) {
  RecuperativeDriveModel m;
  auto& d = m.drive;
  // Seed 000 data at 100 rpm (the speed Table 1 was computed at; see docs/reproduction.md).
  d = {0.2, 0.8, std::numbers::pi / 2, 0.0, 100 * std::numbers::pi / 30, 1000, 80, 0.9, 3562};
  if (!root.has("model")) return m;
  const opt::ConfigNode n = root.at("model");
  n.allow_only({"crank_radius", "crank_speed", "cart_mass", "rod_mass_per_length", "efficiency",
                "cart_resistance", "phase_shift", "rod_length", "offset", "layout", "fidelity",
                "resistance", "cycle_points"});
  d.crank_radius = n.quantity_or("crank_radius", Dimension::length, d.crank_radius, opt::kPositive);
  d.rod_length = n.quantity_or("rod_length", Dimension::length, d.rod_length, opt::kPositive);
  d.offset = n.quantity_or("offset", Dimension::length, d.offset);
  d.phase_shift = n.quantity_or("phase_shift", Dimension::angle, d.phase_shift);
  d.crank_speed = n.quantity_or("crank_speed", Dimension::angular_speed, d.crank_speed, opt::kPositive);
  // > 0: T_min = 4 m r^2 w^2 / pi^2 (eq. 14) divides k2 and k3.
  d.cart_mass = n.quantity_or("cart_mass", Dimension::mass, d.cart_mass, opt::kPositive);
  d.rod_mass_per_length = n.quantity_or("rod_mass_per_length", Dimension::linear_density,
                                        d.rod_mass_per_length, opt::kNonNegative);
  d.efficiency = n.quantity_or("efficiency", Dimension::dimensionless, d.efficiency, {0, 1, true, false});
  d.cart_resistance = n.quantity_or("cart_resistance", Dimension::force, d.cart_resistance,
                                    opt::kNonNegative);
  if (n.has("layout"))
    d.layout = n.at("layout").choice({"opposed", "same_side"}) == "opposed" ? mech::Layout::opposed
                                                                            : mech::Layout::same_side;
  if (n.has("resistance"))
    d.resistance = n.at("resistance").choice({"signed", "opposes_motion"}) == "signed"
                       ? mech::Resistance::signed_velocity
                       : mech::Resistance::opposes_motion;
  if (n.has("fidelity")) {
    const opt::ConfigNode f = n.at("fidelity");
    f.allow_only({"kinematics", "rod"});
    if (f.has("kinematics"))
      d.kinematics = f.at("kinematics").choice({"exact", "binomial"}) == "exact"
                         ? mech::Kinematics::exact
                         : mech::Kinematics::binomial;
    if (f.has("rod"))
      d.rod = f.at("rod").choice({"point_masses", "full"}) == "full" ? mech::RodModel::full
                                                                      : mech::RodModel::point_masses;
  }
  if (n.has("cycle_points") && n.at("cycle_points").text() != "auto")
    m.cycle_points = n.at("cycle_points").integer(4, 100000);
  return m;
}

std::unique_ptr<opt::Problem> make_recuperative_drive(const opt::ConfigNode& root) {
  RecuperativeDriveModel m = parse_recuperative_drive_model(root);
  const auto& d = m.drive;
  const std::map<std::string, double> values = {{"rod_length", d.rod_length},
                                                {"phase_shift", d.phase_shift},
                                                {"crank_radius", d.crank_radius},
                                                {"offset", d.offset}};
  auto vars = opt::parse_variables(root, kVariables, values);
  return std::make_unique<RecuperativeDrive>(std::move(m), std::move(vars));
}

const Registration kRegistration{
    {"recuperative_drive", "twin slider-crank recuperative drive of a roller forming installation (seed 000)", kVariables, make_recuperative_drive}};

}  // namespace problems
