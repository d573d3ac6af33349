// A wall-clock limit on the evaluation under way in this thread (a batch's
// per-sample time limit). Long computations, the drive's integrations, check
// it in their callbacks and end with status timed_out; the algebraic models
// take microseconds and never look.
#pragma once
#include <chrono>
#include <stdexcept>

namespace mech {

using Clock = std::chrono::steady_clock;

// Thrown by a check past the deadline; the drive dynamics turn it into the
// status timed_out.
class TimedOut : public std::runtime_error {
 public:
  TimedOut() : std::runtime_error("the evaluation ran past its time limit") {}
};

inline thread_local bool has_deadline = false;
inline thread_local Clock::time_point deadline;
inline thread_local unsigned deadline_calls = 0;

// Sets (seconds > 0) or clears (0) this thread's deadline, from now.
inline void set_deadline(double seconds) {
  has_deadline = seconds > 0;
  if (has_deadline)
    deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

// Reads the clock every 64th call: a right-hand side costs ~0.1 us and the
// clock ~20 ns, 8% of a limited elastic DOE's time if read on every call;
// 64 calls are microseconds past the limit at most.
inline void check_deadline() {
  if (has_deadline && (++deadline_calls & 63) == 0 && Clock::now() > deadline) throw TimedOut();
}

}  // namespace mech
