// Quantities with units in configs: "0.2 m", "100 rpm", "90 deg". Values are
// converted to SI (angles to radians); a bare number is taken as SI already.
#pragma once
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace opt {

enum class Dimension {
  dimensionless, length, angle, angular_speed, mass, linear_density, force, time, torque,
  energy, rotational_stiffness, linear_stiffness, rotational_damping, inertia, power,
  pressure, inverse_length,
};

// Where a quantity may lie (SI), with open or closed ends.
struct Domain {
  double lo = -HUGE_VAL, hi = HUGE_VAL;
  bool lo_open = false, hi_open = false;
  bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
};
inline const Domain kAnyValue{};
inline const Domain kPositive{0, HUGE_VAL, true, false};
inline const Domain kNonNegative{0, HUGE_VAL, false, false};

std::string to_string(Dimension d);
// "any", "> 0 m", "(0, 1]": the domain with the SI unit of dim.
std::string to_string(const Domain& d, Dimension dim);
// The unit names accepted for a dimension, e.g. {"m", "mm", "cm"} for length.
std::vector<std::string> units_of(Dimension d);
// The SI unit written in result files, e.g. "m", "rad", "rad/s".
std::string si_unit(Dimension d);

// The dimension whose SI unit is `unit` ("rad" -> angle); dimensionless when
// none is (e.g. "N m", "J": bounds on such metrics are plain SI numbers).
Dimension dimension_of(const std::string& unit);

struct ParsedQuantity {
  double value = 0;
  std::string error;  // empty when parsed
};

// Parses "NUMBER [UNIT]" as a quantity of dimension d. Units are written
// with spaces or '*' between factors: "110 kN m/rad", "0.32 kg*m^2".
ParsedQuantity parse_quantity(const std::string& text, Dimension d);

}  // namespace opt
