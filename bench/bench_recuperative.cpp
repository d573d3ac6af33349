// Speed of the recuperative drive: one cycle evaluation (value, value with
// gradient, all metrics) and one full rod-length optimisation. Each case puts
// the value it computed in a counter so bench/run_bench.py can measure its
// error against the high-precision reference (tools/reference_seed000.json).
#include <benchmark/benchmark.h>

#include <string>

#include <numbers>

#include "mech/twin_slider_crank.hpp"
#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "problems/recuperative_drive.hpp"

namespace {

constexpr double kPi = std::numbers::pi;
const mech::TwinDrive<double> kDrive{0.2, 0.8, kPi / 2, 0.0, 100 * kPi / 30, 1000, 80, 0.9, 3562};

void BM_MeanKineticEnergy(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  double v = 0;
  for (auto _ : state) {
    mech::TwinDrive<double> d = kDrive;
    benchmark::DoNotOptimize(d);
    v = mech::mean_kinetic_energy(d, n);
    benchmark::DoNotOptimize(v);
  }
  state.counters["value"] = v;
}
BENCHMARK(BM_MeanKineticEnergy)->Arg(8)->Arg(12)->Arg(16)->Arg(24)->Arg(28)->Arg(32);

void BM_MeanKineticEnergyGradient(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  mech::TwinDrive<mech::DualN<2>> d = kDrive.cast<mech::DualN<2>>();
  d.rod_length = mech::seed<2>(0.8, 0);
  d.phase_shift = mech::seed<2>(kPi / 2, 1);
  double v = 0, g = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(d);
    const auto m = mech::mean_kinetic_energy(d, n);
    v = m.value();
    g = m.derivatives()[0];
    benchmark::DoNotOptimize(m);
  }
  state.counters["value"] = v;
  state.counters["gradient"] = g;  // d T_cp / d rod_length
}
BENCHMARK(BM_MeanKineticEnergyGradient)->Arg(24)->Arg(28)->Arg(32);

void BM_CycleMetrics(benchmark::State& state) {
  double v = 0;
  for (auto _ : state) {
    mech::TwinDrive<double> d = kDrive;
    benchmark::DoNotOptimize(d);
    const auto m = mech::cycle_metrics(d, 32);
    v = m.peak_kinetic_energy;
    benchmark::DoNotOptimize(m);
  }
  state.counters["value"] = v;
}
BENCHMARK(BM_CycleMetrics);

// One objective evaluation with its gradient through the Problem interface
// (what a driver pays per evaluation: the model plus the interface's cost).
void BM_ProblemEvaluate(benchmark::State& state) {
  const auto p = problems::make_recuperative_drive(opt::ConfigNode::parse(
      "problem: recuperative_drive\nmodel: {cycle_points: 28}\n"
      "variables: {rod_length: {min: 0.5 m, max: 1.5 m}}\n", "<bench>"));
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 0.6);
  // Metrics by id, resolved once, as drivers do.
  const opt::MetricSet wanted = p->metric_set({"mean_kinetic_energy", "crank_rod_ratio"});
  const opt::MetricId mean = p->metric_id("mean_kinetic_energy");
  for (auto _ : state) {
    const auto e = p->evaluate(x, wanted, true);
    benchmark::DoNotOptimize(e);
  }
  // From one evaluation after the loop: Debian's Google Benchmark 1.7's
  // DoNotOptimize on a double in the loop left the counter garbage (GCC 12).
  state.counters["value"] = p->evaluate(x, wanted, true)[mean].value;
}
BENCHMARK(BM_ProblemEvaluate);

// The continuous optimum of Table 1's rod length (least mean kinetic energy),
// from the problem layer through the driver, as `mechopt run` does it.
void BM_RodLengthOptimum(benchmark::State& state, const char* algorithm) {
  const auto p = problems::make_recuperative_drive(opt::ConfigNode::parse(
      "problem: recuperative_drive\n"
      "variables: {rod_length: {min: 0.5 m, max: 1.5 m}}\n", "<bench>"));
  opt::DriverOptions o;
  if (std::string(algorithm) == "line") o.library = "line";  // Brent on the exact derivative
  else o.algorithm = algorithm;
  o.xtol_rel = 1e-12;
  o.record_history = false;
  const auto driver = opt::make_driver(o);
  opt::Result r;
  for (auto _ : state) {
    r = driver->minimize(*p, {"mean_kinetic_energy"}, {}, p->initial_point());
    benchmark::DoNotOptimize(r);
  }
  state.counters["value"] = r.x[0];
  state.counters["evaluations"] = r.evaluations;
}
BENCHMARK_CAPTURE(BM_RodLengthOptimum, LD_SLSQP, "LD_SLSQP")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RodLengthOptimum, LD_LBFGS, "LD_LBFGS")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RodLengthOptimum, LD_MMA, "LD_MMA")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RodLengthOptimum, LD_CCSAQ, "LD_CCSAQ")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RodLengthOptimum, LN_BOBYQA, "LN_BOBYQA")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RodLengthOptimum, LN_COBYLA, "LN_COBYLA")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RodLengthOptimum, line, "line")->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
