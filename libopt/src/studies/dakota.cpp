#include "opt/dakota.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "opt/config.hpp"

namespace opt {

namespace {

// The headers of APREPRO's format by their standard names.
const std::map<std::string, std::string> kAprepro = {
    {"DAKOTA_VARS", "variables"},           {"DAKOTA_FNS", "functions"},
    {"DAKOTA_DER_VARS", "derivative_variables"}, {"DAKOTA_AN_COMPS", "analysis_components"},
    {"DAKOTA_EVAL_ID", "eval_id"},          {"DAKOTA_METADATA", "metadata"}};

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

[[noreturn]] void fail(const std::string& file, int line, const std::string& what) {
  throw ConfigError(file + (line ? ":" + std::to_string(line) : "") + ": " + what);
}

// Every non-blank line as {label, value}: "VALUE LABEL" (standard) or
// "{ LABEL = VALUE }" (APREPRO, its headers renamed to the standard's).
std::vector<DakotaParams::Entry> entries(const std::string& file) {
  std::ifstream in(file);
  if (!in) fail(file, 0, "cannot read the parameters file");
  std::vector<DakotaParams::Entry> out;
  int n = 0;
  for (std::string text; std::getline(in, text);) {
    ++n;
    const std::string t = trimmed(text);
    if (t.empty()) continue;
    DakotaParams::Entry e;
    e.line = n;
    if (t.front() == '{') {
      const auto eq = t.find('=');
      if (eq == std::string::npos || t.back() != '}') fail(file, n, "expected '{ label = value }', got '" + t + "'");
      e.label = trimmed(t.substr(1, eq - 1));
      e.value = trimmed(t.substr(eq + 1, t.size() - eq - 2));
      if (e.value.size() >= 2 && e.value.front() == '"' && e.value.back() == '"')
        e.value = e.value.substr(1, e.value.size() - 2);
      if (const auto it = kAprepro.find(e.label); it != kAprepro.end()) e.label = it->second;
    } else {
      const auto sp = t.find_first_of(" \t");
      if (sp == std::string::npos) fail(file, n, "expected 'value label', got '" + t + "'");
      e.value = t.substr(0, sp);
      e.label = trimmed(t.substr(sp));
    }
    out.push_back(std::move(e));
  }
  return out;
}

// "ASV_3:peak_torque" -> "peak_torque".
std::string after_colon(const std::string& label) {
  const auto c = label.find(':');
  return c == std::string::npos ? label : label.substr(c + 1);
}

double number(const std::string& file, const DakotaParams::Entry& e, const std::string& what) {
  char* end = nullptr;
  const double v = std::strtod(e.value.c_str(), &end);
  if (e.value.empty() || *end) fail(file, e.line, "expected " + what + ", got '" + e.value + "' for " + e.label);
  return v;
}

}  // namespace

DakotaParams read_dakota_params(const std::string& file) {
  const auto lines = entries(file);
  DakotaParams p;
  p.file = file;
  std::size_t at = 0;
  // A section: its header "N NAME", then N entries.
  auto section = [&](const std::string& name, std::vector<DakotaParams::Entry>* into) {
    if (at >= lines.size() || lines[at].label != name) {
      if (!into) return;  // an optional section
      fail(file, at < lines.size() ? lines[at].line : 0,
           "expected the '" + name + "' header (N " + name + ")" +
               (at < lines.size() ? ", got '" + lines[at].value + " " + lines[at].label + "'" : ", got the end"));
    }
    const double n = number(file, lines[at], "a count");
    if (n < 0 || n != static_cast<long>(n)) fail(file, lines[at].line, "expected a count of " + name);
    ++at;
    if (at + static_cast<std::size_t>(n) > lines.size())
      fail(file, lines.back().line, "the file ends inside its " + name + " (" + std::to_string(long(n)) + " entries)");
    for (long i = 0; i < static_cast<long>(n); ++i, ++at)
      if (into) into->push_back(lines[at]);
  };
  section("variables", &p.variables);
  section("functions", &p.functions);
  section("derivative_variables", &p.derivative_variables);
  section("analysis_components", &p.analysis_components);
  if (at < lines.size() && lines[at].label == "eval_id") p.eval_id = lines[at++].value;
  section("metadata", nullptr);
  if (at < lines.size()) fail(file, lines[at].line, "unexpected line '" + lines[at].value + " " + lines[at].label + "'");
  for (auto& f : p.functions) f.label = after_colon(f.label);
  for (auto& d : p.derivative_variables) d.label = after_colon(d.label);
  return p;
}

std::vector<std::string> dakota_responses(const RunSpec& spec) {
  std::vector<std::string> order;
  if (!spec.objective.metric.empty()) order.push_back(spec.objective.metric);
  for (bool equal : {false, true})
    for (const auto& c : spec.constraints)
      if (c.equal == equal) order.push_back(c.metric);
  return order;
}

std::string dakota_results(const Problem& problem, const std::vector<std::string>& order,
                           const DakotaParams& params) {
  const std::string& file = params.file;
  const auto& vars = problem.variables();
  auto variable_names = [&] {
    std::string s;
    for (const auto& v : vars) s += (s.empty() ? "" : ", ") + v.name;
    return s;
  };
  // The variables, by label.
  Eigen::VectorXd x = problem.initial_point(false);
  std::vector<int> column;  // each of params.variables' position among the problem's
  for (const auto& e : params.variables) {
    int j = 0;
    while (j < static_cast<int>(vars.size()) && vars[static_cast<size_t>(j)].name != e.label) ++j;
    if (j == static_cast<int>(vars.size()))
      fail(file, e.line, "variable '" + e.label + "' is not one of the config's variables (" + variable_names() + ")");
    x[j] = number(file, e, "a number");
    column.push_back(j);
  }
  std::vector<int> dvv;  // the derivative variables' positions among the problem's
  for (const auto& d : params.derivative_variables) {
    const double k = number(file, d, "a variable's position");
    if (k < 1 || k > static_cast<double>(column.size()) || k != static_cast<long>(k))
      fail(file, d.line, "derivative variable " + d.value + " is not a position among the " +
                             std::to_string(column.size()) + " variables");
    dvv.push_back(column[static_cast<size_t>(k) - 1]);
  }
  // The functions: a metric by label, else the config's responses in Dakota's order.
  std::vector<MetricId> ids;
  std::vector<int> asv;
  MetricSet wanted;
  bool gradient = false;
  for (std::size_t i = 0; i < params.functions.size(); ++i) {
    const auto& f = params.functions[i];
    const double a = number(file, f, "an active set value (1, 2, 4 or their sum)");
    if (a < 0 || a > 7 || a != static_cast<int>(a)) fail(file, f.line, "expected an active set value from 0 to 7");
    if (static_cast<int>(a) & 4)
      fail(file, f.line, "function '" + f.label + "' asks for its Hessian (ASV " + f.value +
                             "); mechopt gives values and gradients: ask Dakota for numerical_hessians or "
                             "quasi_hessians");
    MetricId id = problem.metric_id(f.label);
    if (id < 0 && i < order.size()) id = problem.metric_id(order[i]);
    if (id < 0)
      fail(file, f.line, "function '" + f.label + "' is not a metric of problem " + problem.name() +
                             ", and the config's objective and constraints give " + std::to_string(order.size()) +
                             " responses for the functions without a metric's name");
    ids.push_back(id);
    asv.push_back(static_cast<int>(a));
    wanted.add(id);
    gradient = gradient || (asv.back() & 2);
  }
  const Evaluation e = problem.evaluate(x, wanted, gradient);
  if (!e.ok()) return "FAIL\n";
  std::ostringstream out;
  char buf[64];
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (asv[i] & 1) {
      std::snprintf(buf, sizeof buf, "%24.16e ", e[ids[i]].value);
      out << buf << params.functions[i].label << "\n";
    }
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (asv[i] & 2) {
      out << "[";
      for (int j : dvv) {
        std::snprintf(buf, sizeof buf, " %24.16e", e[ids[i]].gradient[j]);
        out << buf;
      }
      out << " ]\n";
    }
  return out.str();
}

}  // namespace opt
