// Cycle quantities of a 2*pi-periodic function of the crank angle.
// Means use the periodic trapezoidal rule (exponentially convergent for smooth
// periodic integrands); maxima are bracketed on the grid and refined to machine
// precision by root searches on the angle derivative (LaneRootSearch, side by
// side, their points answered kLanes at a time).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "mech/autodiff.hpp"
#include "mech/simd.hpp"

namespace mech {

inline constexpr double kTwoPi = 2.0 * std::numbers::pi;
// std::round (halves away from zero) without libm's call: x - trunc(x) is
// exact, so the same value for every x.
inline double round_half_away(double x) {
  const double t = std::trunc(x);
  return std::abs(x - t) >= 0.5 ? t + std::copysign(1.0, x) : t;
}
// An angle taken into [0, 2 pi) (NaN stays NaN). Past |phi| ~ 1e16 the
// product's rounding leaves the range; the exact remainder then.
inline double wrap_angle(double phi) {
  const double w = phi - kTwoPi * std::floor(phi / kTwoPi);
  if ((w >= 0 && w < kTwoPi) || std::isnan(w)) return w;
  const double r = std::fmod(phi, kTwoPi);  // exact; NaN for an infinity
  return r < 0 ? (r + kTwoPi < kTwoPi ? r + kTwoPi : 0.0) : r;
}

// Calls f(k, c, s) for phi_k = 2*pi*k/n, k = 0..n-1, with c = cos(phi_k) and
// s = sin(phi_k) advanced by rotation (no trig call per point; drift ~n*eps).
template <class F>
void for_each_grid_angle(int n, F&& f) {
  const double ch = std::cos(kTwoPi / n), sh = std::sin(kTwoPi / n);
  double c = 1.0, s = 0.0;
  for (int k = 0; k < n; ++k) {
    f(k, c, s);
    const double cn = c * ch - s * sh;
    s = s * ch + c * sh;
    c = cn;
  }
}

// cos and sin of the grid angles 2*pi*k/n, kLanes at a time, computed once
// per n and thread for n up to 512 (nullptr beyond: such a design's cycle
// costs far more than its sincos). All tables together stay under 2.1 MB a
// thread (every n from 4 to 512), however many designs a batch runs.
struct GridTable {
  std::vector<Lanes> c, s;
};
inline const GridTable* grid_table(int n) {
  constexpr int kMost = 512;
  if (n > kMost || n < 1) return nullptr;
  static thread_local std::vector<GridTable> tables(kMost + 1);  // by n: no hashing per evaluation
  GridTable& t = tables[static_cast<std::size_t>(n)];
  if (t.c.empty()) {
    for (int k = 0; k < n; k += kLanes) {
      Lanes c, s;
      sincos(iota(k) * kTwoPi / n, s, c);
      t.c.push_back(c);
      t.s.push_back(s);
    }
  }
  return &t;
}

// Calls f(k, m, c, s) for the grid angles phi = 2*pi*j/n, j = k..k+kLanes-1,
// kLanes at a time (Lanes c = cos(phi), s = sin(phi)); the first m lanes are
// on the grid (the last block may run past n - 1).
template <class F>
void for_each_grid_block(int n, F&& f) {
  const GridTable* table = grid_table(n);
  for (int k = 0; k < n; k += kLanes) {
    Lanes c, s;
    if (table) {
      c = table->c[k / kLanes];
      s = table->s[k / kLanes];
    } else {
      sincos(iota(k) * kTwoPi / n, s, c);
    }
    f(k, std::min(kLanes, n - k), c, s);
  }
}

// Brent's root finder (zeroin) for g on [a, b] with g(a), g(b) of opposite
// signs, as a search that asks for one value at a time: while !done(), feed
// it g(x()). The root comes to within rel_tol |root| (by default a few
// ulps). Searches side by side (find_cycle_maxima) share each evaluation.
class BrentSearch {
 public:
  BrentSearch(double a, double b, double ga, double gb, int max_iter = 100, double rel_tol = 4.4e-16)
      : a_(a), b_(b), c_(a), ga_(ga), gb_(gb), gc_(ga), d_(b - a), e_(b - a), left_(max_iter), rel_tol_(rel_tol) {
    step();
  }
  bool done() const { return done_; }
  double x() const { return b_; }     // where g is wanted next
  double root() const { return b_; }  // once done()
  void feed(double g) {
    gb_ = g;
    if (--left_ == 0) done_ = true;
    else step();
  }

