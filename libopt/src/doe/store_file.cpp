// Opening a store file, its meta, and the writer's lock (store_file.hpp).
#include "doe/store_file.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

namespace opt::doe {

namespace fs = std::filesystem;
using sql::Db;
using sql::Statement;

namespace {

// The writer's lock: DIR/store.lock, a file of its own: SQLite's fcntl locks on store.sqlite are
// dropped when any descriptor of that file in the process closes, and cover
// one file where a store may be several. flock belongs to the open file
// description, so the kernel releases it with the process however it ends;
// the file itself stays (removing it would race with a run that has just
// opened it) and its text, the last writer's name, means nothing unlocked.

std::string text_of(const std::string& file) {
  std::ifstream in(file);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// "pid 12, host h, started 2026-...Z, command mechopt run ..." from the lines
// WriterLock writes.
std::string holder_text(const std::string& lines) {
  std::string s;
  std::istringstream in(lines);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) s += (s.empty() ? "" : ", ") + line;
  return s.empty() ? "a process that has not written its name yet" : s;
}

// This process, for the lock file: pid, host, start time (UTC), command line.
std::string holder_lines() {
  char host[256] = "?";
  gethostname(host, sizeof host - 1);
  std::string command = text_of("/proc/self/cmdline");  // NUL-separated arguments
  while (!command.empty() && command.back() == '\0') command.pop_back();
  std::replace(command.begin(), command.end(), '\0', ' ');
  std::replace(command.begin(), command.end(), '\n', ' ');
  const std::time_t t = std::time(nullptr);
  char started[32];
  std::strftime(started, sizeof started, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return "pid " + std::to_string(getpid()) + "\nhost " + host + "\nstarted " + started +
         (command.empty() ? "" : "\ncommand " + command) + "\n";
}

}  // namespace

std::map<std::string, std::string> read_meta(const Db& db) {
  std::map<std::string, std::string> m;
  Statement s(db, "SELECT key, value FROM meta");
  while (s.step()) m[*s.text(0)] = s.text(1).value_or("");
  return m;
}

// Adds the keys the store lacks; stored values (e.g. "started" of the first
// run) are kept.
void add_meta(const Db& db, const std::map<std::string, std::string>& meta) {
  Statement add(db, "INSERT OR IGNORE INTO meta(key, value) VALUES(?, ?)");
  for (const auto& [key, value] : meta) {
    add.reset();
    add.bind(1, std::string_view(key));
    add.bind(2, std::string_view(value));
    add.step();
  }
}

// A store to read: a missing file is an error, never a new empty store.
// Opened read-write when the file allows it (nothing is written): a
// read-only connection that is the last to close cannot checkpoint the WAL,
// and would leave store.sqlite-wal and -shm beside the store.
Db open_to_read(const std::string& file) {
  if (!fs::is_regular_file(file)) throw std::runtime_error(file + ": no such store");
  return Db(file, access(file.c_str(), W_OK) == 0 ? SQLITE_OPEN_READWRITE : SQLITE_OPEN_READONLY);
}

WriterLock::WriterLock(const std::string& dir) : file_((fs::path(dir) / "store.lock").string()) {
  // CLOEXEC: a program the run starts does not inherit (and keep) the lock.
  fd_ = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::runtime_error(file_ + ": cannot open the store's lock file: " + std::strerror(errno));
  if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int e = errno;
    ::close(fd_);
    const std::string store = (fs::path(dir) / "store.sqlite").string();
    if (e != EWOULDBLOCK) throw std::runtime_error(file_ + ": cannot lock the store's lock file: " + std::strerror(e));
    throw StoreBusy(store + " is being written by another run (" + holder_text(text_of(file_)) + "), which holds " +
                    file_ + " until it ends; wait for it or stop it (readers such as `mechopt export` "
                    "and pandas may read the store meanwhile)");
  }
  const std::string lines = holder_lines();
  if (ftruncate(fd_, 0) != 0 || pwrite(fd_, lines.data(), lines.size(), 0) != ssize_t(lines.size())) {
    const int e = errno;
    ::close(fd_);
    throw std::runtime_error(file_ + ": cannot write to the store's lock file: " + std::strerror(e));
  }
}

WriterLock::~WriterLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the flock
}

WriterLock::WriterLock(WriterLock&& o) noexcept : file_(std::move(o.file_)), fd_(std::exchange(o.fd_, -1)) {}

Db open_to_write(const std::string& file) {
  Db db(file, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  // 64 KiB pages (a new file only; the page size is fixed once a table
  // exists): rows are appended and read in whole scans, and big pages cut
  // the page writes per batch and the pages finished() walks: appends run
  // a third faster than at SQLite's default 4 KiB, finished(10^6) in about
  // half the time.
  db.exec("PRAGMA page_size=65536");
  {
    // WAL: a commit appends to the log, readers never block the writer, and
    // a kill loses at most the uncommitted batch. NORMAL: no fsync per
    // commit (only at checkpoints); a power cut may lose the last commits,
    // never consistency, and a resume redoes them.
    Statement wal(db, "PRAGMA journal_mode=WAL");
    if (!wal.step() || wal.text(0) != "wal") throw std::runtime_error(file + ": cannot switch to WAL journal mode");
  }
  db.exec("PRAGMA synchronous=NORMAL");
  return db;
}

std::optional<std::string> meta_value(const std::map<std::string, std::string>& m, const std::string& key) {
  const auto it = m.find(key);
  return it == m.end() ? std::nullopt : std::optional(it->second);
}

}  // namespace opt::doe
