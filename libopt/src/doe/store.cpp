// The SQLite results store (docs/doe.md, "The store" and "Resume, exactly").
// Every sqlite3 return code is checked; an error throws std::runtime_error
// with the file and SQLite's message, so a full disk or a locked file stops a
// run loudly instead of losing rows.
#include "opt/doe/store.hpp"

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <utility>

#include "doe/checksum.hpp"
#include "doe/sqlite.hpp"
#include "doe/store_file.hpp"
#include "mech/status.hpp"

namespace opt::doe {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using sql::Db;
using sql::identifier;
using sql::Statement;
using sql::Transaction;

// ---- layout, meta, schema -----------------------------------------------

constexpr std::size_t kColumnsBefore = 4;  // idx, status, wall_time, message: then factors, metrics, checksum

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// labels may be left empty when no factor is categorical.
StoreLayout normalized(StoreLayout l) {
  if (l.labels.empty()) l.labels.resize(l.factors.size());
  if (l.labels.size() != l.factors.size())
    throw std::invalid_argument("store layout: " + std::to_string(l.labels.size()) + " label lists for " +
                                std::to_string(l.factors.size()) + " factors");
  return l;
}

json layout_json(const StoreLayout& l) {
  json factors = json::array();
  for (std::size_t i = 0; i < l.factors.size(); ++i)
    factors.push_back({{"name", l.factors[i]}, {"labels", l.labels[i]}});
  return {{"factors", factors}, {"metrics", l.metrics}};
}

StoreLayout layout_from_json(const std::string& file, const std::optional<std::string>& text) {
  const json j = json::parse(text.value_or(""), nullptr, false);
  try {
    StoreLayout l;
    for (const auto& f : j.at("factors")) {
      l.factors.push_back(f.at("name").get<std::string>());
      l.labels.push_back(f.at("labels").get<std::vector<std::string>>());
    }
    l.metrics = j.at("metrics").get<std::vector<std::string>>();
    return l;
  } catch (const json::exception&) {
    throw std::runtime_error(file + ": meta 'layout' is missing or not a store layout");
  }
}

// What differs between two layouts, in column names.
std::string columns_difference(const StoreLayout& a, const StoreLayout& b, const std::string& a_name,
                               const std::string& b_name) {
  auto columns = [](const StoreLayout& l) {
    std::map<std::string, std::vector<std::string>> c;  // name -> labels (metrics: none)
    for (std::size_t i = 0; i < l.factors.size(); ++i) c[l.factors[i]] = l.labels[i];
    for (const auto& m : l.metrics) c[m];
    return c;
  };
  const auto ca = columns(a), cb = columns(b);
  std::vector<std::string> only_a, only_b, labels;
  for (const auto& [name, l] : ca) {
    const auto it = cb.find(name);
    if (it == cb.end())
      only_a.push_back(name);
    else if (it->second != l)
      labels.push_back(name);
  }
  for (const auto& [name, l] : cb)
    if (!ca.contains(name)) only_b.push_back(name);
  std::string s;
  if (!only_a.empty()) s += "columns only in " + a_name + ": " + joined(only_a) + "; ";
  if (!only_b.empty()) s += "columns only in " + b_name + ": " + joined(only_b) + "; ";
  if (!labels.empty()) s += "categorical options differ: " + joined(labels) + "; ";
  return s.empty() ? "the columns' order or kinds differ" : s.substr(0, s.size() - 2);
}

// The top-level keys whose canonical config values differ: a refusal says
// what changed, not just that two hashes differ.
std::string config_difference(const std::optional<std::string>& a_text, const std::optional<std::string>& b_text,
                              const std::string& a_name, const std::string& b_name) {
  const json a = json::parse(a_text.value_or(""), nullptr, false);
  const json b = json::parse(b_text.value_or(""), nullptr, false);
  if (!a.is_object() || !b.is_object()) return "no canonical config (meta 'config_canonical') to compare";
  std::vector<std::string> changed, only_a, only_b;
  for (const auto& [key, value] : a.items()) {
    if (!b.contains(key))
      only_a.push_back(key);
    else if (b.at(key) != value)
      changed.push_back(key);
  }
  for (const auto& [key, value] : b.items())
    if (!a.contains(key)) only_b.push_back(key);
  std::string s;
  if (!changed.empty()) s += "keys that differ: " + joined(changed) + "; ";
  if (!only_a.empty()) s += "keys only in " + a_name + ": " + joined(only_a) + "; ";
  if (!only_b.empty()) s += "keys only in " + b_name + ": " + joined(only_b) + "; ";
  return s.empty() ? "no top-level key differs" : s.substr(0, s.size() - 2);
}

std::optional<std::string> find(const std::map<std::string, std::string>& m, const std::string& key) {
  const auto it = m.find(key);
  return it == m.end() ? std::nullopt : std::optional(it->second);
}

bool has_table(const Db& db, const char* name) {
  Statement s(db, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?");
  s.bind(1, std::string_view(name));
  return s.step();
}

void create_schema(const Db& db, const StoreLayout& l, const std::map<std::string, std::string>& meta) {
  db.exec("CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT)");
  std::string sql = "CREATE TABLE samples(idx INTEGER PRIMARY KEY, status TEXT NOT NULL, wall_time REAL, message TEXT";
  for (std::size_t i = 0; i < l.factors.size(); ++i)
    sql += ", " + identifier(l.factors[i]) + (l.labels[i].empty() ? " REAL" : " TEXT");
  for (const auto& m : l.metrics) sql += ", " + identifier(m) + " REAL";
  db.exec(sql + ", checksum INTEGER)");
  add_meta(db, meta);
}

// "INSERT INTO samples VALUES(?, ?, ...)" for n columns.
std::string insert_sql(std::size_t columns) {
  std::string sql = "INSERT INTO samples VALUES(?";
  for (std::size_t i = 1; i < columns; ++i) sql += ", ?";
  return sql + ")";
}

std::string timestamp() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  localtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
  return buf;
}

// FILE (and its -wal, -shm) -> FILE.old-<time> (-wal, -shm): SQLite finds the
// old store's WAL by that name, so nothing committed to it is lost.
void move_aside(const std::string& file) {
  const std::string base = file + ".old-" + timestamp();
  std::string old = base;
  for (int n = 2; fs::exists(old); ++n) old = base + "-" + std::to_string(n);  // two --new in one second
  for (const char* suffix : {"", "-wal", "-shm"})
    if (fs::exists(file + suffix)) fs::rename(file + suffix, old + suffix);
}

// The names of the columns of `samples` (SELECT * FROM samples), in order.
std::vector<std::string> stored_columns(const Db& db) {
  Statement s(db, "SELECT * FROM samples LIMIT 0");
  std::vector<std::string> names;
  for (int c = 0; c < sqlite3_column_count(s.get()); ++c) names.push_back(sqlite3_column_name(s.get(), c));
  return names;
}

std::vector<std::string> column_names(const StoreLayout& l) {
  std::vector<std::string> names = {"idx", "status", "wall_time", "message"};
  names.insert(names.end(), l.factors.begin(), l.factors.end());
  names.insert(names.end(), l.metrics.begin(), l.metrics.end());
  names.push_back("checksum");
  return names;
}

// An existing store must hold this run's samples: the same config_hash and
// columns; else StoreMismatch names what differs. A store that `mechopt
// recover` saved without its meta has neither hash nor layout: its columns
// must be this run's, whose meta it then takes.
void check_same_run(const Db& db, const std::map<std::string, std::string>& meta, const StoreLayout& l) {
  const std::string& file = db.file();
  const auto stored = read_meta(db);
  const auto stored_hash = find(stored, "config_hash"), hash = find(meta, "config_hash");
  if (stored_hash && stored_hash != hash)
    throw StoreMismatch(
        file + ": written by another configuration (config_hash " + *stored_hash + ", this run " +
        hash.value_or("none") + "); " +
        config_difference(find(stored, "config_canonical"), find(meta, "config_canonical"), "the store", "this run") +
        ". Start afresh (--new) to move it aside.");
  const std::vector<std::string> columns = stored_columns(db);
  if (columns.empty() || columns.back() != "checksum")
    throw StoreMismatch(file + ": written by a mechopt before row checksums; `mechopt recover " + file +
                        " OUT` copies it into a store of this version, or start afresh (--new) to move it aside.");
  if (!stored.contains("layout")) {
    if (columns != column_names(l))
      throw StoreMismatch(file + ": has no meta and other columns than this run (" + joined(columns) + "; this run " +
                          joined(column_names(l)) + "). Start afresh (--new) to move it aside.");
    return;
  }
  const StoreLayout old = layout_from_json(file, find(stored, "layout"));
  if (layout_json(old) != layout_json(l))
    throw StoreMismatch(file + ": written with other columns; " + columns_difference(old, l, "the store", "this run") +
                        ". Start afresh (--new) to move it aside.");
}

// SELECT * FROM samples ORDER BY idx, every row's checksum verified: step()
// throws StoreDamaged at the first row that fails it. columns(): the values
// without the checksum. A store from before checksums is read unverified.
class Rows {
 public:
  explicit Rows(const Db& db)
      : file_(db.file()), s_(db, "SELECT * FROM samples ORDER BY idx"), n_(sqlite3_column_count(s_.get())) {
    checked_ = n_ > 0 && std::string_view(sqlite3_column_name(s_.get(), n_ - 1)) == "checksum";
    n_ -= checked_;
  }
  bool step() {
    if (!s_.step()) return false;
    if (checked_ && !checksum_holds(s_.get()))
      throw StoreDamaged(file_, "sample " + std::to_string(s_.int64(0)) + " fails its checksum");
    return true;
  }
  Statement& row() { return s_; }
  int columns() const { return n_; }

