#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "report/report.hpp"

namespace opt::report {

std::string fmt(double v, int precision) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + v[i];
  return out;
}

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

void print_variables(std::ostream& out, const Problem& p, const Eigen::VectorXd& x) {
  const auto& vars = p.variables();
  for (size_t i = 0; i < vars.size(); ++i)
    out << "  " << std::left << std::setw(26) << vars[i].name << std::right << std::setw(14)
        << fmt(x[i], 10) << " " << std::left << std::setw(6) << si_unit(vars[i].dimension)
        << std::right << " in [" << fmt(vars[i].lower) << ", " << fmt(vars[i].upper) << "]\n";
}

void print_metrics(std::ostream& out, const Problem& p, const nlohmann::json& m) {
  for (const auto& [name, v] : m.items())
    out << "  " << std::left << std::setw(26) << name << std::right << std::setw(14)
        << fmt(v.get<double>(), 10) << " " << p.metric_unit(name) << "\n";
}

}  // namespace opt::report
