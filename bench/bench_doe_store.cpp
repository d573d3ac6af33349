// Throughput of the DOE results store (docs/doe.md, "The store" and
// "Segments"): rows/s of append() in 20 000-row batches, 4 factors and 4 to
// 60 metrics (BM_Append/METRICS/ROWS: rows/s against the column count, and at
// 12 metrics against the rows a transaction); N producer threads, each
// appending to a file of its own as a run's threads do (BM_Producers/N/0: the
// rows/s of all together, against BM_Producers/1/0; BM_Producers/2/1, two
// processes, the control); the fold of segments
// into the store (BM_Fold/INTERLEAVED: the segments' indices after the
// store's, or interleaved with them in chunks as a run's threads take them);
// `merge` of shard stores (BM_Merge); and the resume bitmap finished() over
// 10^6 rows. Targets: >= 300k rows/s at 12 metrics, producers at N times one
// producer's rate up to the cores, merge at no less than half of BM_Append,
// finished(10^6) < 0.3 s.
#include <benchmark/benchmark.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "opt/doe/store.hpp"

namespace {

namespace fs = std::filesystem;
constexpr std::int64_t kBatch = 20000;  // the writer's batch (docs/doe.md)

// A directory of its own, removed afterwards.
struct BenchDir {
  explicit BenchDir(const std::string& name)
      : path((fs::temp_directory_path() / ("bench_doe_store_" + name + "_" + std::to_string(getpid()))).string()) {
    fs::remove_all(path);
  }
  ~BenchDir() { fs::remove_all(path); }
  std::string path;
};

opt::doe::StoreLayout layout(int metrics) {
  opt::doe::StoreLayout l;
  l.factors = {"rod_length", "crank_radius", "mass.slider", "layout"};
  l.labels = {{}, {}, {}, {"inline", "offset"}};
  for (int m = 0; m < metrics; ++m) l.metrics.push_back("metric_" + std::to_string(m));
  return l;
}

opt::doe::Store store(const std::string& dir, int metrics = 12) {
  return opt::doe::Store(dir, layout(metrics), {{"config_hash", "bench"}}, false);
}

// Rows first, first+1, ..: values that vary, one failed design in ten.
std::vector<opt::doe::Row> batch(std::int64_t first, int metrics = 12, std::int64_t count = kBatch) {
  std::vector<opt::doe::Row> rows(static_cast<std::size_t>(count));
  for (std::int64_t k = 0; k < count; ++k) {
    auto& r = rows[std::size_t(k)];
    const double x = double(first + k);
    r.index = first + k;
    r.status = k % 10 ? "ok" : "cannot_assemble";
    r.wall_time = 1e-4 * (1 + k % 7);
    r.factors = {0.5 + 1e-6 * x, 0.1 + 1e-7 * x, 2.0 + 1e-5 * x, double(k % 2)};
    r.metrics.assign(std::size_t(metrics), k % 10 ? 1.0 / (1 + x) : NAN);
  }
  return rows;
}

// BM_Append/METRICS/ROWS: transactions of ROWS rows each.
void BM_Append(benchmark::State& state) {
  const int metrics = int(state.range(0));
  const std::int64_t count = state.range(1);
  BenchDir dir("append");
  auto s = store(dir.path, metrics);
  auto rows = batch(0, metrics, count);
  std::int64_t first = 0;
  for (auto _ : state) {
    for (std::int64_t k = 0; k < count; ++k) rows[std::size_t(k)].index = first + k;
    s.append(rows);
    first += count;
  }
  state.counters["rows_per_second"] = benchmark::Counter(double(first), benchmark::Counter::kIsRate);
  state.counters["columns"] = 8 + metrics;  // idx, status, wall_time, message, 4 factors
  state.counters["batch_rows"] = double(count);
}
// The column counts at 20 000-row batches; the batch sizes at 20 columns.
BENCHMARK(BM_Append)
    ->Args({4, kBatch})->Args({12, kBatch})->Args({28, kBatch})->Args({60, kBatch})
    ->Args({12, 100})->Args({12, 1000})->Args({12, 4096})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// Producer p's 4096-row batches of its own indices, appended for 0.2 s;
// returns its rows.
template <class Append>
std::int64_t produce(int p, std::int64_t& at, Append&& append) {
  constexpr std::int64_t kRows = 4096, kStride = std::int64_t(1) << 40;  // producer p: indices from p kStride
  auto b = batch(0, 12, kRows);
  std::int64_t made = 0;
  for (const auto t0 = std::chrono::steady_clock::now();
       std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(200); made += kRows, at += kRows) {
    for (std::int64_t k = 0; k < kRows; ++k) b[std::size_t(k)].index = p * kStride + at + k;
    append(b);
  }
  return made;
}

// BM_Producers/N/0: N threads of one process, each appending to a file of
// its own (the first to store.sqlite, the others to segments: a run's
// threads when store.sqlite is busy). BM_Producers/N/1, the control: N
// forked processes, each with a store of its own, which share nothing in a
// process: what the machine's cores give this work.
void BM_Producers(benchmark::State& state) {
  const int producers = int(state.range(0));
  const bool processes = state.range(1) != 0;
  BenchDir dir("producers");
  fs::create_directories(dir.path);
  std::vector<std::int64_t> first(std::size_t(producers), 0);
  std::int64_t rows = 0;
  if (processes) {
    for (auto _ : state) {
      std::vector<std::pair<pid_t, int>> children;  // pid, the read end of its pipe
      for (int p = 0; p < producers; ++p) {
        int fds[2];
        if (pipe(fds) != 0) throw std::runtime_error("pipe");
        const pid_t pid = fork();
        if (pid == 0) {
          close(fds[0]);
          fs::create_directories(dir.path + "/p" + std::to_string(p));
          auto s = store(dir.path + "/p" + std::to_string(p));
          const std::int64_t made = produce(p, first[std::size_t(p)], [&](const auto& b) { s.append(b); });
          _exit(write(fds[1], &made, sizeof made) == sizeof made ? 0 : 1);
        }
        close(fds[1]);
        children.push_back({pid, fds[0]});
      }
      for (const auto& [pid, fd] : children) {
        std::int64_t made = 0;
        if (read(fd, &made, sizeof made) == sizeof made) rows += made;
        close(fd);
        waitpid(pid, nullptr, 0);
      }
      // A child's indices went on in its own memory: the next round starts past them.
      for (auto& at : first) at += std::int64_t(1) << 30;
    }
  } else {
    auto s = store(dir.path);
    std::vector<opt::doe::Segment> segments;
    for (int p = 1; p < producers; ++p) segments.push_back(s.segment("bench-" + std::to_string(p)));
    for (auto _ : state) {
      std::vector<std::int64_t> made(std::size_t(producers), 0);
      std::vector<std::thread> threads;
      for (int p = 0; p < producers; ++p)
        threads.emplace_back([&, p] {
          made[std::size_t(p)] = produce(p, first[std::size_t(p)], [&](const auto& b) {
            p == 0 ? s.append(b) : segments[std::size_t(p - 1)].append(b);
          });
        });
      for (auto& t : threads) t.join();
      for (const auto m : made) rows += m;
    }
  }
  state.counters["rows_per_second"] = benchmark::Counter(double(rows), benchmark::Counter::kIsRate);
  state.counters["producers"] = producers;
}
BENCHMARK(BM_Producers)
    ->ArgsProduct({{1, 2, 3, 4}, {0}})->Args({2, 1})->Iterations(5)->Unit(benchmark::kMillisecond)->UseRealTime();

// BM_Fold/INTERLEAVED: 5*10^5 rows in the store and 5*10^5 in a segment,
// folded: INTERLEAVED 0, the segment's indices after the store's; 1, the
// two take turns in chunks of 4096 (a two-thread run).
void BM_Fold(benchmark::State& state) {
  constexpr std::int64_t kHalf = 500'000, kChunk = 4096;
  const bool interleaved = state.range(0) != 0;
  std::int64_t rows = 0;
  for (auto _ : state) {
    state.PauseTiming();
    BenchDir dir("fold");
    auto s = store(dir.path);
    {
      auto segment = s.segment("bench");
      for (std::int64_t c = 0; c < 2 * kHalf / kChunk; ++c) {
        const bool mine = interleaved ? c % 2 == 0 : c < kHalf / kChunk;
        const std::int64_t first = c * kChunk;
        mine ? s.append(batch(first, 12, kChunk)) : segment.append(batch(first, 12, kChunk));
      }
    }  // the segment closed, as its writer closes it
    state.ResumeTiming();
    rows += s.fold();
  }
  state.counters["rows_per_second"] = benchmark::Counter(double(rows), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Fold)->Arg(0)->Arg(1)->Iterations(3)->Unit(benchmark::kMillisecond)->UseRealTime();

// BM_FoldAlong/OVERLAP: a producer thread appends 16 segments of 65536 rows
// (a run's segment size) while this thread folds each one it closes
// (OVERLAP 1, as a run's first thread does), or folds them all after it
// (0): rows/s of the whole, the fold included. On two cores the overlap
// takes about the longer of the two, not their sum.
void BM_FoldAlong(benchmark::State& state) {
  constexpr int kSegments = 16;
  constexpr std::int64_t kRows = 65536, kChunk = 4096;
  const bool overlap = state.range(0) != 0;
  std::int64_t rows = 0;
  for (auto _ : state) {
    state.PauseTiming();
    BenchDir dir("fold_along");
    auto s = store(dir.path);
    auto chunk = batch(0, 12, kChunk);
    state.ResumeTiming();
    std::mutex m;
    std::vector<std::string> closed;
    std::atomic<bool> done{false};
    std::thread producer([&] {
      for (int k = 0; k < kSegments; ++k) {
        std::string file;
        {
          auto segment = s.segment("p" + std::to_string(100 + k));
          for (std::int64_t first = k * kRows; first < (k + 1) * kRows; first += kChunk) {
            for (std::int64_t j = 0; j < kChunk; ++j) chunk[std::size_t(j)].index = first + j;
            segment.append(chunk);
          }
          file = segment.path();
        }
        std::lock_guard lock(m);
        closed.push_back(file);
      }
      done = true;
    });
    for (std::size_t folded = 0; overlap && !(done && folded == closed.size());) {
      std::string file;
      {
        std::lock_guard lock(m);
        if (folded < closed.size()) file = closed[folded++];
      }
      if (file.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
      else rows += s.fold(file);
    }
    producer.join();
    rows += s.fold();
  }
  state.counters["rows_per_second"] = benchmark::Counter(double(rows), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FoldAlong)->Arg(0)->Arg(1)->Iterations(3)->Unit(benchmark::kMillisecond)->UseRealTime();

// BM_Merge: four shard stores of 250 000 rows each (12 metrics) merged into
// one, as `mechopt merge` does; against BM_Append/12/20000.
void BM_Merge(benchmark::State& state) {
  constexpr std::int64_t kShard = 250'000;
  BenchDir dir("merge");
  std::vector<std::string> shards;
  for (int k = 0; k < 4; ++k) {
    shards.push_back(dir.path + "/shard" + std::to_string(k));
    auto s = opt::doe::Store(shards.back(), layout(12), {{"config_hash", "bench"}, {"samples", std::to_string(4 * kShard)}},
                             false);
    for (std::int64_t first = k * kShard; first < (k + 1) * kShard; first += kBatch)
      s.append(batch(first, 12, std::min(kBatch, (k + 1) * kShard - first)));
  }
  std::int64_t rows = 0;
  for (auto _ : state) {
    state.PauseTiming();
    fs::remove_all(dir.path + "/out");
    state.ResumeTiming();
    rows += opt::doe::merge_stores(dir.path + "/out", shards).rows;
  }
  state.counters["rows_per_second"] = benchmark::Counter(double(rows), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Merge)->Iterations(3)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Finished(benchmark::State& state) {
  constexpr std::int64_t kRows = 1'000'000;
  BenchDir dir("finished");
  auto s = store(dir.path);
  for (std::int64_t first = 0; first < kRows; first += kBatch) s.append(batch(first));
  for (auto _ : state) benchmark::DoNotOptimize(s.finished(kRows));
}
BENCHMARK(BM_Finished)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
