// The `linkage` problem's metrics: what each measures over the cycle
// (a Quantity, a function of the crank angle whose maximum the searches
// find, and a Form that makes the metric of it), and the metrics a
// description offers, named by its outputs and loops (docs/linkage.md,
// "The metrics"). problem.cpp evaluates them.
#pragma once
#include <string>
#include <vector>

#include "opt/config.hpp"
#include "opt/model_problem.hpp"
#include "problems/linkage/description.hpp"

namespace problems::linkage {

// A function of the crank angle whose cycle maximum the metrics need.
enum class Kind {
  margin,          // -(a group's distance from a singular position)^2
  coordinate,      // an output's coordinate (a rocker's angle unwrapped about its direction at phi = 0)
  neg_coordinate,  // minus that
  speed,           // |an output's velocity|
  acceleration,    // |an output's acceleration|
  pressure,        // the sine of an RRP group's pressure angle (the rod against the line)
  transmission,    // minus the sine of an RRR group's transmission angle (acute)
  torque,          // |driving torque|
  energy,          // kinetic energy
  reaction,        // |a pin's reaction| (reactions.hpp's Joints order)
  guide,           // |a slide's normal force|
  shaking_force,   // |the inertia forces' resultant|
  shaking_moment,  // |their moment about the origin|
};
struct Quantity {
  Kind kind;
  int index;  // the output, the group, the pin or the slide; none for the whole mechanism's
};

// A metric: its form, over quantity q (and q2: a range's or a time
// ratio's minimum, as the maximum of minus the coordinate).
enum class Form {
  peak,      // the cycle maximum of q (a coordinate's minimum and the least transmission angle
             // as minus the maximum of minus them; the angles as the asin of their sines')
  range,     // max q + max q2: a stroke
  ratio,     // the crank angle from q2's maximum to q's over the rest: the time ratio
  grashof,   // a four-bar loop's p + q - s - l (group q.index), from the lengths alone
  mean,      // cycle means of q (the torque or the energy) ...
  mean_abs,  // ... of |q|
  rms,       // ... and its root mean square
  k1,        // seed 000's k1: the peak kinetic energy over the mean
  flywheel,  // the flywheel inertia that keeps the speed fluctuation: the torque's work swing / (delta w^2)
};
struct Metric {
  opt::MetricSpec spec;
  Form form;
  Quantity q, q2 = {Kind::margin, mech::linkage::kNone};
};

// The metrics description d offers, in the order of their ids.
std::vector<Metric> metrics_of(const Description& d);
std::vector<opt::MetricSpec> specs_of(const std::vector<Metric>& ms);

// A torque or energy metric named by the config's objective or constraints
// when the description gives it none (no masses, loads or springs): a
// located error that says what is missing, not just "unknown metric".
void check_dynamics_asked(const opt::ConfigNode& root, const std::vector<Metric>& metrics);

}  // namespace problems::linkage
