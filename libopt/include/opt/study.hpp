// Studies orchestrate runs of a Problem: `optimize` (one driver run),
// `sweep` (1-D or 2-D grid, like the paper's tables, optionally followed by an
// optimisation) and `pareto` (epsilon-constraint front of two metrics). Every
// evaluation's status is recorded; results go to result.json, sweep.csv,
// history.csv, pareto.csv and SVG charts in the output directory.
#pragma once
#include <iosfwd>
#include <nlohmann/json.hpp>

#include "opt/problem.hpp"
#include "opt/run_spec.hpp"

namespace opt {

// Runs the study, prints a readable summary to `out`, writes the files, and
// returns result.json's content.
nlohmann::json run_study(const Problem& problem, const RunSpec& spec, std::ostream& out);

// Every metric at x as JSON {status, metrics: {name: value}}.
nlohmann::json metrics_json(const Problem& problem, const Eigen::VectorXd& x);

}  // namespace opt
