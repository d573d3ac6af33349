// A linkage's kinetic energy and driving torque at one crank angle, from
// its solved state (kinematics.hpp) at constant crank speed w: each body's
// centre of mass G and angle t carry their transfer functions, so
//   T / w^2 = sum (m |G'|^2 + J t'^2) / 2,
//   M = w^2 sum (m G'' . G' + J t'' t') + g sum m G'_y - sum Q_load,
// the torque the crank needs in its sense of rotation (virtual power:
// M w = dT/dt + dV/dt + the loads' power taken; positive resists the
// drive), a load's generalised force Q its power per unit crank speed: a
// force F along a slider's line u at its pin B, F u . B'; a torque T on a
// link, T t'; a friction torque, -|T| |t_i' - t_j'|. docs/design/linkage.md,
// section 3.
#pragma once
#include <cmath>

#include "mech/angles.hpp"
#include "mech/linkage/kinematics.hpp"

namespace mech::linkage {

// A link's mass, inertia about its centre and its centre's position jets
// (*G: a point of the state where the centre is one, else `own`; not
// copied). turns: J is given (a slider's or a point mass's is 0: the sums
// skip its terms, the same bits).
template <class S>
struct Inertial {
  S m, J;
  const Vec<S>* G;
  Vec<S> own;
  bool turns;
};

// False for a massless link.
template <class S>
MECH_INLINE bool inertial(const Link& l, const S* v, const State<S>& st, int k, Inertial<S>& out) {
  const Vec<S>& o = st.point[static_cast<size_t>(l.origin)];
  const Vec<S>& e = st.axis[static_cast<size_t>(k)];
  if (l.mass_per_length != kNone) {
    const S& L = v[l.length];
    out.m = v[l.mass_per_length] * L;
    out.J = out.m * L * L / 12.0;
    out.own = o + S(L / 2.0) * e;
    out.G = &out.own;
    out.turns = true;
    return true;
  }
  if (l.mass == kNone) return false;
  out.m = v[l.mass];
  out.turns = l.inertia != kNone;
  out.J = out.turns ? v[l.inertia] : S(0.0);
  out.G = &o;
  if (l.cg_u != kNone) out.own = o + v[l.cg_u] * e + v[l.cg_v] * rot90(e), out.G = &out.own;
  return true;
}

// A table's row at x: its value y0 + slope (x - x0) there (linear between
// rows; constant outside, slope 0).
struct TableRow {
  double y0, x0, slope;
};
inline TableRow table_row(const Load& l, double x) {
  const auto& xs = l.xs;
  if (x <= xs.front()) return {l.ys.front(), 0.0, 0.0};
  if (x >= xs.back()) return {l.ys.back(), 0.0, 0.0};
  size_t i = 1;
  while (xs[i] < x) ++i;
  return {l.ys[i - 1], xs[i - 1], (l.ys[i] - l.ys[i - 1]) / (xs[i] - xs[i - 1])};
}

// A table's value at x.
template <class S>
S interpolate(const Load& l, const S& x) {
  const TableRow r = table_row(l, value(x));
  return S(r.y0 + r.slope * (x - r.x0));
}

// The rate whose sign switches load l (a `when`, an opposing load, a
// friction), with its slope in the crank angle: a force's slider's ds/dphi,
// a torque's link's rate (less `other`'s).
template <class S>
Jet<S> switch_rate(const Load& l, const State<S>& st) {
  if (l.kind == Load::Kind::force) {
    const Jet<S>& s = st.slide[static_cast<size_t>(l.link)];
    return {s.d, s.dd, S(0.0)};
  }
  Jet<S> t = st.rates(l.link);
  if (l.other != kNone) t = t - st.rates(l.other);
  return {t.d, t.dd, S(0.0)};
}
inline bool switching(const Load& l) { return l.when != 0 || l.opposing || l.kind == Load::Kind::friction; }

// Load l's rate (a force: u . B' at its slider's pin B on its line u; a
// torque or a friction: its link's t', less `other`'s) and the coordinate
// its table over position reads (the slider's s, the link's angle).
template <class S>
void load_rate(const Chain& c, const Load& l, const State<S>& st, S& rate, S& coordinate) {
  const size_t k = static_cast<size_t>(l.link);
  if (l.kind == Load::Kind::force) {
    const Vec<S>& u = st.axis[k];
    const Vec<S>& B = st.point[static_cast<size_t>(c.links()[k].origin)];
    rate = S(u.x.v * B.x.d + u.y.v * B.y.d);
    coordinate = st.slide[k].v;
  } else {
    rate = st.rates(l.link).d;
    if (l.other != kNone) rate = S(rate - st.rates(l.other).d);
    if (l.over == Load::Over::position) coordinate = st.angle(l.link).v;
  }
}

// A load at crank angle phi as `size`, its generalised force per unit of
// `rate`, so that its power per unit crank speed is size * rate. A force:
// size along its slider's line u at the pin B, rate u . B'; a torque or a
// friction: size a couple on the link (minus on `other`), rate t' - t_o'.
// Opposing loads and friction take the size's sign against the rate; an
// efficiency divides it. False while `when` holds the load off, or a
// pressure law's depth is below zero.
template <class S>
bool load_action(const Chain& c, const Load& l, const S* v, const State<S>& st, const S& phi, S& size, S& rate) {
  using std::abs;
  using std::exp;
  const size_t k = static_cast<size_t>(l.link);
  S coordinate(0.0);  // what a table reads
  load_rate(c, l, st, rate, coordinate);
  double along = l.kind == Load::Kind::force ? value(st.slide[k].d) : value(rate), sign_rate = value(rate);
  if (st.held_load != kNone && &l == &c.loads()[static_cast<size_t>(st.held_load)]) {
    const double slope = value(switch_rate(l, st).d);
    along = sign_rate = st.held_side * slope;
  }
  if ((l.when > 0 && !(along > 0)) || (l.when < 0 && !(along < 0))) return false;
  if (l.law_a != kNone) {
    const S depth = S(coordinate - v[l.law_contact]);
    if (!(value(depth) >= 0)) return false;
    const S growth = exp(S(v[l.law_b] * depth));  // named: AutoDiff's products of temporaries
    const S pressure = S(v[l.law_a] * growth);
    size = S(-(v[l.law_area] * pressure));
  } else if (l.over == Load::Over::none) {
    size = v[l.value];
  } else if (l.over == Load::Over::position) {
    size = interpolate(l, coordinate);
  } else {
    size = interpolate(l, S(phi + (wrap_angle(value(phi)) - value(phi))));  // phi in [0, 2 pi)
  }
  // -|size| |rate| / eta: its sign against the rate's, the division before
  // the sign (the same bits: off lane_load's chain through the rate).
  const bool opposing = l.kind == Load::Kind::friction || l.opposing;
  if (opposing) size = abs(size);
  if (l.efficiency != kNone) size = S(size / v[l.efficiency]);
  if (opposing) size = S(-(size * double((sign_rate > 0) - (sign_rate < 0))));
  return true;
}

// A spring's tension (rate times stretch: > 0 pulls p and q together), the
// unit vector from q to p and its length's rate.
template <class S>
struct Tension {
  S tension, ux, uy, length_rate;
};

template <class S>
Tension<S> tension(const Spring& sp, const S* v, const State<S>& st) {
  using std::sqrt;
  const Vec<S> d = st.point[static_cast<size_t>(sp.p)] - st.point[static_cast<size_t>(sp.q)];
  const S length = sqrt(S(d.x.v * d.x.v + d.y.v * d.y.v));
  const S ux = d.x.v / length, uy = d.y.v / length;
  return {S(v[sp.rate] * (length - v[sp.free_length])), ux, uy, S(ux * d.x.d + uy * d.y.d)};
}

// Load l at kLanes crank angles phi as load_action takes it (solve_lanes'
// state; L: Lanes, or LaneDual with design derivatives): where it acts
// (on: 1 or 0), its size and rate, its branches (a `when`'s stroke, a
// law's contact, a table's row, an opposing load's sign) taken lane by
// lane from the values. With slope (size1, rate1 given) their slopes in
// phi too (third.hpp's torque slope). No load is held (means take no
// one-sided limit).
template <class L>
void lane_load(const Chain& c, const Load& l, const L* v, const State<L>& st, const Lanes& phi, Lanes& on, L& size,
               L& rate, L* size1 = nullptr, L* rate1 = nullptr) {
  using std::abs;
  using std::exp;
  const size_t k = static_cast<size_t>(l.link);
  const bool force = l.kind == Load::Kind::force;
  L coordinate(0.0), coordinate1(0.0);
  load_rate(c, l, st, rate, coordinate);
  if (rate1) {  // (u . B')' and (t' - t_o')', the coordinate's s' or t'
    if (force) {
      const Vec<L>& u = st.axis[k];
      const Vec<L>& B = st.point[static_cast<size_t>(c.links()[k].origin)];
      *rate1 = L(u.x.d * B.x.d + u.x.v * B.x.dd + u.y.d * B.y.d + u.y.v * B.y.dd);
      coordinate1 = st.slide[k].d;
    } else {
      const Jet<L> r = st.rates(l.link);
      *rate1 = l.other == kNone ? r.dd : L(r.dd - st.rates(l.other).dd);
      coordinate1 = r.d;
    }
  }
  const Lanes along = lane_values(force ? st.slide[k].d : rate), sign = sign_of(lane_values(rate));
  on = l.when > 0 ? step(along) : l.when < 0 ? step(-along) : Lanes(1.0);
  L slope1(0.0);  // the size's slope
  if (l.law_a != kNone) {
    const L depth = L(coordinate - v[l.law_contact]);
    on = Lanes(lane_values(depth).v >= 0 ? on.v : Lanes::Raw{});  // off where not in contact
    const L growth = exp(L(v[l.law_b] * depth));
    size = L(-(v[l.law_area] * L(v[l.law_a] * growth)));
    if (size1) slope1 = L(size * v[l.law_b] * coordinate1);
  } else if (l.over == Load::Over::none) {
    size = v[l.value];
  } else {
    // Each lane's row: y0 + slope (x - x0), constant outside the table.
    const bool by_position = l.over == Load::Over::position;
    Lanes x = lane_values(coordinate), y0, slope(0.0), x0(0.0);
    for (int j = 0; j < kLanes; ++j) {
      if (!by_position) x[j] = phi[j] + (wrap_angle(phi[j]) - phi[j]);  // phi in [0, 2 pi)
      const TableRow row = table_row(l, x[j]);
      y0[j] = row.y0, x0[j] = row.x0, slope[j] = row.slope;
    }
    size = L(L(y0) + L(slope) * L((by_position ? coordinate : L(x)) - L(x0)));
    if (size1) slope1 = by_position ? L(L(slope) * coordinate1) : L(slope);
  }
  // -|size| sign(rate) / eta, as load_action's: the division before the sign.
  const bool opposing = l.kind == Load::Kind::friction || l.opposing;
  if (opposing) {
    if (size1) slope1 = L(L(sign_of(lane_values(size))) * slope1);
    size = abs(size);
  }
  if (l.efficiency != kNone) {
    size = L(size / v[l.efficiency]);
    if (size1) slope1 = L(slope1 / v[l.efficiency]);
  }
  if (opposing) {
    size = L(-(size * L(sign)));
    if (size1) slope1 = L(-(slope1 * L(sign)));
  }
  if (size1) *size1 = slope1;
}

// load_action's size times rate at kLanes crank angles phi, summed over
// the loads (lane_load).
template <class L>
L lane_loads(const Chain& c, const L* v, const State<L>& st, const Lanes& phi) {
  L sum(0.0), size, rate;
  Lanes on;
  for (const Load& l : c.loads()) {
    lane_load(c, l, v, st, phi, on, size, rate);
    sum += where(on, L(size * rate));
  }
  return sum;
}

// The loads' generalised force at crank angle phi (their power per unit
// crank speed), the springs' with them unless `springs` is false; on
// lanes, kLanes angles at once.
template <class S>
S load_power(const Chain& c, const S* v, const State<S>& st, const S& phi, bool springs = true) {
  S sum(0.0), size(0.0), rate(0.0);
  if constexpr (is_lanes<S>) {
    sum = lane_loads(c, v, st, lane_values(phi));
  } else {
    for (const Load& l : c.loads())
      if (load_action(c, l, v, st, phi, size, rate)) sum += size * rate;
  }
  if (springs)
    for (const Spring& sp : c.springs()) {
      const Tension<S> t = tension(sp, v, st);
      sum -= t.tension * t.length_rate;
    }
  return sum;
}

template <class S>
struct DrivePoint {
  S energy;  // T / w^2 [kg m^2]: the reduced moment of inertia over 2
  S torque;  // M [N m]
  S energy_slope;  // d(T / w^2)/dphi: the inertia forces' share of M / w^2
};

// The bodies' sums at unit crank speed: 2 T / w^2 = sum m |G'|^2 + J t'^2
// (the reduced moment of inertia), its half slope sum m G'' . G' + J t''
// t', and sum m G'_y (gravity's torque over g); kInertiaOnly: the first
// alone (the others left 0).
template <class S>
struct BodySums {
  S inertia, half_slope, weight;
};

template <class S, bool kInertiaOnly = false>
BodySums<S> body_sums(const Chain& c, const S* v, const State<S>& st) {
  BodySums<S> out{S(0.0), S(0.0), S(0.0)};
  Inertial<S> b;
  const auto& links = c.links();
  for (size_t k = 0; k < links.size(); ++k) {
    if (!inertial(links[k], v, st, static_cast<int>(k), b)) continue;
    const Jet<S> t = st.rates(static_cast<int>(k));
    const Jet<S> &x = b.G->x, &y = b.G->y;
    S inertia = b.m * (x.d * x.d + y.d * y.d);
    if (b.turns) inertia += b.J * t.d * t.d;
    out.inertia += inertia;
    if constexpr (kInertiaOnly) continue;
    S half = b.m * (x.dd * x.d + y.dd * y.d);
    if (b.turns) half += b.J * t.dd * t.d;
    out.half_slope += half;
    out.weight += b.m * y.d;
  }
  return out;
}

template <class S>
DrivePoint<S> drive_point(const Chain& c, const S* v, const State<S>& st) {
  const S& phi = st.phi;
  const S& w = v[c.crank().speed];
  const BodySums<S> b = body_sums(c, v, st);
  const S w2 = w * w;
  S torque = w2 * b.half_slope;
  torque += S(c.gravity() * b.weight);
  torque -= load_power(c, v, st, phi);
  return {S(b.inertia / 2.0), torque, b.half_slope};
}

}  // namespace mech::linkage
