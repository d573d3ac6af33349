// `mechopt check` and `mechopt recover` (docs/doe.md, "Damage"): a store
// file read tolerantly. SQLite stops a query at the first page it cannot
// read (SQLITE_CORRUPT); the rows are therefore read by ranges of indices,
// and a range that fails is read up to the failure, then split in two, down
// to single indices: what lies in an unreadable page is lost, every other
// row is read. A row counts when its checksum holds.
#include "opt/doe/recover.hpp"

#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <sstream>
#include <unordered_set>

#include "doe/checksum.hpp"
#include "doe/store_file.hpp"
#include "opt/doe/batch.hpp"
#include "opt/doe/store.hpp"

namespace opt::doe {
namespace {

namespace fs = std::filesystem;
using sql::Db;
using sql::Statement;

// Single indices probed in vain before the scan gives up: a damaged
// interior page can hide a million rows; beyond that, the file is lost.
constexpr std::int64_t kMaxLostProbes = 1'000'000;
constexpr int kNamed = 10;  // indices named in a problem's line

// "3: 7, 8, 9" (at most kNamed named).
std::string named(std::int64_t count, const std::vector<std::int64_t>& indices) {
  std::string s = std::to_string(count) + ":";
  for (std::size_t i = 0; i < indices.size(); ++i) s += (i ? ", " : " ") + std::to_string(indices[i]);
  return s + (count > std::int64_t(indices.size()) ? ", ..." : "");
}

void note(std::vector<std::int64_t>& indices, std::int64_t i) {
  if (indices.size() < kNamed) indices.push_back(i);
}

// The indices read intact so far, over a store file and its segments: a row
// in two files (a fold killed half way) counts once.
class Seen {
 public:
  Seen(std::int64_t lo, std::int64_t hi) : lo_(lo), bits_(std::size_t(std::max<std::int64_t>(hi - lo, 0))) {}
  // true the first time i is seen.
  bool first(std::int64_t i) {
    if (i >= lo_ && i - lo_ < std::int64_t(bits_.size())) {
      if (bits_[std::size_t(i - lo_)]) return false;
      return bits_[std::size_t(i - lo_)] = true;
    }
    return others_.insert(i).second;
  }
  // Up to kNamed indices of [lo, hi) not seen.
  std::vector<std::int64_t> unseen() const {
    std::vector<std::int64_t> at;
    for (std::size_t k = 0; k < bits_.size() && at.size() < kNamed; ++k)
      if (!bits_[k]) at.push_back(lo_ + std::int64_t(k));
    return at;
  }

 private:
  std::int64_t lo_;
  std::vector<bool> bits_;
  std::unordered_set<std::int64_t> others_;  // outside [lo, hi), or all when the range is unknown
};

// The rows of one file of a store, read around what cannot be read; its
// problems are prefixed with `where` (the segment's name, or "" for the
// store file).
class Scan {
 public:
  using Intact = std::function<void(sqlite3_stmt* row)>;
  Scan(const Db& db, StoreCheck& c, Intact intact, Seen& seen, std::string where = "")
      : c_(c), intact_(std::move(intact)), seen_(seen), where_(std::move(where)),
        q_(db, "SELECT * FROM samples WHERE idx >= ? AND idx < ? ORDER BY idx") {}

  // Every row of the file: indices far outside any run are damage too.
  void all() {
    read(-(std::int64_t(1) << 62), (std::int64_t(1) << 62) - 1);
    auto problem = [&](std::int64_t count, const std::vector<std::int64_t>& indices, const std::string& what) {
      if (count) c_.problems.push_back(where_ + what + " " + named(count, indices));
    };
    problem(failed_, failed_at_, "rows whose checksum fails (damaged values)");
    problem(lost_, lost_at_, "indices in pages SQLite cannot read");
    problem(doubled_, doubled_at_, "rows out of order or doubled");
    problem(outside_, outside_at_, "intact rows outside the run's [" + std::to_string(c_.lo) + ", " +
                                       std::to_string(c_.hi) + ")");
    if (gave_up_)
      c_.problems.push_back(where_ + "gave up after " + std::to_string(kMaxLostProbes) +
                            " unreadable indices: the rows after " + std::to_string(last_) + " were not read");
  }

