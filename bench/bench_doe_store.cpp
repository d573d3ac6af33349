// Throughput of the DOE results store (docs/doe.md, "The store"): rows/s of
// append() in 20 000-row batches, 4 factors and 4 to 60 metrics
// (BM_Append/METRICS/ROWS: rows/s against the column count, and at 12
// metrics against the rows a transaction), and the resume
// bitmap finished() over 10^6 rows. Targets: >= 300k rows/s at 12 metrics,
// finished(10^6) < 0.3 s, so the store never limits a batch run.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
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
