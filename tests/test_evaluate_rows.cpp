// opt::evaluate_rows, the batch behind the Python module's evaluate: every
// row once, the bits of one evaluation at a time whatever the threads, a
// stop request honoured between designs, a failing callback rethrown.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "opt/evaluate_rows.hpp"
#include "opt/interrupt.hpp"
#include "opt/registry.hpp"
#include "paths.hpp"

namespace {

std::unique_ptr<opt::Problem> conveyor() {
  return opt::make_problem(
      opt::ConfigNode::load(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage/conveyor_swing.yaml"));
}

// n designs within 40% of the initial one, row-major with a stride of
// k + 1 (a column the batch must skip).
std::vector<double> designs(const opt::Problem& p, int n) {
  const auto k = static_cast<int>(p.variables().size());
  const Eigen::VectorXd x0 = p.initial_point();
  std::vector<double> X(static_cast<size_t>(n * (k + 1)), -1.0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < k; ++j)
      X[static_cast<size_t>(i * (k + 1) + j)] = x0[j] * (0.6 + 0.8 * ((i * 7 + j * 3) % 17) / 16.0);
  return X;
}

TEST(EvaluateRows, EveryRowOnceWithTheBitsOfOneEvaluation) {
  const auto p = conveyor();
  const int n = 60;
  const auto k = static_cast<Eigen::Index>(p->variables().size());
  const std::vector<double> X = designs(*p, n);
  const opt::MetricSet wanted = p->metric_set({"rms_drive_torque", "rocker_stroke"});
  const opt::MetricId rms = p->metric_id("rms_drive_torque");
  for (int threads : {1, 2, 3}) {
    std::vector<double> got(n, NAN);
    std::vector<opt::Status> status(n);
    std::vector<std::atomic<int>> puts(n);
    ASSERT_TRUE(opt::evaluate_rows(*p, X.data(), n, k + 1, wanted, true, threads,
                                   [&](std::int64_t i, const opt::Evaluation& e) {
      ++puts[static_cast<size_t>(i)];
      status[static_cast<size_t>(i)] = e.status;
      if (e.has(rms)) got[static_cast<size_t>(i)] = e[rms].value;
    }));
    int ok = 0;
    for (int i = 0; i < n; ++i) {
      ASSERT_EQ(puts[static_cast<size_t>(i)], 1) << i;
      const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(X.data() + i * (k + 1), k);
      const opt::Evaluation e = p->evaluate(x, wanted, true);
      ASSERT_EQ(status[static_cast<size_t>(i)], e.status) << i;
      if (!e.ok()) continue;
      ++ok;
      EXPECT_EQ(got[static_cast<size_t>(i)], e[rms].value) << i;  // the same bits
    }
    EXPECT_GT(ok, 10);
    EXPECT_LT(ok, n);  // the box holds designs that are not ok too
  }
}

TEST(EvaluateRows, StopsBetweenDesignsWhenAStopIsRequested) {
  const auto p = conveyor();
  const int n = 200;
  const std::vector<double> X = designs(*p, n);
  std::atomic<int> puts{0};
  opt::clear_stop();
  const bool done = opt::evaluate_rows(*p, X.data(), n, static_cast<std::int64_t>(p->variables().size()) + 1,
                                       opt::MetricSet::all(), false, 2, [&](std::int64_t, const opt::Evaluation&) {
    if (++puts == 5) opt::request_stop();
  });
  const bool stopped = opt::stop_requested();
  opt::clear_stop();
  EXPECT_TRUE(stopped);
  EXPECT_FALSE(done);
  EXPECT_LT(puts, 8);  // the designs under way when the stop came, no more
}

TEST(EvaluateRows, ACallbackThatThrowsStopsTheBatchAndIsRethrown) {
  const auto p = conveyor();
  const int n = 100;
  const std::vector<double> X = designs(*p, n);
  std::atomic<int> puts{0};
  EXPECT_THROW(opt::evaluate_rows(*p, X.data(), n, static_cast<std::int64_t>(p->variables().size()) + 1,
                                  opt::MetricSet::all(), false, 2, [&](std::int64_t i, const opt::Evaluation&) {
                 ++puts;
                 if (i == 3) throw std::runtime_error("full");
               }),
               std::runtime_error);
  EXPECT_LT(puts, n);
}

}  // namespace