 private:
  std::string file_;
  Statement s_;
  int n_;
  bool checked_ = false;
};

// The indices of the store's rows as `total` bits. Only the indices are
// read: a value damaged inside an intact page is found by the readers of
// whole rows (export, check, merge), since verifying every row's checksum
// here would make the resume's scan about 10x slower (bench_doe_store,
// BM_Finished).
void index_bitmap(const Db& db, std::int64_t total, std::vector<bool>& done) {
  Statement s(db, "SELECT idx FROM samples");
  while (s.step()) {
    const std::int64_t i = s.int64(0);
    if (i < 0 || i >= total)  // the config hash matched: damage (a row or a page decoded into garbage)
      throw StoreDamaged(db.file(), "it holds sample " + std::to_string(i) + ", outside this run's [0, " +
                                        std::to_string(total) + ")");
    done[std::size_t(i)] = true;
  }
}

// ---- the writer's lock ----------------------------------------------------
//
// DIR/store.lock, a file of its own: SQLite's fcntl locks on store.sqlite are
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

// ---- a batch of rows as a table ------------------------------------------
//
// append() writes a batch with one statement, INSERT INTO samples SELECT *
// FROM mechopt_batch, mechopt_batch being a virtual table over the rows in
// memory: one step a batch, with SQLite's cursor on samples open through
// it, where a prepared one-row INSERT was reset, bound column by column and
// stepped (opening its cursor anew) once a row. The conveyor DOE's 20
// columns: 9100 -> 7100 instructions a row under callgrind; bench_doe_store,
// interleaved on a noisy machine: 20 columns 0.57-0.89M -> 0.94-1.02M
// rows/s, 68 columns 0.24-0.27M -> 0.30-0.40M. The values are what binding
// gave: NaN and "" as NULL, a categorical factor as its option's label,
// texts read in place (the rows outlive the statement's step).

struct Batch {  // set by append() around its one step
  const StoreLayout* layout = nullptr;
  std::span<const Row> rows;
  std::size_t at = 0;  // the row the scan is on: the one that failed, on an error
};

struct BatchTable {
  sqlite3_vtab base{};  // first: SQLite's pointer to it is a pointer to this
  Batch* batch = nullptr;
};

Batch& batch_of(sqlite3_vtab_cursor* c) { return *reinterpret_cast<BatchTable*>(c->pVtab)->batch; }

int batch_connect(sqlite3* db, void* aux, int, const char* const*, sqlite3_vtab** table, char**) {
  auto* batch = static_cast<Batch*>(aux);
  const StoreLayout& l = *batch->layout;
  std::string sql = "CREATE TABLE x(c0";
  for (std::size_t i = 1; i < kColumnsBefore + l.factors.size() + l.metrics.size() + 1; ++i)  // + the checksum
    sql += ", c" + std::to_string(i);
  if (const int rc = sqlite3_declare_vtab(db, (sql + ")").c_str()); rc != SQLITE_OK) return rc;
  auto* t = new BatchTable;
  t->batch = batch;
  *table = &t->base;
  return SQLITE_OK;
}

int batch_disconnect(sqlite3_vtab* t) {
  delete reinterpret_cast<BatchTable*>(t);
  return SQLITE_OK;
}

int batch_best_index(sqlite3_vtab*, sqlite3_index_info* info) {  // a scan, the only plan
  info->estimatedCost = 1;
  return SQLITE_OK;
}

int batch_open(sqlite3_vtab*, sqlite3_vtab_cursor** cursor) {
  *cursor = new sqlite3_vtab_cursor{};
  return SQLITE_OK;
}

int batch_close(sqlite3_vtab_cursor* cursor) {
  delete cursor;
  return SQLITE_OK;
}

int batch_filter(sqlite3_vtab_cursor* c, int, const char*, int, sqlite3_value**) {
  batch_of(c).at = 0;
  return SQLITE_OK;
}

int batch_next(sqlite3_vtab_cursor* c) {
  ++batch_of(c).at;
  return SQLITE_OK;
}

int batch_eof(sqlite3_vtab_cursor* c) { return batch_of(c).at >= batch_of(c).rows.size(); }

int batch_rowid(sqlite3_vtab_cursor* c, sqlite3_int64* rowid) {
  *rowid = static_cast<sqlite3_int64>(batch_of(c).at);
  return SQLITE_OK;
}

void result(sqlite3_context* ctx, double v) {
  if (std::isnan(v)) sqlite3_result_null(ctx);
  else sqlite3_result_double(ctx, v);
}

void result(sqlite3_context* ctx, std::string_view v) {
  if (v.empty()) sqlite3_result_null(ctx);
  else sqlite3_result_text(ctx, v.data(), int(v.size()), SQLITE_STATIC);
}

// The checksum of a row as the store will hold it (checksum.hpp): the values
// batch_column gives, NaN and "" as NULL, a categorical factor as its label.
// Not inlined: in batch_column, its registers and frame cost every column's
// call (callgrind: 1140 against 750 instructions a row of 20 columns).
[[gnu::noinline]] std::int64_t checksum(const Row& r, const StoreLayout& l) {
  RowHash h;
  auto real = [&](double v) { std::isnan(v) ? h.null() : h.real(v); };
  auto text = [&](std::string_view v) { v.empty() ? h.null() : h.text(v); };
  h.integer(r.index);
  text(r.status);
  real(r.wall_time);
  text(r.message);
  for (std::size_t j = 0; j < r.factors.size(); ++j)
    l.labels[j].empty() ? real(r.factors[j]) : text(l.labels[j][std::size_t(r.factors[j])]);
  for (const double v : r.metrics) real(v);
  return h.value();
}

// Columns: idx, status, wall_time, message, the factors, the metrics, the checksum.
int batch_column(sqlite3_vtab_cursor* c, sqlite3_context* ctx, int column) {
  const Batch& b = batch_of(c);
  const Row& r = b.rows[b.at];
  const std::vector<std::vector<std::string>>& labels = b.layout->labels;
  const std::size_t i = std::size_t(column), f = i - kColumnsBefore, m = f - labels.size();
  if (i == 0) sqlite3_result_int64(ctx, r.index);
  else if (i == 1) result(ctx, std::string_view(r.status));
  else if (i == 2) result(ctx, r.wall_time);
  else if (i == 3) result(ctx, std::string_view(r.message));
  else if (f < labels.size()) labels[f].empty() ? result(ctx, r.factors[f])
                                                 : result(ctx, std::string_view(labels[f][std::size_t(r.factors[f])]));
  else if (m < r.metrics.size()) result(ctx, r.metrics[m]);
  else sqlite3_result_int64(ctx, checksum(r, *b.layout));
  return SQLITE_OK;
}

// Eponymous only (no xCreate): the table exists on the connection that
// registers the module, never in the file.
sqlite3_module batch_module() {
  sqlite3_module m{};
  m.xConnect = batch_connect;
  m.xBestIndex = batch_best_index;
  m.xDisconnect = batch_disconnect;
  m.xOpen = batch_open;
  m.xClose = batch_close;
  m.xFilter = batch_filter;
  m.xNext = batch_next;
  m.xEof = batch_eof;
  m.xColumn = batch_column;
  m.xRowid = batch_rowid;
  return m;
}

Statement batch_insert(const Db& db, Batch& batch) {
  static const sqlite3_module module = batch_module();
  if (sqlite3_create_module_v2(db.get(), "mechopt_batch", &module, &batch, nullptr) != SQLITE_OK)
    db.fail("cannot register the batch table");
  return Statement(db, "INSERT INTO samples SELECT * FROM mechopt_batch");
}

}  // namespace

