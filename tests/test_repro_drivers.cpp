// Regression tests for the driver configs in tests/repro/ (README.md there
// says what each did and what a user should get), run as a user runs them:
// the mechopt binary, its exit code, its output and its result files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "cli.hpp"

namespace {

constexpr int kTimeout = 60;  // seconds; each run takes well under one

std::string run_args(const std::string& config, const std::string& dir) {
  return "run " + config + " --output " + dir;
}

nlohmann::json read_json(const std::string& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in, nullptr, false);
}

// Every number anywhere in j is finite (a NaN written as null is not a number).
void expect_finite_numbers(const nlohmann::json& j, const std::string& where = "") {
  if (j.is_number()) {
    EXPECT_TRUE(std::isfinite(j.get<double>())) << where;
  }
  if (j.is_structured())
    for (const auto& [key, value] : j.items()) expect_finite_numbers(value, where + "/" + key);
}

// SIGABRT before: LN_BOBYQA refused the constraint, then a writer indexed an
// empty x. Now: exit 2 before any work, one line at study.driver naming the
// algorithm, why, and the algorithms that can (NLopt's documentation).
TEST(ReproDrivers, BoundOnlyAlgorithmWithAConstraintIsRefusedBeforeAnyWork) {
  const std::string dir = cli::fresh_dir("repro_bobyqa");
  const auto o = cli::run(run_args(cli::source("tests/repro/driver_rejects_constraints_bobyqa.yaml"), dir), kTimeout);
  EXPECT_TRUE(o.exited(2)) << o.output;
  EXPECT_NE(o.output.find("driver_rejects_constraints_bobyqa.yaml:5:"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("key 'study.driver'"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("LN_BOBYQA takes no inequality constraints (max_pressure_angle <= 1.0472)"),
            std::string::npos)
      << o.output;
  EXPECT_NE(o.output.find("algorithms that can take this problem: LN_COBYLA, LD_SLSQP, LD_MMA, "
                          "LD_CCSAQ, GN_ISRES, library: ipopt"),
            std::string::npos)
      << o.output;
  // One error line (the config's old metric name adds one notice line).
  EXPECT_EQ(std::count(o.output.begin(), o.output.end(), '\n'), 2) << o.output;
  EXPECT_NE(o.output.find("metric 'peak_moment' is now called 'peak_crank_torque'"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir)) << "nothing written: the run never started";
}

// SIGABRT before: the default LD_SLSQP refused a problem without gradients,
// then a writer indexed an empty x. Now the default is derivative-free
// (LN_COBYLA): exit 0, converged, and the objective it reports is the
// model's at that design.
TEST(ReproDrivers, DefaultDriverFitsAProblemWithoutGradients) {
  const std::string dir = cli::fresh_dir("repro_elastic_default");
  const auto o = cli::run(run_args(cli::source("tests/repro/elastic_default_driver.yaml"), dir), kTimeout);
  ASSERT_TRUE(o.exited(0)) << o.output;
  const auto j = read_json(dir + "/result.json");
  ASSERT_TRUE(j.is_object()) << o.output;
  expect_finite_numbers(j);
  EXPECT_EQ(j["driver"]["algorithm"], "LN_COBYLA");
  EXPECT_EQ(j["status"], "converged") << j["message"];
  EXPECT_EQ(j["design_status"], "ok");
  EXPECT_DOUBLE_EQ(j["objective"]["value"].get<double>(), j["metrics"]["rms_coupling_torque"].get<double>());
  const double damping = j["variables"]["damping"]["value"].get<double>();
  EXPECT_GE(damping, 500);
  EXPECT_LE(damping, 10000);
}

// The same default where the model cannot be evaluated anywhere: seed 001's
// printed roller loads (4 x 7962 N) stall the motor at every damping. The
// honest outcome is still exit 0, with status infeasible, every evaluation
// marked infeasible, and no number made up.
TEST(ReproDrivers, DefaultDriverReportsAnAllInfeasibleRunAsSuch) {
  const std::string dir = cli::fresh_dir("repro_elastic_default_stalled");
  std::filesystem::create_directories(dir);
  const std::string config = dir + "/config.yaml";
  std::ofstream(config) << "problem: elastic_drive\nmodel: {roller_horizontal: 31848 N}\n"
                           "variables: {damping: {min: 500, max: 10000}}\n"
                           "objective: {minimize: rms_coupling_torque}\n";
  const auto o = cli::run(run_args(config, dir + "/out"), kTimeout);
  ASSERT_TRUE(o.exited(0)) << o.output;
  const auto j = read_json(dir + "/out/result.json");
  ASSERT_TRUE(j.is_object()) << o.output;
  expect_finite_numbers(j);
  EXPECT_EQ(j["driver"]["algorithm"], "LN_COBYLA");
  // The status agrees with the model at the reported design, evaluated apart.
  const double damping = j["variables"]["damping"]["value"].get<double>();
  const auto e = cli::run("eval " + config + " --set damping=" + std::to_string(damping), kTimeout);
  ASSERT_TRUE(e.exited(0)) << e.output;
  EXPECT_NE(e.output.find("\"status\": \"stalled\""), std::string::npos) << e.output;
  EXPECT_EQ(j["design_status"], "stalled");
  EXPECT_EQ(j["status"], "infeasible") << j["message"];
  EXPECT_TRUE(j["objective"]["value"].is_null());
  EXPECT_EQ(j["infeasible_evaluations"], j["evaluations"]);
  EXPECT_NE(j["message"].get<std::string>().find("all " + std::to_string(j["evaluations"].get<int>()) +
                                                  " evaluations were infeasible"),
            std::string::npos)
      << j["message"];
}

// SIGSEGV in MUMPS before: the 1e12 m bound let Ipopt's barrier jump to
// l = 6e10 m, where the pressure angle's gradient is infinite, and the inf
// reached the linear solver. Now: exit 0, every front point converged at a
// sane l_co1, finite numbers.
TEST(ReproDrivers, IpoptWithAnAbsurdBoundGivesAFiniteFront) {
  const std::string dir = cli::fresh_dir("repro_ipopt_huge_bound");
  const auto o = cli::run(run_args(cli::source("tests/repro/ipopt_huge_upper_bound.yaml"), dir), kTimeout);
  EXPECT_EQ(o.signal, 0) << o.output;
  ASSERT_TRUE(o.exited(0)) << o.output;
  const auto j = read_json(dir + "/result.json");
  ASSERT_TRUE(j.is_object()) << o.output;
  expect_finite_numbers(j);
  const auto& points = j["pareto"]["points"];
  ASSERT_EQ(points.size(), 9u);
  for (const auto& p : points) {
    EXPECT_EQ(p["status"], "converged") << p.dump();
    const double l = p["variables"]["l_co1"]["value"].get<double>();
    EXPECT_GT(l, 0.9) << p.dump();
    EXPECT_LT(l, 2.4) << "the links of this conveyor: " << p.dump();
  }
}

// The root cause, at the design Ipopt jumped to: the pressure angle's
// gradient is infinite there (acos at -1). The derivative check says so
// instead of passing with no checks at all.
TEST(ReproDrivers, InfiniteGradientFailsTheDerivativeCheck) {
  const auto o = cli::run("check-derivatives " + cli::source("tests/repro/ipopt_huge_upper_bound.yaml") +
                              " --set l_co1=61996449.46",
                          kTimeout);
  EXPECT_TRUE(o.exited(1)) << o.output;
  EXPECT_NE(o.output.find("max_pressure_angle has a non-finite gradient"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("MISMATCH"), std::string::npos) << o.output;
}

}  // namespace