 private:
  // Brent's step: done_, or b_ moved to the next point to evaluate.
  void step() {
    if ((gb_ > 0) == (gc_ > 0)) { c_ = a_; gc_ = ga_; d_ = e_ = b_ - a_; }
    if (std::abs(gc_) < std::abs(gb_)) {
      a_ = b_; b_ = c_; c_ = a_;
      ga_ = gb_; gb_ = gc_; gc_ = ga_;
    }
    const double tol = rel_tol_ * std::abs(b_) + 1e-300;
    const double m = 0.5 * (c_ - b_);
    if (std::abs(m) <= tol || gb_ == 0.0 || left_ <= 0) {
      done_ = true;
      return;
    }
    if (std::abs(e_) >= tol && std::abs(ga_) > std::abs(gb_)) {
      double p, q, s = gb_ / ga_;
      if (a_ == c_) {
        p = 2.0 * m * s; q = 1.0 - s;
      } else {
        const double r = gb_ / gc_, t = ga_ / gc_;
        p = s * (2.0 * m * t * (t - r) - (b_ - a_) * (r - 1.0));
        q = (t - 1.0) * (r - 1.0) * (s - 1.0);
      }
      if (p > 0) q = -q; else p = -p;
      if (2.0 * p < std::min(3.0 * m * q - std::abs(tol * q), std::abs(e_ * q))) {
        e_ = d_; d_ = p / q;
      } else {
        d_ = m; e_ = m;
      }
    } else {
      d_ = m; e_ = m;
    }
    a_ = b_; ga_ = gb_;
    b_ += (std::abs(d_) > tol) ? d_ : (m > 0 ? tol : -tol);
  }
  double a_, b_, c_, ga_, gb_, gc_, d_, e_;
  int left_;  // evaluations still allowed
  double rel_tol_;
  bool done_ = false;
};

template <class G>
double brent_root(G&& g, double a, double b, double ga, double gb, int max_iter = 100, double rel_tol = 4.4e-16) {
  BrentSearch s(a, b, ga, gb, max_iter, rel_tol);
  while (!s.done()) s.feed(g(s.x()));
  return s.root();
}

// A root search for g on [a, b] (g(a), g(b) of opposite signs) that asks
// for up to kPoints values a step, so that searches side by side fill a
// model's kLanes: while !done(), feed it g at xs(). Each step interpolates
// x(g) at g = 0 through the (up to five) points seen with the smallest |g|
// (Lagrange's form; a third point beside the bracket may be given to start
// from) and asks for g at the estimate r and at r + d, d twice the change
// the farthest point made to r: g(r), near zero, anchors the next
// interpolation, and the bracket closes to [r, r + d] when the root lies
// right of r (asking r - d and r + d instead bracketed more often but took
// more steps). It ends when that
// change is within rel_tol |r| (at least four points interpolated) or the
// bracket is that narrow; where the bracket has not halved in two steps,
// the next asks for its thirds, so it ends like bisection where
// interpolation fails (a jump). From a grid cell of a smooth slope it
// typically takes two steps (Brent's search: five to six evaluations, one a
// step). The points it asks for depend only on its own bracket and answers,
// so searches run side by side give the answers they give alone.
class LaneRootSearch {
 public:
  static constexpr int kPoints = 2;
  LaneRootSearch() = default;  // storage for a search to come (Grow)
  LaneRootSearch(double a, double b, double ga, double gb, double x3 = NAN, double g3 = NAN,
                 double rel_tol = 4.4e-16)
      : rel_tol_(rel_tol) {
    if (a > b) std::swap(a, b), std::swap(ga, gb);
    a_ = {a, ga}, b_ = {b, gb};
    see(a_), see(b_);
    if (std::isfinite(g3) && g3 != 0) see({x3, g3});
    plan();
  }
  bool done() const { return done_; }
  std::span<const double> xs() const { return {xs_, static_cast<std::size_t>(asked_)}; }
  void feed(std::span<const double> g) {
    feed_each([&](int i) { return g[static_cast<std::size_t>(i)]; });
  }
  // The same, g at xs()[i] from g_at(i).
  template <class G>
  void feed_each(G&& g_at) {
    const double width = b_.x - a_.x;
    for (int i = 0; i < asked_; ++i) {
      const Point p{xs_[i], g_at(i)};
      if (p.g == 0) {
        done_ = true, root_ = p.x;
        return;
      }
      see(p);
      if (!(p.x > a_.x && p.x < b_.x)) continue;  // xs() ascend: past the first sign change
      ((p.g < 0) == (a_.g < 0) ? a_ : b_) = p;
    }
    slow_ = b_.x - a_.x > 0.5 * width_before_;  // over two steps
    width_before_ = width;
    ++steps_;
    plan();
  }
  double root() const { return root_; }

