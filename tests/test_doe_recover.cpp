// A damaged store (docs/doe.md, "Damage"): row checksums catch values that
// SQLite's own checks cannot see; `mechopt check` names what is wrong;
// export and resume say the store is damaged; `mechopt recover` saves every
// intact row, and the run on the recovered store ends with the canonical
// dump of a run that was never damaged. Damage is 4 KiB of random bytes
// written over the file, as a failing disk would.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "cli.hpp"
#include "opt/doe/recover.hpp"
#include "opt/doe/store.hpp"

namespace {

namespace fs = std::filesystem;
using opt::doe::Row;
using opt::doe::Store;
using opt::doe::StoreLayout;

constexpr std::uintmax_t kPage = 65536;  // the store's page size
constexpr std::size_t kDamage = 4096;    // bytes a failing disk loses: a sector group

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

// Overwrites `bytes` bytes of `file` from `offset` with `rng`'s bytes.
void damage(const std::string& file, std::uintmax_t offset, std::size_t bytes, std::mt19937_64& rng) {
  std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
  ASSERT_TRUE(f) << file;
  f.seekp(std::streamoff(offset));
  for (std::size_t k = 0; k < bytes; ++k) f.put(static_cast<char>(rng()));
  ASSERT_TRUE(f) << file << ": cannot write at " << offset;
}

// The first page of each table and index but samples' (sqlite_master, read
// straight through SQLite): pages that hold no rows.
std::vector<std::uintmax_t> pages_without_rows(const std::string& file) {
  std::vector<std::uintmax_t> pages = {1};
  sqlite3* db = nullptr;
  sqlite3_stmt* s = nullptr;
  EXPECT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  EXPECT_EQ(sqlite3_prepare_v2(db, "SELECT rootpage FROM sqlite_master WHERE tbl_name != 'samples' AND rootpage > 0",
                               -1, &s, nullptr), SQLITE_OK);
  while (sqlite3_step(s) == SQLITE_ROW) pages.push_back(std::uintmax_t(sqlite3_column_int64(s, 0)));
  sqlite3_finalize(s);
  sqlite3_close(db);
  return pages;
}

std::uintmax_t meta_page(const std::string& file) {
  sqlite3* db = nullptr;
  sqlite3_stmt* s = nullptr;
  EXPECT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  EXPECT_EQ(sqlite3_prepare_v2(db, "SELECT rootpage FROM sqlite_master WHERE name = 'meta'", -1, &s, nullptr),
            SQLITE_OK);
  EXPECT_EQ(sqlite3_step(s), SQLITE_ROW);
  const auto page = std::uintmax_t(sqlite3_column_int64(s, 0));
  sqlite3_finalize(s);
  sqlite3_close(db);
  return page;
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

// A store whose run was killed with rows in a segment, some of them also in
// the store file (a fold killed half way): check counts each index once and
// finds nothing wrong; recover copies the union; a segment of another run is
// named as a problem.
TEST(DoeRecover, CheckAndRecoverReadTheSegmentsOnce) {
  const std::string dir = cli::fresh_dir("recover_segments"), out = cli::fresh_dir("recover_segments_out");
  const std::vector<Row> all = rows(100);
  {
    Store s(dir, layout(), meta(), false);
    s.append({all.begin(), all.begin() + 60});
    s.segment("t1").append({all.begin() + 40, all.end()});
  }
  auto c = opt::doe::check_store(dir);
  EXPECT_TRUE(c.sound()) << c.problems.front();
  EXPECT_EQ(c.intact, 100);
  EXPECT_EQ(c.missing, 0);
  EXPECT_EQ(c.statuses, (std::map<std::string, std::int64_t>{{"cannot_assemble", 15}, {"ok", 85}}));
  EXPECT_EQ(opt::doe::recover_store(dir, out + "/r").saved, 100);
  EXPECT_EQ(cli::stored_rows(out + "/r"), 100);
  EXPECT_EQ(cli::canonical_dump(out + "/r"), cli::canonical_dump(dir));

  opt::doe::Segment(dir, "other", layout(), "h2").append({all.begin(), all.begin() + 1});
  c = opt::doe::check_store(dir);
  ASSERT_EQ(c.problems.size(), 1u);
  EXPECT_EQ(c.problems[0], "store.seg-other.sqlite: a segment of another run (config_hash h2)");
}

// One bit of one stored value flipped: SQLite's integrity check passes, the
// row's checksum does not; check names the sample, export stops and says so,
// and recover leaves that sample out.
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

  const std::string out = cli::fresh_dir("recover_bit_out");
  const auto r = opt::doe::recover_store(file, out);
  EXPECT_EQ(r.saved, 99);
  const auto again = opt::doe::check_store(out);
  EXPECT_TRUE(again.sound()) << again.problems.front();
  EXPECT_EQ(again.intact, 99);
  EXPECT_EQ(again.missing, 1);
}

// A store from before row checksums: a run refuses it, check reads it as
// unverified, recover copies it into a store with checksums that a run takes.
TEST(DoeRecover, StoreFromBeforeChecksumsIsRecoveredWithThem) {
  const std::string dir = cli::fresh_dir("recover_old");
  Store(dir, layout(), meta(), false).append(rows(100));
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir + "/store.sqlite").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "ALTER TABLE samples DROP COLUMN checksum", nullptr, nullptr, nullptr), SQLITE_OK)
      << sqlite3_errmsg(db);
  sqlite3_close(db);
  try {
    Store s(dir, layout(), meta(), false);
    ADD_FAILURE() << "a store without checksums was resumed";
  } catch (const opt::doe::StoreMismatch& e) {
    EXPECT_TRUE(has(e.what(), "before row checksums; `mechopt recover")) << e.what();
  }
  const auto c = opt::doe::check_store(dir);
  EXPECT_TRUE(c.sound()) << c.problems.front();
  EXPECT_FALSE(c.checksums);
  EXPECT_EQ(c.intact, 100);
  const std::string out = cli::fresh_dir("recover_old_out");
  EXPECT_EQ(opt::doe::recover_store(dir, out).saved, 100);
  const auto again = opt::doe::check_store(out);
  EXPECT_TRUE(again.sound()) << again.problems.front();
  EXPECT_TRUE(again.checksums);
  EXPECT_EQ(again.intact, 100);
  EXPECT_EQ(Store(out, layout(), meta(), false).count(), 100);
}

