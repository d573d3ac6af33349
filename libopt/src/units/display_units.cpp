#include "opt/display_units.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

namespace opt {

ShownUnit shown_unit(const std::string& si) {
  if (si == "rad") return {"deg", 180 / std::numbers::pi};
  return {si.empty() ? "-" : si, 1.0};
}

std::string shown_label(const std::string& name, const std::string& si) {
  return name + " [" + shown_unit(si).unit + "]";
}

std::string shown_value(double v, const std::string& si, int precision) {
  if (!std::isfinite(v)) return "-";
  const ShownUnit u = shown_unit(si);
  std::ostringstream s;
  s.precision(precision);
  s << v * u.scale + 0.0;  // no "-0"
  return si.empty() ? s.str() : s.str() + " " + u.unit;
}

}  // namespace opt
