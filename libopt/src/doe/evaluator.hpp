// Inside the batch pipeline (docs/doe.md): how a sample index becomes a
// problem, a point x and a row, shared by the runner (batch.cpp) and the
// local optimisations from the best samples (refine.cpp).
#pragma once
#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "opt/doe/batch.hpp"
#include "opt/doe/store.hpp"

namespace opt::doe {

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The run's config: the factors that can be design variables become
// variables spanning their range, so that a sample sets them through x.
ConfigNode run_root(const ConfigNode& root, const DoeSpec& spec);

class Evaluator {
 public:
  // `base` is the problem of run_root's config (its variables: the factors through x).
  Evaluator(const Problem& base, const DoeSpec& spec, const Sampler& sampler);

  // Are some factors model values (the problem is rebuilt per sample)?
  bool model_factors() const { return model_factors_; }

  // The problem of a sample with these factor values (the base, or one built
  // by `maker` with the model values written over the config) and its x.
  // A value the model refuses throws ConfigError.
  struct Sample {
    std::unique_ptr<Problem> own;  // when built for the sample
    const Problem* problem = nullptr;
    Eigen::VectorXd x;
  };
  Sample sample(const SampleMaker& maker, std::int64_t index, const std::vector<double>& factors) const;
  // The same into `s`, its x's storage reused.
  void sample_into(const SampleMaker& maker, std::int64_t index, const std::vector<double>& factors, Sample& s) const;

  // What a worker thread reuses from one sample to the next: the sample's
  // storage, its evaluation's, and the workspace of the base problem (a
  // sample with a problem of its own evaluates with a workspace of that
  // problem, made for it).
  struct Worker {
    Sample sample;
    Evaluation out;
    std::unique_ptr<Workspace> base_workspace;  // made on first use
    std::unique_ptr<Workspace> own_workspace;   // the sample's own problem's
  };

  // Sample i as a row: a status (never an exception) and the stored metrics
  // (stored_metrics), the only ones computed.
  Row evaluate(const SampleMaker& maker, std::int64_t i) const;
  // The same into `r`, the storage of its vectors reused (a batch's spent
  // rows), with a worker thread's storage `w`.
  void evaluate(const SampleMaker& maker, std::int64_t i, Row& r, Worker& w) const;

  const Problem& base() const { return base_; }
  // Factor j's index in x, or -1 (a model value).
  int variable(std::size_t j) const { return variable_[j]; }

 private:
  const Problem& base_;
  const DoeSpec& spec_;
  const Sampler& sampler_;
  std::vector<MetricId> stored_;  // a row's metrics, in order
  MetricSet wanted_;               // the same, as the model's wanted set
  Eigen::VectorXd initial_;  // the base problem's start: every x before its factors are written
  std::vector<int> variable_;
  bool model_factors_ = false;
};

// `where` of SQL for a feasible sample: status ok, the constraints met (summary_reads.cpp).
std::string feasible_where(const DoeSpec& spec);

// `refine`: a local optimisation from each of the best feasible samples of
// the store (refine.cpp); rows in its `refined` table, the summary returned.
nlohmann::json refine(const Evaluator& evaluator, const SampleMaker& maker, const DoeSpec& spec,
                      const std::string& store_file, std::ostream& out);

}  // namespace opt::doe
