// `mechopt dakota`: parameters files written to Dakota's documented formats
// (its standard format as the reference manual lists params.in, and the
// APREPRO format), read back into the problem's own evaluation: the same
// values and exact gradients, Dakota's default descriptors mapped through
// the config's objective and constraints, FAIL for an infeasible design,
// refusals named by line. Dakota itself is not in Debian: the files are
// written here as Dakota writes them.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli.hpp"
#include "opt/dakota.hpp"
#include "opt/registry.hpp"

namespace {

const std::string kTwin = cli::source("configs/recuperative_drive/rod_length.yaml");
const std::string kConveyor = cli::source("configs/conveyor_swing/optimum.yaml");

std::string write(const std::string& name, const std::string& text) {
  const std::string file = testing::TempDir() + "/" + name;
  std::ofstream(file) << text;
  return file;
}

std::string read(const std::string& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Dakota's standard format: right-aligned values and descriptors.
const char* kStandard = R"(                                          1 variables
                      9.000000000000000e-01 rod_length
                                          3 functions
                                          3 ASV_1:mean_kinetic_energy
                                          1 ASV_2:peak_crank_torque
                                          2 ASV_3:k1
                                          1 derivative_variables
                                          1 DVV_1:rod_length
                                          0 analysis_components
                                        1:7 eval_id
)";

const char* kAprepro = R"(                    { DAKOTA_VARS     =                      1 }
                    { rod_length      =  9.000000000000000e-01 }
                    { DAKOTA_FNS      =                      3 }
                    { ASV_1:mean_kinetic_energy =            3 }
                    { ASV_2:peak_crank_torque =              1 }
                    { ASV_3:k1        =                      2 }
                    { DAKOTA_DER_VARS =                      1 }
                    { DVV_1:rod_length =                     1 }
                    { DAKOTA_AN_COMPS =                      0 }
                    { DAKOTA_EVAL_ID  =                      7 }
)";

std::unique_ptr<opt::Problem> problem_of(const std::string& config) {
  return opt::make_problem(opt::ConfigNode::load(config));
}

std::vector<std::string> responses_of(const std::string& config, const opt::Problem& p) {
  return opt::dakota_responses(opt::parse_run(opt::ConfigNode::load(config), p));
}

TEST(Dakota, ValuesThenGradientsAsTheProblemEvaluatesThem) {
  const auto p = problem_of(kTwin);
  const auto params = opt::read_dakota_params(write("params.std", kStandard));
  EXPECT_EQ(params.eval_id, "1:7");
  const std::string results =
      opt::dakota_results(*p, responses_of(kTwin, *p), params);
  const opt::Evaluation e =
      p->evaluate(Eigen::VectorXd::Constant(1, 0.9), {"mean_kinetic_energy", "peak_crank_torque", "k1"}, true);
  ASSERT_TRUE(e.ok());
  std::istringstream in(results);
  std::string label, open, close;
  double v1, v2, g1, g3;
  in >> v1 >> label;
  EXPECT_EQ(label, "mean_kinetic_energy");
  in >> v2 >> label;
  EXPECT_EQ(label, "peak_crank_torque");
  in >> open >> g1 >> close;
  EXPECT_EQ(open + close, "[]");
  in >> open >> g3 >> close;
  EXPECT_TRUE(in.good());
  in >> label;
  EXPECT_TRUE(in.eof());  // k1's value not asked (ASV 2): its gradient alone
  // %24.16e: 17 digits, the same double back.
  EXPECT_EQ(v1, e.at("mean_kinetic_energy"));
  EXPECT_EQ(v2, e.at("peak_crank_torque"));
  EXPECT_EQ(g1, e[p->metric_id("mean_kinetic_energy")].gradient[0]);
  EXPECT_EQ(g3, e[p->metric_id("k1")].gradient[0]);
  // APREPRO's format says the same.
  EXPECT_EQ(opt::dakota_results(*p, responses_of(kTwin, *p), opt::read_dakota_params(write("params.apr", kAprepro))),
            results);
}

TEST(Dakota, DefaultDescriptorsAreTheConfigsObjectiveThenConstraints) {
  // Dakota's defaults for one objective and the config's inequality
  // constraints (a pressure angle, two lengths within bounds: five).
  const auto p = problem_of(kConveyor);
  const auto spec = opt::parse_run(opt::ConfigNode::load(kConveyor), *p);
  const int n = static_cast<int>(spec.constraints.size());
  ASSERT_EQ(n, 5);
  std::string text = "1 variables\n1.3 l_co1\n" + std::to_string(n + 1) + " functions\n1 ASV_1:obj_fn\n";
  for (int i = 1; i <= n; ++i) text += "1 ASV_" + std::to_string(i + 1) + ":nln_ineq_con_" + std::to_string(i) + "\n";
  text += "0 derivative_variables\n0 analysis_components\n";
  const std::string results =
      opt::dakota_results(*p, opt::dakota_responses(spec), opt::read_dakota_params(write("params.def", text)));
  const opt::Evaluation e = p->evaluate(Eigen::VectorXd::Constant(1, 1.3), opt::MetricSet::all(), false);
  ASSERT_TRUE(e.ok());
  std::istringstream in(results);
  double v;
  std::string label;
  in >> v >> label;
  EXPECT_EQ(label, "obj_fn");
  EXPECT_EQ(v, e.at(spec.objective.metric));
  for (int i = 0; i < n; ++i) {
    in >> v >> label;
    EXPECT_EQ(label, "nln_ineq_con_" + std::to_string(i + 1));
    EXPECT_EQ(v, e.at(spec.constraints[static_cast<size_t>(i)].metric)) << label;
  }
}

