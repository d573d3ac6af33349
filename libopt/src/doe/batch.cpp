// The batch runner (docs/doe.md): worker threads take chunks of sample
// indices from one atomic counter, evaluate them on their own workspace and
// queue the rows; one of them at a time commits the queue to the store in a
// batched transaction and reports progress. Only samples the store does not
// hold are evaluated, so running the same command again resumes exactly.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <thread>

#include "mech/deadline.hpp"
#include "opt/doe/batch.hpp"
#include "opt/doe/store.hpp"
#include "opt/interrupt.hpp"
#include "opt/record.hpp"
#include "doe/evaluator.hpp"

namespace opt::doe {
namespace {

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

// A segment's name for thread `thread` of rank `rank` (thread -1: the
// rank's own, under MPI, written by its main thread) and its `part`-th file, numbered so that the
// names sort in the order of the ranges (the order the fold appends them in).
std::string segment_name(int rank, int thread, int part = 0) {
  char name[48];
  if (thread < 0) std::snprintf(name, sizeof name, "r%05d-p%06d", rank, part);
  else std::snprintf(name, sizeof name, "r%05d-t%04d-p%06d", rank, thread, part);
  return name;
}

// The segments the other threads have closed, which the run's first thread
// folds into store.sqlite between its own commits while the run goes
// (docs/doe.md, "Segments"): the run then takes about the longer of its
// evaluation and its fold rather than their sum, with no thread of its own
// and no second writer of store.sqlite. Work stealing between the ranges
// hands the first thread's samples to the others while it folds.
class Folder {
 public:
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
      store.fold(file);
    }
  }

 private:
  std::mutex m_;
  std::deque<std::string> files_;
};

// The rows of one worker thread, committed in batches to a file of its own
// (docs/doe.md, "Segments"): the first thread's into store.sqlite, whose
// only writer it is (it also folds what the folder holds after each
// commit), every other's into segments, each closed at `segment_rows` rows
// and handed to the folder. No lock is shared between the writers, so the
// write path scales with them. A batch is due at kBatchRows rows or 0.25 s
// after the last commit (a slow model's rows do not wait long: a kill loses
// at most what is uncommitted), and at the end. The rows' vectors are
// evaluated into again after their commit, so a sample costs no allocation
// and no thread frees what another allocated.
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
  // A row to evaluate into: the next one of the batch.
  Row& next() {
    if (used_ == rows_.size()) rows_.emplace_back();
    return rows_[used_++];
  }
  void commit_if_due() {
    if (used_ >= kBatchRows || (used_ > 0 && since(last_) >= 0.25)) commit();
    if (thread_ == 0) folder_->fold(store_);
  }
  void commit() {
    if (used_ == 0) return;
    const std::span<const Row> rows(rows_.data(), used_);
    if (thread_ == 0) {
      store_.append(rows);
    } else {
      if (!segment_) segment_ = store_.segment(segment_name(0, thread_, part_++));  // no rows, no file
      segment_->append(rows);
      in_segment_ += used_;
    }
    committed_.add(rows);
    used_ = 0;
    last_ = Clock::now();
    if (in_segment_ >= segment_rows_) close();
  }
  // Commits what is left and hands the open segment to the folder.
  void close() {
    commit();
    if (!segment_) return;
    const std::string file = segment_->path();
    segment_.reset();
    in_segment_ = 0;
    folder_->hand(file);
  }

 private:
  // A commit rewrites its last, partly filled 64 KiB pages: at 20 columns
  // 4096-row transactions run as fast as 20 000-row ones, 1000-row ones at
  // 65-85% of it (bench_doe_store BM_Append/12/ROWS).
  static constexpr std::size_t kBatchRows = 4096;
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