// A DOE config of `samples` samples in DIR/config.yaml.
std::string config(const std::string& dir, long samples) {
  fs::create_directories(dir);
  std::ofstream(dir + "/config.yaml") << "problem: slider_crank\nstudy:\n  type: doe\n  sampler: sobol\n  samples: "
                                      << samples << "\n  seed: 11\n  factors:\n"
                                         "    crank_radius: {min: 0.05 m, max: 0.25 m}\n"
                                         "    rod_length: {min: 0.6 m, max: 1.4 m}\n"
                                         "    crank_speed: {min: 5 rad/s, max: 15 rad/s}\n";
  return dir + "/config.yaml";
}

struct Finished {
  std::string config, store, dump;  // dump: the canonical one
};

// A finished run of 20 000 samples, once per test program (in a directory
// named after the first test that asks: ctest runs each test as a process
// of its own, perhaps at once).
const Finished& finished_run() {
  static const Finished f = [] {
    const std::string dir =
        cli::fresh_dir(std::string("recover_run_") + testing::UnitTest::GetInstance()->current_test_info()->name());
    Finished r{config(dir, 20000), dir + "/out/store.sqlite", ""};
    // One thread: rows appended in index order, so the file and the pages the
    // seeded damages hit are the same in every run (two threads fold their
    // ranges out of order and leave pages half full, so more damages fall
    // in free space).
    const auto o = cli::run("run " + r.config + " --output " + dir + "/out --progress=none --threads 1");
    EXPECT_TRUE(o.exited(0)) << o.output;
    r.dump = cli::canonical_dump(dir + "/out");
    return r;
  }();
  return f;
}

// A copy of the finished store in DIR/store.sqlite.
std::string copy_of_store(const std::string& dir) {
  fs::create_directories(dir);
  fs::copy_file(finished_run().store, dir + "/store.sqlite");
  return dir + "/store.sqlite";
}

