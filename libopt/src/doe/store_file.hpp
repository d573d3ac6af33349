// What the files of the store share (store.cpp, store_file.cpp,
// store_schema.cpp, store_rows.cpp, appender.cpp, export.cpp, merge.cpp,
// recover.cpp): opening a store file, its meta and schema, the writer's
// lock, and reading the rows of a store and its segments.
#pragma once
#include <sqlite3.h>

#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "doe/sqlite.hpp"
#include "opt/doe/store.hpp"

namespace opt::doe {

// ---- opening, meta (store_file.cpp) -----------------------------------------

// A store to read: a missing file is an error, never a new empty store.
sql::Db open_to_read(const std::string& file);
// A store to write: 64 KiB pages (for a new file), WAL journal, synchronous=NORMAL.
sql::Db open_to_write(const std::string& file);

std::map<std::string, std::string> read_meta(const sql::Db& db);
// Adds the keys the store lacks; stored values are kept.
void add_meta(const sql::Db& db, const std::map<std::string, std::string>& meta);
// m[key], if there.
std::optional<std::string> meta_value(const std::map<std::string, std::string>& m, const std::string& key);

// DIR/store.lock, held (flock, exclusive) from construction to destruction:
// StoreBusy naming the holder when another process holds it (store.hpp, Store).
class WriterLock {
 public:
  explicit WriterLock(const std::string& dir);
  ~WriterLock();
  WriterLock(WriterLock&& o) noexcept;
  WriterLock& operator=(WriterLock&&) = delete;

 private:
  std::string file_;
  int fd_ = -1;
};

// ---- layout and schema (store_schema.cpp) -------------------------------------

constexpr std::size_t kColumnsBefore = 4;  // idx, status, wall_time, message: then factors, metrics, checksum

// labels may be left empty when no factor is categorical.
StoreLayout normalized(StoreLayout l);
nlohmann::json layout_json(const StoreLayout& l);
// The layout in meta 'layout' of `file`; runtime_error when missing.
StoreLayout layout_from_json(const std::string& file, const std::optional<std::string>& text);
// The top-level keys whose canonical config values differ.
std::string config_difference(const std::optional<std::string>& a_text, const std::optional<std::string>& b_text,
                              const std::string& a_name, const std::string& b_name);
bool has_table(const sql::Db& db, const char* name);
// The tables meta and samples (with its checksum column), and `meta`.
void create_schema(const sql::Db& db, const StoreLayout& l, const std::map<std::string, std::string>& meta);
// "INSERT INTO samples VALUES(?, ?, ...)" for n columns.
std::string insert_sql(std::size_t columns);
// FILE (and its -wal, -shm) -> FILE.old-<time> (-wal, -shm).
void move_aside(const std::string& file);
// The names of the columns of `samples` (SELECT * FROM samples), in order.
std::vector<std::string> stored_columns(const sql::Db& db);
// An existing store must hold this run's samples (StoreMismatch naming what differs).
void check_same_run(const sql::Db& db, const std::map<std::string, std::string>& meta, const StoreLayout& l);

// ---- the rows of a store and its segments (store_rows.cpp) ------------------

// SELECT * FROM samples ORDER BY idx, every row's checksum verified: step()
// throws StoreDamaged at the first row that fails it. columns(): the values
// without the checksum. A store from before checksums is read unverified.
class Rows {
 public:
  explicit Rows(const sql::Db& db);
  bool step();
  sql::Statement& row() { return s_; }
  const sql::Statement& row() const { return s_; }
  int columns() const { return n_; }

 private:
  std::string file_;
  sql::Statement s_;
  int n_;
  bool checked_ = false;
};

// The rows of a store file and of its segments, by idx, each index once (a
// fold killed half way leaves a row in both; the copies differ at most in
// wall_time, and the store file's is taken), every checksum verified.
class UnionRows {
 public:
  explicit UnionRows(const std::string& store_file);
  bool step();
  sql::Statement& row();
  int columns() const;
  const sql::Db& store() const;

 private:
  struct Source {
    explicit Source(sql::Db d) : db(std::move(d)), rows(db) {}
    std::int64_t index() const { return rows.row().int64(0); }
    sql::Db db;
    Rows rows;
    bool live = false;
  };
  std::vector<std::unique_ptr<Source>> sources_;
  Source* current_ = nullptr;
  bool started_ = false;
};

// The indices of a store file's rows, set in `done` (`total` bits): only
// the indices are read. An index outside [0, total): StoreDamaged.
void index_bitmap(const sql::Db& db, std::int64_t total, std::vector<bool>& done);
// A segment must be of the store's run: its config_hash and columns (StoreMismatch).
void check_segment(const sql::Db& segment, const sql::Db& store);
// FILE and its -wal and -shm.
void remove_file(const std::string& file);
// The rows of the store file `file` appended to `to` in one transaction
// (an index `to` holds already keeps `to`'s row); returns how many.
std::int64_t copy_rows(const sql::Db& to, const std::string& file);

}  // namespace opt::doe
