// The DOE results store (docs/doe.md, "The store", "Resume, exactly"): rows
// round-trip, a resumed run sees what is done, another config is refused, a
// duplicate is a bug, a SIGKILL loses whole batches only, and export and merge
// write what a reader expects. Expected texts are written out by hand.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>
#include <variant>

#include "opt/doe/store.hpp"

namespace {

namespace fs = std::filesystem;
using opt::doe::Row;
using opt::doe::Store;
using opt::doe::StoreLayout;
using opt::doe::StoreMismatch;
using opt::doe::row_bytes;
using Meta = std::map<std::string, std::string>;

// A fresh directory per test, removed afterwards.
struct TempDir {
  explicit TempDir(const std::string& name)
      : path((fs::temp_directory_path() / ("doe_store_" + name + "_" + std::to_string(getpid()))).string()) {
    fs::remove_all(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string file() const { return path + "/store.sqlite"; }
  std::string path;
};

// A real factor, a categorical one whose name holds a dot, and two metrics.
StoreLayout layout() { return {{"rod_length", "fidelity.rod"}, {{}, {"rigid", "elastic"}}, {"k1", "peak_torque"}}; }

Meta meta(const std::string& hash, const std::string& canonical = "{}") {
  return {{"config_hash", hash}, {"config_canonical", canonical}, {"samples", "10"}};
}

Row row(std::int64_t i, double k1 = 1.5) { return {i, "ok", 0.5, "", {0.1 * double(i), double(i % 2)}, {k1, 2.25}}; }

std::vector<Row> rows(std::int64_t first, std::int64_t n) {
  std::vector<Row> r;
  for (std::int64_t i = first; i < first + n; ++i) r.push_back(row(i));
  return r;
}

// A cell read straight through the C API, independent of the code under test.
using Cell = std::variant<std::monostate, std::int64_t, double, std::string>;

std::vector<std::vector<Cell>> query(const std::string& file, const std::string& sql) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* s = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  std::vector<std::vector<Cell>> out;
  while (sqlite3_step(s) == SQLITE_ROW) {
    auto& r = out.emplace_back();
    for (int c = 0; c < sqlite3_column_count(s); ++c) {
      switch (sqlite3_column_type(s, c)) {
        case SQLITE_NULL: r.emplace_back(); break;
        case SQLITE_INTEGER: r.emplace_back(std::int64_t(sqlite3_column_int64(s, c))); break;
        case SQLITE_FLOAT: r.emplace_back(sqlite3_column_double(s, c)); break;
        default: r.emplace_back(std::string(reinterpret_cast<const char*>(sqlite3_column_text(s, c))));
      }
    }
  }
  sqlite3_finalize(s);
  sqlite3_close(db);
  return out;
}

// NULL -> NaN, as a reader of the store does.
double real(const Cell& c) { return std::holds_alternative<double>(c) ? std::get<double>(c) : NAN; }

TEST(DoeStore, RowsRoundTrip) {
  TempDir dir("round_trip");
  Store s(dir.path, layout(), meta("h1"), false);
  EXPECT_EQ(s.path(), dir.file());
  std::vector<Row> batch = {row(0), row(3, NAN), row(1)};
  batch[1].status = "cannot_assemble";
  batch[1].message = "rod too short";
  s.append(batch);

  EXPECT_EQ(s.count(), 3);
  EXPECT_EQ(s.finished(5), (std::vector<bool>{true, true, false, true, false}));
  EXPECT_THROW(s.finished(3), std::runtime_error);  // index 3 is not in [0, 3)
  EXPECT_EQ(s.meta("config_hash"), "h1");
  EXPECT_EQ(s.meta("nothing"), std::nullopt);
  s.set_meta("finished", "2024-01-01");
  s.set_meta("finished", "2024-01-02");
  EXPECT_EQ(s.meta("finished"), "2024-01-02");

  const auto r = query(dir.file(), "SELECT * FROM samples ORDER BY idx");
  ASSERT_EQ(r.size(), 3u);
  ASSERT_EQ(r[2].size(), 9u);  // idx, status, wall_time, message, 2 factors, 2 metrics, checksum
  EXPECT_EQ(std::get<std::int64_t>(r[2][0]), 3);
  EXPECT_EQ(std::get<std::string>(r[2][1]), "cannot_assemble");
  EXPECT_EQ(real(r[2][2]), 0.5);
  EXPECT_EQ(std::get<std::string>(r[2][3]), "rod too short");
  EXPECT_TRUE(std::holds_alternative<std::monostate>(r[0][3]));  // "" -> NULL
  EXPECT_EQ(real(r[2][4]), 0.1 * 3);
  EXPECT_EQ(std::get<std::string>(r[2][5]), "elastic");  // option 1 by its name
  EXPECT_EQ(std::get<std::string>(r[0][5]), "rigid");
  EXPECT_TRUE(std::holds_alternative<std::monostate>(r[2][6]));  // NaN -> NULL
  EXPECT_TRUE(std::isnan(real(r[2][6])));                        // -> NaN
  EXPECT_EQ(real(r[1][6]), 1.5);
  EXPECT_TRUE(std::holds_alternative<std::int64_t>(r[0][8]));

  // Movable: the runner keeps it in a member.
  Store moved = std::move(s);
  EXPECT_EQ(moved.count(), 3);
}

TEST(DoeStore, BadRowsAreRefusedBeforeWriting) {
  TempDir dir("bad_rows");
  Store s(dir.path, layout(), meta("h1"), false);
  Row wrong_size = row(0);
  wrong_size.metrics.pop_back();
  EXPECT_THROW(s.append(std::vector{wrong_size}), std::invalid_argument);
  Row bad_option = row(1);
  bad_option.factors[1] = 2;  // two options: 0, 1
  EXPECT_THROW(s.append(std::vector{row(0), bad_option}), std::invalid_argument);
  EXPECT_EQ(s.count(), 0);
  EXPECT_THROW(Store(dir.path, layout(), {{"samples", "10"}}, false), std::invalid_argument);  // no config_hash
}

TEST(DoeStore, ReopenResumesOrRefusesAnotherConfig) {
  TempDir dir("reopen");
  const std::string old_config = R"({"problem": "slider_crank", "samples": 10, "seed": 1, "output": "a"})";
  {
    Store s(dir.path, layout(), meta("h1", old_config), false);
    s.append(rows(0, 4));
    s.set_meta("started", "yesterday");
  }
  {
    Meta again = meta("h1", old_config);
    again["started"] = "today";
    again["mechopt_version"] = "0.2";
    Store s(dir.path, layout(), again, false);
    EXPECT_EQ(s.count(), 4);
    EXPECT_EQ(s.finished(10), (std::vector<bool>{true, true, true, true, false, false, false, false, false, false}));
    EXPECT_EQ(s.meta("started"), "yesterday");    // kept
    EXPECT_EQ(s.meta("mechopt_version"), "0.2");  // added
  }
  const std::string new_config = R"({"problem": "slider_crank", "samples": 20, "seed": 1, "sampler": "sobol"})";
  try {
    Store s(dir.path, layout(), meta("h2", new_config), false);
    FAIL() << "another config_hash was accepted";
  } catch (const StoreMismatch& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(dir.file()), std::string::npos) << what;
    EXPECT_NE(what.find("keys that differ: samples"), std::string::npos) << what;
    EXPECT_NE(what.find("only in the store: output"), std::string::npos) << what;
    EXPECT_NE(what.find("only in this run: sampler"), std::string::npos) << what;
    EXPECT_EQ(what.find("problem"), std::string::npos) << what;
  }
  // Same config, other columns (a metric added by a newer mechopt).
  StoreLayout more = layout();
  more.metrics.push_back("stroke");
  try {
    Store s(dir.path, more, meta("h1", old_config), false);
    FAIL() << "other columns were accepted";
  } catch (const StoreMismatch& e) {
    EXPECT_NE(std::string(e.what()).find("stroke"), std::string::npos) << e.what();
  }
  // --new: the old store moves aside, whole; the new one starts empty.
  Store s(dir.path, layout(), meta("h2", new_config), true);
  EXPECT_EQ(s.count(), 0);
  std::vector<std::string> old;
  for (const auto& e : fs::directory_iterator(dir.path))
    if (e.path().filename().string().starts_with("store.sqlite.old-")) old.push_back(e.path().string());
  ASSERT_EQ(old.size(), 1u);
  EXPECT_EQ(fs::path(old[0]).filename().string().size(), std::string("store.sqlite.old-20240101-120000").size());
  EXPECT_EQ(std::get<std::int64_t>(query(old[0], "SELECT count(*) FROM samples")[0][0]), 4);
}

// One writer at a time: while a Store lives, a second one on its directory
// is refused, naming the first by pid, host and start time, and a --new
// moves nothing aside; a reader reads on; the lock goes with the first.
TEST(DoeStore, SecondWriterIsRefusedWhileTheFirstLives) {
  TempDir dir("lock");
  {
    Store first(dir.path, layout(), meta("h1"), false);
    first.append(rows(0, 3));
    for (const bool fresh : {false, true}) {
      try {
        Store second(dir.path, layout(), meta("h1"), fresh);
        ADD_FAILURE() << "fresh=" << fresh << ": a second writer was accepted";
      } catch (const opt::doe::StoreBusy& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(dir.file()), std::string::npos) << what;
        EXPECT_NE(what.find("pid " + std::to_string(getpid()) + ", host "), std::string::npos) << what;
        EXPECT_NE(what.find(", started 20"), std::string::npos) << what;
      }
    }
    for (const auto& e : fs::directory_iterator(dir.path))
      EXPECT_FALSE(e.path().filename().string().starts_with("store.sqlite.old-")) << e.path() << ": moved aside";
    const auto done = Store::peek(dir.path, layout(), meta("h1"), 10);
    ASSERT_TRUE(done);
    EXPECT_EQ(std::count(done->begin(), done->end(), true), 3);
  }
  Store again(dir.path, layout(), meta("h1"), false);
  EXPECT_EQ(again.count(), 3);
}