// 20 damages (8 under ASan) at offsets drawn from a fixed seed in the pages that hold rows:
// an export either gives the canonical dump or fails saying the output is
// incomplete; a resume either runs or says the store is damaged; recover,
// then a run of the config on what it saved, gives the canonical dump of the
// undamaged run.
TEST(DoeRecover, TwentyDamagesRecoverToTheCanonicalDump) {
  const Finished& run = finished_run();
  const auto skip = pages_without_rows(run.store);
  const std::uintmax_t pages = fs::file_size(run.store) / kPage;
  std::mt19937_64 rng(20261127);
  constexpr int kDamages = cli::kSanitized ? 8 : 20;
  int found = 0;
  for (int k = 0; k < kDamages; ++k) {
    const std::string dir = cli::fresh_dir("recover_" + std::to_string(k));
    const std::string file = copy_of_store(dir);
    std::uintmax_t page;
    do page = 1 + rng() % pages;
    while (std::find(skip.begin(), skip.end(), page) != skip.end());
    const std::uintmax_t offset = (page - 1) * kPage + rng() % (kPage - kDamage);
    damage(file, offset, kDamage, rng);
    SCOPED_TRACE("damage " + std::to_string(k) + " at " + std::to_string(offset) + " (page " + std::to_string(page) + ")");

    const auto checked = cli::run("check " + file);
    ASSERT_TRUE(checked.exited(0) || checked.exited(1)) << checked.output;
    found += checked.exited(1);
    const auto exported = cli::run("export " + file + " --canonical");
    if (exported.exited(0))
      EXPECT_TRUE(exported.output == run.dump) << "an export of a damaged store ended without saying so";
    else
      EXPECT_TRUE(has(exported.output, "the output is incomplete")) << exported.output.substr(exported.output.size() - 500);
    const auto resumed = cli::run("run " + run.config + " --output " + dir + " --progress=none");
    EXPECT_TRUE(resumed.exited(0) || (resumed.exited(1) && has(resumed.output, "is damaged") &&
                                      has(resumed.output, "mechopt recover")))
        << resumed.output;

    const auto recovered = cli::run("recover " + file + " " + dir + "/recovered");
    ASSERT_TRUE(recovered.exited(0)) << recovered.output;
    const auto again = cli::run("run " + run.config + " --output " + dir + "/recovered --progress=none");
    ASSERT_TRUE(again.exited(0)) << again.output;
    EXPECT_TRUE(cli::canonical_dump(dir + "/recovered") == run.dump);
    fs::remove_all(dir);
  }
  EXPECT_GE(found, kDamages * 3 / 4) << "check found damage in " << found << " of " << kDamages
                                     << " (a damage may fall in a page's free space)";
}

// The first page damaged: the file header and the schema are gone; check and
// recover say so and that nothing can be saved; a resume says the store is
// damaged.
TEST(DoeRecover, DamagedFirstPageIsNamed) {
  const Finished& run = finished_run();
  const std::string dir = cli::fresh_dir("recover_first_page");
  const std::string file = copy_of_store(dir);
  std::mt19937_64 rng(1);
  damage(file, 0, kDamage, rng);
  const auto checked = cli::run("check " + file);
  EXPECT_TRUE(checked.exited(1)) << checked.output;
  EXPECT_TRUE(has(checked.output, "the first page (the file header and the schema) is damaged (file is not a database)"))
      << checked.output;
  const auto recovered = cli::run("recover " + file + " " + dir + "/recovered");
  EXPECT_TRUE(recovered.exited(1)) << recovered.output;
  EXPECT_TRUE(has(recovered.output, "nothing could be saved from " + file)) << recovered.output;
  const auto resumed = cli::run("run " + run.config + " --output " + dir + " --progress=none");
  EXPECT_TRUE(resumed.exited(1)) << resumed.output;
  EXPECT_TRUE(has(resumed.output, file + " is damaged (file is not a database)")) << resumed.output;
  EXPECT_TRUE(has(resumed.output, "`mechopt recover " + file + " OUT`")) << resumed.output;
}

// The meta's page damaged: the config hash is unreadable; check and recover
// say so, recover saves every row without meta, and the run of the config on
// the recovered store supplies the hash and evaluates nothing again.
TEST(DoeRecover, DamagedMetaIsNamedAndTheConfigSuppliesIt) {
  const Finished& run = finished_run();
  const std::string dir = cli::fresh_dir("recover_meta");
  const std::string file = copy_of_store(dir);
  std::mt19937_64 rng(2);
  damage(file, (meta_page(file) - 1) * kPage, kDamage, rng);
  const auto checked = cli::run("check " + file);
  EXPECT_TRUE(checked.exited(1)) << checked.output;
  EXPECT_TRUE(has(checked.output, "config hash: none")) << checked.output;
  EXPECT_TRUE(has(checked.output, "the meta is damaged (")) << checked.output;
  const auto recovered = cli::run("recover " + file + " " + dir + "/recovered");
  EXPECT_TRUE(recovered.exited(0)) << recovered.output;
  EXPECT_TRUE(has(recovered.output, "saved 20000 rows into " + dir + "/recovered/store.sqlite without meta"))
      << recovered.output;
  const auto again = cli::run("run " + run.config + " --output " + dir + "/recovered --progress=none");
  ASSERT_TRUE(again.exited(0)) << again.output;
  EXPECT_TRUE(has(again.output, "resuming: 20000 done")) << again.output;
  EXPECT_TRUE(cli::canonical_dump(dir + "/recovered") == run.dump);
  const auto sound = cli::run("check " + dir + "/recovered");
  EXPECT_TRUE(sound.exited(0)) << sound.output;
  EXPECT_FALSE(has(sound.output, "config hash: none")) << sound.output;
}

}  // namespace
