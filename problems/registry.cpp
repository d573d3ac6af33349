#include "problems/registry.hpp"

#include <algorithm>

namespace problems {
namespace {
std::vector<Entry>& entries() {
  static std::vector<Entry> all;
  return all;
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

std::unique_ptr<opt::Problem> make_problem(const opt::ConfigNode& root) {
  root.allow_only(config_keys());
  const opt::ConfigNode name = root.at("problem");
  std::vector<std::string> names;
  for (const auto& e : registry()) names.push_back(e.name);
  const std::string n = name.choice(names);
  for (const auto& e : registry())
    if (e.name == n) return e.make(root);
  return nullptr;
}

}  // namespace problems