// The samples [lo, hi) as one contiguous range per taker (a thread of this
// process, or under MPI another rank): each takes chunks from the front of
// its own, and one whose range is spent steals the back half of the largest
// range left. Each writer's rows are then few long runs of indices, so that
// the fold appends them to the store's B-tree instead of inserting them
// between another writer's: 1.4-1.6x faster (bench_doe_store, BM_Fold/0
// against BM_Fold/1, which interleaves two writers in chunks of 4096 as one
// shared counter did).
class Ranges {
 public:
  Ranges(std::int64_t lo, std::int64_t hi, int takers) : ranges_(static_cast<std::size_t>(takers)) {
    for (int k = 0; k < takers; ++k) {
      ranges_[std::size_t(k)].begin = lo + (hi - lo) * k / takers;
      ranges_[std::size_t(k)].end = lo + (hi - lo) * (k + 1) / takers;
    }
  }
  // The next chunk, of up to `want` indices, for taker k: [begin, end), empty when every range is spent.
  std::pair<std::int64_t, std::int64_t> take(int k, std::int64_t want) {
    Range& own = ranges_[std::size_t(k)];
    for (;;) {
      {
        std::lock_guard lock(own.m);
        if (own.begin < own.end) {
          const std::int64_t begin = own.begin;
          own.begin = std::min(own.end, begin + std::max<std::int64_t>(want, 1));
          return {begin, own.begin};
        }
      }
      Range* victim = nullptr;
      std::int64_t most = 0;
      for (Range& r : ranges_) {
        std::lock_guard lock(r.m);
        if (r.end - r.begin > most) most = r.end - r.begin, victim = &r;
      }
      if (!victim) return {0, 0};
      std::int64_t begin, end;
      {
        std::lock_guard lock(victim->m);
        const std::int64_t left = victim->end - victim->begin;
        if (left <= 0) continue;  // spent meanwhile: look again
        end = victim->end;
        begin = victim->end -= (left + 1) / 2;
      }
      std::lock_guard lock(own.m);
      own.begin = begin, own.end = end;
    }
  }

 private:
  struct Range {
    std::mutex m;
    std::int64_t begin = 0, end = 0;
  };
  std::vector<Range> ranges_;
};

// The next chunk's size after `count` samples took `seconds` on `threads`
// threads: ~50 ms of work, few enough requests to keep the counter (or rank
// 0) cold, small enough that slow samples do not idle the others.
std::int64_t next_chunk(double seconds, std::int64_t count, int threads) {
  const double per = seconds / static_cast<double>(std::max<std::int64_t>(1, count));
  return std::clamp<std::int64_t>(static_cast<std::int64_t>(0.05 * threads / std::max(per, 1e-9)), 1, 4096);
}

std::string hex64(std::uint64_t v) {
  char s[17];
  std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(v));
  return s;
}

std::string now_text() {
  const std::time_t t = std::time(nullptr);
  char s[32];
  std::strftime(s, sizeof s, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return s;
}

}  // namespace

nlohmann::json canonical_run(const Problem& problem, const DoeSpec& spec, const Sampler& sampler) {
  nlohmann::json j = problem.record();
  if (!j.is_object()) j = {{"settings", j}};
  j["problem"] = problem.name();
  j["sampler"] = sampler.describe();
  j["factors"] = nlohmann::json::array();
  for (const auto& f : spec.factors) {
    const Factor& x = f.factor;
    j["factors"].push_back({{"name", x.name}, {"kind", static_cast<int>(x.kind)}, {"lower", x.lower},
                            {"upper", x.upper}, {"count", x.count}, {"levels", x.levels}, {"labels", x.labels}});
  }
  if (!spec.rows.empty()) j["points"] = spec.rows;
  if (!spec.columns.empty()) j["metrics"] = stored_metrics(spec, problem);  // what a row holds
  return j;
}

std::string config_hash(const nlohmann::json& canonical) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a, 64 bits: stable across builds and machines
  for (const unsigned char c : canonical.dump()) h = (h ^ c) * 1099511628211ull;
  return hex64(h);
}

// "42 s", "13.5 min", "2.25 h".
std::string duration_text(double seconds) {
  char text[32];
  if (seconds < 120) std::snprintf(text, sizeof text, "%.3g s", seconds);
  else if (seconds < 7200) std::snprintf(text, sizeof text, "%.3g min", seconds / 60);
  else std::snprintf(text, sizeof text, "%.3g h", seconds / 3600);
  return text;
}

