// What every problem built on a libmech model shares: a table of named metrics
// with units, a table of model values (opt/parameters.hpp) with the chosen
// variables among its rows, and evaluation on the scalar type the driver
// needs (double, or an autodiff type with one derivative per variable). A
// problem supplies `evaluate_model(v, metrics)` templated on the scalar;
// nothing here knows which driver runs it. opt/registry.hpp builds a
// problem from a config and registers it by name.
#pragma once
#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "mech/autodiff.hpp"
#include "mech/cycle.hpp"
#include "opt/parameters.hpp"
#include "opt/problem.hpp"

namespace opt {

// Collects the metrics a caller wants, with gradients when S carries them.
// Metrics are named by the problem's own enum, whose values are the rows of
// its metric table (TabledProblem checks the order).
template <class S>
class MetricSink {
 public:
  // Into `into`, cleared, its storage reused.
  MetricSink(const opt::MetricSet& wanted, opt::Evaluation& into) : result(into), wanted_(wanted) { into.clear(); }
  template <class Id>
  bool want(Id id) const { return wanted_.contains(static_cast<opt::MetricId>(id)); }
  template <class... Ids>
  bool want_any(Ids... ids) const { return (want(ids) || ...); }
  template <class Id>
  [[gnu::always_inline]] void put(Id id, const S& v) {  // ten a design: inline
    if (!want(id)) return;
    opt::MetricValue& mv = result.slot(static_cast<opt::MetricId>(id));
    mv.value = mech::value(v);
    if constexpr (mech::is_dual<S>) mech::gradient_into(v, mv.gradient);
    else mv.gradient.resize(0);
  }
  opt::Evaluation& result;

 private:
  const opt::MetricSet& wanted_;
};

// A row of a problem's metric table: `id` is the problem's enum value for
// it, equal to the row's position.
struct MetricSpec {
  int id;
  std::string name, unit;
  std::string formerly = "";  // an earlier name, still accepted in configs
  template <class Id>
  MetricSpec(Id i, std::string n, std::string u, std::string f = "")
      : id(static_cast<int>(i)), name(std::move(n)), unit(std::move(u)), formerly(std::move(f)) {}
};

// A problem's name, its table of metrics with units, its table of model
// values (opt/parameters.hpp) with the values a config gave, and its
// variables: rows of the table.
class TabledProblem : public opt::Problem {
 public:
  // `values` as read from the config, any derived (auto) values resolved.
  TabledProblem(std::string name, std::vector<MetricSpec> metrics, std::vector<opt::Parameter> table,
                opt::Values<double> values, std::vector<opt::Variable> vars)
      : TabledProblem(std::move(name), std::move(metrics), std::move(vars)) {
    table_ = std::move(table);
    values_ = std::move(values);
    rows_ = opt::variable_rows(table_, variables());
  }
  // Without a table: the values are the variables.
  TabledProblem(std::string name, std::vector<MetricSpec> metrics, std::vector<opt::Variable> vars)
      : name_(std::move(name)), metrics_(std::move(metrics)), vars_(std::move(vars)) {
    if (metrics_.size() > static_cast<size_t>(opt::MetricSet::kMax))
      throw std::logic_error(name_ + ": more metrics than opt::MetricSet holds");
    std::vector<std::string> names;
    for (size_t i = 0; i < metrics_.size(); ++i) {
      if (metrics_[i].id != static_cast<int>(i))
        throw std::logic_error(name_ + ": metric " + metrics_[i].name + " is not at its enum's position");
      names.push_back(metrics_[i].name);
    }
    names_ = std::make_shared<const std::vector<std::string>>(std::move(names));
  }

  std::string name() const override { return name_; }
  const std::vector<opt::Variable>& variables() const override { return vars_; }
  const std::vector<std::string>& metric_names() const override { return *names_; }
  std::shared_ptr<const std::vector<std::string>> shared_metric_names() const override { return names_; }
  std::string renamed_metric(const std::string& old) const override {
    for (const auto& m : metrics_)
      if (!old.empty() && m.formerly == old) return m.name;
    return "";
  }
  std::string metric_unit(const std::string& metric) const override {
    for (const auto& m : metrics_)
      if (m.name == metric) return m.unit;
    return "";
  }

