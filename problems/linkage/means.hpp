// A linkage's cycle means (problems/linkage/problem.cpp's evaluation):
// the torque's |M| and M^2 by Gauss-Legendre arcs between its kinks, the
// chain kLanes nodes at a time; the mean torque from the loads' work at
// its arcs' ends where every load's allows (work.hpp), else by Gauss with
// the torque's; the mean energy by the trapezoid rule on the grid where
// the poles are far; the flywheel's work swing. W: the problem's
// workspace (its grid's states, scratch and the values as doubles).
#pragma once
#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "mech/linkage/dynamics.hpp"
#include "mech/quadrature.hpp"
#include "problems/linkage/description.hpp"
#include "problems/linkage/kinks.hpp"
#include "problems/linkage/metrics.hpp"
#include "problems/linkage/work.hpp"
#include "problems/model_problem.hpp"

namespace problems::linkage {

// Lane blocks of the chain an evaluation has solved and keeps, with each
// kept lane's angle: a later pass at one of those angles (the loads' arc
// ends) takes the lane instead of solving again (the same call on the
// same lanes: the same bits). clear() as an evaluation starts.
template <class L>
struct SolvedBlocks {
  std::vector<mech::linkage::State<L>> blocks;
  size_t used = 0;
  struct At {
    double phi;
    size_t block;
    int lane;
  };
  std::vector<At> at;
  void clear() { used = 0, at.clear(); }
  // The block to solve in next (sized for the chain).
  mech::linkage::State<L>& next(const mech::linkage::Chain& c) {
    if (blocks.size() <= used) blocks.emplace_back().resize(c);
    return blocks[used];
  }
  // Keeps next()'s block, solved at phi's first m lanes.
  void keep(const mech::Lanes& phi, int m) {
    for (int j = 0; j < m; ++j) at.push_back({phi[j], used, j});
    ++used;
  }
  // The links (lane_state's axes and slides) of the chain at angle phi,
  // if a kept block holds it.
  template <class S>
  bool links_at(double phi, mech::linkage::State<S>& to) const {
    for (const At& a : at)
      if (a.phi == phi) return mech::linkage::lane_state<S, true>(blocks[a.block], a.lane, to), true;
    return false;
  }
};

// What an evaluation on scalar S keeps from one design to the next (the
// workspace's `scalar` holds one per scalar, ScalarScratches: no
// allocation once warm): the chain's lanes at the design, states to solve
// in (the means'), and the chain at each search's maximum with the
// metric's value there (problem.cpp's, on a dual S: Danskin).
template <class S>
struct ScalarScratch {
  std::optional<mech::linkage::LaneSolver<S>> lanes;
  bool lanes_set = false;  // ... at this evaluation's values (cleared as one starts)
  // The chain's lanes at v, set once an evaluation.
  mech::linkage::LaneSolver<S>& lanes_at(const mech::linkage::Chain& c, const S* v) {
    if (!lanes_set) {
      if (lanes) lanes->reset(v);
      else lanes.emplace(c, v);
      lanes_set = true;
    }
    return *lanes;
  }
  mech::linkage::State<S> a, b;
  ArcEnds<S> ends;  // mean_load_torque's
  mech::linkage::State<double> e;
  std::vector<mech::linkage::State<S>> maxima;  // per search, where `solved` says
  std::vector<char> solved;
  // The chain on lanes at the maxima's angles (solve_maxima's blocks):
  // mean_load_torque takes the arcs' ends from them where they are the
  // same angles (an output's stops).
  SolvedBlocks<mech::lanes_of<S>> at_maxima;
  // The chain on velocity lanes (energy_mean's gradient).
  std::vector<mech::linkage::velocity_lanes<mech::lanes_of<S>>> velocity_values;
  mech::linkage::State<mech::linkage::velocity_lanes<mech::lanes_of<S>>> at_velocity;
  // ... on position lanes (values and their design derivatives alone):
  // the coordinates' maxima, kept as at_maxima for the loads' arc ends.
  std::vector<mech::linkage::position_lanes<mech::lanes_of<S>>> position_values;
  SolvedBlocks<mech::linkage::position_lanes<mech::lanes_of<S>>> at_positions;
  std::vector<std::optional<S>> tops;    // per search, its maximum on S once taken
  std::vector<std::optional<S>> angles;  // ... a coordinate's, the angle of it
};
using ScalarScratches = std::tuple<ScalarScratch<double>, ScalarScratch<mech::Dual>, ScalarScratch<mech::DualN<2>>,
                                   ScalarScratch<mech::DualN<3>>, ScalarScratch<mech::DualN<4>>>;

// The poles of a group's margin^2 from its grid f = -margin^2 (periodic,
// n points, step h): each local minimum's parabola through its three grid
// points, m2 and m0 its curvature and least value, the width sqrt(2 m0 /
// m2) at its vertex, appended to `out`. Where every minimum's width is 4
// steps or more the parabola's error, of order (h / width)^2, leaves the
// width within a few per cent (asinh of it within 0.8% of the refined one
// over the linkage tests wherever n asinh(w) < 100): what the trapezoid's
// choice and the panels' grading need, both kPoleDigits clear. Else false,
// and nothing appended.
inline bool grid_poles(std::span<const double> f, std::vector<mech::NearPole>& out) {
  const int n = static_cast<int>(f.size());
  const double h = mech::kTwoPi / n;
  const size_t first = out.size();
  for (int k = 0, before = n - 1; k < n; before = k++) {  // (no division per point)
    if (k % mech::kLanes == 1 && k + mech::kLanes < n) {  // kLanes points at a time where none is a minimum
      auto at = [&](int i) { return mech::load_lanes(&f[static_cast<size_t>(i)]).v; };
      const auto low = (at(k) >= at(k - 1)) & (at(k) > at(k + 1));  // (b <= a and b < c below)
      bool none = true;
      for (int j = 0; j < mech::kLanes; ++j) none &= low[j] == 0;
      if (none) {
        k += mech::kLanes - 1;
        continue;
      }
    }
    const int after = k + 1 == n ? 0 : k + 1;
    const double a = -f[static_cast<size_t>(before)], b = -f[static_cast<size_t>(k)],
                 c = -f[static_cast<size_t>(after)];
    if (!(b <= a && b < c)) continue;  // (the first of two equal points)
    const double m2 = (a - 2 * b + c) / (h * h), m1 = (c - a) / (2 * h);
    const double m0 = b - 0.5 * m1 * m1 / m2, width = m2 > 0 && m0 > 0 ? std::sqrt(2 * m0 / m2) : 0.0;
    if (!(width >= 4 * h)) {
      out.resize(first);
      return false;
    }
    out.push_back({k * h - m1 / m2, width});
  }
  return true;
}

// The least asinh(width) of the poles, HUGE_VAL for none: the nearest's
// (one call: asinh rises).
inline double least_asinh_width(std::span<const mech::NearPole> near) {
  double least = HUGE_VAL;
  for (const mech::NearPole& p : near) least = std::min(least, p.width);
  return std::asinh(least);
}

// The mean kinetic energy. It is smooth and periodic: the trapezoid
// rule on the n-point grid errs like e^(-n w), w the half-width of the
// strip around the real axis where it is analytic (the nearest pole's
// imaginary part; a margin's quadratic model overstates a slider-crank's
// sqrt(lambda^2 - 1) for its acosh(lambda) = asinh of it, which is taken
// instead). Where n w >= 2 kPoleDigits the grid serves, or every s-th
// point of it where that is enough: its energies (`energies`, where the
// grid has them) or its states; a gradient, the chain on S at as few
// points as the rule asks; nearer a pole, Gauss panels graded toward it.
template <class S, class W>
S energy_mean(const Description& d, const opt::Values<S>& v, const std::vector<mech::NearPole>& near,
              ScalarScratch<S>& kept, const double* energies, W& ws) {
  using L = mech::lanes_of<S>;
  mech::linkage::LaneSolver<S>& lanes = *kept.lanes;
  const mech::linkage::Chain& c = d.chain;
  const int n = static_cast<int>(ws.grid.size());
  const S& w = v[static_cast<size_t>(c.crank().speed)];
  const double a = least_asinh_width(near);
  if (n * a < 2 * mech::kPoleDigits) {
    const L ww = mech::LaneForm<S>::broadcast(S(w * w / 2.0));
    return mech::piecewise_means<S>(
               [&](const mech::Lanes& phi, const mech::Lanes& cp, const mech::Lanes& sp) {
                 return L(mech::linkage::body_sums<L, true>(c, lanes.v.data(), lanes.at(phi, cp, sp)).inertia * ww);
               },
               {}, 2 * d.mean_points(), ws.cycle, near)
        .mean;
  }
  // The value: every s-th grid point, s the largest divisor of n that
  // leaves the trapezoid its n / s asinh(w) >= 2 kPoleDigits (and 16
  // points; with no pole known, every point), kLanes at a time, each
  // lane's energy (I / 2) w w as the grid's (quantity.hpp's
  // drive_quantity), or from the grid's states, summed in one order: the
  // same bits with or without a gradient.
  int s = 1;
  for (int t = 2; t <= n / 16 && a < HUGE_VAL; ++t)
    if (n % t == 0 && (n / t) * a >= 2 * mech::kPoleDigits) s = t;
  const int points = n / s;
  const double wd = mech::value(w);
  const GridStates states = energies ? GridStates{} : ws.states();
  mech::Lanes sums(0.0);
  for (int k = 0; k < points; k += mech::kLanes) {
    if (energies && s == 1 && k + mech::kLanes <= points) {  // (one load: lanes filled one by one stall)
      sums += mech::load_lanes(energies + k);
      continue;
    }
    mech::Lanes e(0.0);
    for (int j = 0; j < std::min(mech::kLanes, points - k); ++j) {
      const size_t i = static_cast<size_t>((k + j) * s);
      e[j] = energies ? energies[i]
                      : mech::linkage::body_sums<double, true>(c, ws.plain.data(), states[i]).inertia / 2.0 * wd * wd;
    }
    sums += e;
  }
  const double mean = mech::sum(sums) / static_cast<double>(points);
  if constexpr (!mech::is_dual<S>) {
    return mean;
  } else {
    // Its gradient: the trapezoid on the fewest points that give it the
    // same m asinh(w) >= 2 kPoleDigits (a multiple of kLanes, 16 at
    // least, the value's at most), the chain on S kLanes angles a call,
    // its jets velocities alone (LaneVelocity).
    using V = mech::linkage::velocity_lanes<L>;
    const double all = points, fewest = mech::kLanes * std::ceil(2 * mech::kPoleDigits / a / mech::kLanes);
    const int m = a < HUGE_VAL ? static_cast<int>(std::clamp(fewest, std::min(16.0, all), all)) : points;
    const L ww = mech::LaneForm<S>::broadcast(w);
    std::vector<V>& vv = kept.velocity_values;
    vv.assign(lanes.v.begin(), lanes.v.end());
    mech::linkage::State<V>& st = kept.at_velocity;
    if (st.point.size() != c.point_names().size()) st.resize(c);
    L grads(0.0);
    for (int k = 0; k < m; k += mech::kLanes) {
      const int lanes_used = std::min(mech::kLanes, m - k);
      mech::Lanes phi;
      for (int j = 0; j < mech::kLanes; ++j) phi[j] = mech::kTwoPi * (k + std::min(j, lanes_used - 1)) / m;
      mech::linkage::solve_lanes_at<V, false>(c, vv.data(), V(L(phi)), st, k == 0);
      grads += mech::first_lanes(L(L(mech::linkage::body_sums<V, true>(c, vv.data(), st).inertia / 2.0) * ww * ww),
                                 lanes_used);
    }
    S r = S(mech::LaneForm<S>::sum(grads) / static_cast<double>(m));
    if constexpr (std::is_same_v<S, mech::Dual>) r.v = mean;
    else r.value() = mean;
    return r;
  }
}

// The grid's energies, where the evaluation asked for them (the peak's
// search), else null.
template <class W>
const double* energy_grid(const W& ws) {
  const size_t n = ws.grid.size();
  for (size_t q = 0; q < ws.asked.size(); ++q)
    if (ws.asked[q].kind == Kind::energy) return ws.grids.size() >= (q + 1) * n ? ws.grids.data() + q * n : nullptr;
  return nullptr;
}

// The largest swing of the work W(phi) = integral from 0 to phi of (M -
// mean M): W at the zeros of M - mean M (its extremes, found on the grid
// and refined) by Gauss on the arcs between them and the torque's kinks
// (a kink inside an arc would cost Gauss its accuracy), the largest less
// the smallest (W' = 0 at the extremes: holding them is exact for the
// gradient; W at a kink lies between them).
template <class S, class W>
S work_swing(const Description& d, const opt::Values<S>& v, const S& mean, const std::vector<double>& kinks,
             const std::vector<Jump<S>>& js, const std::vector<mech::NearPole>& near, mech::linkage::State<S>& ss,
             W& ws) {
  const mech::linkage::Chain& c = d.chain;
  const int n = static_cast<int>(ws.grid.size());
  const double mean_d = mech::value(mean);
  auto excess = [&](const mech::linkage::State<double>& st) {
    return mech::linkage::drive_point(c, ws.plain.data(), st).torque - mean_d;
  };
  ws.grids.resize(static_cast<size_t>(n));
  const GridStates states = ws.states();
  for (int i = 0; i < n; ++i) ws.grids[static_cast<size_t>(i)] = excess(states[static_cast<size_t>(i)]);
  const std::span<const double> grid[1] = {std::span<const double>(ws.grids.data(), static_cast<size_t>(n))};
  std::vector<double> zeros = mech::periodic_roots_together(std::span(grid), [&](std::span<mech::AngleQuery> qs) {
    for (mech::AngleQuery& q : qs) {
      mech::linkage::solve(c, ws.plain.data(), q.phi, ws.sd);
      q.out = excess(ws.sd);
    }
  });
  if (zeros.size() < 2) return S(0.0);
  zeros.insert(zeros.end(), kinks.begin(), kinks.end());
  std::sort(zeros.begin(), zeros.end());  // each end once (a jump is a zero and a kink: its motion once)
  zeros.erase(std::unique(zeros.begin(), zeros.end(), [](double a, double b) { return b - a < 1e-9; }), zeros.end());
  S work(0.0), top(0.0), bottom(0.0);
  for (size_t j = 0; j < zeros.size(); ++j) {
    const double a = zeros[j], b = j + 1 < zeros.size() ? zeros[j + 1] : zeros[0] + mech::kTwoPi;
    work -= jump_term(js, a, false, mean_d);  // a pressure law's jumps move with the design
    mech::for_each_panel(a, b, 2 * d.mean_points(), near, [&](double mid, double half, int nodes) {
      const mech::GaussRule& rule = mech::gauss_rule(nodes);
      for (size_t i = 0; i < static_cast<size_t>(rule.m + 1) / 2; ++i) {
        const bool centre = 2 * i + 1 == static_cast<size_t>(rule.m);
        const double t = centre ? 0.0 : half * rule.nodes[i].first, weight = rule.nodes[i].second * half;
        for (double phi : {mid + t, mid - t}) {
          mech::linkage::solve(c, v.data(), S(phi), ss);
          work += weight * (mech::linkage::drive_point(c, v.data(), ss).torque - mean);
          if (centre) break;
        }
      }
    });
    work += jump_term(js, b, true, mean_d);
    if (mech::value(work) > mech::value(top)) top = work;
    if (mech::value(work) < mech::value(bottom)) bottom = work;
  }
  return S(top - bottom);
}

// The cycle means the wanted metrics ask for: Gauss-Legendre arcs between
// the torque's kinks (2 mean_points() nodes a revolution, the chain kLanes nodes at a
// time), the loads' work from its arcs' ends where it can, the energy on
// the grid (ws.wanted: the wanted metrics' indices in `metrics`). Returns
// the mean kinetic energy (0 when not computed).
template <class S, class W>
S put_means(const Description& d, const std::vector<Metric>& metrics, bool has_law,
            const std::vector<mech::NearPole>& near, const opt::Values<S>& v, MetricSink<S>& out, W& ws) {
  using mech::Lanes;
  using L = mech::lanes_of<S>;
  const mech::linkage::Chain& c = d.chain;
  auto& kept = std::get<ScalarScratch<S>>(ws.scalar);
  if (kept.a.point.size() != c.point_names().size()) {
    for (auto* st : {&kept.a, &kept.b}) st->resize(c);
    kept.e.resize(c);
  }
  mech::linkage::LaneSolver<S>& lanes = kept.lanes_at(c, v.data());
  const int n = static_cast<int>(ws.grid.size());
  const int nodes = 2 * d.mean_points();
  const S& w = v[static_cast<size_t>(c.crank().speed)];
  // Which integrals the wanted means need: the torque's (|M|, M^2), the
  // loads' power (the mean torque: inertia, gravity and springs give
  // back over a cycle what they take, so the mean is the loads' work,
  // free of the cancellation of a large periodic torque: exactly zero
  // without loads), the energy's.
  bool torque = false, work = false, energy = false, flywheel = false;
  for (size_t m : ws.wanted) {
    if (metrics[m].form < Form::mean) continue;
    if (metrics[m].q.kind == Kind::energy) energy = energy || metrics[m].form <= Form::k2;  // (k1, k2 too)
    else if (metrics[m].form == Form::flywheel || metrics[m].form == Form::swing) flywheel = work = true;
    else (metrics[m].form == Form::mean ? work : torque) = true;
  }
  const mech::ArcMeans<S> none{S(0.0), S(0.0), S(0.0)};
  mech::ArcMeans<S> mt = none, ml = none, me = none;
  // The loads' work from its arcs' ends where every load's allows
  // (work.hpp): then the kinks only where the torque's own means need them.
  const bool by_ends = work && work_from_ends(c);
  const bool arcs = torque || flywheel || (work && !by_ends);
  // The switches alone: the peaks' searches' where they found them (the same bits).
  const bool found = !arcs && by_ends && ws.switches_found;
  std::vector<std::pair<double, int>> own;
  const std::vector<double> kinks = arcs || (by_ends && !found) ? torque_kinks(c, ws.plain.data(), n, ws.zeros,
                                                                               ws.sd, ws.blocks, &own, arcs, &*ws.lanes)
                                                                : std::vector<double>{};
  const std::vector<std::pair<double, int>>& switches = found ? ws.switches : own;
  std::vector<Jump<S>> js;
  if (has_law && arcs) {
    contacts(c, ws.plain.data(), n, ws.contacts, ws.zeros, ws.sd, ws.blocks);
    js = jumps(c, v.data(), ws.plain.data(), std::span<const Contact>(ws.contacts), ws.sd);
  }
  // Both on the same arcs: the torque's pass keeps the loads' power at
  // its nodes, which the work's pass visits in the same order.
  const bool fused = work && !by_ends;
  auto loads = [&](const Lanes& phi, const mech::linkage::State<L>& st) {
    return L(-mech::linkage::load_power(c, lanes.v.data(), st, L(phi), false));
  };
  std::vector<L> power;
  size_t next = 0;
  if (torque)
    mt = mech::piecewise_means<S>(
        [&](const Lanes& phi, const Lanes& cp, const Lanes& sp) {
          const mech::linkage::State<L>& st = lanes.at(phi, cp, sp);
          if (fused) power.push_back(loads(phi, st));
          return mech::linkage::drive_point(c, lanes.v.data(), st).torque;
        },
        kinks, nodes, ws.cycle, near);
  mech::ArcMeans<S> unused = none;  // (the work from the ends takes no jump's term)
  if (by_ends) {
    ml.mean = mean_load_torque(c, v.data(), ws.plain.data(), switches, n, ws.blocks, [&] { return ws.states(); },
                               ws.sd, kept.e, kept.ends, lanes,
                               [&](double phi, mech::linkage::State<S>& to) {
                                 if constexpr (std::is_same_v<S, double>) return ws.searched.links_at(phi, to);
                                 else return kept.at_maxima.links_at(phi, to) || kept.at_positions.links_at(phi, to);
                               });
  } else if (work) {
    ml = mech::piecewise_means<S>(
        [&](const Lanes& phi, const Lanes& cp, const Lanes& sp) {
          return torque ? power.at(next++) : loads(phi, lanes.at(phi, cp, sp));
        },
        kinks, nodes, ws.cycle, near);
  }
  if (energy) me.mean = energy_mean(d, v, near, kept, energy_grid(ws), ws);
  S swing(0.0);
  add_jumps(js, mt, by_ends ? unused : ml);
  if (flywheel) swing = work_swing(d, v, ml.mean, kinks, js, near, kept.a, ws);
  for (size_t m : ws.wanted) {
    const Metric& mt_m = metrics[m];
    if (mt_m.form < Form::mean) continue;
    using std::sqrt;
    if (mt_m.form >= Form::k1) continue;  // put by the caller
    if (mt_m.form == Form::swing)
      out.put(static_cast<int>(m), swing);
    else if (mt_m.form == Form::flywheel)
      out.put(static_cast<int>(m), S(swing / (v[static_cast<size_t>(d.speed_fluctuation)] * w * w)));
    else if (mt_m.q.kind == Kind::energy) out.put(static_cast<int>(m), me.mean);
    else if (mt_m.form == Form::mean) out.put(static_cast<int>(m), ml.mean);
    else out.put(static_cast<int>(m), mt_m.form == Form::mean_abs ? mt.mean_abs : S(sqrt(mt.mean_square)));
  }
  return me.mean;
}

}  // namespace problems::linkage
