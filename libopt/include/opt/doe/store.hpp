// The results store of the batch pipeline (docs/doe.md, "The store" and
// "Resume, exactly"): one SQLite file DIR/store.sqlite, one row per evaluated
// sample, and while a run writes, one segment file per writer beside it
// (DIR/store.seg-NAME.sqlite), folded into store.sqlite when the run ends or
// the next run opens the store. A row is committed or absent, so a run
// killed at any moment resumes from the indices the store and its segments
// hold; readers of whole rows take each index once.
#pragma once
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace opt::doe {

// The columns of `samples` after idx, status, wall_time and message.
struct StoreLayout {
  std::vector<std::string> factors;              // column names, in order
  std::vector<std::vector<std::string>> labels;  // per factor: option names if categorical (TEXT), else empty (REAL)
  std::vector<std::string> metrics;              // column names, in order
};

// One evaluated sample. In the store, one row of `samples`: idx, status,
// wall_time, message, the factors, the metrics, and `checksum`, 64 bits over
// the values before it, which the writer computes and every reader of whole
// rows verifies (docs/doe.md, "Damage").
struct Row {
  std::int64_t index = 0;
  std::string_view status;      // e.g. "ok", "cannot_assemble"
  double wall_time = 0;         // s
  std::string message;          // "" -> NULL
  std::vector<double> factors;  // SI; a categorical factor's option index (written as its label)
  std::vector<double> metrics;  // NaN -> NULL
};

// An existing store that another configuration (or another set of columns)
// wrote: resuming into it would mix two designs.
class StoreMismatch : public std::runtime_error {
 public:
  using runtime_error::runtime_error;
};

// A store file that SQLite (SQLITE_CORRUPT, SQLITE_NOTADB), a row's checksum
// or an index outside the run finds damaged: the message names the file and
// what was found, and points to `mechopt check` and `mechopt recover`.
class StoreDamaged : public std::runtime_error {
 public:
  StoreDamaged(const std::string& file, const std::string& what)
      : runtime_error(file + " is damaged (" + what + "): `mechopt check " + file + "` says what is wrong, " +
                      "`mechopt recover " + file + " OUT` copies its intact rows into OUT/store.sqlite") {}
};

// Another process writes the store in that directory (it holds DIR/store.lock):
// the message names it by pid, host, start time and command.
class StoreBusy : public std::runtime_error {
 public:
  using runtime_error::runtime_error;
};

// A writer's own file beside a store, DIR/store.seg-NAME.sqlite (docs/doe.md,
// "Segments"): the samples table of the store and the meta keys config_hash
// and layout, appended to by one thread in batched transactions with no lock
// shared with any other writer, so that N writers append N times as fast as
// one. Its rows join store.sqlite at the store's fold; until then the
// readers of whole rows (export, read_rows, merge, check, recover) and the
// resume read the union. Under MPI each rank writes segments of its own
// (DIR on a file system every rank reaches).
class Segment {
 public:
  // Creates DIR/store.seg-NAME.sqlite; std::runtime_error if it exists.
  Segment(const std::string& dir, const std::string& name, const StoreLayout& layout, const std::string& config_hash);
  ~Segment();
  Segment(Segment&&) noexcept;
  Segment& operator=(Segment&&) noexcept;
  const std::string& path() const;
  // As Store::append, within this file (an index in another segment or the
  // store is not seen: the scheduler hands each index out once).
  void append(std::span<const Row> rows);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// DIR/store.seg-NAME.sqlite: the file of the segment NAME of the store in DIR.
std::string segment_path(const std::string& dir, const std::string& name);

// The segment files of a store file FILE.sqlite: FILE.seg-*.sqlite beside it,
// sorted by name.
std::vector<std::string> segment_files(const std::string& store_file);

// One writer at a time: a Store holds an exclusive flock on DIR/store.lock
// (a file of its own, beside the store) for its lifetime, taken before the
// store is opened, created or moved aside. The operating system releases it
// with the process, so a run killed by SIGKILL or a power cut leaves nothing
// that blocks the next one. Readers (export, peek, check, pandas) never take
// it. Under MPI only the rank that writes opens the Store.
class Store {
 public:
  // Takes DIR/store.lock (StoreBusy when another process holds it), then
  // opens DIR/store.sqlite (creating DIR), or creates it with `layout` and
  // `meta` (key -> text; must hold "config_hash"). An existing store must have
  // the same config_hash and layout, else StoreMismatch names the file and the
  // top-level keys of meta "config_canonical" (a JSON object) that differ; one
  // that `mechopt recover` saved without meta must have this run's columns,
  // and takes this run's meta. A store from before row checksums is refused
  // (StoreMismatch: recover copies it into one with them). On
  // reopening, meta keys the store lacks are added; stored ones are kept (use
  // set_meta to change them). fresh=true first renames an existing store (and
  // its -wal/-shm) to store.sqlite.old-YYYYmmdd-HHMMSS, and its segments
  // likewise. Segments left by a killed run are folded in (StoreMismatch when
  // one is of another run).
  Store(const std::string& dir, const StoreLayout& layout, const std::map<std::string, std::string>& meta, bool fresh);
  ~Store();
  Store(Store&&) noexcept;
  Store& operator=(Store&&) noexcept;

  const std::string& path() const;
  // A new segment DIR/store.seg-NAME.sqlite of this store, for one writer.
  Segment segment(const std::string& name) const;
  // Moves every segment's rows into store.sqlite (INSERT OR IGNORE: a row a
  // killed fold left in both is taken once), each segment in a transaction of
  // its own and then removed; returns the rows moved. The segments' writers
  // must have closed them.
  std::int64_t fold();
  // The same for one segment file of this store, which its writer has
  // closed (a run's folder thread, while the other threads write).
  std::int64_t fold(const std::string& segment_file);
  // The indices in the store as `total` bits (bit i: sample i done). An index
  // outside [0, total) (the config hash matched) or a page SQLite cannot
  // read: StoreDamaged. The values are not read, nor their checksums.
  std::vector<bool> finished(std::int64_t total) const;
  // For a dry run, reading only: nullopt when DIR holds no store; else the
  // finished() bitmap of it and its segments, after the checks the
  // constructor makes (StoreMismatch).
  static std::optional<std::vector<bool>> peek(const std::string& dir, const StoreLayout& layout,
                                               const std::map<std::string, std::string>& meta, std::int64_t total);
  std::int64_t count() const;
  // All rows in one transaction: all committed or none. A duplicate index (in
  // the store or the batch) is a bug of the caller: std::logic_error naming it.
  void append(std::span<const Row> rows);
  void set_meta(const std::string& key, const std::string& value);
  std::optional<std::string> meta(const std::string& key) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The bytes `row` will take in a store file (its record, cell and share of a
// page), for --dry-run's size estimate.
double row_bytes(const Row& row, const StoreLayout& layout);

// Readers of any store file (`mechopt export`) and its segments: rows ordered
// by idx, each index once, every
// row's checksum verified (StoreDamaged at the first that fails; what was
// written by then is incomplete); the checksum column is not written.
// CSV: a header row, numbers with 17 significant digits (%.17g: every double
// exactly), NULL as an empty cell. Without wall_time it is the canonical dump
// (`mechopt export --canonical`): rows by index and nothing of the run itself,
// so two stores of the same results give the same bytes whatever threads,
// ranks or shards made them.
void export_csv(const std::string& store_file, std::ostream& out, bool wall_time = true);
// Every row, ordered by idx (a categorical factor as its option index).
void read_rows(const std::string& store_file, const std::function<void(const Row&)>& f);
// JSON: {"meta": {...}, "samples": [{column: value or null}, ...]}, streamed
// row by row (one sample a line), so memory does not grow with the store.
void export_json(const std::string& store_file, std::ostream& out);

// `mechopt merge OUT STORE...`: the shard stores (files, or directories holding
// store.sqlite), each with its segments, into OUT/store.sqlite, which must not exist yet. Every
// config_hash must agree (else StoreMismatch naming the store), and every index
// in [0, meta "samples") must appear exactly once (else runtime_error naming up
// to 10 missing or doubled indices and their counts); nothing is written then.
struct MergeReport {
  std::int64_t rows = 0;
  std::vector<std::string> inputs;  // the store files read
};
MergeReport merge_stores(const std::string& out_dir, const std::vector<std::string>& stores);

}  // namespace opt::doe