 private:
  // The rows of [a, b): up to a failure, then the rest in two halves.
  void read(std::int64_t a, std::int64_t b) {
    while (a < b && !gave_up_) {
      sqlite3_stmt* q = q_.get();
      sqlite3_reset(q);
      sqlite3_bind_int64(q, 1, a);
      sqlite3_bind_int64(q, 2, b);
      std::int64_t last = a - 1;
      int rc;
      while ((rc = sqlite3_step(q)) == SQLITE_ROW) {
        const std::int64_t i = sqlite3_column_int64(q, 0);
        if (i < a || i >= b) continue;  // a damaged page's cell: its row is read in its own range, if anywhere
        row(q, i);
        last = std::max(last, i);
      }
      sqlite3_reset(q);
      if (rc == SQLITE_DONE) return;
      if (last >= a) {  // read up to the failure: on after it
        a = last + 1;
        continue;
      }
      if (b - a == 1) {
        ++lost_;
        note(lost_at_, a);
        gave_up_ = lost_ >= kMaxLostProbes;
        return;
      }
      const std::int64_t mid = a + (b - a) / 2;
      read(a, mid);
      a = mid;
    }
  }

  void row(sqlite3_stmt* q, std::int64_t i) {
    if (i <= last_) {  // ranges are read in order: an index seen before
      ++doubled_;
      note(doubled_at_, i);
      return;
    }
    last_ = i;
    if (c_.checksums && !checksum_holds(q)) {
      ++failed_;
      note(failed_at_, i);
      return;
    }
    if (c_.hi >= 0 && (i < c_.lo || i >= c_.hi)) {
      ++outside_;
      note(outside_at_, i);
      return;
    }
    if (!seen_.first(i)) return;  // in the store file and a segment: once
    ++c_.intact;
    const auto* status = reinterpret_cast<const char*>(sqlite3_column_text(q, 1));
    ++c_.statuses[status ? status : "(none)"];
    if (intact_) intact_(q);
  }