// ---- what recover.cpp shares (store_file.hpp) -----------------------------

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
  // the page writes per batch and the pages finished() walks. Measured:
  // append 270k -> 360k rows/s, finished(10^6) 150 -> 80 ms.
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

namespace {

// ---- appending batches -----------------------------------------------------

// One file's batched appends: a Store's or a Segment's. Rows are checked
// before the transaction (a bad row is the caller's bug, and nothing of its
// batch is written), then written in one statement and one transaction.
struct Appender {
  Appender(Db d, StoreLayout l) : db(std::move(d)), layout(std::move(l)), insert(batch_insert(db, batch)) {}
  Appender(Appender&&) = delete;  // SQLite holds &batch, the statement &db
  Db db;  // before the statement: destroyed after it
  StoreLayout layout;
  Batch batch{&layout, {}, 0};  // before insert: preparing it reads the layout
  Statement insert;             // every batch goes through it

  void append(std::span<const Row> rows) {
    const StoreLayout& l = layout;
    for (const Row& r : rows) {
      auto where = [&] { return db.file() + ": sample " + std::to_string(r.index); };  // only on an error
      if (r.status.empty()) throw std::invalid_argument(where() + ": no status");
      if (r.factors.size() != l.factors.size() || r.metrics.size() != l.metrics.size())
        throw std::invalid_argument(where() + ": " + std::to_string(r.factors.size()) + " factors and " +
                                    std::to_string(r.metrics.size()) + " metrics, the store has " +
                                    std::to_string(l.factors.size()) + " and " + std::to_string(l.metrics.size()));
      for (std::size_t j = 0; j < l.factors.size(); ++j) {
        const double v = r.factors[j];
        const auto n = double(l.labels[j].size());
        if (n > 0 && !(v >= 0 && v < n && v == std::floor(v)))
          throw std::invalid_argument(where() + ": factor " + l.factors[j] + ": option index " + std::to_string(v) +
                                      " is not one of its " + std::to_string(l.labels[j].size()) + " options");
      }
    }
    if (rows.empty()) return;
    // Never INSERT OR REPLACE: a sample written twice means the scheduler
    // handed it out twice, which must not pass silently.
    Transaction t(db);
    batch.rows = rows;
    insert.reset();
    const int rc = sqlite3_step(insert.get());
    const std::int64_t at = rows[std::min(batch.at, rows.size() - 1)].index;
    batch.rows = {};
    if (rc == SQLITE_CONSTRAINT_PRIMARYKEY)
      throw std::logic_error(db.file() + ": sample " + std::to_string(at) +
                             " is already in the store (or twice in the batch); the batch was rolled back");
    if (rc != SQLITE_DONE) db.fail("cannot insert sample " + std::to_string(at));
    t.commit();
  }
};

// ---- segments --------------------------------------------------------------

constexpr const char* kSegmentInfix = ".seg-";

// A segment must be of the store's run: its config_hash and columns.
void check_segment(const Db& segment, const Db& store) {
  const auto hash = find(read_meta(segment), "config_hash");
  const auto store_hash = find(read_meta(store), "config_hash");
  if (hash != store_hash || stored_columns(segment) != stored_columns(store))
    throw StoreMismatch(segment.file() + " is a segment of another run than " + store.file() + " (config_hash " +
                        hash.value_or("none") + ", the store's " + store_hash.value_or("none") +
                        "): remove it, or run with --new to move both aside");
}

void remove_file(const std::string& file) {
  for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(file + suffix);
}

// The rows of the store file `file` appended to `to` in one transaction;
// returns how many. The plain INSERT copies each row's record as it lies in
// `file` (SQLite's transfer optimisation: no column decoded or encoded);
// only when an index is in both (after a killed fold) are rows compared,
// and `to`'s copy kept.
std::int64_t copy_rows(const Db& to, const std::string& file) {
  Statement attach(to, "ATTACH DATABASE ? AS source");
  attach.bind(1, std::string_view(file));
  attach.step();
  std::int64_t copied = 0;
  try {
    Transaction t(to);
    const int rc =
        sqlite3_exec(to.get(), "INSERT INTO main.samples SELECT * FROM source.samples", nullptr, nullptr, nullptr);
    if (rc == SQLITE_CONSTRAINT_PRIMARYKEY) to.exec("INSERT OR IGNORE INTO main.samples SELECT * FROM source.samples");
    else if (rc != SQLITE_OK) to.fail("cannot copy the rows of " + file);
    copied = sqlite3_changes64(to.get());
    t.commit();
  } catch (...) {
    sqlite3_exec(to.get(), "DETACH DATABASE source", nullptr, nullptr, nullptr);
    throw;
  }
  to.exec("DETACH DATABASE source");
  return copied;
}

// The segment's rows into `store`, then the segment's files removed: a kill
// in between leaves rows in both, which every reader takes once and the next
// fold skips. Returns the rows moved.
std::int64_t fold_segment(const Db& store, const std::string& file) {
  {
    const Db segment = open_to_read(file);  // recovers a killed writer's WAL
    if (!has_table(segment, "samples")) {   // created, killed before its schema
      remove_file(file);
      return 0;
    }
    check_segment(segment, store);
  }
  const std::int64_t moved = copy_rows(store, file);
  remove_file(file);
  return moved;
}

// ---- reading a store and its segments ---------------------------------------

// The rows of a store file and of its segments, by idx, each index once (a
// fold killed half way leaves a row in both; the copies differ at most in
// wall_time, and the store file's is taken), every checksum verified.
class UnionRows {
 public:
  explicit UnionRows(const std::string& store_file) {
    sources_.push_back(std::make_unique<Source>(open_to_read(store_file)));
    for (const auto& file : segment_files(store_file)) {
      if (!fs::exists(file)) continue;  // folded since it was listed: its rows are in the store file
      auto s = std::make_unique<Source>(open_to_read(file));
      if (!has_table(s->db, "samples")) continue;
      check_segment(s->db, sources_[0]->db);
      sources_.push_back(std::move(s));
    }
  }
  bool step() {
    if (!started_) {
      // The segments' snapshots first: rows a fold moves meanwhile are then
      // in the store file's snapshot, taken after.
      for (auto s = sources_.rbegin(); s != sources_.rend(); ++s) (*s)->live = (*s)->rows.step();
      started_ = true;
    } else {
      current_->live = current_->rows.step();
    }
    current_ = nullptr;
    for (auto& s : sources_)
      if (s->live && (!current_ || s->index() < current_->index())) current_ = s.get();
    if (!current_) return false;
    for (auto& s : sources_)  // the same index elsewhere: skipped
      if (s.get() != current_ && s->live && s->index() == current_->index()) s->live = s->rows.step();
    return true;
  }
  Statement& row() { return current_ ? current_->rows.row() : sources_[0]->rows.row(); }
  int columns() const { return sources_[0]->rows.columns(); }
  const Db& store() const { return sources_[0]->db; }

