// What every problem built on a libmech model shares: a table of named metrics
// with units, the chosen variables, and evaluation on the scalar type the
// driver needs (double, or an autodiff type with one derivative per
// variable). A problem supplies `evaluate_model(xs, metrics)` templated on
// the scalar; nothing here knows which driver runs it.
#pragma once
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "mech/autodiff.hpp"
#include "opt/problem.hpp"

namespace problems {

// Collects the metrics a caller wants, with gradients when S carries them.
template <class S>
class MetricSink {
 public:
  explicit MetricSink(const std::vector<std::string>& wanted) : wanted_(wanted) {}
  bool want(const std::string& name) const {
    return wanted_.empty() || std::find(wanted_.begin(), wanted_.end(), name) != wanted_.end();
  }
  template <class... Names>
  bool want_any(const Names&... names) const { return (want(names) || ...); }
  void put(const std::string& name, const S& v) {
    if (!want(name)) return;
    opt::MetricValue mv;
    mv.value = mech::value(v);
    if constexpr (mech::is_dual<S>) mv.gradient = v.derivatives();
    result.metrics[name] = mv;
  }
  opt::Evaluation result;

 private:
  const std::vector<std::string>& wanted_;
};

struct MetricSpec {
  std::string name, unit;
};

// Derived implements:
//   template <class S> void evaluate_model(const std::vector<S>& x, MetricSink<S>& out) const;
// setting out.result.status for an infeasible design.
template <class Derived>
class ModelProblem : public opt::Problem {
 public:
  ModelProblem(std::string name, std::vector<MetricSpec> metrics, std::vector<opt::Variable> vars)
      : name_(std::move(name)), metrics_(std::move(metrics)), vars_(std::move(vars)) {}

  std::string name() const override { return name_; }
  const std::vector<opt::Variable>& variables() const override { return vars_; }
  std::vector<std::string> metric_names() const override {
    std::vector<std::string> out;
    for (const auto& m : metrics_) out.push_back(m.name);
    return out;
  }
  std::string metric_unit(const std::string& metric) const override {
    for (const auto& m : metrics_)
      if (m.name == metric) return m.unit;
    return "";
  }

  opt::Evaluation evaluate(const Eigen::VectorXd& x, const std::vector<std::string>& wanted,
                           bool gradient) const override {
    if (!gradient) return evaluate_as<double>(x, wanted);
    switch (vars_.size()) {  // one derivative per variable
      case 1: return evaluate_as<mech::DualN<1>>(x, wanted);
      case 2: return evaluate_as<mech::DualN<2>>(x, wanted);
      case 3: return evaluate_as<mech::DualN<3>>(x, wanted);
      default: return evaluate_as<mech::DualN<mech::kMaxDerivatives>>(x, wanted);
    }
  }

 private:
  template <class S>
  opt::Evaluation evaluate_as(const Eigen::VectorXd& x, const std::vector<std::string>& wanted) const {
    std::vector<S> xs(x.size());
    for (int i = 0; i < x.size(); ++i) {
      if constexpr (mech::is_dual<S>) xs[i] = S(x[i], S::DerType::RowsAtCompileTime, i);
      else xs[i] = x[i];
    }
    MetricSink<S> sink(wanted);
    static_cast<const Derived&>(*this).evaluate_model(xs, sink);
    return std::move(sink.result);
  }

  std::string name_;
  std::vector<MetricSpec> metrics_;
  std::vector<opt::Variable> vars_;
};

}  // namespace problems
