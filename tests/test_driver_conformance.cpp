// Driver conformance: every driver and algorithm on a shared table of
// problems with known optima, one test per pair. Each pair either converges
// (a tolerance met: Result::success) to the optimum within its algorithm
// class's tolerance and evaluation budget, or refuses the set-up with
// invalid_arguments, before any evaluation, when the algorithm cannot take
// the problem (constraints, gradients, dimension).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>

#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "opt/drivers/ipopt.hpp"
#include "opt/drivers/nlopt.hpp"
#include "opt/registry.hpp"
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
  return opt::make_problem(opt::ConfigNode::parse(yaml, "<conformance>"));
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
       "peak_crank_torque", {{"max_pressure_angle", true, 60 * M_PI / 180}}, 98310.834286910226,
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
  // documentation in test_nlopt_driver.cpp (Capabilities.*).
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

// Every driver's outcomes on the problems that break drivers: the wall-clock
// limit, a stop request, an exception in the model, non-finite values, an
// absurd bound, and an evaluation limit in a chain.
#include <chrono>
#include <stdexcept>
#include <thread>

#include "opt/interrupt.hpp"

namespace {

// Bounded Rosenbrock (the conformance case above) whose evaluation sleeps
// kEvaluationSeconds, like a slow model; registered like every problem, so
// that a config builds it.
constexpr double kEvaluationSeconds = 0.03;

std::vector<opt::Parameter> slow_parameters() {
  std::vector<opt::Parameter> p = {
      opt::variable("x", opt::Dimension::dimensionless, opt::kAnyValue, "x", ""),
      opt::variable("y", opt::Dimension::dimensionless, opt::kAnyValue, "y", "")};
  p[0].value = -1.2, p[1].value = 1.0;  // Rosenbrock's classic start
  return p;
}

class SlowRosenbrock : public opt::Problem {
 public:
  explicit SlowRosenbrock(std::vector<opt::Variable> v) : vars_(std::move(v)) {}
  std::string name() const override { return "slow_rosenbrock"; }
  const std::vector<opt::Variable>& variables() const override { return vars_; }
  const std::vector<std::string>& metric_names() const override { return names_; }
  const std::vector<std::string> names_ = {"f"};
  std::string metric_unit(const std::string&) const override { return ""; }
  nlohmann::json settings() const override { return {}; }

 protected:
  opt::Evaluation evaluate_model_at(const Eigen::VectorXd& x, const opt::MetricSet& wanted,
                                    bool gradient) const override {
    starts.push_back(std::chrono::steady_clock::now());
    std::this_thread::sleep_for(std::chrono::duration<double>(kEvaluationSeconds));
    return rosenbrock_.evaluate(x, wanted, gradient);
  }

 public:
  mutable std::vector<std::chrono::steady_clock::time_point> starts;  // of each evaluation

