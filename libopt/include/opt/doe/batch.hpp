// Batch design of experiments (docs/doe.md): the `doe` study's keys, and the
// runner that evaluates every sample of a sampler on all cores into one
// SQLite store, resumes exactly where a killed run stopped, and reports
// progress. A sample's values depend on (seed, index) only.
#pragma once
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "opt/doe/sampler.hpp"
#include "opt/parameters.hpp"
#include "opt/problem.hpp"
#include "opt/run_spec.hpp"

namespace opt::doe {

// A factor with the parameter-table row it sets.
struct FactorSpec {
  Factor factor;
  Parameter parameter;
  // Set through x when the row may be a design variable (bound once, by
  // index: the fast path), else in the model, by rebuilding the problem
  // from the config with the sample's value over it.
  bool through_x = false;
};

struct DoeSpec {
  std::vector<FactorSpec> factors;
  std::string sampler = "sobol";  // factorial | random | latin_hypercube | sobol | saltelli | list
  std::int64_t samples = 0;       // random, latin_hypercube, sobol; saltelli: base rows
  std::optional<std::uint64_t> seed;
  bool maximin = false;                      // latin_hypercube
  std::vector<std::vector<double>> rows;     // list: in factor order, SI
  // The metrics a row stores and the summary reports (default: every metric
  // stored; the objective and constraints summarised, else all).
  std::vector<std::string> columns;
  Objective objective;                       // optional: the best feasible sample is reported
  std::vector<Constraint> constraints;       // feasible: status ok and these met
  double sample_seconds = 0;                 // per-sample time limit (0: none)
  // refine: {best: K, driver: {...}}: a local optimisation of the objective
  // from each of the K best feasible samples, over the factors that are
  // design variables (within their ranges); K = 0: none.
  int refine_best = 0;
  DriverOptions refine_driver;
  nlohmann::json refine_settings;  // what the refined rows depend on besides the samples (resume key)
};

// The metrics each row computes and stores, in the problem's order: every
// metric when `columns` is empty, else `columns` with the objective's and the
// constraints' metrics (the summary reads feasibility and the best sample from
// the store). A DOE computes nothing else.
std::vector<std::string> stored_metrics(const DoeSpec& spec, const Problem& problem);

// Makes a problem from a config: opt::make_problem.
using ProblemFactory = std::function<std::unique_ptr<Problem>(const ConfigNode& root)>;

// More samples than kMaxSamples (opt/run_spec.hpp, a sweep's limit too) need
// --force (--dry-run shows what they would take). More than this, never: the
// finished-sample bitmap alone would take 1.25 GB, the store ~1.5 TB.
constexpr std::int64_t kHardMaxSamples = 10'000'000'000;

// Reads `study: {type: doe, sampler, samples, seed, maximin, factors, points,
// points_file, columns, sample_time_limit, refine}` and the top-level
// objective and constraints against the problem's parameter
// table; every value is checked against its row's domain, with located
// errors. More than kMaxSamples samples only when `beyond_limit` (--force,
// or --dry-run, which only estimates).
DoeSpec parse_doe(const ConfigNode& root, const std::vector<Parameter>& table, const Problem& problem,
                  bool beyond_limit = false);

// The store's column of a metric: its name, or NAME_metric when a factor has
// that name (the conveyor's crank_length is a factor and a metric).
std::string metric_column(const DoeSpec& spec, const std::string& metric);

// The sampler a spec asks for.
std::unique_ptr<Sampler> make_sampler(const DoeSpec& spec);

struct Shard {
  int index = 0, count = 1;  // --shard index/count: samples [index N / count, (index + 1) N / count)
};

struct Row;  // opt/doe/store.hpp

// Rows committed, by status name.
using StatusCounts = std::map<std::string, std::int64_t>;

// What a rank reports to rank 0 with each request: the rows it committed
// since its last report, and how many of its segment files it has closed
// in all (rank 0 folds those while the run goes).
struct Report {
  StatusCounts committed;
  std::int64_t closed = 0;
};

// The other processes of one run (MPI ranks, docs/doe.md): rank 0 owns the
// store and hands out chunks of indices; every other rank evaluates the
// chunks it is given, commits their rows to a segment of its own and reports
// what it committed with its next request.
class Peers {
 public:
  virtual ~Peers() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // The finished-sample bitmap, from rank 0 to all (n bits everywhere).
  virtual void share(std::vector<bool>& finished) = 0;
  // Rank 0: serves chunks to the other ranks, each asking for a size (`chunk(rank,
  // size)` gives [begin, end), empty when none is left), until every one has
  // been told to stop; each request's report goes to `reported(rank,
  // report)`. Stops handing out work once `stopping()` is true.
  virtual void serve(const std::function<std::pair<std::int64_t, std::int64_t>(int, std::int64_t)>& chunk,
                     const std::function<void(int, const Report&)>& reported,
                     const std::function<bool()>& stopping) = 0;
  // Other ranks: asks for chunks, evaluates and commits each with
  // `evaluate(begin, end, chunk size wanted next)`, whose report goes with
  // the next request, until told to stop.
  virtual void work(const std::function<Report(std::int64_t, std::int64_t, std::int64_t&)>& evaluate) = 0;
  // Every rank waits for every other (rank 0 folds the segments after it).
  virtual void barrier() = 0;
};

// The MPI ranks of this process's run, or nullptr when it was not started
// by mpirun with more than one rank (or mechopt was built without MPI).
// Initialises MPI on first use; finalised at exit.
Peers* mpi_peers();
// Ends a multi-rank run after an error on one rank (MPI_Abort), else nothing.
void abort_peers(int code);

struct BatchOptions {
  std::string output_directory = "results";
  int threads = 0;                 // 0: every core
  std::string progress = "auto";   // auto (bar on a terminal, else jsonl) | bar | jsonl | none
  bool fresh = false;              // --new: move an existing store aside
  bool force = false;              // --force: allow more than kMaxSamples
  bool dry_run = false;
  Shard shard;
  Peers* peers = nullptr;  // MPI ranks, if any
  bool quiet = false;      // the caller reports: no printed lines, summary or result.json (sweeps)
  // A segment's rows before its writer closes it for the fold (docs/doe.md,
  // "Segments"): 10 MB at 150 bytes a row, so that the fold follows the
  // writers closely and each fold is one transaction of a small file.
  std::size_t segment_rows = 65536;
};

// Makes the problem of a sample whose model values differ from the run's
// (`over`: {model: {KEY: VALUE}} as a config writes it; `name` for errors).
// Each thread has its own.
using SampleMaker = std::function<std::unique_ptr<Problem>(const YAML::Node& over, const std::string& name)>;

// The runner: evaluates every sample of `spec` not yet in DIR/store.sqlite on
// `problem` (factors through x), or, when model values are factors, on the
// problem a thread's maker (from `makers`, once per thread) builds per
// sample; writes result.json; prints a summary to `out` and progress to
// `err`. `config` is the run's config as written, kept in the store.
// Returns result.json's content (run_status: complete or interrupted).
nlohmann::json run_samples(const Problem& problem, const std::function<SampleMaker()>& makers, const DoeSpec& spec,
                           const BatchOptions& options, const nlohmann::json& config, std::ostream& out,
                           std::ostream& err);

// run_samples from a config: the factors that may be design variables become
// variables (the fast path), the others model values of a problem `make`
// builds per sample from the thread's own copy of the config.
nlohmann::json run_batch(const ConfigNode& root, const ProblemFactory& make, const DoeSpec& spec,
                         const BatchOptions& options, std::ostream& out, std::ostream& err);

// Summaries of a store: failures by status, the best feasible sample per
// objective (or per metric), main effects of each factor on each metric,
// Sobol' indices for a saltelli design; printed, written to the store's
// `summary` table and charted (main_effects_METRIC.svg, appended to `charts`).
// Printed values are in the units the charts show (display_units.hpp), the
// store and the returned JSON in SI; `problem` gives the metrics' units.
nlohmann::json summarize(const std::string& store_file, const DoeSpec& spec, const std::vector<std::string>& metrics,
                         const Problem& problem, const std::string& dir, std::ostream& out,
                         std::vector<std::string>& charts);

// The points of status_map.svg over the first two factors (at least two):
// per outcome ("feasible", "constraint not met", or a failure status) its
// count over the whole store and, up to kMaxDrawnPoints samples, every
// sample; beyond, in each cell of a kMapCells x kMapCells grid over the two
// factors' extents, the one sample of that outcome whose index hashes
// lowest. Every region where an outcome occurs shows it, whatever order the
// sampler visits the space in, and one scan of the store needs memory for
// the grid only. A categorical factor's value is its option's index.
// Outcomes in the order of their names.
constexpr int kMapCells = 30;
struct MapSeries {
  std::string outcome;
  std::int64_t count = 0;
  std::vector<double> x, y;  // SI, at most kMapCells^2 each
};
std::vector<MapSeries> status_map(const std::string& store_file, const DoeSpec& spec);

// What a store's rows depend on, and its hash (FNV-1a 64, hex): the problem,
// its settings (every model value and numerical setting), the sampler and
// the factors; not the output directory, the driver or progress settings.
nlohmann::json canonical_run(const Problem& problem, const DoeSpec& spec, const Sampler& sampler);
std::string config_hash(const nlohmann::json& canonical);

}  // namespace opt::doe
