// slider_crank: one slider-crank at constant crank speed (seed 000 eqs 1-8),
// sized for its stroke, the slider's peak acceleration and the rod's largest
// angle to the slider axis (the pressure angle). The smallest complete
// problem: its parameter table, metrics, evaluation on any scalar, and its
// registration; docs/adding-a-problem.md walks through it.
#include <cmath>

#include "mech/cycle.hpp"
#include "mech/slider_crank.hpp"
#include "opt/parameters.hpp"
#include "problems/model_problem.hpp"

namespace problems {
namespace {


// The model values: the rows of kTable.
struct R {
  enum Id : int { crank_radius, rod_length, offset, crank_speed, kinematics, cycle_points };
};

const std::vector<opt::Parameter> kTable = opt::table(
    "slider_crank",
    {{R::crank_radius, variable("crank_radius", Dimension::length, opt::kPositive, "r", "seed 000 eq. (1)"), 0.2},
     {R::rod_length, variable("rod_length", Dimension::length, opt::kPositive, "l (l <= r + |e|: cannot_assemble)",
         "seed 000 eq. (1)"), 0.8},
     {R::offset, variable("offset", Dimension::length, opt::kAnyValue, "e, the slider axis off the crank axis", ""),
         0.0},
     {R::crank_speed, quantity("crank_speed", Dimension::angular_speed, opt::kPositive, "w, constant",
         "seed 000 eq. (5)"), 100 * std::numbers::pi / 30},
     {R::kinematics, choice("kinematics", {"exact", "binomial"}, "exact, or the binomial series",
         "seed 001 eqs (36)-(39)"), 0},
     {R::cycle_points, whole("cycle_points", {8, 100000, false, false}, "grid points per revolution for the extrema",
         ""), 64}});

// The metrics, in the order of kMetrics (their MetricIds).
struct M {
  enum Id : int {
    stroke,
    peak_slider_acceleration,
    max_pressure_angle,
  };
};

const std::vector<MetricSpec> kMetrics = {
    {M::stroke, "stroke", "m"},                          // max x - min x over the cycle
    {M::peak_slider_acceleration, "peak_slider_acceleration", "m/s^2"},    // max |x''| w^2
    {M::max_pressure_angle, "max_pressure_angle", "rad"},            // max |asin(h / l)|, the rod against the slider axis
};

class SliderCrankProblem : public ModelProblem<SliderCrankProblem> {
 public:
  SliderCrankProblem(opt::Values<double> values, std::vector<opt::Variable> vars)
      : ModelProblem("slider_crank", kMetrics, kTable, std::move(values), std::move(vars)) {}

  nlohmann::json settings() const override {
    return {{"model", model_json()},
            {"numerics", {{"extrema", "grid bracket + Brent root of the angle derivative; Danskin gradients"}}}};
  }

  template <class S>
  void evaluate_model(const opt::Values<S>& v, MetricSink<S>& out) const {
    const mech::SliderCrank<S> k{v[R::crank_radius], v[R::rod_length], v[R::offset], 1,
                                 static_cast<mech::Kinematics>(values()[R::kinematics])};
    const int n = static_cast<int>(values()[R::cycle_points]);
    if (!mech::assembles_over_cycle(k)) {
      out.result.status = mech::Status::cannot_assemble;
      return;
    }
    // Each extremum at its refined angle (double), then valued with S there:
    // the gradient at a fixed maximising angle is the extremum's (Danskin).
    const mech::SliderCrank<double> kd{mech::value(k.r), mech::value(k.l), mech::value(k.e), 1, k.kinematics};
    const mech::SliderCrank<mech::Dual> kv{mech::Dual(kd.r), mech::Dual(kd.l), mech::Dual(kd.e), 1, k.kinematics};
    auto at = [&](const auto& f) {  // angle of the cycle maximum of f(model, phi)
      std::vector<double> grid(n);
      for (int i = 0; i < n; ++i) grid[i] = f(kd, mech::kTwoPi * i / n);
      return mech::global_max_angle(
          grid, [&](double phi) { return f(kd, phi); },
          [&](double phi) { return f(kv, mech::seed(phi)).d; });
    };
    // (Named points: GCC takes members of a temporary point for uninitialised.)
    auto position = [](const auto& m, const auto& phi) {
      const auto p = mech::slider_crank_point(m, phi);
      return p.x;
    };
    auto minus_position = [&](const auto& m, const auto& phi) {
      const auto x = position(m, phi);
      return decltype(x)(-x);  // a value: AutoDiff's -x is an expression on x
    };
    auto acceleration = [](const auto& m, const auto& phi) {
      using std::abs;
      const auto p = mech::slider_crank_point(m, phi);
      return decltype(p.ddx)(abs(p.ddx));
    };
    auto rod_slope = [](const auto& m, const auto& phi) {  // |h| / l = |sin(rod angle)|
      using std::abs;
      using std::sin;
      return decltype(m.r)(abs(m.r * sin(phi) + m.e) / m.l);
    };
    using std::asin;
    const S& w = v[R::crank_speed];
    if (out.want(M::stroke))
      out.put(M::stroke, position(k, S(at(position))) - position(k, S(at(minus_position))));
    if (out.want(M::peak_slider_acceleration))
      out.put(M::peak_slider_acceleration, acceleration(k, S(at(acceleration))) * w * w);
    if (out.want(M::max_pressure_angle)) out.put(M::max_pressure_angle, asin(rod_slope(k, S(at(rod_slope)))));
  }
};

const opt::Registered<SliderCrankProblem> kRegistration{
    "slider_crank", "one slider-crank sized for stroke, peak acceleration and pressure angle (seed 000)", kTable};

}  // namespace
}  // namespace problems
