// The `linkage` problem's metrics: what each measures over the cycle
// (a Quantity, a function of the crank angle whose maximum the searches
// find, and a Form that makes the metric of it), and the metrics a
// description offers, named by its outputs and loops (docs/linkage.md,
// "The metrics"). problem.cpp evaluates them.
#pragma once
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
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
  pressure,        // the sine of an RRP (PRP) group's pressure angle: pressure_sine
  transmission,    // minus the sine of an RRR group's transmission angle (acute)
  torque,          // |driving torque|
  energy,          // kinetic energy
  reaction,        // |a pin's reaction| (reactions.hpp's Joints order)
  guide,           // |a slide's normal force|
  shaking_force,   // |the inertia forces' resultant|
  shaking_moment,  // |their moment about the origin|
};
// Whether kind k (pressure, transmission) measures groups of type t: a
// pressure angle is an RRP or PRP group's, a transmission angle an RRR group's.
inline bool measures(Kind k, mech::linkage::GroupType t) {
  using mech::linkage::GroupType;
  if (k == Kind::pressure) return t == GroupType::RRP || t == GroupType::PRP;
  return k == Kind::transmission && t == GroupType::RRR;
}

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
  swing,     // the torque's work swing: the largest less the smallest of its work about its mean
  flywheel,  // the flywheel inertia that keeps the speed fluctuation: the work swing / (delta w^2)
  k1,        // seed 000's k1: the peak kinetic energy over the mean
  k2,        // ... k2: the mean over T_min (least_mean_energy below)
  k3,        // ... k3: the peak over T_min
  least,     // T_min itself
};
struct Metric {
  opt::MetricSpec spec;
  Form form;
  Quantity q, q2 = {Kind::margin, mech::linkage::kNone};
};

// The metrics description d offers, in the order of their ids.
std::vector<Metric> metrics_of(const Description& d);
std::vector<opt::MetricSpec> specs_of(const std::vector<Metric>& ms);

// Seed 000's T_min (eq. 14) for any linkage: the kinetic energy its
// outputs with a mass would have if each ran its stroke at constant speed,
// out in half a revolution and back in the other, the sum over them of
// (1/2) M (stroke w / pi)^2. It counts the outputs whose energy is
// (1/2) M x'^2 of their one coordinate x: a slider with a mass on a ground
// line (M its mass; it only translates) and a link with a mass turning
// about a ground point, not the crank (M its inertia about that pivot, x
// its angle: a rocker; one that turns fully has no stroke). Their mean
// energy is at least T_min (mean x'^2 >= (mean |x'|)^2 >= (stroke w /
// pi)^2), so k2 >= 1 (the other bodies only add energy). The twin drive's two
// carts of stroke 2 r give 2 (1/2) m (2 r w / pi)^2 = 4 m r^2 w^2 / pi^2.
// The outputs that count, by index (none: no T_min, k2 or k3).
std::vector<int> moving_masses(const Description& d);

// Appends to `asked` the quantities metric m searches the cycle for (a
// group kind's: one per group of that type), each once; masses: the
// outputs T_min counts (moving_masses).
void ask(const Description& d, const std::vector<int>& masses, const Metric& m, std::vector<Quantity>& asked);

// Output link l's M at the values v: a slider's mass, or a link's
// inertia about its frame's origin (a rocker's pivot): a bar's q L^3 / 3,
// a body's J + m |cg|^2.
template <class S>
S moving_mass(const mech::linkage::Link& l, const S* v) {
  using mech::linkage::kNone;
  if (l.length == kNone) return v[l.mass];
  if (l.mass_per_length != kNone) return S(v[l.mass_per_length] * v[l.length] * v[l.length] * v[l.length] / 3.0);
  S m = l.inertia == kNone ? S(0.0) : v[l.inertia];
  if (l.cg_u != kNone) m += v[l.mass] * (v[l.cg_u] * v[l.cg_u] + v[l.cg_v] * v[l.cg_v]);
  return m;
}

// Group g's four-bar loop (the crank, its two links, the frame between
// the crank's pivot and the ground point): the sum of the middle two
// lengths less the shortest and the longest; >= 0 lets a link turn fully.
template <class S>
S grashof_margin(const mech::linkage::Chain& c, int g, const S* v) {
  const auto& gr = c.groups()[static_cast<size_t>(g)];
  const int ground = gr.p == c.crank().joint ? gr.q : gr.p;
  auto at = [&](int p) -> std::pair<S, S> {
    for (const auto& gp : c.ground_points())
      if (gp.first == p) return {v[static_cast<size_t>(gp.second.first)], v[static_cast<size_t>(gp.second.second)]};
    return {S(0.0), S(0.0)};
  };
  using std::sqrt;
  const auto [ax, ay] = at(c.crank().pivot);
  const auto [bx, by] = at(ground);
  const auto length = [&](int link) { return v[static_cast<size_t>(c.links()[static_cast<size_t>(link)].length)]; };
  const S dx = bx - ax, dy = by - ay;
  S d2 = dx * dx;
  d2 += S(dy * dy);
  S l[4] = {length(c.crank().link), length(gr.first), length(gr.second), S(sqrt(d2))};
  std::sort(l, l + 4, [](const S& a, const S& b) { return mech::value(a) < mech::value(b); });
  S middle = l[1], ends = l[0];
  middle += l[2], ends += l[3];
  return S(middle - ends);
}

// T_min at the values v over the outputs moving_masses gives, stroke(o)
// output o's stroke on S.
template <class S, class Stroke>
S least_mean_energy(const Description& d, const S* v, const std::vector<int>& outputs, Stroke&& stroke) {
  const S& w = v[d.chain.crank().speed];
  S sum(0.0);
  for (int o : outputs) {
    const auto& l = d.chain.links()[static_cast<size_t>(d.outputs[static_cast<size_t>(o)].link)];
    const S speed = stroke(o) * w / std::numbers::pi;
    sum += 0.5 * moving_mass(l, v) * speed * speed;
  }
  return sum;
}

// A torque or energy metric named by the config's objective or constraints
// when the description gives it none (no masses, loads or springs; for
// T_min, k2 and k3 no output that moving_masses counts): a located error
// that says what is missing, not just "unknown metric".
void check_dynamics_asked(const opt::ConfigNode& root, const std::vector<Metric>& metrics);

}  // namespace problems::linkage