// --dry-run's view: nothing when there is no store (and none is made), the
// finished bitmap of this run's store, a refusal for another config's.
TEST(DoeStore, PeekReadsWithoutWriting) {
  TempDir dir("peek");
  EXPECT_FALSE(Store::peek(dir.path, layout(), meta("h1"), 10));
  EXPECT_FALSE(fs::exists(dir.path)) << "a peek creates nothing";
  {
    Store s(dir.path, layout(), meta("h1"), false);
    s.append(rows(2, 3));
  }
  const auto done = Store::peek(dir.path, layout(), meta("h1"), 10);
  ASSERT_TRUE(done);
  EXPECT_EQ(*done, (std::vector<bool>{false, false, true, true, true, false, false, false, false, false}));
  EXPECT_THROW(Store::peek(dir.path, layout(), meta("h2"), 10), StoreMismatch);
}

// row_bytes against SQLite's own file: 10^5 rows of 4 factors and 10
// metrics (the recuperative DOE's columns), appended in batches as the
// writer does, take within 5% of the estimate; a NULL metric saves its 8
// bytes (and the cell's size varint may lose a byte).
TEST(DoeStore, RowBytesPredictTheFileSize) {
  TempDir dir("row_bytes");
  const StoreLayout l{{"a", "b", "c", "d"}, {{}, {}, {}, {}}, {"m0", "m1", "m2", "m3", "m4", "m5", "m6", "m7", "m8", "m9"}};
  constexpr std::int64_t kRows = 100000;
  auto make = [](std::int64_t i) {
    Row r{i, "ok", 1e-5 * (1 + i % 7), "", {}, {}};
    for (int j = 0; j < 4; ++j) r.factors.push_back(std::sin(double(i + j)));
    for (int j = 0; j < 10; ++j) r.metrics.push_back(std::exp(std::cos(double(i * j))));
    return r;
  };
  {
    Store s(dir.path, l, meta("h"), false);
    for (std::int64_t b = 0; b < kRows; b += 20000) {
      std::vector<Row> batch;
      for (std::int64_t i = b; i < b + 20000; ++i) batch.push_back(make(i));
      s.append(batch);
    }
  }  // closed: the WAL is checkpointed into the file
  const double per_row = double(fs::file_size(dir.file())) / kRows;
  EXPECT_NEAR(row_bytes(make(kRows / 2), l), per_row, 0.05 * per_row);
  Row infeasible = make(kRows / 2);
  infeasible.metrics.assign(10, NAN);
  EXPECT_NEAR(row_bytes(make(kRows / 2), l) - row_bytes(infeasible, l), 80 / 0.94, 1 / 0.94 + 1e-9);
}

