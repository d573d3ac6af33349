// Where a linkage's driving torque is not smooth in the crank angle: the
// angles its means' Gauss arcs end at (the torque's zeros, a load switching
// on or off, a motion reversing under an opposing load or a friction, a
// table's row), and a pressure law's contacts, where the torque jumps. A
// jump or a table's row is a candidate for the torque's and the forces'
// maxima, and a contact or a row over position moves with the design: the
// maximum's gradient takes its motion (kink_shift), as the means take a
// jump's (the Leibniz term that Gauss arcs with fixed ends leave out).
#pragma once
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "mech/angles.hpp"
#include "mech/cycle_maxima.hpp"
#include "mech/linkage/dynamics.hpp"
#include "mech/periodic_roots.hpp"
#include "mech/quadrature.hpp"

namespace problems::linkage {

// A function of the crank angle whose zeros bend or break the metrics:
// the driving torque (load -1), a load's switching rate (row -1), the
// coordinate its table reads less a row, or a pressure law's depth (kDepth).
struct KinkFn {
  int load, row;
};
inline constexpr int kDepth = -2;

// The coordinate load l's table over position reads (dynamics.hpp's
// load_action), with its slopes: its slider's s, or its link's angle in
// (-pi, pi].
template <class S>
mech::linkage::Jet<S> table_coordinate(const mech::linkage::Load& l, const mech::linkage::State<S>& st) {
  if (l.kind == mech::linkage::Load::Kind::force) return st.slide[static_cast<size_t>(l.link)];
  return st.angle(l.link);
}

// A row's or a contact's gap (f.row >= 0 or kDepth): the coordinate less
// the row's x, or the slider's s less the law's contact, with its slopes.
template <class S>
mech::linkage::Jet<S> gap(const mech::linkage::Chain& c, const KinkFn& f, const mech::linkage::State<S>& st,
                          const S* v) {
  const auto& l = c.loads()[static_cast<size_t>(f.load)];
  mech::linkage::Jet<S> g = f.row == kDepth ? st.slide[static_cast<size_t>(l.link)] : table_coordinate(l, st);
  g.v = S(g.v - (f.row == kDepth ? v[l.law_contact] : S(l.xs[static_cast<size_t>(f.row)])));
  return g;
}

template <class S>
S kink_value(const mech::linkage::Chain& c, const KinkFn& f, const mech::linkage::State<S>& st, const S* v) {
  if (f.load < 0) return mech::linkage::drive_point(c, v, st).torque;
  if (f.row >= 0 || f.row == kDepth) return gap(c, f, st, v).v;
  return mech::linkage::switch_rate(c.loads()[static_cast<size_t>(f.load)], st).v;
}

// The chain solved at the n grid angles 2 pi i / n of an evaluation, once
// for every pass that starts on the grid (empty: each solves its own):
// its states, or the same in blocks of kLanes angles (block b holds
// angles b kLanes, ...; the last block's spare lanes repeat its last).
using GridStates = std::span<const mech::linkage::State<double>>;
using GridBlocks = std::span<const mech::linkage::State<mech::Lanes>>;

namespace detail {

// Where point p lies on the crank: its radius from the pivot and its
// angle in the crank's frame; false where p is not on the crank or is
// its pivot.
inline bool on_crank(const mech::linkage::Chain& c, const double* v, int p, double& rho, double& alpha) {
  const mech::linkage::Crank& k = c.crank();
  const mech::linkage::Link& l = c.links()[static_cast<size_t>(k.link)];
  double u = v[l.length], w = 0;
  if (p != k.joint) {
    const auto at = std::find_if(l.points.begin(), l.points.end(), [p](const auto& lp) { return lp.point == p; });
    if (at == l.points.end()) return false;
    u = v[at->u], w = v[at->v];
  }
  rho = std::hypot(u, w), alpha = std::atan2(w, u);
  return rho > 0;
}
// A ground point's place; false where p is not on the ground.
inline bool on_ground(const mech::linkage::Chain& c, const double* v, int p, double& x, double& y) {
  for (const auto& [q, xy] : c.ground_points())
    if (q == p) return x = v[xy.first], y = v[xy.second], true;
  return false;
}

}  // namespace detail

// Where a link's coordinate stands still, in closed form, where it is the
// output of a group driven straight from the crank: a slider (`slides`:
// its s) on a line fixed to the ground (RRP) or a link pivoted on a ground
// point (RRR: its angle), the group's other known point P on the crank,
// rho from its pivot O. That output stands still where the crank and the
// link from P lie in line (O, P and the joint B collinear: a slider's
// dead centres, a rocker's limits), so B is on its line or its circle at
// |B - O| = a + rho (stretched) or |a - rho| (folded), a the length P -
// B. at[0, m): the crank angles in [0, 2 pi) of those on the group's
// branch; false where the link is no such output.
inline bool output_stops(const mech::linkage::Chain& c, const double* v, int link, bool slides, double (&at)[4],
                         int& m) {
  using mech::linkage::GroupType;
  using mech::linkage::kNone;
  const mech::linkage::Crank& k = c.crank();
  const auto& links = c.links();
  double ox = 0, oy = 0;
  if (!detail::on_ground(c, v, k.pivot, ox, oy)) return false;
  for (const mech::linkage::Group& gr : c.groups()) {
    const bool slider = slides && gr.type == GroupType::RRP && gr.second == link;
    const bool rocker = !slides && gr.type == GroupType::RRR && (gr.first == link || gr.second == link);
    if (!slider && !rocker) continue;
    const bool from_p = !rocker || gr.second == link;  // the input is the group's p (else its q)
    const int input = from_p ? gr.p : gr.q;
    double rho, alpha, qx = 0, qy = 0, ux = 0, uy = 0, tx = 0, ty = 0;
    if (!detail::on_crank(c, v, input, rho, alpha)) return false;
    const double a = v[links[static_cast<size_t>(from_p ? gr.first : gr.second)].length];
    double b = 0;
    if (rocker) {
      if (!detail::on_ground(c, v, from_p ? gr.q : gr.p, qx, qy)) return false;
      b = v[links[static_cast<size_t>(link)].length];
    } else {
      const mech::linkage::Link& s = links[static_cast<size_t>(gr.second)];
      if (s.line_on != kNone || !detail::on_ground(c, v, s.line_through, tx, ty)) return false;
      ux = std::cos(v[s.line_angle]), uy = std::sin(v[s.line_angle]);
      const double offset = s.line_offset == kNone ? 0.0 : v[s.line_offset];
      tx -= offset * uy, ty += offset * ux;  // the line's origin, offset to the left of u
    }
    if (!(a > 0) || a == rho) return false;
    m = 0;
    for (const double r : {a + rho, std::abs(a - rho)}) {
      // P along B - O (stretched, or folded with rho > a), else against it.
      const double toward = r == a + rho || rho > a ? 1.0 : -1.0;
      for (const double side : {-1.0, 1.0}) {
        double bx, by;
        if (rocker) {  // the circles |B - O| = r and |B - Q| = b
          const double dx = qx - ox, dy = qy - oy, d = std::hypot(dx, dy);
          const double along = (r * r - b * b + d * d) / (2 * d), across2 = r * r - along * along;
          if (!(across2 > 0)) continue;
          const double across = side * std::sqrt(across2);
          bx = ox + (along * dx - across * dy) / d, by = oy + (along * dy + across * dx) / d;
        } else {  // the line T + s u at |B - O| = r
          const double wx = tx - ox, wy = ty - oy, wn = uy * wx - ux * wy;  // (w . n, n = rot90(u), negated)
          const double disc = r * r - wn * wn;
          if (!(disc > 0)) continue;
          const double s = -(wx * ux + wy * uy) + side * std::sqrt(disc);
          bx = tx + s * ux, by = ty + s * uy;
        }
        const double len = std::hypot(bx - ox, by - oy), ex = toward * (bx - ox) / len, ey = toward * (by - oy) / len;
        const double px = ox + rho * ex, py = oy + rho * ey;
        // On the group's branch (kinematics.hpp's sign conventions)?
        double sign;
        if (rocker) {
          const double gpx = from_p ? px : qx, gpy = from_p ? py : qy, gqx = from_p ? qx : px, gqy = from_p ? qy : py;
          sign = (gqx - gpx) * (by - gpy) - (gqy - gpy) * (bx - gpx);
        } else {
          sign = (bx - px) * ux + (by - py) * uy;
        }
        if (!(sign * gr.branch > 0) || m == 4) continue;
        at[m++] = mech::wrap_angle(k.sense * (std::atan2(ey, ex) - alpha - v[k.phase]));
      }
    }
    return true;
  }
  return false;
}

// Load l's switches in closed form: its link's stops, where it acts on
// that link alone (a force on a slider, a torque on a rocker).
inline bool output_stops(const mech::linkage::Chain& c, const double* v, const mech::linkage::Load& l,
                         double (&at)[4], int& m) {
  return l.other == mech::linkage::kNone &&
         output_stops(c, v, l.link, l.kind == mech::linkage::Load::Kind::force, at, m);
}

// The stops at[0, m) appended in the order of the grid's cells (g: the
// rate on the n-point grid) where every cell whose rate changes sign
// holds exactly one of them and none is left over; else false, nothing
// appended (the root searches find the zeros).
inline bool stops_in_cells(const double (&at)[4], int m, const double* g, int n, std::vector<double>& out) {
  const size_t first = out.size();
  const double h = mech::kTwoPi / n;
  for (int k = 0; k < n; ++k) {
    // Most cells keep one nonzero sign (ga gb > 0): kLanes of them skipped at a time.
    if (k % mech::kLanes == 0 && k + mech::kLanes < n &&
        mech::positive_everywhere(mech::load_lanes(g + k) * mech::load_lanes(g + k + 1))) {
      k += mech::kLanes - 1;
      continue;
    }
    const double ga = g[k], gb = g[k + 1 == n ? 0 : k + 1];
    if (!(ga == 0.0 || ((ga < 0) != (gb < 0) && gb != 0.0))) continue;
    int in = -1;
    for (int i = 0; i < m; ++i) {
      double off = at[i] - (k + 0.5) * h;  // from the cell's middle, in (-2 pi, 2 pi): the nearest copy
      off = off > std::numbers::pi ? off - mech::kTwoPi : off < -std::numbers::pi ? off + mech::kTwoPi : off;
      if (!(std::abs(off) <= 0.5 * h * (1 + 1e-9))) continue;
      if (in >= 0) return out.resize(first), false;
      in = i;
    }
    if (in < 0) return out.resize(first), false;
    out.push_back(at[in]);
  }
  if (out.size() - first == static_cast<size_t>(m)) return true;
  out.resize(first);
  return false;
}

// What zeros_of reuses from one call to the next (no allocation per
// design once warm): the functions' grids and its lists, and output_stops'
// answers for the design under evaluation (`stops`: clear them for
// another design).
struct ZeroScratch {
  std::vector<double> grid, closed, zeros;
  std::vector<size_t> closed_end, searched;
  std::vector<std::span<const double>> grids;
  std::vector<int> found_owner, owner;
  std::vector<KinkFn> fns;
  struct Stops {
    int link;
    bool slides, found;
    double at[4];
    int m;
  };
  std::vector<Stops> stops;
  // output_stops, once a design for each link.
  bool output_stops(const mech::linkage::Chain& c, const double* v, int link, bool slides, double (&at)[4], int& m) {
    auto known = std::find_if(stops.begin(), stops.end(),
                              [&](const Stops& s) { return s.link == link && s.slides == slides; });
    if (known == stops.end()) {
      Stops s{link, slides, false, {}, 0};
      s.found = problems::linkage::output_stops(c, v, link, slides, s.at, s.m);
      known = stops.insert(stops.end(), s);
    }
    std::copy(known->at, known->at + 4, at);
    m = known->m;
    return known->found;
  }
};

// The zeros of switch f in closed form (output_stops) by stops_in_cells.
inline bool grid_stops(const mech::linkage::Chain& c, const double* v, const KinkFn& f, const double* g, int n,
                       ZeroScratch& z) {
  double at[4];
  int m = 0;
  if (f.load < 0 || f.row != -1) return false;
  const mech::linkage::Load& l = c.loads()[static_cast<size_t>(f.load)];
  return l.other == mech::linkage::kNone &&
         z.output_stops(c, v, l.link, l.kind == mech::linkage::Load::Kind::force, at, m) &&
         stops_in_cells(at, m, g, n, z.closed);
}

// The angles in [0, 2 pi) where the functions fns cross zero (each
// function's by grid cell), found on an n-point grid (kept in z.grid) and
// refined, or in closed form where a switch has one (grid_stops): z.zeros;
// sd: a state to solve in; owner, where given: each zero's function (its
// index in fns); lanes, where given: the chain's lanes at v (kept by the
// caller: none made per call).
inline const std::vector<double>& zeros_of(const mech::linkage::Chain& c, const double* v, int n,
                                           const std::vector<KinkFn>& fns, ZeroScratch& z,
                                           mech::linkage::State<double>& sd, GridBlocks solved = {},
                                           std::vector<int>* owner = nullptr,
                                           mech::linkage::LaneSolver<double>* lanes = nullptr) {
  const size_t un = static_cast<size_t>(n);
  std::vector<double>& grid = z.grid;
  grid.resize(fns.size() * un);
  std::optional<mech::linkage::LaneSolver<double>> own;
  if (!lanes) lanes = &own.emplace(c, v);
  if (solved.empty()) {
    for (int i = 0; i < n; ++i) {
      mech::linkage::solve(c, v, mech::kTwoPi * i / n, sd);
      for (size_t f = 0; f < fns.size(); ++f) grid[f * un + static_cast<size_t>(i)] = kink_value(c, fns[f], sd, v);
    }
  } else {
    for (size_t b = 0; b < solved.size(); ++b) {
      const size_t k = b * mech::kLanes;
      const int m = static_cast<int>(std::min<size_t>(mech::kLanes, un - k));
      for (size_t f = 0; f < fns.size(); ++f)
        mech::store_lanes(grid.data() + f * un + k, kink_value(c, fns[f], solved[b], lanes->v.data()), m);
    }
  }
  std::vector<double>& stops = z.closed;  // the closed forms' zeros, function by function
  std::vector<size_t>& stops_end = z.closed_end;
  std::vector<size_t>& searched = z.searched;
  std::vector<std::span<const double>>& grids = z.grids;
  stops.clear(), stops_end.assign(fns.size(), 0), searched.clear(), grids.clear();
  for (size_t f = 0; f < fns.size(); ++f) {
    if (!grid_stops(c, v, fns[f], grid.data() + f * un, n, z)) {
      searched.push_back(f);
      grids.emplace_back(grid.data() + f * un, un);
    }
    stops_end[f] = stops.size();
  }
  // The searches' angles kLanes at a time on the chain's lanes (a lane
  // where the chain does not assemble, between grid points that do, takes
  // the scalar chain's stale state, as a lone query would).
  std::vector<int>& found_owner = z.found_owner;
  auto eval = [&](std::span<mech::AngleQuery> qs) {
    for (size_t i = 0; i < qs.size(); i += mech::kLanes) {
      const int m = static_cast<int>(std::min<size_t>(mech::kLanes, qs.size() - i));
      mech::Lanes phi, cp, sp, out;
      for (int j = 0; j < mech::kLanes; ++j) phi[j] = qs[i + static_cast<size_t>(std::min(j, m - 1))].phi;
      mech::sincos(phi, sp, cp);
      const auto& st = lanes->at(phi, cp, sp);
      for (int j = 0; j < m; ++j) {
        mech::AngleQuery& q = qs[i + static_cast<size_t>(j)];
        const KinkFn& fn = fns[searched[static_cast<size_t>(q.fn)]];
        if (j == 0 || q.fn != qs[i + static_cast<size_t>(j) - 1].fn) out = kink_value(c, fn, st, lanes->v.data());
        q.out = out[j];
        if (!std::isfinite(q.out)) {
          mech::linkage::solve(c, v, q.phi, sd);
          q.out = kink_value(c, fn, sd, v);
        }
      }
    }
  };
  const std::vector<double> found =
      grids.empty() ? std::vector<double>{} : mech::periodic_roots_together(std::span(grids), eval, &found_owner);
  // Function by function: the closed forms', the searches'.
  std::vector<double>& zeros = z.zeros;
  zeros.clear();
  if (owner) owner->clear();
  auto take = [&](double zero, size_t f) {
    zeros.push_back(zero);
    if (owner) owner->push_back(static_cast<int>(f));
  };
  for (size_t f = 0, r = 0, s = 0, i = 0; f < fns.size(); ++f) {
    if (i < searched.size() && searched[i] == f) {
      for (; r < found.size() && found_owner[r] == static_cast<int>(i); ++r) take(found[r], f);
      ++i;
    } else {
      for (; s < stops_end[f]; ++s) take(stops[s], f);
    }
  }
  return zeros;
}

// The angles where the driving torque is zero or bends (a load switches
// on or off, turns against a motion that reverses, or crosses a table's
// row or a law's contact): the arcs of its means (in z.zeros). With
// `torque` false, the switches alone. switches, where given: each
// switching load's zeros of its switch_rate, with the load. lanes: as
// zeros_of's.
inline const std::vector<double>& torque_kinks(const mech::linkage::Chain& c, const double* v, int n, ZeroScratch& z,
                                               mech::linkage::State<double>& sd, GridBlocks solved = {},
                                               std::vector<std::pair<double, int>>* switches = nullptr,
                                               bool torque = true,
                                               mech::linkage::LaneSolver<double>* lanes = nullptr) {
  using mech::linkage::Load;
  std::vector<KinkFn>& fns = z.fns;
  fns.clear();
  if (torque) fns.push_back({-1, -1});
  for (size_t i = 0; i < c.loads().size(); ++i) {
    const auto& l = c.loads()[i];
    const int li = static_cast<int>(i);
    if (mech::linkage::switching(l)) fns.push_back({li, -1});
    if (!torque) continue;
    if (l.over == Load::Over::position)
      for (size_t r = 0; r < l.xs.size(); ++r) fns.push_back({li, static_cast<int>(r)});
    if (l.law_a != mech::linkage::kNone) fns.push_back({li, kDepth});
  }
  std::vector<int>& owner = z.owner;
  std::vector<double>& kinks = z.zeros;
  zeros_of(c, v, n, fns, z, sd, solved, &owner, lanes);
  if (switches) {
    switches->clear();
    for (size_t i = 0; i < kinks.size(); ++i)
      if (const KinkFn& f = fns[static_cast<size_t>(owner[i])]; f.load >= 0 && f.row == -1)
        switches->emplace_back(kinks[i], f.load);
  }
  if (!torque) return kinks;
  for (const auto& l : c.loads())
    if (l.over == Load::Over::crank_angle)
      for (double x : l.xs) kinks.push_back(mech::wrap_angle(x));
  return kinks;
}

// A pressure law's contact: where its depth crosses zero, moved by ulps to
// the side where the depth is >= 0 (the law acts there, so the torque takes
// its upper value at the jump), and its load.
struct Contact {
  double phi;
  int load;
};
inline void contacts(const mech::linkage::Chain& c, const double* v, int n, std::vector<Contact>& out,
                     ZeroScratch& grid, mech::linkage::State<double>& sd, GridBlocks solved = {}) {
  out.clear();
  for (size_t i = 0; i < c.loads().size(); ++i) {
    const auto& l = c.loads()[i];
    if (l.law_a == mech::linkage::kNone) continue;
    const KinkFn depth{static_cast<int>(i), kDepth};
    for (double phi : zeros_of(c, v, n, {depth}, grid, sd, solved)) {
      mech::linkage::solve(c, v, phi, sd);
      const double toward = sd.slide[static_cast<size_t>(l.link)].d > 0 ? HUGE_VAL : -HUGE_VAL;
      for (int step = 0; step < 64 && kink_value(c, depth, sd, v) < 0; ++step)
        mech::linkage::solve(c, v, phi = std::nextafter(phi, toward), sd);
      out.push_back({phi, static_cast<int>(i)});
    }
  }
}

// How the kink where f's gap g crosses zero at phi (a contact's depth, a
// row's) moves with the design: zero, with the derivatives -g_x / g' (the
// implicit function theorem). A maximum there is the quantity at phi plus
// this on S: the total derivative along the kink. At a contact that is the
// side where the law acts (contacts() puts phi there); across a row the
// quantity is continuous (so is the table), so either side's formula has
// the same derivative along the kink, and the table's argument, held at
// the row, has none there: the segment interpolate picks (the left one at
// the row exactly) changes nothing.
template <class S>
S kink_shift(const mech::linkage::Chain& c, const S* v, const KinkFn& f, double phi, mech::linkage::State<S>& ss) {
  mech::linkage::solve(c, v, S(phi), ss);
  const mech::linkage::Jet<S> g = gap(c, f, ss, v);
  return S(-(g.v - mech::value(g.v)) / mech::value(g.d));
}

// A kink of the torque's and the forces' maxima that moves with the
// design, at phi: a law's contact ({load, kDepth}) or a table's row that
// its coordinate crosses ({load, row}).
struct MovingKink {
  double phi;
  KinkFn fn;
};

// The tables' rows: where each table over position is crossed at a row
// (appended to `moving`), and the angles of the rows of each table over
// the crank angle (fixed: appended to `fixed`).
inline void table_rows(const mech::linkage::Chain& c, const double* v, int n, std::vector<MovingKink>& moving,
                       std::vector<double>& fixed, ZeroScratch& grid, mech::linkage::State<double>& sd,
                       GridBlocks solved = {}) {
  using mech::linkage::Load;
  std::vector<KinkFn> fns;
  for (size_t i = 0; i < c.loads().size(); ++i) {
    const auto& l = c.loads()[i];
    if (l.over == Load::Over::crank_angle)
      for (double x : l.xs) fixed.push_back(mech::wrap_angle(x));
    if (l.over == Load::Over::position)
      for (size_t r = 0; r < l.xs.size(); ++r) fns.push_back({static_cast<int>(i), static_cast<int>(r)});
  }
  if (fns.empty()) return;
  for (double phi : zeros_of(c, v, n, fns, grid, sd, solved)) {
    // Its row: the gap nearest zero there; none beyond round-off where a
    // link's angle wraps at +-pi (a jump, not a row).
    mech::linkage::solve(c, v, phi, sd);
    size_t best = 0;
    double least = HUGE_VAL;
    for (size_t f = 0; f < fns.size(); ++f)
      if (const double g = std::abs(kink_value(c, fns[f], sd, v)); g < least) least = g, best = f;
    const double x = c.loads()[static_cast<size_t>(fns[best].load)].xs[static_cast<size_t>(fns[best].row)];
    if (least <= 1e-9 * (1 + std::abs(x))) moving.push_back({phi, fns[best]});
  }
}

// The torque's jump at a contact: its value with the law acting (on) and
// without (off), the sign of the depth's rate (+1: on after the contact),
// and the contact's shift.
template <class S>
struct Jump {
  double phi, sign, on, off;
  S shift;
};

// The jumps at the contacts ks (none where `when` holds the law off).
template <class S>
std::vector<Jump<S>> jumps(const mech::linkage::Chain& c, const S* v, const double* vd, std::span<const Contact> ks,
                           mech::linkage::State<double>& sd) {
  std::vector<Jump<S>> out;
  mech::linkage::State<S> ss;
  ss.resize(c);
  for (const Contact& k : ks) {
    const auto& l = c.loads()[static_cast<size_t>(k.load)];
    mech::linkage::solve(c, vd, k.phi, sd);
    double size = 0, rate = 0;
    if (!mech::linkage::load_action(c, l, vd, sd, k.phi, size, rate)) continue;
    const double on = mech::linkage::drive_point(c, vd, sd).torque;
    const double sign = sd.slide[static_cast<size_t>(l.link)].d > 0 ? 1.0 : -1.0;
    out.push_back({k.phi, sign, on, on + size * rate, kink_shift(c, v, {k.load, kDepth}, k.phi, ss)});
  }
  return out;
}

// The Leibniz terms the Gauss arcs with fixed ends leave out at the jumps:
// sign (f_off - f_on) shift / 2 pi in the cycle means of f = M (|M|, M^2:
// `torque`) and of the loads' power (`work`; its jump is the torque's).
template <class S>
void add_jumps(const std::vector<Jump<S>>& js, mech::ArcMeans<S>& torque, mech::ArcMeans<S>& work) {
  using std::abs;
  for (const Jump<S>& j : js) {
    const S d = S(j.shift * (j.sign / mech::kTwoPi));
    work.mean += (j.off - j.on) * d;
    torque.mean_abs += (abs(j.off) - abs(j.on)) * d;
    torque.mean_square += (j.off * j.off - j.on * j.on) * d;
  }
}

// The work of M - mean from a jump at phi on (before: up to it) takes its
// motion: f = M - mean beside it times its shift; zero where none is.
template <class S>
S jump_term(const std::vector<Jump<S>>& js, double phi, bool before, double mean) {
  for (const Jump<S>& j : js)
    if (std::abs(std::remainder(phi - j.phi, mech::kTwoPi)) < 1e-9)
      return S(((before == (j.sign > 0) ? j.off : j.on) - mean) * j.shift);
  return S(0.0);
}

// Each law given by its depth at the end of the stroke: its contact, the
// slider's largest coordinate over the cycle (on an n-point grid, refined)
// less the depth, written into v's contact slot with its design
// derivatives (Danskin: the coordinate at its maximising angle on S). vd:
// v's values. False where the chain does not assemble on the grid.
template <class S>
bool place_contacts(const mech::linkage::Chain& c, S* v, const double* vd, int n, std::vector<double>& grid,
                    mech::linkage::State<double>& sd, mech::linkage::State<S>& ss) {
  for (const auto& l : c.loads()) {
    if (l.law_depth == mech::linkage::kNone) continue;
    const size_t k = static_cast<size_t>(l.link);
    grid.resize(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
      if (!mech::linkage::solve(c, vd, mech::kTwoPi * i / n, sd)) return false;
      grid[static_cast<size_t>(i)] = sd.slide[k].v;
    }
    auto at = [&](double phi) -> const mech::linkage::Jet<double>& {
      mech::linkage::solve(c, vd, phi, sd);
      return sd.slide[k];
    };
    const double phi = mech::global_max_angle(
        grid, [&](double p) { return at(p).v; }, [&](double p) { return at(p).d; });
    mech::linkage::solve(c, v, S(phi), ss);
    v[l.law_contact] = S(ss.slide[k].v - v[l.law_depth]);
  }
  return true;
}

// v with those contacts placed; plain: scratch for v's values.
template <class S>
std::vector<S>& placed(const mech::linkage::Chain& c, int n, std::vector<S>& v, std::vector<double>& plain,
                       std::vector<double>& grid, mech::linkage::State<double>& sd) {
  plain.resize(v.size());
  for (size_t i = 0; i < v.size(); ++i) plain[i] = mech::value(v[i]);
  mech::linkage::State<S> ss;
  ss.resize(c);
  place_contacts(c, v.data(), plain.data(), n, grid, sd, ss);
  return v;
}

}  // namespace problems::linkage
