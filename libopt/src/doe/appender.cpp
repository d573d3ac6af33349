// Appending a batch of rows in one statement (appender.hpp): INSERT INTO
// samples SELECT * FROM mechopt_batch, mechopt_batch being a virtual table
// over the rows in memory, registered on the writer's connection only. One
// step a batch, with SQLite's cursor on samples open through it, where a
// prepared one-row INSERT is reset, bound column by column and stepped
// (opening its cursor anew) once a row: about a fifth fewer instructions a
// row at 20 columns. The values are what binding gives: NaN and "" as NULL,
// a categorical factor as its option's label, texts read in place (the rows
// outlive the statement's step).
#include "doe/appender.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "doe/checksum.hpp"
#include "doe/store_file.hpp"

namespace opt::doe {

using sql::Db;
using sql::Statement;
using sql::Transaction;

namespace {

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

}  // namespace

Statement batch_insert(const Db& db, Batch& batch) {
  static const sqlite3_module module = batch_module();
  if (sqlite3_create_module_v2(db.get(), "mechopt_batch", &module, &batch, nullptr) != SQLITE_OK)
    db.fail("cannot register the batch table");
  return Statement(db, "INSERT INTO samples SELECT * FROM mechopt_batch");
}

void Appender::append(std::span<const Row> rows) {
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

}  // namespace opt::doe
