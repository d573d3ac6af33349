#include <algorithm>
#include <iomanip>
#include <iostream>

#include "core/text.hpp"
#include "opt/display_units.hpp"
#include "report/report.hpp"

namespace opt::report {

using text::fmt;

void print_row(std::ostream& out, const std::vector<std::string>& cells,
               const std::vector<std::string>& head) {
  for (size_t i = 0; i < cells.size(); ++i)
    out << std::setw(std::max<int>(12, static_cast<int>(head[i].size())) + 1) << cells[i];
  out << "\n";
}

nlohmann::json variables_json(const Problem& p, const Eigen::VectorXd& x) {
  nlohmann::json j = nlohmann::json::object();
  const auto& vars = p.variables();
  for (size_t i = 0; i < vars.size(); ++i)
    j[vars[i].name] = {{"value", x[i]}, {"unit", si_unit(vars[i].dimension)},
                       {"min", vars[i].lower}, {"max", vars[i].upper}};
  return j;
}

size_t longest(const std::vector<std::string>& names, size_t at_least) {
  for (const auto& n : names) at_least = std::max(at_least, n.size());
  return at_least;
}

void print_variables(std::ostream& out, const Problem& p, const Eigen::VectorXd& x) {
  const auto& vars = p.variables();
  std::vector<std::string> names;
  for (const auto& v : vars) names.push_back(v.name);
  for (size_t i = 0; i < vars.size(); ++i) {
    const std::string si = si_unit(vars[i].dimension);
    const ShownUnit u = shown_unit(si);
    out << "  " << std::left << std::setw(static_cast<int>(longest(names))) << vars[i].name << std::right
        << std::setw(16) << fmt(x[i] * u.scale, 10) << " " << std::left << std::setw(6) << (si.empty() ? "" : u.unit)
        << std::right << " in [" << fmt(vars[i].lower * u.scale) << ", " << fmt(vars[i].upper * u.scale) << "]\n";
  }
}

void print_metrics(std::ostream& out, const Problem& p, const nlohmann::json& m) {
  std::vector<std::string> names;
  for (const auto& [name, v] : m.items()) names.push_back(name);
  for (const auto& [name, v] : m.items()) {
    const std::string si = p.metric_unit(name);
    const ShownUnit u = shown_unit(si);
    out << "  " << std::left << std::setw(static_cast<int>(longest(names))) << name << std::right << std::setw(16)
        << fmt(v.get<double>() * u.scale, 10) << (si.empty() ? "" : " " + u.unit) << "\n";
  }
}

}  // namespace opt::report
