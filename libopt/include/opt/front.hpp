// Two-objective fronts, both objectives minimised: the non-dominated points
// of a set and the hypervolume they dominate, the measure that compares an
// epsilon-constraint front with an evolutionary one (studies/pareto.cpp).
#pragma once
#include <array>
#include <vector>

namespace opt {

using Objectives = std::array<double, 2>;

// The indices of the points no other point dominates (a point dominates
// another when it is no worse in both objectives and better in one), in
// increasing first objective; of equal points the first is kept. Points
// with a NaN are left out.
std::vector<std::size_t> non_dominated(const std::vector<Objectives>& points);

// The area dominated by `points` and bounded by `reference`: the union of
// the boxes [f, reference] over the points that lie below the reference in
// both objectives (the others add nothing).
double hypervolume(const std::vector<Objectives>& points, const Objectives& reference);

// Objectives scaled so that `ideal` maps to (0, 0) and `nadir` to (1, 1):
// the front's two ends (the single-objective optima) fix both, so fronts of
// different methods are measured against one reference point, (1.1, 1.1).
struct Normalisation {
  Objectives ideal, nadir;
  Objectives operator()(const Objectives& f) const {
    return {(f[0] - ideal[0]) / (nadir[0] - ideal[0]), (f[1] - ideal[1]) / (nadir[1] - ideal[1])};
  }
};
constexpr Objectives kHypervolumeReference{1.1, 1.1};

// The hypervolume of `points` normalised by n, against kHypervolumeReference.
double normalised_hypervolume(const std::vector<Objectives>& points, const Normalisation& n);

}  // namespace opt
