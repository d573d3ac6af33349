// Runs the mechopt binary as a user would, for the end-to-end and regression
// tests: exit code (or the signal that killed it), combined stdout+stderr,
// under a wall-time limit, with the output directory's total size.
#pragma once
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>
#include <sqlite3.h>
#include <sys/wait.h>

#include "paths.hpp"

namespace cli {

// Whether this build runs under AddressSanitizer, where an evaluation costs
// about 4 times what it costs in Release and a 200 000-sample run a minute:
// the tests that kill, damage or race whole runs do fewer rounds on smaller
// stores there, with the same checks. The Release suite runs them in full.
#ifdef __SANITIZE_ADDRESS__
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

struct Outcome {
  int exit_code = -1;  // -1 when killed by a signal
  int signal = 0;      // the signal, or 0
  bool timed_out = false;
  std::string output;  // stdout and stderr together
  bool exited(int code) const { return signal == 0 && !timed_out && exit_code == code; }
};

// `mechopt ARGS` with `timeout` seconds at most (coreutils timeout sends
// SIGTERM, then SIGKILL 5 s later; exit code 124 or a signal means it hung).
inline Outcome run(const std::string& args, int timeout = 120) {
  const std::string cmd = "timeout -k 5 " + std::to_string(timeout) + " " + MECHOPT_BINARY + " " +
                          args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  Outcome o;
  if (!pipe) return o;
  char buf[4096];
  // Whole canonical dumps (a 200 000-row store's is ~25 MB) and what an
  // export says after its rows; a runaway output is cut at 64 MiB.
  while (size_t n = fread(buf, 1, sizeof buf, pipe))
    if (o.output.size() < (64u << 20)) o.output.append(buf, n);
  const int status = pclose(pipe);
  if (WIFEXITED(status)) {
    o.exit_code = WEXITSTATUS(status);
    // timeout(1) reports 124 on a timeout and 128 + N when the child died of signal N.
    if (o.exit_code == 124) o.timed_out = true;
    if (o.exit_code > 128 && o.exit_code < 160 && o.exit_code != 130 && o.exit_code != 143)
      o.signal = o.exit_code - 128;
  } else if (WIFSIGNALED(status)) {
    o.signal = WTERMSIG(status);
  }
  return o;
}

// A config of the source tree, e.g. source("tests/repro/duplicate_key.yaml").
inline std::string source(const std::string& relative) {
  return std::string(MECHOPT_SOURCE_DIR) + "/" + relative;
}

// A fresh, empty directory under the test temp dir.
inline std::string fresh_dir(const std::string& name) {
  const std::string dir = testing::TempDir() + "/" + name;
  std::filesystem::remove_all(dir);
  return dir;
}

// Bytes in every file under dir.
inline std::uintmax_t directory_bytes(const std::string& dir) {
  std::uintmax_t total = 0;
  std::error_code ec;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir, ec))
    if (e.is_regular_file()) total += e.file_size();
  return total;
}

// The segment files beside DIR/store.sqlite (docs/doe.md, "Segments").
inline std::vector<std::string> segment_files(const std::string& dir) {
  std::vector<std::string> found;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.starts_with("store.seg-") && name.ends_with(".sqlite")) found.push_back(e.path().string());
  }
  return found;
}

// The samples committed in DIR so far (0 while the store is being created),
// for polling a running batch: the distinct indices of store.sqlite and its
// segments, read straight through SQLite's C API (segments never share an
// index with each other, only with store.sqlite after a fold was killed).
inline long stored_rows(const std::string& dir) {
  sqlite3* db = nullptr;
  long n = 0;
  auto count = [&](const std::string& sql) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &st, nullptr) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW)
      n += static_cast<long>(sqlite3_column_int64(st, 0));
    sqlite3_finalize(st);
  };
  const std::string main = dir + "/store.sqlite";
  if (!std::filesystem::exists(main) ||
      sqlite3_open_v2(main.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(db);
    return 0;
  }
  count("select count(*) from samples");
  for (const auto& file : segment_files(dir)) {
    char* quoted = sqlite3_mprintf("attach %Q as segment", file.c_str());
    if (sqlite3_exec(db, quoted, nullptr, nullptr, nullptr) == SQLITE_OK) {
      count("select count(*) from segment.samples where idx not in (select idx from main.samples)");
      sqlite3_exec(db, "detach segment", nullptr, nullptr, nullptr);
    }
    sqlite3_free(quoted);
  }
  sqlite3_close(db);
  return n;
}

inline std::string canonical_dump(const std::string& dir) {
  const Outcome o = run("export " + dir + "/store.sqlite --canonical");
  EXPECT_TRUE(o.exited(0)) << o.output;
  return o.output;
}

}  // namespace cli