 private:
  struct Point {
    double x, g;
  };
  // Five points: a sixth made the interpolation dearer than the steps it
  // saved (3.5% of a recuperative design); the peaks agree with six points'
  // to roundoff.
  static constexpr int kUsed = 5, kMaxSteps = 60;
  // Keeps the kUsed points of smallest |g|, in that order.
  void see(Point p) {
    int i = std::min(seen_count_, kUsed - 1);
    if (seen_count_ == kUsed && std::abs(p.g) >= std::abs(seen_[i].g)) return;
    for (; i > 0 && std::abs(seen_[i - 1].g) > std::abs(p.g); --i) seen_[i] = seen_[i - 1];
    seen_[i] = p;
    seen_count_ = std::min(seen_count_ + 1, kUsed);
  }
  // x at g = 0 through seen_[0..m) and through seen_[0..m-1) (m >= 2),
  // Lagrange's form on offsets from seen_[0].x, in one pass: the weights of
  // the m points are those of the m - 1 over (g_last - g_i).
  // Unrolled for each m (the same operations in the same order).
  template <int M>
  std::pair<double, double> interpolate() const {
    const Point* p = seen_;
    const double last = p[M - 1].g;
    double all = 1, sum = 0, sum_less = 0;
    for (int i = 0; i + 1 < M; ++i) all *= p[i].g;
    for (int i = 1; i + 1 < M; ++i) {  // p[0] has offset 0
      double den = p[i].g;
      for (int j = 0; j + 1 < M; ++j)
        if (j != i) den *= p[j].g - p[i].g;
      const double to_last = last - p[i].g, t = (p[i].x - p[0].x) / (den * to_last);  // one division
      sum += t;
      sum_less += t * to_last;
    }
    double den = last;
    for (int j = 0; j + 1 < M; ++j) den *= p[j].g - last;
    sum += (p[M - 1].x - p[0].x) / den;
    return {p[0].x + all * last * sum, p[0].x + all * sum_less};
  }
  std::pair<double, double> interpolate(int m) const {
    static_assert(kUsed == 5);
    switch (m) {
      case 2: return interpolate<2>();
      case 3: return interpolate<3>();
      case 4: return interpolate<4>();
      default: return interpolate<5>();
    }
  }
  void plan() {
    const double tol = rel_tol_ * std::max(std::abs(a_.x), std::abs(b_.x)) + 1e-300;
    const double width = b_.x - a_.x;
    root_ = std::abs(a_.g) < std::abs(b_.g) ? a_.x : b_.x;
    if (width <= 2.5 * tol || steps_ >= kMaxSteps) {
      done_ = true;
      return;
    }
    asked_ = 0;
    const int m = seen_count_;
    auto [r, fewer] = interpolate(m);
    const double change = m > 2 ? std::abs(r - fewer) : width / 8;
    // A root at an end (its |g| at roundoff) puts r on it or just past it:
    // look just inside, as Brent's search steps by its tolerance there.
    if (r > a_.x - 0.25 * width && r < b_.x + 0.25 * width) r = std::clamp(r, a_.x + tol, b_.x - tol);
    if (r > a_.x && r < b_.x && std::isfinite(change)) {  // r is not NaN
      if (m >= 4 && change <= tol) {
        done_ = true, root_ = r;
        return;
      }
      if (!slow_) {
        const double d = std::max(2 * change, tol);
        for (double x : {r, r + d})
          if (x > a_.x && x < b_.x) xs_[asked_++] = x;
        if (asked_ == 0) xs_[asked_++] = r;
        return;
      }
    }
    xs_[asked_++] = a_.x + width / 3, xs_[asked_++] = b_.x - width / 3;
  }
  Point a_, b_;        // the bracket, a_.x < b_.x
  Point seen_[kUsed] = {};  // the points of smallest |g|, ascending
  int seen_count_ = 0;
  double xs_[kPoints];
  int asked_ = 0;
  double rel_tol_, root_ = 0;
  int steps_ = 0;
  double width_before_ = HUGE_VAL;  // the bracket's width a step earlier
  bool done_ = false, slow_ = false;
};

// Whether a slope going from ga to gb crosses + to - (a maximum between):
// 1 inside (a root search), 2 at the right end (gb = 0), 0 none.
inline int falls_through_zero(double ga, double gb) { return ga > 0 ? (gb < 0 ? 1 : gb == 0 ? 2 : 0) : 0; }

// + to - sign changes of df on [a, b] (df(a) = ga, df(b) = gb) split into
// `parts` equal pieces, each refined by Brent, appended to out.
template <class DF>
void sign_changes(DF&& df, double a, double b, double ga, double gb, int parts, std::vector<double>& out) {
  const double start = a;
  for (int i = 1; i <= parts; ++i) {
    const double x = i == parts ? b : start + (b - start) * i / parts, gx = i == parts ? gb : df(x);
    if (const int fall = falls_through_zero(ga, gx); fall == 1) out.push_back(brent_root(df, a, x, ga, gx));
    else if (fall == 2) out.push_back(x);
    a = x;
    ga = gx;
  }
}

// One evaluation a batched search asks for: f of search `fn` at the angle
// phi, or its angle derivative (slope); the evaluator writes `out`.
struct AngleQuery {
  double phi;
  int fn;
  bool slope;
  double out = 0;
};

// A list for the searches' working storage, kept by the thread: appending
// is inline (std::vector's emplace_back stayed a call in the model's
// translation unit, 6% of a recuperative DOE design) and the storage is
// never given back. T: default-constructible (the storage is made ahead)
// and copyable.
template <class T>
class Grow {
 public:
  void clear() { n_ = 0; }
  std::size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  T* begin() { return data_.data(); }
  T* end() { return data_.data() + n_; }
  const T* begin() const { return data_.data(); }
  const T* end() const { return data_.data() + n_; }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  operator std::span<T>() { return {begin(), n_}; }               // NOLINT: a view of the list
  operator std::span<const T>() const { return {begin(), n_}; }   // NOLINT
  MECH_FORCE_INLINE void push_back(const T& x) {
    if (n_ == room_) [[unlikely]] grow();
    data_[n_++] = x;
  }
  // Built in place (a root search: no copy of its ~200 bytes).
  template <class... A>
  MECH_FORCE_INLINE void emplace_back(A&&... a) {
    static_assert(std::is_trivially_destructible_v<T>);
    if (n_ == room_) [[unlikely]] grow();
    std::construct_at(&data_[n_++], std::forward<A>(a)...);
  }

