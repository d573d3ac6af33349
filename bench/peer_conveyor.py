#!/usr/bin/env python3
"""Peer baseline for the conveyor swing mechanism (seed 002): the same model
written as a user would in numpy/scipy (loop-closure velocity and
acceleration formulas vectorised over the crank angle, scipy to refine the
peak and to optimise), timed in the same run as mechopt.
Prints JSON rows {case: {seconds, value}}; run_bench.py turns them into ratios.
With --wp, the work-precision cases instead: the optimum over SLSQP's ftol,
swing_optimum_ftol_<-log10 ftol>: {seconds, value, evaluations, converged},
drawn against mechopt's drivers in docs/img/work_precision_conveyor_l_co1.svg.
"""
import argparse
import json
import math

import numpy as np
from scipy import optimize

from peer_timing import timed

A, B, THETA, L_CB = 1.0, 2.2, math.radians(16), 1.0
W1, MN, M3 = 12.0, 200.0, 3200.0
J_O1 = M3 * 1.2**2 + M3 * (1.2**2 + 1.0)
MC = 0.01 * 32000 * 0.3 / 2


def synthesis(l_co1):
    pts = [(math.cos(t) * l_co1 - math.sin(t) * L_CB, math.sin(t) * l_co1 + math.cos(t) * L_CB)
           for t in (THETA, -THETA)]
    d = [math.hypot(x - A, y - B) for x, y in pts]
    far = 0 if d[0] > d[1] else 1
    side = 1.0 if A * pts[far][1] - B * pts[far][0] >= 0 else -1.0
    return (d[far] - d[1 - far]) / 2, (d[0] + d[1]) / 2, math.hypot(l_co1, L_CB), side


def state(phi, l1, l2, l3, side):
    """Moment and pressure angle at crank angles phi (numpy arrays)."""
    ax, ay = A + l1 * np.cos(phi), B + l1 * np.sin(phi)
    d2 = ax * ax + ay * ay
    along = (l3 * l3 - l2 * l2 + d2) / (2 * d2)
    h = side * np.sqrt(l3 * l3 / d2 - along * along)
    bx, by = along * ax - h * ay, along * ay + h * ax
    t1, t2, t3 = phi, np.arctan2(by - ay, bx - ax), np.arctan2(by, bx)
    s23 = np.sin(t2 - t3)
    w3 = l1 * np.sin(t2 - t1) / (l3 * s23)
    w2 = l1 * np.sin(t3 - t1) / (l2 * s23)
    a3 = (-l1 * np.cos(t1 - t2) - l2 * w2**2 + l3 * w3**2 * np.cos(t3 - t2)) / (l3 * s23)
    a2 = -(l1 * np.cos(t1 - t3) + l2 * w2**2 * np.cos(t2 - t3) - l3 * w3**2) / (l2 * s23)
    hh = l2 / 2
    vx, vy = -l1 * np.sin(t1) - w2 * hh * np.sin(t2), l1 * np.cos(t1) + w2 * hh * np.cos(t2)
    ax_ = -l1 * np.cos(t1) - a2 * hh * np.sin(t2) - w2**2 * hh * np.cos(t2)
    ay_ = -l1 * np.sin(t1) + a2 * hh * np.cos(t2) - w2**2 * hh * np.sin(t2)
    m2 = MN * l2
    power = m2 * (ax_ * vx + ay_ * vy) + m2 * l2**2 / 12 * a2 * w2 + J_O1 * a3 * w3
    return W1**2 * power + MC * np.abs(w3), np.arcsin(np.abs(np.cos(t2 - t3)))


def peak_moment(l_co1, n=48):
    link = synthesis(l_co1)
    phi = np.arange(n) * (2 * math.pi / n)
    m = np.abs(state(phi, *link)[0])
    k, h = int(np.argmax(m)), 2 * math.pi / n
    res = optimize.minimize_scalar(lambda p: -abs(state(np.array([p]), *link)[0][0]),
                                   bounds=(phi[k] - h, phi[k] + h), method="bounded",
                                   options={"xatol": 1e-12})
    return -res.fun


def max_pressure(l_co1, n=48):
    link = synthesis(l_co1)
    phi = np.arange(n) * (2 * math.pi / n)
    p = state(phi, *link)[1]
    k, h = int(np.argmax(p)), 2 * math.pi / n
    res = optimize.minimize_scalar(lambda q: -state(np.array([q]), *link)[1][0],
                                   bounds=(phi[k] - h, phi[k] + h), method="bounded",
                                   options={"xatol": 1e-12})
    return -res.fun


def optimum_result(ftol):
    return optimize.minimize(lambda x: peak_moment(x[0]) / 1e5, [1.2], method="SLSQP",
                             bounds=[(0.9, 2.4)],
                             constraints=[{"type": "ineq",
                                           "fun": lambda x: math.radians(60) - max_pressure(x[0])}],
                             options={"ftol": ftol, "maxiter": 200})


def optimum():
    return optimum_result(1e-12).x[0]


def work_precision():
    """The optimum over ftol; evaluations: the objective's (finite differences included)."""
    out = {}
    for k in (4, 6, 8, 10, 12):
        seconds, res = timed(lambda: optimum_result(10.0 ** -k))
        out[f"swing_optimum_ftol_{k}"] = {"seconds": seconds, "value": float(res.x[0]),
                                          "evaluations": int(res.nfev), "converged": bool(res.success)}
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--wp", action="store_true", help="the work-precision cases instead")
    if ap.parse_args().wp:
        print(json.dumps(work_precision(), indent=1))
        return
    out = {}
    for name, fn in {"swing_peak": lambda: peak_moment(1.2), "swing_optimum": optimum}.items():
        seconds, value = timed(fn)
        out[name] = {"seconds": seconds, "value": float(value)}
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
