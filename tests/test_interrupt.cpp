// SIGINT and SIGTERM during a run: the evaluation under way finishes, every
// row done so far is written, result.json says "interrupted", the exit code
// is 128 + the signal, and no partial file or earlier run's result remains.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include "cli.hpp"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;

// A sweep of 20 000 rod lengths at 20 000 cycle points each: long enough
// (seconds) to be stopped midway.
const char* kLongSweep = R"(problem: recuperative_drive
model: {cycle_points: 20000}
variables: {rod_length: {min: 0.5 m, max: 1.5 m}}
objective: {minimize: k1}
study: {type: sweep, grid: {rod_length: {from: 0.5 m, to: 1.49999 m, step: 5e-5 m}}}
)";

long lines_in(const std::string& file) {
  std::ifstream in(file);
  long n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}


// Runs the sweep, sends `sig` once its store has some rows, and returns the
// exit code.
int interrupted_run(const std::string& dir, int sig) {
  fs::create_directories(dir);
  std::ofstream(dir + "/config.yaml") << kLongSweep;
  // A stale result of an earlier run in the same directory.
  fs::create_directories(dir + "/out");
  std::ofstream(dir + "/out/result.json") << R"({"stale": true})";
  const pid_t pid = fork();
  if (pid == 0) {
    freopen((dir + "/log.txt").c_str(), "w", stdout);
    execl(MECHOPT_BINARY, "mechopt", "run", (dir + "/config.yaml").c_str(), "--output",
          (dir + "/out").c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (cli::stored_rows(dir + "/out") < 50 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  kill(pid, sig);
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

void expect_interrupted_output(const std::string& dir) {
  EXPECT_FALSE(fs::exists(dir + "/out/sweep.csv.partial"));
  EXPECT_FALSE(fs::exists(dir + "/out/result.json.partial"));
  std::ifstream in(dir + "/out/result.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_FALSE(j.contains("stale"));
  EXPECT_EQ(j["run_status"], "interrupted");
  const long evaluated = j["sweep"]["evaluated"].get<long>();
  EXPECT_GE(evaluated, 50);
  EXPECT_LT(evaluated, j["sweep"]["points"].get<long>());
  EXPECT_EQ(lines_in(dir + "/out/sweep.csv"), evaluated + 1);  // the header and one row each
  EXPECT_FALSE(j.contains("status")) << "no optimisation after an interrupted sweep";
}

TEST(Interrupt, SigintWritesWhatWasDoneAndExits130) {
  const std::string dir = testing::TempDir() + "/interrupt_int";
  fs::remove_all(dir);
  EXPECT_EQ(interrupted_run(dir, SIGINT), 130);
  expect_interrupted_output(dir);
}

TEST(Interrupt, SigtermWritesWhatWasDoneAndExits143) {
  const std::string dir = testing::TempDir() + "/interrupt_term";
  fs::remove_all(dir);
  EXPECT_EQ(interrupted_run(dir, SIGTERM), 143);
  expect_interrupted_output(dir);
}

}  // namespace
