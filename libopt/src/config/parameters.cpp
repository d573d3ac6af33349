#include "opt/parameters.hpp"

#include "opt/display_units.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace opt {
std::string value_text(const Parameter& p) {
  if (!p.choices.empty()) return p.choices.at(static_cast<size_t>(p.value));
  if (p.automatic && p.value == 0) return "auto";
  return shown_value(p.value, si_unit(p.dimension));
}

std::string exact_value_text(const Parameter& p, double v) {
  if (!p.choices.empty()) return p.choices.at(static_cast<size_t>(v));
  char text[40];
  std::snprintf(text, sizeof text, p.integer ? "%.0f" : "%.17g", v);
  const std::string unit = si_unit(p.dimension);
  return unit.empty() ? std::string(text) : std::string(text) + " " + unit;
}

std::string domain_text(const Parameter& p) {
  std::string out;
  if (!p.choices.empty()) {
    for (const auto& c : p.choices) out += (out.empty() ? "one of: " : ", ") + c;
    if (!p.coarse_to_fine.empty()) out += ", or auto";
    return out;
  }
  const std::string si = si_unit(p.dimension);
  const ShownUnit u = shown_unit(si);
  out = to_string(Domain{p.domain.lo * u.scale, p.domain.hi * u.scale, p.domain.lo_open, p.domain.hi_open},
                  Dimension::dimensionless);
  if (out != "any" && !si.empty()) out += " " + u.unit;
  if (p.integer) out += ", whole";
  if (p.automatic) out += ", or auto";
  return out;
}

double read_parameter(const ConfigNode& n, const Parameter& p) {
  if (!p.choices.empty()) {
    const std::string c = n.choice(p.choices);
    return static_cast<double>(std::find(p.choices.begin(), p.choices.end(), c) - p.choices.begin());
  }
  if (p.automatic && n.is_scalar() && n.text() == "auto") return 0;
  if (p.integer) {
    const auto bound = [](double v) { return static_cast<int>(std::clamp(v, -2e9, 2e9)); };
    return n.integer(bound(p.domain.lo + (p.domain.lo_open ? 1 : 0)), bound(p.domain.hi - (p.domain.hi_open ? 1 : 0)));
  }
  return n.quantity(p.dimension, p.domain);
}

void check_model_keys(const ConfigNode& model, const std::vector<Parameter>& rows,
                      const std::vector<std::string>& elsewhere) {
  std::vector<std::string> top;
  auto add = [](std::vector<std::string>& v, const std::string& k) {
    if (std::find(v.begin(), v.end(), k) == v.end()) v.push_back(k);
  };
  for (const auto& r : rows) add(top, r.name.substr(0, r.name.find('.')));
  std::vector<std::string> allowed = top;
  for (const auto& k : elsewhere) add(allowed, k);
  model.allow_only(allowed);
  for (const auto& section : top) {
    if (!model.has(section)) continue;
    std::vector<std::string> inner;
    for (const auto& r : rows)
      if (r.name.rfind(section + ".", 0) == 0) add(inner, r.name.substr(section.size() + 1));
    if (!inner.empty()) model.at(section).allow_only(inner);
  }
}

nlohmann::json parameters_json(const std::vector<Parameter>& rows) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& r : rows) {
    nlohmann::json v = r.value;
    if (!r.choices.empty()) v = r.choices.at(static_cast<size_t>(r.value));
    else if (r.automatic && r.value == 0) v = "auto";
    else if (r.integer) v = static_cast<long>(r.value);
    const auto dot = r.name.find('.');
    if (dot == std::string::npos) j[r.name] = v;
    else j[r.name.substr(0, dot)][r.name.substr(dot + 1)] = v;
  }
  return j;
}

std::vector<Parameter> table(const std::string& problem, std::initializer_list<TableRow> rows) {
  std::vector<Parameter> out;
  for (const auto& r : rows) {
    if (r.id != static_cast<int>(out.size()))
      throw std::logic_error(problem + ": model value " + r.p.name + " is not at its enum's position");
    out.push_back(r.p);
  }
  return out;
}

Values<double> read_values(const ConfigNode& root, const std::vector<Parameter>& table,
                           const std::vector<std::string>& elsewhere) {
  Values<double> v;
  for (const auto& p : table) v.push_back(p.value);
  if (!root.has("model")) return v;
  const ConfigNode model = root.at("model");
  check_model_keys(model, table, elsewhere);
  for (size_t i = 0; i < table.size(); ++i) {
    const std::string& name = table[i].name;
    // (No ConfigNode is assigned to: a YAML::Node assignment writes into the tree.)
    const auto dot = name.find('.');
    if (dot != std::string::npos && !model.has(name.substr(0, dot))) continue;
    const ConfigNode section = dot == std::string::npos ? model : model.at(name.substr(0, dot));
    const std::string key = dot == std::string::npos ? name : name.substr(dot + 1);
    if (section.has(key)) v[i] = read_parameter(section.at(key), table[i]);
  }
  return v;
}

std::vector<Parameter> with_values(std::vector<Parameter> table, const Values<double>& v) {
  for (size_t i = 0; i < table.size(); ++i) table[i].value = v.at(i);
  return table;
}

std::vector<int> variable_rows(const std::vector<Parameter>& table, const std::vector<Variable>& vars) {
  std::vector<int> rows;
  for (const auto& var : vars)
    for (size_t i = 0; i < table.size(); ++i)
      if (table[i].name == var.name) rows.push_back(static_cast<int>(i));
  return rows;
}

}  // namespace opt
