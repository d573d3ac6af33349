#include "opt/units.hpp"

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <sstream>

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
    {"MN", Dimension::force, 1e6},          {"tf", Dimension::force, 9806.65},  // tonne-force
    {"s", Dimension::time, 1.0},            {"ms", Dimension::time, 1e-3}, {"us", Dimension::time, 1e-6},
    {"N m", Dimension::torque, 1.0},        {"kN m", Dimension::torque, 1e3},
    {"J", Dimension::energy, 1.0},          {"kJ", Dimension::energy, 1e3},
    {"N m/rad", Dimension::rotational_stiffness, 1.0},
    {"kN m/rad", Dimension::rotational_stiffness, 1e3},
    {"N/m", Dimension::linear_stiffness, 1.0}, {"kN/m", Dimension::linear_stiffness, 1e3},
    {"N m s/rad", Dimension::rotational_damping, 1.0},
    {"kg m^2", Dimension::inertia, 1.0},
    {"W", Dimension::power, 1.0},           {"kW", Dimension::power, 1e3},
    {"Pa", Dimension::pressure, 1.0},       {"MPa", Dimension::pressure, 1e6},
    {"1/m", Dimension::inverse_length, 1.0}, {"1/mm", Dimension::inverse_length, 1e3},
};

// "kN*m / rad" -> "kN m/rad": factors separated by one space, none around '/'.
std::string normalize_unit(std::string u) {
  std::string out;
  for (char c : u) {
    if (c == '*') c = ' ';
    if (c == ' ' && (out.empty() || out.back() == ' ' || out.back() == '/')) continue;
    if (c == '/' && !out.empty() && out.back() == ' ') out.pop_back();
    out += c;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

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
    case Dimension::torque: return "a torque";
    case Dimension::energy: return "an energy";
    case Dimension::rotational_stiffness: return "a rotational stiffness";
    case Dimension::linear_stiffness: return "a linear stiffness";
    case Dimension::rotational_damping: return "a rotational damping";
    case Dimension::inertia: return "a moment of inertia";
    case Dimension::power: return "a power";
    case Dimension::pressure: return "a pressure";
    case Dimension::inverse_length: return "an inverse length";
  }
  return "a quantity";
}

std::string to_string(const Domain& d, Dimension dim) {
  auto number = [](double x) {
    std::ostringstream s;
    s << x;
    return s.str();
  };
  const bool lo = std::isfinite(d.lo), hi = std::isfinite(d.hi);
  std::string out;
  if (!lo && !hi) out = "any";
  else if (!hi) out = std::string(d.lo_open ? "> " : ">= ") + number(d.lo);
  else if (!lo) out = std::string(d.hi_open ? "< " : "<= ") + number(d.hi);
  else out = std::string(d.lo_open ? "(" : "[") + number(d.lo) + ", " + number(d.hi) + (d.hi_open ? ")" : "]");
  return si_unit(dim).empty() || out == "any" ? out : out + " " + si_unit(dim);
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
  for (char& c : unit)
    if (c == '\t') c = ' ';
  unit = normalize_unit(unit);
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
