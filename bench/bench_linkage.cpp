// The general linkage against the hand-written problems on the same
// mechanism, in one process: one evaluation of the same metrics through the
// Problem interface (a kept workspace, as a driver or a DOE thread holds
// one), at the configs' designs. The ratio general / hand-written is the
// cost of describing a mechanism instead of writing it (issue 34's target:
// at most 3: rows 0-5 and 9-10). Counters: the first metric's value, equal on both rows. The
// six-bars' and the shaper's rows compute what bench/peer_linkage.py (the
// same solution in numpy) does, for the ratio against it.
// bench/linkage_ratios.py runs the pairs' rows interleaved, many short
// repetitions each, and prints their times' ratios (docs/performance.md).
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "opt/registry.hpp"

namespace {

struct Case {
  const char* config;
  std::vector<std::string> metrics;
  const char* over = "";  // YAML laid over the config (the same mechanism on both rows)
};

// range(0): the case; range(1): 1 with gradients.
const Case kCases[] = {
    {"slider_crank/stroke.yaml", {"stroke", "peak_slider_acceleration", "max_pressure_angle"}},
    {"linkage/slider_crank.yaml", {"ram_stroke", "ram_peak_acceleration", "max_pressure_angle"}},
    {"conveyor_swing/free_links.yaml",
     {"peak_crank_torque", "mean_abs_crank_torque", "rms_crank_torque", "max_pressure_angle", "swing_angle",
      "time_ratio"}},
    {"linkage/conveyor_swing.yaml",
     {"peak_drive_torque", "mean_abs_drive_torque", "rms_drive_torque", "min_transmission_angle", "rocker_stroke",
      "rocker_time_ratio"}},
    {"conveyor_swing/free_links.yaml", {"peak_crank_torque", "max_pressure_angle", "swing_angle"}},
    {"linkage/conveyor_swing.yaml", {"peak_drive_torque", "min_transmission_angle", "rocker_stroke"}},
    // The six-bars and the shaper: what bench/peer_linkage.py (numpy) computes.
    {"linkage/watt2_sixbar.yaml",
     {"peak_drive_torque", "rms_drive_torque", "mean_drive_torque", "rocker2_stroke", "rocker2_peak_acceleration"}},
    {"linkage/stephenson3_sixbar.yaml",
     {"peak_drive_torque", "rms_drive_torque", "mean_drive_torque", "slider_stroke", "slider_peak_acceleration",
      "rocker_stroke", "rocker_peak_acceleration"}},
    {"linkage/whitworth_shaper.yaml",
     {"peak_drive_torque", "rms_drive_torque", "mean_drive_torque", "ram_stroke", "ram_peak_acceleration"}},
    // The twin drive (seed 000) with its rods' rotation and the resistance
    // against the motion, both rods 0.8 m: the equivalence test's mechanism.
    {"recuperative_drive/rod_length.yaml",
     {"peak_kinetic_energy", "mean_kinetic_energy", "k1", "k2", "k3", "peak_crank_torque", "mean_crank_torque"},
     "model: {fidelity: {rod: full}, resistance: opposes_motion}"},
    {"linkage/recuperative_drive.yaml",
     {"peak_kinetic_energy", "mean_kinetic_energy", "k1", "k2", "k3", "peak_drive_torque", "mean_drive_torque"},
     "model: {links: {rod1: {length: 0.8 m}}}"},
};

void BM_Evaluate(benchmark::State& state) {
  const Case& c = kCases[state.range(0)];
  const auto root = opt::ConfigNode::load(std::string(MECHOPT_SOURCE_DIR) + "/configs/" + c.config);
  const auto p = opt::make_problem(*c.over ? root.with(YAML::Load(c.over), c.config) : root);
  opt::MetricSet wanted;
  for (const auto& m : c.metrics) wanted.add(p->metric_id(m));
  const Eigen::VectorXd x = p->initial_point();
  const bool gradient = state.range(1) != 0;
  const auto ws = p->make_workspace();
  opt::Evaluation e;
  for (auto _ : state) {
    p->evaluate(x, wanted, gradient, e, *ws);
    benchmark::DoNotOptimize(e);
  }
  state.counters["value"] = e.ok() ? e[p->metric_id(c.metrics[0])].value : -1;
  state.SetLabel(c.config);
}
BENCHMARK(BM_Evaluate)
    ->Args({0, 0})->Args({1, 0})->Args({2, 0})->Args({3, 0})->Args({4, 0})->Args({5, 0})
    ->Args({0, 1})->Args({1, 1})->Args({4, 1})->Args({5, 1})->Args({6, 0})->Args({7, 0})->Args({8, 0})
    ->Args({9, 0})->Args({10, 0})->Args({9, 1})->Args({10, 1})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
