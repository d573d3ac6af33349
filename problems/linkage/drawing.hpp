// The mechanism of a linkage description drawn as plain SVG 1.1: what a run
// writes as mechanism.svg beside cycle.svg, and `mechopt kinematics --svg`
// (docs/linkage.md, "Check it against your drawing").
#pragma once
#include <iosfwd>
#include <string>
#include <vector>

#include "opt/config.hpp"
#include "problems/linkage/description.hpp"

namespace problems::linkage {

// The crank angles a run draws: 0, 60, ..., 300 deg (rad).
std::vector<double> drawn_angles();

// The mechanism at the values v at each crank angle phi (rad) of `angles`:
// the first that assembles in full, the others faintly; ground pivots,
// links (a link with more than two points as a polygon through them),
// sliders and blocks as rectangles on their lines, joints as circles,
// point names; and the paths of the outputs' points and of every point
// fixed on a link at the crank angles 2 pi k / path_points, k = 0 ..
// path_points. x and y share one scale, with ticks in metres. Angles where
// a group cannot assemble are left out, and the caption says so.
//
// For readers of the file (tests/test_linkage_drawing.cpp): each drawn
// angle is a group id='angle.K' (K its index in `angles`), each of its
// points a circle id='NAME.K' at the point; a ground point's circle is
// id='NAME.ground'; each path a polyline id='path.NAME' with a vertex per
// angle that assembles (a gap where one does not: a new polyline
// id='path.NAME.2', ...); the tick labels are text class='xtick' (at its
// x) and class='ytick' (at its y). Coordinates in pixels to 3 decimals.
std::string mechanism_svg(const Description& d, const std::vector<double>& v, const std::vector<double>& angles,
                          const std::string& title, int path_points = 360);

// `mechopt kinematics CONFIG [--svg FILE]`: kinematics_report at the
// config's model values as JSON on `out`; with a file, its drawing at the
// same angles there (std::runtime_error when it cannot be written).
void kinematics_command(const opt::ConfigNode& root, const std::vector<double>& angles, const std::string& svg,
                        std::ostream& out);

}  // namespace problems::linkage
