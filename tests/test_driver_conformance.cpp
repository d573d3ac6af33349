// Driver conformance: every driver and algorithm on a shared table of
// problems with known optima, one test per pair. Each pair either converges
// (a tolerance met: Result::success) to the optimum within its algorithm
// class's tolerance and evaluation budget, or refuses the set-up with
// invalid_arguments, before any evaluation, when the algorithm cannot take
// the problem (constraints, gradients, dimension).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>

#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "problems/registry.hpp"
#include "test_problems.hpp"

namespace {

struct Case {
  std::string name;
  std::function<std::shared_ptr<opt::Problem>()> make;
  std::string objective;
  std::vector<opt::Constraint> constraints;
  double f_star;  // documented optimum
  const char* source;
};

std::shared_ptr<opt::Problem> from_yaml(const std::string& yaml) {
  return problems::make_problem(opt::ConfigNode::parse(yaml, "<conformance>"));
}

const std::vector<Case>& cases() {
  static const std::vector<Case> c = {
      {"nlopt_tutorial", [] { return std::make_shared<testing_problems::Analytic>(testing_problems::tutorial()); },
       "f", testing_problems::kTutorialConstraints, std::sqrt(8.0 / 27.0), "NLopt tutorial: sqrt(8/27)"},
      {"hs071", [] { return std::make_shared<testing_problems::Analytic>(testing_problems::hs071()); },
       "f", testing_problems::kHs071Constraints, 17.0140173, "Ipopt's HS071"},
      {"rosenbrock_bounded", [] { return std::make_shared<testing_problems::Analytic>(testing_problems::rosenbrock()); },
       "f", {}, 0.25, "closed form at the bound x = 0.5"},
      {"rod_length", [] {
         return from_yaml("problem: recuperative_drive\nvariables: {rod_length: {min: 0.5 m, max: 1.5 m}}\n");
       },
       "mean_kinetic_energy", {}, 2390.1336147556022, "tools/reference_seed000.json"},
      {"conveyor_l_co1", [] {
         return from_yaml("problem: conveyor_swing\nvariables: {l_co1: {min: 0.9 m, max: 2.4 m}}\n");
       },
       "peak_moment", {{"max_pressure_angle", true, 60 * M_PI / 180}}, 98310.834286910226,
       "tools/reference_seed002.json (a kink: two moment troughs equal)"},
  };
  return c;
}

struct Algo {
  std::string name;  // test name
  opt::DriverOptions options;
  double tol;        // relative error of f allowed for this class, and why
};

opt::DriverOptions nlopt(const std::string& a, int max_evaluations = 20000, double xtol_rel = 1e-10) {
  opt::DriverOptions o;
  o.algorithm = a;
  o.xtol_rel = xtol_rel;
  o.max_evaluations = max_evaluations;
  o.record_history = false;
  return o;
}

const std::vector<Algo>& algos() {
  static const std::vector<Algo> a = [] {
    std::vector<Algo> v;
    // Curvature-building local methods resolve f to ~1e-10; 1e-7 is margin.
    v.push_back({"LD_SLSQP", nlopt("LD_SLSQP"), 1e-7});
    v.push_back({"LD_LBFGS", nlopt("LD_LBFGS"), 1e-7});
    opt::DriverOptions ip;
    ip.library = "ipopt";
    ip.record_history = false;
    v.push_back({"ipopt", ip, 1e-7});
    // CCSA methods (MMA, CCSAQ) end just outside curved constraints, and
    // derivative-free methods stop on the step tolerance: 1e-5. Their step
    // tolerance is 1e-6: COBYLA's randomised simplex steps never meet 1e-8
    // on HS071 (it stops on the evaluation limit, f already within 1e-9).
    v.push_back({"LD_MMA", nlopt("LD_MMA"), 1e-5});
    v.push_back({"LD_CCSAQ", nlopt("LD_CCSAQ"), 1e-5});
    v.push_back({"LN_COBYLA", nlopt("LN_COBYLA", 20000, 1e-6), 1e-5});
    v.push_back({"LN_BOBYQA", nlopt("LN_BOBYQA", 20000, 1e-6), 1e-5});
    v.push_back({"LN_NEWUOA_BOUND", nlopt("LN_NEWUOA_BOUND", 20000, 1e-6), 1e-5});
    v.push_back({"LN_NELDERMEAD", nlopt("LN_NELDERMEAD", 20000, 1e-6), 1e-5});
    v.push_back({"LN_SBPLX", nlopt("LN_SBPLX", 20000, 1e-6), 1e-5});
    // Global searches hand over to a local polish (global-then-local).
    auto global = [](const std::string& g, int evals) {
      opt::DriverOptions o = nlopt(g, evals);
      o.polish = std::make_shared<opt::DriverOptions>(nlopt("LD_SLSQP"));
      return o;
    };
    v.push_back({"GN_DIRECT_L_then_SLSQP", global("GN_DIRECT_L", 500), 1e-7});
    v.push_back({"GN_DIRECT_then_SLSQP", global("GN_DIRECT", 500), 1e-7});
    v.push_back({"GN_ISRES_then_SLSQP", global("GN_ISRES", 2000), 1e-7});
    opt::DriverOptions mlsl = global("G_MLSL_LDS", 2000);
    mlsl.local_algorithm = "LD_SLSQP";
    v.push_back({"G_MLSL_LDS_then_SLSQP", mlsl, 1e-7});
    return v;
  }();
  return a;
}

using Pair = std::tuple<size_t, size_t>;
class Conformance : public ::testing::TestWithParam<Pair> {};

TEST_P(Conformance, ReachesTheDocumentedOptimumOrRefuses) {
  const Case& c = cases()[std::get<0>(GetParam())];
  const Algo& a = algos()[std::get<1>(GetParam())];
  const auto p = c.make();
  const auto driver = opt::make_driver(a.options);
  const auto r = driver->minimize(*p, {c.objective}, c.constraints, p->initial_point());
  // Which algorithm takes which problem is checked against NLopt's
  // documentation in test_driver_capabilities (test_nlopt_driver.cpp).
  const std::string why = opt::driver_incompatibility(a.options, *p, {c.objective}, c.constraints);
  if (!why.empty()) {
    EXPECT_EQ(r.status, opt::DriverStatus::invalid_arguments) << r.message;
    EXPECT_EQ(r.message, why);
    EXPECT_EQ(r.evaluations, 0) << "refused before any work";
    return;
  }
  ASSERT_TRUE(r.success()) << to_string(r.status) << ": " << r.message;
  EXPECT_NEAR(r.objective, c.f_star, a.tol * std::max(1.0, std::abs(c.f_star)))
      << c.source << "; " << r.message;
  for (size_t i = 0; i < c.constraints.size(); ++i)
    EXPECT_LE(c.constraints[i].violation(r.constraint_values[i]), 1e-6) << c.constraints[i].metric;
  EXPECT_GT(r.evaluations, 0);
  EXPECT_LE(r.evaluations, 60000) << "evaluation budget";
  RecordProperty("evaluations", r.evaluations);
}

std::vector<Pair> pairs() {
  std::vector<Pair> out;
  for (size_t i = 0; i < cases().size(); ++i)
    for (size_t j = 0; j < algos().size(); ++j) out.emplace_back(i, j);
  return out;
}

INSTANTIATE_TEST_SUITE_P(AllPairs, Conformance, ::testing::ValuesIn(pairs()), [](const auto& info) {
  return cases()[std::get<0>(info.param)].name + "__" + algos()[std::get<1>(info.param)].name;
});

}  // namespace
