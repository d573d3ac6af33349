// Angles of the crank cycle: 2 pi, rounding and wrapping into [0, 2 pi), and
// the n-point grid phi_k = 2 pi k / n with cos and sin of its angles, one
// at a time by rotation or kLanes at a time from tables made once.
#pragma once
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <mutex>
#include <numbers>
#include <vector>

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
// per n for the process for n up to 512 (nullptr beyond: such a design's
// cycle costs far more than its sincos). All tables together stay under 2.1
// MB (every n from 4 to 512), however many designs and threads a batch runs.
// A reader loads the table's pointer (acquire: a plain load on x86, no
// hashing per evaluation); only a miss takes the lock.
struct GridTable {
  std::vector<Lanes> c, s;
};
inline const GridTable* grid_table(int n) {
  constexpr int kMost = 512;
  if (n > kMost || n < 1) return nullptr;
  static std::array<std::atomic<const GridTable*>, kMost + 1> made{};  // by n
  static std::array<GridTable, kMost + 1> tables;
  static std::mutex making;
  const auto i = static_cast<std::size_t>(n);
  if (const GridTable* t = made[i].load(std::memory_order_acquire)) [[likely]] return t;
  const std::lock_guard lock(making);
  if (const GridTable* t = made[i].load(std::memory_order_relaxed)) return t;
  GridTable& t = tables[i];
  for (int k = 0; k < n; k += kLanes) {
    Lanes c, s;
    sincos(iota(k) * kTwoPi / n, s, c);
    t.c.push_back(c);
    t.s.push_back(s);
  }
  made[i].store(&t, std::memory_order_release);
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

}  // namespace mech
