// The angles where periodic functions cross zero: sign changes on their
// grids, refined by root searches side by side (run_side_by_side of
// cycle_maxima.hpp asks for their values in batches of AngleQuery).
#pragma once
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

#include "mech/angles.hpp"
#include "mech/cycle_maxima.hpp"
#include "mech/grow.hpp"
#include "mech/roots.hpp"

namespace mech {

// Sign changes of periodic functions g_0, g_1, ... given their samples on
// grids (grids[f][k] = g_f(2 pi k / n_f)), refined by root searches side
// by side: eval(std::span<AngleQuery>) writes g_fn(phi) into each query's
// out. The angles in [0, 2 pi) where each crosses zero, g_0's first, each
// function's by grid cell; `owner`, where given: each root's function.
template <class Eval>
std::vector<double> periodic_roots_together(std::span<const std::span<const double>> grids, Eval&& eval,
                                            std::vector<int>* owner = nullptr) {
  std::vector<double> roots;
  std::vector<LaneRootSearch> searches;
  std::vector<int> fn;
  std::vector<std::size_t> slot;  // the root each search ends in
  if (owner) owner->clear();
  for (std::size_t f = 0; f < grids.size(); ++f) {
    const auto& v = grids[f];
    const int n = static_cast<int>(v.size());
    const double h = kTwoPi / n;
    for (int k = 0; k < n; ++k) {
      const double ga = v[k], gb = v[k + 1 == n ? 0 : k + 1];
      if (ga == 0.0 || ((ga < 0) != (gb < 0) && gb != 0.0))
        if (owner) owner->push_back(static_cast<int>(f));
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
