// How a sample index becomes a problem, x and a row (evaluator.hpp).
#include "doe/evaluator.hpp"

#include <algorithm>
#include <limits>

#include "mech/deadline.hpp"

namespace opt::doe {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

YAML::Node value_node(const Parameter& p, double v) { return YAML::Node(exact_value_text(p, v)); }

}  // namespace

ConfigNode run_root(const ConfigNode& root, const DoeSpec& spec) {
  YAML::Node over(YAML::NodeType::Map);
  for (const auto& f : spec.factors) {
    if (!f.through_x) continue;
    const auto& lv = f.factor.levels;
    const bool range = f.factor.kind == Factor::Kind::range;
    const double lo = range ? f.factor.lower : *std::min_element(lv.begin(), lv.end());
    const double hi = range ? f.factor.upper : *std::max_element(lv.begin(), lv.end());
    over["variables"][f.factor.name]["min"] = value_node(f.parameter, lo);
    over["variables"][f.factor.name]["max"] = value_node(f.parameter, hi);
  }
  return root.with(over, root.file());
}

Evaluator::Evaluator(const Problem& base, const DoeSpec& spec, const Sampler& sampler)
    : base_(base), spec_(spec), sampler_(sampler), initial_(base.initial_point(false)) {
  for (const auto& m : stored_metrics(spec, base)) {
    stored_.push_back(base.metric_id(m));
    wanted_.add(stored_.back());
  }
  for (const auto& f : spec.factors) {
    int index = -1;
    for (size_t v = 0; v < base.variables().size(); ++v)
      if (f.through_x && base.variables()[v].name == f.factor.name) index = static_cast<int>(v);
    variable_.push_back(index);
    model_factors_ = model_factors_ || index < 0;
  }
}

Evaluator::Sample Evaluator::sample(const SampleMaker& maker, std::int64_t index,
                                    const std::vector<double>& factors) const {
  Sample s;
  sample_into(maker, index, factors, s);
  return s;
}

void Evaluator::sample_into(const SampleMaker& maker, std::int64_t index, const std::vector<double>& factors,
                            Sample& s) const {
  s.own.reset();
  s.problem = &base_;
  if (model_factors_) {  // model values change: the problem is built for this sample
    YAML::Node over(YAML::NodeType::Map);
    for (size_t j = 0; j < spec_.factors.size(); ++j)
      if (variable_[j] < 0)
        set_dotted(over["model"], spec_.factors[j].factor.name, value_node(spec_.factors[j].parameter, factors[j]));
    s.own = maker(over, "sample " + std::to_string(index));
    s.problem = s.own.get();
    s.x = s.problem->initial_point(false);
  } else {
    s.x = initial_;  // same size: no allocation
  }
  for (size_t j = 0; j < variable_.size(); ++j)
    if (variable_[j] >= 0) s.x[variable_[j]] = factors[j];
}

Row Evaluator::evaluate(const SampleMaker& maker, std::int64_t i) const {
  Row r;
  Worker w;
  evaluate(maker, i, r, w);
  return r;
}

void Evaluator::evaluate(const SampleMaker& maker, std::int64_t i, Row& r, Worker& w) const {
  r.index = i;
  r.message.clear();
  r.factors.assign(spec_.factors.size(), 0.0);
  sampler_.point(i, r.factors);
  r.metrics.assign(stored_.size(), kNan);
  const auto t0 = Clock::now();
  mech::set_deadline(spec_.sample_seconds);  // checked inside long computations
  Sample& s = w.sample;
  Evaluation& out = w.out;
  try {
    sample_into(maker, i, r.factors, s);
    Workspace* ws;
    if (s.own) {
      w.own_workspace = s.own->make_workspace();
      ws = w.own_workspace.get();
    } else {
      if (!w.base_workspace) w.base_workspace = base_.make_workspace();
      ws = w.base_workspace.get();
    }
    s.problem->evaluate(s.x, wanted_, false, out, *ws);
    r.status = mech::to_string(out.status);
    r.message = out.message;
    for (size_t k = 0; k < stored_.size(); ++k)
      if (out.has(stored_[k])) r.metrics[k] = out[stored_[k]].value;
  } catch (const mech::TimedOut& e) {
    r.status = mech::to_string(Status::timed_out);
    r.message = e.what();
    std::fill(r.metrics.begin(), r.metrics.end(), kNan);
  } catch (const ConfigError& e) {  // a factor value the model does not accept
    r.status = mech::to_string(Status::invalid_parameter);
    r.message = e.what();
    std::fill(r.metrics.begin(), r.metrics.end(), kNan);
  } catch (const std::exception& e) {
    r.status = mech::to_string(Status::evaluation_error);
    r.message = e.what();
    std::fill(r.metrics.begin(), r.metrics.end(), kNan);
  }
  mech::set_deadline(0);
  w.own_workspace.reset();
  s.own.reset();  // no problem outlives its sample in the worker's storage
  r.wall_time = since(t0);
}

}  // namespace opt::doe
