#include "problems/registry.hpp"

#include "problems/conveyor_swing.hpp"
#include "problems/elastic_drive.hpp"
#include "problems/recuperative_drive.hpp"

namespace problems {

const std::vector<Entry>& registry() {
  static const std::vector<Entry> entries = {
      {"recuperative_drive",
       "twin slider-crank recuperative drive of a roller forming installation (seed 000)",
       recuperative_drive_variables(),
       [](const opt::ConfigNode& root) { return make_recuperative_drive(root); }},
      {"conveyor_swing",
       "crank-rocker swing mechanism of a radial-rotary conveyor (seed 002)",
       conveyor_swing_variables(),
       [](const opt::ConfigNode& root) { return make_conveyor_swing(root); }},
      {"elastic_drive",
       "two-mass elastic drive with an induction motor, on SUNDIALS (seed 001)",
       elastic_drive_variables(),
       [](const opt::ConfigNode& root) { return make_elastic_drive(root); }},
  };
  return entries;
}

const std::vector<std::string>& config_keys() {
  static const std::vector<std::string> keys = {"problem", "model",  "variables", "objective",
                                                "constraints", "study", "output", "reference"};
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