TEST(DoeStore, DuplicateIndexRollsBackTheBatch) {
  TempDir dir("duplicate");
  Store s(dir.path, layout(), meta("h1"), false);
  s.append(rows(0, 5));
  // The message names the duplicate: last, in the middle, or twice in the batch.
  for (const auto& [batch, named] : {std::pair{std::vector{row(5), row(6), row(2)}, "sample 2 "},
                                     std::pair{std::vector{row(5), row(3), row(6)}, "sample 3 "},
                                     std::pair{std::vector{row(7), row(8), row(7)}, "sample 7 "}}) {
    try {
      s.append(batch);
      FAIL() << "a duplicate index was accepted: " << named;
    } catch (const std::logic_error& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(s.count(), 5);  // 5 to 8 rolled back
  s.append(std::vector{row(5), row(6)});  // and still free
  EXPECT_EQ(s.count(), 7);
}

// The segment files in DIR (not their -wal and -shm), by name.
std::vector<std::string> segment_names(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.starts_with("store.seg-") && !n.ends_with("-wal") && !n.ends_with("-shm")) names.push_back(n);
  }
  std::sort(names.begin(), names.end());
  return names;
}

// A writer killed at a random moment, its batches going in turn to the store
// and to a segment of its own (as a run's threads' do): the store and the
// segment hold whole batches, the next opening of the store finds the
// segment beside it and folds it, and the next run resumes after them.
// Three kill-and-resume rounds.
TEST(DoeStore, KilledWriterLeavesWholeBatches) {
  constexpr std::int64_t kBatch = 1000;
  TempDir dir("kill");
  std::int64_t before = 0;
  for (int round = 0; round < 3; ++round) {
    int ready[2];
    ASSERT_EQ(pipe(ready), 0);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      // The writer: resumes after what is there and never stops. _exit: no
      // gtest teardown in the child.
      close(ready[0]);
      try {
        Store s(dir.path, layout(), meta("h1"), false);
        auto segment = s.segment("killed-" + std::to_string(round));
        for (std::int64_t first = s.count(), k = 0;; first += kBatch, ++k) {
          k % 2 ? segment.append(rows(first, kBatch)) : s.append(rows(first, kBatch));
          const char one = 1;
          if (k > 0 && ready[1] >= 0 && write(ready[1], &one, 1) == 1) {  // both files hold a batch: kill now
            close(ready[1]);
            ready[1] = -1;
          }
        }
      } catch (...) {
        _exit(1);
      }
    }
    close(ready[1]);
    char c = 0;
    const bool started = read(ready[0], &c, 1) == 1;
    close(ready[0]);
    if (started) std::this_thread::sleep_for(std::chrono::milliseconds(300));
    kill(child, SIGKILL);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(started) << "the writer failed before its first commit";
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);

    const auto check = query(dir.file(), "PRAGMA integrity_check");
    ASSERT_EQ(check.size(), 1u);
    EXPECT_EQ(std::get<std::string>(check[0][0]), "ok");
    EXPECT_EQ(segment_names(dir.path).size(), 1u) << "round " << round;
    Store s(dir.path, layout(), meta("h1"), false);
    EXPECT_TRUE(segment_names(dir.path).empty()) << "round " << round;
    const std::int64_t n = s.count();
    EXPECT_GT(n, before) << "round " << round;
    EXPECT_EQ(n % kBatch, 0) << n << " rows";
    const auto done = s.finished(n);  // throws if an index is >= n: so exactly 0 .. n-1
    EXPECT_EQ(std::count(done.begin(), done.end(), true), n);
    before = n;
  }
}