 private:
  std::vector<opt::Variable> vars_;
  testing_problems::Analytic rosenbrock_ = testing_problems::rosenbrock();
};

const opt::Registration kSlow{
    {"slow_rosenbrock", "test only: the bounded Rosenbrock, 30 ms an evaluation", slow_parameters(),
     [](const opt::ConfigNode& root) -> std::unique_ptr<opt::Problem> {
       return std::make_unique<SlowRosenbrock>(opt::parse_variables(root, slow_parameters()));
     }}};

// Every single-stage driver: each NLopt algorithm, and Ipopt.
std::vector<std::string> every_driver() {
  auto v = opt::nlopt_algorithms();
  v.push_back("ipopt");
  return v;
}

opt::DriverOptions single(const std::string& name) {
  opt::DriverOptions o;
  if (name == "ipopt") o.library = "ipopt";
  else o.algorithm = name;
  o.local_algorithm = "LD_SLSQP";
  return o;
}

class EveryDriver : public ::testing::TestWithParam<std::string> {
 protected:
  void TearDown() override { opt::clear_stop(); }
};

// max_seconds is wall clock for every algorithm and for Ipopt (whose own
// max_cpu_time would never fire here: sleeping costs no CPU time), honoured
// to within the evaluation under way at the limit.
TEST_P(EveryDriver, MaxSecondsIsWallClockWithinOneEvaluation) {
  constexpr double kMaxSeconds = 0.2;
  const auto p = opt::make_problem(opt::ConfigNode::parse(
      "problem: slow_rosenbrock\nvariables: {x: {min: -1.5, max: 0.5}, y: {min: -0.5, max: 1.5}}\n",
      "<slow>"));
  opt::DriverOptions o = single(GetParam());
  o.max_seconds = kMaxSeconds;
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = opt::make_driver(o)->minimize(*p, {"f"}, {}, p->initial_point());
  auto since_t0 = [&](auto t) { return std::chrono::duration<double>(t - t0).count(); };
  const double elapsed = since_t0(std::chrono::steady_clock::now());
  EXPECT_EQ(r.status, opt::DriverStatus::max_time) << r.message;
  EXPECT_FALSE(r.success());
  EXPECT_TRUE(r.stopped());
  EXPECT_GE(elapsed, kMaxSeconds);
  // Honoured to within one evaluation, counted rather than timed: the
  // evaluation under way at the limit finishes, and after the limit (or after
  // the first evaluation, when the driver's own set-up outlasted the limit)
  // only the report's evaluation of the final design starts. When it starts
  // is not bounded: the driver's iteration and tear-down before it (Ipopt's,
  // under the sanitizers on a loaded shared machine, took 0.27 s) are not
  // evaluations, and the limit cannot stop them. A driver that ignored the
  // limit would start an evaluation every 30 ms after it; the 2 s bound
  // catches one that never returns.
  const auto& starts = dynamic_cast<const SlowRosenbrock&>(*p).starts;
  ASSERT_FALSE(starts.empty());
  const double limit = std::max(kMaxSeconds, since_t0(starts.front()));
  const auto late = std::count_if(starts.begin(), starts.end(), [&](auto t) { return since_t0(t) > limit; });
  EXPECT_LE(late, 1) << r.evaluations << " evaluations, " << elapsed << " s";
  EXPECT_LE(elapsed, limit + 2.0) << r.evaluations << " evaluations";
  EXPECT_LE(r.seconds, elapsed);
  EXPECT_NE(r.message.find("time limit (max_seconds 0.2 s, wall clock)"), std::string::npos) << r.message;
  ASSERT_EQ(r.x.size(), 2);
  EXPECT_TRUE(std::isfinite(r.objective)) << "the best design so far, evaluated";
}

// A problem that counts its evaluations, and on the k-th one requests a stop
// (as SIGINT would) or throws.
class Tripwire : public testing_problems::Analytic {
 public:
  enum class Action { stop, raise };
  Tripwire(int at, Action action)
      : Analytic(testing_problems::rosenbrock()), at_(at), action_(action) {}
  mutable int evaluations = 0;

 protected:
  opt::Evaluation evaluate_model_at(const Eigen::VectorXd& x, const opt::MetricSet& wanted,
                                    bool gradient) const override {
    if (++evaluations == at_) {
      if (action_ == Action::raise) throw std::runtime_error("model exploded at evaluation " + std::to_string(at_));
      opt::request_stop();
    }
    return Analytic::evaluate_model_at(x, wanted, gradient);
  }

 private:
  int at_;
  Action action_;
};

constexpr int kTripAt = 4;  // the start, then three of the library's

// A stop request (SIGINT/SIGTERM) during an evaluation: it finishes, and
// nothing more is evaluated, not even the final design again.
TEST_P(EveryDriver, StopRequestEndsTheRunAfterTheEvaluationUnderWay) {
  const Tripwire p(kTripAt, Tripwire::Action::stop);
  const auto r = opt::make_driver(single(GetParam()))->minimize(p, {"f"}, {}, p.initial_point());
  EXPECT_EQ(r.status, opt::DriverStatus::interrupted) << r.message;
  EXPECT_FALSE(r.success());
  EXPECT_EQ(p.evaluations, kTripAt);
  EXPECT_NE(r.message.find("interrupted by a stop request"), std::string::npos) << r.message;
  EXPECT_EQ(r.x.size(), 2);
}

// An exception in the model never crosses the library's C (NLopt) or
// Fortran-backed (Ipopt) code: the library is stopped, nothing more is
// evaluated, and the exception reaches the caller after the library returns.
TEST_P(EveryDriver, ExceptionInTheModelIsRethrownAfterTheLibraryStops) {
  const Tripwire p(kTripAt, Tripwire::Action::raise);
  try {
    opt::make_driver(single(GetParam()))->minimize(p, {"f"}, {}, p.initial_point());
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "model exploded at evaluation " + std::to_string(kTripAt));
  }
  EXPECT_EQ(p.evaluations, kTripAt);
}

INSTANTIATE_TEST_SUITE_P(All, EveryDriver, ::testing::ValuesIn(every_driver()),
                         [](const auto& info) { return info.param; });

// f = 1 + |x - (1, 1)|^2 on [-2, 3]^2, NaN (value and gradient) where
// x0 > 1.5: the minimum f* = 1 at (1, 1) lies inside the finite region,
// which DIRECT's first trisection (x0 = 0.5 + 5/3) already leaves.
class NanBeyond : public opt::Problem {
 public:
  std::string name() const override { return "nan_beyond"; }
  const std::vector<opt::Variable>& variables() const override { return vars_; }
  const std::vector<std::string>& metric_names() const override { return names_; }
  const std::vector<std::string> names_ = {"f"};
  std::string metric_unit(const std::string&) const override { return ""; }
  nlohmann::json settings() const override { return {}; }
  mutable int nan_evaluations = 0;

