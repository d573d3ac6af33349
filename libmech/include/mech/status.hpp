// Why a design could not be evaluated. An infeasible design is a value, never
// an exception and never a NaN.
#pragma once
#include <string_view>

namespace mech {

enum class Status {
  ok,
  cannot_assemble,     // the rod cannot reach the slider axis somewhere on the cycle
  invalid_parameter,   // a length, mass or speed outside its physical domain
};

inline std::string_view to_string(Status s) {
  switch (s) {
    case Status::ok: return "ok";
    case Status::cannot_assemble: return "cannot_assemble";
    case Status::invalid_parameter: return "invalid_parameter";
  }
  return "unknown";
}

}  // namespace mech