  // The model values as the config gave them (derived values resolved).
  const opt::Values<double>& values() const { return values_; }
  // The model values at design x.
  opt::Values<double> values_at(const Eigen::VectorXd& x) const { return seeded<double>(x); }
  // {name: value} of the model values, for result files.
  nlohmann::json model_json() const { return opt::parameters_json(opt::with_values(table_, values_)); }

 protected:
  template <class S>
  opt::Values<S> seeded(const Eigen::VectorXd& x, int first = 0) const {
    opt::Values<S> v;
    fill(x, v, first);
    return v;
  }
  // v = the values with each variable's row set to it, seeded when S
  // carries derivatives: DualX variable i of x.size(); a fixed-size S
  // variables first, first + 1, ... as its derivatives 0, 1, ... (the
  // others constant).
  template <class S>
  void fill(const Eigen::VectorXd& x, opt::Values<S>& v, int first = 0) const {
    const int n = static_cast<int>(x.size());
    if (table_.empty()) v.resize(n);
    else v.assign(values_.begin(), values_.end());
    for (int i = 0; i < n; ++i) {
      S& s = v[table_.empty() ? i : rows_[i]];
      const int k = i - first;
      if constexpr (std::is_same_v<S, mech::Dual>) s = k == 0 ? mech::seed(x[i]) : S(x[i]);
      else if constexpr (std::is_same_v<S, mech::DualX>) s = S(x[i], n, i);
      else if constexpr (mech::is_dual<S>) {
        constexpr int kSize = S::DerType::RowsAtCompileTime;
        s = k >= 0 && k < kSize ? S(x[i], kSize, k) : S(x[i]);
      }
      else s = x[i];
    }
  }

 private:
  std::vector<opt::Parameter> table_;  // empty without a table
  opt::Values<double> values_;
  std::vector<int> rows_;  // the table row of each variable
  std::string name_;
  std::vector<MetricSpec> metrics_;
  std::shared_ptr<const std::vector<std::string>> names_;  // shared with the evaluations
  std::vector<opt::Variable> vars_;
};

// The scratch of a ModelProblem's evaluation: the model values at the
// design as doubles (a batch evaluates millions of designs, and an
// allocation each cost a DOE sample ~3%). A problem with scratch of its own
// derives from it (see ModelProblem).
struct ModelWorkspace : opt::Workspace {
  opt::Values<double> values;
  opt::Evaluation chunk;  // a gradient's later chunks (beyond four variables)
};

// Derived implements
//   template <class S> void evaluate_model(const opt::Values<S>& v, MetricSink<S>& out) const;
// setting out.result.status for an infeasible design. v holds the model
// values of the problem's table at the design (each variable's row set to
// the variable, with its derivative when S carries them); a problem built
// without a table has its variables as its values. A problem that keeps
// scratch of its own declares `struct Workspace : opt::ModelWorkspace`
// with it and implements
//   template <class S> void evaluate_model(const opt::Values<S>& v, MetricSink<S>& out, Workspace& ws) const;
// instead: make_workspace makes one, and the evaluation gets the one its
// caller passed.
template <class Derived>
class ModelProblem : public TabledProblem {
 public:
  using TabledProblem::TabledProblem;

  std::unique_ptr<opt::Workspace> make_workspace() const override { return std::make_unique<WorkspaceOf<Derived>>(); }

