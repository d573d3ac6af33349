// Every config in configs/ runs through the command line: exit code 0, a
// result.json whose status is a success, and the files a user expects.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

namespace {

namespace fs = std::filesystem;

std::vector<std::string> configs() {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(std::string(MECHOPT_SOURCE_DIR) + "/configs"))
    if (e.path().extension() == ".yaml")
      out.push_back(fs::relative(e.path(), std::string(MECHOPT_SOURCE_DIR) + "/configs").string());
  std::sort(out.begin(), out.end());
  return out;
}

class Config : public ::testing::TestWithParam<std::string> {};

// A doe config of more than kSlice samples runs its first shard of about
// kSlice samples (`--shard 0/K`, as a job array's first task would): every
// key is read and every step runs, without 10^6 evaluations per test run
// (minutes under the sanitizers).
constexpr long kSlice = 5000;

std::string shard_flag(const std::string& config) {
  std::ifstream in(config);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // (no std::regex: GCC 12's <regex> trips -Wmaybe-uninitialized in the sanitizer build)
  const std::string key = "\n  samples: ";
  const auto at = text.find(key);
  if (at == std::string::npos) return "";
  const long n = static_cast<long>(std::strtod(text.c_str() + at + key.size(), nullptr));
  return n > kSlice ? " --shard 0/" + std::to_string((n + kSlice - 1) / kSlice) : "";
}

TEST_P(Config, RunsAndWritesResults) {
  const std::string dir = testing::TempDir() + "/e2e_" + std::to_string(std::hash<std::string>{}(GetParam()));
  fs::remove_all(dir);
  const std::string config = std::string(MECHOPT_SOURCE_DIR) + "/configs/" + GetParam();
  const std::string cmd = std::string(MECHOPT_BINARY) + " run " + config + shard_flag(config) + " --output " + dir +
                          " > " + dir + ".log 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "see " << dir << ".log";
  std::ifstream in(dir + "/result.json");
  ASSERT_TRUE(in) << "no result.json";
  const auto j = nlohmann::json::parse(in);
  // configs/PROBLEM/NAME.yaml, or configs/doe/PROBLEM[_NAME].yaml
  const fs::path p(GetParam());
  const std::string problem = j["problem"];
  if (p.parent_path() == "doe") EXPECT_EQ(p.stem().string().rfind(problem, 0), 0u) << problem;
  else EXPECT_EQ(problem, p.parent_path().string());
  EXPECT_FALSE(j["mechopt_version"].get<std::string>().empty());
  EXPECT_TRUE(j.contains("settings"));
  if (j.contains("status")) {
    EXPECT_EQ(j["status"], "converged") << j["message"];
    EXPECT_EQ(j["design_status"], "ok");
    EXPECT_GT(j["evaluations"].get<int>(), 0);
    for (const auto& [name, v] : j["metrics"].items()) EXPECT_TRUE(v.is_number()) << name;
    EXPECT_TRUE(fs::exists(dir + "/history.csv"));
  }
  if (j["study"] == "sweep") {
    EXPECT_TRUE(fs::exists(dir + "/sweep.csv"));
  }
  if (j["study"] == "sweep" || j["study"] == "doe") {  // the store closed: its WAL checkpointed and gone
    EXPECT_FALSE(fs::exists(dir + "/store.sqlite-wal"));
    EXPECT_FALSE(fs::exists(dir + "/store.sqlite-shm"));
  }
  if (j["study"] == "doe") {
    EXPECT_TRUE(fs::exists(dir + "/store.sqlite"));
    EXPECT_EQ(j["run_status"], "complete");
  }
  if (j.contains("charts")) {  // (const json's [] on a missing key is undefined)
    for (const auto& f : j["charts"]) EXPECT_TRUE(fs::exists(f.get<std::string>())) << f;
  }
  if (j.contains("variables") && j["variables"].size() == 1) {
    EXPECT_TRUE(fs::exists(dir + "/chart.svg"));
  }
}

INSTANTIATE_TEST_SUITE_P(All, Config, ::testing::ValuesIn(configs()), [](const auto& info) {
  std::string n = info.param;
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
});

}  // namespace
