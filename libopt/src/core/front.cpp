#include "opt/front.hpp"

#include <algorithm>
#include <cmath>

namespace opt {

std::vector<std::size_t> non_dominated(const std::vector<Objectives>& points) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!std::isnan(points[i][0]) && !std::isnan(points[i][1])) order.push_back(i);
  // By the first objective, then the second: a point is dominated exactly
  // when an earlier one has a second objective no greater than its own.
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return points[a] < points[b]; });
  std::vector<std::size_t> kept;
  for (const std::size_t i : order)
    if (kept.empty() || points[i][1] < points[kept.back()][1]) kept.push_back(i);
  return kept;
}

double hypervolume(const std::vector<Objectives>& points, const Objectives& reference) {
  std::vector<Objectives> inside;
  for (const auto& f : points)
    if (f[0] < reference[0] && f[1] < reference[1]) inside.push_back(f);
  double area = 0, ceiling = reference[1];  // the lowest second objective so far
  for (const std::size_t i : non_dominated(inside)) {
    area += (reference[0] - inside[i][0]) * (ceiling - inside[i][1]);
    ceiling = inside[i][1];
  }
  return area;
}

double normalised_hypervolume(const std::vector<Objectives>& points, const Normalisation& n) {
  std::vector<Objectives> scaled;
  scaled.reserve(points.size());
  for (const auto& f : points) scaled.push_back(n(f));
  return hypervolume(scaled, kHypervolumeReference);
}

}  // namespace opt
