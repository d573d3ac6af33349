// Maxima over the cycle of 2*pi-periodic functions of the crank angle:
// bracketed on the grid and refined to machine precision by root searches on
// the angle derivative (LaneRootSearch, side by side, their points asked for
// as batches of AngleQuery and answered kLanes at a time).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "mech/angles.hpp"
#include "mech/autodiff.hpp"
#include "mech/cycle_scratch.hpp"
#include "mech/grow.hpp"
#include "mech/inline.hpp"
#include "mech/roots.hpp"
#include "mech/simd.hpp"

namespace mech {

// Calls block(q, lanes, c, s) for the queries, kLanes at a time: q =
// &qs[i], lanes how many (at most kLanes), c and s the cos and sin of their
// angles (missing lanes take the first angle again).
template <class F>
void for_query_blocks(std::span<AngleQuery> qs, F&& block) {
  for (std::size_t i = 0; i < qs.size(); i += kLanes) {
    AngleQuery* q = &qs[i];
    const int lanes = static_cast<int>(std::min<std::size_t>(kLanes, qs.size() - i));
    Lanes phi(q[0].phi), c, s;
    for (int j = 1; j < lanes; ++j) phi[j] = q[j].phi;
    sincos(phi, s, c);
    block(q, lanes, c, s);
  }
}

// Runs root searches side by side until every one is done, one batch a
// step: search i asks for function fn[i] (its slope when `slope`).
template <class Eval>
void run_side_by_side(std::span<LaneRootSearch> searches, std::span<const int> fn, bool slope,
                      Grow<AngleQuery>& batch, Eval& eval) {
  while (true) {
    batch.clear();
    for (std::size_t i = 0; i < searches.size(); ++i)
      if (!searches[i].done())
        for (double x : searches[i].xs()) batch.push_back({x, fn[i], slope});
    if (batch.empty()) return;
    eval(std::span<AngleQuery>(batch));
    const AngleQuery* q = batch.begin();  // each search's queries, in the order asked
    for (LaneRootSearch& s : searches) {
      if (s.done()) continue;
      const std::size_t asked = s.xs().size();
      s.feed_each([q](int i) { return q[i].out; });
      q += asked;
    }
  }
}

// The largest of v (n >= 3 samples of a periodic function) and the largest
// |second difference|, kLanes points at a time (running maxima in lanes;
// the largest of a set does not depend on the order it is taken in).
MECH_INLINE std::pair<double, double> max_and_curvature(std::span<const double> v) {
  const std::size_t n = v.size();
  auto second = [&](std::size_t k) { return std::abs(v[k + 1] - 2 * v[k] + v[k - 1]); };
  double top = std::max(v[0], v[n - 1]);
  double bend = std::max(std::abs(v[1] - 2 * v[0] + v[n - 1]), std::abs(v[0] - 2 * v[n - 1] + v[n - 2]));
  std::size_t k = 1;
  if (n >= kLanes + 2) {
    Lanes tops(top), bends(bend);
    for (; k + kLanes < n; k += kLanes) {
      const Lanes at = load_lanes(&v[k]);
      tops = max(tops, at);
      bends = max(bends, abs(load_lanes(&v[k + 1]) - 2 * at + load_lanes(&v[k - 1])));
    }
    for (int j = 0; j < kLanes; ++j) top = std::max(top, tops[j]), bend = std::max(bend, bends[j]);
  }
  for (; k + 1 < n; ++k) top = std::max(top, v[k]), bend = std::max(bend, second(k));
  return {top, bend};
}

// Finds the maxima of several periodic functions of the crank angle together,
// asking for their values and slopes in batches: eval(std::span<AngleQuery>)
// fills every query's out (a model can answer kLanes at a time). The answers
// do not depend on how the searches are grouped.
//
// Local maxima: next to every grid local maximum (no lower than max(v) -
// margin) the + to - sign changes of df one grid step h either side, each
// side cut at the kinks of f inside it (where df jumps: a kink may part two
// maxima, or be one), each refined by a LaneRootSearch (from a third point
// on the same piece where there is one). Where nothing shows (two maxima
// closer than a step), each piece is searched again in 4 parts; none found:
// the grid point. A search given `known` angles (a global one: every
// local maximum lies at one of them) takes those whose grid cell reaches
// max(v) - margin as found, with no root search, and asks f there in the
// first batch (with the kinks': a model that answers queries at one
// angle together solves those angles once).
//
// Global maximum: two nearly equal peaks can swap order between the grid
// and the truth, so every grid local maximum that could be the highest is
// refined and the largest kept. A peak lies at most h^2 |f''| / 8 above its
// best grid value; |f''| h^2 is estimated by the largest second difference,
// and peaks more than twice that bound below the grid maximum are skipped.
// Kinks are candidates themselves, as is the best grid point (the answer is
// never below a value the grid has seen). A smooth maximum beside a kink
// need not show on the grid as a local maximum (the grid point past the kink
// may be higher): where the grid rises into a kink, the two cells before it
// (or after it) are searched too.
//
// `scratch`: the lists reused from one call to the next (eval must not call
// find_cycle_maxima with the same scratch).
template <class Eval>
void find_cycle_maxima(std::span<CycleMaxSearch> searches, Eval&& eval, CycleScratch& scratch) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  using Point = CycleScratch::Point;
  using Candidate = CycleScratch::Candidate;
  using Root = CycleScratch::Root;
  using Bracket = CycleScratch::Bracket;
  auto& batch = scratch.batch;
  auto& points = scratch.points;
  auto& cands = scratch.cands;
  auto &roots = scratch.roots, &beside_roots = scratch.beside_roots;
  auto& beside = scratch.beside;
  auto& known = scratch.known;
  auto &kink_queries = scratch.kink_queries, &root_fn = scratch.root_fn, &tops = scratch.tops;
  auto& kink_f = scratch.kink_f;
  auto& roots_searched = scratch.roots_searched;
  points.clear(), cands.clear(), roots.clear(), beside_roots.clear(), beside.clear(), known.clear();
  kink_queries.clear(), kink_f.clear(), roots_searched.clear(), root_fn.clear(), tops.clear();
  auto ask = [&](double phi, int fn, bool slope) {
    batch.push_back({phi, fn, slope});
    return static_cast<int>(batch.size()) - 1;
  };
  auto run = [&] {
    if (!batch.empty()) eval(std::span<AngleQuery>(batch));
  };
  // A root search where the slope falls through zero from a to b; `beside`:
  // a third point on the same piece of f, to start the interpolation from.
  auto root_of = [&](int fn, const Point& a, const Point& b, Grow<Root>& to, const Point* beside = nullptr) {
    if (const int fall = falls_through_zero(a.g, b.g); fall == 1) {
      to.push_back({fn, nan, static_cast<int>(roots_searched.size())});
      roots_searched.emplace_back(a.x, b.x, a.g, b.g, beside ? beside->x : nan, beside ? beside->g : nan);
      root_fn.push_back(fn);
    } else if (fall == 2) {
      to.push_back({fn, b.x});
    }
  };
  auto fill = [&](Point& p) {
    if (p.query >= 0) p.g = batch[p.query].out;
  };
  auto wrapped = [](double phi) { return phi < 0 ? phi + kTwoPi : phi >= kTwoPi ? phi - kTwoPi : phi; };

