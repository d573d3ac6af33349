#!/usr/bin/env python3
"""Independent reference for the general planar linkage (docs/design/linkage.md, issue 34).

Reads a `problem: linkage` YAML config and computes, in mpmath at 30 digits and
sharing no code with mechopt, without the design's closed-form group solutions:

- positions: every moving link is a body with a pose (x, y, theta) of its frame
  (the frames of the design's "Frames and signs"); every joint is a constraint
  between two bodies (revolute: 2 equations, prismatic: 2, the crank's driver:
  1), and the full system Phi(q, phi) = 0 is solved by Newton's method, started
  from the previous grid angle's solution (a second-order predictor). The closed
  form of the design is used ONLY at phi = 0 to seed the branch (`branch` or
  `near`); the branch's sign is then checked at every grid angle. A PRP group
  (two sliders pinned together, no branch) starts with both sliders at its
  first line's point.
- transfer functions per radian of phi: Phi_q q' = -Phi_phi and
  Phi_q q'' = -(Phi_q q')_q q' (the constraints' quadratic velocity terms);
  velocities are speed times them, accelerations speed^2 times.
- dynamics at the constant crank speed w: the driving torque (in the sense of
  rotation, `sense`) (a) by virtual power, M = w^2 sum(m G''.G' + J t'' t')
  - sum(generalised forces of gravity and loads); (b) by Newton-Euler: the 3
  equations of every link about its centre of mass, all joint reaction
  components and the driving torque unknown, one global linear solve. (a) and
  (b) must agree to 1e-20 (relative to the size of the terms) at every point,
  or the script stops. The shaking force (the forces the mechanism puts on the
  frame through the ground joints and the slider lines) and the shaking moment
  about the origin (their moments, the line couples and the motor's reaction
  -M) are checked against the momentum balance (weights + loads - momentum
  rate) to the same tolerance. Process loads are NOT counted as frame forces.
- cycle metrics on a 720-point grid, each extremum refined by an Illinois root
  search on its derivative (mp.diff at doubled precision, or the analytic s', s'')
  to ~1e-27 rad; kinks of the loads (s' = 0 for `when:` loads, s = a table row
  for tables) are located the same way and every quantity is also evaluated
  there, on both sides (a `when` load switches there). Means and RMS: Gauss-
  Legendre, 24 nodes on every piece between kinks, pieces no longer than
  pi/8; the 16-node value gives the reported error estimate (< 1e-15 relative).

Units: exactly those of UNITS below (m, mm, deg, rad, rev/min, rpm, rad/s,
kg, kg/m, kg m^2, N, kN, N m, kN m); a bare number is SI. PyYAML reads the
keys and values `on`/`off` as booleans: keys True are read back as `on`.
Loads supported: slider force (constant or `table: {over: position}`) with
`when: forward|return|always` (forward: ds/dphi > 0), link torque. Anything
else in the description is refused loudly.

Code: this file is the entry point; the work is in the package lkref/ next to
it (found from this file's directory, wherever it is run from):
  lkref/numeric.py     precision, grid, tolerances; plane vectors, dense LU,
                       Illinois root search, Gauss-Legendre, table interpolation
  lkref/model.py       units (UNITS, num) and the YAML description: bodies,
                       points, joints, groups, masses, loads (class Mechanism)
  lkref/kinematics.py  the constraints, Newton on them, the transfer functions,
                       the closed-form branch seed (class Kinematics)
  lkref/dynamics.py    virtual power, Newton-Euler and its reactions, frame and
                       shaking forces; the grid, kinks, extrema, means (Linkage)
  lkref/cli.py         the JSON output, the selftest, main

Run from the repository root (the JSON records the configs' paths as given;
the selftest reads configs/linkage/):
     /usr/bin/python3 tests/ref/linkage_ref.py configs/linkage/watt2_sixbar.yaml \
       configs/linkage/stephenson3_sixbar.yaml configs/linkage/whitworth_shaper.yaml \
       configs/linkage/wedge_press.yaml > tests/ref/linkage_ref.json
     /usr/bin/python3 tests/ref/linkage_ref.py --selftest  (~70 s; slider-crank closed forms,
       transfer functions against mp.diff of the positions, Whitworth time ratio
       and mean torque = cutting work / 2 pi, the wedge's ram stroke)
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from lkref.cli import main  # noqa: E402  (the package next to this file)

if __name__ == "__main__":
    main(__doc__)