// The store's seconds a row: the pilot's rows appended to a scratch store
// in the temporary directory (removed). Each thread pays it for its own rows,
// and the fold once more for the rows of all threads but the first (a fold
// appends a row in less than an append's time: BM_Fold/0 against BM_Append),
// so a run of r samples on T threads takes at most about
// r (e + w) / T + r w (T - 1) / T.
double store_seconds_per_row(const StoreLayout& layout, const std::map<std::string, std::string>& meta,
                             std::span<const Row> rows) {
  namespace fs = std::filesystem;
  if (rows.empty()) return 0;
  const fs::path dir = fs::temp_directory_path() / ("mechopt-dry-run-" + std::to_string(getpid()));
  fs::remove_all(dir);
  double seconds = 0;
  try {
    Store scratch(dir.string(), layout, meta, false);
    const auto t0 = Clock::now();
    scratch.append(rows);
    seconds = since(t0);
  } catch (...) {
    fs::remove_all(dir);
    throw;
  }
  fs::remove_all(dir);
  return seconds / static_cast<double>(rows.size());
}

// --dry-run: the samples the store already holds (read only; a store of
// another config is refused as a real run would refuse it), the time a pilot
// of a few samples predicts for the rest (their evaluation and their rows in
// a scratch store), and the store's size from the pilot rows' record sizes.
// Nothing is written to the output directory.
nlohmann::json dry_run(const Evaluator& evaluator, const SampleMaker& maker, const StoreLayout& layout,
                       const std::map<std::string, std::string>& meta, std::int64_t lo, std::int64_t hi, int threads,
                       const BatchOptions& o, std::ostream& out) {
  const std::int64_t total = std::stoll(meta.at("samples"));
  std::int64_t stored = 0;
  if (!o.fresh)
    if (const auto done = Store::peek(o.output_directory, layout, meta, total))
      for (std::int64_t i = lo; i < hi; ++i) stored += (*done)[static_cast<std::size_t>(i)];
  // The pilot: the first samples of the range for up to 0.2 s (at most
  // 4096), after one untimed sample that pays for first-use costs.
  const std::int64_t rest = hi - lo - stored;
  double bytes_per_row = 0;
  std::vector<Row> rows;
  if (hi > lo) rows.push_back(evaluator.evaluate(maker, lo));
  const auto t0 = Clock::now();
  while (lo + static_cast<std::int64_t>(rows.size()) < hi && rows.size() <= 4096 && since(t0) < 0.2)
    rows.push_back(evaluator.evaluate(maker, lo + static_cast<std::int64_t>(rows.size())));
  const auto pilot = static_cast<std::int64_t>(rows.size()) - (hi > lo);  // timed: all but the first
  const double per = pilot ? since(t0) / static_cast<double>(pilot) : 0;
  for (const Row& r : rows) bytes_per_row += row_bytes(r, layout);
  bytes_per_row /= static_cast<double>(std::max<std::size_t>(1, rows.size()));
  const double store = store_seconds_per_row(layout, meta, rows);
  const double seconds = static_cast<double>(rest) * ((per + store) / threads + store * (threads - 1) / threads),
               bytes = bytes_per_row * static_cast<double>(hi - lo);
  const bool needs_force = total > kMaxSamples && !o.force;
  const std::string shard = meta.at("shard");
  out << "dry run: " << hi - lo << " samples" << (o.shard.count > 1 ? " (shard " + shard + ")" : "") << ", "
      << stored << " already in " << o.output_directory << "/store.sqlite, " << rest << " to evaluate on " << threads
      << " threads\n  pilot: " << pilot << " samples, " << per * 1e6 << " us each, and " << store * 1e6
      << " us a row in the store\n  estimated time: "
      << duration_text(seconds) << "\n  estimated store size: " << bytes / 1e6 << " MB (" << bytes_per_row
      << " bytes a row)\n";
  if (needs_force) out << "  more than " << kMaxSamples << " samples: run with --force to go ahead\n";
  return {{"samples", hi - lo}, {"stored", stored}, {"to_evaluate", rest}, {"pilot_samples", pilot},
          {"seconds_per_sample", per}, {"store_seconds_per_row", store}, {"estimated_seconds", seconds}, {"estimated_store_bytes", bytes},
          {"bytes_per_row", bytes_per_row}, {"needs_force", needs_force}};
}