 protected:
  opt::Evaluation evaluate_model_at(const Eigen::VectorXd& x, const opt::MetricSet&,
                                    bool gradient) const override {
    const Eigen::VectorXd d = x - Eigen::Vector2d(1, 1);
    opt::MetricValue f{1 + d.squaredNorm(), gradient ? Eigen::VectorXd(2 * d) : Eigen::VectorXd()};
    if (x[0] > 1.5) {
      ++nan_evaluations;
      f.value = std::numeric_limits<double>::quiet_NaN();
      f.gradient.setConstant(std::numeric_limits<double>::quiet_NaN());
    }
    opt::Evaluation e;
    e.set(0, f);
    return e;
  }

 private:
  std::vector<opt::Variable> vars_ = {{"x0", opt::Dimension::dimensionless, -2, 3, -1},
                                      {"x1", opt::Dimension::dimensionless, -2, 3, -1}};
};

class NonFinite : public ::testing::TestWithParam<size_t> {};

// Non-finite values are infeasible evaluations the algorithm steps back
// from; none reaches the library, and the answer is the finite optimum.
TEST_P(NonFinite, ValuesAreInfeasibleEvaluations) {
  const Algo& a = algos()[GetParam()];
  const NanBeyond p;
  const auto r = opt::make_driver(a.options)->minimize(p, {"f"}, {}, p.initial_point());
  ASSERT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  EXPECT_NEAR(r.objective, 1.0, a.tol) << "f* = 1 at (1, 1)";
  if (a.name.rfind("GN_DIRECT", 0) == 0) {
    EXPECT_GT(p.nan_evaluations, 0) << "DIRECT samples the whole box";
    EXPECT_GT(r.infeasible_evaluations, 0);
  }
  RecordProperty("nan_evaluations", p.nan_evaluations);
}

INSTANTIATE_TEST_SUITE_P(EveryAlgorithm, NonFinite, ::testing::Range<size_t>(0, algos().size()),
                         [](const auto& info) { return algos()[info.param].name; });

// Epigraph rows come from Problem::local_maxima, which evaluate() does not
// screen: a peak with an infinite gradient at the start (as the pressure
// angle's acos at +-1) must not reach Ipopt's linear solver (MUMPS crashed on
// one). max((x-1)^2, (x+1)^2/4) has its kink minimum 4/9 at x = 1/3.
class InfinitePeak : public opt::Problem {
 public:
  explicit InfinitePeak(double start) : vars_{{"x", opt::Dimension::dimensionless, -3, 5, start}} {}
  std::string name() const override { return "infinite_peak"; }
  const std::vector<opt::Variable>& variables() const override { return vars_; }
  const std::vector<std::string>& metric_names() const override { return names_; }
  const std::vector<std::string> names_ = {"peak"};
  std::string metric_unit(const std::string&) const override { return ""; }
  nlohmann::json settings() const override { return {}; }
  std::vector<opt::MetricValue> local_maxima(const Eigen::VectorXd& x, opt::MetricId) const override {
    const double a = x[0] - 1, b = x[0] + 1;
    std::vector<opt::MetricValue> peaks = {{a * a, Eigen::VectorXd::Constant(1, 2 * a)},
                                           {b * b / 4, Eigen::VectorXd::Constant(1, b / 2)}};
    if (x[0] > 4) peaks[0].gradient[0] = std::numeric_limits<double>::infinity();
    return peaks;
  }

 protected:
  opt::Evaluation evaluate_model_at(const Eigen::VectorXd& x, const opt::MetricSet&,
                                    bool gradient) const override {
    const double a = (x[0] - 1) * (x[0] - 1), b = (x[0] + 1) * (x[0] + 1) / 4;
    opt::Evaluation e;
    e.set(0, {std::max(a, b), gradient ? Eigen::VectorXd::Constant(1, a > b ? 2 * (x[0] - 1) : (x[0] + 1) / 2)
                                                  : Eigen::VectorXd()});
    return e;
  }

 private:
  std::vector<opt::Variable> vars_;
};

