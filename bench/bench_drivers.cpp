// Work-precision of every driver and algorithm: time to an optimum against its
// error, over step/KKT tolerances, on the two mechanism optima with
// independent references (tools/reference_seed000.json, reference_seed002.json).
// Counters: error (relative error of the optimal variable), evaluations.
#include <benchmark/benchmark.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>
#include <string>

#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "opt/drivers/nlopt.hpp"
#include "opt/registry.hpp"

namespace {

struct Scene {
  const char* name;
  const char* yaml;
  const char* objective;
  std::vector<opt::Constraint> constraints;
  double x_star;
};

// An optimum's reference, as bench/run_bench.py reads it for the peers.
double reference(const std::string& file, const char* key) {
  const std::string path = std::string(MECHOPT_SOURCE_DIR) + "/tools/" + file;
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  return std::stod(nlohmann::json::parse(in).at(key).get<std::string>());
}

const Scene kScenes[] = {
    {"rod_length", "problem: recuperative_drive\nvariables: {rod_length: {min: 0.5 m, max: 1.5 m}}\n",
     "mean_kinetic_energy", {}, reference("reference_seed000.json", "rod_length_optimum")},
    {"conveyor_l_co1", "problem: conveyor_swing\nvariables: {l_co1: {min: 0.9 m, max: 2.4 m}}\n",
     "peak_crank_torque", {{"max_pressure_angle", true, 60 * std::numbers::pi / 180}},
     reference("reference_seed002.json", "l_co1_optimum")},
};

void run(benchmark::State& state, const Scene& scene, opt::DriverOptions o) {
  const auto p = opt::make_problem(opt::ConfigNode::parse(scene.yaml, "<bench>"));
  const auto driver = opt::make_driver(o);
  opt::Result r;
  for (auto _ : state) {
    r = driver->minimize(*p, {scene.objective}, scene.constraints, p->initial_point());
    benchmark::DoNotOptimize(r);
  }
  state.counters["error"] = r.success() ? std::abs(r.x[0] - scene.x_star) / scene.x_star : NAN;
  state.counters["evaluations"] = r.evaluations;
  if (r.iterations > 0) state.counters["iterations"] = r.iterations;
  state.counters["converged"] = r.status == opt::DriverStatus::converged;
}

// WP/<scene>/<driver>/<-log10 tol>.
void add(const Scene& s, const std::string& driver, double tol, const opt::DriverOptions& o) {
  benchmark::RegisterBenchmark(
      (std::string("WP/") + s.name + "/" + driver + "/" + std::to_string(-int(std::log10(tol)))).c_str(),
      [&s, o](benchmark::State& st) { run(st, s, o); })
      ->Unit(benchmark::kMicrosecond);
}

void register_all() {
  const char* nlopt[] = {"LD_SLSQP", "LD_LBFGS", "LD_MMA", "LD_CCSAQ", "LN_COBYLA", "LN_BOBYQA"};
  for (const Scene& s : kScenes) {
    for (const char* a : nlopt) {
      const bool takes = s.constraints.empty() || opt::algorithm_supports_constraints(a);
      if (!takes) continue;
      for (double tol : {1e-4, 1e-6, 1e-8, 1e-10, 1e-12}) {
        opt::DriverOptions o;
        o.algorithm = a;
        o.xtol_rel = tol;
        o.record_history = false;
        add(s, std::string("nlopt_") + a, tol, o);
      }
    }
    // Brent on the exact derivative (`library: line`): one variable with
    // bounds only, so the rod length and not the constrained conveyor.
    if (s.constraints.empty()) {
      for (double tol : {1e-4, 1e-6, 1e-8, 1e-10, 1e-12}) {
        opt::DriverOptions o;
        o.library = "line";
        o.xtol_rel = tol;
        o.record_history = false;
        add(s, "line", tol, o);
      }
    }
    for (bool epigraph : {true, false}) {
      if (!epigraph && std::string(s.name) == "rod_length") continue;  // smooth: the same run
      for (double tol : {1e-4, 1e-6, 1e-8, 1e-10}) {
        opt::DriverOptions o;
        o.library = "ipopt";
        o.tol = tol;
        o.epigraph = epigraph;
        o.max_iterations = 500;
        o.record_history = false;
        add(s, epigraph ? "ipopt" : "ipopt_plain", tol, o);
      }
    }
    // Ipopt's iteration with its own sparse solver, against the dense one
    // above (docs/drivers.md, "Ipopt's linear solver").
    opt::DriverOptions o;
    o.library = "ipopt";
    o.tol = 1e-8;
    o.linear_solver = "mumps";
    o.record_history = false;
    add(s, "ipopt_mumps", 1e-8, o);
  }
}

// Registered at start-up, before BENCHMARK_MAIN parses the command line.
const bool kRegistered = (register_all(), true);

}  // namespace

BENCHMARK_MAIN();
