// recuperative_drive: the twin slider-crank drive of seed 000 as an
// optimisation problem (variables rod_length, phase_shift, crank_radius,
// offset; metrics of libmech/twin_slider_crank.hpp).
#pragma once
#include <memory>

#include "mech/twin_slider_crank.hpp"
#include "opt/config.hpp"
#include "opt/problem.hpp"
#include "opt/study.hpp"

namespace problems {

struct RecuperativeDriveModel {
  mech::TwinDrive<double> drive;
  int cycle_points = 0;  // points per revolution; 0: auto_cycle_points (~1e-13)
};

// Reads the `model` section (every key optional, defaults are seed 000's data
// at 100 rpm); throws opt::ConfigError on bad input.
RecuperativeDriveModel parse_recuperative_drive_model(const opt::ConfigNode& root);

std::unique_ptr<opt::Problem> make_recuperative_drive(const opt::ConfigNode& root);

}  // namespace problems
