// The checks of a run that met its tolerance (stationarity.cpp): is the
// answer an optimum, or did the optimiser stop on a kink, a plateau or a
// slope? Every driver's final report asks them (driver.cpp, detail::finish).
#pragma once
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "opt/problem.hpp"

namespace opt {

// Where the objective, a maximum over the crank cycle (Problem::local_maxima),
// has two or more peaks within 1e-6 (relative) of each other at x: how far x
// is from first-order (Clarke) stationarity. `measure` is the distance from
// 0 to the convex hull of the peaks' gradients plus the cone of the active
// bounds' and constraints' gradients (variables scaled by their ranges),
// over the largest peak gradient: 0 at an optimum, of order 1 where the
// optimiser stopped on the kink with a descent direction left. None where
// the objective has fewer equal peaks, is maximised, or cannot be checked.
struct KinkCheck {
  int peaks = 0;
  double measure = 0;
};
std::optional<KinkCheck> check_kink(const Problem& problem, const Objective& objective,
                                    const std::vector<Constraint>& constraints, const Eigen::VectorXd& x);
// A converged run whose check_kink measure exceeds this ends as stopped_on_kink.
inline constexpr double kKinkTolerance = 1e-3;

// The same measure for any objective at a design x that meets every
// constraint (the pieces: the equal peaks of a minimised maximum over the
// cycle, else the objective's gradient): 0 at a KKT point. None where x
// breaks a constraint, cannot be evaluated, or the problem has no
// gradients. NLopt's local gradient algorithms that stop with
// ROUNDOFF_LIMITED where it is at most kKktTolerance have converged.
std::optional<double> kkt_measure(const Problem& problem, const Objective& objective,
                                  const std::vector<Constraint>& constraints, const Eigen::VectorXd& x);
inline constexpr double kKktTolerance = 1e-6;

// Around x, each variable moved by kPlateauStep of its range (or of its
// size where unbounded) either way, inside its bounds, with the others
// held: the variables along which the objective f (its value at x) does not
// change by more than kPlateauChange of its size. An optimiser without
// derivatives reads a plateau as convergence: its steps shrink because
// nothing they try is better, not because it stands at an optimum (a model
// whose level of detail ignores the variables, an objective clipped to a
// constant). At a smooth optimum each move changes f by about
// f'' (range kPlateauStep)^2 / 2, far above kPlateauChange unless f varies
// by less than ~1e-6 over a variable's whole range. Probes the model cannot
// evaluate do not count as flat.
inline constexpr double kPlateauStep = 1e-3, kPlateauChange = 1e-12;
std::vector<int> flat_variables(const Problem& problem, const Objective& objective, const Eigen::VectorXd& x,
                                double f);

// Where a local run met its tolerance at x (objective value f): is x a
// first-order (KKT) point, or does the objective still fall along a
// direction the bounds and constraints allow? From the gradients at x
// (at_x, when it holds them at x, saves the evaluation): r, the objective's
// gradient less the nearest combination of the active bounds' and
// constraints' gradients (variables scaled by their ranges), is 0 at a KKT
// point. For a maximum over the cycle the objective's gradient is the
// nearest point of the hull of the gradients of the peaks the step could
// lift to the top (a kink where no direction lowers them all has r = 0).
// The step: kSlopeStep of the ranges, or less where that would change f by
// more than kSlopeReach |f| to first order. Where r promises a fall of more
// than kSlopeChange |f|, the step (and a tenth of it) along -r is
// evaluated, pulled back onto the equalities and onto the active
// inequalities it overran (Gauss-Newton with their Jacobian at x); a
// constraint the probe breaks is held from then on and r recomputed. A
// probe that meets every constraint and is lower by more than
// kSlopeChange |f| is returned (its step and value). An optimiser that
// converged to its tolerance at a local optimum is within ~step / 2 of it,
// so the step cannot improve on it; one that stalled (LD_MMA on a maximum
// over the cycle that barely moves one variable) is caught. None where x
// passes, the problem has no gradients, or more than 12 pieces and held
// bounds and constraints would need checking.
struct SlopeCheck {
  double step = 0;   // fraction of the variables' ranges
  double value = 0;  // the objective at the step
};
inline constexpr double kSlopeStep = 1e-2, kSlopeReach = 1e-2, kSlopeChange = 1e-4;
std::optional<SlopeCheck> check_slope(const Problem& problem, const Objective& objective,
                                      const std::vector<Constraint>& constraints, const Eigen::VectorXd& x,
                                      double f, const Evaluation* at_x = nullptr);

}  // namespace opt