 private:
  [[gnu::noinline]] void grow() {
    data_.resize(std::max<std::size_t>(16, 2 * data_.size()));
    room_ = data_.size();  // kept: data_.size() divides by sizeof(T) on every push
  }
  std::vector<T> data_;
  std::size_t n_ = 0, room_ = 0;
};

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

// The maxima over the cycle of a periodic f sampled as v[k] = f(2 pi k / n),
// found by find_cycle_maxima. `kinks`: the angles where f has kinks (a
// slider's dead centres for |M|); `slopes`: df on the grid, where the caller
// has it (its evaluations saved).
struct CycleMaxSearch {
  std::span<const double> v, kinks = {}, slopes = {};
  bool global = true;        // the global maximum; else every local one within `margin`
  double margin = HUGE_VAL;  // local ones: no lower than max(v) - margin
  std::vector<double> maxima;  // out: the refined local maxima, sorted by angle
  double phi = 0;              // out (global): the angle of the largest value
  double value = 0;            // out (global): f there, as eval answered it (or the grid's)

  // A global search of these inputs, the maxima's storage kept: a model
  // that searches every design keeps its searches per thread (an allocation
  // a search cost a DOE design 3%).
  void reset(std::span<const double> values, std::span<const double> kinks_of_f = {},
             std::span<const double> slopes_of_f = {}) {
    v = values, kinks = kinks_of_f, slopes = slopes_of_f;
    global = true, margin = HUGE_VAL;
    maxima.clear();
    phi = value = 0;
  }
};

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
// the grid point.
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
template <class Eval>
void find_cycle_maxima(std::span<CycleMaxSearch> searches, Eval&& eval) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Point {
    double x, g;
    int query = -1;     // g comes from this query
    bool kink = false;  // eps beside a kink (f's pieces part between two such points)
  };
  struct Candidate {
    int fn;
    double phi_k;
    int first, count;  // its points: phi_k -+ h, phi_k, and kink -+ eps
    int quarter = -1;  // the 4-part search's first query
  };
  struct Root {  // a maximum: known, or where a root search ends
    int fn;
    double phi;
    int search = -1;  // its root search, if any
  };
  struct Bracket {  // a cell beside a kink
    int fn;
    Point a, b;
  };
  // Working storage reused by every call on a thread (eval must not call
  // find_cycle_maxima): no allocation per design once warm.
  static thread_local Grow<AngleQuery> batch;
  static thread_local Grow<Point> points;
  static thread_local Grow<Candidate> cands;
  static thread_local Grow<Root> roots, beside_roots;
  static thread_local Grow<Bracket> beside;
  static thread_local Grow<int> kink_queries, root_fn, tops;
  static thread_local Grow<double> kink_f;
  static thread_local Grow<LaneRootSearch> roots_searched;
  points.clear(), cands.clear(), roots.clear(), beside_roots.clear(), beside.clear();
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
    auto at = [&](int i) { return v[static_cast<std::size_t>(i < 0 ? i + n : i >= n ? i - n : i)]; };  // -n <= i < 2n
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
    for (double& phi : m) phi = phi < 0 ? phi + kTwoPi : phi >= kTwoPi ? phi - kTwoPi : phi;
    if (m.size() == 2) {  // the usual count: no call
      if (m[1] < m[0]) std::swap(m[0], m[1]);
    } else {
      std::sort(m.begin(), m.end());
    }
    if (searches[fn].global)
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
    for (std::size_t i = 0; i < s.maxima.size(); ++i, ++q) consider(batch[q].phi, batch[q].out);
    for (double k : s.kinks) consider(k, kink_f[kink++]);
    for (std::size_t i = 0; i < beside_roots.size(); ++i)
      if (beside_roots[i].fn == static_cast<int>(fn)) consider(batch[beside_first + i].phi, batch[beside_first + i].out);
  }
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

