// Bad input: every file in tests/bad_configs/ must make `mechopt run` exit with
// code 2 and one message naming the file, line:column, key, what was expected
// and what came. The expected text is the file's first line ("# expect: ...").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <sys/wait.h>

#include "cli.hpp"
#include "opt/units.hpp"

namespace {

namespace fs = std::filesystem;

struct Outcome {
  int exit_code;
  std::string output;
};

Outcome run(const std::string& args) {
  const std::string cmd = std::string(MECHOPT_BINARY) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, pipe)) out.append(buf, n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

std::vector<std::string> bad_configs() {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(std::string(MECHOPT_SOURCE_DIR) + "/tests/bad_configs"))
    out.push_back(e.path().stem().string());
  std::sort(out.begin(), out.end());
  return out;
}

class BadConfig : public ::testing::TestWithParam<std::string> {};

TEST_P(BadConfig, ExitsWithCode2AndNamesFileLineKey) {
  const std::string file = std::string(MECHOPT_SOURCE_DIR) + "/tests/bad_configs/" + GetParam() + ".yaml";
  std::ifstream in(file);
  std::string first;
  std::getline(in, first);
  const std::string prefix = "# expect: ";
  ASSERT_EQ(first.rfind(prefix, 0), 0u) << "first line must be '# expect: ...'";
  const std::string expect = first.substr(prefix.size());
  const Outcome o = run("run " + file + " --output " + testing::TempDir() + "/bad_" + GetParam());  // one per test process
  EXPECT_EQ(o.exit_code, 2) << o.output;
  EXPECT_NE(o.output.find("mechopt: error: " + file + ":"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find(expect), std::string::npos) << "expected: " << expect << "\ngot: " << o.output;
  EXPECT_EQ(std::count(o.output.begin(), o.output.end(), '\n'), 1) << "one line: " << o.output;
}

INSTANTIATE_TEST_SUITE_P(Files, BadConfig, ::testing::ValuesIn(bad_configs()),
                         [](const auto& info) { return info.param; });

TEST(BadConfig, AtLeastTenCases) { EXPECT_GE(bad_configs().size(), 10u); }

TEST(CommandLine, UnreadableFileAndBadArgumentsExitWith2) {
  Outcome o = run("run /nonexistent/config.yaml");
  EXPECT_EQ(o.exit_code, 2);
  EXPECT_NE(o.output.find("/nonexistent/config.yaml: cannot read the config file"), std::string::npos);
  EXPECT_EQ(run("frobnicate").exit_code, 2);
  EXPECT_EQ(run("run").exit_code, 2);
  const std::string cfg = std::string(MECHOPT_SOURCE_DIR) + "/configs/recuperative_drive/rod_length.yaml";
  o = run("eval " + cfg + " --set crank_radius=0.2kg");
  EXPECT_EQ(o.exit_code, 2);
  EXPECT_NE(o.output.find("key 'model.crank_radius'"), std::string::npos) << o.output;
}

TEST(CommandLine, EvalPrintsEveryMetricAsJson) {
  // --set takes a unit; T_cp at l = 0.6 m is the reference 2390.178022370431 J
  // (tools/reference_seed000.json).
  const std::string cfg = std::string(MECHOPT_SOURCE_DIR) + "/configs/recuperative_drive/rod_length.yaml";
  const Outcome o = run("eval " + cfg + " --set rod_length=600mm");
  ASSERT_EQ(o.exit_code, 0) << o.output;
  const auto j = nlohmann::json::parse(o.output);
  EXPECT_EQ(j["status"], "ok");
  EXPECT_NEAR(j["metrics"]["mean_kinetic_energy"].get<double>(), 2390.178022370431, 1e-9);
  EXPECT_EQ(j["metrics"].size(), 10u);
  EXPECT_EQ(j["settings"]["model"]["rod_length"], 0.6);
  // An infeasible design is a status, not an error.
  const auto k = nlohmann::json::parse(run("eval " + cfg + " --set rod_length=0.1m").output);
  EXPECT_EQ(k["status"], "cannot_assemble");
  EXPECT_FALSE(k["metrics"].contains("mean_kinetic_energy"));
}

// `eval CONFIG --set ...` against `eval` of the config with the same
// values edited into its text (each `from` replaced by `to`, which must be
// there): the same metrics. Returns the --set run's JSON.
nlohmann::json expect_set_as_edited(const std::string& cfg, const std::string& sets,
                                    const std::vector<std::pair<std::string, std::string>>& edits,
                                    const std::string& dir) {
  const Outcome set = run("eval " + cfg + " " + sets);
  EXPECT_EQ(set.exit_code, 0) << set.output;
  std::ifstream in(cfg);
  std::stringstream text;
  text << in.rdbuf();
  std::string edited = text.str();
  for (const auto& [from, to] : edits) {
    const auto at = edited.find(from);
    if (at == std::string::npos) ADD_FAILURE() << cfg << " changed ('" << from << "' is gone): update this test";
    else edited.replace(at, from.size(), to);
  }
  fs::create_directories(dir);
  std::ofstream(dir + "/config.yaml") << edited;
  const Outcome file = run("eval " + dir + "/config.yaml");
  EXPECT_EQ(file.exit_code, 0) << file.output;
  const auto a = nlohmann::json::parse(set.output), b = nlohmann::json::parse(file.output);
  EXPECT_EQ(a["metrics"], b["metrics"]);
  return a;
}

// --set of a variable whose config gives an `initial` evaluates at the set
// value (it used to print the initial's metrics): as the same config with
// that initial would.
TEST(CommandLine, EvalSetsAVariableOverItsInitial) {
  const std::string cfg = std::string(MECHOPT_SOURCE_DIR) + "/configs/balanced_slider_crank/least_torque.yaml";
  const auto a = expect_set_as_edited(cfg, "--set cam_offset=25mm", {{"initial: 0.0219 m", "initial: 0.025 m"}},
                                      testing::TempDir() + "/eval_set_variable");
  const auto initial = nlohmann::json::parse(run("eval " + cfg).output);
  EXPECT_NE(a["metrics"]["acceleration_deviation"], initial["metrics"]["acceleration_deviation"]);
}

// --set of a linkage's address walks the description: a coordinate of a
// ground point's pair and a spring's free length, as the same edits in the
// file would.
TEST(CommandLine, EvalSetsALinkageAddress) {
  const std::string cfg = std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage/balanced_slider_crank.yaml";
  const auto a = expect_set_as_edited(cfg, "--set ground.C.x=-25mm --set springs.balance.free_length=8.01m",
                                      {{"C: [-0.0219 m, 0 m]", "C: [-0.025 m, 0 m]"},
                                       {"free_length: 8 m}", "free_length: 8.01 m}"}},
                                      testing::TempDir() + "/eval_set_linkage");
  EXPECT_EQ(a["settings"]["model"]["ground"]["C.x"], -0.025);
}

TEST(CommandLine, CheckDerivativesReportsEveryMetric) {
  const std::string cfg = std::string(MECHOPT_SOURCE_DIR) + "/configs/conveyor_swing/optimum.yaml";
  const Outcome o = run("check-derivatives " + cfg);
  EXPECT_EQ(o.exit_code, 0) << o.output;
  EXPECT_NE(o.output.find(" 0 mismatches"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("peak_crank_torque[peak 0]"), std::string::npos) << o.output;
}

TEST(CommandLine, VersionHelpList) {
  EXPECT_EQ(run("--version").output, "mechopt " MECHOPT_VERSION "\n");
  EXPECT_EQ(run("--help").exit_code, 0);
  const Outcome o = run("list");
  EXPECT_NE(o.output.find("recuperative_drive"), std::string::npos);
  EXPECT_NE(o.output.find("units: a unit is symbols with SI prefixes"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("LD_SLSQP"), std::string::npos);
}

// Every command's --help and -h exit 0 with its usage and every option its
// parser takes, wherever the flag stands; the top-level help names every command.
TEST(CommandLine, EveryCommandHasHelp) {
  const std::pair<std::string, std::vector<std::string>> commands[] = {
      {"run", {"CONFIG", "--output", "--threads", "--progress", "--new", "--force", "--dry-run", "--shard"}},
      {"eval", {"CONFIG", "--set"}},
      {"check-derivatives", {"CONFIG", "--set"}},
      {"export", {"STORE", "--csv", "--json", "--canonical"}},
      {"merge", {"OUT", "STORE..."}},
      {"check", {"STORE"}},
      {"recover", {"STORE", "OUT"}},
      {"list", {"--markdown"}},
  };
  const std::string top = run("--help").output;
  for (const auto& [command, options] : commands) {
    EXPECT_NE(top.find("  mechopt " + command + " "), std::string::npos) << command;
    for (const std::string& args : {command + " --help", command + " -h", "help " + command}) {
      const Outcome o = run(args);
      EXPECT_EQ(o.exit_code, 0) << args << ": " << o.output;
      EXPECT_EQ(o.output.rfind("usage: mechopt " + command + " ", 0), 0) << args << ": " << o.output;
      for (const auto& option : options)
        EXPECT_NE(o.output.find("  " + option + " "), std::string::npos) << args << " lacks " << option;
    }
  }
  EXPECT_EQ(run("run config.yaml --threads 2 --help").exit_code, 0);
  EXPECT_EQ(run("frobnicate --help").exit_code, 2);
}

}  // namespace

namespace {

// Model values with units of every kind read through the parameter tables.
TEST(CommandLine, ParameterTableReadsUnitsAndSections) {
  const std::string cfg = std::string(MECHOPT_SOURCE_DIR) + "/configs/elastic_drive/optimum.yaml";
  Outcome o = run("eval " + cfg + " --set \"stiffness=0.11 MN*m/rad\" --set \"coupling_inertia=0.32 kg m^2\"" +
                  " --set \"damping=2 kN m s/rad\"");
  ASSERT_EQ(o.exit_code, 0) << o.output;
  const auto j = nlohmann::json::parse(o.output);
  EXPECT_DOUBLE_EQ(j["settings"]["model"]["stiffness"].get<double>(), 110000);
  EXPECT_DOUBLE_EQ(j["settings"]["model"]["damping"].get<double>(), 2000);
  EXPECT_DOUBLE_EQ(j["settings"]["model"]["coupling_inertia"].get<double>(), 0.32);
  EXPECT_DOUBLE_EQ(j["settings"]["model"]["motor"]["critical_torque"].get<double>(), 215.4);
  // Issue 32's spellings of seed 000's values (kgf = 9.80665 N, 100 rev/min = 10 pi/3 rad/s).
  const std::string recuperative = std::string(MECHOPT_SOURCE_DIR) + "/configs/recuperative_drive/rod_length.yaml";
  o = run("eval " + recuperative + " --set \"crank_speed=100 rev/min\" --set \"cart_resistance=363 kgf\"" +
          " --set \"rod_mass_per_length=0.08 kg/mm\"");
  ASSERT_EQ(o.exit_code, 0) << o.output;
  const auto model = nlohmann::json::parse(o.output)["settings"]["model"];
  EXPECT_DOUBLE_EQ(model["crank_speed"].get<double>(), 10.47197551196597746);
  EXPECT_DOUBLE_EQ(model["cart_resistance"].get<double>(), 3559.81395);
  EXPECT_DOUBLE_EQ(model["rod_mass_per_length"].get<double>(), 80);
  o = run("eval " + cfg + " --set \"stiffness=110 kN m\"");
  EXPECT_EQ(o.exit_code, 2);
  EXPECT_NE(o.output.find("key 'model.stiffness': expected a rotational stiffness"), std::string::npos) << o.output;
}

}  // namespace

namespace {

// `base: FILE` inherits a config's keys, map by map; the config's own values
// win, and an error in the base names the base file and its line.
TEST(CommandLine, BaseFileIsInheritedAndOverridden) {
  const std::string dir = testing::TempDir() + "/base_config";
  fs::create_directories(dir);
  std::ofstream(dir + "/base.yaml") << "problem: recuperative_drive\nmodel: {crank_radius: 0.25 m, rod_length: 0.9 m}\n";
  std::ofstream(dir + "/run.yaml") << "base: base.yaml\nmodel: {rod_length: 0.7 m}\n";
  Outcome o = run("eval " + dir + "/run.yaml");
  ASSERT_EQ(o.exit_code, 0) << o.output;
  const auto j = nlohmann::json::parse(o.output);
  EXPECT_DOUBLE_EQ(j["settings"]["model"]["crank_radius"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["settings"]["model"]["rod_length"].get<double>(), 0.7);
  // An absolute base path is taken as it is (it used to be joined to the
  // config's directory).
  std::ofstream(dir + "/absolute.yaml") << "base: " << fs::absolute(dir + "/base.yaml").string() << "\n";
  o = run("eval " + dir + "/absolute.yaml");
  ASSERT_EQ(o.exit_code, 0) << o.output;
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(o.output)["settings"]["model"]["rod_length"].get<double>(), 0.9);
  std::ofstream(dir + "/base.yaml") << "problem: recuperative_drive\nmodel:\n  crank_radius: 0.25 kg\n";
  o = run("eval " + dir + "/run.yaml");
  EXPECT_EQ(o.exit_code, 2);
  EXPECT_NE(o.output.find(dir + "/base.yaml:3:17: key 'model.crank_radius'"), std::string::npos) << o.output;
  std::ofstream(dir + "/run.yaml") << "base: run.yaml\n";
  o = run("eval " + dir + "/run.yaml");
  EXPECT_EQ(o.exit_code, 2);
  EXPECT_NE(o.output.find("more than 8 base files"), std::string::npos) << o.output;
}

}  // namespace

#include "opt/registry.hpp"

namespace {

// A model value taken from another config's result. The linked config is a
// centred slider-crank (offset 0), whose stroke is exactly 2 r (closed
// form), so the linked value is known without the code under test.
opt::ConfigNode linking(const std::string& link) {
  return opt::ConfigNode::parse("problem: slider_crank\nmodel:\n  rod_length: 1.2 m\n  crank_radius: {from: " +
                                    std::string(MECHOPT_SOURCE_DIR) + "/configs/slider_crank/stroke.yaml, " + link +
                                    "}\nstudy: {type: evaluate}\n",
                                "<links>");
}

TEST(Links, ModelValueIsTheLinkedMetricAtItsDesignWithTheLinksValues) {
  // stroke.yaml's own design has offset 0.02 m (a variable's initial value);
  // the link sets it to 0, and its crank radius to 0.15 m: stroke 0.3 m.
  const auto p = opt::make_problem(linking("metric: stroke, offset: 0 m, crank_radius: 0.15 m"));
  const nlohmann::json r = p->record();
  EXPECT_NEAR(r["model"]["crank_radius"].get<double>(), 0.3, 1e-15);
  ASSERT_EQ(r["links"].size(), 1u);
  EXPECT_EQ(r["links"][0]["key"], "crank_radius");
  EXPECT_EQ(r["links"][0]["metric"], "stroke");
  EXPECT_EQ(r["links"][0]["unit"], "m");
  EXPECT_NEAR(r["links"][0]["value"].get<double>(), 0.3, 1e-15);
  EXPECT_NEAR(r["links"][0]["linked"]["model"]["crank_radius"].get<double>(), 0.15, 0);
  // Its own metrics see the linked radius: stroke 2 x 0.3 m.
  const auto e = p->evaluate(p->initial_point(false), std::vector<std::string>{"stroke"}, false);
  EXPECT_NEAR(e[p->metric_id("stroke")].value, 0.6, 1e-15);
}

TEST(Links, DoeFactorsNameTheLinkedModelValuesAndASampleSetsThem) {
  const opt::ConfigNode root = linking("metric: stroke, offset: 0 m");
  const auto table = opt::model_parameters(root);
  const auto it = std::find_if(table.begin(), table.end(), [](const auto& q) { return q.name == "crank_radius.crank_radius"; });
  ASSERT_NE(it, table.end());
  EXPECT_FALSE(it->variable) << "set in the linked config, which each sample rebuilds";
  EXPECT_EQ(it->dimension, opt::Dimension::length);
  // A sample's value, written as the DOE writes it (over the config).
  YAML::Node over;
  opt::set_dotted(over["model"], "crank_radius.crank_radius", YAML::Node("0.12 m"));
  const auto p = opt::make_problem(root.with(over, "sample 0"));
  EXPECT_NEAR(p->record()["model"]["crank_radius"].get<double>(), 0.24, 1e-15);
  // Without the link, no such factor.
  const auto plain = opt::model_parameters(opt::ConfigNode::parse("problem: slider_crank\n", "<plain>"));
  EXPECT_TRUE(std::none_of(plain.begin(), plain.end(), [](const auto& q) { return q.name.find('.') != std::string::npos; }));
}

}  // namespace

namespace {

// `auto` fidelity: the coarsest level whose compared metrics (the objective
// and constraints) move less than the tolerance from the next finer level at
// the start point. The change is computed here from two configs that name
// the levels outright.
opt::ConfigNode rod_length_with(const std::string& fidelity) {
  // One file per test: ctest runs the tests of this suite as processes side
  // by side, and a shared file was once rewritten under a reader.
  const std::string file = testing::TempDir() + "/fidelity_auto_" +
                           testing::UnitTest::GetInstance()->current_test_info()->name() + ".yaml";
  std::ofstream(file) << "base: " << MECHOPT_SOURCE_DIR << "/configs/recuperative_drive/rod_length.yaml\n"
                      << "model: {fidelity: " << fidelity << "}\n";
  return opt::ConfigNode::load(file);
}

double mean_kinetic_energy(const opt::ConfigNode& root) {
  const auto p = opt::make_problem(root);
  return p->evaluate(p->initial_point(false), std::vector<std::string>{"mean_kinetic_energy"}, false)
      [p->metric_id("mean_kinetic_energy")].value;
}

TEST(FidelityAuto, TheCoarsestLevelWithinTheToleranceOfTheNextFiner) {
  const double point_masses = mean_kinetic_energy(rod_length_with("{rod: point_masses}"));
  const double full = mean_kinetic_energy(rod_length_with("{rod: full}"));
  const double change = std::abs(point_masses - full) / full;
  ASSERT_GT(change, 1e-4);  // the two levels differ: the choice means something
  for (const double tolerance : {change * 2, change / 2}) {
    const auto p = opt::make_problem(rod_length_with("{rod: {auto: " + std::to_string(tolerance) + "}}"));
    const nlohmann::json r = p->record();
    const std::string expected = tolerance > change ? "point_masses" : "full";
    EXPECT_EQ(r["model"]["fidelity"]["rod"], expected) << tolerance;
    ASSERT_EQ(r["fidelity_auto"].size(), 1u);
    const auto& a = r["fidelity_auto"][0];
    EXPECT_EQ(a["key"], "fidelity.rod");
    EXPECT_EQ(a["chosen"], expected);
    EXPECT_EQ(a["compared"], nlohmann::json({"mean_kinetic_energy"}));  // rod_length.yaml's objective
    EXPECT_NEAR(a["steps"][0]["largest_change"].get<double>(), change, 1e-15);
    EXPECT_NE(a["why"].get<std::string>().find("moves mean_kinetic_energy by"), std::string::npos) << a["why"];
    EXPECT_NEAR(mean_kinetic_energy(rod_length_with("{rod: " + expected + "}")),
                p->evaluate(p->initial_point(false), std::vector<std::string>{"mean_kinetic_energy"}, false)
                    [p->metric_id("mean_kinetic_energy")].value,
                0);
  }
}

// `fidelity: auto` makes every fidelity row of the section auto: the rod's
// (the kinematics' binomial series is not a cheaper level, so not one of
// them); its inertia moves the mean energy by 0.5% at l = 0.8 m, more than
// the default 1e-3, so the full rod stays.
TEST(FidelityAuto, ASectionWrittenAutoCoversEveryLevelInIt) {
  const nlohmann::json r = opt::make_problem(rod_length_with("auto"))->record();
  ASSERT_EQ(r["fidelity_auto"].size(), 1u);
  EXPECT_EQ(r["fidelity_auto"][0]["key"], "fidelity.rod");
  EXPECT_EQ(r["model"]["fidelity"]["rod"], "full");
  EXPECT_EQ(r["model"]["fidelity"]["kinematics"], "exact");
}

TEST(FidelityAuto, BadToleranceIsALocatedError) {
  try {
    opt::make_problem(rod_length_with("{rod: {auto: 2}}"));
    FAIL() << "no error";
  } catch (const opt::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("key 'model.fidelity.rod.auto'"), std::string::npos) << e.what();
  }
}

}  // namespace

namespace {

// A whole number may be written in any number form (2e4, 24.0); 32.5 is still
// an error (tests/bad_configs/cycle_points_not_integer.yaml).
TEST(ConfigValues, WholeNumbersInAnyNumberForm) {
  for (const char* text : {"24", "24.0", "2.4e1"}) {
    const auto p = opt::make_problem(opt::ConfigNode::parse(
        std::string("problem: recuperative_drive\nmodel: {cycle_points: ") + text + "}\n", "<whole>"));
    EXPECT_EQ(p->record()["numerics"]["cycle_points"], 24) << text;
  }
}

}  // namespace

namespace {

// Nested aliases ("billion laughs"): &a1 holds nine *a0, &a2 nine *a1, ...,
// twelve deep, about 1 KB of YAML that a walk expands to 9^12 nodes. The
// reader counts the nodes it visits (config.cpp, kMaxNodes) and refuses the
// file with its location, at the problem, the model or one model value, in
// `run` and in `eval`, well inside the 20 s limit given here (unbounded, each
// of these ran past it).
std::string laughs() {
  std::string y = "[&a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]";
  for (int depth = 1; depth <= 12; ++depth) {
    y += ", &a" + std::to_string(depth) + " [";
    for (int k = 0; k < 9; ++k) y += (k ? ", *a" : "*a") + std::to_string(depth - 1);
    y += "]";
  }
  return y + "]";
}

TEST(ConfigValues, NestedAliasesAreRefusedWithTheirPlace) {
  const std::string dir = testing::TempDir() + "/laughs";
  fs::create_directories(dir);
  struct Case {
    std::string key, line, text;
  };
  const Case cases[] = {
      {"problem", "1", "problem: " + laughs() + "\n"},
      {"model", "2", "problem: slider_crank\nmodel: " + laughs() + "\n"},
      {"model.crank_radius", "3", "problem: slider_crank\nmodel:\n  crank_radius: " + laughs() + "\n"},
  };
  for (const auto& [key, line, text] : cases) {
    ASSERT_LT(text.size(), 1500u);
    const std::string file = dir + "/" + key + ".yaml";
    std::ofstream(file) << text;
    for (const std::string& command : {"run " + file + " --output " + dir + "/out", "eval " + file}) {
      const cli::Outcome o = cli::run(command, 20);
      EXPECT_TRUE(o.exited(2)) << command << "\n" << o.output;
      EXPECT_NE(o.output.find(file + ":" + line + ":"), std::string::npos) << o.output;
      EXPECT_NE(o.output.find("key '" + key), std::string::npos) << o.output;
      EXPECT_NE(o.output.find("through its aliases"), std::string::npos) << o.output;
    }
  }
}

}  // namespace
