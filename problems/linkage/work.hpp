// The loads' work over a cycle from their coordinates at the ends of the
// arcs where they act, without quadrature: the mean driving torque. A
// load whose size is a function of its own coordinate x (a force along a
// slider's line fixed to the ground: x its slider's s, power F s'; a
// torque of constant size on a link, or between two: x their relative
// angle) does the work G(x_b) - G(x_a) on an arc [a, b] where it acts, G
// its size's antiderivative in x. It switches only where x' = 0 (`when`,
// an opposing load, a friction: docs/design/linkage.md, section 4), so
// its arcs end at the zeros of x'; there the work does not move with the
// arc's end (x' = 0), so the ends held fixed give the design gradient
// exactly. Over a whole cycle a force's s returns to itself: a force that
// never switches does no net work; a torque on a link that turns round
// does its size times 2 pi per turn.
#pragma once
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "mech/angles.hpp"
#include "mech/autodiff.hpp"
#include "mech/linkage/dynamics.hpp"
#include "problems/linkage/kinks.hpp"

namespace problems::linkage {

// Whether every load's work comes from its coordinate (the rest: a table
// over the crank angle, a force on a moving line, a torque's table, an
// opposing table or law, take Gauss arcs).
inline bool work_from_ends(const mech::linkage::Chain& c) {
  using mech::linkage::Load;
  using mech::linkage::kNone;
  for (const Load& l : c.loads()) {
    if (l.over == Load::Over::crank_angle) return false;
    const bool sized = l.over == Load::Over::position || l.law_a != kNone;  // by a table or a law
    if (l.kind == Load::Kind::force) {
      if (c.links()[static_cast<size_t>(l.link)].line_on != kNone) return false;
      if (sized && l.opposing) return false;
    } else if (sized) {
      return false;
    }
  }
  return true;
}

namespace detail {

// A table's integral from its first row to x (constant beyond its ends).
template <class S>
S table_integral(const mech::linkage::Load& l, const S& x) {
  const auto &xs = l.xs, &ys = l.ys;
  const double xv = mech::value(x);
  if (xv <= xs.front()) return S(ys.front() * (x - xs.front()));
  double area = 0;
  size_t i = 1;
  for (; i < xs.size() && xs[i] < xv; ++i) area += 0.5 * (ys[i] + ys[i - 1]) * (xs[i] - xs[i - 1]);
  if (i == xs.size()) return S(area + ys.back() * (x - xs.back()));
  const double slope = (ys[i] - ys[i - 1]) / (xs[i] - xs[i - 1]);
  const S t = S(x - xs[i - 1]);
  return S(area + t * (ys[i - 1] + 0.5 * slope * t));
}

// A force load's size integrated over its slider's s from s0 (the
// difference of two of these is its work between them).
template <class S>
S force_potential(const mech::linkage::Load& l, const S* v, const S& s) {
  using mech::linkage::kNone;
  using std::exp;
  if (l.law_a != kNone) {  // -area a (e^(b d) - 1) / b over the depth d >= 0
    const S depth = S(s - v[l.law_contact]);
    if (!(mech::value(depth) > 0)) return S(0.0);
    const S& b = v[l.law_b];
    const S grown = mech::value(b) == 0 ? depth : S((exp(S(b * depth)) - 1.0) / b);
    return S(-(v[l.law_area] * v[l.law_a] * grown));
  }
  if (l.over == mech::linkage::Load::Over::position) return table_integral(l, s);
  return S(v[l.value] * s);
}

// Load l's coordinate at state b less at state a (an angle's change by
// the arc's turns: `turns` 2 pi added to the change atan2 gives).
template <class S>
S coordinate_change(const mech::linkage::Load& l, const mech::linkage::State<S>& a, const mech::linkage::State<S>& b,
                    double turns) {
  using mech::linkage::kNone;
  const size_t k = static_cast<size_t>(l.link);
  if (l.kind == mech::linkage::Load::Kind::force) return S(b.slide[k].v - a.slide[k].v);
  // The link's axis relative to `other`'s (the ground's: itself), at a and b.
  auto relative = [&](const mech::linkage::State<S>& st, S& x, S& y) {
    const auto& e = st.axis[k];
    if (l.other == kNone) {
      x = e.x.v, y = e.y.v;
      return;
    }
    const auto& o = st.axis[static_cast<size_t>(l.other)];
    x = S(e.x.v * o.x.v + e.y.v * o.y.v), y = S(e.y.v * o.x.v - e.x.v * o.y.v);
  };
  S xa, ya, xb, yb;
  relative(a, xa, ya);
  relative(b, xb, yb);
  return S(mech::atan2_of(S(xa * yb - ya * xb), S(xa * xb + ya * yb)) + mech::kTwoPi * turns);
}

// Whole turns of load l's coordinate (an angle) from phi_a to phi_b
// beyond the change atan2 gives between them: its changes summed over the
// grid states between (doubles), less the end-to-end change, rounded.
inline double turns_between(const mech::linkage::Load& l, double phi_a, double phi_b, GridStates grid,
                            const mech::linkage::State<double>& a, const mech::linkage::State<double>& b) {
  if (l.kind == mech::linkage::Load::Kind::force) return 0;
  const int n = static_cast<int>(grid.size());
  const double h = mech::kTwoPi / n;
  double sum = 0;
  const mech::linkage::State<double>* from = &a;
  for (int i = static_cast<int>(std::floor(phi_a / h)) + 1; i * h < phi_b; ++i) {
    const auto& at = grid[static_cast<size_t>(((i % n) + n) % n)];
    sum += coordinate_change(l, *from, at, 0.0);
    from = &at;
  }
  sum += coordinate_change(l, *from, b, 0.0);
  return std::round((sum - coordinate_change(l, a, b, 0.0)) / mech::kTwoPi);
}

}  // namespace detail

// mean_load_torque's arcs' ends: their angles, load by load (load i's
// from first[i] to first[i + 1]), and the chain at each.
template <class S>
struct ArcEnds {
  std::vector<double> phi;
  std::vector<size_t> first;
  std::vector<mech::linkage::State<S>> at;
};

// The mean over a cycle of the loads' generalised force with its sign
// reversed: the mean driving torque the loads ask for (dynamics.hpp's
// load_power; springs, gravity and inertia give back what they take).
// switches: (angle, load) where a switching load's coordinate turns
// (zeros of its switch_rate, torque_kinks'); blocks: the chain at the n
// grid angles, and states() the same as scalar states (GridStates: asked
// only for a torque's turns); vd: v's values; sd, se: states to solve in;
// ends: the arcs' ends (kept by the caller: no allocation once warm; the
// states' links' values alone are read, so position lanes serve); lanes:
// the chain on lanes at v; known(phi, st): the chain's links at phi into
// st where the caller has them (the same bits as lanes'), else false.
// Only where work_from_ends(c).
template <class S, class States, class Known>
S mean_load_torque(const mech::linkage::Chain& c, const S* v, const double* vd,
                   const std::vector<std::pair<double, int>>& switches, int n, GridBlocks blocks, States&& states,
                   mech::linkage::State<double>& sd, mech::linkage::State<double>& se,
                   ArcEnds<S>& arcs, mech::linkage::LaneSolver<S>& lanes, Known&& known) {
  using mech::linkage::Load;
  S work(0.0);
  // A load's work on one arc, over its efficiency.
  auto add = [&](const Load& l, const S& done) {
    work += l.efficiency == mech::linkage::kNone ? done : S(done / v[l.efficiency]);
  };
  // Every switching load's arcs' ends, load by load, each by angle (a
  // load that never turns: one arc, the whole cycle, from 0), and the
  // chain solved at each once, kLanes at a time: lane by lane solve's
  // values.
  std::vector<double>& ends = arcs.phi;
  std::vector<size_t>& first = arcs.first;
  std::vector<mech::linkage::State<S>>& at = arcs.at;
  ends.clear(), first.assign(c.loads().size() + 1, 0);
  for (size_t i = 0; i < c.loads().size(); ++i) {
    if (mech::linkage::switching(c.loads()[i])) {
      for (const auto& [phi, load] : switches)
        if (load == static_cast<int>(i)) ends.push_back(phi);
      std::sort(ends.begin() + static_cast<std::ptrdiff_t>(first[i]), ends.end());
      if (ends.size() == first[i]) ends.push_back(0.0);
    }
    first[i + 1] = ends.size();
  }
  if (at.size() < ends.size()) {
    at.resize(ends.size());
    for (auto& st : at) st.resize(c);
  }
  for (size_t e = 0; e < ends.size(); e += mech::kLanes) {
    const int m = static_cast<int>(std::min<size_t>(mech::kLanes, ends.size() - e));
    int held = 0;  // the caller's
    while (held < m && known(ends[e + static_cast<size_t>(held)], at[e + static_cast<size_t>(held)])) ++held;
    if (held == m) continue;
    mech::Lanes phi;
    for (int j = 0; j < mech::kLanes; ++j) phi[j] = ends[e + static_cast<size_t>(std::min(j, m - 1))];
    bool solved = true;
    if constexpr (std::is_same_v<S, double>) solved = mech::linkage::solve_lanes_exact(c, lanes.v.data(), phi, lanes.st);
    else if constexpr (mech::has_lanes<S>)  // (the ends are on the searched cycle: no check)
      mech::linkage::solve_lanes_at<mech::lanes_of<S>, false>(c, lanes.v.data(), mech::lanes_of<S>(phi), lanes.st);
    else solved = false;
    if (solved) {
      for (int j = 0; j < m; ++j) mech::linkage::lane_state<S, true>(lanes.st, j, at[e + static_cast<size_t>(j)]);
      continue;
    }
    for (size_t j = e; j < e + static_cast<size_t>(m); ++j) mech::linkage::solve(c, v, S(ends[j]), at[j]);
  }
  for (size_t i = 0; i < c.loads().size(); ++i) {
    const Load& l = c.loads()[i];
    const bool force = l.kind == Load::Kind::force;
    if (!mech::linkage::switching(l)) {
      // A force's s comes back: no work. A torque's angle may turn round:
      // its constant size times the turns (no design derivative).
      if (!force)
        add(l, S(v[l.value] * (mech::kTwoPi * detail::turns_between(l, 0.0, mech::kTwoPi, states(), states()[0],
                                                                    states()[0]))));
      continue;
    }
    const size_t count = first[i + 1] - first[i];
    for (size_t j = 0; j < count; ++j) {
      const bool last = j + 1 == count;
      const size_t ia = first[i] + j, ib = last ? first[i] : ia + 1;  // (the last arc ends where the first starts)
      const double a = ends[ia], b = last ? ends[ib] + mech::kTwoPi : ends[ib];
      const auto &sa = at[ia], &sb = at[ib];
      // The coordinate's direction on the arc: its rate's sign inside it
      // (it has no zero there), at the grid angle nearest the middle where
      // that lies a quarter of the arc from both ends, else at the middle.
      const double mid = 0.5 * (a + b), h = mech::kTwoPi / n;
      const double i_mid = std::round(mid / h);
      const int at = (static_cast<int>(i_mid) % n + n) % n;
      double rate;
      if (std::abs(i_mid * h - mid) <= 0.25 * (b - a)) {
        rate = mech::linkage::switch_rate(l, blocks[static_cast<size_t>(at / mech::kLanes)]).v[at % mech::kLanes];
      } else {
        mech::linkage::solve(c, vd, mid, sd);
        rate = mech::linkage::switch_rate(l, sd).v;
      }
      const double sign = rate > 0 ? 1.0 : -1.0;
      if (l.when * sign >= 0) {  // (else held off on this arc)
        if (force && !l.opposing) {
          const size_t k = static_cast<size_t>(l.link);
          add(l, S(detail::force_potential(l, v, sb.slide[k].v) - detail::force_potential(l, v, sa.slide[k].v)));
        } else {
          double turns = 0;  // (a force's: none)
          if (!force) {
            if constexpr (mech::is_dual<S>) {
              mech::linkage::solve(c, vd, a, sd);
              mech::linkage::solve(c, vd, b, se);
              turns = detail::turns_between(l, a, b, states(), sd, se);
            } else {
              turns = detail::turns_between(l, a, b, states(), sa, sb);
            }
          }
          const S change = detail::coordinate_change(l, sa, sb, turns);
          using std::abs;
          const S& size = v[l.value];
          // Against the motion: -|size| |change| (the change has the rate's sign).
          add(l, l.opposing || l.kind == Load::Kind::friction ? S(-(abs(size) * change * sign)) : S(size * change));
        }
      }
    }
  }
  return S(-work / mech::kTwoPi);
}

}  // namespace problems::linkage
