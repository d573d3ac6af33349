// How a run's threads share its samples and write its rows (batch.cpp;
// docs/doe.md, "Threads" and "Segments"): a writer per thread, the folder
// of closed segments (the ranges of indices: opt/ranges.hpp).
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "doe/evaluator.hpp"
#include "doe/progress.hpp"
#include "opt/doe/store.hpp"
#include "opt/ranges.hpp"

namespace opt::doe {

// A segment's name for thread `thread` of rank `rank` (thread -1: the
// rank's own, under MPI, written by its main thread) and its `part`-th
// file, numbered so that the names sort in the order of the ranges.
inline std::string segment_name(int rank, int thread, int part = 0) {
  char name[48];
  if (thread < 0) std::snprintf(name, sizeof name, "r%05d-p%06d", rank, part);
  else std::snprintf(name, sizeof name, "r%05d-t%04d-p%06d", rank, thread, part);
  return name;
}

// store.sqlite's one writer at a time, and the segments waiting to be
// folded into it (docs/doe.md, "Segments"). A thread's batch goes to
// store.sqlite when no other thread is writing it; a thread that finds it
// busy keeps its rows, and sends them to its own segment only when the
// store has been busy long (RowWriter): with few threads most rows go
// straight in, with many no thread waits for another. The run's first
// thread folds the closed segments between its own commits while the run
// goes, so that a run takes about the longer of its evaluation and its
// fold rather than their sum; work stealing between the ranges hands its
// samples to the others while it folds.
class Folder {
 public:
  void append(Store& store, std::span<const Row> rows) {
    std::lock_guard lock(store_m_);
    store.append(rows);
  }
  // Appends to store.sqlite if no other thread is writing it.
  bool try_append(Store& store, std::span<const Row> rows) {
    std::unique_lock lock(store_m_, std::try_to_lock);
    if (!lock) return false;
    store.append(rows);
    return true;
  }
  void hand(std::string file) {
    std::lock_guard lock(m_);
    files_.push_back(std::move(file));
  }
  // Folds every segment handed over so far.
  void fold(Store& store) {
    for (;;) {
      std::string file;
      {
        std::lock_guard lock(m_);
        if (files_.empty()) return;
        file = std::move(files_.front());
        files_.pop_front();
      }
      std::lock_guard lock(store_m_);
      store.fold(file);
    }
  }

 private:
  std::mutex store_m_;  // held while a thread writes store.sqlite
  std::mutex m_;        // files_
  std::deque<std::string> files_;
};

// The rows of one worker thread, committed in batches (docs/doe.md,
// "Segments"): to store.sqlite when no other thread writes it, else kept,
// and at kSpillRows to the thread's own segment, closed at `segment_rows`
// rows and handed to the folder. A batch is due at kBatchRows rows or
// 0.25 s after the last commit (a slow model's rows do not wait long: a
// kill loses at most what is uncommitted), and at the end. The rows' vectors are evaluated into again
// after their commit, so a sample costs no allocation and no thread frees
// what another allocated.
class RowWriter {
 public:
  RowWriter(Store& store, Folder* folder, int thread, std::size_t segment_rows, Committed& committed)
      : store_(store), folder_(folder), thread_(thread), segment_rows_(segment_rows), committed_(committed) {}
  ~RowWriter() {
    try {
      close();
    } catch (...) {  // an unwinding run: its own error is the one to report
    }
  }
  // A row to evaluate into: the next one of the batch. A full batch
  // (kBatchRows) is committed before it grows, while its rows are still in
  // the cache; one that has waited for store.sqlite to be free as long as
  // kSpillRows rows take goes to the thread's segment instead.
  Row& next() {
    if (used_ % kBatchRows == 0 && used_ > 0) commit(used_ >= kSpillRows ? Busy::spill : Busy::keep);
    if (used_ == rows_.size()) rows_.emplace_back();
    return rows_[used_++];
  }
  void commit_if_due() {
    if (used_ > 0 && since(last_) >= 0.25) commit(Busy::keep);
    if (thread_ == 0) folder_->fold(store_);
  }
  // What a batch does when another thread is writing store.sqlite: keep its
  // rows and evaluate on (a few threads, whose commits take turns: rows
  // written to a segment would be written again by the fold), go to the
  // segment (store.sqlite has been busy for long: many threads), or wait.
  enum class Busy { keep, spill, wait };
  void commit(Busy busy) {
    if (used_ == 0) return;
    const std::span<const Row> rows(rows_.data(), used_);
    if (busy == Busy::wait) {
      folder_->append(store_, rows);
    } else if (!folder_->try_append(store_, rows)) {
      if (busy == Busy::keep) return;
      if (!segment_) segment_ = store_.segment(segment_name(0, thread_, part_++));  // no rows, no file
      segment_->append(rows);
      in_segment_ += used_;
    }
    committed_.add(rows);
    used_ = 0;
    last_ = Clock::now();
    if (in_segment_ >= segment_rows_) close_segment();
  }
  // Commits what is left (to store.sqlite) and hands the open segment to the folder.
  void close() {
    commit(Busy::wait);
    close_segment();
  }

 private:
  void close_segment() {
    if (!segment_) return;
    const std::string file = segment_->path();
    segment_.reset();
    in_segment_ = 0;
    folder_->hand(file);
  }
  // A commit rewrites its last, partly filled 64 KiB pages: at 20 columns
  // 4096-row transactions run as fast as 20 000-row ones, 1000-row ones at
  // 65-85% of it (bench_doe_store BM_Append/12/ROWS).
  static constexpr std::size_t kBatchRows = 4096, kSpillRows = 4 * kBatchRows;
  Store& store_;
  Folder* folder_;
  int thread_;
  std::size_t segment_rows_;
  Committed& committed_;
  std::optional<Segment> segment_;
  int part_ = 0;
  std::size_t in_segment_ = 0;
  std::vector<Row> rows_;
  std::size_t used_ = 0;
  Clock::time_point last_ = Clock::now();
};

}  // namespace opt::doe
