// Positions of a linkage's points and the axes of its links at one crank
// angle, on jets: their first and second transfer functions come exactly
// with them. Each class II group is its closed form (docs/design/linkage.md,
// "Groups"); the groups are solved in the chain's order, each link's points
// right after the link.
#pragma once
#include <array>
#include <cmath>
#include <vector>

#include "mech/autodiff.hpp"
#include "mech/linkage/chain.hpp"
#include "mech/linkage/jet.hpp"
#include "mech/simd.hpp"

namespace mech::linkage {

// LaneDuals whose jets carry derivatives in phi up to kOrder alone (jet.hpp's
// kJetOrder; the rest left 0): LaneVelocity (1), what a kinetic energy's
// design gradient needs, at about half a jet's products; LanePosition
// (0), a coordinate's design gradient at its maximum's angle. Their
// arithmetic is LaneDual's.
template <int N, int kOrder>
struct LaneJets : LaneDual<N> {
  using LaneDual<N>::LaneDual;
  LaneJets(const LaneDual<N>& x) : LaneDual<N>(x) {}  // NOLINT
};
template <int N, int kOrder>
inline constexpr int kJetOrder<LaneJets<N, kOrder>> = kOrder;
template <int N>
using LaneVelocity = LaneJets<N, 1>;
template <int N>
using LanePosition = LaneJets<N, 0>;
// A lane form's velocity and position forms (Lanes: itself).
template <class L>
struct VelocityForm {
  using type = L;
  using position = L;
};
template <int N>
struct VelocityForm<LaneDual<N>> {
  using type = LaneVelocity<N>;
  using position = LanePosition<N>;
};
template <class L>
using velocity_lanes = typename VelocityForm<L>::type;
template <class L>
using position_lanes = typename VelocityForm<L>::position;

}  // namespace mech::linkage

namespace mech {
template <int N, int kOrder>
inline constexpr bool is_lanes<linkage::LaneJets<N, kOrder>> = true;
}  // namespace mech

namespace mech::linkage {

// The linkage at one crank angle. Sized once for a chain (resize), then
// overwritten by every solve: no allocation per angle.
template <class S>
struct State {
  std::vector<Vec<S>> point;   // every point, by index
  std::vector<Vec<S>> axis;    // each link's unit x axis
  std::vector<Jet<S>> slide;   // a slider's (block's) coordinate along its line; 0 for other links
  // Per group, its distance from a singular position (see solve); on
  // lanes, each lane's.
  std::vector<std::conditional_t<is_lanes<S>, Lanes, double>> margin;
  int failed = kNone;          // the group that could not assemble, when solve returned false
  S phi = S(0.0);              // the crank angle it was solved at
  // A load held on one side of its switch (dynamics.hpp's `switching`):
  // load `held_load` acts as it does just past the angle solved at (side
  // +1) or just before it (-1), its rate's sign taken from the rate's
  // slope. What the one-sided limits at a switch need; kNone: none.
  int held_load = kNone, held_side = 0;
  // The crank's phase whose cosine and sine are kept (doubles: solve's
  // angle sum with a given cosine and sine of phi).
  double phase = HUGE_VAL, phase_cos = 1, phase_sin = 0;
  // Per link, its line's and its slot's angle with their cosine and sine,
  // kept while the angle is (fixed_cos_sin).
  std::vector<std::array<std::conditional_t<is_lanes<S>, Lanes, double>, 3>> trig;

