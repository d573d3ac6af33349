// A parameter table built at run time, its rows named by the config (as the
// general linkage's points and links will be): the same reading, units,
// domains, variables, exact gradients and located errors as a problem's
// fixed table. The problem here: the lengths a config names under `model`,
// and their total.
#include <gtest/gtest.h>

#include "opt/model_problem.hpp"
#include "opt/registry.hpp"

namespace {

// One length row per key the config writes under `model`.
std::vector<opt::Parameter> table_of(const opt::ConfigNode& root) {
  std::vector<opt::Parameter> rows;
  if (root.has("model"))
    for (const auto& key : root.at("model").keys()) {
      rows.push_back(opt::variable(key, opt::Dimension::length, opt::kPositive, "a named length", ""));
      rows.back().value = 1.0;
    }
  return rows;
}

class NamedLengths : public opt::ModelProblem<NamedLengths> {
 public:
  enum Metric { total_length };
  NamedLengths(std::vector<opt::Parameter> table, opt::Values<double> values, std::vector<opt::Variable> vars)
      : ModelProblem("named_lengths", {{total_length, "total_length", "m"}}, std::move(table), std::move(values),
                     std::move(vars)) {}
  template <class S>
  void evaluate_model(const opt::Values<S>& v, opt::MetricSink<S>& out) const {
    S sum(0.0);
    for (const S& length : v) sum += length;
    out.put(total_length, sum);
  }
  nlohmann::json settings() const override { return {{"model", model_json()}}; }
};

const opt::Registration kNamed{{"named_lengths", "test only: the total of the lengths a config names", {},
                                [](const opt::ConfigNode& root) {
                                  return opt::make_tabled<NamedLengths>(root, table_of(root));
                                }}};

std::unique_ptr<opt::Problem> make(const std::string& yaml) {
  return opt::make_problem(opt::ConfigNode::parse(yaml, "<named>"));
}

TEST(RuntimeTable, ValuesVariablesAndGradients) {
  const auto p = make(R"(
problem: named_lengths
model: {upper_arm: 0.3 m, forearm: 250 mm, hand: 8 cm}
variables: {forearm: {min: 0.1 m, max: 0.4 m, initial: 0.2 m}, hand: {min: 5 cm, max: 10 cm}}
)");
  ASSERT_EQ(p->variables().size(), 2u);
  const Eigen::VectorXd x = p->initial_point();
  EXPECT_DOUBLE_EQ(x[0], 0.2);
  EXPECT_DOUBLE_EQ(x[1], 0.08);  // a variable's initial defaults to its model value
  const auto e = p->evaluate(x, opt::MetricSet::all(), true);
  ASSERT_TRUE(e.ok());
  EXPECT_DOUBLE_EQ(e.at("total_length"), 0.3 + 0.2 + 0.08);
  const Eigen::VectorXd& g = e[p->metric_id("total_length")].gradient;  // d(sum)/d(each variable) = 1
  ASSERT_EQ(g.size(), 2);
  EXPECT_EQ(g[0], 1.0);
  EXPECT_EQ(g[1], 1.0);
  EXPECT_EQ(p->settings()["model"]["forearm"], 0.25);  // the config's value; the variable starts at 0.2
}

TEST(RuntimeTable, BadValuesAreLocatedErrors) {
  try {
    make("problem: named_lengths\nmodel: {upper_arm: 0.3 kg}\n");
    FAIL() << "a mass for a length was accepted";
  } catch (const opt::ConfigError& err) {
    const std::string what = err.what();
    EXPECT_NE(what.find("<named>"), std::string::npos) << what;
    EXPECT_NE(what.find("upper_arm"), std::string::npos) << what;
  }
  EXPECT_THROW(make("problem: named_lengths\nmodel: {upper_arm: -1 m}\n"), opt::ConfigError);  // outside > 0
  EXPECT_THROW(make("problem: named_lengths\nmodel: {upper_arm: 1 m}\nvariables: {elbow: {min: 0 m, max: 1 m}}\n"),
               opt::ConfigError);  // not a row of this config's table
}

}  // namespace
