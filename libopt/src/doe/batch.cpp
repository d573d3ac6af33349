// The batch runner (docs/doe.md): worker threads take chunks of sample
// indices from ranges of their own (writers.hpp), evaluate them on their
// own workspace and commit the rows to files of their own, which the first
// thread folds into the store as the run goes; under MPI rank 0 serves the
// other ranks' chunks. Only samples the store does not hold are evaluated,
// so running the same command again resumes exactly.
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
#include "doe/dry_run.hpp"
#include "doe/evaluator.hpp"
#include "doe/progress.hpp"
#include "doe/writers.hpp"

namespace opt::doe {
namespace {

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
    std::vector<Evaluator::Worker> workers(static_cast<size_t>(threads));
    std::optional<Segment> segment;
    std::int64_t closed = 0;      // segment files closed, for rank 0 to fold
    std::size_t in_segment = 0;  // rows in the open one
    o.peers->work([&](std::int64_t begin, std::int64_t end, std::int64_t& want) {
      const auto c0 = Clock::now();
      std::vector<std::vector<Row>> parts(static_cast<size_t>(threads));
      auto part = [&](int t) {  // every threads-th index from begin + t
        for (std::int64_t i = begin + t; i < end && !stop_requested(); i += threads)
          if (!finished[static_cast<size_t>(i)])
            evaluator.evaluate(makers_of[static_cast<size_t>(t)], i, parts[static_cast<size_t>(t)].emplace_back(),
                               workers[static_cast<size_t>(t)]);
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
        Evaluator::Worker worker;  // this thread's storage and workspace
        RowWriter writer(store, &folder, t, o.segment_rows, committed);
        std::int64_t chunk = 1;
        while (!stop_requested()) {
          const auto [begin, end] = ranges.take(t, chunk);
          if (begin == end) break;
          const auto c0 = Clock::now();
          for (std::int64_t i = begin; i < end && !stop_requested(); ++i)
            if (!finished[static_cast<size_t>(i)]) evaluator.evaluate(m, i, writer.next(), worker);
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
