#include "opt/evaluate_rows.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "opt/interrupt.hpp"
#include "opt/ranges.hpp"

namespace opt {

bool evaluate_rows(const Problem& p, const double* X, std::int64_t n, std::int64_t stride, const MetricSet& wanted,
                   bool gradient, int threads, const std::function<void(std::int64_t, const Evaluation&)>& put) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = static_cast<int>(std::clamp<std::int64_t>(n, 1, threads));
  const auto k = static_cast<Eigen::Index>(p.variables().size());
  Ranges ranges(0, n, threads);
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_m;
  auto work = [&](int t) {
    try {
      const auto ws = p.make_workspace();
      Evaluation e;
      Eigen::VectorXd x(k);
      std::int64_t want = 1;
      for (;;) {
        const auto [begin, end] = ranges.take(t, want);
        if (begin == end) return;
        const auto c0 = std::chrono::steady_clock::now();
        for (std::int64_t i = begin; i < end; ++i) {
          if (stop_requested() || failed) return;
          x = Eigen::Map<const Eigen::VectorXd>(X + i * stride, k);
          try {
            p.evaluate(x, wanted, gradient, e, *ws);
          } catch (const std::exception& ex) {  // this design's status, as a DOE records it
            e.clear();
            e.status = Status::evaluation_error;
            e.message = ex.what();
          }
          put(i, e);
        }
        const std::chrono::duration<double> took = std::chrono::steady_clock::now() - c0;
        want = next_chunk(took.count(), end - begin, 1);  // ~50 ms of this thread's work
      }
    } catch (...) {
      std::lock_guard lock(error_m);
      if (!error) error = std::current_exception();
      failed = true;
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  return !stop_requested();
}

}  // namespace opt