// Nodes and weights of the m-point Gauss-Legendre rule on [-1, 1] (Newton on
// the Legendre recurrence; nodes to ~1e-16).
// The first `count` of them (all by default: x descending).
inline std::vector<std::pair<double, double>> compute_gauss_legendre(int m, int count = -1) {
  std::vector<std::pair<double, double>> nw(count < 0 ? m : count);
  for (int i = 0; i < static_cast<int>(nw.size()); ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (m + 0.5)), dp = 1;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= m; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = m * (x * p1 - p0) / (x * x - 1);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    nw[i] = {x, 2 / ((1 - x * x) * dp * dp)};
  }
  return nw;
}

// The m-point rule for 1 <= m <= kMaxGaussNodes, each computed on its first
// use (thread-safe): 128 nodes integrate an analytic arc to roundoff. The
// whole table at once took 7-10 ms, a third of a small `mechopt run`.
inline constexpr int kMaxGaussNodes = 128;
inline const std::vector<std::pair<double, double>>& gauss_legendre(int m) {
  static std::array<std::once_flag, kMaxGaussNodes + 1> once;
  static std::array<std::vector<std::pair<double, double>>, kMaxGaussNodes + 1> table;
  const auto k = static_cast<size_t>(std::clamp(m, 1, kMaxGaussNodes));
  std::call_once(once[k], [k] { table[k] = compute_gauss_legendre(static_cast<int>(k)); });
  return table[k];
}

