#!/usr/bin/env python3
"""Peer baseline for the cam-balanced sawmill slider-crank (seed 004, Pasika
2017), the paper's improved mechanism against the original, written as a
user would in numpy/scipy: the exact kinematics (crank-pin radius on the cam,
eq. 1; the slider and the rod by the geometry, angle derivatives by the chain
rule) and the Newton-Euler kinetostatics (3)-(4) vectorised over a 72-point
grid of the revolution, each peak refined by scipy's minimize_scalar.
Cases: the peak balancing torque alone, and the cycle metrics (the peer
computes 17 of mechopt's 23: all but the four quarter-turn torque ratios n_d,
their mean k_d, and the rod length, which is an input).
Timed in the same run as mechopt (bench/bench_press_sawmill.cpp).
Prints JSON rows {case: {seconds, value}}; run_bench.py turns them into ratios.
"""
import json
import math

import numpy as np
from scipy import optimize

from peer_timing import timed

# configs/balanced_slider_crank/paper.yaml, SI.
W = 320 * 2 * math.pi / 60
L1, L2, A = 0.3, 2.0, 0.0219
M2, I2, K, M3, G = 150.0, 0.5, 0.5, 600.0, 9.81
IMPROVED = dict(a=A, rod=L2 + A, rate=M3 * W * W, neutral=L1, cam=True)
ORIGINAL = dict(a=0.0, rod=L2, rate=0.0, neutral=L1, cam=False)
X0 = L1 + L2  # s = x0 - x_B


def point(phi, a, rod, rate, neutral, cam):
    """Every per-angle quantity at crank angles phi (numpy arrays)."""
    c, s = np.cos(phi), np.sin(phi)
    if cam:  # r = -a cos phi + sqrt(l1^2 - a^2 sin^2 phi) and its phi-derivatives
        q = np.sqrt(L1 * L1 - (a * s) ** 2)
        q1 = -a * a * s * c / q
        q2 = (-a * a * (c * c - s * s) - q1 * q1) / q
        r, r1, r2 = q - a * c, q1 + a * s, q2 + a * c
    else:
        r, r1, r2 = L1, 0.0, 0.0
    ax, ax1, ax2 = r * c, r1 * c - r * s, r2 * c - 2 * r1 * s - r * c
    ay, ay1, ay2 = r * s, r1 * s + r * c, r2 * s + 2 * r1 * c - r * s
    d = np.sqrt(rod * rod - ay * ay)  # L cos(phi2)
    d1 = -ay * ay1 / d
    d2 = (-(ay1 * ay1 + ay * ay2) - d1 * d1) / d
    bx, bx1, bx2 = ax + d, ax1 + d1, ax2 + d2
    p21, p22 = -ay1 / d, -(ay2 * d - ay1 * d1) / (d * d)  # rod angle's derivatives
    gx, gx1, gx2 = ax + K * d, ax1 + K * d1, ax2 + K * d2
    gy, gy1, gy2 = (1 - K) * ay, (1 - K) * ay1, (1 - K) * ay2
    travel = X0 - bx
    w2 = W * W
    agx, agy, ab, eps = w2 * gx2, w2 * gy2, w2 * bx2, w2 * p22
    spring = rate * (travel - neutral)
    fbx = spring - M3 * ab
    pin_x = M2 * agx - fbx
    py = M2 * (agy + G)
    fby = (I2 * eps - (ax - gx) * py + (ay - gy) * pin_x - gy * fbx) / (bx - ax)
    pin_y = py - fby
    out = {}
    if cam:
        nx, ny = (ax + a) / L1, ay / L1
        n_r, n_t = nx * c + ny * s, ny * c - nx * s
        cam_force = (pin_x * c + pin_y * s) / n_r
        t = pin_y * c - pin_x * s - cam_force * n_t
        out.update(torque=r * t, support=np.abs(t), cam=cam_force, pressure=np.arctan2(-n_t, n_r))
    else:
        out.update(torque=ax * pin_y - ay * pin_x, support=np.hypot(pin_x, pin_y))
    out["rod_force"] = np.hypot(pin_x, pin_y)
    out["rod_inertia"] = M2 * np.hypot(agx, agy)
    out["shaking"] = np.hypot(M2 * agx + M3 * ab, M2 * agy)
    e = travel - neutral
    out["energy"] = (0.5 * (w2 * (M2 * (gx1 ** 2 + gy1 ** 2) + I2 * p21 ** 2 + M3 * bx1 ** 2) + rate * e * e)
                     + M2 * G * gy)
    out["dev0"] = (travel - L1 * (1 - c)) / L1
    out["dev1"] = (-bx1 - L1 * s) / L1
    out["dev2"] = (-bx2 - L1 * c) / L1
    return out


def peak(mech, key, grid, phi, f=lambda v: v):
    """max over the revolution of f(quantity): the grid's best point refined by minimize_scalar."""
    v = f(grid[key])
    k, h = int(np.argmax(v)), phi[1] - phi[0]
    res = optimize.minimize_scalar(lambda p: -f(point(np.array([p]), **mech)[key][0]),
                                   bounds=(phi[k] - h, phi[k] + h), method="bounded", options={"xatol": 1e-12})
    return max(-res.fun, v[k])


def grid_of(mech, n):
    phi = np.arange(n) * (2 * math.pi / n)
    return phi, point(phi, **mech)


def peak_torque(n=72):
    phi, g = grid_of(IMPROVED, n)
    return peak(IMPROVED, "torque", g, phi, np.abs)


def all_metrics(n=72):
    phi, imp = grid_of(IMPROVED, n)
    _, orig = grid_of(ORIGINAL, n)
    neg = lambda v: -v
    m = {"peak_balancing_torque": peak(IMPROVED, "torque", imp, phi, np.abs),
         "original_peak_balancing_torque": peak(ORIGINAL, "torque", orig, phi, np.abs),
         "peak_support_reaction": peak(IMPROVED, "support", imp, phi),
         "original_peak_support_reaction": peak(ORIGINAL, "support", orig, phi),
         "peak_cam_force": peak(IMPROVED, "cam", imp, phi, np.abs),
         "max_cam_pressure_angle": peak(IMPROVED, "pressure", imp, phi, np.abs),
         "peak_rod_force": peak(IMPROVED, "rod_force", imp, phi),
         "peak_rod_inertia_force": peak(IMPROVED, "rod_inertia", imp, phi),
         "peak_shaking_force": peak(IMPROVED, "shaking", imp, phi),
         "original_peak_shaking_force": peak(ORIGINAL, "shaking", orig, phi),
         "energy_swing": peak(IMPROVED, "energy", imp, phi) + peak(IMPROVED, "energy", imp, phi, neg),
         "original_energy_swing": peak(ORIGINAL, "energy", orig, phi) + peak(ORIGINAL, "energy", orig, phi, neg)}
    for i in range(3):
        m[f"deviation_{i}"] = peak(IMPROVED, f"dev{i}", imp, phi, np.abs)
    m["peak_torque_ratio"] = m["original_peak_balancing_torque"] / m["peak_balancing_torque"]
    m["support_reaction_ratio"] = m["original_peak_support_reaction"] / m["peak_support_reaction"]
    return m


def main():
    out = {}
    seconds, value = timed(peak_torque)
    out["sawmill_peak_torque"] = {"seconds": seconds, "value": float(value)}
    seconds, metrics = timed(all_metrics)
    out["sawmill_all_metrics"] = {"seconds": seconds, "value": float(metrics["peak_balancing_torque"]),
                                  "metrics": {k: float(v) for k, v in metrics.items()}}
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