  StoreCheck& c_;
  Intact intact_;
  Seen& seen_;
  std::string where_;
  Statement q_;
  std::int64_t last_ = std::numeric_limits<std::int64_t>::min();
  std::int64_t failed_ = 0, lost_ = 0, doubled_ = 0, outside_ = 0;
  std::vector<std::int64_t> failed_at_, lost_at_, doubled_at_, outside_at_;
  bool gave_up_ = false;
};

std::string store_file(const std::string& store) {
  return fs::is_directory(store) ? (fs::path(store) / "store.sqlite").string() : store;
}

// SQLite's message for the last failure on `db` (the exception's names the
// file and points to check and recover, which this is).
std::string sqlite_says(const Db& db) { return sqlite3_errmsg(db.get()); }

// The file's schema, SQLite's integrity check and the meta, into `c`; the
// samples table's CREATE statement, or "" when the schema is unreadable
// (nothing can be read then).
std::string examine(const Db& db, StoreCheck& c, std::map<std::string, std::string>& meta) {
  std::string schema;
  try {
    db.exec("PRAGMA cell_size_check=ON");  // a damaged cell is caught where it lies
    Statement s(db, "SELECT sql FROM sqlite_master WHERE type = 'table' AND name = 'samples'");
    if (s.step()) schema = s.text(0).value_or("");
    if (schema.empty()) c.problems.push_back("no samples table: not a store, or its schema is lost");
  } catch (const std::runtime_error&) {
    c.problems.push_back("the first page (the file header and the schema) is damaged (" + sqlite_says(db) +
                         "): no row can be read");
    return "";
  }
  try {
    Statement s(db, "PRAGMA integrity_check(" + std::to_string(kNamed) + ")");
    while (s.step()) {  // "ok", or messages, the first after a line that names the database
      std::istringstream lines(s.text(0).value_or(""));
      for (std::string line; std::getline(lines, line);)
        if (line != "ok" && !line.starts_with("*** ")) c.problems.push_back("SQLite's integrity check: " + line);
    }
  } catch (const std::runtime_error&) {
    c.problems.push_back("SQLite's integrity check stopped: " + sqlite_says(db));
  }
  try {
    meta = read_meta(db);
  } catch (const std::runtime_error&) {
    c.problems.push_back("the meta is damaged (" + sqlite_says(db) +
                         "): the config hash and the sample count are lost; the config given to the next run "
                         "supplies them");
    return schema;
  }
  if (const auto it = meta.find("config_hash"); it != meta.end()) c.config_hash = it->second;
  try {
    const std::int64_t n = std::stoll(meta.at("samples"));
    int index = 0, count = 1;
    if (const auto it = meta.find("shard"); it != meta.end()) std::sscanf(it->second.c_str(), "%d/%d", &index, &count);
    if (count < 1 || index < 0 || index >= count) index = 0, count = 1;
    c.lo = n * index / count, c.hi = n * (index + 1) / count;  // as the runner splits a run into shards
  } catch (const std::exception&) {  // no 'samples': the range is unknown
  }
  c.finished = meta.contains("finished") && !meta.at("finished").empty();
  Statement columns(db, "SELECT * FROM samples LIMIT 0");
  const int n = sqlite3_column_count(columns.get());
  c.checksums = n > 0 && std::string_view(sqlite3_column_name(columns.get(), n - 1)) == "checksum";
  return schema;
}

// The check of `store`; `begin`, when given, is told the schema and meta
// before the rows are read and gives what takes each intact row; `end` is
// called after the last.
using Begin = std::function<Scan::Intact(const Db&, const std::string& schema,
                                         const std::map<std::string, std::string>& meta, StoreCheck&)>;
StoreCheck scan(const std::string& store, const Begin& begin = nullptr, const std::function<void()>& end = nullptr) {
  StoreCheck c;
  c.file = store_file(store);
  const Db db = open_to_read(c.file);
  std::map<std::string, std::string> meta;
  const std::string schema = examine(db, c, meta);
  if (schema.empty()) return c;
  Seen seen(c.lo, c.hi);
  const Scan::Intact intact = begin ? begin(db, schema, meta, c) : Scan::Intact();
  Scan(db, c, intact, seen).all();
  for (const auto& file : segment_files(c.file)) {  // a killed run's rows, not yet folded
    const std::string where = fs::path(file).filename().string() + ": ";
    try {
      const Db segment = open_to_read(file);
      Statement q(segment, "SELECT value FROM meta WHERE key = 'config_hash'");
      const auto hash = q.step() ? q.text(0) : std::nullopt;
      if (hash != c.config_hash && c.config_hash) {
        c.problems.push_back(where + "a segment of another run (config_hash " + hash.value_or("none") + ")");
        continue;
      }
      Scan(segment, c, intact, seen, where).all();
    } catch (const std::runtime_error& e) {
      c.problems.push_back(where + "cannot be read: " + e.what());
    }
  }
  if (c.hi >= 0) c.missing = c.hi - c.lo - c.intact;
  if (c.finished && c.missing)
    c.problems.push_back("samples missing from a finished store " + named(c.missing, seen.unseen()));
  if (end) end();
  return c;
}

}  // namespace

StoreCheck check_store(const std::string& store) { return scan(store); }

StoreCheck recover_store(const std::string& store, const std::string& out_dir) {
  const std::string out_file = (fs::path(out_dir) / "store.sqlite").string();
  if (fs::exists(out_file)) throw std::runtime_error("recover: " + out_file + " exists already");
  std::optional<WriterLock> lock;
  std::optional<Db> out;
  std::optional<sql::Transaction> t;
  std::optional<Statement> insert;
  return scan(store, [&](const Db&, const std::string& schema, const std::map<std::string, std::string>& meta,
                          StoreCheck& c) -> Scan::Intact {
    fs::create_directories(out_dir);
    lock.emplace(out_dir);
    out.emplace(open_to_write(out_file));
    t.emplace(*out);  // every row or none (a failure leaves an empty file)
    out->exec(schema);
    if (!c.checksums) out->exec("ALTER TABLE samples ADD COLUMN checksum INTEGER");
    out->exec("CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT)");
    auto kept = meta;
    kept.erase("finished");  // the run that fills in the lost samples sets it
    kept.erase("refine");    // its table is not copied
    kept["recovered_from"] = c.file;
    add_meta(*out, kept);
    int n = 0;
    {
      Statement s(*out, "SELECT * FROM samples LIMIT 0");
      n = sqlite3_column_count(s.get());
    }
    std::string sql = "INSERT INTO samples VALUES(?";
    for (int i = 1; i < n; ++i) sql += ", ?";
    insert.emplace(*out, sql + ")");
    c.saved = 0;
    return [&, n](sqlite3_stmt* row) {
      insert->reset();
      RowHash h;
      for (int i = 0; i + 1 < n; ++i) {
        insert->bind(i + 1, sqlite3_column_value(row, i));
        h.column(row, i);
      }
      insert->bind(n, h.value());  // the stored one, which held (or the first, for a store from before them)
      insert->step();
      ++c.saved;
    };
  }, [&] { if (t) t->commit(); });
}

}  // namespace opt::doe
