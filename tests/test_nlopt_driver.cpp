// The NLopt driver on NLopt's own tutorial problem (documented optimum
// sqrt(8/27) at x = (1/3, 8/27)), plus its failure paths.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "opt/driver.hpp"
#include "opt/drivers/ipopt.hpp"
#include "opt/drivers/line.hpp"
#include "opt/drivers/nlopt.hpp"
#include "opt/stationarity.hpp"
#include "test_problems.hpp"

namespace {

using Tutorial = testing_problems::Analytic;
const auto& kCons = testing_problems::kTutorialConstraints;

class TutorialByAlgorithm : public ::testing::TestWithParam<const char*> {};

TEST_P(TutorialByAlgorithm, FindsTheDocumentedOptimum) {
  opt::DriverOptions o;
  o.algorithm = GetParam();
  o.xtol_rel = 1e-8;
  const Tutorial p = testing_problems::tutorial();
  const auto r = opt::NloptDriver(o).minimize(p, {"f"}, kCons, p.initial_point());
  ASSERT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  // NLopt's tutorial reports the minimum 0.544331053951817 = sqrt(8/27).
  // SLSQP lands within 1e-8; COBYLA (no derivatives) and the CCSA family
  // MMA and CCSAQ (which end just outside the curved constraint, measured
  // 5e-8 and 2e-8 below f*) within 1e-6.
  const std::string alg = GetParam();
  const double tol = alg == "LD_SLSQP" ? 1e-8 : 1e-6;
  EXPECT_NEAR(r.objective, std::sqrt(8.0 / 27.0), tol);
  EXPECT_NEAR(r.x[0], 1.0 / 3.0, 1e-5);
  EXPECT_GT(r.evaluations, 3);
  EXPECT_EQ(r.history.size(), static_cast<size_t>(r.evaluations));
}

INSTANTIATE_TEST_SUITE_P(Nlopt, TutorialByAlgorithm,
                         ::testing::Values("LD_MMA", "LD_SLSQP", "LN_COBYLA", "LD_CCSAQ"));

TEST(NloptDriver, ExceptionInCallbackIsRethrownAfterTheSolverReturns) {
  Tutorial p = testing_problems::tutorial();
  p.throws = true;
  EXPECT_THROW(opt::NloptDriver(opt::DriverOptions{}).minimize(p, {"f"}, kCons, p.initial_point()),
               std::runtime_error);
}

TEST(NloptDriver, BoundOnlyAlgorithmRejectsMetricConstraints) {
  opt::DriverOptions o;
  o.algorithm = "LN_BOBYQA";
  const Tutorial p = testing_problems::tutorial();
  const auto r = opt::NloptDriver(o).minimize(p, {"f"}, kCons, p.initial_point());
  EXPECT_EQ(r.status, opt::DriverStatus::invalid_arguments);
  EXPECT_EQ(r.message.rfind("LN_BOBYQA takes no inequality constraints (c1 <= 0)", 0), 0u) << r.message;
  EXPECT_EQ(r.evaluations, 0);
  EXPECT_EQ(r.x, p.initial_point()) << "an early return leaves the start point";
}

TEST(NloptDriver, EvaluationLimitIsAStatus) {
  opt::DriverOptions o;
  o.algorithm = "LN_COBYLA";
  o.max_evaluations = 5;
  const Tutorial p = testing_problems::tutorial();
  const auto r = opt::NloptDriver(o).minimize(p, {"f"}, kCons, p.initial_point());
  EXPECT_EQ(r.status, opt::DriverStatus::max_evaluations);
  EXPECT_EQ(r.evaluations, 5);
  EXPECT_FALSE(r.success()) << "a limit reached is not a converged optimum";
  EXPECT_TRUE(r.stopped());
  EXPECT_EQ(r.message.rfind("stopped on the evaluation limit (max_evaluations 5) before converging", 0), 0u)
      << r.message;
}

// f = offset + cosh(x - 0.3) + cosh(y + 0.2) on [-1, 1]^2 (not a quadratic,
// which SLSQP would solve in one step): the minimum is (0.3, -0.2). The driver stops a local run where the gradient is zero to
// roundoff; that stop must come at the minimum, not before it, whatever
// the offset: with offset 1e6 the value resolves x only to ~1e-5, the
// gradient to ~1e-16, and a stop scaled by |f| alone would end 5e-9 off.
testing_problems::Analytic offset_bowl(double offset) {
  return testing_problems::Analytic(
      "offset_bowl",
      {{"x", opt::Dimension::dimensionless, -1, 1, 0.9}, {"y", opt::Dimension::dimensionless, -1, 1, 0.7}},
      {{"f", [offset](const Eigen::VectorXd& v) {
          const double a = v[0] - 0.3, b = v[1] + 0.2;
          return opt::MetricValue{offset + std::cosh(a) + std::cosh(b), Eigen::Vector2d(std::sinh(a), std::sinh(b))};
        }}});
}

TEST(NloptDriver, RoundoffStopEndsAtTheMinimumNotBeforeIt) {
  for (const double offset : {1.0, 1e6}) {
    opt::DriverOptions o;
    o.algorithm = "LD_SLSQP";
    o.xtol_rel = 1e-14;
    const auto p = offset_bowl(offset);
    const auto r = opt::NloptDriver(o).minimize(p, {"f"}, {}, p.initial_point());
    ASSERT_EQ(r.status, opt::DriverStatus::converged) << r.message;
    EXPECT_NEAR(r.x[0], 0.3, 1e-12) << "offset " << offset << ": " << r.message;
    EXPECT_NEAR(r.x[1], -0.2, 1e-12) << "offset " << offset << ": " << r.message;
    if (offset == 1.0) {
      EXPECT_NE(r.message.find("gradient is zero to roundoff"), std::string::npos) << r.message;
    }
  }
}

// A gradient algorithm's first call reuses the start's evaluation that
// prepare_start made (with gradients), so the model runs once per
// evaluation the run counts and not once more; and a start whose values
// are fine but whose gradient is not is still a usable start (no phase 1),
// the gradient's failure met by the run as before.
TEST(NloptDriver, TheStartIsEvaluatedOnce) {
  int calls = 0;
  const testing_problems::Analytic counted(
      "counted", {{"x", opt::Dimension::dimensionless, -1, 1, 0.9}},
      {{"f", [&calls](const Eigen::VectorXd& v) {
          ++calls;
          return opt::MetricValue{std::cosh(v[0] - 0.3), Eigen::VectorXd::Constant(1, std::sinh(v[0] - 0.3))};
        }}});
  opt::DriverOptions o;
  o.algorithm = "LD_SLSQP";
  o.xtol_rel = 1e-12;
  const auto r = opt::NloptDriver(o).minimize(counted, {"f"}, {}, counted.initial_point());
  ASSERT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  EXPECT_NEAR(r.x[0], 0.3, 1e-12);
  EXPECT_EQ(calls, r.evaluations) << "prepare_start's evaluation of the start was made again";

  const testing_problems::Analytic kinked(
      "kinked_start", {{"x", opt::Dimension::dimensionless, -1, 1, 0.9}},
      {{"f", [](const Eigen::VectorXd& v) {
          const double g = v[0] == 0.9 ? HUGE_VAL : std::sinh(v[0] - 0.3);  // no slope at the start itself
          return opt::MetricValue{std::cosh(v[0] - 0.3), Eigen::VectorXd::Constant(1, g)};
        }}});
  const auto k = opt::NloptDriver(o).minimize(kinked, {"f"}, {}, kinked.initial_point());
  EXPECT_EQ(k.message.find("phase 1"), std::string::npos) << k.message;
  EXPECT_EQ(k.message.find("start was infeasible"), std::string::npos) << k.message;
  EXPECT_GE(k.infeasible_evaluations, 1) << "the first call meets the failed gradient";
}

// check_slope on closed forms: the bowl's gradient (sinh(x - 0.3),
// sinh(y + 0.2)) vanishes only at its minimum; a bound that holds a
// variable whose gradient points out of the box leaves a KKT point; the
// tutorial's optimum is a KKT point of its two active constraints.
TEST(CheckSlope, FlagsOnlyPointsWithAFeasibleDescent) {
  const auto bowl = offset_bowl(1.0);
  const opt::Objective f = bowl.bind(opt::Objective{"f"});
  auto value = [&](double x, double y) { return 1.0 + std::cosh(x - 0.3) + std::cosh(y + 0.2); };
  EXPECT_FALSE(opt::check_slope(bowl, f, {}, Eigen::Vector2d(0.3, -0.2), value(0.3, -0.2)));
  // 1e-4 of the range off the minimum: the gradient promises a fall of
  // about 1e-2 * 2 * sinh(2e-4) ~ 4e-6, below 1e-4 |f|: not probed.
  EXPECT_FALSE(opt::check_slope(bowl, f, {}, Eigen::Vector2d(0.3002, -0.2), value(0.3002, -0.2)));
  const auto slope = opt::check_slope(bowl, f, {}, Eigen::Vector2d(0.6, -0.2), value(0.6, -0.2));
  ASSERT_TRUE(slope);
  EXPECT_EQ(slope->step, opt::kSlopeStep);
  // Along -r / max|r_j| = (-1, 0): x moves by 1% of its range of 2.
  EXPECT_NEAR(slope->value, value(0.58, -0.2), 1e-15);

  testing_problems::Analytic boxed(
      "boxed_bowl", {{"x", opt::Dimension::dimensionless, 0.5, 1, 0.9}, {"y", opt::Dimension::dimensionless, -1, 1, 0.7}},
      {{"f", [](const Eigen::VectorXd& v) {
          return opt::MetricValue{std::cosh(v[0] - 0.3) + std::cosh(v[1] + 0.2),
                                  Eigen::Vector2d(std::sinh(v[0] - 0.3), std::sinh(v[1] + 0.2))};
        }}});
  const opt::Objective fb = boxed.bind(opt::Objective{"f"});
  EXPECT_FALSE(opt::check_slope(boxed, fb, {}, Eigen::Vector2d(0.5, -0.2), value(0.5, -0.2) - 1))
      << "x = 0.5 is held by its lower bound";
  EXPECT_TRUE(opt::check_slope(boxed, fb, {}, Eigen::Vector2d(0.5, 0.3), value(0.5, 0.3) - 1))
      << "y is free and not at its minimum";

  const Tutorial t = testing_problems::tutorial();
  const auto cons = t.bind(kCons);
  const Eigen::Vector2d star(1.0 / 3, 8.0 / 27);
  EXPECT_FALSE(opt::check_slope(t, t.bind(opt::Objective{"f"}), cons, star, std::sqrt(star[1])));
  // Above the optimum x2 can still come down, from far (both constraints
  // slack) or near (slack 0.2, which a step of 1% of the ranges, 20 and 10,
  // would overrun along the gradient)...
  for (const double x2 : {2.0, 0.5})
    EXPECT_TRUE(opt::check_slope(t, t.bind(opt::Objective{"f"}), cons, Eigen::Vector2d(1.0 / 3, x2), std::sqrt(x2)))
        << x2;
  // ... and on the curved constraint c1 (x2 = 8 x1^3) above the optimum, x1
  // can come down along it: the probe's tangent step is pulled back onto it.
  EXPECT_TRUE(opt::check_slope(t, t.bind(opt::Objective{"f"}), cons, Eigen::Vector2d(0.5, 1.0), 1.0));
}

// kkt_measure on closed forms: 0 at the bowl's minimum (a zero gradient)
// and at the tutorial's optimum, where its two active constraints hold the
// gradient; 1 (the unit gradient, nothing holding it) where every
// constraint is slack; none where a constraint is broken.
TEST(KktMeasure, ZeroAtKktPointsOneOnASlopeNoneWhenInfeasible) {
  const auto bowl = offset_bowl(1.0);
  EXPECT_EQ(opt::kkt_measure(bowl, bowl.bind(opt::Objective{"f"}), {}, Eigen::Vector2d(0.3, -0.2)), 0.0);
  const Tutorial t = testing_problems::tutorial();
  const auto cons = t.bind(kCons);
  const opt::Objective f = t.bind(opt::Objective{"f"});
  const auto at_star = opt::kkt_measure(t, f, cons, Eigen::Vector2d(1.0 / 3, 8.0 / 27));
  ASSERT_TRUE(at_star);
  EXPECT_LT(*at_star, 1e-12);
  const auto above = opt::kkt_measure(t, f, cons, Eigen::Vector2d(1.0 / 3, 2.0));
  ASSERT_TRUE(above);
  EXPECT_NEAR(*above, 1.0, 1e-15);
  EXPECT_FALSE(opt::kkt_measure(t, f, cons, Eigen::Vector2d(1.0 / 3, 0.1)));  // x2 >= 8 x1^3 broken
}

// A library that says "infeasible" (Ipopt after a failed restoration) at a
// design that meets every constraint has failed: the problem is not shown
// infeasible. At the tutorial's optimum it is a failure; below its curved
// constraint, where the design breaks it, "infeasible" stands.
TEST(Finish, LibraryInfeasibleAtAFeasibleDesignIsAFailure) {
  const Tutorial t = testing_problems::tutorial();
  auto finished = [&](const Eigen::Vector2d& x) {
    opt::Result r;
    r.library = "ipopt";
    r.status = opt::DriverStatus::infeasible;
    r.x = x;
    opt::detail::finish(t, opt::detail::Bound(t, {"f"}, kCons), r, nullptr);
    return r;
  };
  const auto feasible = finished(Eigen::Vector2d(1.0 / 3, 8.0 / 27));
  EXPECT_EQ(feasible.status, opt::DriverStatus::failure);
  EXPECT_NE(feasible.message.find("the final design meets every constraint"), std::string::npos) << feasible.message;
  const auto broken = finished(Eigen::Vector2d(1.0 / 3, 0.1));  // x2 >= 8 x1^3 broken
  EXPECT_EQ(broken.status, opt::DriverStatus::infeasible) << broken.message;
}

TEST(IpoptDriver, IterationLimitIsAStopNotASuccess) {
  opt::DriverOptions o;
  o.library = "ipopt";
  o.max_iterations = 2;
  const Tutorial p = testing_problems::tutorial();
  const auto r = opt::IpoptDriver(o).minimize(p, {"f"}, kCons, p.initial_point());
  EXPECT_EQ(r.status, opt::DriverStatus::max_evaluations) << r.message;
  EXPECT_FALSE(r.success());
  EXPECT_EQ(r.message.rfind("stopped on the iteration limit (max_iterations 2) before converging", 0), 0u)
      << r.message;
}

}  // namespace

