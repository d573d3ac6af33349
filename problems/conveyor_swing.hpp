// conveyor_swing: the crank-rocker swing mechanism of a radial-rotary conveyor
// (seed 002) as an optimisation problem. Design modes: `synthesis` (the
// paper's one-parameter family, variable l_co1; l1, l2, l3 from eqs 2-3) and
// `free_links` (variables crank_length, coupler_length, rocker_length, with
// the swing angle as a constraint).
#pragma once
#include <memory>

#include "opt/config.hpp"
#include "opt/problem.hpp"
#include "opt/study.hpp"

namespace problems {

std::unique_ptr<opt::Problem> make_conveyor_swing(const opt::ConfigNode& root);

}  // namespace problems
