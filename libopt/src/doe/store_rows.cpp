// Reading the rows of a store and its segments, and copying them between
// files (store_file.hpp; docs/doe.md, "Segments").
#include <algorithm>
#include <filesystem>

#include "doe/checksum.hpp"
#include "doe/store_file.hpp"

namespace opt::doe {

namespace fs = std::filesystem;
using sql::Db;
using sql::Statement;
using sql::Transaction;

namespace {
constexpr const char* kSegmentInfix = ".seg-";
}  // namespace

Rows::Rows(const Db& db)
    : file_(db.file()), s_(db, "SELECT * FROM samples ORDER BY idx"), n_(sqlite3_column_count(s_.get())) {
  checked_ = n_ > 0 && std::string_view(sqlite3_column_name(s_.get(), n_ - 1)) == "checksum";
  n_ -= checked_;
}

bool Rows::step() {
  if (!s_.step()) return false;
  if (checked_ && !checksum_holds(s_.get()))
    throw StoreDamaged(file_, "sample " + std::to_string(s_.int64(0)) + " fails its checksum");
  return true;
}

UnionRows::UnionRows(const std::string& store_file) {
  sources_.push_back(std::make_unique<Source>(open_to_read(store_file)));
  for (const auto& file : segment_files(store_file)) {
    if (!fs::exists(file)) continue;  // folded since it was listed: its rows are in the store file
    auto s = std::make_unique<Source>(open_to_read(file));
    if (!has_table(s->db, "samples")) continue;
    check_segment(s->db, sources_[0]->db);
    sources_.push_back(std::move(s));
  }
}

bool UnionRows::step() {
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

sql::Statement& UnionRows::row() { return current_ ? current_->rows.row() : sources_[0]->rows.row(); }
int UnionRows::columns() const { return sources_[0]->rows.columns(); }
const Db& UnionRows::store() const { return sources_[0]->db; }

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

// A segment must be of the store's run: its config_hash and columns.
void check_segment(const Db& segment, const Db& store) {
  const auto hash = meta_value(read_meta(segment), "config_hash");
  const auto store_hash = meta_value(read_meta(store), "config_hash");
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

}  // namespace opt::doe
