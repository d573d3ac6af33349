// A run's tally of committed rows and its progress line (batch.cpp).
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <ostream>
#include <span>
#include <string>

#include "doe/evaluator.hpp"
#include "opt/doe/batch.hpp"
#include "opt/doe/store.hpp"

namespace opt::doe {

// Counts of the rows committed: in the shard (this run and earlier ones) and by this run.
struct Tally {
  std::int64_t done = 0;       // in the shard, committed
  std::int64_t evaluated = 0;  // by this run
  std::map<std::string, std::int64_t> statuses;  // this run
  std::int64_t failures() const {
    std::int64_t n = 0;
    for (const auto& [s, c] : statuses) n += s == "ok" ? 0 : c;
    return n;
  }
};

class Progress {
 public:
  Progress(std::string mode, std::ostream& err, std::int64_t total)
      : mode_(std::move(mode)), err_(err), total_(total) {}
  void update(const Tally& t, std::int64_t pending_at_start, bool final) {
    if (mode_ == "none") return;
    const double elapsed = since(t0_);
    if (!final && elapsed - last_ < (mode_ == "bar" ? 0.2 : 2.0)) return;
    last_ = elapsed;
    const double rate = elapsed > 0 ? t.evaluated / elapsed : 0;
    const std::int64_t left = pending_at_start - t.evaluated;
    const double eta = rate > 0 ? left / rate : 0;
    if (mode_ == "jsonl") {
      err_ << nlohmann::json{{"event", final ? "finished" : "progress"}, {"done", t.done}, {"total", total_},
                             {"evaluated", t.evaluated}, {"rate", rate}, {"eta_s", eta},
                             {"failures", t.failures()}, {"elapsed_s", elapsed}}
                  .dump()
           << "\n"
           << std::flush;
      return;
    }
    const double f = total_ ? static_cast<double>(t.done) / total_ : 1.0;
    const int width = 30, filled = static_cast<int>(f * width);
    char line[200];
    const long e = std::lround(eta);
    std::snprintf(line, sizeof line, "\r[%s%s] %5.1f%% %lld/%lld  %.3g/s  ETA %ld:%02ld:%02ld  failures %lld ",
                  std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), 100 * f,
                  static_cast<long long>(t.done), static_cast<long long>(total_), rate, e / 3600, e / 60 % 60,
                  e % 60, static_cast<long long>(t.failures()));
    err_ << line << (final ? "\n" : "") << std::flush;
  }

 private:
  std::string mode_;
  std::ostream& err_;
  std::int64_t total_;
  Clock::time_point t0_ = Clock::now();
  double last_ = -1e9;
};

// The rows committed by this run, with the progress line: each writer adds
// the rows of its commits (a worker thread's, or another rank's reported
// counts), so that the tally and the progress stay one.
class Committed {
 public:
  Committed(Tally& tally, Progress& progress, std::int64_t pending)
      : tally_(tally), progress_(progress), pending_(pending) {}
  void add(std::span<const Row> rows) {
    std::lock_guard lock(m_);
    for (std::size_t i = 0, j; i < rows.size(); i = j) {  // one map lookup per run of a status
      for (j = i + 1; j < rows.size() && rows[j].status == rows[i].status;) ++j;
      count(rows[i].status, static_cast<std::int64_t>(j - i));
    }
    progress_.update(tally_, pending_, false);
  }
  void add(const StatusCounts& counts) {
    std::lock_guard lock(m_);
    for (const auto& [status, n] : counts) count(status, n);
    progress_.update(tally_, pending_, false);
  }

 private:
  void count(std::string_view status, std::int64_t n) {
    tally_.done += n;
    tally_.evaluated += n;
    tally_.statuses[std::string(status)] += n;
  }
  Tally& tally_;
  Progress& progress_;
  std::int64_t pending_;
  std::mutex m_;
};

}  // namespace opt::doe