  // 1. Candidates; df where not known (and, for the global maximum, f at the
  // kinks and df at the ends of the cells beside them).
  batch.clear();
  for (std::size_t fn = 0; fn < searches.size(); ++fn) {
    const CycleMaxSearch& s = searches[fn];
    const auto& v = s.v;
    const int n = static_cast<int>(v.size()), f = static_cast<int>(fn);
    const double h = kTwoPi / n, eps = 1e-9 * h;  // eps: either side of a kink, its one-sided slopes
    const auto [vmax, curvature] = max_and_curvature(v);
    const double margin = s.global ? 0.25 * curvature : s.margin, low = vmax - margin;
    auto at = [&](int i) { return v[static_cast<std::size_t>(i < 0 ? i + n : i >= n ? i - n : i)]; };  // -n <= i < 2n
    if (!s.known.empty()) {  // found already, where their cells reach low; f there in this batch
      for (double phi : s.known) {
        const int j = static_cast<int>(std::floor(wrap_angle(phi) / h));
        if (std::max(at(j), at(j + 1)) < low) continue;
        roots.push_back({f, phi});
        if (s.global) known.push_back({f, wrapped(phi), ask(wrapped(phi), f, false)});
      }
      tops.push_back(-1);
      continue;
    }
    int top = -1;  // the first grid point at vmax (none where v holds a NaN)
    for (int k = 0; k < n; ++k) {
      // Most points lie below low: kLanes of them skipped at a time.
      if (k % kLanes == 0 && k + kLanes <= n && all_below(load_lanes(&v[k]), low)) {
        k += kLanes - 1;
        continue;
      }
      if (v[k] < low) continue;
      if (top < 0 && v[k] == vmax) top = k;
      const int before = k == 0 ? n - 1 : k - 1, after = k + 1 == n ? 0 : k + 1;  // no division per point
      if (v[k] < v[before] || v[k] < v[after]) continue;
      if (v[after] == v[k] && k + 1 < n) continue;  // a flat top: refine it once
      const double phi_k = k * h;
      const int first = static_cast<int>(points.size()), around[3] = {before, k, after};
      for (int i = 0; i < 3; ++i) points.push_back({phi_k + (i - 1) * h, s.slopes.empty() ? nan : s.slopes[around[i]]});
      for (double kink : s.kinks) {
        // The copy nearest phi_k (times 1/(2 pi), not divided: the rounding
        // differs only for a kink half a turn away, outside the cells either way).
        const double kc = kink + kTwoPi * round_half_away((phi_k - kink) * (1 / kTwoPi));
        if (kc - eps > phi_k - h && kc + eps < phi_k + h) {
          points.push_back({kc - eps, nan, -1, true});
          points.push_back({kc + eps, nan, -1, true});
        }
      }
      // By angle: insertion (what std::sort does for so few, without its calls).
      for (auto p = points.begin() + first + 1; p != points.end(); ++p)
        for (auto q = p; q != points.begin() + first && q->x < (q - 1)->x; --q) std::iter_swap(q, q - 1);
      for (auto p = points.begin() + first; p != points.end(); ++p)
        if (std::isnan(p->g)) p->query = ask(p->x, f, true);
      cands.push_back({f, phi_k, first, static_cast<int>(points.size()) - first});
    }
    tops.push_back(top);
    if (!s.global) continue;
    for (double kink : s.kinks) {
      kink_queries.push_back(ask(kink, f, false));
      if (!std::isfinite(kink)) continue;  // its value asked above: NaN, never the peak
      const int j = static_cast<int>(std::floor(wrap_angle(kink) / h));  // grid points j <= kink < j + 1
      if (std::max(at(j), at(j + 1)) < vmax - margin) continue;
      auto cell = [&](double a, double b) {
        beside.push_back({f, {a, nan, ask(a, f, true)}, {b, nan, ask(b, f, true)}});
      };
      if (at(j) > at(j - 1)) cell((j - 1) * h, kink - eps);
      if (at(j + 1) > at(j + 2)) cell(kink + eps, (j + 2) * h);
    }
  }
  run();
  for (int q : kink_queries) kink_f.push_back(batch[q].out);
  for (CycleScratch::Known& k : known) k.f = batch[k.query].out;
  for (Point& p : points) fill(p);
  for (Bracket& b : beside) {
    fill(b.a), fill(b.b);
    root_of(b.fn, b.a, b.b, beside_roots);
  }