// Which NLopt algorithm takes which problem, against NLopt's own algorithm
// documentation (doc/docs/NLopt_Algorithms.md, quoted), not the driver's
// table: every offered algorithm x {bounds only, an inequality, an
// equality, no gradients, one variable, an unbounded variable}.
#include <set>
#include <sstream>

namespace {

struct Documented {
  const char* algorithm;
  bool gradient;    // a D algorithm needs the gradient
  bool inequality;  // nonlinear inequality constraints
  bool equality;    // nonlinear equality constraints
  bool global;      // needs finite bounds
  int min_variables;
  const char* quote;
};

const Documented kDocumented[] = {
    {"LN_COBYLA", false, true, true, false, 1,
     "COBYLA ... for derivative-free optimization with nonlinear inequality and equality constraints"},
    {"LN_BOBYQA", false, false, false, false, 1,
     "BOBYQA performs derivative-free bound-constrained optimization"},
    {"LN_NEWUOA_BOUND", false, false, false, false, 2,
     "NEWUOA requires the dimension n of the parameter space to be >= 2"},
    {"LN_NELDERMEAD", false, false, false, false, 1,
     "only COBYLA currently supports arbitrary nonlinear inequality and equality constraints; the "
     "rest of them support bound-constrained or unconstrained problems only"},
    {"LN_SBPLX", false, false, false, false, 1, "(as LN_NELDERMEAD)"},
    {"LD_SLSQP", true, true, true, false, 1, "(supporting both inequality and equality constraints)"},
    {"LD_MMA", true, true, false, false, 1,
     "including nonlinear inequality constraints (but *not* equality constraints)"},
    {"LD_CCSAQ", true, true, false, false, 1, "another CCSA algorithm from the same paper (as MMA)"},
    {"LD_LBFGS", true, false, false, false, 1,
     "only MMA and SLSQP support arbitrary nonlinear inequality constraints ... the rest support "
     "bound-constrained or unconstrained problems only"},
    {"GN_DIRECT_L", false, false, false, true, 1,
     "Most of the above algorithms only handle bound constraints, and in fact require finite bound "
     "constraints"},
    {"GN_DIRECT", false, false, false, true, 1, "(as GN_DIRECT_L)"},
    {"GN_ISRES", false, true, true, true, 1,
     "supports arbitrary nonlinear inequality and equality constraints in addition to the bound "
     "constraints"},
    // The local search decides the gradient (local_algorithm LN_COBYLA here).
    {"G_MLSL_LDS", false, false, false, true, 1,
     "Only bound-constrained problems are supported by this algorithm"},
};

// Two (or n) variables in [-1, 2], f = |x|^2, c = x0 + x1, with or without gradients.
class Quadratic : public opt::Problem {
 public:
  Quadratic(int n, bool gradients, double upper = 2) : gradients_(gradients) {
    for (int i = 0; i < n; ++i)
      vars_.push_back({"x" + std::to_string(i), opt::Dimension::dimensionless, -1, upper, 0.5});
  }
  std::string name() const override { return "quadratic"; }
  const std::vector<opt::Variable>& variables() const override { return vars_; }
  const std::vector<std::string>& metric_names() const override { return names_; }
  const std::vector<std::string> names_ = {"f", "c"};
  std::string metric_unit(const std::string&) const override { return ""; }
  bool provides_gradients() const override { return gradients_; }
  nlohmann::json settings() const override { return {}; }
  mutable int evaluations = 0;

