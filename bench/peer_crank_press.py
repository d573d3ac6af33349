#!/usr/bin/env python3
"""Peer baseline for the crank-lever brick press (seed 003, exercise 7): the
true peak crankshaft torque over the pressing stroke of Table 7.2's variant 1
on the press SM-816 (inner dead centre, lever as a slider), written as a user
would in numpy/scipy: the slider kinematics (7.5)-(7.6) vectorised over the
crank angle, scipy's brentq for the compaction start, a 64-cell grid over
the pressing stroke and scipy's minimize_scalar to refine an interior peak.
Timed in the same run as mechopt (bench/bench_press_sawmill.cpp).
Prints JSON rows {case: {seconds, value}}; run_bench.py turns them into ratios.
"""
import json
import math

import numpy as np
from scipy import optimize

from peer_timing import timed

# Table 7.1, SM-816 [m]; Table 7.2 variant 1; b = 1.4 per cm.
R, L_SH, L, L_P = 0.200, 0.500, 0.290, 1.156
H, A, BRICKS, F, B = 0.020, 0.035e6, 4, 0.03, 140.0
AREA = BRICKS * F
STROKE = 2 * R * L / L_P


def travel(phi):
    """Piston travel from the start of the working half-turn and its rate per radian."""
    sa = R * np.sin(phi) / L_SH
    ca = np.sqrt(1 - sa * sa)
    s = L / L_P * (R * (1 - np.cos(phi)) + L_SH * (1 - ca))
    ds = L / L_P * R * (np.sin(phi) * ca + np.cos(phi) * sa) / ca
    return s, ds


def torque(phi, pressure_law):
    s, ds = travel(phi)
    depth = H - (STROKE - s) if pressure_law else H
    return AREA * A * np.exp(B * depth) * ds


def peak_torque(pressure_law, cells=64):
    phi_c = optimize.brentq(lambda p: travel(p)[0] - (STROKE - H), 0.0, math.pi, xtol=1e-15)
    phi = np.linspace(phi_c, math.pi, cells + 1)
    m = torque(phi, pressure_law)
    k = int(np.argmax(m))
    if k == 0 or k == cells:  # the maximum at an end of the stroke
        return m[k]
    res = optimize.minimize_scalar(lambda p: -torque(p, pressure_law), bounds=(phi[k - 1], phi[k + 1]),
                                   method="bounded", options={"xatol": 1e-12})
    return max(-res.fun, m[k])


def main():
    out = {}
    for name, fn in {"press_peak_constant": lambda: peak_torque(False),
                     "press_peak_pressure_law": lambda: peak_torque(True)}.items():
        seconds, value = timed(fn)
        out[name] = {"seconds": seconds, "value": float(value)}
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
