#include "opt/units.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <sstream>
#include <utility>

namespace opt {
namespace {

// Exponents of mass, length, time and angle.
using Exponents = std::array<long long, 4>;
constexpr Exponents kNone{0, 0, 0, 0}, kMass{1, 0, 0, 0}, kLength{0, 1, 0, 0}, kTime{0, 0, 1, 0},
    kAngle{0, 0, 0, 1}, kForce{1, 1, -2, 0}, kEnergy{1, 2, -2, 0}, kPower{1, 2, -3, 0},
    kPressure{1, -1, -2, 0}, kAngularSpeed{0, 0, -1, 1};

struct Kind {
  Dimension d;
  Exponents e;
  const char* name;
  const char* si;
  std::array<const char*, 3> examples;
};

// In the enum's order (checked in to_string); the first of equal exponents
// wins a tie that no marking symbol decides.
const Kind kKinds[] = {
    {Dimension::dimensionless, kNone, "a plain number", "", {"", "", ""}},
    {Dimension::length, kLength, "a length", "m", {"mm", "cm", "мм"}},
    {Dimension::angle, kAngle, "an angle", "rad", {"deg", "rev", "°"}},
    {Dimension::angular_speed, kAngularSpeed, "an angular speed", "rad/s", {"rpm", "rev/min", "deg/s"}},
    {Dimension::mass, kMass, "a mass", "kg", {"t", "g", "кг"}},
    {Dimension::linear_density, {1, -1, 0, 0}, "a mass per length", "kg/m", {"kg/mm", "t/m", "g/cm"}},
    {Dimension::force, kForce, "a force", "N", {"kN", "kgf", "тс"}},
    {Dimension::time, kTime, "a time", "s", {"ms", "min", "h"}},
    {Dimension::torque, kEnergy, "a torque", "N m", {"kN m", "N·m", "kgf m"}},
    {Dimension::energy, kEnergy, "an energy", "J", {"kJ", "kW h", "W s"}},
    {Dimension::rotational_stiffness, {1, 2, -2, -1}, "a rotational stiffness", "N m/rad",
     {"kN m/rad", "MN*m/rad", "N m/deg"}},
    {Dimension::linear_stiffness, {1, 0, -2, 0}, "a linear stiffness", "N/m", {"kN/m", "N/mm", "kgf/cm"}},
    {Dimension::rotational_damping, {1, 2, -1, -1}, "a rotational damping", "N m s/rad",
     {"kN m s/rad", "N m min/rev", "кН м с/рад"}},
    {Dimension::inertia, {1, 2, 0, 0}, "a moment of inertia", "kg m^2", {"t m^2", "kg·m²", "kgf m s^2"}},
    {Dimension::power, kPower, "a power", "W", {"kW", "hp", "PS"}},
    {Dimension::pressure, kPressure, "a pressure", "Pa", {"MPa", "bar", "kgf/cm^2"}},
    {Dimension::inverse_length, {0, -1, 0, 0}, "an inverse length", "1/m", {"1/mm", "m^-1", "1/cm"}},
    {Dimension::acceleration, {0, 1, -2, 0}, "an acceleration", "m/s^2", {"mm/s^2", "m s^-2", "m/s²"}},
    {Dimension::volume_rate, {0, 3, -1, 0}, "a volume rate", "m^3/s", {"m^3/h", "mm^3/s", "м³/ч"}},
    {Dimension::power_per_length, {1, 1, -3, 0}, "a power per length", "W/m", {"kW/m", "W/mm", "hp/m"}},
    {Dimension::area, {0, 2, 0, 0}, "an area", "m^2", {"cm^2", "mm^2", "м²"}},
};

const Kind& kind(Dimension d) { return kKinds[static_cast<size_t>(d)]; }

constexpr long double kPi = std::numbers::pi_v<long double>;

// A symbol is factor x 10^pow10 SI units of its exponents; the decimal part
// of a factor is kept in pow10 so that kgf (980665 x 10^-5) is exact.
struct Symbol {
  const char* name;
  Exponents e;
  long double factor;
  int pow10;
  bool prefixed;
  const char* meaning;
  Dimension marks = Dimension::dimensionless;  // the dimension it names in a tie
};

const Symbol kSymbols[] = {
    {"m", kLength, 1, 0, true, "metre"},
    {"g", kMass, 1, -3, true, "gram (kg: kilogram)"},
    {"t", kMass, 1, 3, false, "tonne, 1000 kg"},
    {"s", kTime, 1, 0, true, "second"},
    {"min", kTime, 60, 0, false, "minute, 60 s"},
    {"h", kTime, 3600, 0, false, "hour, 3600 s"},
    {"rad", kAngle, 1, 0, true, "radian"},
    {"deg", kAngle, kPi / 180, 0, false, "degree, π/180 rad"},
    {"°", kAngle, kPi / 180, 0, false, "degree"},
    {"rev", kAngle, 2 * kPi, 0, false, "revolution, 2π rad"},
    {"rpm", kAngularSpeed, kPi / 30, 0, false, "revolution per minute, rev/min"},
    {"N", kForce, 1, 0, true, "newton"},
    {"gf", kForce, 980665, -8, false, "gram-force, 9.80665e-3 N"},
    {"kgf", kForce, 980665, -5, false, "kilogram-force, 9.80665 N (standard gravity)"},
    {"tf", kForce, 980665, -2, false, "tonne-force, 9806.65 N"},
    {"J", kEnergy, 1, 0, true, "joule (an energy, never a torque)", Dimension::energy},
    {"W", kPower, 1, 0, true, "watt (W s, W h: an energy)", Dimension::energy},
    {"hp", kPower, 74569987158227022.0L, -14, false, "mechanical horsepower, 550 ft lbf/s = 745.69987158227022 W"},
    {"PS", kPower, 73549875, -5, false, "metric horsepower, 75 kgf m/s = 735.49875 W"},
    {"Pa", kPressure, 1, 0, true, "pascal"},
    {"bar", kPressure, 1, 5, true, "bar, 10^5 Pa"},
};

// The Cyrillic spellings of the seeds: the same symbols.
const std::pair<const char*, const char*> kCyrillic[] = {
    {"м", "m"},     {"г", "g"},   {"т", "t"},   {"с", "s"},   {"мин", "min"}, {"ч", "h"},   {"рад", "rad"},
    {"град", "deg"}, {"об", "rev"}, {"Н", "N"},   {"гс", "gf"}, {"кгс", "kgf"}, {"тс", "tf"}, {"Дж", "J"},
    {"Вт", "W"},    {"Па", "Pa"}, {"бар", "bar"},
};

struct Prefix {
  const char* name;
  int pow10;
};
const Prefix kPrefixes[] = {
    {"T", 12}, {"G", 9},  {"M", 6},  {"k", 3},  {"h", 2},  {"d", -1}, {"c", -2}, {"m", -3},
    {"u", -6}, {"µ", -6}, {"μ", -6}, {"n", -9}, {"Г", 9},  {"М", 6},  {"к", 3},  {"д", -1},
    {"с", -2}, {"м", -3}, {"мк", -6}, {"н", -9},
};

bool cyrillic(const std::string& s) {
  const auto c = static_cast<unsigned char>(s.empty() ? 0 : s[0]);
  return c >= 0xD0 && c <= 0xD4;
}

bool starts(const std::string& s, size_t i, const char* with) { return s.compare(i, std::string(with).size(), with) == 0; }

// The separators a symbol cannot contain: '·', '⋅' (products) and the
// superscripts (powers), all UTF-8.
const char* const kProductSigns[] = {"·", "⋅"};
const char* const kSuperscripts[] = {"⁰", "¹", "²", "³", "⁴", "⁵", "⁶", "⁷", "⁸", "⁹", "⁻", "⁺"};

size_t sign_at(const std::string& u, size_t i, const char* const* signs, size_t n, int* which = nullptr) {
  for (size_t k = 0; k < n; ++k)
    if (starts(u, i, signs[k])) {
      if (which) *which = static_cast<int>(k);
      return std::string(signs[k]).size();
    }
  return 0;
}
size_t product_sign_at(const std::string& u, size_t i) { return sign_at(u, i, kProductSigns, 2); }
size_t superscript_at(const std::string& u, size_t i, int* which = nullptr) {
  return sign_at(u, i, kSuperscripts, 12, which);
}

// The length of the symbol character at i (an ASCII letter or any UTF-8
// character but the signs above), 0 when there is none.
size_t symbol_char_at(const std::string& u, size_t i) {
  const auto c = static_cast<unsigned char>(u[i]);
  if (c < 0x80) return std::isalpha(c) ? 1 : 0;
  if (product_sign_at(u, i) || superscript_at(u, i)) return 0;
  size_t n = 1;
  while (i + n < u.size() && (static_cast<unsigned char>(u[i + n]) & 0xC0) == 0x80) ++n;
  return n;
}

struct Resolved {
  const Symbol* symbol = nullptr;
  int prefix = 0;  // its decimal power
};

const Symbol* lookup(const std::string& name) {
  for (const auto& s : kSymbols)
    if (name == s.name) return &s;
  for (const auto& [spelling, latin] : kCyrillic)
    if (name == spelling) return lookup(latin);
  return nullptr;
}

// The whole name first, then prefix + a symbol that takes prefixes.
Resolved resolve(const std::string& name) {
  if (const Symbol* s = lookup(name)) return {s, 0};
  for (const auto& p : kPrefixes) {
    if (name.rfind(p.name, 0) != 0) continue;
    const std::string rest = name.substr(std::string(p.name).size());
    const Symbol* s = lookup(rest);
    if (s && s->prefixed && cyrillic(rest) == cyrillic(p.name)) return {s, p.pow10};
  }
  return {};
}

// A parsed unit: SI value = number x num / den x 10^pow10.
struct Unit {
  Exponents e{};
  long double num = 1, den = 1;
  long long pow10 = 0;
  std::vector<Dimension> marks;
  std::string error;
};

// 1-based position of byte i in characters, for messages.
size_t column(const std::string& u, size_t i) {
  size_t col = 1;
  for (size_t k = 0; k < i && k < u.size(); ++k) col += (static_cast<unsigned char>(u[k]) & 0xC0) != 0x80;
  return col;
}

constexpr int kMaxPower = 99;

Unit parse_unit(const std::string& u) {
  Unit out;
  auto fail = [&](const std::string& what, size_t i) {
    out.error = what + " at character " + std::to_string(column(u, i)) + " of '" + u + "'; " + unit_grammar();
    return out;
  };
  auto character = [&](size_t i) {
    size_t n = 1;
    while (i + n < u.size() && (static_cast<unsigned char>(u[i + n]) & 0xC0) == 0x80) ++n;
    return "'" + u.substr(i, n) + "'";
  };
  size_t i = 0;
  bool denominator = false, need_factor = true, spaced = false;
  if (u[0] == '1') {  // "1/m"
    size_t j = 1;
    while (j < u.size() && u[j] == ' ') ++j;
    if (j < u.size() && u[j] == '/') {
      i = 1;
      need_factor = false;
    }
  }
  while (true) {
    const size_t before = i;
    while (i < u.size() && u[i] == ' ') ++i;
    spaced = i > before;
    if (i == u.size()) {
      if (need_factor) return fail("a symbol is missing", i);
      return out;
    }
    const size_t sign = u[i] == '*' || u[i] == '.' ? 1 : product_sign_at(u, i);
    if (u[i] == '/') {
      if (denominator) return fail("a second '/' (everything after the first is the denominator)", i);
      if (need_factor) return fail("no symbol before '/' (1/s for a reciprocal)", i);
      denominator = need_factor = true;
      ++i;
      continue;
    }
    if (sign) {
      if (need_factor) return fail("a symbol is missing before " + character(i), i);
      need_factor = true;
      i += sign;
      continue;
    }
    if (!symbol_char_at(u, i)) return fail("unexpected " + character(i), i);
    if (!need_factor && !spaced) return fail("expected ' ', '*' or '/' before " + character(i), i);
    // FACTOR
    const size_t start = i;
    while (i < u.size() && symbol_char_at(u, i)) i += symbol_char_at(u, i);
    const std::string name = u.substr(start, i - start);
    const Resolved r = resolve(name);
    if (!r.symbol) return fail("unknown unit symbol '" + name + "'", start);
    long long power = 1;
    if (i < u.size() && u[i] == '^') {
      const size_t at = i++;
      const bool negative = i < u.size() && u[i] == '-';
      if (i < u.size() && (u[i] == '-' || u[i] == '+')) ++i;
      const size_t digits = i;
      power = 0;
      while (i < u.size() && std::isdigit(static_cast<unsigned char>(u[i])) && power <= kMaxPower)
        power = power * 10 + (u[i++] - '0');
      if (i == digits) return fail("'^' needs a whole number", at);
      if (power > kMaxPower) return fail("a power above " + std::to_string(kMaxPower), at);
      if (negative) power = -power;
    } else if (int which; superscript_at(u, i, &which)) {
      const size_t at = i;
      bool negative = false;
      if (which >= 10) {
        negative = which == 10;
        i += superscript_at(u, i);
      }
      power = 0;
      size_t digits = 0;
      while (superscript_at(u, i, &which) && which < 10 && power <= kMaxPower) {
        power = power * 10 + which;
        i += superscript_at(u, i);
        ++digits;
      }
      if (!digits) return fail("a superscript sign needs superscript digits", at);
      if (power > kMaxPower) return fail("a power above " + std::to_string(kMaxPower), at);
      if (negative) power = -power;
    }
    const Symbol& s = *r.symbol;
    const long long k = denominator ? -power : power;
    for (size_t d = 0; d < 4; ++d) out.e[d] += k * s.e[d];
    out.pow10 += k * (s.pow10 + r.prefix);
    for (long long n = 0; n < std::llabs(k); ++n) (k > 0 ? out.num : out.den) *= s.factor;
    if (s.marks != Dimension::dimensionless) out.marks.push_back(s.marks);
    need_factor = false;
  }
}

// The dimension a unit is: its exponents', a marked one in a tie.
std::optional<Dimension> kind_of(const Unit& u) {
  std::optional<Dimension> first;
  for (const auto& k : kKinds) {
    if (k.e != u.e) continue;
    for (Dimension m : u.marks)
      if (m == k.d) return k.d;
    if (!first) first = k.d;
  }
  return first;
}

// "kg m/s^2": exponents in SI base units, for a unit of no dimension.
std::string base_units(const Exponents& e) {
  const char* names[] = {"kg", "m", "s", "rad"};
  std::string num, den;
  for (size_t d = 0; d < 4; ++d) {
    if (!e[d]) continue;
    std::string& side = e[d] > 0 ? num : den;
    side += (side.empty() ? "" : " ") + std::string(names[d]);
    if (std::llabs(e[d]) != 1) side += "^" + std::to_string(std::llabs(e[d]));
  }
  return (num.empty() ? "1" : num) + (den.empty() ? "" : "/" + den);
}

// number x num / den x 10^pow10, rounded to double once.
double to_si(long double number, const Unit& u) {
  long double ten = 1;
  for (long long p = 0; p < std::min(std::llabs(u.pow10), 6000LL); ++p) ten *= 10;
  long double v = number * u.num;
  v = u.pow10 >= 0 ? v * ten : v / ten;
  return static_cast<double>(v / u.den);
}

}  // namespace

std::string to_string(Dimension d) {
  static_assert(std::size(kKinds) == static_cast<size_t>(Dimension::area) + 1);
  return kind(d).d == d ? kind(d).name : "a quantity";
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

std::string si_unit(Dimension d) { return kind(d).si; }

Dimension dimension_of(const std::string& unit) {
  if (unit.empty()) return Dimension::dimensionless;
  const Unit u = parse_unit(unit);
  if (!u.error.empty() || u.num != 1 || u.den != 1 || u.pow10 != 0) return Dimension::dimensionless;
  return kind_of(u).value_or(Dimension::dimensionless);
}

ParsedQuantity parse_quantity(const std::string& text, Dimension d) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double number = std::strtod(begin, &end);
  if (end == begin) return {0, "not a number"};
  if (!std::isfinite(number)) return {0, "not a finite number"};
  std::string unit(end);
  for (char& c : unit)
    if (c == '\t') c = ' ';
  unit.erase(0, unit.find_first_not_of(' '));
  unit.erase(unit.find_last_not_of(' ') + 1);
  if (unit.empty()) return {number, ""};
  const Unit u = parse_unit(unit);
  if (!u.error.empty()) return {0, u.error};
  const auto k = kind_of(u);
  if (!k) return {0, "unit '" + unit + "' is " + base_units(u.e) + ", no dimension of the tables"};
  if (*k != d) return {0, "unit '" + unit + "' is " + to_string(*k)};
  if (u.num == 1 && u.den == 1 && u.pow10 == 0) return {number, ""};
  const double v = to_si(std::strtold(begin, nullptr), u);
  if (!std::isfinite(v) || (v == 0 && number != 0)) return {0, "'" + text + "' is out of range in SI"};
  return {v, ""};
}

std::string unit_grammar() {
  return "a unit is symbols with SI prefixes and powers, multiplied by ' ', '*' or '·', everything after "
         "'/' dividing: 'kN m/rad', 'kg/mm', 'rev/min', 'kgf/cm^2' (mechopt list)";
}

std::vector<Dimension> unit_dimensions() {
  std::vector<Dimension> out;
  for (const auto& k : kKinds)
    if (k.d != Dimension::dimensionless) out.push_back(k.d);
  return out;
}

std::array<const char*, 3> unit_examples(Dimension d) { return kind(d).examples; }

const std::vector<UnitSymbol>& unit_symbols() {
  static const std::vector<UnitSymbol> out = [] {
    std::vector<UnitSymbol> v;
    for (const auto& s : kSymbols) v.push_back({s.name, s.meaning, s.prefixed});
    for (const auto& [spelling, latin] : kCyrillic)
      v.push_back({spelling, "Cyrillic " + std::string(latin), lookup(latin)->prefixed});
    return v;
  }();
  return out;
}

const std::vector<UnitPrefix>& unit_prefixes() {
  static const std::vector<UnitPrefix> out = [] {
    std::vector<UnitPrefix> v;
    for (const auto& p : kPrefixes) v.push_back({p.name, p.pow10});
    return v;
  }();
  return out;
}

}  // namespace opt
