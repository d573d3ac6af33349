// `mpirun -n 2 mechopt run CONFIG`: the ranks split the samples, each
// commits to files of its own, rank 0 folds them into one store, and its
// canonical dump equals a single process's, byte for byte. This test fails, never skips, when MPI cannot run: CI must
// notice a batch that lost its ranks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli.hpp"

namespace {

// The canonical dumps of CONFIG run on 2 ranks and on 1 process.
std::pair<std::string, std::string> two_ranks_and_one(const std::string& dir, const std::string& config) {
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/config.yaml") << config;
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  const std::string mpirun = "mpirun -n 2 --oversubscribe " + std::string(MECHOPT_BINARY);
  const std::string cmd = "timeout -k 5 300 " + mpirun + " run " + dir + "/config.yaml --output " + dir +
                          "/two --progress=none 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  EXPECT_NE(pipe, nullptr);
  if (!pipe) return {};
  std::string output;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, pipe)) output.append(buf, n);
  EXPECT_EQ(pclose(pipe), 0) << "mpirun failed (is OpenMPI installed?):\n" << output;
  std::ifstream in(dir + "/two/result.json");
  EXPECT_TRUE(in) << output;
  if (!in) return {};
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["ranks"], 2) << "mechopt was built without MPI, or mpirun gave one rank";
  EXPECT_EQ(j["run_status"], "complete");
  EXPECT_TRUE(cli::segment_files(dir + "/two").empty()) << "a segment was left unfolded";
  const auto one = cli::run("run " + dir + "/config.yaml --output " + dir + "/one --progress=none --threads 1");
  EXPECT_TRUE(one.exited(0)) << one.output;
  return {cli::canonical_dump(dir + "/two"), cli::canonical_dump(dir + "/one")};
}

TEST(DoeMpi, TwoRanksWriteOneStoreEqualToOneProcess) {
  // crank_speed is a model value: every rank rebuilds the problem per sample.
  const auto [two, one] = two_ranks_and_one(cli::fresh_dir("doe_mpi"), R"(problem: slider_crank
study:
  type: doe
  sampler: latin_hypercube
  samples: 3000
  seed: 5
  factors:
    crank_radius: {min: 0.05 m, max: 0.25 m}
    crank_speed: {min: 5 rad/s, max: 15 rad/s}
)");
  EXPECT_EQ(std::count(two.begin(), two.end(), '\n'), 3001) << "a header and 3000 rows";
  EXPECT_EQ(two, one) << "the canonical dumps of 2 ranks and 1 process differ";
}

// Enough rows that rank 1 closes segments (65 536 rows each) for rank 0 to
// fold while the run goes.
TEST(DoeMpi, RanksSegmentsFoldedAlongGiveTheSameStore) {
  const auto [two, one] = two_ranks_and_one(cli::fresh_dir("doe_mpi_segments"), R"(problem: slider_crank
study:
  type: doe
  sampler: sobol
  samples: 300000
  factors:
    crank_radius: {min: 0.05 m, max: 0.25 m}
    rod_length: {min: 0.6 m, max: 1.4 m}
)");
  EXPECT_EQ(std::count(two.begin(), two.end(), '\n'), 300001) << "a header and 300000 rows";
  EXPECT_TRUE(two == one) << "the canonical dumps of 2 ranks and 1 process differ";
}

}  // namespace
