// The study kinds run_study dispatches to. Each prints its part of the
// summary, writes its rows through a Recorder, stops between evaluations when
// a stop is requested (opt/interrupt.hpp), and returns its part of
// result.json.
#pragma once
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "opt/driver.hpp"
#include "opt/study.hpp"

namespace opt::studies {

// One driver run from the model values; history.csv lists every evaluation.
struct OptimizeOutcome {
  Result result;
  nlohmann::json json;
};
OptimizeOutcome optimize(const Problem& p, const RunSpec& s, std::ostream& out, const std::string& dir);

// Every grid point, in the order of the grid's axes (the first slowest);
// sweep.csv has one row per point.
struct SweepOutcome {
  std::vector<Eigen::VectorXd> x;
  std::vector<Evaluation> e;
  long total = 0;  // points on the grid (x.size() of them evaluated)
  nlohmann::json json;
};
SweepOutcome sweep(const Problem& p, const RunSpec& s, std::ostream& out, const std::string& dir);

// The epsilon-constraint front of two metrics, or pagmo's (below):
// pareto.csv and pareto.svg; adds the files it wrote to `files`.
nlohmann::json pareto(const Problem& p, const RunSpec& s, std::ostream& out, const std::string& dir,
                      std::vector<std::string>& files);

// The front of a population evolved by pagmo (driver library: pagmo):
// pareto.csv (the final non-dominated feasible designs), generations.csv
// (the hypervolume after each generation) and pareto.svg.
nlohmann::json pareto_evolution(const Problem& p, const RunSpec& s, std::ostream& out, const std::string& dir,
                                std::vector<std::string>& files);

}  // namespace opt::studies