TEST(IpoptDriver, InfinitePeakGradientIsAFailedEvaluationNotACrash) {
  opt::DriverOptions o;
  o.library = "ipopt";
  // From x = 4.5 every row has an infinite derivative at the start: Ipopt
  // cannot begin, and says so (before: a NaN/inf Jacobian reached MUMPS).
  const InfinitePeak stuck(4.5);
  const auto r = opt::IpoptDriver(o).minimize(stuck, {"peak"}, {}, stuck.initial_point());
  EXPECT_FALSE(r.success()) << r.message;
  EXPECT_EQ(r.x.size(), 1);
  // From x = 2 the epigraph converges to the kink, 4/9 at 1/3.
  const InfinitePeak fine(2);
  const auto s = opt::IpoptDriver(o).minimize(fine, {"peak"}, {}, fine.initial_point());
  ASSERT_EQ(s.status, opt::DriverStatus::converged) << s.message;
  constexpr double kTol = 1e-7;  // Ipopt's tol 1e-10 on the KKT error; the kink is exact in the epigraph
  EXPECT_NEAR(s.x[0], 1.0 / 3.0, kTol);
  EXPECT_NEAR(s.objective, 4.0 / 9.0, kTol);
}

// A bound of 1e12 m on a 1.2 m link (repro ipopt_huge_upper_bound.yaml):
// Ipopt gets no bound there, and reaches the optimum NLopt SLSQP finds with a
// sane bound (2.4 m), instead of jumping to l = 6e10 m where the pressure
// angle saturates at 90 deg.
TEST(IpoptDriver, AbsurdBoundIsPassedAsNone) {
  auto conveyor = [](const std::string& max) {
    return opt::make_problem(opt::ConfigNode::parse(
        "problem: conveyor_swing\nmodel: {design: synthesis, frame_x: 1.0 m, frame_y: 2.2 m, "
        "swing_angle: 32 deg, coupler_offset: 1.0 m, crank_speed: 12 rad/s, l_co1: 1.2 m}\n"
        "variables: {l_co1: {min: 0.9 m, max: " + max + "}}\n", "<conveyor>"));
  };
  const auto huge = conveyor("1e12 m"), sane = conveyor("2.4 m");
  opt::DriverOptions ipopt, slsqp;
  ipopt.library = "ipopt";
  slsqp.algorithm = "LD_SLSQP";
  slsqp.xtol_rel = 1e-12;
  const auto r = opt::make_driver(ipopt)->minimize(*huge, {"max_pressure_angle"}, {}, huge->initial_point());
  const auto ref = opt::make_driver(slsqp)->minimize(*sane, {"max_pressure_angle"}, {}, sane->initial_point());
  ASSERT_EQ(ref.status, opt::DriverStatus::converged) << ref.message;
  ASSERT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  constexpr double kTol = 1e-6;  // relative: two drivers on a kink, each converged far tighter
  EXPECT_NEAR(r.x[0], ref.x[0], kTol * ref.x[0]);
  EXPECT_NEAR(r.objective, ref.objective, kTol * ref.objective);
}

// A global stage that stops on its evaluation limit is not a success, and
// still hands its best design to the polish (docs/drivers.md).
TEST(ChainDriver, PolishRunsAfterAGlobalStageStoppedOnItsLimit) {
  const auto p = testing_problems::rosenbrock();
  opt::DriverOptions direct = nlopt("GN_DIRECT_L", 50);
  const auto first = opt::make_driver(direct)->minimize(p, {"f"}, {}, p.initial_point());
  EXPECT_EQ(first.status, opt::DriverStatus::max_evaluations) << first.message;
  EXPECT_FALSE(first.success());
  EXPECT_NE(first.message.find("evaluation limit (max_evaluations 50)"), std::string::npos) << first.message;
  direct.polish = std::make_shared<opt::DriverOptions>(nlopt("LD_SLSQP"));
  const auto r = opt::make_driver(direct)->minimize(p, {"f"}, {}, p.initial_point());
  ASSERT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  EXPECT_NEAR(r.objective, 0.25, 1e-7 * 0.25) << "closed form at the bound x = 0.5 (tolerance as SLSQP above)";
  EXPECT_GT(r.evaluations, first.evaluations);
  EXPECT_NE(r.message.find("max_evaluations"), std::string::npos) << r.message;
}

// A chain whose first stage is interrupted ends there: the polish would only
// be stopped at its first evaluation.
TEST(ChainDriver, InterruptedFirstStageEndsTheChain) {
  const Tripwire p(kTripAt, Tripwire::Action::stop);
  opt::DriverOptions o = nlopt("GN_DIRECT_L", 500);
  o.polish = std::make_shared<opt::DriverOptions>(nlopt("LD_SLSQP"));
  const auto r = opt::make_driver(o)->minimize(p, {"f"}, {}, p.initial_point());
  opt::clear_stop();
  EXPECT_EQ(r.status, opt::DriverStatus::interrupted) << r.message;
  EXPECT_EQ(p.evaluations, kTripAt);
}

}  // namespace