TEST(Dakota, TheCommandWritesTheResultsOrFailForAnInfeasibleDesign) {
  const std::string params = write("params.cli", kStandard);
  const std::string results = testing::TempDir() + "/results.cli";
  std::filesystem::remove(results);
  const auto ok = cli::run("dakota " + params + " " + results + " --config " + kTwin);
  ASSERT_TRUE(ok.exited(0)) << ok.output;
  const auto p = problem_of(kTwin);
  EXPECT_EQ(read(results), opt::dakota_results(*p, responses_of(kTwin, *p), opt::read_dakota_params(params)));
  // A rod of 0.15 m cannot reach its cart from a crank of 0.2 m.
  std::string short_rod = kStandard;
  short_rod.replace(short_rod.find("9.000000000000000e-01"), 21, "1.500000000000000e-01");
  const auto fail = cli::run("dakota " + write("params.short", short_rod) + " " + results + " --config " + kTwin);
  ASSERT_TRUE(fail.exited(0)) << fail.output;
  EXPECT_EQ(read(results), "FAIL\n");
  // docs/interfaces.md's sampling config: no objective, functions by their metrics.
  const std::string lhs = write("twin_lhs.yaml", R"(problem: recuperative_drive
model: {crank_speed: 100 rpm, cart_mass: 1000 kg, rod_mass_per_length: 80 kg/m, efficiency: 0.9,
        cart_resistance: 3562 N, resistance: opposes_motion}
variables:
  rod_length: {min: 0.3 m, max: 1.6 m}
  phase_shift: {min: 0 deg, max: 180 deg}
)");
  const std::string sample = "2 variables\n0.9 rod_length\n1.2 phase_shift\n3 functions\n1 ASV_1:mean_kinetic_energy\n"
                             "1 ASV_2:k1\n1 ASV_3:peak_crank_torque\n0 derivative_variables\n0 analysis_components\n";
  const auto lhs_run = cli::run("dakota --config " + lhs + " " + write("params.lhs", sample) + " " + results);
  ASSERT_TRUE(lhs_run.exited(0)) << lhs_run.output;
  Eigen::VectorXd x(2);
  x << 0.9, 1.2;
  const opt::Evaluation e = problem_of(lhs)->evaluate(x, {"mean_kinetic_energy", "k1", "peak_crank_torque"}, false);
  std::istringstream in(read(results));
  for (const char* m : {"mean_kinetic_energy", "k1", "peak_crank_torque"}) {
    double v;
    std::string label;
    in >> v >> label;
    EXPECT_EQ(label, m);
    EXPECT_EQ(v, e.at(m));
  }
}

TEST(Dakota, RefusalsNameTheLine) {
  auto refused = [](const std::string& name, std::string text, const std::string& expected) {
    const auto r = cli::run("dakota " + write(name, text) + " " + testing::TempDir() + "/results.bad --config " + kTwin);
    EXPECT_TRUE(r.exited(2)) << r.output;
    EXPECT_NE(r.output.find(expected), std::string::npos) << r.output;
  };
  std::string hessian = kStandard;
  hessian.replace(hessian.find("3 ASV_1"), 1, "7");
  refused("params.hess", hessian, "params.hess:4: function 'mean_kinetic_energy' asks for its Hessian");
  std::string unknown = kStandard;
  unknown.replace(unknown.find("rod_length"), 10, "rod_lenght");
  refused("params.unknown", unknown, "params.unknown:2: variable 'rod_lenght' is not one of the config's variables");
  std::string metric = kStandard;
  metric.replace(metric.find("ASV_2:peak_crank_torque"), 23, "ASV_2:peak_torque");
  refused("params.metric", metric, "params.metric:5: function 'peak_torque' is not a metric");
  const std::string cut = std::string(kStandard).substr(0, std::string(kStandard).find("                                          1 DVV_1"));
  refused("params.cut", cut, "params.cut:7: the file ends inside its derivative_variables");
  refused("params.word", "one variables\n", "params.word:1: expected a count");
  const auto usage = cli::run("dakota " + write("params.u", kStandard) + " " + testing::TempDir() + "/r.u");
  EXPECT_TRUE(usage.exited(2));
  EXPECT_NE(usage.output.find("dakota expects PARAMS RESULTS --config CONFIG"), std::string::npos);
}

}  // namespace
