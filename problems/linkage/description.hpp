// A linkage config's `model:` read into a mech::linkage::Chain and the
// parameter table of its numbers (one row per chain slot, named by its
// address: docs/design/linkage.md, sections 1-2). Bad input is an
// opt::ConfigError naming the file, line and key.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mech/linkage/chain.hpp"
#include "opt/config.hpp"
#include "opt/parameters.hpp"
#include "opt/problem.hpp"

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
  // Grid points a revolution (model.cycle_points); 0: auto, the grid
  // from the groups' poles (problem.cpp's grid_points), 32 or 64 points.
  int cycle_points = 0;
  // The points of the grids that do not follow the poles (a law's contact
  // by its depth), and half the Gauss nodes a revolution of the means:
  // the given grid's, 64 under auto.
  int mean_points() const { return cycle_points ? cycle_points : 64; }
  bool has_mass = false;
  // Whether anything takes a torque from the crank: masses, loads, springs.
  bool has_dynamics() const { return has_mass || !chain.loads().empty() || !chain.springs().empty(); }
  // The coefficient of speed fluctuation a flywheel must keep, (w_max -
  // w_min) / w (model.speed_fluctuation, a table row), or kNone.
  mech::linkage::Slot speed_fluctuation = mech::linkage::kNone;
  // The contacts of laws given by their depth: rows the problem computes.
  std::vector<mech::linkage::Slot> derived;
};

// The description under root's `model` (a built-in slider-crank when the
// config has none: `mechopt list` shows its metrics).
Description read_description(const opt::ConfigNode& root);
// The description that is the map `model` (a section of another problem's
// model: the elastic drive's `machine`); errors name its keys.
Description read_model(const opt::ConfigNode& model);

// A variable naming a contact that follows its law's depth (a derived row,
// named `prefix` + its address) is an error at its key under `variables`.
void check_derived_not_free(const Description& d, const opt::ConfigNode& root, const std::vector<opt::Variable>& vars,
                            const std::string& prefix = "");

// What a torque or an energy needs of a description, as its errors say.
inline constexpr const char* kNeedsMasses = "masses (a link's mass or mass_per_length)";

}  // namespace problems::linkage

namespace problems::linkage {

// `mechopt kinematics`: the linkage of a `problem: linkage` config at its
// model values, at each crank angle (rad): every point's position,
// velocity and acceleration, every link's angle, rate and acceleration,
// each slider's coordinate, speed and acceleration along its line, the
// groups' transmission and pressure angles, the driving torque and the
// kinetic energy, SI. An angle where a group cannot assemble says so.
nlohmann::json kinematics_report(const opt::ConfigNode& root, const std::vector<double>& angles);

// The curves of a run's cycle.csv and cycle.svg at the values v (empty
// where the design cannot assemble): the driving torque, its loads' and
// its inertia's and gravity's shares, the kinetic energy, and each
// output's position or angle (unwrapped from its direction at phi = 0).
opt::CycleCurves cycle_curves(const Description& d, const std::vector<double>& v, int n);

// "0,37,90 deg": the angles in radians; a unit after the last item applies
// to the items written without one. std::invalid_argument names a bad item.
std::vector<double> crank_angles(const std::string& list);

}  // namespace problems::linkage
