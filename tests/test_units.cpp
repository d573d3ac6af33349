// Units as a grammar (opt/units.hpp): every dimension of the tables in its SI
// spelling, a prefixed one and a composed one, the spellings of issue 32, the
// '/' rule, the torque/energy tie, mismatch messages and malformed units.
//
// Reference values come from the definitions, written as decimal literals:
// exact where the definition is decimal (kgf = 9.80665 N, tf = 1000 kgf,
// hp = 550 ft lbf/s = 550 x 0.3048 m x 0.45359237 kg x 9.80665 m/s^2 / s =
// 745.69987158227022 W exactly, PS = 75 kgf m/s = 735.49875 W, bar = 1e5 Pa),
// and to 25 digits (mpmath) where pi enters (deg = pi/180 rad, rev = 2 pi rad).
// The compiler rounds each literal to the nearest double, half an ulp from the
// exact value; the parser's result is within half an ulp (and a few 2^-64
// relative of its long double arithmetic) too. So the two may differ by one
// ulp and no more: kOneUlp is the tolerance, as the issue asks.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <set>
#include <string>

#include "opt/config.hpp"
#include "opt/study.hpp"
#include "opt/units.hpp"
#include "opt/registry.hpp"

namespace {

using opt::Dimension;

// a and b are equal or neighbouring doubles.
bool within_one_ulp(double a, double b) { return a == b || std::nextafter(b, a) == a; }

struct Case {
  const char* text;
  Dimension d;
  double si;
};

void expect_cases(const std::vector<Case>& cases) {
  for (const auto& c : cases) {
    const auto q = opt::parse_quantity(c.text, c.d);
    EXPECT_TRUE(q.error.empty()) << c.text << ": " << q.error;
    EXPECT_TRUE(within_one_ulp(q.value, c.si)) << c.text << ": " << q.value << " vs " << c.si << " (diff "
                                               << q.value - c.si << ")";
  }
}

// Every Dimension: SI, prefixed, composed (and a Cyrillic spelling where the
// seeds use one).
TEST(Units, EveryDimensionInSiPrefixedAndComposedSpelling) {
  expect_cases({
      {"0.2 m", Dimension::length, 0.2},
      {"250 mm", Dimension::length, 0.25},
      {"250mm", Dimension::length, 0.25},
      {"1.5 km", Dimension::length, 1500},
      {"5 cm^3/cm^2", Dimension::length, 0.05},
      {"250 мм", Dimension::length, 0.25},
      {"1.5 rad", Dimension::angle, 1.5},
      {"2 mrad", Dimension::angle, 0.002},
      {"30 deg", Dimension::angle, 0.5235987755982988730771072},
      {"90°", Dimension::angle, 1.570796326794896619231322},
      {"0.25 rev", Dimension::angle, 1.570796326794896619231322},
      {"1 rpm min", Dimension::angle, 6.283185307179586476925287},
      {"3 rad/s", Dimension::angular_speed, 3},
      {"6 mrad/ms", Dimension::angular_speed, 6},
      {"100 rpm", Dimension::angular_speed, 10.47197551196597746154214},
      {"100 rev/min", Dimension::angular_speed, 10.47197551196597746154214},
      {"100 об/мин", Dimension::angular_speed, 10.47197551196597746154214},
      {"180 deg/s", Dimension::angular_speed, 3.141592653589793238462643},
      {"80 kg", Dimension::mass, 80},
      {"500 g", Dimension::mass, 0.5},
      {"2 t", Dimension::mass, 2000},
      {"3 кг", Dimension::mass, 3},
      {"2 kgf s^2/m", Dimension::mass, 19.6133},
      {"80 kg/m", Dimension::linear_density, 80},
      {"0.08 kg/mm", Dimension::linear_density, 80},
      {"5 g/cm", Dimension::linear_density, 0.5},
      {"0.5 t/m", Dimension::linear_density, 500},
      {"1.2 kg m^-1", Dimension::linear_density, 1.2},
      {"3562 N", Dimension::force, 3562},
      {"3.562 kN", Dimension::force, 3562},
      {"1.5 MN", Dimension::force, 1.5e6},
      {"363 kgf", Dimension::force, 3559.81395},
      {"5 tf", Dimension::force, 49033.25},
      {"10 кгс", Dimension::force, 98.0665},
      {"2 тс", Dimension::force, 19613.3},
      {"2 kg m/s^2", Dimension::force, 2},
      {"3 t m/s²", Dimension::force, 3000},
      {"2 s", Dimension::time, 2},
      {"5 ms", Dimension::time, 0.005},
      {"7 us", Dimension::time, 7e-6},
      {"7 µs", Dimension::time, 7e-6},
      {"3 min", Dimension::time, 180},
      {"1.5 h", Dimension::time, 5400},
      {"120 rev/rpm", Dimension::time, 7200},
      {"2 N m", Dimension::torque, 2},
      {"2 kN m", Dimension::torque, 2000},
      {"2 kN*m", Dimension::torque, 2000},
      {"2 kN·m", Dimension::torque, 2000},
      {"2 kN⋅m", Dimension::torque, 2000},
      {"2 kN.m", Dimension::torque, 2000},
      {"1.5 MN m", Dimension::torque, 1.5e6},
      {"5 kgf m", Dimension::torque, 49.03325},
      {"3 кН м", Dimension::torque, 3000},
      {"4 J", Dimension::energy, 4},
      {"4 kJ", Dimension::energy, 4000},
      {"5 MJ", Dimension::energy, 5e6},
      {"2 kW h", Dimension::energy, 7.2e6},
      {"3 W s", Dimension::energy, 3},
      {"2 Дж", Dimension::energy, 2},
      {"110 N m/rad", Dimension::rotational_stiffness, 110},
      {"110 kN m/rad", Dimension::rotational_stiffness, 110e3},
      {"110 kN*m / rad", Dimension::rotational_stiffness, 110e3},
      {"0.11 MN*m/rad", Dimension::rotational_stiffness, 110e3},
      {"2 N m/deg", Dimension::rotational_stiffness, 114.5915590261646417535963},
      {"3 kgf m/rad", Dimension::rotational_stiffness, 29.41995},
      {"3 N/m", Dimension::linear_stiffness, 3},
      {"3 kN/m", Dimension::linear_stiffness, 3000},
      {"2 N/mm", Dimension::linear_stiffness, 2000},
      {"1 kgf/cm", Dimension::linear_stiffness, 980.665},
      {"4 MN/m", Dimension::linear_stiffness, 4e6},
      {"2000 N m s/rad", Dimension::rotational_damping, 2000},
      {"2 kN m s/rad", Dimension::rotational_damping, 2000},
      {"1 N m min/rev", Dimension::rotational_damping, 9.549296585513720146133026},
      {"2 кН м с/рад", Dimension::rotational_damping, 2000},
      {"0.32 kg m^2", Dimension::inertia, 0.32},
      {"0.32 kg*m^2", Dimension::inertia, 0.32},
      {"0.5 t m^2", Dimension::inertia, 500},
      {"3 kg·m²", Dimension::inertia, 3},
      {"5 g cm^2", Dimension::inertia, 5e-7},
      {"2 kgf m s^2", Dimension::inertia, 19.6133},
      {"11 W", Dimension::power, 11},
      {"11 kW", Dimension::power, 11000},
      {"1 hp", Dimension::power, 745.69987158227022},
      {"100 hp", Dimension::power, 74569.987158227022},
      {"1 PS", Dimension::power, 735.49875},
      {"2 N m/s", Dimension::power, 2},
      {"3 kgf m/s", Dimension::power, 29.41995},
      {"5 Вт", Dimension::power, 5},
      {"2 Pa", Dimension::pressure, 2},
      {"2 MPa", Dimension::pressure, 2e6},
      {"3 bar", Dimension::pressure, 3e5},
      {"100 mbar", Dimension::pressure, 1e4},
      {"1013 hPa", Dimension::pressure, 101300},
      {"2 kgf/cm^2", Dimension::pressure, 196133},
      {"2 кгс/см²", Dimension::pressure, 196133},
      {"5 N/mm^2", Dimension::pressure, 5e6},
      {"2 1/m", Dimension::inverse_length, 2},
      {"0.5 1/mm", Dimension::inverse_length, 500},
      {"4 mm^-1", Dimension::inverse_length, 4000},
      {"2 1 / cm", Dimension::inverse_length, 200},
      {"3 m⁻¹", Dimension::inverse_length, 3},
      {"9.81 m/s^2", Dimension::acceleration, 9.81},
      {"500 mm/s^2", Dimension::acceleration, 0.5},
      {"2 m s^-2", Dimension::acceleration, 2},
      {"1 kgf/kg", Dimension::acceleration, 9.80665},
      {"2 m^3/s", Dimension::volume_rate, 2},
      {"3.6 m^3/h", Dimension::volume_rate, 0.001},
      {"5 mm^3/s", Dimension::volume_rate, 5e-9},
      {"2 W/m", Dimension::power_per_length, 2},
      {"2 kW/m", Dimension::power_per_length, 2000},
      {"1 hp/m", Dimension::power_per_length, 745.69987158227022},
      {"0.12 m^2", Dimension::area, 0.12},
      {"300 cm^2", Dimension::area, 0.03},
      {"2 m²", Dimension::area, 2},
      {"0.3", Dimension::dimensionless, 0.3},
      {"5 mm/m", Dimension::dimensionless, 0.005},
  });
}

// Each dimension's SI unit and its listed spellings (docs/config.md) read as it.
TEST(Units, ListedSpellingsAreTheirDimension) {
  std::set<Dimension> seen;
  for (const Dimension d : opt::unit_dimensions()) {
    seen.insert(d);
    EXPECT_EQ(opt::dimension_of(opt::si_unit(d)), d) << opt::si_unit(d);
    EXPECT_TRUE(opt::parse_quantity("1 " + opt::si_unit(d), d).error.empty()) << opt::si_unit(d);
    for (const char* e : opt::unit_examples(d))
      EXPECT_TRUE(opt::parse_quantity(std::string("1 ") + e, d).error.empty())
          << e << ": " << opt::parse_quantity(std::string("1 ") + e, d).error;
  }
  EXPECT_EQ(seen.size(), static_cast<size_t>(Dimension::area));
}

// A name is read whole, else as prefix + symbol; no name may be both, and no
// two prefix + symbol pairs may spell the same name, so each reading is unique.
TEST(Units, EveryNameHasOneReading) {
  std::set<std::string> names;
  for (const auto& s : opt::unit_symbols()) EXPECT_TRUE(names.insert(s.name).second) << s.name;
  // Cyrillic letters lead with UTF-8 bytes 0xD0-0xD4; a prefix goes with a symbol of its script.
  auto cyrillic = [](const std::string& s) {
    const auto c = static_cast<unsigned char>(s[0]);
    return c >= 0xD0 && c <= 0xD4;
  };
  for (const auto& p : opt::unit_prefixes())
    for (const auto& s : opt::unit_symbols()) {
      if (!s.prefixed || cyrillic(p.name) != cyrillic(s.name)) continue;
      EXPECT_TRUE(names.insert(p.name + s.name).second) << p.name << " + " << s.name;
    }
}

// Issue 32: "/" takes everything after it; a unit is never a list.
TEST(Units, EverythingAfterTheSlashIsTheDenominator) {
  // J/m m is J/m^2 (a linear stiffness), not (J/m) m (an energy).
  expect_cases({{"6 J/m m", Dimension::linear_stiffness, 6}});
  EXPECT_EQ(opt::parse_quantity("6 J/m m", Dimension::energy).error, "unit 'J/m m' is a linear stiffness");
  // N m/rad s is N m/(rad s), not the damping N m s/rad.
  EXPECT_NE(opt::parse_quantity("1 N m/rad s", Dimension::rotational_damping).error, "");
  EXPECT_EQ(opt::parse_quantity("1 kg/m s", Dimension::linear_density).error,
            "unit 'kg/m s' is kg/m s, no dimension of the tables");
}

TEST(Units, TorqueAndEnergyStayApartAndMismatchesNameTheDimension) {
  EXPECT_EQ(opt::parse_quantity("4 kJ", Dimension::torque).error, "unit 'kJ' is an energy");
  EXPECT_EQ(opt::parse_quantity("2 kW h", Dimension::torque).error, "unit 'kW h' is an energy");
  EXPECT_EQ(opt::parse_quantity("2 kN m", Dimension::energy).error, "unit 'kN m' is a torque");
  EXPECT_EQ(opt::parse_quantity("2 kN", Dimension::torque).error, "unit 'kN' is a force");
  EXPECT_EQ(opt::parse_quantity("110 kN m", Dimension::rotational_stiffness).error, "unit 'kN m' is a torque");
  EXPECT_EQ(opt::parse_quantity("1 m", Dimension::mass).error, "unit 'm' is a length");
  EXPECT_EQ(opt::parse_quantity("1 m", Dimension::dimensionless).error, "unit 'm' is a length");
  EXPECT_EQ(opt::parse_quantity("1 rad/s", Dimension::angle).error, "unit 'rad/s' is an angular speed");
  EXPECT_EQ(opt::dimension_of("N m"), Dimension::torque);
  EXPECT_EQ(opt::dimension_of("J"), Dimension::energy);
  EXPECT_EQ(opt::dimension_of("m/s^2"), Dimension::acceleration);
  EXPECT_EQ(opt::dimension_of("mm"), Dimension::dimensionless) << "not a coherent SI unit";
  EXPECT_EQ(opt::dimension_of(""), Dimension::dimensionless);
  EXPECT_EQ(opt::dimension_of("furlong"), Dimension::dimensionless);
}

TEST(Units, MalformedUnitsSayWhatAndWhere) {
  struct Bad {
    const char* text;
    const char* says;  // the error starts with it
  };
  const Bad bad[] = {
      {"1 kgg m", "unknown unit symbol 'kgg' at character 1 of 'kgg m'; a unit is symbols with SI prefixes"},
      {"1 m kgg", "unknown unit symbol 'kgg' at character 3 of 'm kgg'"},
      {"100 rpmm", "unknown unit symbol 'rpmm' at character 1 of 'rpmm'"},
      {"1 кm", "unknown unit symbol 'кm'"},
      {"1 Mkgf", "unknown unit symbol 'Mkgf'"},
      {"1 m^", "'^' needs a whole number at character 2 of 'm^'"},
      {"1 m^x", "'^' needs a whole number at character 2"},
      {"1 m^1000", "a power above 99 at character 2"},
      {"1 /s", "no symbol before '/' (1/s for a reciprocal) at character 1 of '/s'"},
      {"1 kg//m", "a second '/' (everything after the first is the denominator) at character 4 of 'kg//m'"},
      {"1 m/s/s", "a second '/'"},
      {"1 m*", "a symbol is missing at character 3 of 'm*'"},
      {"1 m**s", "a symbol is missing before '*' at character 3"},
      {"1 m^2kg", "expected ' ', '*' or '/' before 'k' at character 4"},
      {"1 m ,", "unexpected ',' at character 3"},
      {"1 m)", "unexpected ')' at character 2"},
      {"1 m⁻", "a superscript sign needs superscript digits at character 2"},
      {"1 1", "unexpected '1' at character 1"},
  };
  for (const auto& b : bad) {
    const std::string error = opt::parse_quantity(b.text, Dimension::length).error;
    EXPECT_EQ(error.rfind(b.says, 0), 0u) << b.text << ": " << error;
  }
  EXPECT_EQ(opt::parse_quantity("heavy", Dimension::mass).error, "not a number");
  EXPECT_EQ(opt::parse_quantity("inf m", Dimension::length).error, "not a finite number");
  EXPECT_NE(opt::parse_quantity("1e308 km", Dimension::length).error.find("out of range"), std::string::npos);
}

// A unit whose scale is 1 keeps strtod's value bit for bit, so configs written
// in SI (and %.17g texts written back) read exactly as before.
TEST(Units, SiSpellingsKeepTheNumberExactly) {
  for (const char* number : {"0.1", "1.2345678901234567", "3.0000000000000004", "1e-300"})
    for (const char* unit : {"", " m", " kg", " N m/rad", " kg m^2", " kg·m²", " 1/m"}) {
      const std::string text = std::string(number) + unit;
      const Dimension d = *unit ? opt::dimension_of(unit + 1) : Dimension::dimensionless;
      EXPECT_EQ(opt::parse_quantity(text, d).value, std::strtod(number, nullptr)) << text;
    }
}

// The config reads model values, variable bounds, initial values, grid points
// and the bounds of metric constraints by the one grammar; a metric's bound
// takes the metric's dimension (m/s^2 had none before the grammar).
TEST(Units, TheConfigReadsEveryValueByTheGrammar) {
  const auto root = opt::ConfigNode::parse(R"(
problem: slider_crank
model: {crank_radius: 20 cm, rod_length: 800 mm, crank_speed: 60 rev/min}
variables:
  crank_radius: {min: 0.1 m, max: 400 mm, initial: 25 cm}
constraints:
  stroke: {equal: 500 mm}
  max_pressure_angle: {max: 20 deg}
  peak_slider_acceleration: {max: 2000 cm/s^2}
study: {type: sweep, optimize: false, grid: {crank_radius: {from: 10 cm, to: 0.4 m, step: 15 cm}}}
)", "<units>");
  const auto p = opt::make_problem(root);
  const auto& v = p->variables();
  ASSERT_EQ(v.size(), 1u);
  EXPECT_TRUE(within_one_ulp(v[0].upper, 0.4));
  EXPECT_TRUE(within_one_ulp(v[0].initial, 0.25));
  const auto model = p->record()["model"];
  EXPECT_TRUE(within_one_ulp(model["rod_length"].get<double>(), 0.8));
  EXPECT_TRUE(within_one_ulp(model["crank_speed"].get<double>(), 6.283185307179586476925287));  // 2 pi
  const opt::RunSpec spec = opt::parse_run(root, *p);
  ASSERT_EQ(spec.constraints.size(), 3u);
  EXPECT_TRUE(within_one_ulp(spec.constraints[0].bound, 0.5));
  EXPECT_TRUE(within_one_ulp(spec.constraints[1].bound, 0.3490658503988659153847382));  // pi/9
  EXPECT_TRUE(within_one_ulp(spec.constraints[2].bound, 20));
  ASSERT_EQ(spec.grid.size(), 1u);
  ASSERT_EQ(spec.grid[0].values.size(), 3u);
  EXPECT_TRUE(within_one_ulp(spec.grid[0].values[0], 0.1));

  const auto wrong = opt::ConfigNode::parse(R"(
problem: slider_crank
constraints: {peak_slider_acceleration: {max: 2 kJ}}
study: {type: evaluate}
)", "<units>");
  try {
    opt::parse_run(wrong, *opt::make_problem(wrong));
    ADD_FAILURE() << "2 kJ taken for an acceleration";
  } catch (const opt::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("key 'constraints.peak_slider_acceleration.max': expected an acceleration "
                                         "(SI unit m/s^2), got '2 kJ': unit 'kJ' is an energy"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
