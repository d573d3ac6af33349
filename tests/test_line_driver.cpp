// `library: line`: one variable, bounds only, Brent's method on the exact
// derivative. Against closed forms (the minimum of cos x on [2, 5] is at
// pi; of (x - 3)^2 on [0, 2] at the bound 2), the seed-000 rod-length
// optimum of tools/reference_seed000.json (mpmath), and its refusals, limits
// and failures, each a typed status.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "opt/drivers/line.hpp"
#include "opt/interrupt.hpp"
#include "opt/registry.hpp"
#include "test_problems.hpp"
#include "paths.hpp"

namespace {

using testing_problems::Analytic;

Analytic one_variable(std::function<double(double)> f, std::function<double(double)> df, double lo, double hi,
                      double x0) {
  return Analytic("line", {{"x", opt::Dimension::dimensionless, lo, hi, x0}},
                  {{"f", [f, df](const Eigen::VectorXd& x) {
                      return opt::MetricValue{f(x[0]), Eigen::VectorXd::Constant(1, df(x[0]))};
                    }}});
}

opt::DriverOptions line() {
  opt::DriverOptions o;
  o.library = "line";
  return o;
}

opt::Result minimize(const opt::Problem& p, opt::Objective objective = {"f"}, const opt::DriverOptions& o = line()) {
  return opt::make_driver(o)->minimize(p, objective, {}, p.initial_point());
}

TEST(LineDriver, InteriorMinimumToRoundoffInAHandfulOfEvaluations) {
  const auto p = one_variable([](double x) { return std::cos(x); }, [](double x) { return -std::sin(x); }, 2, 5, 2.5);
  const auto r = minimize(p);
  EXPECT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  EXPECT_NEAR(r.x[0], std::numbers::pi, 1e-12);
  EXPECT_NEAR(r.objective, -1, 1e-15);
  EXPECT_LE(r.evaluations, 12);
  EXPECT_EQ(r.library, "line");
}

TEST(LineDriver, MaximizeAndBoundMinimum) {
  // max cos x on [-1, 2] from 1.5: 0; min (x - 3)^2 on [0, 2]: the bound 2.
  const auto c = one_variable([](double x) { return std::cos(x); }, [](double x) { return -std::sin(x); }, -1, 2, 1.5);
  auto r = minimize(c, {"f", true});
  EXPECT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  EXPECT_NEAR(r.x[0], 0, 1e-12);
  const auto q = one_variable([](double x) { return (x - 3) * (x - 3); }, [](double x) { return 2 * (x - 3); }, 0, 2, 0.5);
  r = minimize(q);
  EXPECT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  EXPECT_EQ(r.x[0], 2);
  EXPECT_NE(r.message.find("on the bound"), std::string::npos) << r.message;
  EXPECT_EQ(r.evaluations, 2);
}

TEST(LineDriver, RodLengthOptimumAgainstTheReference) {
  std::ifstream in(std::string(MECHOPT_SOURCE_DIR) + "/tools/reference_seed000.json");
  const double reference = std::stod(nlohmann::json::parse(in)["rod_length_optimum"].get<std::string>());
  const auto p = opt::make_problem(opt::ConfigNode::parse(
      "problem: recuperative_drive\n"
      "model: {crank_radius: 0.2 m, crank_speed: 100 rpm, cart_mass: 1000 kg, rod_mass_per_length: 80 kg/m,\n"
      "        efficiency: 0.9, cart_resistance: 3562 N, phase_shift: 90 deg, rod_length: 0.8 m}\n"
      "variables: {rod_length: {min: 0.5 m, max: 1.5 m}}\n",
      "<rod>"));
  const auto r = opt::make_driver(line())->minimize(*p, {"mean_kinetic_energy"}, {}, p->initial_point());
  EXPECT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  EXPECT_NEAR(r.x[0] / reference, 1, 1e-12);
  EXPECT_LE(r.evaluations, 12);
}

TEST(LineDriver, RefusesWhatItCannotTakeBeforeAnyWork) {
  const auto two = testing_problems::rosenbrock();
  auto r = minimize(two);
  EXPECT_EQ(r.status, opt::DriverStatus::invalid_arguments);
  EXPECT_NE(r.message.find("line takes one variable"), std::string::npos) << r.message;
  EXPECT_EQ(r.evaluations, 0);
  const auto open = one_variable([](double x) { return x * x; }, [](double x) { return 2 * x; }, -HUGE_VAL, 1, 0.5);
  r = minimize(open);
  EXPECT_EQ(r.status, opt::DriverStatus::invalid_arguments);
  EXPECT_NE(r.message.find("needs finite bounds"), std::string::npos) << r.message;
  const auto p = one_variable([](double x) { return x * x; }, [](double x) { return 2 * x; }, -1, 1, 0.5);
  r = opt::make_driver(line())->minimize(p, {"f"}, {{"f", true, 0.1}}, p.initial_point());
  EXPECT_EQ(r.status, opt::DriverStatus::invalid_arguments);
  EXPECT_NE(r.message.find("line takes no constraints"), std::string::npos) << r.message;
  // The config reader says so too, at the driver.
  const auto root = opt::ConfigNode::parse(
      "problem: slider_crank\nvariables: {crank_radius: {min: 0.1 m, max: 0.3 m}, rod_length: {min: 0.5 m, max: 1 m}}\n"
      "objective: {minimize: peak_slider_acceleration}\nstudy: {type: optimize, driver: {library: line}}\n",
      "<two>");
  const auto sc = opt::make_problem(root);
  try {
    opt::parse_run(root, *sc);
    FAIL() << "no error";
  } catch (const opt::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("key 'study.driver': line takes one variable"), std::string::npos) << e.what();
  }
}