  // 2. Sign changes of df in each candidate's pieces; the 4-part search
  // where none shows (two maxima closer than a step)...
  batch.clear();
  for (Candidate& c : cands) {
    const std::size_t before = roots.size();
    const Point* p = &points[c.first];
    for (int i = 0; i + 1 < c.count; ++i) {
      const bool left = i > 0 && !(p[i - 1].kink && p[i].kink), right = i + 2 < c.count && !(p[i + 1].kink && p[i + 2].kink);
      const Point* beside = left && (!right || std::abs(p[i].g) <= std::abs(p[i + 1].g)) ? &p[i - 1] : right ? &p[i + 2] : nullptr;
      root_of(c.fn, p[i], p[i + 1], roots, beside);
    }
    if (roots.size() > before) continue;
    c.quarter = static_cast<int>(batch.size());
    for (int i = 0; i + 1 < c.count; ++i)
      for (int part = 1; part < 4; ++part) ask(p[i].x + (p[i + 1].x - p[i].x) * part / 4, c.fn, true);
  }
  run();
  for (const Candidate& c : cands) {  // ... and where that finds none, the grid point
    if (c.quarter < 0) continue;
    const std::size_t before = roots.size();
    const Point* p = &points[c.first];
    for (int i = 0, q = c.quarter; i + 1 < c.count; ++i) {
      Point a = p[i];
      for (int part = 1; part <= 4; ++part) {
        const Point x = part == 4 ? p[i + 1] : Point{batch[q].phi, batch[q].out};
        q += part < 4;
        root_of(c.fn, a, x, roots);
        a = x;
      }
    }
    if (roots.size() == before) roots.push_back({c.fn, c.phi_k});
  }

  // 3. Every root search side by side, one batch a step.
  run_side_by_side(roots_searched, root_fn, true, batch, eval);
  auto resolved = [&](const Root& r) { return r.search >= 0 ? roots_searched[r.search].root() : r.phi; };

