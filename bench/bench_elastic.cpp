// Speed of the elastic drive (seed 001) on SUNDIALS: one steady-state
// evaluation as an optimisation makes it (rigid first guess, no samples; the
// configs' ERK at rtol 1e-8), the same from a 3 s start-up guess, one
// start-up simulation, the steady state over tolerances and methods
// (work-precision), and a map of where each method works over stiffness and
// damping. Counters: value (peak coupling torque at the crank [N m]), steps,
// ok, multiplier (largest Floquet multiplier). The Twin rows drive the same
// twin slider-crank written out by hand (exact kinematics, no guide
// friction) and as a linkage (configs/elastic_drive/linkage_twin.yaml's
// machine, mech/linkage/machine.hpp): what a general machine costs.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "mech/drive_dynamics.hpp"
#include "mech/linkage/machine.hpp"
#include "opt/config.hpp"
#include "problems/linkage/description.hpp"

namespace {

constexpr double kStart = 10.686;  // synchronous crank speed

mech::ElasticDrive scene() {  // configs/elastic_drive/*.yaml
  mech::ElasticDrive d;
  d.roller_horizontal = 3562;
  d.roller_vertical = d.cart_weight;
  d.resistance_opposes_motion = true;
  return d;
}

mech::OdeOptions erk(double rtol) {
  mech::OdeOptions o;
  o.method = mech::OdeMethod::erk;
  o.rtol = o.atol = rtol;
  return o;
}

void steady(benchmark::State& state, mech::ElasticDrive d, mech::OdeOptions o, double warmup = 0) {
  mech::SteadyCycle s;
  for (auto _ : state) {
    s = mech::steady_by_shooting(d, o, 0, warmup, kStart);
    benchmark::DoNotOptimize(s);
  }
  state.counters["value"] = s.coupling_peak;
  state.counters["steps"] = static_cast<double>(s.steps);
  state.counters["ok"] = s.status == mech::Status::ok;
  state.counters["multiplier"] = s.largest_multiplier;
}

// The hand-written twin that linkage_twin.yaml's machine describes.
mech::ElasticDrive twin() {
  mech::ElasticDrive d = scene();
  d.kinematics = mech::Kinematics::exact;
  d.guide_friction = 0;
  return d;
}
const problems::linkage::Description& twin_linkage() {
  static const problems::linkage::Description d = problems::linkage::read_model(
      opt::ConfigNode::load(MECHOPT_SOURCE_DIR "/configs/elastic_drive/linkage_twin.yaml").at("model").at("machine"));
  return d;
}

// The steady state (erk) and a 3 s start-up (bdf: its Newton matrix takes
// the machine's slopes), hand-written or with the linkage as its machine.
void BM_ElasticSteadyTwin(benchmark::State& state, bool linkage) {
  const mech::linkage::LinkageMachine m(twin_linkage().chain, twin_linkage().chain.defaults());
  mech::ElasticDrive d = twin();
  if (linkage) d.machine = &m;
  steady(state, d, erk(1e-8));
}
void BM_ElasticStartupTwin(benchmark::State& state, bool linkage) {
  const mech::linkage::LinkageMachine m(twin_linkage().chain, twin_linkage().chain.defaults());
  mech::ElasticDrive d = twin();
  if (linkage) d.machine = &m;
  mech::Startup st;
  for (auto _ : state) {
    st = mech::simulate_startup(d, {}, 3.0, 1e-3, nullptr, kStart);
    benchmark::DoNotOptimize(st);
  }
  state.counters["value"] = st.peak_coupling;
  state.counters["steps"] = static_cast<double>(st.steps);
}
BENCHMARK_CAPTURE(BM_ElasticSteadyTwin, hand_written, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ElasticSteadyTwin, linkage, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ElasticStartupTwin, hand_written, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ElasticStartupTwin, linkage, true)->Unit(benchmark::kMillisecond);

void BM_ElasticStartup(benchmark::State& state) {
  mech::Startup st;
  for (auto _ : state) {
    st = mech::simulate_startup(scene(), {}, 3.0, 1e-3, nullptr, kStart);
    benchmark::DoNotOptimize(st);
  }
  state.counters["value"] = st.peak_coupling;
  state.counters["steps"] = static_cast<double>(st.steps);
}
BENCHMARK(BM_ElasticStartup)->Unit(benchmark::kMillisecond);

void register_all() {
  benchmark::RegisterBenchmark("BM_ElasticSteady", [](benchmark::State& s) { steady(s, scene(), erk(1e-8)); })
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("BM_ElasticSteadyFromStartup",
                               [](benchmark::State& s) { steady(s, scene(), erk(1e-8), 3.0); })
      ->Unit(benchmark::kMillisecond);
  const char* names[] = {"bdf", "adams", "erk"};
  // Work-precision: the steady state over tolerances and methods.
  for (int m = 0; m < 3; ++m)
    for (int e : {5, 6, 7, 8, 9, 10}) {
      mech::OdeOptions o;
      o.method = static_cast<mech::OdeMethod>(m);
      o.rtol = o.atol = std::pow(10.0, -e);
      benchmark::RegisterBenchmark(("WPE/" + std::string(names[m]) + "/" + std::to_string(e)).c_str(),
                                   [o](benchmark::State& s) { steady(s, scene(), o); })
          ->Unit(benchmark::kMillisecond);
    }
  // Where methods work: stiffness x damping (as a ratio of critical), one run each.
  for (int m = 0; m < 3; ++m)
    for (int ce = 3; ce <= 10; ++ce)
      for (double zeta : {0.05, 1.0}) {
        mech::ElasticDrive d = scene();
        d.stiffness = std::pow(10.0, ce);
        d.damping = zeta * 2 * std::sqrt(d.stiffness * 40.0);
        mech::OdeOptions o;
        o.method = static_cast<mech::OdeMethod>(m);
        o.max_steps = 20000;
        benchmark::RegisterBenchmark(
            ("MAP/" + std::string(names[m]) + "/c1e" + std::to_string(ce) + "/zeta" +
             (zeta < 1 ? "0.05" : "1")).c_str(),
            [d, o](benchmark::State& s) { steady(s, d, o); })
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);
      }
}

// Registered at start-up, before BENCHMARK_MAIN parses the command line.
const bool kRegistered = (register_all(), true);

}  // namespace

BENCHMARK_MAIN();
