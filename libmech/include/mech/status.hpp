// Why a design could not be evaluated. An infeasible design is a value, never
// an exception and never a NaN.
#pragma once
#include <string_view>

namespace mech {

enum class Status {
  ok,
  cannot_assemble,     // the rod cannot reach the slider axis somewhere on the cycle
  invalid_parameter,   // a length, mass or speed outside its physical domain
  not_grashof,         // four-bar: no link can turn fully (s + l > p + q)
  toggle_in_cycle,     // four-bar: the crank meets a toggle before a full turn
  synthesis_failed,    // four-bar: the extreme positions give no crank-rocker
};

inline std::string_view to_string(Status s) {
  switch (s) {
    case Status::ok: return "ok";
    case Status::cannot_assemble: return "cannot_assemble";
    case Status::invalid_parameter: return "invalid_parameter";
    case Status::not_grashof: return "not_grashof";
    case Status::toggle_in_cycle: return "toggle_in_cycle";
    case Status::synthesis_failed: return "synthesis_failed";
  }
  return "unknown";
}

}  // namespace mech
