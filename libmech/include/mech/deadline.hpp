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

// The limit on the evaluation under way in a thread.
struct Deadline {
  bool set = false;
  Clock::time_point at;
  unsigned calls = 0;  // checks since the thread began: the clock is read every 64th
};
// thread_local, not passed: SUNDIALS' callbacks check it and have no path
// for an argument; it is the batch's limit on the evaluation under way on
// that thread, set by the DOE worker around each sample.
inline thread_local Deadline thread_deadline;

// Sets (seconds > 0) or clears (0) this thread's deadline, from now.
inline void set_deadline(double seconds) {
  Deadline& d = thread_deadline;
  d.set = seconds > 0;
  if (d.set) d.at = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

// Reads the clock every 64th call: a right-hand side costs ~0.1 us and the
// clock ~20 ns, 8% of a limited elastic DOE's time if read on every call;
// 64 calls are microseconds past the limit at most.
inline void check_deadline() {
  Deadline& d = thread_deadline;
  if (d.set && (++d.calls & 63) == 0 && Clock::now() > d.at) throw TimedOut();
}

}  // namespace mech
