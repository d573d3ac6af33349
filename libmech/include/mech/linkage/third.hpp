// The third derivatives in the crank angle of a solved chain (kinematics.hpp
// gives positions to the second), group by group, and from them the
// driving torque's slope: what a search for the torque's peak asks at
// every step (drive_slope, with the drive point itself). The chain on a
// Dual in phi gives the same (solve_lanes_at) at about twice the cost of
// the second-order chain; this pass adds one linear solve per group. RRR and RRP groups (docs/design/linkage.md,
// section 7); a chain with others takes the Dual.
//
// Each group's constraint differentiated three times: |B - P|^2 = a^2
// gives r . r''' + 3 r' . r'' = 0 (r = B - P), linear in the new joint's
// B''' with the velocity equations' matrix. The crank's axis e turns at
// sense: e''' = -e'. A link's angle t has t' = e x e', t'' = e x e'', so
// t''' = e' x e'' + e x e'''.
#pragma once
#include <vector>

#include "mech/linkage/dynamics.hpp"
#include "mech/linkage/kinematics.hpp"

namespace mech::linkage {

// A plane vector's third derivative.
template <class S>
struct Third {
  S x, y;
};

// The third derivatives of a state's points, axes and slides.
template <class S>
struct Thirds {
  std::vector<Third<S>> point, axis;
  std::vector<S> slide;
  void resize(const Chain& c) {
    point.assign(c.point_names().size(), {S(0.0), S(0.0)});
    axis.assign(c.links().size(), {S(0.0), S(0.0)});
    slide.assign(c.links().size(), S(0.0));
  }
};

// Whether third_order can take the chain: RRR and RRP groups only.
inline bool has_third_order(const Chain& c) {
  for (const Group& g : c.groups())
    if (g.type != GroupType::RRR && g.type != GroupType::RRP) return false;
  return true;
}

namespace detail {

template <class S>
Third<S> turned(const Third<S>& a) {  // rot90
  return {S(-a.y), a.x};
}
// The points on link l at its origin's and its axis's third derivatives.
template <class S>
void place_thirds(const Link& l, const S* v, Thirds<S>& t, const Third<S>& e) {
  const Third<S>& o = t.point[static_cast<size_t>(l.origin)];
  const Third<S> n = turned(e);
  for (const LocalPoint& lp : l.points)
    t.point[static_cast<size_t>(lp.point)] = {S(o.x + v[lp.u] * e.x + v[lp.v] * n.x),
                                              S(o.y + v[lp.u] * e.y + v[lp.v] * n.y)};
}

}  // namespace detail

// The third derivatives of st (solved at v; has_third_order(c)) into t.
template <class S>
void third_order(const Chain& c, const S* v, const State<S>& st, Thirds<S>& t) {
  const auto& links = c.links();
  auto at = [&](int p) -> const Vec<S>& { return st.point[static_cast<size_t>(p)]; };
  auto third = [&](int p) -> Third<S>& { return t.point[static_cast<size_t>(p)]; };
  auto dot = [](const S& ax, const S& ay, const S& bx, const S& by) { return S(ax * bx + ay * by); };
  // Ground points keep zeros (resize). The crank: e''' = -e'.
  const Crank& k = c.crank();
  const Vec<S>& e = st.axis[static_cast<size_t>(k.link)];
  const Third<S> e3{S(-e.x.d), S(-e.y.d)};
  const Link& crank = links[static_cast<size_t>(k.link)];
  t.axis[static_cast<size_t>(k.link)] = e3;
  third(k.joint) = {S(third(k.pivot).x + v[crank.length] * e3.x), S(third(k.pivot).y + v[crank.length] * e3.y)};
  detail::place_thirds(crank, v, t, e3);
  for (const Group& g : c.groups()) {
    const Link &first = links[static_cast<size_t>(g.first)], &second = links[static_cast<size_t>(g.second)];
    const Vec<S>& B = at(g.joint);
    const Vec<S>& P = at(g.p);
    const Third<S>& P3 = third(g.p);
    // r = B - P and its first two derivatives.
    const S rx = B.x.v - P.x.v, ry = B.y.v - P.y.v, r1x = B.x.d - P.x.d, r1y = B.y.d - P.y.d;
    const S r2x = B.x.dd - P.x.dd, r2y = B.y.dd - P.y.dd;
    Third<S> B3, e2;
    if (g.type == GroupType::RRR) {
      const Vec<S>& Q = at(g.q);
      const Third<S>& Q3 = third(g.q);
      const S qx = B.x.v - Q.x.v, qy = B.y.v - Q.y.v;
      const S c1 = S(dot(rx, ry, P3.x, P3.y) - 3.0 * dot(r1x, r1y, r2x, r2y));
      const S c2 = S(dot(qx, qy, Q3.x, Q3.y) -
                     3.0 * dot(S(B.x.d - Q.x.d), S(B.y.d - Q.y.d), S(B.x.dd - Q.x.dd), S(B.y.dd - Q.y.dd)));
      const S det = S(rx * qy - ry * qx);
      B3 = {S((c1 * qy - c2 * ry) / det), S((rx * c2 - qx * c1) / det)};
      const S& b = v[second.length];
      e2 = {S((B3.x - Q3.x) / b), S((B3.y - Q3.y) / b)};
    } else {  // RRP: B = T0 + s u, T0 = T + offset n
      const Vec<S>& u = st.axis[static_cast<size_t>(g.second)];
      Third<S> u3{S(0.0), S(0.0)};
      if (second.line_on != kNone) {  // u = cos(alpha) eo + sin(alpha) rot90(eo)
        const Third<S>& eo3 = t.axis[static_cast<size_t>(second.line_on)];
        const auto& trig = st.trig[2 * static_cast<size_t>(g.second)];  // (solve's cos and sin of alpha)
        const S ca = S(trig[1]), sa = S(trig[2]);
        u3 = {S(ca * eo3.x - sa * eo3.y), S(ca * eo3.y + sa * eo3.x)};
      }
      const Third<S>& T3 = third(second.line_through);
      const S offset = second.line_offset == kNone ? S(0.0) : v[second.line_offset];
      const Jet<S>& s = st.slide[static_cast<size_t>(g.second)];
      // K = T0''' + 3 s'' u' + 3 s' u'' + s u''' - P''', so B''' = P''' + K + s''' u.
      const S kx = S(T3.x - offset * u3.y + 3.0 * (s.dd * u.x.d) + 3.0 * (s.d * u.x.dd) + s.v * u3.x - P3.x);
      const S ky = S(T3.y + offset * u3.x + 3.0 * (s.dd * u.y.d) + 3.0 * (s.d * u.y.dd) + s.v * u3.y - P3.y);
      const S s3 = S((-3.0 * dot(r1x, r1y, r2x, r2y) - dot(rx, ry, kx, ky)) / dot(rx, ry, u.x.v, u.y.v));
      t.slide[static_cast<size_t>(g.second)] = s3;
      B3 = {S(P3.x + kx + s3 * u.x.v), S(P3.y + ky + s3 * u.y.v)};
      e2 = u3;
    }
    third(g.joint) = B3;
    const S& a = v[first.length];
    const Third<S> e1{S((B3.x - P3.x) / a), S((B3.y - P3.y) / a)};
    t.axis[static_cast<size_t>(g.first)] = e1;
    t.axis[static_cast<size_t>(g.second)] = e2;
    detail::place_thirds(first, v, t, e1);
    detail::place_thirds(second, v, t, e2);
  }
}

// A drive point on lanes with the slope of |M| in the crank angle.
struct DriveSlope {
  DrivePoint<Lanes> point;  // drive_point's, bit for bit (the same sums in the same order)
  Lanes slope;              // d|M|/dphi
};

// drive_point on lanes with the slope of |M| (M: its torque), from st and
// its thirds t: M' = w^2 (sum m (G''' . G' + |G''|^2) + J (t''' t' +
// t''^2)) + g sum m G''_y less the loads' and the springs' generalised
// force's slope, a load's size' rate + size rate' (lane_load's).
inline DriveSlope drive_slope(const Chain& c, const Lanes* v, const State<Lanes>& st, const Thirds<Lanes>& t) {
  using L = Lanes;
  using std::sqrt;
  const auto& links = c.links();
  L inertia(0.0), half(0.0), half1(0.0), weight(0.0), weight1(0.0);
  Inertial<L> b;
  for (size_t k = 0; k < links.size(); ++k) {
    const Link& l = links[k];
    if (!inertial(l, v, st, static_cast<int>(k), b)) continue;
    const Third<L>& o3 = t.point[static_cast<size_t>(l.origin)];
    const Third<L>& e3 = t.axis[k];
    Third<L> G3 = o3;  // inertial's centre, G = o + u e + w rot90(e)
    if (l.mass_per_length != kNone) {
      const L u = L(v[l.length] / 2.0);
      G3 = {L(o3.x + u * e3.x), L(o3.y + u * e3.y)};
    } else if (l.cg_u != kNone) {
      G3 = {L(o3.x + v[l.cg_u] * e3.x - v[l.cg_v] * e3.y), L(o3.y + v[l.cg_u] * e3.y + v[l.cg_v] * e3.x)};
    }
    const Vec<L>& e = st.axis[k];
    const Jet<L> r = st.rates(static_cast<int>(k));
    const L t3 = L(e.x.d * e.y.dd - e.y.d * e.x.dd + e.x.v * e3.y - e.y.v * e3.x);
    const Jet<L> &x = b.G->x, &y = b.G->y;
    L in = b.m * (x.d * x.d + y.d * y.d), h = b.m * (x.dd * x.d + y.dd * y.d),  // (body_sums' terms)
        h1 = b.m * (G3.x * x.d + G3.y * y.d + x.dd * x.dd + y.dd * y.dd);
    if (b.turns) in += b.J * r.d * r.d, h += b.J * r.dd * r.d, h1 += b.J * (t3 * r.d + r.dd * r.dd);
    inertia += in, half += h, half1 += h1;
    weight += b.m * y.d;
    weight1 += b.m * y.dd;
  }
  // The loads' generalised force (load_power) and its slope.
  L power(0.0), power1(0.0), size, rate, size1, rate1;
  Lanes on;
  for (const Load& l : c.loads()) {
    lane_load(c, l, v, st, st.phi, on, size, rate, &size1, &rate1);
    power += where(on, L(size * rate));
    power1 += where(on, L(size1 * rate + size * rate1));
  }
  // A spring's -T l': T' = k l', l'' = (|d'|^2 - l'^2) / l + u . d''.
  for (const Spring& sp : c.springs()) {
    const Tension<L> s = tension(sp, v, st);
    const Vec<L> d = st.point[static_cast<size_t>(sp.p)] - st.point[static_cast<size_t>(sp.q)];
    const L length = sqrt(L(d.x.v * d.x.v + d.y.v * d.y.v));
    const L rate1 = L((d.x.d * d.x.d + d.y.d * d.y.d - s.length_rate * s.length_rate) / length + s.ux * d.x.dd +
                      s.uy * d.y.dd);
    power -= s.tension * s.length_rate;
    power1 -= v[sp.rate] * s.length_rate * s.length_rate + s.tension * rate1;
  }
  const L w2 = v[c.crank().speed] * v[c.crank().speed];
  const L torque = L(w2 * half + c.gravity() * weight - power), slope = L(w2 * half1 + c.gravity() * weight1 - power1);
  return {{L(inertia / 2.0), torque, half}, L(sign_of(torque) * slope)};
}

}  // namespace mech::linkage