// The m-point rule as piecewise_means uses it: its +-x pairs, the first
// (m+1)/2 nodes (x >= 0; odd m has x = 0 last among them, exactly 0 in
// `pairs`), the same bits as gauss_legendre(m)'s and half its work (a DOE's
// process computed ~10 ms of rules); `pairs` and `weights` kLanes at a time,
// the missing lanes of the last block 0.
struct GaussRule {
  int m = 0;
  std::vector<std::pair<double, double>> nodes;  // (x, w) on [-1, 1], the first (m+1)/2
  std::vector<Lanes> pairs, weights;
};
inline const GaussRule& gauss_rule(int m) {
  static std::array<std::once_flag, kMaxGaussNodes + 1> once;
  static std::array<GaussRule, kMaxGaussNodes + 1> table;
  // Each thread remembers the rules it has seen: call_once costs a design
  // of a DOE 2% even when the rule is long made.
  thread_local std::array<const GaussRule*, kMaxGaussNodes + 1> seen{};
  const auto k = static_cast<size_t>(std::clamp(m, 1, kMaxGaussNodes));
  if (seen[k]) return *seen[k];
  std::call_once(once[k], [k] {
    GaussRule& r = table[k];
    const std::size_t pairs = (k + 1) / 2;
    r.m = static_cast<int>(k);
    r.nodes = compute_gauss_legendre(r.m, static_cast<int>(pairs));
    for (std::size_t i = 0; i < pairs; i += kLanes) {
      Lanes x(0.0), w(0.0);
      for (std::size_t j = 0; j < kLanes && i + j < pairs; ++j)
        x[static_cast<int>(j)] = 2 * (i + j) + 1 == k ? 0.0 : r.nodes[i + j].first, w[static_cast<int>(j)] = r.nodes[i + j].second;
      r.pairs.push_back(x);
      r.weights.push_back(w);
    }
  });
  return *(seen[k] = &table[k]);
}

// Cycle means of a periodic f, of |f| and of f^2.
template <class S>
struct ArcMeans {
  S mean, mean_abs, mean_square;
};

// Cycle means when f is smooth between the angles `kinks` (its kinks, and its
// zeros for |f|): Gauss-Legendre on each arc with nodes in proportion to the
// arc's length (n per revolution, at least 12 per arc), so kinks cost no
// accuracy. f(phi, cos phi, sin phi) returns a scalar S (which may carry
// design derivatives); the arc ends are held fixed under differentiation,
// exact when f is continuous there (the Leibniz boundary terms of adjacent
// arcs cancel).
// mean_abs is right when `kinks` holds every sign change of f.
// An f that takes Lanes and returns the lane form of S (simd.hpp) gets
// kLanes nodes a call.
//
// `poles`: where f, smooth on the real line, has a singularity close to it,
// at phi +- i width (a four-bar near its toggle). On a panel of half-length
// h around mid, Gauss-Legendre with m nodes errs like rho^-2m, rho the
// Bernstein ellipse through the nearest pole: rho = |z + sqrt(z^2 - 1)| with
// z = (pole - mid) / h (Trefethen, Approximation Theory and Approximation
// Practice, ch. 19). Where the arc's nodes are too few for that, the arc is
// halved until each piece needs at most kMaxPanelNodes (pieces next to a
// pole come out graded toward it); each piece takes its nodes from rho or
// from the density n, whichever asks more.
struct NearPole {
  double phi, width;
};
inline constexpr double kPoleDigits = 22;  // ln of 1/(the error asked for) over 2, with a margin: rho^-2m <= ~1e-19
inline constexpr int kMaxPanelNodes = 32;

// Gauss-Legendre nodes the panel [mid - half, mid + half] needs for the
// poles (the copy of each nearest the panel); 0 if none is near, 10^6 if
// one is on the panel itself. rho is a +
// sqrt(a^2 - 1), a = (|z - 1| + |z + 1|) / 2 the semi-major axis of the
// ellipse with foci -1, 1 through z; poles beyond 8 half-lengths (rho > 8:
// 11 nodes at most) are skipped before that.
inline int nodes_for_poles(double mid, double half, std::span<const NearPole> poles) {
  double rho = HUGE_VAL;
  for (const NearPole& p : poles) {
    const double x = std::remainder(p.phi - mid, kTwoPi) / half, y = p.width / half;
    if (x * x + y * y >= 64) continue;
    const double a = 0.5 * (std::sqrt((x - 1) * (x - 1) + y * y) + std::sqrt((x + 1) * (x + 1) + y * y));
    rho = std::min(rho, a + std::sqrt(a * a - 1));
  }
  if (!(rho < HUGE_VAL)) return 0;
  return rho > 1 ? static_cast<int>(std::min(std::ceil(kPoleDigits / std::log(rho)), 1e6)) : 1000000;  // on the axis: no rule converges
}

