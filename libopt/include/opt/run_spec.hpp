// A run's keys read from its config (config/run_spec.cpp): the variables,
// objective, constraints, study, driver, grid, reference and output; keys
// are checked against the problem's variables and metrics, errors located.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "opt/parameters.hpp"
#include "opt/problem.hpp"

namespace opt {

// Reads `variables: {NAME: {min: .., max: .., initial: ..}}` for the
// parameters that may be freed (Parameter::variable); bounds and the initial
// value (default: the model value) must lie in the parameter's domain.
std::vector<Variable> parse_variables(const ConfigNode& root, const std::vector<Parameter>& parameters);

struct GridAxis {
  std::string variable;
  int index = 0;               // of the variable in Problem::variables()
  std::vector<double> values;  // SI
};

// Values printed by a paper next to a sweep, for the chart and the printed table.
struct Reference {
  std::string source;
  std::map<std::string, std::vector<double>> columns;  // variable or metric -> values (SI)
};

struct RunSpec {
  std::string type = "optimize";  // optimize | sweep | pareto | evaluate (the model values)
  Objective objective;
  std::vector<Constraint> constraints;
  bool optimize = true;           // sweeps: also run the driver
  DriverOptions driver;
  std::vector<GridAxis> grid;     // sweeps
  std::vector<std::string> columns;  // metrics printed and charted
  std::vector<std::string> objectives;  // pareto: the two metrics traded, both minimised
  int points = 11;                   // pareto: points on the front
  // pareto with a pagmo driver: the gradient driver that finds the front's
  // two ends, which scale the objectives for the hypervolume.
  DriverOptions anchor_driver;
  Reference reference;
  std::string output_directory = "results";
  int threads = 0;     // sweeps: --threads (0: every core)
  bool force = false;  // sweeps: --force
  bool chart = true;
};

// Reads a `driver:` map (library, algorithm, tolerances, limits, polish).
// library: pagmo only where this mechopt was built with pagmo.
DriverOptions parse_driver(const ConfigNode& n);

// The most designs one run evaluates without --force: a sweep's grid points
// in all, a DOE's samples (a sweep is a factorial design, run by the DOE's
// runner; opt/doe/batch.hpp).
constexpr std::int64_t kMaxSamples = 10'000'000;

// Reads objective, constraints, study, output and reference (keys checked
// against the problem's variables and metrics).
// `force`: a sweep may have more than kMaxSamples points in all.
RunSpec parse_run(const ConfigNode& root, const Problem& problem, bool force = false);

}  // namespace opt
