// Appending a batch of rows to a store file in one statement (appender.cpp):
// the store's and every segment's writer.
#pragma once
#include <span>

#include "doe/sqlite.hpp"
#include "opt/doe/store.hpp"

namespace opt::doe {

struct Batch {  // set by append() around its one step
  const StoreLayout* layout = nullptr;
  std::span<const Row> rows;
  std::size_t at = 0;  // the row the scan is on: the one that failed, on an error
};

// The statement INSERT INTO samples SELECT * FROM mechopt_batch on `db`, the
// virtual table mechopt_batch showing `batch`'s rows.
sql::Statement batch_insert(const sql::Db& db, Batch& batch);

// One file's batched appends: a Store's or a Segment's. Rows are checked
// before the transaction (a bad row is the caller's bug, and nothing of its
// batch is written), then written in one statement and one transaction.
struct Appender {
  Appender(sql::Db d, StoreLayout l) : db(std::move(d)), layout(std::move(l)), insert(batch_insert(db, batch)) {}
  Appender(Appender&&) = delete;  // SQLite holds &batch, the statement &db
  sql::Db db;  // before the statement: destroyed after it
  StoreLayout layout;
  Batch batch{&layout, {}, 0};  // before insert: preparing it reads the layout
  sql::Statement insert;        // every batch goes through it
  void append(std::span<const Row> rows);
};

}  // namespace opt::doe
