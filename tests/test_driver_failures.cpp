// Where the drivers fail on a nonsmooth objective, and how they say so
// (docs/drivers.md, "Kinks"), run as a user runs them: the shipped
// configs/recuperative_drive/rod_and_phase.yaml (least peak kinetic energy
// over rod length and phase shift; three peaks of T over the cycle are equal
// at the optimum, a kink of the objective) with the driver changed.
//
// The optimum, l = 1.2824 m, 95.27 deg, T_max = 2770.28 J, is the
// reproduction's (docs/reproduction.md), confirmed there by a 0.05 deg x
// 0.1 m grid. SLSQP and Ipopt's epigraph form reach it; COBYLA, MMA and
// CCSAQ meet their step tolerance on the kink above it, where the peaks can
// still descend together: status stopped_on_kink, not converged. Ipopt on
// the bare maximum stops with Infeasible_Problem_Detected at a design that
// meets the constraint: status failure, not infeasible.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli.hpp"

namespace {

constexpr double kOptimum = 2770.28;  // J, docs/reproduction.md

// rod_and_phase.yaml with its driver replaced by `driver`, run into a fresh
// directory: the process and its result.json.
std::pair<cli::Outcome, nlohmann::json> run_with(const std::string& name, const std::string& driver) {
  std::ifstream in(cli::source("configs/recuperative_drive/rod_and_phase.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string config = text.str();
  const std::string study = "study: {type: optimize, driver: {library: nlopt, algorithm: LD_SLSQP, xtol_rel: 1e-12}}";
  const auto at = config.find(study);
  EXPECT_NE(at, std::string::npos) << "the shipped config changed: update this test";
  config.replace(at, study.size(), "study: {type: optimize, driver: " + driver + "}");
  const std::string dir = cli::fresh_dir("kink_" + name);
  std::filesystem::create_directories(dir);
  const std::string file = dir + "/config.yaml";
  std::ofstream(file) << config;
  const auto o = cli::run("run " + file + " --output " + dir + "/out", 60);
  std::ifstream result(dir + "/out/result.json");
  return {o, nlohmann::json::parse(result, nullptr, false)};
}

double objective(const nlohmann::json& j) { return j["objective"]["value"].get<double>(); }

TEST(DriverFailures, GradientModelDriversReachTheKinkOptimum) {
  for (const std::string driver : {"{library: nlopt, algorithm: LD_SLSQP, xtol_rel: 1e-12}",
                                   "{library: ipopt, epigraph: true}"}) {
    const auto [o, j] = run_with(driver.find("ipopt") != std::string::npos ? "ipopt" : "slsqp", driver);
    ASSERT_TRUE(o.exited(0)) << o.output;
    EXPECT_EQ(j["status"], "converged") << j["message"];
    EXPECT_NEAR(objective(j), kOptimum, 0.01) << driver;
  }
}

TEST(DriverFailures, DerivativeFreeAndCcsaDriversStopOnTheKink) {
  for (const std::string algorithm : {"LN_COBYLA", "LD_MMA", "LD_CCSAQ"}) {
    const auto [o, j] = run_with(algorithm, "{library: nlopt, algorithm: " + algorithm + ", xtol_rel: 1e-12}");
    ASSERT_TRUE(o.exited(0)) << o.output;
    EXPECT_EQ(j["status"], "stopped_on_kink") << algorithm << ": " << j["message"];
    const std::string message = j["message"];
    EXPECT_NE(message.find("peaks of peak_kinetic_energy over the cycle are equal here"), std::string::npos)
        << message;
    EXPECT_NE(message.find("stationarity measure"), std::string::npos) << message;
    // Above the optimum: the kink is not it (measured: 0.4% to 2% above).
    EXPECT_GT(objective(j), kOptimum + 5) << algorithm;
  }
}

TEST(DriverFailures, IpoptOnTheBareMaximumFailsWithoutClaimingInfeasibility) {
  const auto [o, j] = run_with("ipopt_bare", "{library: ipopt, epigraph: false}");
  ASSERT_TRUE(o.exited(0)) << o.output;
  EXPECT_EQ(j["status"], "failure") << j["message"];
  const std::string message = j["message"];
  EXPECT_NE(message.find("the final design meets every constraint"), std::string::npos) << message;
  EXPECT_NE(message.find("epigraph: true"), std::string::npos) << message;
  EXPECT_LE(j["constraints"][0]["value"].get<double>(), 0.3);
}

}  // namespace
