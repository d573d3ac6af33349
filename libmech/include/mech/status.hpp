// Why a design could not be evaluated. An infeasible design is a value, never
// an exception and never a NaN. The names are for output only (result files,
// tables); status_from_string reads them back.
#pragma once
#include <cstddef>
#include <iterator>
#include <optional>
#include <string_view>

namespace mech {

enum class Status {
  ok,
  cannot_assemble,     // the rod cannot reach the slider axis somewhere on the cycle
  invalid_parameter,   // a length, mass, speed or option outside its physical domain
  not_grashof,         // four-bar: no link can turn fully (s + l > p + q)
  toggle_in_cycle,     // four-bar: the crank meets a toggle before a full turn
  synthesis_failed,    // four-bar: the extreme positions give no crank-rocker
  stalled,             // drive: the crank stopped or turned back, no steady motion
  too_many_steps,      // drive: the integrator hit its step limit
  integration_failed,  // drive: error test or corrector failures in the integrator
  not_converged,       // drive: no periodic orbit (shooting or revolutions did not settle)
  non_finite,          // a metric came out NaN or infinite
  timed_out,           // the evaluation ran past its time limit (a batch's sample_time_limit)
  evaluation_error,    // an unexpected failure inside one evaluation, recorded with the design
  singular_position,   // linkage: a group passes a position where its branch could flip
};

// In the enum's order.
inline constexpr std::string_view kStatusNames[] = {
    "ok", "cannot_assemble", "invalid_parameter", "not_grashof", "toggle_in_cycle",
    "synthesis_failed", "stalled", "too_many_steps", "integration_failed", "not_converged",
    "non_finite", "timed_out", "evaluation_error", "singular_position"};
static_assert(std::size(kStatusNames) == static_cast<std::size_t>(Status::singular_position) + 1);

inline std::string_view to_string(Status s) {
  const auto i = static_cast<std::size_t>(s);
  return i < std::size(kStatusNames) ? kStatusNames[i] : "unknown";
}

// The status named `name` (as to_string writes it), or none.
inline std::optional<Status> status_from_string(std::string_view name) {
  for (std::size_t i = 0; i < std::size(kStatusNames); ++i)
    if (kStatusNames[i] == name) return static_cast<Status>(i);
  return std::nullopt;
}

}  // namespace mech
