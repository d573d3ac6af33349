// A problem of this program's own, a four-bar's least transmission angle in
// closed form, registered by name through libopt's registry (as mechopt's
// own problems register theirs), made from a config and evaluated; then a
// built-in problem of the installed library beside it.
#include <cmath>
#include <iostream>
#include <memory>

#include "opt/config.hpp"
#include "opt/registry.hpp"

namespace {

// A crank-rocker a-b-c on a frame d: the transmission angle runs between
// acos((b^2 + c^2 - (d - a)^2) / 2bc) and acos((b^2 + c^2 - (d + a)^2) / 2bc);
// its least departure from 90 deg is the metric. Variable: the coupler b.
class FourBarTransmission : public opt::Problem {
 public:
  FourBarTransmission(double a, double c, double d, double b) : a_(a), c_(c), d_(d) {
    vars_ = {{"coupler", opt::Dimension::length, 0.5 * b, 2 * b, b}};
  }
  std::string name() const override { return "consumer_four_bar"; }
  const std::vector<opt::Variable>& variables() const override { return vars_; }
  const std::vector<std::string>& metric_names() const override { return names_; }
  std::string metric_unit(const std::string&) const override { return "rad"; }
  nlohmann::json settings() const override { return {{"crank", a_}, {"rocker", c_}, {"frame", d_}}; }
  bool provides_gradients() const override { return false; }

 protected:
  opt::Evaluation evaluate_model_at(const Eigen::VectorXd& x, const opt::MetricSet&, bool) const override {
    const double b = x[0];
    const double lo = (b * b + c_ * c_ - (d_ - a_) * (d_ - a_)) / (2 * b * c_);
    const double hi = (b * b + c_ * c_ - (d_ + a_) * (d_ + a_)) / (2 * b * c_);
    opt::Evaluation e;
    if (std::abs(lo) > 1 || std::abs(hi) > 1) {
      e.status = opt::Status::cannot_assemble;
      return e;
    }
    e.set(0, {std::min(std::acos(lo), M_PI - std::acos(hi)), {}});
    return e;
  }

 private:
  double a_, c_, d_;
  std::vector<opt::Variable> vars_;
  std::vector<std::string> names_ = {"min_transmission_angle"};
};

const opt::Registration kRegistration{
    {"consumer_four_bar", "a crank-rocker's least transmission angle (examples/consumer)", {},
     [](const opt::ConfigNode& root) -> std::unique_ptr<opt::Problem> {
       const opt::ConfigNode m = root.at("model");
       auto length = [&](const char* key) { return m.at(key).quantity(opt::Dimension::length, opt::kPositive); };
       return std::make_unique<FourBarTransmission>(length("crank"), length("rocker"), length("frame"),
                                                    length("coupler"));
     }}};

}  // namespace

int main() {
  const auto own = opt::make_problem(opt::ConfigNode::parse(
      "problem: consumer_four_bar\nmodel: {crank: 100 mm, coupler: 0.45 m, rocker: 0.35 m, frame: 0.4 m}\n",
      "<consumer>"));
  const double mu = own->evaluate(own->initial_point(), {"min_transmission_angle"}, false).at("min_transmission_angle");
  std::cout << "consumer_four_bar min_transmission_angle " << mu * 180 / M_PI << " deg\n";
  const auto builtin = opt::make_problem(opt::ConfigNode::parse("problem: recuperative_drive\n", "<consumer>"));
  std::cout << "recuperative_drive mean_kinetic_energy "
            << builtin->evaluate(builtin->initial_point(), {"mean_kinetic_energy"}, false).at("mean_kinetic_energy")
            << " J\n";
  int registered = 0;
  for (const auto& e : opt::registry()) registered += e.name == "consumer_four_bar" || e.name == "linkage";
  std::cout << "registered " << registered << " of consumer_four_bar, linkage\n";
  return registered == 2 ? 0 : 1;
}