 private:
  struct Source {
    explicit Source(Db d) : db(std::move(d)), rows(db) {}
    std::int64_t index() const { return rows.row().int64(0); }
    Db db;
    mutable Rows rows;
    bool live = false;
  };
  std::vector<std::unique_ptr<Source>> sources_;
  Source* current_ = nullptr;
  bool started_ = false;
};

}  // namespace

std::string segment_path(const std::string& dir, const std::string& name) {
  return (fs::path(dir) / ("store" + std::string(kSegmentInfix) + name + ".sqlite")).string();
}

std::vector<std::string> segment_files(const std::string& store_file) {
  const fs::path file(store_file);
  const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
  const std::string prefix = file.stem().string() + kSegmentInfix;
  std::vector<std::string> found;
  std::error_code e;
  for (const auto& entry : fs::directory_iterator(dir, e)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with(prefix) && name.ends_with(".sqlite")) found.push_back(entry.path().string());
  }
  std::sort(found.begin(), found.end());
  return found;
}

// ---- Segment ---------------------------------------------------------------

struct Segment::Impl {
  Impl(Db d, StoreLayout l) : appender(std::move(d), std::move(l)) {}
  Appender appender;
};

Segment::Segment(const std::string& dir, const std::string& name, const StoreLayout& layout,
                 const std::string& config_hash) {
  const StoreLayout l = normalized(layout);
  const std::string file = segment_path(dir, name);
  if (fs::exists(file)) throw std::runtime_error(file + ": a segment of that name exists already");
  Db db = open_to_write(file);
  Transaction t(db);
  create_schema(db, l, {{"config_hash", config_hash}, {"layout", layout_json(l).dump()}});
  t.commit();
  impl_ = std::make_unique<Impl>(std::move(db), l);
}