  // 4. The local maxima in [0, 2 pi) by angle; for the global maximum, f at
  // each of them, at the kinks and beside them, the largest kept (the first
  // of equal values, in that order).
  for (CycleMaxSearch& s : searches) s.maxima.clear();
  for (const Root& r : roots) searches[r.fn].maxima.push_back(resolved(r));
  batch.clear();
  for (std::size_t fn = 0; fn < searches.size(); ++fn) {
    auto& m = searches[fn].maxima;
    for (double& phi : m) phi = wrapped(phi);
    if (m.size() == 2) {  // the usual count: no call
      if (m[1] < m[0]) std::swap(m[0], m[1]);
    } else {
      std::sort(m.begin(), m.end());
    }
    if (searches[fn].global && searches[fn].known.empty())
      for (double phi : m) ask(phi, static_cast<int>(fn), false);
  }
  const std::size_t beside_first = batch.size();
  for (const Root& r : beside_roots) ask(resolved(r), r.fn, false);
  run();
  std::size_t q = 0, kink = 0;
  for (std::size_t fn = 0; fn < searches.size(); ++fn) {
    CycleMaxSearch& s = searches[fn];
    if (!s.global) continue;
    const std::size_t top = tops[fn] >= 0 ? static_cast<std::size_t>(tops[fn])
                                          : static_cast<std::size_t>(std::max_element(s.v.begin(), s.v.end()) - s.v.begin());
    s.value = s.v[top];
    s.phi = kTwoPi * static_cast<double>(top) / static_cast<double>(s.v.size());
    auto consider = [&](double phi, double fv) {
      if (fv > s.value) s.value = fv, s.phi = phi;
    };
    if (s.known.empty()) {
      for (std::size_t i = 0; i < s.maxima.size(); ++i, ++q) consider(batch[q].phi, batch[q].out);
    } else {  // (by angle, as the others)
      for (double phi : s.maxima)
        for (const CycleScratch::Known& k : known)
          if (k.fn == static_cast<int>(fn) && k.phi == phi) {
            consider(phi, k.f);
            break;
          }
    }
    for (double k : s.kinks) consider(k, kink_f[kink++]);
    for (std::size_t i = 0; i < beside_roots.size(); ++i)
      if (beside_roots[i].fn == static_cast<int>(fn)) consider(batch[beside_first + i].phi, batch[beside_first + i].out);
  }
}

// The same with lists of its own (tests, one-off searches).
template <class Eval>
void find_cycle_maxima(std::span<CycleMaxSearch> searches, Eval&& eval) {
  CycleScratch scratch;
  find_cycle_maxima(searches, eval, scratch);
}

// An evaluator of angle queries by reference, its type erased: the searches
// that evaluate one angle at a time go through find_cycle_maxima<BatchEval>,
// made once, not once for every function searched (the balanced
// slider-crank made it once for each of its cycle quantities and scalar
// types: most of its compile time under the sanitizers); one indirect call
// a batch.
class BatchEval {
 public:
  template <class F>
  explicit BatchEval(F& f)
      : f_(&f), call_([](void* g, std::span<AngleQuery> qs) { (*static_cast<F*>(g))(qs); }) {}
  void operator()(std::span<AngleQuery> qs) const { call_(f_, qs); }

 private:
  void* f_;
  void (*call_)(void*, std::span<AngleQuery>);
};

// find_cycle_maxima for one function f, evaluated one angle at a time: the
// refined local maxima of f (given its derivative df) no lower than max(v) -
// margin, sorted by angle...
template <class DF>
std::vector<double> local_max_angles(const std::vector<double>& v, DF&& df, double margin = HUGE_VAL,
                                     const std::vector<double>& kinks = {}, const std::vector<double>& slopes = {}) {
  CycleMaxSearch s{.v = v, .kinks = kinks, .slopes = slopes, .global = false, .margin = margin, .maxima = {}};
  auto eval = [&](std::span<AngleQuery> qs) {
    for (AngleQuery& q : qs) q.out = df(q.phi);
  };
  find_cycle_maxima(std::span(&s, 1), BatchEval(eval));
  return std::move(s.maxima);
}

// ... and the angle of its global maximum, given f and df.
template <class F, class DF>
double global_max_angle(const std::vector<double>& v, F&& f, DF&& df, const std::vector<double>& kinks = {},
                        const std::vector<double>& slopes = {}) {
  CycleMaxSearch s{.v = v, .kinks = kinks, .slopes = slopes, .maxima = {}};
  auto eval = [&](std::span<AngleQuery> qs) {
    for (AngleQuery& q : qs) q.out = q.slope ? df(q.phi) : f(q.phi);
  };
  find_cycle_maxima(std::span(&s, 1), BatchEval(eval));
  return s.phi;
}

// g(model, phi) on an n-point grid, for a model of doubles.
template <class M, class G>
std::vector<double> cycle_samples(const M& md, int n, G& g) {
  std::vector<double> v(n);
  for (int k = 0; k < n; ++k) v[k] = g(md, kTwoPi * k / n);
  return v;
}

// Refined angles of every local maximum over the cycle of g(model, phi), a
// quantity of a model with cast<T>() (double samples on an n-point grid; the
// angle derivative by autodiff in phi), sorted by angle.
template <class M, class G>
std::vector<double> cycle_max_angles(const M& model, int n, G&& g) {
  const auto md = model.template cast<double>();
  const auto mv = model.template cast<Dual>();
  return local_max_angles(cycle_samples(md, n, g), [&](double phi) { return g(mv, seed(phi)).d; });
}

}  // namespace mech
