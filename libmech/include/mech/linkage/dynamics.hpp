// A linkage's kinetic energy and driving torque at one crank angle, from
// its solved state (kinematics.hpp) at constant crank speed w: each body's
// centre of mass G and angle t carry their transfer functions, so
//   T / w^2 = sum (m |G'|^2 + J t'^2) / 2,
//   M = w^2 sum (m G'' . G' + J t'' t') + g sum m G'_y,
// the torque the crank needs (virtual power: M w = dT/dt + dV/dt;
// positive resists the drive). docs/design/linkage.md, section 3.
#pragma once
#include "mech/linkage/kinematics.hpp"

namespace mech::linkage {

// A link's mass, inertia about its centre and its centre's position jets.
template <class S>
struct Inertial {
  S m, J;
  Vec<S> G;
};

// False for a massless link.
template <class S>
bool inertial(const Link& l, const S* v, const State<S>& st, int k, Inertial<S>& out) {
  const Vec<S>& o = st.point[static_cast<size_t>(l.origin)];
  const Vec<S>& e = st.axis[static_cast<size_t>(k)];
  if (l.mass_per_length != kNone) {
    const S& L = v[l.length];
    out.m = v[l.mass_per_length] * L;
    out.J = out.m * L * L / 12.0;
    out.G = o + S(L / 2.0) * e;
    return true;
  }
  if (l.mass == kNone) return false;
  out.m = v[l.mass];
  out.J = l.inertia == kNone ? S(0.0) : v[l.inertia];
  out.G = o;
  if (l.cg_u != kNone) out.G = out.G + v[l.cg_u] * e + v[l.cg_v] * rot90(e);
  return true;
}

template <class S>
struct DrivePoint {
  S energy;  // T / w^2 [kg m^2]: the reduced moment of inertia over 2
  S torque;  // M [N m]
};

template <class S>
DrivePoint<S> drive_point(const Chain& c, const S* v, const State<S>& st) {
  const S& w = v[c.crank().speed];
  S energy(0.0), inertia(0.0), weight(0.0);
  Inertial<S> b;
  const auto& links = c.links();
  for (size_t k = 0; k < links.size(); ++k) {
    if (!inertial(links[k], v, st, static_cast<int>(k), b)) continue;
    const Jet<S> t = st.angle(static_cast<int>(k));
    const Jet<S> &x = b.G.x, &y = b.G.y;
    energy += b.m * (x.d * x.d + y.d * y.d) + b.J * t.d * t.d;
    inertia += b.m * (x.dd * x.d + y.dd * y.d) + b.J * t.dd * t.d;
    weight += b.m * y.d;
  }
  return {S(energy / 2.0), S(w * w * inertia + c.gravity() * weight)};
}

}  // namespace mech::linkage