TEST(LineDriver, LimitsAndFailuresAreStatuses) {
  const auto p = one_variable([](double x) { return std::cos(x); }, [](double x) { return -std::sin(x); }, 2, 5, 2.5);
  opt::DriverOptions o = line();
  o.max_evaluations = 3;
  auto r = minimize(p, {"f"}, o);
  EXPECT_EQ(r.status, opt::DriverStatus::max_evaluations) << r.message;
  EXPECT_TRUE(std::isfinite(r.objective)) << "the best design so far, evaluated";
  // A model that fails inside the bracket: a failure naming where.
  const auto hole = one_variable(
      [](double x) { return x > 3 && x < 3.3 ? std::nan("") : std::cos(x); },
      [](double x) { return x > 3 && x < 3.3 ? std::nan("") : -std::sin(x); }, 2, 5, 2.5);
  r = minimize(hole);
  EXPECT_EQ(r.status, opt::DriverStatus::failure) << r.message;
  EXPECT_NE(r.message.find("cannot be evaluated at"), std::string::npos) << r.message;
  EXPECT_GT(r.infeasible_evaluations, 0);
  // A stop request before the run.
  opt::request_stop();
  r = minimize(p);
  opt::clear_stop();
  EXPECT_EQ(r.status, opt::DriverStatus::interrupted) << r.message;
}

}  // namespace

namespace {

// f = x^4 - 2 x^2 has minima at -1 and 1 and a maximum at 0. From -0.9
// downhill is toward -1 (the derivative 4x^3 - 4x is positive there): the
// minimum at -1. From 0.05 (derivative negative) downhill is toward 1: the
// minimum at 1. Never the maximum between them.
TEST(LineDriver, TheMinimumDownhillFromTheStart) {
  auto f = [](double x) { return x * x * x * x - 2 * x * x; };
  auto df = [](double x) { return 4 * x * x * x - 4 * x; };
  for (const auto& [x0, expected] : {std::pair{-0.9, -1.0}, {0.05, 1.0}, {1.4, 1.0}}) {
    const auto p = one_variable(f, df, -1.5, 1.5, x0);
    const auto r = minimize(p);
    EXPECT_EQ(r.status, opt::DriverStatus::converged) << x0 << ": " << r.message;
    EXPECT_NEAR(r.x[0], expected, 1e-12) << x0;
  }
}

}  // namespace
