// Optimisation test problems with documented optima, shared by the driver
// tests: NLopt's tutorial problem, Ipopt's HS071, a bounded Rosenbrock.
#pragma once
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "opt/problem.hpp"

namespace testing_problems {

// Analytic metrics: name -> (value, gradient) at x.
class Analytic : public opt::Problem {
 public:
  using Fn = std::function<opt::MetricValue(const Eigen::VectorXd&)>;
  Analytic(std::string name, std::vector<opt::Variable> vars, std::vector<std::pair<std::string, Fn>> metrics)
      : name_(std::move(name)), vars_(std::move(vars)), metrics_(std::move(metrics)) {
    for (const auto& m : metrics_) names_.push_back(m.first);
  }
  std::string name() const override { return name_; }
  const std::vector<opt::Variable>& variables() const override { return vars_; }
  const std::vector<std::string>& metric_names() const override { return names_; }
  std::string metric_unit(const std::string&) const override { return ""; }
  opt::Evaluation evaluate_model_at(const Eigen::VectorXd& x, const opt::MetricSet&,
                                    bool gradient) const override {
    if (throws) throw std::runtime_error("model exploded");
    opt::Evaluation e;
    for (size_t i = 0; i < metrics_.size(); ++i) {
      opt::MetricValue v = metrics_[i].second(x);
      if (!gradient) v.gradient.resize(0);
      e.set(static_cast<opt::MetricId>(i), std::move(v));
    }
    return e;
  }
  nlohmann::json settings() const override { return {}; }
  bool throws = false;

 private:
  std::string name_;
  std::vector<opt::Variable> vars_;
  std::vector<std::pair<std::string, Fn>> metrics_;
  std::vector<std::string> names_;
};

// NLopt tutorial: min sqrt(x2) s.t. x2 >= (a x1 + b)^3 for (a, b) = (2, 0),
// (-1, 1); minimum sqrt(8/27) = 0.544331053951817 at (1/3, 8/27).
inline Analytic tutorial() {
  auto cubic = [](double a, double b) {
    return [a, b](const Eigen::VectorXd& x) {
      const double t = a * x[0] + b;
      return opt::MetricValue{t * t * t - x[1], Eigen::Vector2d(3 * a * t * t, -1)};
    };
  };
  return Analytic("nlopt_tutorial",
                  {{"x1", opt::Dimension::dimensionless, -10, 10, 1.234},
                   {"x2", opt::Dimension::dimensionless, 1e-6, 10, 5.678}},
                  {{"f", [](const Eigen::VectorXd& x) {
                      return opt::MetricValue{std::sqrt(x[1]), Eigen::Vector2d(0, 0.5 / std::sqrt(x[1]))};
                    }},
                   {"c1", cubic(2, 0)},
                   {"c2", cubic(-1, 1)}});
}
inline const std::vector<opt::Constraint> kTutorialConstraints = {{"c1", true, 0}, {"c2", true, 0}};

// Ipopt's HS071: min x1 x4 (x1 + x2 + x3) + x3 s.t. x1 x2 x3 x4 >= 25,
// sum x^2 = 40, 1 <= x <= 5, from (1, 5, 5, 1); f* = 17.0140173.
inline Analytic hs071() {
  std::vector<opt::Variable> v;
  const double x0[4] = {1, 5, 5, 1};
  for (int i = 0; i < 4; ++i) v.push_back({"x" + std::to_string(i + 1), opt::Dimension::dimensionless, 1, 5, x0[i]});
  return Analytic(
      "hs071", v,
      {{"f", [](const Eigen::VectorXd& x) {
          Eigen::Vector4d g(x[3] * (2 * x[0] + x[1] + x[2]), x[0] * x[3], x[0] * x[3] + 1,
                            x[0] * (x[0] + x[1] + x[2]));
          return opt::MetricValue{x[0] * x[3] * (x[0] + x[1] + x[2]) + x[2], g};
        }},
       {"product", [](const Eigen::VectorXd& x) {
          Eigen::Vector4d g(x[1] * x[2] * x[3], x[0] * x[2] * x[3], x[0] * x[1] * x[3], x[0] * x[1] * x[2]);
          return opt::MetricValue{x[0] * x[1] * x[2] * x[3], g};
        }},
       {"squares", [](const Eigen::VectorXd& x) {
          return opt::MetricValue{x.squaredNorm(), Eigen::VectorXd(2 * x)};
        }}});
}
inline const std::vector<opt::Constraint> kHs071Constraints = {{"product", false, 25},
                                                               {"squares", true, 40, true}};

// Rosenbrock on x in [-1.5, 0.5], y in [-0.5, 1.5]: the bound x <= 0.5 cuts
// off (1, 1); the minimum is at (0.5, 0.25) with f* = 0.25 (df/dx = -1 < 0
// there, pressing on the bound).
inline Analytic rosenbrock() {
  return Analytic("rosenbrock_bounded",
                  {{"x", opt::Dimension::dimensionless, -1.5, 0.5, -1.2},
                   {"y", opt::Dimension::dimensionless, -0.5, 1.5, 1.0}},
                  {{"f", [](const Eigen::VectorXd& v) {
                      const double x = v[0], y = v[1];
                      return opt::MetricValue{(1 - x) * (1 - x) + 100 * (y - x * x) * (y - x * x),
                                              Eigen::Vector2d(-2 * (1 - x) - 400 * x * (y - x * x),
                                                              200 * (y - x * x))};
                    }}});
}

}  // namespace testing_problems
