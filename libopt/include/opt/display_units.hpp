// The units a designer reads values in, on charts and in printed tables: an
// angle in degrees, a plain number as "-", any other quantity in its SI unit
// (units.hpp). Files that scripts read (result.json, the CSV files, the
// store) stay in SI.
#pragma once
#include <string>

namespace opt {

struct ShownUnit {
  std::string unit;   // "deg", "m", "-"
  double scale = 1;   // the shown value is the SI value times this
};

// The unit a quantity of SI unit `si` ("rad", "m", "" for a plain number) is shown in.
ShownUnit shown_unit(const std::string& si);
// "name [unit]": a chart axis's label, a printed table's column head.
std::string shown_label(const std::string& name, const std::string& si);
// The SI value `v` in its shown unit with `precision` significant digits,
// followed by the unit unless it is a plain number ("98.4729 deg", "0.9 m",
// "1.04"); "-" when not finite.
std::string shown_value(double v, const std::string& si, int precision = 6);

}  // namespace opt
