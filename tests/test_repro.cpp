// Regression tests for the configs in tests/repro/ (copied from
// ../shared/repro, where each came with what it did and what a user should
// get; tests/repro/README.md): config reading, grids and domains. The driver,
// chart and dynamics configs have their own files (test_repro_drivers.cpp,
// test_repro_charts.cpp, test_elastic_drive.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "cli.hpp"

namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');) out.push_back(cell);
  return out;
}

// A bad config: exit 2, one line, naming file:line:col and the key, with `what`.
void expect_located_error(const std::string& config, int line, const std::string& key,
                          const std::string& what) {
  const auto o = cli::run("run " + cli::source("tests/repro/" + config) + " --output " +
                          cli::fresh_dir("repro_" + config));
  EXPECT_TRUE(o.exited(2)) << o.output;
  EXPECT_NE(o.output.find(config + ":" + std::to_string(line) + ":"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("key '" + key + "'"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find(what), std::string::npos) << o.output;
  EXPECT_EQ(std::count(o.output.begin(), o.output.end(), '\n'), 1) << o.output;
}

// The sweep evaluated phase_shift = 90 deg, rod_length = 0.6 and 0.8 m
// whatever the order of the grid keys: each row's design, and its T_max
// against the independent mpmath reference (tools/reference_seed000.json,
// Table 1 at 90 deg), so a row with swapped values cannot pass.
TEST(Repro, SweepGridKeyOrderEvaluatesTheRequestedDesigns) {
  const std::string dir = cli::fresh_dir("repro_sweep_2d_key_order");
  const auto o = cli::run("run " + cli::source("tests/repro/sweep_2d_key_order.yaml") + " --output " + dir);
  ASSERT_TRUE(o.exited(0)) << o.output;
  std::ifstream csv(dir + "/sweep.csv");
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const auto head = split(line);
  auto col = [&](const std::string& name) {
    return static_cast<size_t>(std::find(head.begin(), head.end(), name) - head.begin());
  };
  const size_t rod = col("rod_length"), phase = col("phase_shift"), peak = col("peak_kinetic_energy");
  ASSERT_LT(peak, head.size());
  // Reference T_max [J] at l = 0.6 and 0.8 m (tools/reference_seed000.json).
  const double want_rod[] = {0.6, 0.8}, want_peak[] = {3544.8161836289869, 3253.6347036948055};
  constexpr double kTol = 1e-9;  // relative: the cycle maximum is refined to machine precision
  for (int r = 0; r < 2; ++r) {
    ASSERT_TRUE(std::getline(csv, line)) << "row " << r;
    const auto cells = split(line);
    EXPECT_DOUBLE_EQ(std::stod(cells[rod]), want_rod[r]);
    EXPECT_DOUBLE_EQ(std::stod(cells[phase]), std::numbers::pi / 2);
    EXPECT_NEAR(std::stod(cells[peak]) / want_peak[r], 1.0, kTol);
  }
  EXPECT_FALSE(std::getline(csv, line)) << "more rows than grid points";
}

TEST(Repro, DuplicateKeyNamesBothLines) {
  expect_located_error("duplicate_key.yaml", 4, "model.crank_radius",
                       "written twice (first at line 3, again at line 4)");
}

// k2 = T_cp / T_min and T_min = 4 m r^2 w^2 / pi^2 (seed 000 eq. 14): a zero
// cart mass left them NaN with status ok.
TEST(Repro, CartMassZeroIsADomainError) {
  expect_located_error("cart_mass_zero.yaml", 2, "model.cart_mass", "expected a value > 0 kg");
}

TEST(Repro, TinyGridStepNamesThePointCount) {
  expect_located_error("grid_step_tiny.yaml", 4, "study.grid.rod_length",
                       "the grid would have 1e+12 points; the limit is 1e+07");
}

// Each axis is under the limit; their product (about 1e10) is not.
TEST(Repro, GridLimitAppliesToThePointsInAll) {
  expect_located_error("grid_2d_too_many_points.yaml", 4, "study.grid",
                       "the grid would have 1e+10 points in all; the limit is 1e+07 (run with --force");
}

TEST(Repro, VariableBoundsMeetTheModelValuesDomain) {
  expect_located_error("bounds_bypass_domain_negative_stiffness.yaml", 30, "variables.stiffness.min",
                       "expected a value > 0 N m/rad");
}

}  // namespace

namespace {

// Metric names follow one scheme (statistic, then quantity); a config with
// an earlier name still runs, with a one-line notice naming the new one.
TEST(Repro, RenamedMetricIsAcceptedWithANotice) {
  const std::string dir = cli::fresh_dir("repro_renamed");
  const auto r = cli::run("run " + cli::source("tests/repro/ipopt_huge_upper_bound.yaml") + " --output " + dir);
  EXPECT_NE(r.output.find("ipopt_huge_upper_bound.yaml:9:16: metric 'peak_moment' is now called 'peak_crank_torque'"),
            std::string::npos) << r.output;
}

}  // namespace

namespace {

// `problem: elastic_drive` alone: the default BDF path (whose Jacobian once
// read past a 3-entry vector under AddressSanitizer; `make sanitize` runs this
// test too) evaluates the model values. Over a steady cycle the motor's mean
// power goes into the resistance and the damping (energy balance); the
// residual stays at the integration's tolerance level (rtol 1e-8).
TEST(Repro, ElasticDefaultBdfEvaluatesAndBalancesEnergy) {
  const std::string dir = cli::fresh_dir("repro_elastic_default_bdf_sanitizer");
  const auto o = cli::run("run " + cli::source("tests/repro/elastic_default_bdf_sanitizer.yaml") + " --output " + dir);
  ASSERT_TRUE(o.exited(0)) << o.output;
  std::ifstream in(dir + "/result.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["study"], "evaluate");
  ASSERT_EQ(j["design_status"], "ok") << j.dump(2);
  for (const auto& [name, v] : j["metrics"].items()) EXPECT_TRUE(v.is_number()) << name;
  EXPECT_LT(j["metrics"]["energy_balance_error"].get<double>(), 1e-6);
  EXPECT_EQ(j["settings"]["model"]["ode"]["method"], "bdf");
}

}  // namespace
