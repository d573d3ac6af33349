#!/usr/bin/env python3
"""Peer baseline for the recuperative drive: what a user would write in
Python with numpy/scipy (Debian packages), timed in the same run as mechopt.
Prints JSON rows {case: {seconds, value}}; run_bench.py turns them into ratios.
With --wp, the work-precision cases instead: the rod-length optimum over
minimize_scalar's xatol, rod_length_optimum_xatol_<-log10 xatol>: {seconds,
value, evaluations, converged}, drawn against mechopt's drivers in
docs/img/work_precision_rod_length.svg.
"""
import argparse
import json
import math
import timeit

import numpy as np
from scipy import integrate, optimize

R, M, Q, W, DPHI = 0.2, 1000.0, 80.0, 100 * math.pi / 30, math.pi / 2


def energy(phi, l, dphi=DPHI):
    """T(phi), seed 000 eqs (1)-(4), (9)-(11), vectorised over phi."""
    lam = R / l
    p2 = phi + dphi
    s1, c1, s2, c2 = np.sin(phi), np.cos(phi), np.sin(p2), np.cos(p2)
    q1, q2 = np.sqrt(1 - (lam * s1) ** 2), np.sqrt(1 - (lam * s2) ** 2)
    x1 = -R * s1 * (1 + lam * c1 / q1)
    x2 = -R * s2 * (1 - lam * c2 / q2)
    xs3 = -R * s1 * (1 + lam / 2 * c1 / q1)
    xs4 = -R * s2 * (1 - lam / 2 * c2 / q2)
    return W**2 / 2 * (M * (x1**2 + x2**2)
                       + l * Q * (xs3**2 + (R / 2 * c1) ** 2 + xs4**2 + (R / 2 * c2) ** 2))


def mean_trapezoid(l, n=32):
    return float(np.mean(energy(np.arange(n) * (2 * math.pi / n), l)))


def mean_quad(l):
    return integrate.quad(lambda p: energy(p, l), 0, 2 * math.pi, epsabs=0, epsrel=1e-12,
                          limit=200)[0] / (2 * math.pi)


def gradient_fd(l, h=1e-6):
    """Value and dT_cp/dl by central differences, as a user without autodiff would."""
    return mean_trapezoid(l), (mean_trapezoid(l + h) - mean_trapezoid(l - h)) / (2 * h)


def peak(l, n=32):
    phi = np.arange(n) * (2 * math.pi / n)
    k = int(np.argmax(energy(phi, l)))
    h = 2 * math.pi / n
    res = optimize.minimize_scalar(lambda p: -energy(p, l), bounds=(phi[k] - h, phi[k] + h),
                                   method="bounded", options={"xatol": 1e-12})
    return -res.fun


def optimum_result(xatol):
    return optimize.minimize_scalar(mean_trapezoid, bounds=(0.5, 1.5), method="bounded",
                                    options={"xatol": xatol})


def optimum():
    return optimum_result(1e-12).x


def timed(fn, min_seconds=0.2):
    """Median seconds per call over 5 repeats, each at least min_seconds long."""
    t = timeit.Timer(fn)
    number, _ = t.autorange()
    number = max(number, int(number * min_seconds / 0.2))
    runs = sorted(t.repeat(repeat=5, number=number))
    return runs[2] / number, fn()


def work_precision():
    """The optimum over xatol: (seconds, its result) per -log10 xatol."""
    out = {}
    for k in (4, 6, 8, 10, 12):
        seconds, res = timed(lambda: optimum_result(10.0 ** -k))
        out[f"rod_length_optimum_xatol_{k}"] = {"seconds": seconds, "value": float(res.x),
                                                "evaluations": int(res.nfev), "converged": bool(res.success)}
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--wp", action="store_true", help="the work-precision cases instead")
    if ap.parse_args().wp:
        print(json.dumps(work_precision(), indent=1))
        return
    cases = {
        "cycle_mean": lambda: mean_trapezoid(0.8),
        "cycle_mean_16": lambda: mean_trapezoid(0.8, 16),
        "cycle_mean_quad": lambda: mean_quad(0.8),
        "cycle_mean_gradient": lambda: gradient_fd(0.8)[1],
        "cycle_peak": lambda: peak(0.8),
        "rod_length_optimum": optimum,
    }
    out = {}
    for name, fn in cases.items():
        seconds, value = timed(fn)
        out[name] = {"seconds": seconds, "value": float(value)}
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