  void resize(const Chain& c) {
    point.resize(c.point_names().size());
    axis.resize(c.links().size());
    slide.assign(c.links().size(), constant(S(0.0)));
    margin.resize(c.groups().size());
    trig.assign(2 * c.links().size(), {HUGE_VAL, 0.0, 0.0});
  }
  // A link's angle in (-pi, pi] with its transfer functions.
  Jet<S> angle(int link) const { return angle_of(axis[static_cast<size_t>(link)]); }
  // Its transfer functions alone (the value 0).
  Jet<S> rates(int link) const { return angle_rates(axis[static_cast<size_t>(link)]); }
};

namespace detail {

// to = from; where jets on S carry fewer derivatives (kJetOrder), those
// alone (the rest stay 0, as State's resize left them: no stores of
// zeros).
template <class S>
MECH_INLINE void put(Jet<S>& to, const Jet<S>& from) {
  to.v = from.v;
  if constexpr (kJetOrder<S> >= 1) to.d = from.d;
  if constexpr (kJetOrder<S> >= 2) to.dd = from.dd;
}
template <class S>
MECH_INLINE void put(Vec<S>& to, const Vec<S>& from) {
  put(to.x, from.x), put(to.y, from.y);
}

template <class S>
Vec<S> constant_point(const S& x, const S& y) {
  return {constant(x), constant(y)};
}

// The points fixed on link k at origin + u e + v n.
template <class S>
void place_points(const Link& l, const S* v, State<S>& st, const Vec<S>& e) {
  const Vec<S>& o = st.point[static_cast<size_t>(l.origin)];
  const Vec<S> n = rot90(e);
  for (const LocalPoint& lp : l.points)
    put(st.point[static_cast<size_t>(lp.point)], o + v[lp.u] * e + v[lp.v] * n);
}

// The ground points (unless `ground` is false: st has them at v's values
// already), then the crank at its axis e (with its transfer functions) and
// the points on it.
template <class S>
void place_crank(const Chain& c, const S* v, State<S>& st, const Vec<S>& e, bool ground = true) {
  if (ground)
    for (const auto& [p, xy] : c.ground_points())
      put(st.point[static_cast<size_t>(p)], constant_point(v[xy.first], v[xy.second]));
  const Crank& k = c.crank();
  const Link& l = c.links()[static_cast<size_t>(k.link)];
  put(st.axis[static_cast<size_t>(k.link)], e);
  put(st.point[static_cast<size_t>(k.joint)], st.point[static_cast<size_t>(k.pivot)] + v[l.length] * e);
  place_points(l, v, st, e);
}

// The crank's axis from cos and sin of its angle theta = phase + sense
// phi, which turns at sense: e' = sense rot90(e), e'' = -e.
template <class S>
Vec<S> crank_axis(const S& ct, const S& sn, double sense) {
  return {{ct, S(-sense * sn), S(-ct)}, {sn, S(sense * ct), S(-sn)}};
}

// sin and cos of the crank's angle x on any scalar: their values are
// mech::sincos's (simd.hpp's kernels: a lane, a double and a dual's value
// at the same angle agree bit for bit, and four lanes cost about what one
// angle does), their derivatives by the chain rule.
template <class S>
MECH_INLINE void crank_sin_cos(const S& x, S& s, S& c) {
  if constexpr (std::is_same_v<S, double> || std::is_same_v<S, Lanes>) {
    mech::sincos(x, s, c);
  } else if constexpr (is_lanes<S>) {  // LaneDual
    Lanes sv, cv;
    mech::sincos(x.v, sv, cv);
    s = S(sv), c = S(cv);
    const Lanes minus_sin = -sv;
    for (size_t i = 0; i < x.d.size(); ++i) s.d[i] = cv * x.d[i], c.d[i] = minus_sin * x.d[i];
  } else if constexpr (std::is_same_v<S, Dual>) {
    double sv, cv;
    mech::sincos(x.v, sv, cv);
    s = {sv, cv * x.d}, c = {cv, -sv * x.d};
  } else {  // Eigen's AutoDiffScalar
    double sv, cv;
    mech::sincos(x.value(), sv, cv);
    s = x * cv, c = x * -sv;
    s.value() = sv, c.value() = cv;
  }
}

template <class S, bool kChecked = !is_lanes<S>>
bool solve_groups(const Chain& c, const S* v, State<S>& st);

// cos and sin of a (a line's or a slot's angle: a design value), the
// values kept in t = {a, cos a, sin a} while a is: a design's every solve
// asks the same, and the lanes take the C library's per lane. Derivatives
// (a LaneDual's) by the chain rule, as sin_or_cos gives them; a scalar
// dual computes them afresh.
template <class S, class P>
MECH_INLINE void fixed_cos_sin(const S& a, std::array<P, 3>& t, S& c, S& s) {
  using std::cos;
  using std::sin;
  if constexpr (std::is_same_v<S, double>) {
    if (!(t[0] == a)) t = {a, cos(a), sin(a)};
    c = t[1], s = t[2];
  } else if constexpr (std::is_same_v<S, Lanes>) {
    if (!all_equal(t[0], a)) t = {a, cos(a), sin(a)};
    c = t[1], s = t[2];
  } else if constexpr (is_lanes<S>) {
    if (!all_equal(t[0], a.v)) t = {a.v, cos(a.v), sin(a.v)};
    c = S(t[1]), s = S(t[2]);
    const Lanes minus_sin = -t[2];
    for (size_t i = 0; i < a.d.size(); ++i) c.d[i] = minus_sin * a.d[i], s.d[i] = t[1] * a.d[i];
  } else {
    c = cos(a), s = sin(a);
  }
}

// A number's value (double), or its lanes' values (Lanes).
inline double plain(double x) { return x; }
template <class S>
  requires(!is_lanes<S> && !std::is_same_v<S, double>)
double plain(const S& x) {
  return value(x);
}
inline const Lanes& plain(const Lanes& x) { return x; }
template <int N>
const Lanes& plain(const LaneDual<N>& x) {
  return x.v;
}

}  // namespace detail

// Solves the chain at crank angle phi with the values v (the chain's slots).
// False when a group cannot assemble (st.failed names it); st.margin[g] is
// group g's distance from a singular position, where its branch could flip:
// |sin| of the angle between the links at the joint (RRR), |cos| of the
// rod's angle to the line (RRP), s / |A - Q| (RPR: the cosine of the angle
// between the guide and the line from its pivot to the block), |sin| of the
// slot's angle to the line (RPP), |sin| of the angle between the two lines
// (PRP). Past the failing group the state is stale; nothing reads it.
// cs: phi's cosine and sine where the caller has them (doubles): the
// crank's then come by the angle sum with its phase's, kept in st.
template <class S>
bool solve(const Chain& c, const S* v, const S& phi, State<S>& st, const double* cs = nullptr) {
  using std::cos;
  using std::sin;
  st.failed = kNone;
  st.phi = phi;
  const Crank& k = c.crank();
  const double sense = k.sense;
  Vec<S> e;
  if constexpr (std::is_same_v<S, double>) {
    // One sincos.
    double ct, sn;
    if (cs) {
      if (st.phase != v[k.phase]) {
        st.phase = v[k.phase];
        st.phase_cos = std::cos(st.phase), st.phase_sin = std::sin(st.phase);
      }
      ct = st.phase_cos * cs[0] - st.phase_sin * sense * cs[1];
      sn = st.phase_sin * cs[0] + st.phase_cos * sense * cs[1];
    } else {
      detail::crank_sin_cos(v[k.phase] + sense * phi, sn, ct);
    }
    e = detail::crank_axis(ct, sn, sense);
  } else {
    S ct, sn;
    detail::crank_sin_cos(S(v[k.phase] + sense * phi), sn, ct);
    e = detail::crank_axis(ct, sn, sense);
  }
  detail::place_crank(c, v, st, e);
  return detail::solve_groups<S>(c, v, st);
}

// The chain at kLanes crank angles at once, on the lane form L of a scalar
// (Lanes, or LaneDual with design derivatives): the crank's axis from the
// angles' cosines cp and sines sp by the angle sum with its phase's (pc,
// ps: the same in every lane), the groups as solve's. Unchecked (kChecked
// false: a cycle mean's nodes, where the caller's grid and margin searches
// have shown the design assembles clear of every singular position), no
// assembly check or margin; checked, false where some lane cannot
// assemble (st.failed names the group), st.margin each lane's. With pc =
// 1, ps = 0 and cp, sense sp the cosine and sine of the crank's angle
// itself, the same bits as solve's lane by lane. Flattened: GCC leaves
// LaneDual<N > 1>'s sums and quotients out of line (simd.hpp), which cost
// a linkage's gradient a fifth of its time here (bench_linkage row 10).
template <class L, bool kChecked = false>
[[gnu::flatten]] bool solve_lanes(const Chain& c, const L* v, const Lanes& phi, const Lanes& cp, const Lanes& sp,
                                  const L& pc, const L& ps, State<L>& st) {
  static_assert(is_lanes<L>);
  st.failed = kNone;
  st.phi = L(phi);
  const double sense = c.crank().sense;
  const L ct = L(pc * cp - ps * sense * sp), sn = L(ps * cp + pc * sense * sp);
  detail::place_crank(c, v, st, detail::crank_axis(ct, sn, sense));
  return detail::solve_groups<L, kChecked>(c, v, st);
}

// The cosine of the crank's own angle phase + sense phi, and its sine
// times sense: what solve_lanes_exact takes for each lane (solve's bits),
// for one angle or for kLanes.
template <class T>
void crank_cos_sin(const Chain& c, double phase, const T& phi, T& cp, T& sp) {
  const double sense = c.crank().sense;
  T sn;
  detail::crank_sin_cos(T(phase + sense * phi), sn, cp);
  sp = sense * sn;
}

// solve_lanes in the form of the grid and the searches: checked, the
// crank's axis from the cosine and sine of its own angle in each lane (pc =
// 1, ps = 0; cp, sp: crank_cos_sin's at v's phase), so each lane is
// solve's bits at its angle.
inline bool solve_lanes_exact(const Chain& c, const Lanes* v, const Lanes& phi, const Lanes& cp, const Lanes& sp,
                              State<Lanes>& st) {
  return solve_lanes<Lanes, true>(c, v, phi, cp, sp, 1.0, 0.0, st);
}
inline bool solve_lanes_exact(const Chain& c, const Lanes* v, const Lanes& phi, State<Lanes>& st) {
  Lanes cp, sp;
  crank_cos_sin(c, v[c.crank().phase][0], phi, cp, sp);
  return solve_lanes_exact(c, v, phi, cp, sp, st);
}

// The same at kLanes crank angles phi given on L itself (a LaneDual in
// phi: the slopes a third order needs; with design derivatives: a
// gradient's), the crank's axis from cos and sin of its angle as solve's
// on a Dual in phi: lane by lane solve's bits. Flattened as solve_lanes.
// ground false: st has the ground points at v's values already (the
// blocks of one design after its first).
template <class L, bool kChecked = true>
[[gnu::flatten]] bool solve_lanes_at(const Chain& c, const L* v, const L& phi, State<L>& st, bool ground = true) {
  static_assert(is_lanes<L>);
  st.failed = kNone;
  st.phi = phi;
  const Crank& k = c.crank();
  const double sense = k.sense;
  L ct, sn;
  detail::crank_sin_cos(L(v[k.phase] + sense * phi), sn, ct);
  detail::place_crank(c, v, st, detail::crank_axis(ct, sn, sense), ground);
  return detail::solve_groups<L, kChecked>(c, v, st);
}

// The chain on lanes for one design (what a cycle mean's Gauss nodes
// ask, kLanes at a time): its values broadcast from the scalar S, its
// crank phase's cosine and sine, a state to solve in.
template <class S>
struct LaneSolver {
  using L = lanes_of<S>;
  const Chain& chain;
  std::vector<L> v;
  L pc, ps;
  State<L> st;
  LaneSolver(const Chain& c, const S* values) : chain(c) {
    st.resize(c);
    reset(values);
  }
  // Another design's values.
  void reset(const S* values) {
    using std::cos;
    using std::sin;
    v.resize(chain.defaults().size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = LaneForm<S>::broadcast(values[i]);
    const S& phase = values[chain.crank().phase];
    pc = LaneForm<S>::broadcast(S(cos(phase)));
    ps = LaneForm<S>::broadcast(S(sin(phase)));
  }
  // The chain at the angles phi, with their cosines and sines.
  const State<L>& at(const Lanes& phi, const Lanes& cp, const Lanes& sp) {
    solve_lanes(chain, v.data(), phi, cp, sp, pc, ps, st);
    return st;
  }
};

// Lane j of a state on lanes (S's lane form, or its velocity or position
// form: the jets' derivatives it leaves 0), as a state on its scalar S
// (sized for the chain); kLinksOnly: its links' axes' and slides' values
// alone (what a load's coordinate change between two angles reads), the
// rest left as it was.
template <class S, bool kLinksOnly = false, class L = lanes_of<S>>
void lane_state(const State<L>& from, int j, State<S>& to) {
  if constexpr (kLinksOnly) {
    for (size_t k = 0; k < from.axis.size(); ++k) {
      to.axis[k].x.v = LaneForm<S>::lane(from.axis[k].x.v, j), to.axis[k].y.v = LaneForm<S>::lane(from.axis[k].y.v, j);
      to.slide[k].v = LaneForm<S>::lane(from.slide[k].v, j);
    }
    return;
  }
  auto jet = [j](const Jet<L>& a) {
    return Jet<S>{LaneForm<S>::lane(a.v, j), LaneForm<S>::lane(a.d, j), LaneForm<S>::lane(a.dd, j)};
  };
  for (size_t k = 0; k < from.axis.size(); ++k) {
    to.axis[k] = {jet(from.axis[k].x), jet(from.axis[k].y)};
    to.slide[k] = jet(from.slide[k]);
  }
  for (size_t p = 0; p < from.point.size(); ++p) to.point[p] = {jet(from.point[p].x), jet(from.point[p].y)};
  for (size_t g = 0; g < from.margin.size(); ++g) to.margin[g] = from.margin[g][j];
  to.failed = kNone;
  to.phi = LaneForm<S>::lane(from.phi, j);
}

namespace detail {

// solve's groups, in the chain's order, on its crank's state; kChecked:
// with the assembly checks and the margins (on lanes, false where a lane
// fails; st.failed names the group).
template <class S, bool kChecked>
bool solve_groups(const Chain& c, const S* v, State<S>& st) {
  using std::abs;
  using std::cos;
  using std::sin;
  using std::sqrt;
  const auto& links = c.links();
  const auto& groups = c.groups();
  for (size_t g = 0; g < groups.size(); ++g) {
    const Group& gr = groups[g];
    const Link &first = links[static_cast<size_t>(gr.first)], &second = links[static_cast<size_t>(gr.second)];
    auto at = [&](int p) -> const Vec<S>& { return st.point[static_cast<size_t>(p)]; };
    // cos and sin of link k's line angle (slot 0) or slot angle (1).
    auto fixed = [&](int k, int slot, int value, S& ca, S& sa) {
      fixed_cos_sin(v[value], st.trig[2 * static_cast<size_t>(k) + static_cast<size_t>(slot)], ca, sa);
    };
    // A slider's line direction, fixed on the ground or on a solved link.
    auto line_axis = [&](int k) -> Vec<S> {
      const Link& slider = links[static_cast<size_t>(k)];
      S ca, sa;
      fixed(k, 0, slider.line_angle, ca, sa);
      if (slider.line_on == kNone) return detail::constant_point(ca, sa);
      const Vec<S>& eo = st.axis[static_cast<size_t>(slider.line_on)];
      return ca * eo + sa * rot90(eo);
    };
    // The line's point where the slider's coordinate is 0: its point T
    // shifted `offset` to its left (n = rot90(u)); on a ground line a
    // constant, its values alone computed (the same bits).
    auto line_origin = [&](const Link& slider, const Vec<S>& n) -> Vec<S> {
      const S offset = slider.line_offset == kNone ? S(0.0) : v[slider.line_offset];
      const Vec<S>& t = at(slider.line_through);
      if (slider.line_on == kNone) return constant_point(S(t.x.v + n.x.v * offset), S(t.y.v + n.y.v * offset));
      return t + offset * n;
    };
    // The group's two links solved: their axes, then their points.
    auto place = [&](const Vec<S>& e1, const Vec<S>& e2) {
      put(st.axis[static_cast<size_t>(gr.first)], e1);
      put(st.axis[static_cast<size_t>(gr.second)], e2);
      detail::place_points(first, v, st, e1);
      detail::place_points(second, v, st, e2);
    };
    switch (gr.type) {
      case GroupType::RRR: {
        // B = P + f d + branch g rot90(d): f and g are along and h over |d|.
        const S &a = v[first.length], &b = v[second.length];
        const Vec<S> &P = at(gr.p), &Q = at(gr.q);
        const Vec<S> d = Q - P;
        const Jet<S> inv = constant(S(1.0)) / dot(d, d);
        const Jet<S> f = (constant(S(1.0)) + S(a * a - b * b) * inv) * 0.5;
        const Jet<S> g2 = S(a * a) * inv - f * f;
        if constexpr (kChecked)
          if (!positive_everywhere(g2.v)) return st.failed = static_cast<int>(g), false;
        const Jet<S> gb = sqrt(g2) * double(gr.branch);
        const Vec<S> B = P + Vec<S>{f * d.x - gb * d.y, f * d.y + gb * d.x};
        put(st.point[static_cast<size_t>(gr.joint)], B);
        const Vec<S> e1 = S(1.0 / a) * (B - P), e2 = S(1.0 / b) * (B - Q);  // (one quotient each)
        if constexpr (kChecked) st.margin[g] = abs(plain(cross(e1, e2).v));
        place(e1, e2);
        break;
      }
      case GroupType::RRP: {
        // B = T + offset n + s u, |B - P| = a.
        const S& a = v[first.length];
        const Vec<S> u = line_axis(gr.second), n = rot90(u);
        const Vec<S>& P = at(gr.p);
        // On a ground line u, n and T are constant in phi: the jets'
        // products with them are scalar products (the same bits: the
        // derivatives' terms they drop are zeros).
        const bool fixed_line = second.line_on == kNone;
        const S ux = u.x.v, uy = u.y.v, nx = n.x.v, ny = n.y.v;
        const Vec<S> T = line_origin(second, n);
        const Vec<S> w = fixed_line ? Vec<S>{{S(P.x.v - T.x.v), P.x.d, P.x.dd}, {S(P.y.v - T.y.v), P.y.d, P.y.dd}}
                                    : P - T;
        const Jet<S> wn = fixed_line ? w.x * nx + w.y * ny : dot(w, n);
        const Jet<S> disc = constant(S(a * a)) - wn * wn;
        if constexpr (kChecked)
          if (!positive_everywhere(disc.v)) return st.failed = static_cast<int>(g), false;
        const Jet<S> s = (fixed_line ? w.x * ux + w.y * uy : dot(w, u)) + sqrt(disc) * double(gr.branch);
        const Vec<S> B = fixed_line ? Vec<S>{T.x + s * ux, T.y + s * uy} : T + s * u;
        put(st.point[static_cast<size_t>(gr.joint)], B);
        put(st.slide[static_cast<size_t>(gr.second)], s);
        if constexpr (kChecked) st.margin[g] = sqrt(plain(disc.v)) / abs(plain(a));
        place(S(1.0 / a) * (B - P), u);
        break;
      }
      case GroupType::RPR: {
        // A = Q + offset n + s u: u = (s d - offset rot90(d)) / |d|^2, d = A - Q.
        const S offset = second.guide_offset == kNone ? S(0.0) : v[second.guide_offset];
        const Vec<S> d = at(gr.p) - at(gr.q);
        const Jet<S> d2 = dot(d, d);
        const Jet<S> s2 = d2 - constant(S(offset * offset));
        if constexpr (kChecked)
          if (!positive_everywhere(s2.v)) return st.failed = static_cast<int>(g), false;
        const Jet<S> s = sqrt(s2);
        const Vec<S> rd = rot90(d);
        const Vec<S> u{(s * d.x - offset * rd.x) / d2, (s * d.y - offset * rd.y) / d2};
        put(st.slide[static_cast<size_t>(gr.first)], s);
        if constexpr (kChecked) st.margin[g] = plain(s.v) / sqrt(plain(d2.v));
        place(u, u);
        break;
      }
      case GroupType::RPP: {
        // P - T = s u + t w: the slider's point on its line, T + s u, and
        // the pin P on its slot w through it.
        const Vec<S> u = line_axis(gr.second), n = rot90(u);
        S cs, ss;
        fixed(gr.second, 1, second.slot, cs, ss);
        const Vec<S> w = cs * u + ss * n;
        const Vec<S>& P = at(gr.p);
        const Vec<S> q = P - line_origin(second, n);
        const Jet<S> det = cross(u, w);
        if constexpr (kChecked)
          if (!positive_everywhere(abs(plain(det.v)))) return st.failed = static_cast<int>(g), false;
        const Jet<S> s = cross(q, w) / det, t = cross(u, q) / det;
        put(st.point[static_cast<size_t>(gr.joint)], P - t * w);
        put(st.slide[static_cast<size_t>(gr.second)], s);
        put(st.slide[static_cast<size_t>(gr.first)], t);
        if constexpr (kChecked) st.margin[g] = abs(plain(det.v));
        place(w, u);
        break;
      }
      case GroupType::PRP: {
        // B = T1 + s1 u1 = T2 + s2 u2 (T1, T2 the lines' origins): s1 u1 -
        // s2 u2 = d = T2 - T1, so s1 = (d x u2) / (u1 x u2) and s2 = (d x
        // u1) / (u1 x u2) (Cramer; no root where the lines are parallel).
        const Vec<S> u1 = line_axis(gr.first), u2 = line_axis(gr.second);
        const Vec<S> T1 = line_origin(first, rot90(u1));
        const Vec<S> d = line_origin(second, rot90(u2)) - T1;
        const Jet<S> det = cross(u1, u2);
        if constexpr (kChecked)
          if (!positive_everywhere(abs(plain(det.v)))) return st.failed = static_cast<int>(g), false;
        const Jet<S> s1 = cross(d, u2) / det, s2 = cross(d, u1) / det;
        put(st.point[static_cast<size_t>(gr.joint)], T1 + s1 * u1);
        put(st.slide[static_cast<size_t>(gr.first)], s1);
        put(st.slide[static_cast<size_t>(gr.second)], s2);
        if constexpr (kChecked) st.margin[g] = abs(plain(det.v));
        place(u1, u2);
        break;
      }
    }
  }
  return true;
}

}  // namespace detail

}  // namespace mech::linkage