// The store every export test reads: NULLs, a quoted message, a label.
void three_rows(const std::string& dir) {
  Store s(dir, layout(), {{"config_hash", "h1"}, {"samples", "3"}}, false);
  std::vector<Row> r = {{0, "ok", 0.5, "", {0.1, 0}, {1.5, 2.25}},
                        {1, "cannot_assemble", 0.25, "rod, too \"short\"", {0.2, 1}, {NAN, NAN}},
                        {2, "ok", 1.0, "", {1.0 / 3, 1}, {-3e-7, 100}}};
  s.append(std::vector{r[2], r[0]});  // out of order: exports sort by idx
  s.append(std::vector{r[1]});
}

// What `write` (export_csv, export_json) makes of the three-row store.
std::string exported(const std::function<void(const std::string&, std::ostream&)>& write, const std::string& name) {
  TempDir dir(name);
  three_rows(dir.path);
  std::ostringstream out;
  write(dir.file(), out);
  return out.str();
}


TEST(DoeStore, ExportCsv) {
  EXPECT_EQ(exported([](const std::string& f, std::ostream& o) { opt::doe::export_csv(f, o); }, "csv"),
            "idx,status,wall_time,message,rod_length,fidelity.rod,k1,peak_torque\n"
            "0,ok,0.5,,0.10000000000000001,rigid,1.5,2.25\n"
            "1,cannot_assemble,0.25,\"rod, too \"\"short\"\"\",0.20000000000000001,elastic,,\n"
            "2,ok,1,,0.33333333333333331,elastic,-2.9999999999999999e-07,100\n");
  std::ostringstream out;
  EXPECT_THROW(opt::doe::export_csv("/nonexistent/store.sqlite", out), std::runtime_error);
}

