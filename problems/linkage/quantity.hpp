// The functions of the crank angle whose cycle maxima the linkage metrics
// are (metrics.hpp's Kind), at one solved state on any scalar: what
// problem.cpp puts on its grid, searches on a Dual in phi and takes again
// on the evaluation's scalar at the maximising angle (Danskin).
#pragma once
#include <cmath>
#include <vector>

#include "mech/inline.hpp"
#include "mech/linkage/reactions.hpp"
#include "problems/linkage/description.hpp"
#include "problems/linkage/metrics.hpp"

namespace problems::linkage {

// Group g's squared distance from a singular position (kinematics.hpp's
// measure) with its transfer functions: zero where the branch could flip.
// Inline: the grid takes its value alone, and the transfer functions'
// arithmetic drops out.
template <class T>
MECH_INLINE mech::linkage::Jet<T> margin2(const mech::linkage::Chain& c, int g, const mech::linkage::State<T>& st) {
  using mech::linkage::GroupType;
  using mech::linkage::Jet;
  const auto& gr = c.groups()[static_cast<size_t>(g)];
  const auto &e1 = st.axis[static_cast<size_t>(gr.first)], &e2 = st.axis[static_cast<size_t>(gr.second)];
  if (gr.type == GroupType::RRR || gr.type == GroupType::RPP || gr.type == GroupType::PRP) {
    const Jet<T> sine = mech::linkage::cross(e1, e2);
    return sine * sine;
  }
  if (gr.type == GroupType::RRP) {
    const Jet<T> cosine = mech::linkage::dot(e1, e2);
    return cosine * cosine;
  }
  const auto d = st.point[static_cast<size_t>(gr.p)] - st.point[static_cast<size_t>(gr.q)];
  const Jet<T>& s = st.slide[static_cast<size_t>(gr.first)];
  return s * s / mech::linkage::dot(d, d);
}

// Group g's pressure sine with its transfer functions, up to its sign: an
// RRP group's rod against its slider's line, e2 x e1; a PRP group's force
// through its pin, along one line's normal, against the other line, n1 x u2
// = -(u1 . u2) (the same angle both ways: 90 deg less the lines' angle).
template <class T>
mech::linkage::Jet<T> pressure_sine(const mech::linkage::Chain& c, int g, const mech::linkage::State<T>& st) {
  const auto& gr = c.groups()[static_cast<size_t>(g)];
  const auto &e1 = st.axis[static_cast<size_t>(gr.first)], &e2 = st.axis[static_cast<size_t>(gr.second)];
  return gr.type == mech::linkage::GroupType::PRP ? mech::linkage::dot(e1, e2) : mech::linkage::cross(e2, e1);
}

// Output q.index's coordinate (minus it for neg_coordinate) with its
// transfer functions: a slider's s, or a link's angle, unwrapped about
// its direction at phi = 0 (ref: per output x, y and the angle of that
// direction), while it swings less than half a turn either side of it.
template <class T>
mech::linkage::Jet<T> coordinate_jet(const Description& d, const Quantity& q, const mech::linkage::State<T>& st,
                                     const std::vector<double>& ref) {
  const auto& o = d.outputs[static_cast<size_t>(q.index)];
  mech::linkage::Jet<T> x;
  if (o.slides) {
    x = st.slide[static_cast<size_t>(o.link)];
  } else {
    const auto& e = st.axis[static_cast<size_t>(o.link)];
    const size_t i = static_cast<size_t>(q.index);
    const double rx = ref[3 * i], ry = ref[3 * i + 1];
    x = mech::linkage::angle_rates(e);
    x.v = T(mech::atan2_of(T(rx * e.y.v - ry * e.x.v), T(rx * e.x.v + ry * e.y.v)) + ref[3 * i + 2]);
  }
  return q.kind == Kind::neg_coordinate ? -x : x;
}

// Output q.index's coordinate rate and its slope (a rocker's without its
// angle's atan2), minus them for neg_coordinate.
template <class T>
mech::linkage::Jet<T> coordinate_rates(const Description& d, const Quantity& q, const mech::linkage::State<T>& st) {
  const auto& o = d.outputs[static_cast<size_t>(q.index)];
  const auto& s = st.slide[static_cast<size_t>(o.link)];
  const mech::linkage::Jet<T> x =
      o.slides ? mech::linkage::Jet<T>{T(0.0), s.d, s.dd} : mech::linkage::angle_rates(st.axis[static_cast<size_t>(o.link)]);
  return q.kind == Kind::neg_coordinate ? -x : x;
}

// For each asked quantity, the one that is the same coordinate with the
// other sign (its row negated is this one's), or asked.size(): in `out`.
inline const std::vector<size_t>& other_signs(const std::vector<Quantity>& asked, std::vector<size_t>& out) {
  out.assign(asked.size(), asked.size());
  for (size_t q = 0; q < asked.size(); ++q)
    for (size_t p = 0; p < asked.size(); ++p)
      if (asked[q].index == asked[p].index && asked[q].kind != asked[p].kind &&
          (asked[q].kind == Kind::coordinate || asked[q].kind == Kind::neg_coordinate) &&
          (asked[p].kind == Kind::coordinate || asked[p].kind == Kind::neg_coordinate))
        out[q] = p;
  return out;
}

// The torque's or the energy's quantity (kind k) from a drive point.
template <class T>
T drive_quantity(Kind k, const mech::linkage::DrivePoint<T>& p, const T& w) {
  using std::abs;
  return k == Kind::torque ? T(abs(p.torque)) : T(p.energy * w * w);
}
// The energy's slope in the crank angle from a drive point (jet_slope's).
template <class T>
T energy_slope(const mech::linkage::DrivePoint<T>& p, const T& w) {
  return T(p.energy_slope * w * w);
}

// Whether quantity kind k's slope in the crank angle comes from a state's
// second-order jets alone (jet_slope); the torque's, an acceleration's and
// the forces' need the third order (the chain on a Dual in phi).
inline bool has_jet_slope(Kind k) {
  return k == Kind::margin || k == Kind::coordinate || k == Kind::neg_coordinate || k == Kind::speed ||
         k == Kind::pressure || k == Kind::transmission || k == Kind::energy;
}

// Whether the grid keeps a quantity's slopes (its searches' first
// queries): a metric's whose slope the jets give (a margin's search runs
// only near a singular position).
inline bool grid_slopes(Kind k) { return k != Kind::margin && has_jet_slope(k); }
// Whether a quantity is computed on lanes (the joints' forces are not).
inline bool lane_kind(Kind k) {
  return k != Kind::reaction && k != Kind::guide && k != Kind::shaking_force && k != Kind::shaking_moment;
}

// Quantity q's slope in the crank angle (has_jet_slope(q.kind)).
template <class T>
T jet_slope(const Description& d, const Quantity& q, const T* v, const mech::linkage::State<T>& st) {
  const mech::linkage::Chain& c = d.chain;
  const T& w = v[c.crank().speed];
  auto sign = [](const T& x) {  // (on lanes, each lane's)
    if constexpr (mech::is_lanes<T>) {
      return mech::sign_of(x);
    } else {
      return double((mech::value(x) > 0) - (mech::value(x) < 0));
    }
  };
  auto sine = [&](bool pressure) {  // the group's pressure (transmission) sine as a jet
    const auto& g = c.groups()[static_cast<size_t>(q.index)];
    const auto &e1 = st.axis[static_cast<size_t>(g.first)], &e2 = st.axis[static_cast<size_t>(g.second)];
    return pressure ? pressure_sine(c, q.index, st) : mech::linkage::cross(e1, e2);
  };
  switch (q.kind) {
    case Kind::margin: return T(-margin2(c, q.index, st).d);
    case Kind::coordinate:
    case Kind::neg_coordinate: return coordinate_rates(d, q, st).d;
    case Kind::speed: {
      const auto x = coordinate_rates(d, {Kind::coordinate, q.index}, st);
      return T(sign(x.d) * x.dd * w);
    }
    case Kind::pressure: {
      const auto s = sine(true);
      return T(sign(s.v) * s.d);
    }
    case Kind::transmission: {
      const auto s = sine(false);
      return T(-sign(s.v) * s.d);
    }
    case Kind::energy: return energy_slope(mech::linkage::drive_point(c, v, st), w);
    default: return T(0.0);
  }
}

// The reactions of st, in a scratch of this thread's (one per scalar).
template <class T>
const mech::linkage::Reactions<T>& reactions_of(const mech::linkage::Chain& c, const mech::linkage::Joints& j,
                                                const T* v, const mech::linkage::State<T>& st) {
  thread_local mech::linkage::Reactions<T> r;
  r.resize(j, c);
  mech::linkage::reactions(c, j, v, st, r);
  return r;
}

// Quantity q of the solved state st (values v), on its scalar T.
template <class T>
T quantity(const Description& d, const mech::linkage::Joints& j, const Quantity& q, const T* v,
           const mech::linkage::State<T>& st, const std::vector<double>& ref) {
  using std::abs;
  using std::sqrt;
  const mech::linkage::Chain& c = d.chain;
  const T& w = v[c.crank().speed];
  auto axis = [&](int link) -> const mech::linkage::Vec<T>& { return st.axis[static_cast<size_t>(link)]; };
  auto cross_v = [](const mech::linkage::Vec<T>& a, const mech::linkage::Vec<T>& b) {
    return T(a.x.v * b.y.v - a.y.v * b.x.v);
  };
  const size_t i = static_cast<size_t>(q.index);
  switch (q.kind) {
    case Kind::margin: return T(-margin2(c, q.index, st).v);
    case Kind::coordinate:
    case Kind::neg_coordinate: return coordinate_jet(d, q, st, ref).v;
    case Kind::speed:
    case Kind::acceleration: {
      const auto x = coordinate_jet(d, {Kind::coordinate, q.index}, st, ref);
      return q.kind == Kind::speed ? T(abs(x.d) * w) : T(abs(x.dd) * (w * w));
    }
    case Kind::pressure: return T(abs(pressure_sine(c, q.index, st).v));
    case Kind::transmission: {
      const auto& g = c.groups()[i];
      return T(-abs(cross_v(axis(g.first), axis(g.second))));
    }
    case Kind::torque:
    case Kind::energy: return drive_quantity(q.kind, mech::linkage::drive_point(c, v, st), w);
    default: break;
  }
  if constexpr (!mech::is_lanes<T>) {  // the joints' forces: on scalars
    switch (q.kind) {
    case Kind::reaction: {
      const auto& r = reactions_of(c, j, v, st);
      return T(sqrt(T(r.x[i] * r.x[i] + r.y[i] * r.y[i])));
    }
    case Kind::guide: return T(abs(reactions_of(c, j, v, st).normal[i]));
    case Kind::shaking_force: {
      const auto& r = reactions_of(c, j, v, st);
      return T(sqrt(T(r.shaking_x * r.shaking_x + r.shaking_y * r.shaking_y)));
    }
    case Kind::shaking_moment: return T(abs(reactions_of(c, j, v, st).shaking_m));
    default: break;
    }
  }
  return T(0.0);
}

}  // namespace problems::linkage
