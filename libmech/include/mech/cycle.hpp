// Cycle quantities of a 2*pi-periodic function of the crank angle.
// Means use the periodic trapezoidal rule (exponentially convergent for smooth
// periodic integrands); maxima are bracketed on the grid and refined to machine
// precision by Brent's root finder on the angle derivative.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mech/autodiff.hpp"
#include "mech/simd.hpp"

namespace mech {

inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

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
  if (n > 512) return nullptr;
  static thread_local std::unordered_map<int, GridTable> tables;
  GridTable& t = tables[n];
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
// signs; returns the root to within rel_tol |root| (by default a few ulps).
template <class G>
double brent_root(G&& g, double a, double b, double ga, double gb, int max_iter = 100, double rel_tol = 4.4e-16) {
  double c = a, gc = ga, d = b - a, e = d;
  for (int it = 0; it < max_iter; ++it) {
    if ((gb > 0) == (gc > 0)) { c = a; gc = ga; d = e = b - a; }
    if (std::abs(gc) < std::abs(gb)) {
      a = b; b = c; c = a;
      ga = gb; gb = gc; gc = ga;
    }
    const double tol = rel_tol * std::abs(b) + 1e-300;
    const double m = 0.5 * (c - b);
    if (std::abs(m) <= tol || gb == 0.0) return b;
    if (std::abs(e) >= tol && std::abs(ga) > std::abs(gb)) {
      double p, q, s = gb / ga;
      if (a == c) {
        p = 2.0 * m * s; q = 1.0 - s;
      } else {
        const double r = gb / gc, t = ga / gc;
        p = s * (2.0 * m * t * (t - r) - (b - a) * (r - 1.0));
        q = (t - 1.0) * (r - 1.0) * (s - 1.0);
      }
      if (p > 0) q = -q; else p = -p;
      if (2.0 * p < std::min(3.0 * m * q - std::abs(tol * q), std::abs(e * q))) {
        e = d; d = p / q;
      } else {
        d = m; e = m;
      }
    } else {
      d = m; e = m;
    }
    a = b; ga = gb;
    b += (std::abs(d) > tol) ? d : (m > 0 ? tol : -tol);
    gb = g(b);
  }
  return b;
}

// + to - sign changes of df on [a, b] (df(a) = ga, df(b) = gb) split into
// `parts` equal pieces, each refined by Brent, appended to out.
template <class DF>
void sign_changes(DF&& df, double a, double b, double ga, double gb, int parts, std::vector<double>& out) {
  for (int i = 1; i <= parts; ++i) {
    const double x = i == parts ? b : a + (b - a) * i / parts, gx = i == parts ? gb : df(x);
    if (ga > 0 && gx < 0) out.push_back(brent_root(df, a, x, ga, gx));
    else if (ga > 0 && gx == 0) out.push_back(x);
    a = x;
    ga = gx;
  }
}

// Angles of the maxima of a periodic f within one grid step h of the grid
// point phi_k, given its derivative df: the + to - sign changes of df on
// both sides of phi_k, each side cut at the kinks of f inside it (where df
// jumps: a kink may part two maxima, or be one). Where nothing shows (two
// maxima closer than a step), each piece is searched again in 4 parts.
// None found: phi_k. `slopes`, when given, holds df at phi_k - h, phi_k and
// phi_k + h (the grid's own derivative values: three evaluations saved).
template <class DF>
void refine_max(DF&& df, double phi_k, double h, const std::vector<double>& kinks, std::vector<double>& out,
                const double* slopes = nullptr) {
  const std::size_t before = out.size();
  const double unknown = std::numeric_limits<double>::quiet_NaN();
  static thread_local std::vector<std::pair<double, double>> xg;  // (angle, df there): no allocation per call
  xg.assign({{phi_k - h, slopes ? slopes[0] : unknown},
             {phi_k, slopes ? slopes[1] : unknown},
             {phi_k + h, slopes ? slopes[2] : unknown}});
  const double eps = 1e-9 * h;  // either side of a kink: its one-sided slopes
  for (double kink : kinks) {
    const double k = kink + kTwoPi * std::round((phi_k - kink) / kTwoPi);  // the copy nearest phi_k
    if (k - eps > phi_k - h && k + eps < phi_k + h) xg.insert(xg.end(), {{k - eps, unknown}, {k + eps, unknown}});
  }
  std::sort(xg.begin(), xg.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& [x, g] : xg)
    if (std::isnan(g)) g = df(x);
  for (int parts : {1, 4}) {
    for (std::size_t i = 0; i + 1 < xg.size(); ++i)
      sign_changes(df, xg[i].first, xg[i + 1].first, xg[i].second, xg[i + 1].second, parts, out);
    if (out.size() > before) return;
  }
  out.push_back(phi_k);
}

// Refined angles of the local maxima of a periodic f sampled as
// v[k] = f(2 pi k / n), given its derivative df and f's kinks: the maxima
// near every grid local maximum no lower than max(v) - margin, sorted by
// angle. `slopes`, when not empty, holds df on the same grid.
template <class DF>
std::vector<double> local_max_angles(const std::vector<double>& v, DF&& df, double margin = HUGE_VAL,
                                     const std::vector<double>& kinks = {}, const std::vector<double>& slopes = {}) {
  const int n = static_cast<int>(v.size());
  const double h = kTwoPi / n, vmax = *std::max_element(v.begin(), v.end());
  std::vector<double> out;
  for (int k = 0; k < n; ++k) {
    const int before = k == 0 ? n - 1 : k - 1, after = k + 1 == n ? 0 : k + 1;  // no division per point
    const double prev = v[before], next = v[after];
    if (v[k] < prev || v[k] < next || v[k] < vmax - margin) continue;
    if (next == v[k] && k + 1 < n) continue;  // a flat top: refine it once
    const double around[3] = {slopes.empty() ? 0.0 : slopes[before], slopes.empty() ? 0.0 : slopes[k],
                              slopes.empty() ? 0.0 : slopes[after]};
    refine_max(df, k * h, h, kinks, out, slopes.empty() ? nullptr : around);
  }
  for (double& phi : out) phi = phi < 0 ? phi + kTwoPi : phi >= kTwoPi ? phi - kTwoPi : phi;
  std::sort(out.begin(), out.end());
  return out;
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

// Angle of the global maximum of a periodic f sampled as v[k] = f(2 pi k / n),
// given f and its derivative df. Two nearly equal peaks can swap order between
// the grid and the truth, so every grid local maximum that could be the
// highest is refined and the largest kept. A peak lies at most h^2 |f''| / 8
// above its best grid value; |f''| h^2 is estimated by the largest second
// difference, and peaks more than twice that bound below the grid maximum are
// skipped. `kinks` are the angles where f has kinks (a slider's dead centres
// for |M|): they cut the searches and are candidates themselves, as is the
// best grid point, so the answer is never below a value the grid has seen.
// `slopes` (optional): df on the grid, where the caller has it.
template <class F, class DF>
double global_max_angle(const std::vector<double>& v, F&& f, DF&& df, const std::vector<double>& kinks = {},
                        const std::vector<double>& slopes = {}) {
  const int n = static_cast<int>(v.size());
  double curvature = 0;
  for (int k = 0; k < n; ++k)
    curvature = std::max(curvature, std::abs(v[k + 1 == n ? 0 : k + 1] - 2 * v[k] + v[k == 0 ? n - 1 : k - 1]));
  const auto top = std::max_element(v.begin(), v.end());
  double best_phi = kTwoPi * static_cast<double>(top - v.begin()) / n, best = *top;
  auto consider = [&](double phi) {
    if (const double fv = f(phi); fv > best) best = fv, best_phi = phi;
  };
  const double margin = 0.25 * curvature, h = kTwoPi / n, eps = 1e-9 * h;
  for (double phi : local_max_angles(v, df, margin, kinks, slopes)) consider(phi);
  // A smooth maximum beside a kink need not show on the grid as a local
  // maximum (the grid point past the kink may be higher): where the grid
  // rises into a kink, search the two cells before it (or after it).
  std::vector<double> beside;
  for (double kink : kinks) {
    consider(kink);
    const int j = static_cast<int>(std::floor(kink / h));  // grid points j <= kink < j + 1
    auto at = [&](int i) { return v[static_cast<std::size_t>(((i % n) + n) % n)]; };
    if (std::max(at(j), at(j + 1)) < *top - margin) continue;
    if (at(j) > at(j - 1)) sign_changes(df, (j - 1) * h, kink - eps, df((j - 1) * h), df(kink - eps), 1, beside);
    if (at(j + 1) > at(j + 2)) sign_changes(df, kink + eps, (j + 2) * h, df(kink + eps), df((j + 2) * h), 1, beside);
  }
  for (double phi : beside) consider(phi);
  return best_phi;
}

// Nodes and weights of the m-point Gauss-Legendre rule on [-1, 1] (Newton on
// the Legendre recurrence; nodes to ~1e-16).
inline std::vector<std::pair<double, double>> compute_gauss_legendre(int m) {
  std::vector<std::pair<double, double>> nw(m);
  for (int i = 0; i < m; ++i) {
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

// The m-point rule for 1 <= m <= kMaxGaussNodes, tabulated once (thread-safe
// static): 128 nodes integrate an analytic arc to roundoff.
inline constexpr int kMaxGaussNodes = 128;
inline const std::vector<std::pair<double, double>>& gauss_legendre(int m) {
  static const auto table = [] {
    std::vector<std::vector<std::pair<double, double>>> t(kMaxGaussNodes + 1);
    for (int k = 1; k <= kMaxGaussNodes; ++k) t[k] = compute_gauss_legendre(k);
    return t;
  }();
  return table[std::clamp(m, 1, kMaxGaussNodes)];
}

// Cycle means of a periodic f, of |f| and of f^2.
template <class S>
struct ArcMeans {
  S mean, mean_abs, mean_square;
};

// Cycle means when f is smooth between the angles `ends` (its kinks, and its
// zeros for |f|): Gauss-Legendre on each arc with nodes in proportion to the
// arc's length (n per revolution, at least 12 per arc), so kinks cost no
// accuracy. f(phi, cos phi, sin phi) returns a scalar S (which may carry
// design derivatives); the arc ends are held fixed under differentiation,
// exact when f is continuous there (the Leibniz boundary terms of adjacent
// arcs cancel).
// mean_abs is right when `ends` holds every sign change of f.
// An f that takes Lanes and returns the lane form of S (simd.hpp) gets
// kLanes nodes a call.
template <class S, class F>
ArcMeans<S> piecewise_means(F&& f, std::vector<double> ends, int n) {
  constexpr bool kLanesOfF = [] {
    if constexpr (has_lanes<S>) return std::is_invocable_r_v<lanes_of<S>, F&, Lanes, Lanes, Lanes>;
    return false;
  }();
  std::sort(ends.begin(), ends.end());
  if (ends.empty()) ends.push_back(0.0);
  ArcMeans<S> out{S(0.0), S(0.0), S(0.0)};
  for (size_t j = 0; j < ends.size(); ++j) {
    const double a = ends[j], b = j + 1 < ends.size() ? ends[j + 1] : ends[0] + kTwoPi;
    if (b - a <= 0) continue;
    // Nodes in proportion to the arc; an arc needing more than the table's
    // kMaxGaussNodes is cut into equal panels (near the dead point an arc
    // may need thousands).
    const int m = std::max(12, static_cast<int>(std::ceil(n * (b - a) / kTwoPi)));
    const int panels = (m + kMaxGaussNodes - 1) / kMaxGaussNodes;
    const double half = 0.5 * (b - a) / panels;
    S arc(0.0);
    for (int p = 0; p < panels; ++p) {
      const double mid = a + (2 * p + 1) * half;
      const auto& nodes = gauss_legendre((m + panels - 1) / panels);
      const std::size_t k = nodes.size();
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
        std::size_t count = 0;
        for (std::size_t i = 0; i < pairs; i += kLanes) {
          const std::size_t valid = std::min<std::size_t>(kLanes, pairs - i);
          Lanes t, weight, ct, st;
          for (std::size_t j = 0; j < valid; ++j)
            t[j] = 2 * (i + j) + 1 == k ? 0.0 : half * nodes[i + j].first, weight[j] = nodes[i + j].second;
          sincos(t, st, ct);
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
    }
    out.mean += arc;
    out.mean_abs += value(arc) >= 0 ? arc : S(-arc);
  }
  out.mean /= kTwoPi;
  out.mean_abs /= kTwoPi;
  out.mean_square /= kTwoPi;
  return out;
}

// Sign changes of a periodic g given its samples v[k] = g(2 pi k / n),
// refined by Brent: the angles in [0, 2 pi) where g crosses zero.
template <class G>
std::vector<double> periodic_roots(const std::vector<double>& v, G&& g) {
  std::vector<double> roots;
  const int n = static_cast<int>(v.size());
  const double h = kTwoPi / n;
  for (int k = 0; k < n; ++k) {
    const double ga = v[k], gb = v[(k + 1) % n];
    if (ga == 0.0) roots.push_back(k * h);
    else if ((ga < 0) != (gb < 0) && gb != 0.0) roots.push_back(brent_root(g, k * h, (k + 1) * h, ga, gb));
  }
  return roots;
}

}  // namespace mech
