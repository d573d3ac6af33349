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

// One writer at a time: rows from the workers go to the store in batched
// transactions, committed by whichever thread finds a batch due while no
// other thread commits. A batch is due as soon as kBatchRows rows are
// queued and the store is free (or 0.25 s has passed since the last commit,
// or the run closes): a group commit, so the store never idles while rows wait
// and a batch grows with the rows that queue during the commit before it;
// where the store limits the run one thread ends up committing back to back
// while the others evaluate. (Waiting for 20 000 rows left the store idle,
// then behind: the conveyor's last commits, up to 30 ms, ran after every
// evaluation had ended.) No thread of its own: --threads N runs N threads
// in all, each evaluating and taking its turn at the store, so N threads
// use N cores.
// Under MPI, rank 0 gives the writer a thread of its own (`own_thread`):
// its serving loop queues every other rank's rows and must never wait for
// a commit while ranks wait for their next chunk.
class Writer {
 public:
  Writer(Store& store, Tally& tally, Progress& progress, std::int64_t pending, bool own_thread = false)
      : store_(store), tally_(tally), progress_(progress), pending_(pending), own_thread_(own_thread) {
    if (own_thread_) thread_ = std::thread([this] { run(); });
  }
  ~Writer() {
    try {
      close();
    } catch (...) {  // an unwinding run: its own error is the one to report
    }
  }

  // Queues rows and commits the queue if a batch is due. Blocks while too
  // many rows wait for another thread's commit (memory stays constant in N).
  void push(std::vector<Row> rows) {
    std::unique_lock lock(m_);
    room_.wait(lock, [&] { return queued_ < kMaxQueued || (!writing_ && !own_thread_) || failed_; });
    queued_ += rows.size();
    queue_.push_back(std::move(rows));
    if (own_thread_) return ready_.notify_one();
    commit_due(lock);
  }

  // Commits what is queued (the workers have stopped); rethrows the error of
  // any commit, if one failed.
  void close() {
    {
      std::lock_guard lock(m_);
      closing_ = true;
      ready_.notify_one();
    }
    if (thread_.joinable()) thread_.join();
    std::unique_lock lock(m_);
    room_.wait(lock, [&] { return !writing_; });
    commit_due(lock);
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }

  // Commits the queue now unless another thread commits: a worker that
  // finds no more work, so that the rows of the last chunks are not left
  // for one commit after every worker has stopped.
  void flush() {
    std::unique_lock lock(m_);
    if (own_thread_) return ready_.notify_one();
    commit_due(lock, true);
  }

  bool failed() const { return failed_; }

  // Swaps a committed batch's rows, if one is spare, into `stock` (a
  // worker's, empty): evaluated into again, their vectors need no memory.
  // Before, each sample's row was two mallocs in the thread that evaluated
  // it and two frees in the one that committed it, into the first one's
  // arena: on two threads the allocator's locks and lists moved between
  // the cores with every row (a conveyor design took 1.09 us on two threads
  // against 1.04 on one; now 1.04 and 1.01). Measured, interleaved A/B
  // medians: conveyor 1 thread +6.5%, 2 threads +11%; recuperative 2
  // threads +12%; callgrind, the conveyor DOE's worker: -950 instructions
  // a row (-5.5%).
  void take_spare(std::vector<Row>& stock) {
    std::lock_guard lock(m_);
    stock.swap(spare_);
  }

 private:
  // A commit rewrites its last, partly filled 64 KiB pages: at 20 columns
  // 4096-row transactions run as fast as 20 000-row ones, 1000-row ones at
  // 65-85% of it (bench_doe_store BM_Append/12/ROWS).
  static constexpr size_t kBatchRows = 4096, kMaxQueued = 200000;

  // The own thread: commits what is due, and progress, at least every 0.1 s.
  void run() {
    std::unique_lock lock(m_);
    while (!failed_ && !(closing_ && queue_.empty())) {
      ready_.wait_for(lock, std::chrono::milliseconds(100), [&] { return closing_ || queued_ >= kBatchRows; });
      commit_due(lock);
    }
  }

