// Speed of the conveyor swing mechanism (seed 002): one cycle evaluation (all
// swing metrics of variant 1) and one optimisation of the peak balancing
// moment under the pressure-angle limit. Counters carry the computed values
// for bench/run_bench.py to compare with tools/reference_seed002.json.
#include <benchmark/benchmark.h>

#include <numbers>

#include "mech/conveyor_swing.hpp"
#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "opt/drivers/nlopt.hpp"
#include "problems/conveyor_swing.hpp"

namespace {

constexpr double kDeg = std::numbers::pi / 180;

// range(0): grid points; range(1): 1 with the cycle means, 0 peaks only.
void BM_SwingMetrics(benchmark::State& state) {
  const auto k = mech::synthesize_crank_rocker<double>(1.0, 2.2, 1.2, 1.0, 0.0, 16 * kDeg).linkage;
  const mech::SwingMechanism<double> m{k, 12.0, 200.0, 3200.0, 3200 * 1.44, std::hypot(1.2, 1.0), 48.0};
  double v = 0;
  for (auto _ : state) {
    const auto r = mech::swing_metrics(m, static_cast<int>(state.range(0)), state.range(1) != 0);
    v = r.peak_moment;
    benchmark::DoNotOptimize(r);
  }
  state.counters["value"] = v;
}
// {grid points, all metrics}: the peak over grids from 8 to 192 points
// (work against precision), and every metric at 48.
BENCHMARK(BM_SwingMetrics)->Args({8, 0})->Args({12, 0})->Args({16, 0})->Args({24, 0})->Args({48, 0})->Args({96, 0})
    ->Args({192, 0})->Args({48, 1})->Unit(benchmark::kMicrosecond);

void BM_SwingOptimum(benchmark::State& state, const char* algorithm) {
  const auto p = problems::make_conveyor_swing(opt::ConfigNode::parse(
      "problem: conveyor_swing\nvariables: {l_co1: {min: 0.9 m, max: 2.4 m}}\n", "<bench>"));
  opt::DriverOptions o;
  o.algorithm = algorithm;
  o.xtol_rel = 1e-10;
  o.record_history = false;
  const std::vector<opt::Constraint> cons = {{"max_pressure_angle", true, 60 * kDeg}};
  const opt::NloptDriver driver(o);
  opt::Result r;
  for (auto _ : state) {
    r = driver.minimize(*p, {"peak_crank_torque"}, cons, p->initial_point());
    benchmark::DoNotOptimize(r);
  }
  state.counters["value"] = r.x[0];
  state.counters["evaluations"] = r.evaluations;
}
BENCHMARK_CAPTURE(BM_SwingOptimum, LD_SLSQP, "LD_SLSQP")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SwingOptimum, LN_COBYLA, "LN_COBYLA")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SwingOptimum, LD_MMA, "LD_MMA")->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