Segment::~Segment() = default;
Segment::Segment(Segment&&) noexcept = default;
Segment& Segment::operator=(Segment&&) noexcept = default;
const std::string& Segment::path() const { return impl_->appender.db.file(); }
void Segment::append(std::span<const Row> rows) { impl_->appender.append(rows); }

// ---- Store --------------------------------------------------------------

struct Store::Impl {
  Impl(WriterLock w, Db d, StoreLayout l, std::string h)
      : lock(std::move(w)), appender(std::move(d), std::move(l)), hash(std::move(h)) {}
  WriterLock lock;  // declared first: released after the store is closed
  Appender appender;
  std::string hash;
};

Store::Store(const std::string& dir, const StoreLayout& layout, const std::map<std::string, std::string>& meta,
             bool fresh) {
  const auto hash = find(meta, "config_hash");
  if (!hash) throw std::invalid_argument("store in " + dir + ": meta has no config_hash");
  StoreLayout l = normalized(layout);
  std::map<std::string, std::string> all = meta;
  all["layout"] = layout_json(l).dump();

  fs::create_directories(dir);
  WriterLock lock(dir);  // before the store is moved aside, created or opened
  const std::string file = (fs::path(dir) / "store.sqlite").string();
  if (fresh) {
    if (fs::exists(file)) move_aside(file);
    for (const auto& segment : segment_files(file)) move_aside(segment);
  }
  Db db = open_to_write(file);
  {
    Transaction t(db);  // the schema appears whole, or not at all
    if (!has_table(db, "samples")) {
      create_schema(db, l, all);
    } else {
      check_same_run(db, meta, l);
      add_meta(db, all);
    }
    t.commit();
  }
  impl_ = std::make_unique<Impl>(std::move(lock), std::move(db), std::move(l), *hash);
  fold();  // what a killed run left in segments
}

