// `mpirun -n 2 mechopt run CONFIG`: the ranks split the samples, rank 0
// writes one store, and its canonical dump equals a single process's, byte
// for byte. This test fails, never skips, when MPI cannot run: CI must
// notice a batch that lost its ranks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli.hpp"

namespace {

TEST(DoeMpi, TwoRanksWriteOneStoreEqualToOneProcess) {
  const std::string dir = cli::fresh_dir("doe_mpi");
  std::filesystem::create_directories(dir);
  // crank_speed is a model value: every rank rebuilds the problem per sample.
  std::ofstream(dir + "/config.yaml") << R"(problem: slider_crank
study:
  type: doe
  sampler: latin_hypercube
  samples: 3000
  seed: 5
  factors:
    crank_radius: {min: 0.05 m, max: 0.25 m}
    crank_speed: {min: 5 rad/s, max: 15 rad/s}
)";
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  const std::string mpirun = "mpirun -n 2 --oversubscribe " + std::string(MECHOPT_BINARY);
  const std::string cmd = "timeout -k 5 300 " + mpirun + " run " + dir + "/config.yaml --output " + dir +
                          "/two --progress=none 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, pipe)) output.append(buf, n);
  ASSERT_EQ(pclose(pipe), 0) << "mpirun failed (is OpenMPI installed?):\n" << output;
  std::ifstream in(dir + "/two/result.json");
  ASSERT_TRUE(in) << output;
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["ranks"], 2) << "mechopt was built without MPI, or mpirun gave one rank";
  EXPECT_EQ(j["run_status"], "complete");
  const auto one = cli::run("run " + dir + "/config.yaml --output " + dir + "/one --progress=none --threads 1");
  ASSERT_TRUE(one.exited(0)) << one.output;
  const std::string a = cli::canonical_dump(dir + "/two"), b = cli::canonical_dump(dir + "/one");
  EXPECT_EQ(std::count(a.begin(), a.end(), '\n'), 3001) << "a header and 3000 rows";
  EXPECT_EQ(a, b) << "the canonical dumps of 2 ranks and 1 process differ";
}

}  // namespace