// The Gauss panels of the arc [a, b]: visit(mid, half length, nodes). Nodes
// in proportion to the arc (n per revolution, at least 12; more than the
// table's kMaxGaussNodes cut into equal panels: near the dead point an arc
// may need thousands), unless the poles ask for more: then halved as above.
template <class Visit>
void for_each_panel(double a, double b, int n, std::span<const NearPole> poles, Visit&& visit) {
  const int m = std::max(12, static_cast<int>(std::ceil(n * (b - a) / kTwoPi)));
  if (nodes_for_poles(0.5 * (a + b), 0.5 * (b - a), poles) > m) {
    auto piece = [&](auto&& self, double lo, double hi) -> void {
      const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
      const int k = std::max({4, nodes_for_poles(mid, half, poles), static_cast<int>(std::ceil(n * (hi - lo) / kTwoPi))});
      // A pole on the real axis (a model at its singularity) asks for ever
      // more: pieces stop at 1e-9 of a revolution, 30 halvings.
      if (k <= kMaxPanelNodes || half < 1e-9 * kTwoPi) return visit(mid, half, std::min(k, kMaxPanelNodes));
      self(self, lo, mid), self(self, mid, hi);
    };
    return piece(piece, a, b);
  }
  const int panels = (m + kMaxGaussNodes - 1) / kMaxGaussNodes;
  const double half = 0.5 * (b - a) / panels;
  for (int p = 0; p < panels; ++p) visit(a + (2 * p + 1) * half, half, (m + panels - 1) / panels);
}

template <class S, class F>
ArcMeans<S> piecewise_means(F&& f, const std::vector<double>& kinks, int n, std::span<const NearPole> poles = {}) {
  constexpr bool kLanesOfF = [] {
    if constexpr (has_lanes<S>) return std::is_invocable_r_v<lanes_of<S>, F&, Lanes, Lanes, Lanes>;
    return false;
  }();
  static thread_local std::vector<double> ends;  // sorted; no allocation per call once warm
  ends.assign(kinks.begin(), kinks.end());
  std::sort(ends.begin(), ends.end());
  if (ends.empty()) ends.push_back(0.0);
  ArcMeans<S> out{S(0.0), S(0.0), S(0.0)};
  for (size_t j = 0; j < ends.size(); ++j) {
    const double a = ends[j], b = j + 1 < ends.size() ? ends[j + 1] : ends[0] + kTwoPi;
    if (b - a <= 0) continue;
    S arc(0.0);
    for_each_panel(a, b, n, poles, [&](double mid, double half, int panel_nodes) {
      const GaussRule& rule = gauss_rule(panel_nodes);
      const auto& nodes = rule.nodes;
      const auto k = static_cast<std::size_t>(rule.m);
      if constexpr (kLanesOfF) {
        // The nodes are +-x pairs (the table's first (k+1)/2 hold x >= 0;
        // odd k has x = 0 last among them): one sincos of t = half x, kLanes
        // pairs at a time, gives mid + t and mid - t by the angle sum. The
        // nodes are packed in order into blocks of kLanes for f; the last
        // block's missing lanes weigh 0.
        using L = lanes_of<S>;
        using Raw = Lanes::Raw;
        constexpr std::size_t kRoom = kMaxGaussNodes + 2 * kLanes;
        alignas(sizeof(Raw)) double node_c[kRoom], node_s[kRoom], node_phi[kRoom], node_w[kRoom];
        auto put = [](double* to, const Lanes& v) { std::memcpy(to, &v.v, sizeof(Raw)); };
        auto get = [](const double* from) {
          Lanes v;
          std::memcpy(&v.v, from, sizeof(Raw));
          return v;
        };
        const std::size_t pairs = (k + 1) / 2;
        double cos_mid, sin_mid;
        sincos(mid, sin_mid, cos_mid);
        const Lanes cm(cos_mid), sm(sin_mid);
        const bool small = half < 0.78;  // every |t| < pi/4: sincos without its reduction
        std::size_t count = 0;
        for (std::size_t i = 0; i < pairs; i += kLanes) {
          const std::size_t valid = std::min<std::size_t>(kLanes, pairs - i);
          const Lanes t = half * rule.pairs[i / kLanes], weight = rule.weights[i / kLanes];
          Lanes ct, st;
          if (small) sincos_small(t, st, ct);
          else sincos(t, st, ct);
          put(node_c + count, cm * ct - sm * st), put(node_s + count, sm * ct + cm * st);
          put(node_phi + count, mid + t), put(node_w + count, weight);
          count += valid;
          const std::size_t minus = 2 * (i + valid) - 1 == k ? valid - 1 : valid;  // not the centre twice
          put(node_c + count, cm * ct + sm * st), put(node_s + count, sm * ct - cm * st);
          put(node_phi + count, mid - t), put(node_w + count, weight);
          count += minus;
        }
        // The last block's missing lanes: weight 0 at a valid angle (mid).
        put(node_c + count, cm), put(node_s + count, sm), put(node_phi + count, Lanes(mid));
        put(node_w + count, Lanes(0.0));
        L sum_v(0.0), sum_v2(0.0);
        for (std::size_t i = 0; i < count; i += kLanes) {
          const L v = f(get(node_phi + i), get(node_c + i), get(node_s + i));
          const L weight(get(node_w + i));
          sum_v += weight * v;
          sum_v2 += weight * v * v;
        }
        arc += half * LaneForm<S>::sum(sum_v);
        out.mean_square += half * LaneForm<S>::sum(sum_v2);
      } else {
        auto add = [&](const S& v, double weight) {
          arc += weight * v;
          out.mean_square += weight * v * v;
        };
        const double cm = std::cos(mid), sm = std::sin(mid);
        // The nodes are +-x pairs (the table's first half holds x > 0; odd k
        // has x = 0 in the middle): cos and sin of mid +- half x come from
        // one cos and sin of half x.
        for (std::size_t i = 0; i < (k + 1) / 2; ++i) {
          const bool centre = 2 * i + 1 == k;
          const double t = centre ? 0.0 : half * nodes[i].first, ct = std::cos(t), st = std::sin(t);
          const double weight = nodes[i].second * half;
          add(f(mid + t, cm * ct - sm * st, sm * ct + cm * st), weight);
          if (!centre) add(f(mid - t, cm * ct + sm * st, sm * ct - cm * st), weight);
        }
      }
    });
    out.mean += arc;
    out.mean_abs += value(arc) >= 0 ? arc : S(-arc);
  }
  out.mean /= kTwoPi;
  out.mean_abs /= kTwoPi;
  out.mean_square /= kTwoPi;
  return out;
}