Store::~Store() = default;
Store::Store(Store&&) noexcept = default;
Store& Store::operator=(Store&&) noexcept = default;

const std::string& Store::path() const { return impl_->appender.db.file(); }

Segment Store::segment(const std::string& name) const {
  return Segment(fs::path(path()).parent_path().string(), name, impl_->appender.layout, impl_->hash);
}

std::int64_t Store::fold() {
  std::int64_t moved = 0;
  for (const auto& file : segment_files(path())) moved += fold_segment(impl_->appender.db, file);
  return moved;
}

std::int64_t Store::fold(const std::string& segment_file) { return fold_segment(impl_->appender.db, segment_file); }

std::vector<bool> Store::finished(std::int64_t total) const {
  std::vector<bool> done(std::size_t(std::max<std::int64_t>(total, 0)));
  index_bitmap(impl_->appender.db, total, done);
  return done;
}

std::optional<std::vector<bool>> Store::peek(const std::string& dir, const StoreLayout& layout,
                                             const std::map<std::string, std::string>& meta, std::int64_t total) {
  const std::string file = (fs::path(dir) / "store.sqlite").string();
  if (!fs::exists(file)) return std::nullopt;
  const Db db = open_to_read(file);
  if (!has_table(db, "samples")) return std::nullopt;  // created, killed before its schema
  check_same_run(db, meta, normalized(layout));
  std::vector<bool> done(std::size_t(std::max<std::int64_t>(total, 0)));
  index_bitmap(db, total, done);
  for (const auto& segment_file : segment_files(file)) {  // what the run would fold first
    const Db segment = open_to_read(segment_file);
    if (!has_table(segment, "samples")) continue;
    check_segment(segment, db);
    index_bitmap(segment, total, done);
  }
  return done;
}

std::int64_t Store::count() const {
  Statement s(impl_->appender.db, "SELECT count(*) FROM samples");
  s.step();
  return s.int64(0);
}

void Store::append(std::span<const Row> rows) { impl_->appender.append(rows); }

void Store::set_meta(const std::string& key, const std::string& value) {
  Statement s(impl_->appender.db,
              "INSERT INTO meta(key, value) VALUES(?, ?) ON CONFLICT(key) DO UPDATE SET value = excluded.value");
  s.bind(1, std::string_view(key));
  s.bind(2, std::string_view(value));
  s.step();
}

std::optional<std::string> Store::meta(const std::string& key) const {
  Statement s(impl_->appender.db, "SELECT value FROM meta WHERE key = ?");
  s.bind(1, std::string_view(key));
  return s.step() ? s.text(0) : std::nullopt;
}

// Bytes a row takes in the file, by SQLite's record format (sqlite.org/fileformat2.html,
// "Record Format" and "B-tree Pages"): a header of one varint per column,
// the values (REAL 8 bytes, TEXT its length, NULL nothing; idx is the rowid),
// the cell's size and rowid varints and its 2-byte pointer, over a leaf fill
// of 94% (measured: 10^6 rows of 16 columns, 155 bytes a row against 146 by
// the record format alone).
double row_bytes(const Row& r, const StoreLayout& layout) {
  auto varint = [](std::uint64_t v) { int n = 1; while (v >>= 7) ++n; return n; };
  std::size_t header = 1, body = 0;  // idx: a NULL in the record (1 header byte)
  auto text = [&](std::size_t length) { header += varint(13 + 2 * length); body += length; };
  text(r.status.size());
  header += 1, body += 8;  // wall_time
  if (r.message.empty()) header += 1; else text(r.message.size());
  for (std::size_t j = 0; j < r.factors.size(); ++j) {
    const bool labelled = j < layout.labels.size() && !layout.labels[j].empty();
    const auto v = r.factors[j];
    if (!labelled) header += 1, body += 8;
    else text(v >= 0 && v < double(layout.labels[j].size()) ? layout.labels[j][std::size_t(v)].size() : 0);
  }
  for (const double v : r.metrics) header += 1, body += std::isnan(v) ? 0 : 8;
  header += 1, body += 8;  // the checksum: a 64-bit integer
  const std::size_t payload = varint(header + 1) + header + body;
  const std::size_t cell = varint(payload) + varint(std::uint64_t(std::max<std::int64_t>(r.index, 0))) + payload + 2;
  return double(cell) / 0.94;
}