 protected:
  opt::Evaluation evaluate_model_at(const Eigen::VectorXd& x, const opt::MetricSet&,
                                    bool gradient) const override {
    ++evaluations;
    opt::Evaluation e;
    e.set(0, {x.squaredNorm(), gradient ? Eigen::VectorXd(2 * x) : Eigen::VectorXd()});
    e.set(1, {x.sum(), gradient ? Eigen::VectorXd::Ones(x.size()).eval() : Eigen::VectorXd()});
    return e;
  }

 private:
  bool gradients_;
  std::vector<opt::Variable> vars_;
};

struct Shape {
  const char* name;
  int variables;
  bool gradients;
  double upper;  // of every variable
  std::vector<opt::Constraint> constraints;
};

const Shape kShapes[] = {
    {"bounds_only", 2, true, 2, {}},
    {"inequality", 2, true, 2, {{"c", true, 1}}},
    {"equality", 2, true, 2, {{"c", true, 1, true}}},
    {"no_gradients", 2, false, 2, {}},
    {"one_variable", 1, true, 2, {}},
    {"unbounded", 2, true, std::numeric_limits<double>::infinity(), {}},
};

bool documented_takes(const Documented& d, const Shape& s) {
  bool ok = !(d.gradient && !s.gradients) && s.variables >= d.min_variables &&
            !(d.global && !std::isfinite(s.upper));
  for (const auto& k : s.constraints) ok = ok && (k.equal ? d.equality : d.inequality);
  return ok;
}

opt::DriverOptions options_for(const std::string& algorithm) {
  opt::DriverOptions o;
  o.algorithm = algorithm;
  o.local_algorithm = "LN_COBYLA";
  return o;
}

// The names after "algorithms that can take this problem: ".
std::set<std::string> capable_list(const std::string& message) {
  const std::string head = "algorithms that can take this problem: ";
  std::set<std::string> out;
  const auto at = message.find(head);
  if (at == std::string::npos) return out;
  std::stringstream ss(message.substr(at + head.size()));
  for (std::string item; std::getline(ss, item, ',');) out.insert(item.substr(item.find_first_not_of(' ')));
  return out;
}

using CapabilityCase = std::tuple<size_t, size_t>;
class Capabilities : public ::testing::TestWithParam<CapabilityCase> {};

TEST_P(Capabilities, MatchNloptsDocumentation) {
  const Documented& d = kDocumented[std::get<0>(GetParam())];
  const Shape& s = kShapes[std::get<1>(GetParam())];
  const Quadratic p(s.variables, s.gradients, s.upper);
  const std::string why = opt::driver_incompatibility(options_for(d.algorithm), p, {"f"}, s.constraints);
  EXPECT_EQ(why.empty(), documented_takes(d, s)) << d.algorithm << " on " << s.name << ": " << why
                                                 << "\n  NLopt: " << d.quote;
  const auto r = opt::NloptDriver(options_for(d.algorithm)).minimize(p, {"f"}, s.constraints, p.initial_point());
  if (why.empty()) {
    EXPECT_NE(r.status, opt::DriverStatus::invalid_arguments) << r.message;
    return;
  }
  // Refused before any work, with one message: the algorithm, then the
  // algorithms that can take the problem (by the documentation).
  EXPECT_EQ(r.status, opt::DriverStatus::invalid_arguments);
  EXPECT_EQ(r.message, why);
  EXPECT_EQ(p.evaluations, 0);
  EXPECT_EQ(r.x, p.initial_point());
  EXPECT_EQ(why.rfind(d.algorithm + std::string(" "), 0), 0u) << why;
  std::set<std::string> want;
  for (const auto& other : kDocumented)
    if (documented_takes(other, s)) want.insert(other.algorithm);
  if (s.gradients) want.insert("library: ipopt");
  // line: one variable within finite bounds, an exact derivative, no constraints
  if (s.variables == 1 && s.gradients && std::isfinite(s.upper) && s.constraints.empty()) want.insert("library: line");
  EXPECT_EQ(capable_list(why), want) << why;
}

std::vector<CapabilityCase> capability_cases() {
  std::vector<CapabilityCase> out;
  for (size_t a = 0; a < std::size(kDocumented); ++a)
    for (size_t s = 0; s < std::size(kShapes); ++s) out.emplace_back(a, s);
  return out;
}

INSTANTIATE_TEST_SUITE_P(EveryAlgorithm, Capabilities, ::testing::ValuesIn(capability_cases()),
                         [](const auto& info) {
                           return std::string(kDocumented[std::get<0>(info.param)].algorithm) + "__" +
                                  kShapes[std::get<1>(info.param)].name;
                         });

TEST(Capabilities, EveryOfferedAlgorithmIsDocumentedHere) {
  std::set<std::string> documented;
  for (const auto& d : kDocumented) documented.insert(d.algorithm);
  const auto offered = opt::nlopt_algorithms();
  EXPECT_EQ(std::set<std::string>(offered.begin(), offered.end()), documented);
}

// The reasons name what the algorithm lacks.
TEST(Capabilities, MessagesSayWhy) {
  const Quadratic with(2, true), without(2, false), one(1, true);
  auto why = [](const std::string& a, const opt::Problem& p, std::vector<opt::Constraint> k = {}) {
    return opt::driver_incompatibility(options_for(a), p, {"f"}, k);
  };
  EXPECT_EQ(why("LN_BOBYQA", with, {{"c", true, 1}}).rfind("LN_BOBYQA takes no inequality constraints (c <= 1)", 0), 0u);
  EXPECT_EQ(why("LD_MMA", with, {{"c", true, 1, true}}).rfind("LD_MMA takes no equality constraints (c = 1)", 0), 0u);
  EXPECT_EQ(why("LD_SLSQP", without).rfind("LD_SLSQP needs exact gradients, and quadratic has none", 0), 0u);
  EXPECT_EQ(why("LN_NEWUOA_BOUND", one).rfind("LN_NEWUOA_BOUND needs at least 2 variables, and the problem has 1", 0), 0u);
  const Quadratic unbounded(2, true, std::numeric_limits<double>::infinity());
  EXPECT_EQ(why("GN_DIRECT_L", unbounded).rfind("GN_DIRECT_L is a global search and needs finite bounds, and x0 has none", 0), 0u);
}

// A chain is checked whole: the polish, and G_MLSL_LDS's local algorithm.
TEST(Capabilities, ChainsAreCheckedWhole) {
  const Quadratic with(2, true), without(2, false);
  const std::vector<opt::Constraint> ineq = {{"c", true, 1}};
  opt::DriverOptions o = options_for("GN_ISRES");
  o.polish = std::make_shared<opt::DriverOptions>(options_for("LD_LBFGS"));
  std::string why = opt::driver_incompatibility(o, with, {"f"}, ineq);
  EXPECT_EQ(why.rfind("polish: LD_LBFGS takes no inequality constraints", 0), 0u) << why;
  // The whole chain refuses before its first stage runs.
  const auto r = opt::make_driver(o)->minimize(with, {"f"}, ineq, with.initial_point());
  EXPECT_EQ(r.status, opt::DriverStatus::invalid_arguments);
  EXPECT_EQ(with.evaluations, 0);

  opt::DriverOptions mlsl = options_for("G_MLSL_LDS");
  mlsl.local_algorithm = "LD_LBFGS";
  why = opt::driver_incompatibility(mlsl, without, {"f"}, {});
  EXPECT_EQ(why.rfind("G_MLSL_LDS's local_algorithm LD_LBFGS needs exact gradients", 0), 0u) << why;

  opt::DriverOptions ipopt;
  ipopt.library = "ipopt";
  why = opt::driver_incompatibility(ipopt, without, {"f"}, {});
  EXPECT_EQ(why.rfind("ipopt needs exact gradients", 0), 0u) << why;
  EXPECT_EQ(capable_list(why), (std::set<std::string>{"LN_COBYLA", "LN_BOBYQA", "LN_NEWUOA_BOUND",
                                                       "LN_NELDERMEAD", "LN_SBPLX", "GN_DIRECT_L",
                                                       "GN_DIRECT", "GN_ISRES", "G_MLSL_LDS"}));
}

// Each driver answers for itself, naming itself first; a chain answers
// stage by stage; driver_incompatibility adds who can.
TEST(Capabilities, EachDriverDeclaresWhatItSolves) {
  const Quadratic with(2, true), without(2, false), one(1, true);
  const std::vector<opt::Constraint> ineq = {{"c", true, 1}};
  opt::DriverOptions ipopt, line;
  ipopt.library = "ipopt";
  line.library = "line";
  EXPECT_EQ(opt::IpoptDriver(ipopt).incompatibility(with, ineq), "");
  EXPECT_EQ(opt::IpoptDriver(ipopt).incompatibility(without, {}).rfind("ipopt needs exact gradients", 0), 0u);
  EXPECT_EQ(opt::LineDriver(line).incompatibility(one, {}), "");
  EXPECT_EQ(opt::LineDriver(line).incompatibility(with, {}), "line takes one variable, and the problem has 2");
  EXPECT_EQ(opt::LineDriver(line).incompatibility(one, ineq), "line takes no constraints (c <= 1)");
  EXPECT_EQ(opt::NloptDriver(options_for("LD_LBFGS")).incompatibility(with, ineq),
            "LD_LBFGS takes no inequality constraints (c <= 1)");
  const opt::ChainDriver chain(std::make_unique<opt::NloptDriver>(options_for("GN_DIRECT_L")),
                               std::make_unique<opt::LineDriver>(line));
  EXPECT_EQ(chain.incompatibility(with, {}), "polish: line takes one variable, and the problem has 2");
  // The public check is the driver's own reason, then the alternatives.
  const std::string why = opt::driver_incompatibility(line, with, {"f"}, {});
  EXPECT_EQ(why.rfind("line takes one variable, and the problem has 2; algorithms that can take this problem: ", 0),
            0u) << why;
}

// No algorithm given: the problem decides (docs/drivers.md).
TEST(Capabilities, DefaultAlgorithmFitsTheProblem) {
  const Quadratic with(2, true), without(2, false);
  EXPECT_EQ(opt::default_algorithm(with), "LD_SLSQP");
  EXPECT_EQ(opt::default_algorithm(without), "LN_COBYLA");
  const opt::DriverOptions defaults;
  const std::vector<opt::Constraint> both = {{"c", true, 1}, {"c", false, -1}};
  EXPECT_EQ(opt::driver_incompatibility(defaults, without, {"f"}, both), "");
  const auto r = opt::make_driver(defaults)->minimize(without, {"f"}, both, without.initial_point());
  EXPECT_EQ(r.algorithm, "LN_COBYLA");
  EXPECT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  constexpr double kTol = 1e-6;  // COBYLA's step tolerance (xtol_rel 1e-12) is far below this
  EXPECT_NEAR(r.objective, 0.0, kTol) << "min |x|^2 at x = 0, inside -1 <= x0 + x1 <= 1";
}

}  // namespace