// The canonical dump: the CSV without the wall times, nothing else changed.
TEST(DoeStore, ExportCanonical) {
  EXPECT_EQ(exported([](const std::string& f, std::ostream& o) { opt::doe::export_csv(f, o, false); }, "canonical"),
            "idx,status,message,rod_length,fidelity.rod,k1,peak_torque\n"
            "0,ok,,0.10000000000000001,rigid,1.5,2.25\n"
            "1,cannot_assemble,\"rod, too \"\"short\"\"\",0.20000000000000001,elastic,,\n"
            "2,ok,,0.33333333333333331,elastic,-2.9999999999999999e-07,100\n");
}

TEST(DoeStore, ExportJson) {
  const std::string text = exported(opt::doe::export_json, "json");
  EXPECT_EQ(text,
            R"({"meta": {"config_hash":"h1","layout":"{\"factors\":[{\"labels\":[],\"name\":\"rod_length\"},)"
            R"({\"labels\":[\"rigid\",\"elastic\"],\"name\":\"fidelity.rod\"}],\"metrics\":[\"k1\",\"peak_torque\"]}",)"
            R"("samples":"3"},
"samples": [
{"idx": 0, "status": "ok", "wall_time": 0.5, "message": null, "rod_length": 0.1, "fidelity.rod": "rigid", "k1": 1.5, "peak_torque": 2.25},
{"idx": 1, "status": "cannot_assemble", "wall_time": 0.25, "message": "rod, too \"short\"", "rod_length": 0.2, "fidelity.rod": "elastic", "k1": null, "peak_torque": null},
{"idx": 2, "status": "ok", "wall_time": 1.0, "message": null, "rod_length": 0.3333333333333333, "fidelity.rod": "elastic", "k1": -3e-07, "peak_torque": 100.0}
]}
)");
  const auto j = nlohmann::json::parse(text);  // and it is JSON
  EXPECT_EQ(j["samples"].size(), 3u);
}

