// Speed of the two newest problems through the Problem interface (what
// `mechopt run` pays per evaluation), each case's computed value in a counter
// for bench/run_bench.py to compare with bench/reference_press_sawmill.json
// (printed by tests/ref/crank_press_ref.py and balanced_slider_crank_ref.py):
// - the crank press (seed 003), SM-816, Table 7.2 variant 1: the true peak
//   crankshaft torque over the pressing stroke, at both force fidelities;
// - the sawmill's cam-balanced slider-crank (seed 004), the paper's improved
//   mechanism: every metric, and the peak balancing torque alone;
// - the roller-forming machine (seed 003, exercise 6): every metric of the 24
//   variants of Table 6.1, the crank radii summed.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "opt/config.hpp"
#include "opt/registry.hpp"

namespace {

// range(0): 0 constant force (the final pressure), 1 the pressure law (7.2),
// both with the lever as a slider; 2 the pressure law with the exact
// four-bar lever (pivot on the crank pin's side).
std::unique_ptr<opt::Problem> press(int fidelity, int stroke_points = 64) {
  return opt::make_problem(opt::ConfigNode::parse(
      std::string("problem: crank_press\n"
                  "model: {press: SM-816, depth: 20 mm, pressure_factor: 0.035 MPa, bricks: 4,\n"
                  "        tabulated_angle: 120 deg, crank_speed: 20.7 rad/s, pressing_end: inner,\n"
                  "        ") +
          (fidelity == 2 ? "lever: four_bar, lever_pivot: same_side" : "lever: slider") +
          ", force: " + (fidelity == 0 ? "constant" : "pressure_law") +
          ", stroke_points: " + std::to_string(stroke_points) + "}\n",
      "<bench>"));
}

// Times one metric of p at its initial point, its value in the `value` counter.
void time_metric(benchmark::State& state, const opt::Problem& p, const std::string& metric) {
  const Eigen::VectorXd x = p.initial_point();
  const opt::MetricSet wanted = p.metric_set({metric});
  for (auto _ : state) {
    const auto e = p.evaluate(x, wanted, false);
    benchmark::DoNotOptimize(e);
  }
  // From one evaluation after the loop (see bench_recuperative.cpp's BM_ProblemEvaluate).
  state.counters["value"] = p.evaluate(x, wanted, false)[p.metric_id(metric)].value;
}

void BM_PressPeakTorque(benchmark::State& state) {
  time_metric(state, *press(static_cast<int>(state.range(0))), "peak_crank_torque");
}
BENCHMARK(BM_PressPeakTorque)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

// Work against precision: the pressure law's peak with range(0) grid cells
// over the stroke before the root is refined.
void BM_PressGrid(benchmark::State& state) {
  time_metric(state, *press(1, static_cast<int>(state.range(0))), "peak_crank_torque");
}
BENCHMARK(BM_PressGrid)->Arg(4)->Arg(6)->Arg(8)->Arg(12)->Arg(16)->Arg(32)->Arg(64)->Arg(128)->Arg(512)
    ->Unit(benchmark::kMicrosecond);

// The paper's improved mechanism (configs/balanced_slider_crank/paper.yaml), 72 grid points.
std::unique_ptr<opt::Problem> sawmill(int cycle_points = 72) {
  return opt::make_problem(opt::ConfigNode::parse(
      "problem: balanced_slider_crank\n"
      "model: {crank_speed: 320 rpm, crank_length: 0.3 m, original_rod_length: 2 m, cam_offset: 0.0219 m,\n"
      "        rod_length: auto, rod_mass: 150 kg, rod_inertia: 0.5 kg m^2, rod_centre_of_mass: 0.5,\n"
      "        slider_mass: 600 kg, spring_rate: auto, spring_neutral: 0 m, gravity: perpendicular,\n"
      "        cycle_points: " + std::to_string(cycle_points) + "}\n",
      "<bench>"));
}

// range(0): 1 every metric (the value counter is the peak balancing torque), 0 that peak alone.
void BM_SawmillMetrics(benchmark::State& state) {
  const auto p = sawmill();
  const Eigen::VectorXd x = p->initial_point();
  const opt::MetricSet wanted = state.range(0) != 0 ? opt::MetricSet::all() : p->metric_set({"peak_balancing_torque"});
  for (auto _ : state) {
    const auto e = p->evaluate(x, wanted, false);
    benchmark::DoNotOptimize(e);
  }
  const auto e = p->evaluate(x, wanted, false);
  state.counters["value"] = e[p->metric_id("peak_balancing_torque")].value;
  if (state.range(0) != 0) {
    state.counters["original_value"] = e[p->metric_id("original_peak_balancing_torque")].value;
    state.counters["support"] = e[p->metric_id("peak_support_reaction")].value;
    state.counters["cam"] = e[p->metric_id("peak_cam_force")].value;
  }
}
BENCHMARK(BM_SawmillMetrics)->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

// Work against precision: the peak balancing torque with range(0) grid
// points per revolution before each maximum is refined.
void BM_SawmillGrid(benchmark::State& state) {
  time_metric(state, *sawmill(static_cast<int>(state.range(0))), "peak_balancing_torque");
}
BENCHMARK(BM_SawmillGrid)->Arg(8)->Arg(12)->Arg(18)->Arg(24)->Arg(36)->Arg(72)->Arg(144)->Arg(288)
    ->Unit(benchmark::kMicrosecond);

// Every metric of the 24 variants of Table 6.1 per iteration; the value
// counter is the sum of their crank radii (L_X / 2).
void BM_RollerFormingTable(benchmark::State& state) {
  std::vector<std::unique_ptr<opt::Problem>> ps;
  for (int i = 1; i <= 24; ++i)
    ps.push_back(opt::make_problem(opt::ConfigNode::parse(
        "problem: roller_forming\nmodel: {variant: " + std::to_string(i) + "}\n", "<bench>")));
  const Eigen::VectorXd x = ps[0]->initial_point();
  const opt::MetricSet wanted = opt::MetricSet::all();
  for (auto _ : state)
    for (const auto& p : ps) {
      const auto e = p->evaluate(x, wanted, false);
      benchmark::DoNotOptimize(e);
    }
  const opt::MetricId crank = ps[0]->metric_id("crank_radius");
  double sum = 0;
  for (const auto& p : ps) sum += p->evaluate(x, wanted, false)[crank].value;
  state.counters["value"] = sum;
}
BENCHMARK(BM_RollerFormingTable)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