nlohmann::json run_samples(const Problem& base, const std::function<SampleMaker()>& makers, const DoeSpec& spec,
                           const BatchOptions& o, const nlohmann::json& config, std::ostream& printed,
                           std::ostream& err) {
  std::ostream none(nullptr);  // discards what a quiet run would print
  std::ostream& out = o.quiet ? none : printed;
  const auto sampler = make_sampler(spec);
  const std::int64_t n = sampler->size();
  if (n > kMaxSamples && !o.force && !o.dry_run)  // parse_doe says where (this guards other callers)
    throw ConfigError("study: " + std::to_string(n) + " samples is more than " + std::to_string(kMaxSamples) +
                      "; run with --force to go ahead");
  const std::int64_t lo = n * o.shard.index / o.shard.count, hi = n * (o.shard.index + 1) / o.shard.count;
  // All cores by default; one thread per rank under MPI (ranks fill the cores).
  const int threads = o.threads > 0 ? o.threads
                      : o.peers     ? 1
                                    : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const std::vector<std::string> metrics = stored_metrics(spec, base);
  const Evaluator evaluator(base, spec, *sampler);
  auto maker = [&] { return evaluator.model_factors() ? makers() : SampleMaker(); };

  StoreLayout layout;
  for (const auto& f : spec.factors) {
    layout.factors.push_back(f.factor.name);
    layout.labels.push_back(f.factor.labels);
  }
  for (const auto& m : metrics) layout.metrics.push_back(metric_column(spec, m));
  const std::string shard = std::to_string(o.shard.index) + "/" + std::to_string(o.shard.count);
  nlohmann::json j = {{"mechopt_version", MECHOPT_VERSION}, {"problem", base.name()}, {"study", "doe"},
                      {"sampler", sampler->describe()}, {"samples", n}, {"shard", shard},
                      {"threads", threads}, {"ranks", o.peers ? o.peers->size() : 1},
                      {"settings", base.record()}};

  if (o.dry_run && o.peers && o.peers->rank() > 0) return j;  // rank 0 says what the run would take
  const nlohmann::json canonical = canonical_run(base, spec, *sampler);
  const std::string hash = config_hash(canonical);
  if (o.peers && o.peers->rank() > 0) {  // an MPI worker: chunks from rank 0, rows into a segment of its own
    std::vector<bool> finished(static_cast<size_t>(n));
    o.peers->share(finished);
    std::vector<SampleMaker> makers_of(static_cast<size_t>(threads));
    for (auto& m : makers_of) m = maker();
    std::optional<Segment> segment;
    std::int64_t closed = 0;      // segment files closed, for rank 0 to fold
    std::size_t in_segment = 0;  // rows in the open one
    o.peers->work([&](std::int64_t begin, std::int64_t end, std::int64_t& want) {
      const auto c0 = Clock::now();
      std::vector<std::vector<Row>> parts(static_cast<size_t>(threads));
      auto part = [&](int t) {  // every threads-th index from begin + t
        for (std::int64_t i = begin + t; i < end && !stop_requested(); i += threads)
          if (!finished[static_cast<size_t>(i)]) parts[static_cast<size_t>(t)].push_back(evaluator.evaluate(makers_of[static_cast<size_t>(t)], i));
      };
      std::vector<std::thread> pool;
      for (int t = 1; t < threads; ++t) pool.emplace_back(part, t);
      part(0);
      for (auto& t : pool) t.join();
      std::vector<Row> rows;
      for (auto& p : parts) std::move(p.begin(), p.end(), std::back_inserter(rows));
      Report report;
      if (!rows.empty()) {  // committed before rank 0 hears of them
        if (!segment)
          segment.emplace(o.output_directory, segment_name(o.peers->rank(), -1, int(closed)), layout, hash);
        segment->append(rows);
        for (const Row& r : rows) ++report.committed[std::string(r.status)];
        if ((in_segment += rows.size()) >= o.segment_rows) {
          segment.reset();  // closed (its log checkpointed into the file): rank 0 may fold it
          ++closed;
          in_segment = 0;
        }
      }
      report.closed = closed;
      want = next_chunk(since(c0), end - begin, threads);
      return report;
    });
    segment.reset();      // closed before rank 0 folds it at the end
    o.peers->barrier();
    j["rank"] = o.peers->rank();
    return j;
  }

  const std::map<std::string, std::string> meta = {
      {"config", config.dump(2)},          {"config_canonical", canonical.dump()},
      {"config_hash", hash},                   {"problem", base.name()},
      {"sampler", sampler->describe().dump()}, {"seed", spec.seed ? std::to_string(*spec.seed) : ""},
      {"samples", std::to_string(n)},          {"mechopt_version", MECHOPT_VERSION},
      {"shard", shard},                        {"started", now_text()}};
  if (o.dry_run) {
    j["dry_run"] = dry_run(evaluator, maker(), layout, meta, lo, hi, threads, o, out);
    return j;
  }

  namespace fs = std::filesystem;
  fs::create_directories(o.output_directory);
  const std::string dir = o.output_directory + "/";
  // First: a store another run writes is refused. A killed run's segments are folded.
  Store store(o.output_directory, layout, meta, o.fresh);
  remove_previous_outputs(dir);                              // before anything of that run's is removed
  const auto index_t0 = Clock::now();
  std::vector<bool> finished = store.finished(n);
  j["index_seconds"] = since(index_t0);  // reading which samples are done
  if (o.peers) o.peers->share(finished);
  Tally tally;
  for (std::int64_t i = lo; i < hi; ++i) tally.done += finished[static_cast<size_t>(i)];
  const std::int64_t pending = hi - lo - tally.done;
  out << "mechopt " << MECHOPT_VERSION << " — " << base.name() << ", doe (" << spec.sampler << ", " << n
      << " samples" << (o.shard.count > 1 ? ", shard " + shard : "") << ")\n"
      << "store: " << store.path() << (tally.done ? " (resuming: " + std::to_string(tally.done) + " done)" : "")
      << "\n" << pending << " samples to evaluate on " << threads << " threads\n" << std::flush;

  const std::string mode = o.progress != "auto" ? o.progress : isatty(STDERR_FILENO) ? "bar" : "jsonl";
  Progress progress(mode, err, hi - lo);
  const auto t0 = Clock::now();
  {
    Committed committed(tally, progress, pending);
    Folder folder;
    std::atomic<int> working{threads};  // the workers not yet done
    Ranges ranges(lo, hi, threads + (o.peers ? o.peers->size() - 1 : 0));  // under MPI: rank k takes threads + k - 1
    std::exception_ptr worker_error;
    std::mutex error_m;
    auto work = [&](int t) {
      try {
        const SampleMaker m = maker();
        RowWriter writer(store, &folder, t, o.segment_rows, committed);
        std::int64_t chunk = 1;
        while (!stop_requested()) {
          const auto [begin, end] = ranges.take(t, chunk);
          if (begin == end) break;
          const auto c0 = Clock::now();
          for (std::int64_t i = begin; i < end && !stop_requested(); ++i)
            if (!finished[static_cast<size_t>(i)]) evaluator.evaluate(m, i, writer.next());
          chunk = next_chunk(since(c0), end - begin, 1);
          writer.commit_if_due();
        }
        writer.close();
        --working;
        // The first thread folds until the others are done.
        for (bool last = false; t == 0 && !last && !stop_requested();) {
          last = working.load() == 0;
          folder.fold(store);
          if (!last) std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
      } catch (...) {
        std::lock_guard lock(error_m);
        if (!worker_error) worker_error = std::current_exception();
        request_stop();
      }
    };
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(work, t);
    if (o.peers) {  // this thread serves the other ranks
      std::vector<std::int64_t> handed(std::size_t(o.peers->size()), 0);  // their closed segments, to the folder
      o.peers->serve([&](int rank, std::int64_t want) { return ranges.take(threads + rank - 1, want); },
                     [&](int rank, const Report& report) {
                       committed.add(report.committed);
                       for (auto& k = handed[std::size_t(rank)]; k < report.closed; ++k)
                         folder.hand(segment_path(o.output_directory, segment_name(rank, -1, int(k))));
                     },
                     [] { return stop_requested(); });
    }
    for (auto& t : pool) t.join();
    if (o.peers) o.peers->barrier();  // every rank's segment closed
    if (worker_error) std::rethrow_exception(worker_error);
    const auto fold_t0 = Clock::now();
    store.fold();  // what the first thread left, and the other ranks' segments
    j["fold_seconds"] = since(fold_t0);  // the fold's time after the evaluation
  }
  progress.update(tally, pending, true);
  const double seconds = since(t0);
  const bool complete = tally.done == hi - lo;
  if (complete) store.set_meta("finished", now_text());
  j["run_status"] = complete ? "complete" : "interrupted";
  j["store"] = store.path();
  j["done"] = tally.done;
  j["evaluated"] = tally.evaluated;
  j["seconds"] = seconds;
  j["rate"] = seconds > 0 ? static_cast<double>(tally.evaluated) / seconds : 0.0;
  j["statuses"] = tally.statuses;
  out << (complete ? "complete: " : "interrupted: ") << tally.done << "/" << hi - lo << " samples in the store; "
      << tally.evaluated << " evaluated in " << seconds << " s (" << j["rate"].get<double>() << "/s; the fold "
      << j["fold_seconds"].get<double>() << " s of it)\n";
  if (o.quiet) return j;
  // The summary covers every row in the store, this run's and earlier ones'.
  std::vector<std::string> summarised = spec.columns;
  if (summarised.empty() && !spec.objective.metric.empty()) summarised.push_back(spec.objective.metric);
  if (spec.columns.empty())
    for (const auto& c : spec.constraints)
      if (std::find(summarised.begin(), summarised.end(), c.metric) == summarised.end()) summarised.push_back(c.metric);
  if (summarised.empty()) summarised = metrics;
  std::vector<std::string> charts;
  j["summary"] = summarize(store.path(), spec, summarised, base, dir, out, charts);
  j["charts"] = charts;
  if (spec.refine_best > 0 && complete && o.shard.count == 1)
    j["refine"] = refine(evaluator, maker(), spec, store.path(), out);
  else if (spec.refine_best > 0)
    out << "refine: not yet: " << (complete ? "a shard refines nothing; run the config on the merged store"
                                            : "the samples are not all done") << "\n";
  write_file_atomically(dir + "result.json", j.dump(2) + "\n");
  out << "written: " << dir << "result.json, " << store.path();
  for (const auto& c : charts) out << ", " << std::filesystem::path(c).filename().string();
  out << "\n";
  return j;
}

nlohmann::json run_batch(const ConfigNode& root, const ProblemFactory& make, const DoeSpec& spec,
                         const BatchOptions& o, std::ostream& out, std::ostream& err) {
  const ConfigNode run = run_root(root, spec);
  std::unique_ptr<Problem> base;
  try {
    base = make(run);
  } catch (const ConfigError& e) {
    // A factor set through x is a variable of the run's config, a key with no
    // line of its own: the problem's word on it goes to where the factor is written.
    const std::string what = e.what();
    for (const auto& f : spec.factors) {
      const std::string key = "key 'variables." + f.factor.name + "': ";
      const size_t at = what.find(key);
      if (!f.through_x || at == std::string::npos || (root.has("variables") && root.at("variables").has(f.factor.name)))
        continue;
      const ConfigNode st = root.at("study");
      const bool listed = st.has("factors") && st.at("factors").is_map() && st.at("factors").has(f.factor.name);
      (listed ? st.at("factors").at(f.factor.name) : st).fail(what.substr(at + key.size()));
    }
    throw;
  }
  if (spec.refine_best > 0) {  // the driver takes the problem, or the run stops before any sample
    const std::string why = driver_incompatibility(spec.refine_driver, *base, spec.objective, spec.constraints);
    const ConfigNode r = root.at("study").at("refine");
    if (!why.empty()) (r.has("driver") ? r.at("driver") : r).fail(why);
  }
  // Each thread reads its own copy of the config (yaml-cpp trees are not
  // shared between threads).
  const auto makers = [&]() -> SampleMaker {
    auto own = std::make_shared<const ConfigNode>(run.clone());
    return [own, &make](const YAML::Node& over, const std::string& name) { return make(own->with(over, name)); };
  };
  return run_samples(*base, makers, spec, o, root.to_json(), out, err);
}

}  // namespace opt::doe
