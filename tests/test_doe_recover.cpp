// A damaged store (docs/doe.md, "Damage"): row checksums catch values that
// SQLite's own checks cannot see; `mechopt check` names what is wrong;
// export says the store is damaged.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "cli.hpp"
#include "opt/doe/recover.hpp"
#include "opt/doe/store.hpp"

namespace {

namespace fs = std::filesystem;
using opt::doe::Row;
using opt::doe::Store;
using opt::doe::StoreLayout;

// A real factor, a categorical one, two metrics.
StoreLayout layout() { return {{"rod_length", "fidelity.rod"}, {{}, {"rigid", "elastic"}}, {"k1", "peak_torque"}}; }

std::map<std::string, std::string> meta() { return {{"config_hash", "h1"}, {"samples", "100"}}; }

// Rows 0..n-1 with values that exercise every kind a row holds: a message,
// NULL metrics, -0.0 (stored as the integer 0), a categorical factor.
std::vector<Row> rows(std::int64_t n) {
  std::vector<Row> r;
  for (std::int64_t i = 0; i < n; ++i) {
    Row row{i, i % 7 ? "ok" : "cannot_assemble", 1e-4 * double(i), i % 7 ? "" : "rod too short",
            {i % 5 ? 0.5 + 0.01 * double(i) : -0.0, double(i % 2)}, {1234.5 + double(i), i % 7 ? 2.25 : NAN}};
    r.push_back(row);
  }
  return r;
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A sound store checks sound: every row intact, counts by status, the hash.
TEST(DoeRecover, SoundStoreChecksSound) {
  const std::string dir = cli::fresh_dir("recover_sound");
  Store(dir, layout(), meta(), false).append(rows(100));
  const auto c = opt::doe::check_store(dir);
  EXPECT_TRUE(c.sound()) << c.problems.front();
  EXPECT_EQ(c.config_hash, "h1");
  EXPECT_EQ(c.intact, 100);
  EXPECT_EQ(c.missing, 0);
  EXPECT_EQ(c.statuses, (std::map<std::string, std::int64_t>{{"cannot_assemble", 15}, {"ok", 85}}));
  const auto o = cli::run("check " + dir + "/store.sqlite");
  EXPECT_TRUE(o.exited(0)) << o.output;
  EXPECT_TRUE(has(o.output, "by status: cannot_assemble 15 ok 85\nsound\n")) << o.output;
}

// One bit of one stored value flipped: SQLite's integrity check passes, the
// row's checksum does not; check names the sample, export stops and says so.
TEST(DoeRecover, ChecksumCatchesWhatSQLiteCannotSee) {
  const std::string dir = cli::fresh_dir("recover_bit");
  Store(dir, layout(), meta(), false).append(rows(100));
  const std::string file = dir + "/store.sqlite";
  // Sample 42's k1, 1276.5, as SQLite stores a REAL: 8 bytes big-endian.
  const auto bits = std::bit_cast<std::uint64_t>(1234.5 + 42);
  std::string pattern;
  for (int k = 7; k >= 0; --k) pattern += static_cast<char>(bits >> (8 * k));
  std::string bytes;
  {
    std::ifstream in(file, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto at = bytes.find(pattern);
  ASSERT_NE(at, std::string::npos);
  ASSERT_EQ(bytes.find(pattern, at + 1), std::string::npos);
  bytes[at + 7] ^= 1;  // the last bit of the mantissa: 1276.5000000000002
  std::ofstream(file, std::ios::binary) << bytes;

  const auto c = opt::doe::check_store(file);
  ASSERT_EQ(c.problems.size(), 1u);
  EXPECT_EQ(c.problems[0], "rows whose checksum fails (damaged values) 1: 42");
  EXPECT_EQ(c.intact, 99);
  const auto checked = cli::run("check " + file);
  EXPECT_TRUE(checked.exited(1)) << checked.output;
  const auto exported = cli::run("export " + file + " --csv");
  EXPECT_TRUE(exported.exited(1)) << exported.output;
  EXPECT_TRUE(has(exported.output, file + " is damaged (sample 42 fails its checksum)")) << exported.output;
  EXPECT_TRUE(has(exported.output, "mechopt: export: the output is incomplete")) << exported.output;
  EXPECT_TRUE(has(exported.output, "\n41,")) << "the rows before it";

}

}  // namespace
