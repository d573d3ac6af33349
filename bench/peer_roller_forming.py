#!/usr/bin/env python3
"""Peer baseline for the roller-forming machine (seed 003, exercise 6):
every metric mechopt's roller_forming computes, for the 24 variants of
Table 6.1 at once, written as a user would in numpy: the chain (6.1) with
the negative exponent, (6.2)-(6.3), (6.5), (6.4), the crank radius L_X/2,
(6.6)-(6.9) and (6.10)-(6.12), vectorised over the variants, with the
constants of docs/design/crank_press.md section 9.
Timed in the same run as mechopt (bench/bench_press_sawmill.cpp).
Prints JSON rows {case: {seconds, value}}; run_bench.py turns them into ratios.
"""
import json
import math

import numpy as np

from peer_timing import timed

# Table 6.1: L, B, H [m], v_f, v_p [m/s], passes N.
TABLE = np.array([
    (3.0, 2.0, 0.10, 0.004, 0.23, 8), (4.0, 2.0, 0.10, 0.003, 0.24, 10), (4.0, 1.5, 0.08, 0.002, 0.25, 6),
    (4.0, 1.2, 0.08, 0.003, 0.26, 6), (4.5, 1.0, 0.10, 0.004, 0.27, 8), (4.0, 1.0, 0.12, 0.005, 0.24, 10),
    (4.5, 1.2, 0.12, 0.004, 0.28, 10), (4.0, 1.4, 0.10, 0.003, 0.29, 8), (4.0, 1.4, 0.12, 0.002, 0.25, 8),
    (5.0, 1.2, 0.10, 0.005, 0.26, 10), (4.5, 1.0, 0.10, 0.003, 0.27, 8), (5.0, 1.0, 0.10, 0.004, 0.28, 10),
    (3.0, 2.0, 0.12, 0.005, 0.23, 10), (5.0, 1.2, 0.12, 0.003, 0.26, 10), (4.0, 1.2, 0.10, 0.002, 0.28, 8),
    (4.5, 1.0, 0.12, 0.004, 0.29, 10), (5.0, 1.2, 0.10, 0.003, 0.24, 8), (4.5, 1.4, 0.12, 0.004, 0.25, 10),
    (4.0, 1.2, 0.12, 0.002, 0.26, 10), (5.0, 1.4, 0.10, 0.005, 0.27, 6), (4.0, 1.4, 0.10, 0.004, 0.28, 8),
    (4.5, 1.4, 0.10, 0.003, 0.26, 8), (5.0, 1.2, 0.12, 0.004, 0.24, 10), (3.0, 1.5, 0.12, 0.003, 0.25, 10),
]).T
# The chosen constants and design values (section 9), SI.
F, F1, K1, T_PASS, T_FEED, K1_SAFETY, ALPHA1 = 0.35, 0.58, 0.375, 6.5, 0.75, 1.3, math.pi / 6
TAU0, RHO0, G, INITIAL_FACTOR, INITIAL_SHARE, T1, V_C = 300.0, 2400.0, 9.81, 1.5, 0.5, 70.0, 0.002
ROLLERS, T_STOP, THETA, E, NU, ROLLER_RATIO, DELTA = 4, 2.0, 0.3, 2.5e6, 0.3, 1.1, 0.015


def metrics(table=TABLE):
    """Every metric of every variant (numpy arrays by metric name)."""
    L, B, H, v_f, v_p, n = table
    R_p = ROLLER_RATIO * H
    h_min = R_p * (1 - np.cos(np.arctan((F + F1) / (1 - F * F1)))) * np.exp(-(n - 1) / (K1 * n))  # (6.1)
    L_p = v_f * (T_PASS - T_FEED) * H / h_min                                  # (6.2), (6.3)
    k = 2 + np.sin(ALPHA1)
    den = L_p * RHO0 * G - 2 * TAU0 * k                                        # (6.5), below the line
    a = 2 * TAU0 * k * K1_SAFETY * L_p / den                                   # (6.5)
    L_X = 2 * R_p + a + 2 * DELTA                                              # (6.4)
    t2 = L_p * H * B / (V_C * (ROLLERS + 1))                                   # (6.7)
    t3 = (L_X / v_p + T_STOP) * n                                              # (6.8)
    L_rest = L - L_p
    t4 = L_rest / v_f                                                          # (6.9)
    prod = INITIAL_FACTOR * L_p * B * H / (T1 + t2 + t3) + (L_rest - INITIAL_SHARE * L_p) * B * H / t4  # (6.6)
    phi = np.arccos(1 - h_min / R_p)
    s = np.sin(phi)
    l_k = R_p * s / (1 - THETA)                                                # (6.11)
    F_k = L_p * E * s * s * (1 - THETA) / (14.14 * (1 - NU * NU) * THETA)      # (6.12)
    power = (1 - 2 * THETA) / (3 * R_p) * F_k * (2 * l_k + 3 * F * R_p) * v_p * ROLLERS  # (6.10)
    return {"roller_radius": R_p, "min_layer": h_min, "roller_length": L_p, "outlet_width": a,
            "outlet_denominator": den, "cart_stroke": L_X, "crank_radius": L_X / 2, "cycle_time": t3,
            "productivity": prod, "capture_angle": phi, "compaction_power": power,
            "crank_speed": math.pi * v_p / L_X}


def main():
    seconds, m = timed(metrics)
    print(json.dumps({"roller_forming_table": {"seconds": seconds, "value": float(m["crank_radius"].sum())}},
                     indent=1))


if __name__ == "__main__":
    main()
