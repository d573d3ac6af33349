// Quantities with units in configs: "0.2 m", "100 rev/min", "2 kN m s/rad".
// Values are converted to SI (angles to radians); a bare number is SI.
//
// A unit is read by a grammar, not looked up in a list:
//
//   QUANTITY = NUMBER [UNIT]
//   UNIT     = PRODUCT ['/' PRODUCT] | '1' '/' PRODUCT
//   PRODUCT  = FACTOR {SEP FACTOR}        SEP: one or more spaces, '*', '·', '⋅' or '.'
//   FACTOR   = [PREFIX] SYMBOL [POWER]    POWER: '^' [-+] DIGITS, or superscripts (², ³, ⁻¹)
//
// Everything after the one '/' is the denominator: "kg/m s" is kg/(m s); a
// second '/' is an error. A name is looked up whole first ("min", "kgf", "Pa",
// "PS"), then as a prefix and a symbol that takes prefixes ("mm": milli +
// metre, "kPa"); no whole name is also a prefix and a symbol, and no two
// splits spell the same name (tests/test_units.cpp checks), so the reading is
// unique. Prefixes: T G M k h d c m u µ μ n, and the Cyrillic Г М к д с м мк н
// with Cyrillic symbols only (кгс/см², кН м). Symbols that take them: m g s
// rad N J W Pa bar (and м г с рад Н Дж Вт Па бар); t min h deg ° rev rpm gf
// kgf tf hp PS take none. The tables (kSymbols, kPrefixes in units.cpp) are
// listed by `mechopt list` and in docs/config.md.
//
// A parsed unit has exponents of mass, length, time and angle (the radian is
// a dimension of its own, so rev/min is an angular speed and N m/rad a
// rotational stiffness, neither a plain frequency nor a torque). It fits a
// Dimension whose exponents are the same. Dimensions with equal exponents (a
// torque N m and an energy J) are told apart by the spelling: a unit with a
// symbol that marks one of them (J, W for the energy) is that one, any other
// spelling the first in the enum (torque). A mismatch names both dimensions.
//
// The SI value is number x (the symbols' factors) x 10^(the prefixes' and
// symbols' decimal powers), computed in long double and rounded to double
// once, so it lies within one ulp of the exact product (x86-64, where long
// double has a 64-bit mantissa; the decimal factors kgf, hp, PS and the
// powers of ten up to 10^27 are exact in it). A unit whose scale is exactly 1
// (the SI spellings, "kg", "N m/rad") keeps strtod's value bit for bit.
#pragma once
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace opt {

// The kind of a value: exponents above, and the name the tables and messages
// use. New kinds go at the end (a value's kind is never stored as a number,
// but the order decides ties, see above).
enum class Dimension {
  dimensionless, length, angle, angular_speed, mass, linear_density, force, time, torque,
  energy, rotational_stiffness, linear_stiffness, rotational_damping, inertia, power,
  pressure, inverse_length, acceleration, volume_rate, power_per_length, area,
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
// The SI unit written in result files, e.g. "m", "rad", "rad/s".
std::string si_unit(Dimension d);

// The dimension of a coherent SI unit ("rad" -> angle, "N m" -> torque, "J"
// -> energy, "m/s^2" -> acceleration); dimensionless when the unit does not
// parse, has a scale other than 1 or fits no dimension.
Dimension dimension_of(const std::string& unit);

struct ParsedQuantity {
  double value = 0;
  std::string error;  // empty when parsed
};

// Parses "NUMBER [UNIT]" as a quantity of dimension d (grammar above). A
// dimensionless d takes a bare number or a unit whose exponents cancel
// ("5 mm/m" is 0.005).
ParsedQuantity parse_quantity(const std::string& text, Dimension d);

// --- For `mechopt list` and docs/config.md --------------------------------

// The grammar in one line, for error messages: "a unit multiplies symbols ...".
std::string unit_grammar();
// Every dimension but dimensionless, in the enum's order.
std::vector<Dimension> unit_dimensions();
// Spellings of a dimension other than its SI unit, e.g. {"kN m/rad", ...}.
std::array<const char*, 3> unit_examples(Dimension d);

struct UnitSymbol {
  std::string name;     // "kgf"
  std::string meaning;  // "kilogram-force, 9.80665 N"; "Cyrillic kgf" for кгс
  bool prefixed;        // takes SI prefixes
};
const std::vector<UnitSymbol>& unit_symbols();
struct UnitPrefix {
  std::string name;  // "k"
  int power;         // 3: the prefix is 10^3
};
const std::vector<UnitPrefix>& unit_prefixes();

}  // namespace opt