// ---- export -------------------------------------------------------------

namespace {

void csv_text(std::ostream& out, std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) {
    out << text;
    return;
  }
  out << '"';
  for (char c : text) {
    if (c == '"') out << '"';
    out << c;
  }
  out << '"';
}

void check_written(const std::ostream& out, const std::string& file) {
  if (!out) throw std::runtime_error(file + ": export: cannot write the output");
}


}  // namespace

void export_csv(const std::string& store_file, std::ostream& out, bool wall_time) {
  UnionRows rows(store_file);
  const int n = rows.columns();
  constexpr int kWallTime = 2;  // idx, status, wall_time, ...
  auto skip = [&](int c) { return !wall_time && c == kWallTime; };
  for (int c = 0; c < n; ++c) {
    if (skip(c)) continue;
    if (c) out << ',';
    csv_text(out, sqlite3_column_name(rows.row().get(), c));
  }
  out << '\n';
  char number[32];
  while (rows.step()) {
    const Statement& s = rows.row();
    for (int c = 0; c < n; ++c) {
      if (skip(c)) continue;
      if (c) out << ',';
      switch (sqlite3_column_type(s.get(), c)) {
        case SQLITE_NULL: break;
        case SQLITE_INTEGER: out << s.int64(c); break;
        case SQLITE_FLOAT:
          std::snprintf(number, sizeof number, "%.17g", sqlite3_column_double(s.get(), c));
          out << number;
          break;
        default: csv_text(out, *s.text(c));
      }
    }
    out << '\n';
  }
  check_written(out, store_file);
}

void read_rows(const std::string& store_file, const std::function<void(const Row&)>& f) {
  UnionRows rows(store_file);
  const StoreLayout l = layout_from_json(store_file, find(read_meta(rows.store()), "layout"));
  Row r;
  r.factors.resize(l.factors.size());
  r.metrics.resize(l.metrics.size());
  while (rows.step()) {
    const Statement& s = rows.row();
    r.index = s.int64(0);
    // The status as its static name (Row holds a view).
    r.status = mech::to_string(mech::status_from_string(s.text(1).value_or("")).value_or(mech::Status::evaluation_error));
    r.wall_time = s.real(2);
    r.message = s.text(3).value_or("");
    for (std::size_t j = 0; j < l.factors.size(); ++j) {
      const int c = 4 + static_cast<int>(j);
      const auto& labels = l.labels.empty() ? std::vector<std::string>() : l.labels[j];
      if (labels.empty()) {
        r.factors[j] = s.real(c);
      } else {
        const auto at = std::find(labels.begin(), labels.end(), s.text(c).value_or(""));
        r.factors[j] = at == labels.end() ? std::nan("") : static_cast<double>(at - labels.begin());
      }
    }
    for (std::size_t m = 0; m < l.metrics.size(); ++m) r.metrics[m] = s.real(4 + static_cast<int>(l.factors.size() + m));
    f(r);
  }
}

void export_json(const std::string& store_file, std::ostream& out) {
  UnionRows rows(store_file);
  json meta = json::object();
  for (const auto& [key, value] : read_meta(rows.store())) meta[key] = value;
  out << "{\"meta\": " << meta.dump() << ",\n\"samples\": [";
  const int n = rows.columns();
  std::vector<std::string> keys;  // quoted once
  for (int c = 0; c < n; ++c) keys.push_back(json(sqlite3_column_name(rows.row().get(), c)).dump() + ": ");
  // One small object a row: memory stays constant for 10^7 rows.
  for (bool first = true; rows.step(); first = false) {
    out << (first ? "\n{" : ",\n{");
    const Statement& s = rows.row();
    for (int c = 0; c < n; ++c) {
      out << (c ? ", " : "") << keys[std::size_t(c)];
      switch (sqlite3_column_type(s.get(), c)) {
        case SQLITE_NULL: out << "null"; break;
        case SQLITE_INTEGER: out << s.int64(c); break;
        case SQLITE_FLOAT: out << json(sqlite3_column_double(s.get(), c)).dump(); break;
        default: out << json(*s.text(c)).dump();
      }
    }
    out << '}';
  }
  out << "\n]}\n";
  check_written(out, store_file);
}

// ---- merge --------------------------------------------------------------

