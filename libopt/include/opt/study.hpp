// Studies orchestrate runs of a Problem: `optimize` (one driver run),
// `sweep` (1-D or 2-D grid, like the paper's tables, optionally followed by an
// optimisation) and `pareto` (the front of two metrics: epsilon-constraint,
// or evolved by pagmo). Every
// evaluation's status is recorded; results go to result.json, sweep.csv,
// history.csv, pareto.csv and SVG charts in the output directory.
#pragma once
#include <iosfwd>
#include <nlohmann/json.hpp>

#include "opt/problem.hpp"
#include "opt/run_spec.hpp"

namespace opt {

namespace doe {
struct BatchOptions;  // opt/doe/batch.hpp
}

// Runs the study, prints a readable summary to `out`, writes the files, and
// returns result.json's content.
nlohmann::json run_study(const Problem& problem, const RunSpec& spec, std::ostream& out);

// The config's study as `mechopt run` runs it: a doe study (docs/doe.md)
// through doe::run_batch into DIR/store.sqlite, any other through
// run_study (`options`' threads and force go to a sweep). DIR is
// options.output_directory, or where that is "" the config's
// output.directory, which is then written there. Returns result.json's
// content; a stop request leaves it marked interrupted.
nlohmann::json run_config(const ConfigNode& root, const Problem& problem, doe::BatchOptions& options,
                          std::ostream& out, std::ostream& err);
// Whether the config's study is a doe.
bool is_doe(const ConfigNode& root);

// Whether this build has pagmo's evolutionary fronts (driver library: pagmo).
bool evolutionary_fronts_built();

// Every metric at x as JSON {status, metrics: {name: value}}.
nlohmann::json metrics_json(const Problem& problem, const Eigen::VectorXd& x);

}  // namespace opt