// A shard store with the given indices, as `--shard` writes it.
void shard(const std::string& dir, std::int64_t first, std::int64_t n, const std::string& hash = "h1") {
  Meta m = meta(hash, R"({"seed": ")" + hash + R"("})");
  m["shard"] = dir;
  Store s(dir, layout(), m, false);
  s.append(rows(first, n));
}

std::string merge_error(const std::string& out, const std::vector<std::string>& stores) {
  try {
    opt::doe::merge_stores(out, stores);
  } catch (const std::runtime_error& e) {
    EXPECT_FALSE(fs::exists(out + "/store.sqlite")) << "a refused merge wrote " << out;
    return e.what();
  }
  ADD_FAILURE() << "the merge was accepted";
  return "";
}

TEST(DoeStore, MergeShards) {
  TempDir dir("merge");
  shard(dir.path + "/a", 0, 5);
  shard(dir.path + "/b", 5, 5);
  const auto report = opt::doe::merge_stores(dir.path + "/out", {dir.path + "/b", dir.path + "/a/store.sqlite"});
  EXPECT_EQ(report.rows, 10);
  EXPECT_EQ(report.inputs, (std::vector<std::string>{dir.path + "/b/store.sqlite", dir.path + "/a/store.sqlite"}));
  Store merged(dir.path + "/out", layout(), meta("h1"), false);
  EXPECT_EQ(merged.count(), 10);
  EXPECT_EQ(merged.finished(10), std::vector<bool>(10, true));
  EXPECT_EQ(merged.meta("shard"), std::nullopt);
  EXPECT_EQ(std::get<std::string>(query(merged.path(), "SELECT \"fidelity.rod\" FROM samples WHERE idx = 7")[0][0]),
            "elastic");
  // Merging twice into the same place is refused.
  EXPECT_THROW(opt::doe::merge_stores(dir.path + "/out", {dir.path + "/a", dir.path + "/b"}), std::runtime_error);
  EXPECT_EQ(merged.count(), 10);
}