  // With m_ held: while a batch is due (or `now`) and no thread commits,
  // this one commits the whole queue (m_ released meanwhile); then progress.
  void commit_due(std::unique_lock<std::mutex>& lock, bool now = false) {
    while (!writing_ && !failed_ && !queue_.empty() &&
           (now || closing_ || queued_ >= kBatchRows || since(last_) >= 0.25)) {
      writing_ = true;
      batch_.reserve(queued_);  // once: the spent batch took its storage along
      for (auto& rows : queue_) std::move(rows.begin(), rows.end(), std::back_inserter(batch_));
      queue_.clear();
      queued_ = 0;
      room_.notify_all();
      lock.unlock();
      try {
        store_.append(batch_);
      } catch (...) {
        lock.lock();
        error_ = std::current_exception();
        failed_ = true;
        writing_ = false;
        batch_.clear();
        room_.notify_all();
        return;
      }
      lock.lock();
      tally_.done += static_cast<std::int64_t>(batch_.size());
      tally_.evaluated += static_cast<std::int64_t>(batch_.size());
      for (std::size_t i = 0, j; i < batch_.size(); i = j) {  // one map lookup per run of a status
        for (j = i + 1; j < batch_.size() && batch_[j].status == batch_[i].status;) ++j;
        tally_.statuses[std::string(batch_[i].status)] += static_cast<std::int64_t>(j - i);
      }
      std::vector<Row> spent;
      spent.swap(batch_);
      if (spare_.empty()) spare_.swap(spent);  // for take_spare
      last_ = Clock::now();
      writing_ = false;
      room_.notify_all();
      lock.unlock();
      spent = {};  // (when a batch was still spare) freed while another thread may commit
      lock.lock();
    }
    if (!writing_) progress_.update(tally_, pending_, false);  // the tally is still while no thread commits
  }

  Store& store_;
  Tally& tally_;
  Progress& progress_;
  std::int64_t pending_;
  const bool own_thread_;
  std::mutex m_;
  std::condition_variable room_;   // the queue has room, or a commit ended
  std::condition_variable ready_;  // for the own thread: a batch may be due
  std::deque<std::vector<Row>> queue_;
  std::vector<Row> batch_;  // the rows being committed (by the thread with writing_)
  std::vector<Row> spare_;  // a committed batch's rows, for take_spare
  size_t queued_ = 0;
  Clock::time_point last_ = Clock::now();
  bool writing_ = false, closing_ = false;
  std::atomic<bool> failed_{false};
  std::exception_ptr error_;
  std::thread thread_;  // declared last: started once the rest is ready
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
// in the temporary directory (removed). Threads pay it in turns, so a run
// of r samples takes about r max((e + w) / threads, w).
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
  const double seconds = static_cast<double>(rest) * std::max((per + store) / threads, store),
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
  if (o.peers && o.peers->rank() > 0) {  // an MPI worker: chunks from rank 0, rows back to it
    std::vector<bool> finished(static_cast<size_t>(n));
    o.peers->share(finished);
    std::vector<SampleMaker> makers_of(static_cast<size_t>(threads));
    for (auto& m : makers_of) m = maker();
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
      want = next_chunk(since(c0), end - begin, threads);
      return rows;
    });
    j["rank"] = o.peers->rank();
    return j;
  }

  const nlohmann::json canonical = canonical_run(base, spec, *sampler);
  const std::map<std::string, std::string> meta = {
      {"config", config.dump(2)},          {"config_canonical", canonical.dump()},
      {"config_hash", config_hash(canonical)}, {"problem", base.name()},
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
  Store store(o.output_directory, layout, meta, o.fresh);  // first: a store another run writes is refused
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
    Writer writer(store, tally, progress, pending, o.peers != nullptr);
    std::atomic<std::int64_t> next{lo};
    std::exception_ptr worker_error;
    std::mutex error_m;
    auto work = [&] {
      try {
        const SampleMaker m = maker();
        std::int64_t chunk = 1;
        std::vector<Row> stock;  // rows to evaluate into (Writer::take_spare)
        while (!stop_requested() && !writer.failed()) {
          const std::int64_t begin = next.fetch_add(chunk), end = std::min(hi, begin + chunk);
          if (begin >= hi) return writer.flush();
          std::vector<Row> rows;
          rows.reserve(static_cast<std::size_t>(end - begin));
          if (stock.empty()) writer.take_spare(stock);
          const auto c0 = Clock::now();
          for (std::int64_t i = begin; i < end && !stop_requested(); ++i) {
            if (finished[static_cast<size_t>(i)]) continue;
            rows.emplace_back();
            if (!stock.empty()) {
              rows.back() = std::move(stock.back());
              stock.pop_back();
            }
            evaluator.evaluate(m, i, rows.back());
          }
          // Guided toward the end: at most a quarter of each thread's share
          // of what is left, so the threads finish together.
          chunk = std::min(next_chunk(since(c0), end - begin, 1),
                           std::max<std::int64_t>(1, (hi - next.load()) / (4 * threads)));
          if (!rows.empty()) writer.push(std::move(rows));
        }
      } catch (...) {
        std::lock_guard lock(error_m);
        if (!worker_error) worker_error = std::current_exception();
        request_stop();
      }
    };
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(work);
    if (o.peers)  // this thread serves the other ranks
      o.peers->serve(next, hi, [&](std::vector<Row> rows) { writer.push(std::move(rows)); },
                     [&] { return stop_requested() || writer.failed(); });
    for (auto& t : pool) t.join();
    writer.close();
    if (worker_error) std::rethrow_exception(worker_error);
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
      << tally.evaluated << " evaluated in " << seconds << " s (" << j["rate"].get<double>() << "/s)\n";
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
