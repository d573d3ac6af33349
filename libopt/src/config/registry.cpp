#include "opt/registry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>

#include "mech/status.hpp"
#include "opt/parameters.hpp"
#include "opt/units.hpp"

namespace opt {
namespace {
std::vector<Entry>& entries() {
  static std::vector<Entry> all;
  return all;
}

const Entry& entry(const opt::ConfigNode& root) {
  root.allow_only(config_keys());
  std::vector<std::string> names;
  for (const auto& e : registry()) names.push_back(e.name);
  const std::string n = root.at("problem").choice(names);
  return *std::find_if(registry().begin(), registry().end(), [&](const Entry& e) { return e.name == n; });
}

// A model value taken from another config's result (docs/config.md, "Links"):
//   crank_radius: {from: ../roller_forming/variant.yaml, metric: crank_radius, variant: 9}
// `key` is its name in the model (sections dotted), `node` the map.
struct Link {
  std::string key;
  opt::ConfigNode node;
};

constexpr int kMaxLinkDepth = 8;

void find_links(const opt::ConfigNode& n, const std::string& prefix, std::vector<Link>& out) {
  for (const auto& k : n.keys()) {
    if (!n.has(k)) continue;
    const opt::ConfigNode c = n.at(k);
    if (!c.is_map()) continue;
    if (c.has("from")) out.push_back({prefix + k, c});
    else find_links(c, prefix + k + ".", out);
  }
}

std::vector<Link> links_of(const opt::ConfigNode& root) {
  std::vector<Link> out;
  if (root.has("model")) find_links(root.at("model"), "", out);
  return out;
}

// The linked config: the file `from` names (relative to the file the link is
// written in) with the link's other keys as its model values (and as the
// initial values of its variables of those names: the design evaluated).
opt::ConfigNode linked_config(const Link& l) {
  const opt::ConfigNode from = l.node.at("from");
  const std::string file = opt::relative_to(from.file(), from.text());
  if (!std::ifstream(file)) from.fail("cannot read the linked config '" + file + "'");
  const opt::ConfigNode linked = opt::ConfigNode::load(file);
  const bool variables = linked.has("variables") && linked.at("variables").is_map();
  YAML::Node over(YAML::NodeType::Map);
  over["model"] = YAML::Node(YAML::NodeType::Map);
  for (const auto& k : l.node.keys()) {
    if (k == "from" || k == "metric" || !l.node.has(k)) continue;
    opt::set_dotted(over["model"], k, YAML::Clone(l.node.at(k).yaml()));
    // A variable of the linked config starts at the link's value.
    if (variables && linked.at("variables").has(k)) over["variables"][k]["initial"] = YAML::Clone(l.node.at(k).yaml());
  }
  return linked.with(over, l.node.file());
}

const opt::Parameter* row(const std::vector<opt::Parameter>& table, const std::string& name) {
  for (const auto& p : table)
    if (p.name == name) return &p;
  return nullptr;
}

std::unique_ptr<opt::Problem> make_at_depth(const opt::ConfigNode& root, int depth);

// The link whose config l evaluates: l itself, or the link of the same
// model that its `from` names ({from: crank_radius, metric: crank_speed}:
// the same design, another of its metrics; a DOE factor on crank_radius's
// values moves both).
const Link& source_of(const Link& l, const std::vector<Link>& ls) {
  const std::string from = l.node.at("from").text();
  for (const auto& other : ls) {
    if (other.key != from || &other == &l) continue;
    if (std::any_of(ls.begin(), ls.end(), [&](const Link& o) { return o.key == other.node.at("from").text(); }))
      l.node.at("from").fail("names the link " + from + ", which names another link; name a config file");
    for (const auto& k : l.node.keys())
      if (k != "from" && k != "metric")
        l.node.at(k).fail("this link evaluates the design of " + from + "; give the linked model values there");
    return other;
  }
  return l;
}

// The config with every link replaced by the value it names, and the links'
// record for the problem.
opt::ConfigNode resolved(const opt::ConfigNode& root, const Entry& e, int depth, nlohmann::json& record) {
  const std::vector<Link> ls = links_of(root);
  if (ls.empty()) return root;
  YAML::Node over(YAML::NodeType::Map);
  std::map<std::string, std::unique_ptr<opt::Problem>> built;  // by the source link's key
  for (const auto& l : ls) {
    if (depth == kMaxLinkDepth) l.node.fail("links nest more than 8 deep (does a config link to itself?)");
    const opt::Parameter* target = row(e.parameters, l.key);
    if (!target) continue;  // the model's own check names the unknown key
    if (!target->choices.empty() || target->integer)
      l.node.fail("a link gives a quantity; " + l.key + " takes " + opt::domain_text(*target));
    const Link& source = source_of(l, ls);
    auto& linked = built[source.key];
    if (!linked) linked = make_at_depth(linked_config(source), depth + 1);
    const std::string file = source.node.at("from").text();
    const opt::ConfigNode m = l.node.at("metric");
    const std::string metric = m.choice(linked->metric_names());
    const std::string unit = linked->metric_unit(metric), wanted = opt::si_unit(target->dimension);
    if (unit != wanted)
      m.fail("'" + metric + "' of " + file + " is in '" + unit + "'; " + l.key + " takes '" + wanted + "'");
    const opt::Evaluation v = linked->evaluate(linked->initial_point(false), {metric}, false);
    if (!v.ok() || !v.has(linked->metric_id(metric)))
      l.node.fail("the design of " + file + " gives no " + metric + ": " + std::string(mech::to_string(v.status)) +
                  (v.message.empty() ? "" : " (" + v.message + ")"));
    const double value = v[linked->metric_id(metric)].value;
    opt::set_dotted(over["model"], l.key, YAML::Node(opt::exact_value_text(*target, value)));
    record.push_back({{"key", l.key}, {"from", file}, {"metric", metric}, {"value", value}, {"unit", unit},
                      {"linked", linked->record()}});
  }
  return root.with(over, root.file());
}

// A fidelity row written `auto` (tolerance 1e-3) or `{auto: TOL}`;
// `fidelity: auto` makes every fidelity.* row auto.
struct AutoLevel {
  const opt::Parameter* row;
  double tolerance;
};

constexpr double kFidelityTolerance = 1e-3;

// The node that sets row `name` (dotted) under n: its own, or a section's
// scalar (`fidelity: auto`); none when the config leaves it at its default.
// (Recursive: assigning a ConfigNode would overwrite the YAML it refers to.)
std::optional<opt::ConfigNode> setting(const opt::ConfigNode& n, const std::string& name) {
  const size_t dot = name.find('.');
  const std::string key = name.substr(0, dot);
  if (!n.is_map() || !n.has(key)) return std::nullopt;
  const opt::ConfigNode child = n.at(key);
  if (dot == std::string::npos || child.is_scalar()) return child;
  return setting(child, name.substr(dot + 1));
}

std::vector<AutoLevel> auto_levels(const opt::ConfigNode& root, const Entry& e) {
  std::vector<AutoLevel> out;
  if (!root.has("model")) return out;
  for (const auto& p : e.parameters) {
    if (p.coarse_to_fine.empty()) continue;
    const auto n = setting(root.at("model"), p.name);
    if (!n) continue;
    if (n->is_scalar() && n->text() == "auto") out.push_back({&p, kFidelityTolerance});
    else if (n->is_map() && n->has("auto")) {
      n->allow_only({"auto"});
      out.push_back({&p, n->at("auto").quantity(opt::Dimension::dimensionless, {0, 1, true, true})});
    }
  }
  return out;
}

// The metrics an auto fidelity must keep within its tolerance: the config's
// objective and constraints, else every metric.
std::vector<std::string> compared_metrics(const opt::ConfigNode& root, const opt::Problem& p) {
  std::vector<std::string> out;
  auto add = [&](const std::string& m) {
    if (p.has_metric(m) && std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
  };
  if (root.has("objective") && root.at("objective").is_map())
    for (const auto& k : root.at("objective").keys()) add(root.at("objective").at(k).text());
  if (root.has("constraints") && root.at("constraints").is_map())
    for (const auto& k : root.at("constraints").keys()) add(k);
  return out.empty() ? p.metric_names() : out;
}

std::string relative_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2g", v);
  return text;
}

// The config with every auto fidelity row set to its coarsest level whose
// metrics, at the start point, move less than its tolerance (relative) from
// the next finer level's, and the record of each choice. While one row is
// chosen the other auto rows stand at their finest level.
opt::ConfigNode fidelity_chosen(const opt::ConfigNode& root, const Entry& e, int depth, nlohmann::json& record) {
  const std::vector<AutoLevel> autos = auto_levels(root, e);
  if (autos.empty()) return root;
  YAML::Node over(YAML::NodeType::Map);
  for (const auto& a : autos) opt::set_dotted(over["model"], a.row->name, YAML::Node(a.row->coarse_to_fine.back()));
  for (const auto& a : autos) {
    const auto& levels = a.row->coarse_to_fine;
    std::vector<std::string> metrics;
    auto values = [&](const std::string& level) {  // empty: the design fails at this level
      opt::set_dotted(over["model"], a.row->name, YAML::Node(level));
      const auto p = make_at_depth(root.with(over, root.file()), depth);
      if (metrics.empty()) metrics = compared_metrics(root, *p);
      const opt::Evaluation ev = p->evaluate(p->initial_point(false), metrics, false);
      std::vector<double> v;
      for (const auto& m : metrics)
        if (ev.ok() && ev.has(p->metric_id(m))) v.push_back(ev[p->metric_id(m)].value);
      return v.size() == metrics.size() ? v : std::vector<double>{};
    };
    size_t chosen = levels.size() - 1;
    nlohmann::json steps = nlohmann::json::array();
    std::vector<double> finer = values(levels.back());
    std::string why = levels.back() + ": the finest level";
    // From the finest down: a level stands if it is within the tolerance of
    // the next finer one; the coarsest such level in an unbroken run wins.
    for (size_t L = levels.size() - 1; L-- > 0;) {
      const std::vector<double> v = values(levels[L]);
      double worst = HUGE_VAL;
      std::string which = "the design fails at one of the two levels";
      if (!v.empty() && !finer.empty()) {
        worst = 0;
        for (size_t k = 0; k < v.size(); ++k) {
          const double change = std::abs(v[k] - finer[k]) / std::max(std::abs(finer[k]), 1e-300);
          if (change >= worst) worst = change, which = metrics[k];
        }
      }
      steps.push_back({{"level", levels[L]}, {"against", levels[L + 1]}, {"largest_change", worst}, {"metric", which}});
      if (!(worst < a.tolerance)) {
        why = levels[L] + " moves " + which + " by " + relative_text(worst) + " from " + levels[L + 1] +
              " (tolerance " + relative_text(a.tolerance) + "): " + levels[chosen];
        break;
      }
      chosen = L;
      finer = v;
      why = levels[L] + " moves " + which + " by " + relative_text(worst) + " from " + levels[L + 1] + ", within " +
            relative_text(a.tolerance);
    }
    opt::set_dotted(over["model"], a.row->name, YAML::Node(levels[chosen]));
    record.push_back({{"key", a.row->name}, {"chosen", levels[chosen]}, {"tolerance", a.tolerance},
                      {"compared", metrics}, {"steps", steps}, {"why", why}});
  }
  return root.with(over, root.file());
}

std::unique_ptr<opt::Problem> make_at_depth(const opt::ConfigNode& root, int depth) {
  const Entry& e = entry(root);
  nlohmann::json links = nlohmann::json::array(), fidelity = nlohmann::json::array();
  const opt::ConfigNode linked = resolved(root, e, depth, links);
  auto p = e.make(fidelity_chosen(linked, e, depth, fidelity));
  if (!links.empty()) p->resolved["links"] = std::move(links);
  if (!fidelity.empty()) p->resolved["fidelity_auto"] = std::move(fidelity);
  return p;
}
}  // namespace

Registration::Registration(Entry e) {
  auto& all = entries();
  const auto at = std::lower_bound(all.begin(), all.end(), e.name,
                                   [](const Entry& a, const std::string& n) { return a.name < n; });
  all.insert(at, std::move(e));
}

const std::vector<Entry>& registry() { return entries(); }

const std::vector<std::string>& config_keys() {
  static const std::vector<std::string> keys = {"base",        "problem", "model",  "variables", "objective",
                                                "constraints", "study",   "output", "reference"};
  return keys;
}

std::unique_ptr<opt::Problem> make_problem(const opt::ConfigNode& root) { return make_at_depth(root, 0); }

std::vector<opt::Parameter> model_parameters(const opt::ConfigNode& root) {
  const Entry& e = entry(root);
  std::vector<opt::Parameter> out = e.table ? e.table(root) : e.parameters;
  const std::vector<Link> ls = links_of(root);
  for (const auto& l : ls) {
    if (&source_of(l, ls) != &l) continue;  // its values are its source's
    const opt::ConfigNode linked = linked_config(l);
    for (opt::Parameter p : entry(linked).parameters) {
      p.name = l.key + "." + p.name;
      p.variable = false;  // set in the linked config, which the sample rebuilds
      out.push_back(std::move(p));
    }
  }
  return out;
}

}  // namespace opt