namespace {

// "3 indices missing: 7, 8, 9" (at most 10 named).
std::string name_indices(const std::vector<std::int64_t>& indices, std::int64_t count, const std::string& what) {
  std::string s = std::to_string(count) + (count == 1 ? " index " : " indices ") + what + ": ";
  for (std::size_t i = 0; i < indices.size(); ++i) s += (i ? ", " : "") + std::to_string(indices[i]);
  if (count > std::int64_t(indices.size())) s += ", ...";
  return s;
}

// Missing and doubled indices over all inputs, or "" when each of [0, total)
// appears exactly once.
std::string coverage_errors(const std::vector<std::string>& files, std::int64_t total) {
  constexpr std::size_t kNamed = 10;
  std::vector<std::uint8_t> seen(std::size_t(total), 0);  // 0, 1, 2 = twice or more
  std::vector<std::int64_t> outside;
  std::int64_t outside_count = 0;
  for (const auto& file : files) {
    UnionRows rows(file);  // with its segments, each index once; every checksum verified
    while (rows.step()) {
      const std::int64_t i = rows.row().int64(0);
      if (i < 0 || i >= total) {
        if (outside.size() < kNamed) outside.push_back(i);
        ++outside_count;
      } else if (seen[std::size_t(i)] < 2) {
        ++seen[std::size_t(i)];
      }
    }
  }
  std::vector<std::int64_t> missing, doubled;
  std::int64_t missing_count = 0, doubled_count = 0;
  for (std::int64_t i = 0; i < total; ++i) {
    const auto n = seen[std::size_t(i)];
    if (n == 0 && missing_count++ < std::int64_t(kNamed)) missing.push_back(i);
    if (n == 2 && doubled_count++ < std::int64_t(kNamed)) doubled.push_back(i);
  }
  std::string s;
  if (missing_count) s += name_indices(missing, missing_count, "missing") + "; ";
  if (doubled_count) s += name_indices(doubled, doubled_count, "in more than one row") + "; ";
  if (outside_count) s += name_indices(outside, outside_count, "outside [0, " + std::to_string(total) + ")") + "; ";
  return s.empty() ? s : s.substr(0, s.size() - 2);
}

}  // namespace

MergeReport merge_stores(const std::string& out_dir, const std::vector<std::string>& stores) {
  if (stores.empty()) throw std::invalid_argument("merge: no stores given");
  MergeReport report;
  std::vector<std::map<std::string, std::string>> metas;
  for (const auto& s : stores) {
    report.inputs.push_back(fs::is_directory(s) ? (fs::path(s) / "store.sqlite").string() : s);
    metas.push_back(read_meta(open_to_read(report.inputs.back())));
  }
  // All shards of one run: the same config, hence the same columns and total.
  const std::string& first = report.inputs[0];
  const auto hash = find(metas[0], "config_hash");
  const StoreLayout layout = layout_from_json(first, find(metas[0], "layout"));
  for (std::size_t k = 1; k < stores.size(); ++k) {
    const std::string& file = report.inputs[k];
    const auto h = find(metas[k], "config_hash");
    if (h != hash)
      throw StoreMismatch(
          "merge: " + file + " has config_hash " + h.value_or("none") + ", " + first + " has " + hash.value_or("none") +
          "; " +
          config_difference(find(metas[0], "config_canonical"), find(metas[k], "config_canonical"), first, file));
    if (layout_json(layout_from_json(file, find(metas[k], "layout"))) != layout_json(layout))
      throw StoreMismatch("merge: " + file + " has other columns than " + first);
  }
  const auto samples = find(metas[0], "samples");
  std::int64_t total = -1;
  try {
    total = std::stoll(samples.value_or(""));
  } catch (const std::logic_error&) {  // invalid_argument, out_of_range
  }
  if (total < 0) throw std::runtime_error("merge: " + first + ": no meta 'samples' (the number of samples)");
  if (const std::string errors = coverage_errors(report.inputs, total); !errors.empty())
    throw std::runtime_error("merge: " + errors + "; nothing was written");

  const std::string out_file = (fs::path(out_dir) / "store.sqlite").string();
  if (fs::exists(out_file)) throw std::runtime_error("merge: " + out_file + " exists already");
  auto meta = metas[0];
  meta.erase("shard");
  meta["merged_from"] = json(report.inputs).dump();
  const Store created(out_dir, layout, meta, false);  // the schema and meta, and the writer's lock
  const Db out(out_file, SQLITE_OPEN_READWRITE);
  try {
    for (const auto& file : report.inputs) {
      std::vector<std::string> parts = segment_files(file);
      parts.insert(parts.begin(), file);
      if (stored_columns(open_to_read(file)).back() == "checksum") {
        for (const auto& part : parts)  // verified above
          if (part == file || has_table(open_to_read(part), "samples")) report.rows += copy_rows(out, part);
        continue;
      }
      // A shard from before checksums gets them here, row by row.
      const int n = int(kColumnsBefore + layout.factors.size() + layout.metrics.size());
      Statement insert(out, insert_sql(std::size_t(n) + 1));
      Transaction t(out);
      UnionRows rows(file);
      while (rows.step()) {
        sqlite3_stmt* row = rows.row().get();
        insert.reset();
        RowHash h;
        for (int c = 0; c < n; ++c) {
          insert.bind(c + 1, sqlite3_column_value(row, c));
          h.column(row, c);
        }
        insert.bind(n + 1, h.value());
        insert.step();
        ++report.rows;
      }
      t.commit();
    }
  } catch (...) {  // a merge is whole or absent
    for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(out_file + suffix);
    throw;
  }
  return report;
}

}  // namespace opt::doe
