// elastic_drive: the two-mass elastic drive of the recuperative installation
// with an induction motor (seed 001), simulated on SUNDIALS, turning its
// twin slider-crank or any linkage given as model.machine (its rows under
// `machine.`). Variables stiffness, damping, and rod_length, phase_shift
// or the machine's rows; metrics of the periodic steady state (shooting)
// and of the start-up. No exact gradients: derivative-free drivers only.
#pragma once
#include <memory>

#include "opt/config.hpp"
#include "opt/problem.hpp"
#include "opt/study.hpp"

namespace problems {

std::unique_ptr<opt::Problem> make_elastic_drive(const opt::ConfigNode& root);

}  // namespace problems
