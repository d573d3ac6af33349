// Stability maps (configs/*/stability_map.yaml): each is a factorial over two
// parameters across a failure boundary, run as a user runs it; every failure
// region must be its typed status, checked here against closed forms
// written independently of the models:
// - the recuperative drive assembles iff r + |e| < l (the rod reaches the
//   slider axis at every crank angle);
// - the conveyor's four-bar: Grashof's s + l <= p + q, and the crank turns
//   fully iff |O1A|'s span [|l4 - l1|, l4 + l1] lies inside the loop's
//   [|l2 - l3|, l2 + l3];
// - the elastic drive: the explicit method runs out of its step budget under
//   heavy damping, where BDF solves the same design, and with a stiff, light
//   coupling, where BDF does not either.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <fstream>

#include "cli.hpp"
#include "mech/status.hpp"
#include "opt/config.hpp"
#include "opt/registry.hpp"

namespace {

struct Sample {
  std::string status;
  double x, y;  // the two factors, SI
};

// Runs configs/PROBLEM/stability_map.yaml; its samples and its result.json.
std::vector<Sample> run_map(const std::string& problem, const std::string& fx, const std::string& fy,
                            nlohmann::json& result) {
  const std::string dir = cli::fresh_dir("stability_" + problem);
  const auto o = cli::run("run " + cli::source("configs/" + problem + "/stability_map.yaml") + " --output " + dir +
                          " --progress=none");
  EXPECT_TRUE(o.exited(0)) << o.output;
  std::ifstream in(dir + "/result.json");
  result = nlohmann::json::parse(in);
  EXPECT_TRUE(std::filesystem::exists(dir + "/status_map.svg"));
  std::vector<Sample> out;
  sqlite3* db = nullptr;
  sqlite3_stmt* st = nullptr;
  EXPECT_EQ(sqlite3_open_v2((dir + "/store.sqlite").c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  const std::string q = "select status, \"" + fx + "\", \"" + fy + "\" from samples order by idx";
  EXPECT_EQ(sqlite3_prepare_v2(db, q.c_str(), -1, &st, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  while (sqlite3_step(st) == SQLITE_ROW)
    out.push_back({reinterpret_cast<const char*>(sqlite3_column_text(st, 0)), sqlite3_column_double(st, 1),
                   sqlite3_column_double(st, 2)});
  sqlite3_finalize(st);
  sqlite3_close(db);
  return out;
}

std::map<std::string, int> counts(const std::vector<Sample>& samples) {
  std::map<std::string, int> n;
  for (const auto& s : samples) ++n[s.status];
  return n;
}

TEST(StabilityMap, RecuperativeDriveAssemblesExactlyWhereTheRodReaches) {
  nlohmann::json result;
  const auto samples = run_map("recuperative_drive", "crank_radius", "rod_length", result);
  ASSERT_EQ(samples.size(), 41u * 46u);
  const double offset = 0.055;  // the config's
  int reaches = 0;
  for (const auto& s : samples) {
    const bool assembles = s.x + offset < s.y;
    reaches += assembles;
    EXPECT_EQ(s.status, assembles ? "ok" : "cannot_assemble") << "r " << s.x << ", l " << s.y;
  }
  // On the 0.01 m grid r + 0.055 < l iff j >= i + 1: sum over i of (45 - i).
  EXPECT_EQ(reaches, 1025);
  EXPECT_EQ(result["summary"]["failures"]["cannot_assemble"]["count"], 41 * 46 - 1025);
}

TEST(StabilityMap, ConveyorFourBarFailsAsGrashofAndItsLoopSay) {
  nlohmann::json result;
  const auto samples = run_map("conveyor_swing", "crank_length", "coupler_length", result);
  const double l3 = 1.8, l4 = std::hypot(1.0, 2.2);  // the config's rocker and frame
  for (const auto& s : samples) {
    const double l1 = s.x, l2 = s.y;
    const double links[4] = {l1, l2, l3, l4};
    const double shortest = *std::min_element(links, links + 4), longest = *std::max_element(links, links + 4);
    const bool grashof = shortest + longest <= l1 + l2 + l3 + l4 - shortest - longest;
    const bool turns = std::abs(l4 - l1) > std::abs(l2 - l3) && l4 + l1 < l2 + l3;
    SCOPED_TRACE("l1 " + std::to_string(l1) + ", l2 " + std::to_string(l2));
    if (s.status == "ok") {
      EXPECT_TRUE(grashof && turns);
    } else if (s.status == "not_grashof") {
      EXPECT_FALSE(grashof);
    } else if (s.status == "toggle_in_cycle") {
      EXPECT_TRUE(grashof && !turns);
    }
  }
  const auto n = counts(samples);
  for (const char* status : {"ok", "not_grashof", "toggle_in_cycle"}) EXPECT_GT(n.count(status), 0u) << status;
}

// Two regions, two reasons: a heavy damper makes the system stiff (the
// explicit method's steps must stay tiny, BDF's need not), and a stiff,
// lightly damped coupling oscillates fast (every method must resolve it).
bool bdf_solves(const std::string& stiffness, const std::string& damping) {
  const auto p = opt::make_problem(opt::ConfigNode::parse(
      "problem: elastic_drive\nmodel: {stiffness: " + stiffness + ", damping: " + damping +
          ",\n        ode: {method: bdf, rtol: 1e-8, max_steps: 20000}}\n",
      "<bdf>"));
  const auto e = p->evaluate(p->initial_point(false), std::vector<std::string>{"peak_coupling_torque"}, false);
  EXPECT_TRUE(e.ok() || e.status == mech::Status::too_many_steps) << mech::to_string(e.status);
  return e.ok();
}

TEST(StabilityMap, ExplicitMethodRunsOutOfStepsWhereTheDriveIsStiffOrFast) {
  nlohmann::json result;
  const auto samples = run_map("elastic_drive", "stiffness", "damping", result);
  const auto n = counts(samples);
  EXPECT_GT(n.at("ok"), 0);
  EXPECT_GT(n.at("too_many_steps"), 0);
  auto status_at = [&](double c, double k) {
    const auto s = std::find_if(samples.begin(), samples.end(), [&](const Sample& s) { return s.x == c && s.y == k; });
    return s == samples.end() ? std::string("missing") : s->status;
  };
  EXPECT_EQ(status_at(1e3, 1e6), "too_many_steps");  // stiff: heavy damping
  EXPECT_TRUE(bdf_solves("1e3 N m/rad", "1e6 N m s/rad"));
  EXPECT_EQ(status_at(1e10, 10), "too_many_steps");  // fast: a stiff, light coupling
  EXPECT_FALSE(bdf_solves("1e10 N m/rad", "10 N m s/rad"));
  EXPECT_EQ(status_at(1e5, 1e3), "ok");
}

}  // namespace
