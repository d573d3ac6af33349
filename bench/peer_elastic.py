#!/usr/bin/env python3
"""Peer baseline for the elastic drive (seed 001): the same two-mass model in
Python with scipy.integrate.solve_ivp, steady state by shooting over one
crank revolution (scipy.optimize.root on the periodicity residual), first
guess from a 3 s start-up, as mechopt does. Prints JSON rows
{case: {seconds, value}}; value = peak coupling torque [N m] at the crank.
A Radau run at rtol 1e-12 gives the reference for the error columns.
"""
import json
import math
import sys
import timeit

import numpy as np
from scipy import integrate, optimize

# configs/elastic_drive scene (see tests/test_elastic_drive.cpp)
W0, MKR, SKR = 104.72, 215.4, 0.025 * (2 + math.sqrt(3))
U, ETA = 9.8, 0.9
JP1 = (0.138 + 0.32) * 1.2 * U * U
C, K = 110000.0, 2000.0
R, L, DPHI = 0.2, 0.8, math.pi / 2
MB = 1000 + 64 / 2
JK = 64 * R * R
LOAD = 3562.0 + (10124.9 - 10124.9) * 0.008
F_GUIDE = 0.008
START = 10.686


def motor(w1):
    s = 1 - w1 * U / W0
    return U * ETA * 2 * MKR * s * SKR / (s * s + SKR * SKR)


def mechanism(phi2, w2):
    """J_p2, J_p2'/2 and the resistance moment (binomial kinematics, same side)."""
    inertia, half_d, res = JK, 0.0, 0.0
    lam = R / L
    for psi in (phi2, phi2 + DPHI):
        dx = -R * (math.sin(psi) + lam / 2 * math.sin(2 * psi))
        ddx = -R * (math.cos(psi) + lam * math.cos(2 * psi))
        inertia += MB * dx * dx
        half_d += MB * dx * ddx
        beta = math.asin(lam * math.sin(psi))
        force = LOAD / (math.cos(beta) - F_GUIDE * math.sin(beta))
        res += math.tanh(w2 / 1e-3) * abs(force * R * math.sin(psi + beta))
    return inertia, half_d, res


def time_rhs(t, y):
    phi1, phi2, w1, w2 = y
    j2, hd, res = mechanism(phi2, w2)
    cpl = C * (phi1 - phi2) + K * (w1 - w2)
    return [w1, w2, (motor(w1) - cpl) / JP1, (cpl - res - hd * w2 * w2) / j2]


def angle_rhs(phi2, z):
    theta, w1, w2, t, q = z
    dy = time_rhs(t, [phi2 + theta, phi2, w1, w2])
    cpl = C * theta + K * (w1 - w2)
    return [(w1 - w2) / w2, dy[2] / w2, dy[3] / w2, 1 / w2, cpl * cpl / w2]


def steady(method, rtol, atol):
    st = integrate.solve_ivp(time_rhs, (0, 3.0), [0, 0, START, START], method=method,
                             rtol=rtol, atol=atol, dense_output=True)
    phi_end = st.y[1, -1]
    target = 2 * math.pi * math.floor(phi_end / (2 * math.pi))
    t_cross = optimize.brentq(lambda t: st.sol(t)[1] - target, 0, 3.0)
    y = st.sol(t_cross)
    guess = np.array([y[0] - y[1], y[2], y[3]])

    def residual(x):
        r = integrate.solve_ivp(angle_rhs, (0, 2 * math.pi), [*x, 0, 0], method=method,
                                rtol=rtol, atol=atol)
        return r.y[:3, -1] - x

    sol = optimize.root(residual, guess, method="hybr", options={"xtol": 1e-10})
    r = integrate.solve_ivp(angle_rhs, (0, 2 * math.pi), [*sol.x, 0, 0], method=method,
                            rtol=rtol, atol=atol, dense_output=True)
    phi = np.linspace(0, 2 * math.pi, 20001)  # dense: the peak to ~1e-8
    z = r.sol(phi)
    cpl = C * z[0] + K * (z[1] - z[2])
    return float(np.max(np.abs(cpl)))


def timed(fn):
    t = timeit.Timer(fn)
    runs = sorted(t.repeat(repeat=3, number=1))
    return runs[1], fn()


def main():
    out = {"reference": {"seconds": 0, "value": steady("Radau", 1e-12, 1e-12)}}
    for name, method in (("steady_lsoda", "LSODA"), ("steady_radau", "Radau")):
        seconds, value = timed(lambda: steady(method, 1e-8, 1e-8))
        out[name] = {"seconds": seconds, "value": value}
    seconds, _ = timed(lambda: integrate.solve_ivp(time_rhs, (0, 3.0), [0, 0, START, START],
                                                   method="LSODA", rtol=1e-8, atol=1e-8,
                                                   t_eval=np.arange(0, 3.0, 1e-3)))
    out["startup_lsoda"] = {"seconds": seconds, "value": 0.0}
    json.dump(out, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()
