#!/usr/bin/env python3
"""Independent high-precision reference for seed 000 (twin slider-crank).

Written from the paper's printed formulas, eqs (1)-(4), (9)-(15), in mpmath at
40 significant digits; it shares no code with mechopt. The values it prints are
the reference values pinned in tests/test_reproduction_seed000.cpp and used by
the benchmark to measure errors. Run: /usr/bin/python3 tools/reference_seed000.py
"""
import json
import sys

import mpmath as mp

mp.mp.dps = 40
R, M, Q = mp.mpf("0.2"), mp.mpf(1000), mp.mpf(80)
W = 100 * mp.pi / 30  # 100 rpm


def kinetic_energy(phi, l, dphi=mp.pi / 2, r=R, w=W):
    """T(phi), eqs (1)-(4), (9)-(11); second slider mirrored as in eq. (2)."""
    lam = r / l
    p2 = phi + dphi
    s1, c1, s2, c2 = mp.sin(phi), mp.cos(phi), mp.sin(p2), mp.cos(p2)
    q1, q2 = mp.sqrt(1 - lam**2 * s1**2), mp.sqrt(1 - lam**2 * s2**2)
    x1 = -r * s1 * (1 + lam * c1 / q1)
    x2 = -r * s2 * (1 - lam * c2 / q2)
    xs3 = -r * s1 * (1 + lam / 2 * c1 / q1)
    xs4 = -r * s2 * (1 - lam / 2 * c2 / q2)
    ys3, ys4 = r / 2 * c1, r / 2 * c2
    return w**2 / 2 * (M * (x1**2 + x2**2) + l * Q * (xs3**2 + ys3**2 + xs4**2 + ys4**2))


def mean_energy(l, dphi=mp.pi / 2, n=400):
    """Eq. (12): cycle mean; trapezoid on n points (error << 1e-40 for r/l <= 0.4)."""
    return mp.fsum(kinetic_energy(2 * mp.pi * k / n, l, dphi) for k in range(n)) / n


def peak_energy(l, dphi=mp.pi / 2):
    """T_max: densest grid maximum, then a root of dT/dphi at 40 digits."""
    n = 720
    k = max(range(n), key=lambda k: kinetic_energy(2 * mp.pi * k / n, l, dphi))
    phi = mp.findroot(lambda p: mp.diff(lambda t: kinetic_energy(t, l, dphi), p),
                      2 * mp.pi * k / n)
    return kinetic_energy(phi, l, dphi)


def main():
    tmin = 4 * M * R**2 * W**2 / mp.pi**2  # eq. (14)
    table = []
    for i in range(11):
        l = mp.mpf(5 + i) / 10
        tcp, tmax = mean_energy(l), peak_energy(l)
        table.append({"rod_length": float(l), "peak_kinetic_energy": mp.nstr(tmax, 17),
                      "mean_kinetic_energy": mp.nstr(tcp, 17), "k1": mp.nstr(tmax / tcp, 17),
                      "k2": mp.nstr(tcp / tmin, 17), "k3": mp.nstr(tmax / tmin, 17)})
    # Continuous optimum of T_cp over l (phase shift pi/2): dT_cp/dl = 0.
    lstar = mp.findroot(lambda l: mp.diff(mean_energy, l), mp.mpf("0.61"))
    l08 = mp.mpf("0.8")
    out = {"crank_speed_rad_s": mp.nstr(W, 17),
           "mean_kinetic_energy_gradient_l08": mp.nstr(mp.diff(mean_energy, l08), 17), "least_mean_kinetic_energy": mp.nstr(tmin, 17),
           "table1": table, "rod_length_optimum": mp.nstr(lstar, 17),
           "mean_kinetic_energy_at_optimum": mp.nstr(mean_energy(lstar), 17)}
    json.dump(out, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()
