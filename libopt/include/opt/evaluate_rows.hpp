// Many designs at once over threads: the Python module's Problem.evaluate,
// and any C++ caller with a matrix of designs.
#pragma once
#include <cstdint>
#include <functional>

#include "opt/problem.hpp"

namespace opt {

// Evaluates the designs in rows [0, n) of X, row i's variables().size()
// values at X + i * stride, over `threads` threads (0: every core), each
// with its own workspace and Evaluation, taking contiguous ranges of rows
// with stealing (opt::Ranges). put(i, e) is called once for each design
// from the thread that evaluated it. opt::stop_requested() is polled
// between designs: the result is false when the work stopped early (some
// rows then have no put). A design whose evaluation throws gets the status
// evaluation_error with the exception's message, as a DOE records it; an
// exception from put stops every thread and is rethrown here.
bool evaluate_rows(const Problem& p, const double* X, std::int64_t n, std::int64_t stride, const MetricSet& wanted,
                   bool gradient, int threads, const std::function<void(std::int64_t, const Evaluation&)>& put);

}  // namespace opt
