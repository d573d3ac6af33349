#!/usr/bin/env python3
"""Independent high-precision reference for seed 002 (conveyor swing mechanism).

Written from the paper's geometry (eqs 1-3, synthesis from the extreme
positions) and plain mechanics in mpmath at 30 digits; it shares no code with
mechopt and uses none of its closed-form velocity or acceleration formulas:
link angles come from circle intersection, their derivatives from mpmath's
numerical differentiation, and the balancing moment from the derivative of
the kinetic energy (M = dT/dphi + M_c |dtheta3/dphi| at constant crank speed).
Output: tools/reference_seed002.json. Run: /usr/bin/python3 tools/reference_seed002.py
"""
import json
import sys

import mpmath as mp

mp.mp.dps = 30
A, B = mp.mpf(1), mp.mpf("2.2")          # crank pivot O relative to rocker pivot O1
THETA = 16 * mp.pi / 180                 # half swing
L_CB = mp.mpf(1)                         # coupler joint offset from the axis
W1, MN, M3 = mp.mpf(12), mp.mpf(200), mp.mpf(3200)
J_O1 = M3 * mp.mpf("1.2") ** 2 + M3 * (mp.mpf("1.2") ** 2 + 1)   # eq. (11) + parallel axes
MC = mp.mpf("0.01") * 32000 * mp.mpf("0.3") / 2                  # eq. (7)


def synthesis(l_co1):
    bx, by = l_co1, L_CB                 # axis along x, B offset toward O (+y)
    pts = [(mp.cos(t) * bx - mp.sin(t) * by, mp.sin(t) * bx + mp.cos(t) * by)
           for t in (THETA, -THETA)]
    d = [mp.sqrt((x - A) ** 2 + (y - B) ** 2) for x, y in pts]
    far = max(range(2), key=lambda i: d[i])
    side = mp.sign(A * pts[far][1] - B * pts[far][0])
    return (d[far] - d[1 - far]) / 2, (d[0] + d[1]) / 2, mp.sqrt(bx * bx + by * by), side


def angles(phi, l1, l2, l3, side):
    ax, ay = A + l1 * mp.cos(phi), B + l1 * mp.sin(phi)
    d2 = ax * ax + ay * ay
    along = (l3 * l3 - l2 * l2 + d2) / (2 * d2)
    h = side * mp.sqrt(l3 * l3 / d2 - along * along)
    bx, by = along * ax - h * ay, along * ay + h * ax
    return mp.atan2(by - ay, bx - ax), mp.atan2(by, bx)


def moment(phi, link):
    l1, l2, l3, side = link
    th2 = lambda p: angles(p, *link)[0]
    th3 = lambda p: angles(p, *link)[1]

    def energy(p):  # kinetic energy over w1^2
        w2, w3 = mp.diff(th2, p), mp.diff(th3, p)
        t2 = th2(p)
        vx = -l1 * mp.sin(p) - w2 * l2 / 2 * mp.sin(t2)
        vy = l1 * mp.cos(p) + w2 * l2 / 2 * mp.cos(t2)
        m1, m2 = MN * l1, MN * l2
        return (m1 * l1 ** 2 / 3 + m2 * (vx * vx + vy * vy) + m2 * l2 ** 2 / 12 * w2 * w2
                + J_O1 * w3 * w3) / 2

    return W1 ** 2 * mp.diff(energy, phi) + MC * abs(mp.diff(th3, phi))


def trough(link, phi0):
    """A local extremum of M near phi0, refined as a root of dM/dphi."""
    phi = mp.findroot(lambda p: mp.diff(lambda q: moment(q, link), p), phi0)
    return phi, moment(phi, link)


def main():
    out = {"variants": []}
    for l_co1 in ("1.2", "1.4", "1.6", "1.8"):
        link = synthesis(mp.mpf(l_co1))
        # Peak |M| over a 360-point grid, refined at the grid's best point.
        grid = [(abs(moment(2 * mp.pi * k / 360, link)), 2 * mp.pi * k / 360) for k in range(360)]
        phi0 = max(grid)[1]
        phi, m = trough(link, phi0)
        out["variants"].append({"l_co1": float(l_co1), "crank_length": mp.nstr(link[0], 17),
                                "coupler_length": mp.nstr(link[1], 17),
                                "rocker_length": mp.nstr(link[2], 17),
                                "peak_moment": mp.nstr(abs(m), 17), "phi": mp.nstr(phi, 17)})
    # The least peak in the family: the two troughs (near 1.0 and 4.6 rad) are
    # equal there.
    def gap(l):
        link = synthesis(l)
        return abs(trough(link, mp.mpf("0.95"))[1]) - abs(trough(link, mp.mpf("4.6"))[1])
    lstar = mp.findroot(gap, mp.mpf("1.52"))
    link = synthesis(lstar)
    out["l_co1_optimum"] = mp.nstr(lstar, 17)
    out["peak_moment_at_optimum"] = mp.nstr(abs(trough(link, mp.mpf("0.95"))[1]), 17)
    json.dump(out, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()
