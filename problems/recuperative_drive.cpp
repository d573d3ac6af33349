#include "problems/recuperative_drive.hpp"

#include <cmath>
#include <numbers>

#include "opt/study.hpp"

namespace problems {
namespace {

using opt::Dimension;

// Ratio (r + |e|)/l kept at most this far from the dead point (ratio 1), where
// the rod can no longer reach the slider and velocities become unbounded.
constexpr double kMaxCrankRodRatio = 0.99;

const std::vector<opt::VariableSpec> kVariables = {
    {"rod_length", Dimension::length},
    {"phase_shift", Dimension::angle},
    {"crank_radius", Dimension::length},
    {"offset", Dimension::length},
};

// name, unit
const std::vector<std::pair<std::string, std::string>> kMetrics = {
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

class RecuperativeDrive : public opt::Problem {
 public:
  RecuperativeDrive(RecuperativeDriveModel model, std::vector<opt::Variable> vars)
      : model_(std::move(model)), vars_(std::move(vars)) {}

  std::string name() const override { return "recuperative_drive"; }
  const std::vector<opt::Variable>& variables() const override { return vars_; }
  std::vector<std::string> metric_names() const override {
    std::vector<std::string> out;
    for (const auto& m : kMetrics) out.push_back(m.first);
    return out;
  }
  std::string metric_unit(const std::string& metric) const override {
    for (const auto& m : kMetrics)
      if (m.first == metric) return m.second;
    return "";
  }
  std::vector<opt::Constraint> implicit_constraints() const override {
    return {{"crank_rod_ratio", true, kMaxCrankRodRatio}};
  }

  opt::Evaluation evaluate(const Eigen::VectorXd& x, const std::vector<std::string>& wanted,
                           bool gradient) const override {
    if (!gradient) return evaluate_as<double>(x, wanted);
    switch (vars_.size()) {  // one derivative per variable
      case 1: return evaluate_as<mech::DualN<1>>(x, wanted);
      case 2: return evaluate_as<mech::DualN<2>>(x, wanted);
      case 3: return evaluate_as<mech::DualN<3>>(x, wanted);
      default: return evaluate_as<mech::DualN<4>>(x, wanted);
    }
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

 private:
  template <class S>
  opt::Evaluation evaluate_as(const Eigen::VectorXd& x, const std::vector<std::string>& wanted) const {
    mech::TwinDrive<S> d = model_.drive.template cast<S>();
    for (size_t i = 0; i < vars_.size(); ++i) {
      S v;
      if constexpr (mech::is_dual<S>) v = S(x[i], S::DerType::RowsAtCompileTime, static_cast<int>(i));
      else v = x[i];
      const std::string& n = vars_[i].name;
      if (n == "rod_length") d.rod_length = v;
      else if (n == "phase_shift") d.phase_shift = v;
      else if (n == "crank_radius") d.crank_radius = v;
      else d.offset = v;
    }
    auto want = [&](const char* m) {
      return wanted.empty() || std::find(wanted.begin(), wanted.end(), m) != wanted.end();
    };
    opt::Evaluation e;
    auto put = [&](const char* name, const S& v) {
      if (!want(name)) return;
      opt::MetricValue mv;
      mv.value = mech::value(v);
      if constexpr (mech::is_dual<S>) mv.gradient = v.derivatives();
      e.metrics[name] = mv;
    };
    using std::abs;
    put("crank_rod_ratio", (d.crank_radius + abs(d.offset)) / d.rod_length);  // defined everywhere
    if (const mech::Status st = mech::check(d); st != mech::Status::ok) {
      e.status = std::string(mech::to_string(st));
      return e;
    }
    mech::CycleNeeds needs;
    needs.peak_energy = want("peak_kinetic_energy") || want("k1") || want("k3");
    needs.moments = want("peak_total_moment") || want("mean_total_moment") || want("rms_total_moment");
    const bool need_cycle = needs.peak_energy || needs.moments || want("mean_kinetic_energy") ||
                            want("k2");
    if (!need_cycle) {
      put("least_mean_kinetic_energy", mech::least_mean_kinetic_energy(d));
      return e;
    }
    const int n = model_.cycle_points ? model_.cycle_points : mech::auto_cycle_points(d);
    if (!needs.peak_energy && !needs.moments) {  // the fast path: the cycle mean alone
      const S mean = mech::mean_kinetic_energy(d, n);
      const S least = mech::least_mean_kinetic_energy(d);
      put("mean_kinetic_energy", mean);
      put("least_mean_kinetic_energy", least);
      put("k2", mean / least);
      return e;
    }
    const auto m = mech::cycle_metrics(d, n, needs);
    put("mean_kinetic_energy", m.mean_kinetic_energy);
    put("least_mean_kinetic_energy", m.least_mean_kinetic_energy);
    put("k2", m.k2);
    if (needs.peak_energy) {
      put("peak_kinetic_energy", m.peak_kinetic_energy);
      put("k1", m.k1);
      put("k3", m.k3);
    }
    if (needs.moments) {
      put("peak_total_moment", m.peak_total_moment);
      put("mean_total_moment", m.mean_total_moment);
      put("rms_total_moment", m.rms_total_moment);
    }
    return e;
  }

  RecuperativeDriveModel model_;
  std::vector<opt::Variable> vars_;
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
  // Reads key into field if present and checks its domain.
  auto read = [&](const char* key, Dimension dim, double& field, double lo, bool lo_open,
                  double hi, const char* domain) {
    if (!n.has(key)) return;
    const opt::ConfigNode k = n.at(key);
    field = k.quantity(dim);
    if ((lo_open ? !(field > lo) : !(field >= lo)) || !(field <= hi))
      k.fail(std::string("expected a value in ") + domain + ", got '" + k.text() + "'");
  };
  const double inf = HUGE_VAL;
  read("crank_radius", Dimension::length, d.crank_radius, 0, true, inf, "(0, inf) m");
  read("rod_length", Dimension::length, d.rod_length, 0, true, inf, "(0, inf) m");
  read("offset", Dimension::length, d.offset, -inf, false, inf, "(-inf, inf) m");
  read("phase_shift", Dimension::angle, d.phase_shift, -inf, false, inf, "(-inf, inf) rad");
  read("crank_speed", Dimension::angular_speed, d.crank_speed, 0, true, inf, "(0, inf) rad/s");
  read("cart_mass", Dimension::mass, d.cart_mass, 0, false, inf, "[0, inf) kg");
  read("rod_mass_per_length", Dimension::linear_density, d.rod_mass_per_length, 0, false, inf,
       "[0, inf) kg/m");
  read("efficiency", Dimension::dimensionless, d.efficiency, 0, true, 1, "(0, 1]");
  read("cart_resistance", Dimension::force, d.cart_resistance, 0, false, inf, "[0, inf) N");
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

const std::vector<opt::VariableSpec>& recuperative_drive_variables() { return kVariables; }

std::unique_ptr<opt::Problem> make_recuperative_drive(const opt::ConfigNode& root) {
  RecuperativeDriveModel m = parse_recuperative_drive_model(root);
  const auto& d = m.drive;
  const std::map<std::string, double> values = {{"rod_length", d.rod_length},
                                                {"phase_shift", d.phase_shift},
                                                {"crank_radius", d.crank_radius},
                                                {"offset", d.offset}};
  auto vars = opt::parse_variables(root, kVariables, values);
  for (const auto& v : vars)
    if ((v.name == "rod_length" || v.name == "crank_radius") && !(v.lower > 0))
      root.at("variables").at(v.name).at("min").fail("expected a positive length");
  return std::make_unique<RecuperativeDrive>(std::move(m), std::move(vars));
}

}  // namespace problems
