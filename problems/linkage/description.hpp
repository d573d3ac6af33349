// A linkage config's `model:` read into a mech::linkage::Chain and the
// parameter table of its numbers (one row per chain slot, named by its
// address: docs/design/linkage.md, sections 1-2). Bad input is an
// opt::ConfigError naming the file, line and key.
#pragma once
#include <string>
#include <vector>

#include "mech/linkage/chain.hpp"
#include "opt/config.hpp"
#include "opt/parameters.hpp"

namespace problems::linkage {

// A link whose motion the metrics report: a slider's or block's
// coordinate along its line, or a link's angle.
struct Output {
  int link;
  bool slides;
  std::string name;
};

struct Description {
  mech::linkage::Chain chain;
  std::vector<opt::Parameter> table;  // row i is the chain's slot i
  std::vector<Output> outputs;
  int cycle_points = 64;
  bool has_mass = false;
};

// The description under root's `model` (a built-in slider-crank when the
// config has none: `mechopt list` shows its metrics).
Description read_description(const opt::ConfigNode& root);

}  // namespace problems::linkage