// Sign changes of periodic functions g_0, g_1, ... given their samples on
// grids (grids[f][k] = g_f(2 pi k / n_f)), refined by root searches side
// by side: eval(std::span<AngleQuery>) writes g_fn(phi) into each query's
// out. The angles in [0, 2 pi) where each crosses zero, g_0's first, each
// function's by grid cell.
template <class Eval>
std::vector<double> periodic_roots_together(std::span<const std::span<const double>> grids, Eval&& eval) {
  std::vector<double> roots;
  std::vector<LaneRootSearch> searches;
  std::vector<int> fn;
  std::vector<std::size_t> slot;  // the root each search ends in
  for (std::size_t f = 0; f < grids.size(); ++f) {
    const auto& v = grids[f];
    const int n = static_cast<int>(v.size());
    const double h = kTwoPi / n;
    for (int k = 0; k < n; ++k) {
      const double ga = v[k], gb = v[k + 1 == n ? 0 : k + 1];
      if (ga == 0.0) {
        roots.push_back(k * h);
      } else if ((ga < 0) != (gb < 0) && gb != 0.0) {
        slot.push_back(roots.size());
        roots.push_back(0.0);
        // The grid point beside the end nearer zero, to start from.
        const int beside = std::abs(ga) <= std::abs(gb) ? k - 1 : k + 2;
        searches.emplace_back(k * h, (k + 1) * h, ga, gb, beside * h, v[(beside + n) % n]);
        fn.push_back(static_cast<int>(f));
      }
    }
  }
  Grow<AngleQuery> batch;
  run_side_by_side(searches, fn, false, batch, eval);
  for (std::size_t i = 0; i < searches.size(); ++i) roots[slot[i]] = searches[i].root();
  return roots;
}

// The same for one function g, evaluated one angle at a time.
template <class G>
std::vector<double> periodic_roots(const std::vector<double>& v, G&& g) {
  const std::span<const double> grid[1] = {v};
  return periodic_roots_together(std::span(grid), [&](std::span<AngleQuery> qs) {
    for (AngleQuery& q : qs) q.out = g(q.phi);
  });
}

}  // namespace mech
