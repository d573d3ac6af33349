// Thin RAII over SQLite's C API for the store and its readers: every return
// code checked, errors thrown with the file and SQLite's message.
#pragma once
#include <sqlite3.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "opt/doe/store.hpp"

namespace opt::doe::sql {

class Db {
 public:
  Db(std::string file, int flags) : file_(std::move(file)) {
    // No memory statistics: they take a global lock at every allocation.
    // Only before SQLite's first use in the process (else a harmless no).
    [[maybe_unused]] static const int no_statistics = sqlite3_config(SQLITE_CONFIG_MEMSTATUS, 0);
    sqlite3* db = nullptr;
    // NOMUTEX: one thread uses a connection at a time (the writer), so
    // SQLite's per-call lock is pure cost (a tenth of append's time).
    const int rc = sqlite3_open_v2(file_.c_str(), &db, flags | SQLITE_OPEN_NOMUTEX, nullptr);
    handle_.reset(db);  // a failed open may still allocate a handle
    if (rc != SQLITE_OK)
      throw std::runtime_error(file_ + ": cannot open: " + (db ? sqlite3_errmsg(db) : sqlite3_errstr(rc)));
    // Extended codes tell a duplicate index (SQLITE_CONSTRAINT_PRIMARYKEY) from other failures.
    if (sqlite3_extended_result_codes(db, 1) != SQLITE_OK) fail("extended result codes");
    // A reader's checkpoint (pandas, `mechopt export` during a run) may hold a lock briefly.
    if (sqlite3_busy_timeout(db, 5000) != SQLITE_OK) fail("busy timeout");
  }
  sqlite3* get() const { return handle_.get(); }
  const std::string& file() const { return file_; }
  // SQLITE_CORRUPT and SQLITE_NOTADB say the file is damaged: StoreDamaged.
  [[noreturn]] void fail(const std::string& what) const {
    const int rc = sqlite3_errcode(get()) & 0xff;
    if (rc == SQLITE_CORRUPT || rc == SQLITE_NOTADB) throw StoreDamaged(file_, sqlite3_errmsg(get()));
    throw std::runtime_error(file_ + ": " + what + ": " + sqlite3_errmsg(get()));
  }
  void exec(const std::string& sql) const {
    if (sqlite3_exec(get(), sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) fail(sql);
  }

 private:
  struct Close {
    // close_v2: a connection with statements left is closed when they are finalized.
    void operator()(sqlite3* db) const { sqlite3_close_v2(db); }
  };
  std::string file_;
  std::unique_ptr<sqlite3, Close> handle_;
};

class Statement {
 public:
  Statement(const Db& db, const std::string& sql) : db_(&db) {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db.get(), sql.c_str(), -1, &s, nullptr) != SQLITE_OK) db.fail("cannot prepare " + sql);
    stmt_.reset(s);
  }
  sqlite3_stmt* get() const { return stmt_.get(); }
  // Ready to bind and step again; every parameter must be bound anew (old
  // values stay bound). reset's code repeats the previous step's, which was
  // checked (and thrown) there.
  void reset() { sqlite3_reset(get()); }
  // true: a row is ready; false: done.
  bool step() {
    const int rc = sqlite3_step(get());
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) db_->fail(sqlite3_sql(get()));
    return false;
  }
  void bind(int i, std::int64_t v) { check(sqlite3_bind_int64(get(), i, v)); }
  // NaN -> NULL (SQLite has no NaN).
  void bind(int i, double v) { check(std::isnan(v) ? sqlite3_bind_null(get(), i) : sqlite3_bind_double(get(), i, v)); }
  // "" -> NULL when `empty_is_null`.
  void bind(int i, std::string_view v, bool empty_is_null = false) {
    check(empty_is_null && v.empty() ? sqlite3_bind_null(get(), i)
                                     : sqlite3_bind_text(get(), i, v.data(), int(v.size()), SQLITE_TRANSIENT));
  }
  void bind(int i, const sqlite3_value* v) { check(sqlite3_bind_value(get(), i, v)); }
  std::int64_t int64(int col) const { return sqlite3_column_int64(get(), col); }
  // NULL -> NaN.
  double real(int col) const {
    return sqlite3_column_type(get(), col) == SQLITE_NULL ? std::nan("") : sqlite3_column_double(get(), col);
  }
  std::optional<std::string> text(int col) const {
    if (sqlite3_column_type(get(), col) == SQLITE_NULL) return std::nullopt;
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(get(), col));
    return std::string(p, std::size_t(sqlite3_column_bytes(get(), col)));
  }

 private:
  void check(int rc) const {
    if (rc != SQLITE_OK) db_->fail(std::string("cannot bind a value of ") + sqlite3_sql(get()));
  }
  struct Finalize {
    void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
  };
  const Db* db_;
  std::unique_ptr<sqlite3_stmt, Finalize> stmt_;
};

// BEGIN IMMEDIATE .. COMMIT; rolled back when left without commit().
class Transaction {
 public:
  explicit Transaction(const Db& db) : db_(db) { db_.exec("BEGIN IMMEDIATE"); }
  ~Transaction() {
    // A destructor cannot throw: should ROLLBACK fail, closing the
    // connection rolls the transaction back all the same. An error such as
    // SQLITE_FULL may have rolled back already (autocommit is then on).
    if (!committed_ && !sqlite3_get_autocommit(db_.get()))
      sqlite3_exec(db_.get(), "ROLLBACK", nullptr, nullptr, nullptr);
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit() {
    db_.exec("COMMIT");
    committed_ = true;
  }

 private:
  const Db& db_;
  bool committed_ = false;
};

// A column name as an SQL identifier: names hold dots ("fidelity.rod").
inline std::string identifier(std::string_view name) {
  std::string q = "\"";
  for (char c : name) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}

}  // namespace opt::doe::sql
