// Cycle quantities of a 2*pi-periodic function of the crank angle, one header
// per topic, all included here (in this order, that of their dependencies):
//   mech/angles.hpp          2 pi, wrapping, the grid angles and their tables
//   mech/roots.hpp           Brent's search and the lane root search
//   mech/grow.hpp            Grow, the searches' working storage
//   mech/cycle_scratch.hpp   CycleScratch: what the cycle computations reuse
//   mech/cycle_maxima.hpp    the batched maxima search (find_cycle_maxima)
//   mech/quadrature.hpp      Gauss-Legendre rules, arc means, near poles
//   mech/periodic_roots.hpp  the zeros of periodic functions
// Means over the cycle are Gauss-Legendre arcs between the kinks and near
// poles (quadrature.hpp); maxima are bracketed on the grid and refined to
// machine precision by root searches on the angle derivative
// (LaneRootSearch, side by side, their points answered kLanes at a time).
#pragma once

#include "mech/angles.hpp"
#include "mech/roots.hpp"
#include "mech/grow.hpp"
#include "mech/cycle_scratch.hpp"
#include "mech/cycle_maxima.hpp"
#include "mech/quadrature.hpp"
#include "mech/periodic_roots.hpp"
