// Quantities with units in configs: "0.2 m", "100 rpm", "90 deg". Values are
// converted to SI (angles to radians); a bare number is taken as SI already.
#pragma once
#include <optional>
#include <string>
#include <vector>

namespace opt {

enum class Dimension {
  dimensionless, length, angle, angular_speed, mass, linear_density, force, time,
};

std::string to_string(Dimension d);
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

// Parses "NUMBER [UNIT]" as a quantity of dimension d.
ParsedQuantity parse_quantity(const std::string& text, Dimension d);

}  // namespace opt