TEST(DoeStore, MergeRefusesGapsOverlapsAndOtherConfigs) {
  TempDir dir("merge_bad");
  shard(dir.path + "/a", 0, 6);  // 0..5
  shard(dir.path + "/b", 5, 5);  // 5..9: 5 twice
  shard(dir.path + "/c", 7, 3);  // 7..9: 6 missing with a
  shard(dir.path + "/d", 5, 5, "h2");
  EXPECT_EQ(merge_error(dir.path + "/o1", {dir.path + "/a", dir.path + "/b"}),
            "merge: 1 index in more than one row: 5; nothing was written");
  EXPECT_EQ(merge_error(dir.path + "/o2", {dir.path + "/a", dir.path + "/c"}),
            "merge: 1 index missing: 6; nothing was written");
  {
    Meta m = meta("h1");
    m["samples"] = "30";
    Store e(dir.path + "/e", layout(), m, false);
    e.append(rows(0, 5));
  }
  EXPECT_EQ(merge_error(dir.path + "/o3", {dir.path + "/e"}),  // ten named, then "..."
            "merge: 25 indices missing: 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, ...; nothing was written");
  try {
    opt::doe::merge_stores(dir.path + "/o4", {dir.path + "/a", dir.path + "/d"});
    FAIL() << "another config_hash was merged";
  } catch (const StoreMismatch& e) {
    EXPECT_NE(std::string(e.what()).find(dir.path + "/d/store.sqlite"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("keys that differ: seed"), std::string::npos) << e.what();
  }
}

// ---- segments (docs/doe.md, "Segments") ------------------------------------

std::string csv(const std::string& file, bool wall_time = true) {
  std::ostringstream o;
  opt::doe::export_csv(file, o, wall_time);
  return o.str();
}


// Rows 0-2 in store.sqlite, 3-5 in one segment, 6-9 and index 2 again (as a
// fold killed half way leaves it, with another wall time) in a second: the
// readers take each index once, the store file's copy, and equal the
// export of the same ten rows written to one file; opening the store folds
// the segments into it and removes them.
TEST(DoeStore, SegmentsAreReadAsOneStoreAndFolded) {
  TempDir dir("segments"), one("segments_one");
  Store(one.path, layout(), meta("h1"), false).append(rows(0, 10));
  {
    Store s(dir.path, layout(), meta("h1"), false);
    s.append(rows(0, 3));
    s.segment("a").append(rows(3, 3));
    std::vector<Row> b = rows(6, 4);
    b.push_back(row(2));
    b.back().wall_time = 9;
    s.segment("b").append(b);
  }
  EXPECT_EQ(segment_names(dir.path), (std::vector<std::string>{"store.seg-a.sqlite", "store.seg-b.sqlite"}));
  EXPECT_EQ(query(dir.file(), "SELECT count(*) FROM samples")[0][0], Cell(std::int64_t(3)));
  EXPECT_EQ(csv(dir.file()), csv(one.file()));
  std::vector<std::int64_t> read;
  opt::doe::read_rows(dir.file(), [&](const Row& r) { read.push_back(r.index); });
  EXPECT_EQ(read, (std::vector<std::int64_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(Store::peek(dir.path, layout(), meta("h1"), 12),
            (std::vector<bool>{true, true, true, true, true, true, true, true, true, true, false, false}));

  Store s(dir.path, layout(), meta("h1"), false);  // folds
  EXPECT_TRUE(segment_names(dir.path).empty());
  EXPECT_EQ(s.count(), 10);
  EXPECT_EQ(query(dir.file(), "SELECT wall_time FROM samples WHERE idx = 2")[0][0], Cell(0.5));
  EXPECT_EQ(csv(dir.file()), csv(one.file()));
}

// A segment whose rows are all in the store already (the fold was killed
// after its commit, before the file was removed) folds to nothing new; a
// segment of another config is refused by name, as its store would be.
TEST(DoeStore, FoldTakesEachIndexOnceAndRefusesAnotherRunsSegment) {
  TempDir dir("fold");
  {
    Store s(dir.path, layout(), meta("h1"), false);
    s.append(rows(0, 4));
    s.segment("again").append(rows(2, 2));
    EXPECT_EQ(s.fold(), 0);
    EXPECT_EQ(s.count(), 4);
    EXPECT_TRUE(segment_names(dir.path).empty());
  }
  opt::doe::Segment(dir.path, "other", layout(), "h2").append(rows(4, 1));
  try {
    Store s(dir.path, layout(), meta("h1"), false);
    FAIL() << "a segment of another run was folded";
  } catch (const StoreMismatch& e) {
    EXPECT_NE(std::string(e.what()).find("store.seg-other.sqlite"), std::string::npos) << e.what();
  }
  EXPECT_THROW(csv(dir.file()), StoreMismatch);
  // --new moves the segments aside with the store.
  Store fresh(dir.path, layout(), meta("h2"), true);
  EXPECT_EQ(fresh.count(), 0);
  const auto names = segment_names(dir.path);
  ASSERT_EQ(names.size(), 1u);
  EXPECT_TRUE(names[0].starts_with("store.seg-other.sqlite.old-")) << names[0];
}

// A shard whose rows are partly in a segment (its run was killed): merge
// reads its segment, and an index in both its store file and its segment is
// that shard's once, not "in more than one row".
TEST(DoeStore, MergeReadsEachShardsSegments) {
  TempDir dir("merge_segments");
  shard(dir.path + "/a", 0, 5);
  {
    Store b(dir.path + "/b", layout(), meta("h1"), false);
    b.append(rows(5, 2));
    b.segment("t1").append(rows(6, 4));  // 6 in both
  }
  const auto report = opt::doe::merge_stores(dir.path + "/out", {dir.path + "/a", dir.path + "/b"});
  EXPECT_EQ(report.rows, 10);
  EXPECT_EQ(query(dir.path + "/out/store.sqlite", "SELECT count(*) FROM samples")[0][0], Cell(std::int64_t(10)));
}

}  // namespace
