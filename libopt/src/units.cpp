#include "opt/units.hpp"

#include <cmath>
#include <cstdlib>
#include <numbers>

namespace opt {
namespace {

struct Unit {
  const char* name;
  Dimension dim;
  double to_si;
};

constexpr double kPi = std::numbers::pi;
const Unit kUnits[] = {
    {"m", Dimension::length, 1.0},          {"mm", Dimension::length, 1e-3},
    {"cm", Dimension::length, 1e-2},        {"rad", Dimension::angle, 1.0},
    {"deg", Dimension::angle, kPi / 180},   {"rad/s", Dimension::angular_speed, 1.0},
    {"rpm", Dimension::angular_speed, kPi / 30}, {"kg", Dimension::mass, 1.0},
    {"t", Dimension::mass, 1e3},            {"kg/m", Dimension::linear_density, 1.0},
    {"N", Dimension::force, 1.0},           {"kN", Dimension::force, 1e3},
    {"s", Dimension::time, 1.0},            {"ms", Dimension::time, 1e-3},
};

}  // namespace

std::string to_string(Dimension d) {
  switch (d) {
    case Dimension::dimensionless: return "a plain number";
    case Dimension::length: return "a length";
    case Dimension::angle: return "an angle";
    case Dimension::angular_speed: return "an angular speed";
    case Dimension::mass: return "a mass";
    case Dimension::linear_density: return "a mass per length";
    case Dimension::force: return "a force";
    case Dimension::time: return "a time";
  }
  return "a quantity";
}

std::vector<std::string> units_of(Dimension d) {
  std::vector<std::string> out;
  for (const auto& u : kUnits)
    if (u.dim == d) out.push_back(u.name);
  return out;
}

std::string si_unit(Dimension d) {
  for (const auto& u : kUnits)
    if (u.dim == d && u.to_si == 1.0) return u.name;
  return "";
}

Dimension dimension_of(const std::string& unit) {
  for (const auto& u : kUnits)
    if (u.to_si == 1.0 && unit == u.name) return u.dim;
  return Dimension::dimensionless;
}

ParsedQuantity parse_quantity(const std::string& text, Dimension d) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double number = std::strtod(begin, &end);
  if (end == begin) return {0, "not a number"};
  std::string unit(end);
  unit.erase(0, unit.find_first_not_of(" \t"));
  unit.erase(unit.find_last_not_of(" \t") + 1);
  if (!std::isfinite(number)) return {0, "not a finite number"};
  if (unit.empty()) return {number, ""};
  for (const auto& u : kUnits) {
    if (unit != u.name) continue;
    if (u.dim != d) return {0, "unit '" + unit + "' is " + to_string(u.dim)};
    return {number * u.to_si, ""};
  }
  return {0, "unknown unit '" + unit + "'"};
}

}  // namespace opt
