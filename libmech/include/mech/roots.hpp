// Root searches for g on a bracket [a, b] where g changes sign: Brent's
// (one value at a time) and LaneRootSearch (up to kPoints values a step, so
// that searches side by side fill a model's lanes), and the + to - sign
// changes of a slope on an interval.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

namespace mech {

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

}  // namespace mech
