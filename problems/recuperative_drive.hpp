// recuperative_drive: the twin slider-crank drive of seed 000 as an
// optimisation problem (variables rod_length, phase_shift, crank_radius,
// offset; metrics of libmech/twin_slider_crank.hpp).
#pragma once
#include <memory>

#include "opt/config.hpp"
#include "opt/problem.hpp"
#include "opt/study.hpp"

namespace problems {

std::unique_ptr<opt::Problem> make_recuperative_drive(const opt::ConfigNode& root);

}  // namespace problems