  opt::Evaluation evaluate_model_at(const Eigen::VectorXd& x, const opt::MetricSet& wanted,
                                    bool gradient) const override {
    opt::Evaluation e;
    evaluate_model_into(x, wanted, gradient, e);
    return e;
  }
  void evaluate_model_into(const Eigen::VectorXd& x, const opt::MetricSet& wanted, bool gradient,
                           opt::Evaluation& out) const override {
    WorkspaceOf<Derived> ws;
    evaluate_model_with(x, wanted, gradient, out, ws);
  }
  // `w`: made by make_workspace (of this problem's type).
  void evaluate_model_with(const Eigen::VectorXd& x, const opt::MetricSet& wanted, bool gradient,
                           opt::Evaluation& out, opt::Workspace& w) const override {
    auto& ws = static_cast<WorkspaceOf<Derived>&>(w);
    auto run_into = [&](const auto& v, opt::Evaluation& into) {
      MetricSink<typename std::decay_t<decltype(v)>::value_type> sink(wanted, into);
      const Derived& self = static_cast<const Derived&>(*this);
      if constexpr (std::is_same_v<WorkspaceOf<Derived>, ModelWorkspace>) self.evaluate_model(v, sink);
      else self.evaluate_model(v, sink, ws);
    };
    auto run = [&](const auto& v) { run_into(v, out); };
    switch (gradient ? variables().size() : 0) {
      case 0: fill(x, ws.values); return run(ws.values);
      case 1: return run(seeded<mech::Dual>(x));  // value and slope: no Eigen expression templates
      case 2: return run(seeded<mech::DualN<2>>(x));
      case 3: return run(seeded<mech::DualN<3>>(x));
      case 4: return run(seeded<mech::DualN<4>>(x));
      default: break;
    }
    // Beyond four variables, forward mode by chunks: each pass seeds four
    // of them (DualN<4>: no heap, and no Eigen expression over an empty
    // derivative vector, which a run-time sized DualX meets wherever a
    // constant enters a product) and fills its four columns of every
    // gradient. The passes' double paths are the same, so are their status
    // and values.
    const int n = static_cast<int>(x.size());
    for (int first = 0; first < n; first += 4) {
      opt::Evaluation& e = first == 0 ? out : ws.chunk;
      run_into(seeded<mech::DualN<4>>(x, first), e);
      if (!e.ok()) {
        out.status = e.status, out.message = e.message;
        return;
      }
      out.join_gradients(e, first, n);
    }
  }

 protected:
  // Calls f(v) with the model values at x as an autodiff type with one
  // derivative per variable (each variable's row seeded): fixed size up to 4
  // variables, sized at run time beyond.
  template <class F>
  auto with_duals(const Eigen::VectorXd& x, F&& f) const {
    switch (variables().size()) {
      case 1: return f(seeded<mech::Dual>(x));  // value and slope: no Eigen expression templates
      case 2: return f(seeded<mech::DualN<2>>(x));
      case 3: return f(seeded<mech::DualN<3>>(x));
      case 4: return f(seeded<mech::DualN<4>>(x));
      default: return f(seeded<mech::DualX>(x));
    }
  }

  // The local maxima of a cycle integrand g(model, phi) of the model at x
  // (see opt::Problem::local_maxima); model_at(v) builds the model from the
  // values v.
  template <class ModelAt, class G>
  std::vector<opt::MetricValue> cycle_local_maxima(const Eigen::VectorXd& x, int n,
                                                   ModelAt&& model_at, G&& g) const {
    const auto angles = mech::cycle_max_angles(model_at(seeded<double>(x)), n, g);
    return with_duals(x, [&](const auto& v) {
      using S = typename std::decay_t<decltype(v)>::value_type;
      const auto model = model_at(v);
      std::vector<opt::MetricValue> out;
      for (double phi : angles) {
        const S g_phi = g(model, S(phi));
        opt::MetricValue mv{mech::value(g_phi), {}};
        if constexpr (mech::is_dual<S>) mv.gradient = mech::gradient(g_phi);
        out.push_back(mv);
      }
      return out;
    });
  }

 private:
  // Derived::Workspace where Derived declares one, else ModelWorkspace
  // (looked up where Derived is complete: in the member functions' bodies).
  template <class D>
  struct WorkspaceOfT {
    using type = ModelWorkspace;
  };
  template <class D>
    requires requires { typename D::Workspace; }
  struct WorkspaceOfT<D> {
    using type = typename D::Workspace;
  };
  template <class D>
  using WorkspaceOf = typename WorkspaceOfT<D>::type;
};

}  // namespace opt
