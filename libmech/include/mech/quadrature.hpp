// Cycle means of a periodic function by Gauss-Legendre quadrature on the
// arcs between its kinks: the rules (each computed once, on first use), the
// panels an arc is cut into for singularities near the real axis, and
// piecewise_means, which takes a scalar or kLanes nodes a call.
#pragma once
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <mutex>
#include <numbers>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "mech/angles.hpp"
#include "mech/autodiff.hpp"
#include "mech/cycle_scratch.hpp"
#include "mech/simd.hpp"

namespace mech {

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
// Made once per m for the process: a reader loads the rule's pointer
// (acquire: a plain load on x86); only a miss takes the lock (call_once on
// every read cost a design of a DOE 2%).
inline const GaussRule& gauss_rule(int m) {
  static std::array<std::atomic<const GaussRule*>, kMaxGaussNodes + 1> made{};
  static std::array<GaussRule, kMaxGaussNodes + 1> table;
  static std::mutex making;
  const auto k = static_cast<size_t>(std::clamp(m, 1, kMaxGaussNodes));
  if (const GaussRule* r = made[k].load(std::memory_order_acquire)) [[likely]] return *r;
  const std::lock_guard lock(making);
  if (const GaussRule* r = made[k].load(std::memory_order_relaxed)) return *r;
  {
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
  }
  made[k].store(&table[k], std::memory_order_release);
  return table[k];
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

// `scratch`: its ends are the arcs' (no allocation per call once warm).
template <class S, class F>
ArcMeans<S> piecewise_means(F&& f, const std::vector<double>& kinks, int n, CycleScratch& scratch,
                            std::span<const NearPole> poles = {}) {
  constexpr bool kLanesOfF = [] {
    if constexpr (has_lanes<S>) return std::is_invocable_r_v<lanes_of<S>, F&, Lanes, Lanes, Lanes>;
    return false;
  }();
  std::vector<double>& ends = scratch.ends;  // sorted
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
          const S wv = S(weight * v);
          arc += wv;
          out.mean_square += S(wv * v);
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

// The same with scratch of its own (tests).
template <class S, class F>
ArcMeans<S> piecewise_means(F&& f, const std::vector<double>& kinks, int n, std::span<const NearPole> poles = {}) {
  CycleScratch scratch;
  return piecewise_means<S>(f, kinks, n, scratch, poles);
}

}  // namespace mech
