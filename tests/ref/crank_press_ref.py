#!/usr/bin/env python3
"""Independent reference for seed 003: brick press (exercise 7) and the
roller-forming cart stroke (exercise 6).

Written from the guide's eqs (7.1)-(7.8) and (6.1)-(6.12) and plain
geometry, in mpmath at 30 digits; it shares no code with mechopt. Piston
displacement s(phi) is written from the geometry (lever as a slider, or the
exact four-bar lever of docs/design/crank_press.md); s' and s'' come from
mpmath's numerical differentiation (mp.diff, extra working precision), so the
guide's eq. (7.6) is checked, not assumed. The crank torque is the virtual-work
torque M(phi) = Q(depth(phi)) * ds/dphi. Its maximum over the pressing stroke
is the larger of the value at the start of compaction and the value at an
interior root of dM/dphi:
  constant force:  s''(phi) = 0
  pressure law:    b s'(phi)^2 + s''(phi) = 0   (independent of a, m, F, h)
each found on a grid and refined by a bracketed root finder, then checked
against a dense float64 grid and against the work bound M_max >= W / (pi - phi_c).

Design document: docs/design/crank_press.md (symbols, readings, checks).
Run: /usr/bin/python3 tests/ref/crank_press_ref.py > out.json   (~40 s)
"""
import json
import math
import sys
import time

import mpmath as mp

from mp_search import golden_min, max_on_interval

mp.mp.dps = 30
T0 = time.time()
MPF = mp.mpf

# ---- Table 7.1 (mm in the guide; metres here) ---------------------------------
PRESSES = {
    "SM-816": {"r": MPF("0.200"), "l": MPF("0.290"), "l_p": MPF("1.156"), "l_sh": MPF("0.500"),
               "S_printed": MPF("0.100")},
    "MS-152": {"r": MPF("0.200"), "l": MPF("0.275"), "l_p": MPF("1.050"), "l_sh": MPF("0.550"),
               "S_printed": MPF("0.104")},
}
# ---- Table 7.2: h [mm], a [MPa], m [bricks], phi [deg], omega [rad/s] ------------
VARIANTS = [
    (20, "0.035", 4, 120, "20.7"), (25, "0.030", 3, 130, "21.6"), (30, "0.015", 2, 140, "22.5"),
    (35, "0.010", 2, 150, "23.0"), (40, "0.008", 3, 160, "24.2"), (45, "0.006", 2, 105, "25.6"),
    (50, "0.005", 2, 110, "28.2"), (30, "0.015", 3, 115, "22.5"), (20, "0.035", 2, 120, "20.1"),
    (25, "0.030", 2, 125, "30.2"), (35, "0.010", 3, 130, "22.4"), (45, "0.006", 2, 135, "21.8"),
    (50, "0.007", 2, 140, "25.4"), (20, "0.035", 4, 145, "24.6"), (35, "0.010", 3, 150, "23.2"),
    (20, "0.008", 2, 120, "22.5"), (30, "0.015", 3, 130, "22.0"), (40, "0.010", 4, 140, "23.0"),
    (45, "0.007", 2, 125, "30.0"), (35, "0.008", 3, 145, "24.0"), (25, "0.005", 2, 135, "25.0"),
    (30, "0.015", 2, 115, "23.5"), (25, "0.030", 4, 125, "21.6"), (45, "0.006", 3, 140, "24.8"),
]
F_BRICK = MPF("0.12") * MPF("0.25")      # eq. (7.1): brick face 0.12 x 0.25 = 0.03 m^2
B_LAW = MPF("1.4")                       # eq. (7.2): b = 1.4 "per unit of h"
B_PER_M = {"cm": B_LAW * 100, "mm": B_LAW * 1000}   # reading depth_unit: cm (default) | mm
ETA = MPF("0.8")                         # eq. (7.8): drive efficiency
OVERLOAD = MPF("1.5")                    # eq. (7.8): motor overload factor, range 1.5..1.8
P_VALID = (6, 40)                        # MPa: range in which the guide says b = 1.4 holds

SENSES = ("inner", "outer")              # which dead centre ends the pressing (see doc)
LEVERS = ("slider", "four_bar_same", "four_bar_opposite")
FORCES = ("constant", "pressure_law")


def f(x):
    return float(x)


def deg(x):
    return float(x * 180 / mp.pi)


# ---- Kinematics: piston travel s(phi) from the start of the working half-turn -------
# phi = 0 at the dead centre where the working stroke starts, phi = pi where the
# pressing ends (deepest compaction). "inner": the lever end is pulled toward the
# crank axis (rod in tension), as eq. (7.6) with sin(alpha + phi) implies;
# "outer": pushed away (rod in compression), torque factor sin(phi - alpha).

def s_slider(phi, g, sense):
    """Lever end on the line of dead centres (eqs 7.3-7.6): s = (l/l_p) x(phi)."""
    r, lsh = g["r"], g["l_sh"]
    cos_a = mp.sqrt(1 - (r * mp.sin(phi) / lsh) ** 2)          # eq. (7.5)
    sign = 1 if sense == "inner" else -1
    x = r * (1 - mp.cos(phi)) + sign * lsh * (1 - cos_a)
    return g["l"] / g["l_p"] * x


def s_four_bar(phi, g, sense, pivot):
    """Exact lever: pivot C = (l_sh, +-sqrt(l_p^2 - r^2)), so both dead-centre
    positions of the rod end lie on the x axis at l_sh +- r; the piston moves
    parallel to x and is driven at distance l from C: travel = l * d(sin psi)."""
    r, lsh, lp, l = g["r"], g["l_sh"], g["l_p"], g["l"]
    theta = phi if sense == "inner" else phi + mp.pi             # crank angle from +x
    pin_side = 1 if sense == "inner" else -1                     # crank pin's half-plane
    sig = pin_side if pivot == "same" else -pin_side             # pivot's half-plane
    yc = mp.sqrt(lp**2 - r**2)
    dx, dy = lsh - r * mp.cos(theta), sig * yc - r * mp.sin(theta)     # D = C - A
    k = (lsh**2 - lp**2 - dx**2 - dy**2) / (2 * lp)
    rr = mp.hypot(dx, dy)
    psi = mp.atan2(sig * dy, dx) + mp.asin(k / rr)               # B = C + l_p (sin psi, -sig cos psi)
    sin_psi0 = r / lp
    if sense == "inner":
        return l * (sin_psi0 - mp.sin(psi))
    return l * (mp.sin(psi) + sin_psi0)


def travel(g, sense, lever):
    if lever == "slider":
        return lambda p: s_slider(p, g, sense)
    return lambda p: s_four_bar(p, g, sense, lever.split("_")[-1])


def bracket_roots(fn, lo, hi, n=180):
    """Sign changes of fn on a grid of n cells over [lo, hi], each refined."""
    xs = [lo + (hi - lo) * i / n for i in range(n + 1)]
    ys = [fn(x) for x in xs]
    roots = []
    for i in range(n):
        if ys[i] == 0:
            roots.append(xs[i])
        elif ys[i] * ys[i + 1] < 0:
            roots.append(mp.findroot(fn, (xs[i], xs[i + 1]), solver="anderson"))
    return roots


def kinematic_summary(g, sense, lever):
    s = travel(g, sense, lever)
    d1 = lambda p: mp.diff(s, p)
    d2 = lambda p: mp.diff(s, p, 2)
    eps = MPF("1e-6")
    r_const = bracket_roots(d2, eps, mp.pi - eps)           # s'' = 0: peak of s'
    assert len(r_const) == 1, r_const
    out = {"s_end": s(mp.pi), "s_start": s(MPF(0)), "phi_peak_velocity": r_const[0]}
    for unit, b in B_PER_M.items():
        gfun = lambda p, b=b: b * d1(p) ** 2 + d2(p)
        r_law = bracket_roots(gfun, r_const[0], mp.pi - eps)
        assert len(r_law) == 1, r_law                       # one interior maximiser
        out["phi_law_" + unit] = r_law[0]
    return s, d1, d2, out


def compaction_start(s, s_end, h):
    """phi_c: the piston meets the mass, s(phi_c) = s_end - h (s increasing on [0, pi])."""
    return mp.findroot(lambda p: s(p) - (s_end - h), (MPF("1e-9"), mp.pi - MPF("1e-9")),
                       solver="anderson")


def phi_c_closed_form(g, sense, h):
    """Slider reading only: law of cosines in triangle O-A-B (check of the root)."""
    r, lsh = g["r"], g["l_sh"]
    x_c = (2 * r * g["l"] / g["l_p"] - h) * g["l_p"] / g["l"]    # lever-end travel at contact
    ob = lsh + r - x_c if sense == "inner" else lsh - r + x_c
    c = (r**2 + ob**2 - lsh**2) / (2 * r * ob)
    return mp.acos(c) if sense == "inner" else mp.acos(-c)


def press_tables():
    out = {}
    for name, g in PRESSES.items():
        s_kin = 2 * g["r"] * g["l"] / g["l_p"]
        info = {"r": f(g["r"]), "l": f(g["l"]), "l_p": f(g["l_p"]), "l_sh": f(g["l_sh"]),
                "S_printed": f(g["S_printed"]), "S_kinematic_2rl_over_lp": f(s_kin),
                "S_difference_rel": f(g["S_printed"] / s_kin - 1),
                "lambda_r_over_lsh": f(g["r"] / g["l_sh"]),
                "rod_angle_max_deg": deg(mp.asin(g["r"] / g["l_sh"])),
                "lever_swing_half_deg": deg(mp.asin(g["r"] / g["l_p"]))}
        kin = {}
        checks = {}
        for sense in SENSES:
            for lever in LEVERS:
                s, d1, d2, ks = kinematic_summary(g, sense, lever)
                kin[(sense, lever)] = (s, d1, d2, ks)
                key = sense + "/" + lever
                info[key] = {"stroke": f(ks["s_end"] - ks["s_start"]),
                             "phi_peak_velocity_deg": deg(ks["phi_peak_velocity"]),
                             "peak_velocity_m_per_rad": f(d1(ks["phi_peak_velocity"])),
                             "phi_star_pressure_law_cm_deg": deg(ks["phi_law_cm"]),
                             "phi_star_pressure_law_mm_deg": deg(ks["phi_law_mm"])}
            # eq. (7.6) is the derivative of the slider-reading travel (inner sense)
        s, d1, _, _ = kin[("inner", "slider")]
        worst = 0
        for k in range(1, 36):
            p = mp.pi * k / 36
            al = mp.asin(g["r"] * mp.sin(p) / g["l_sh"])
            eq76 = g["l"] / g["l_p"] * g["r"] * mp.sin(al + p) / mp.cos(al)
            worst = max(worst, abs(eq76 - d1(p)))
        checks["eq_7_6_equals_ds_dphi_inner_slider_max_abs"] = f(worst)
        info["checks"] = checks

        rows = []
        for i, (h_mm, a_s, m, phi_deg, w_s) in enumerate(VARIANTS, 1):
            h, a, w = MPF(h_mm) / 1000, MPF(a_s), MPF(w_s)
            p_cm = a * mp.exp(B_LAW * h_mm / 10)                 # eq. (7.2), MPa, h in cm
            p_mm = a * mp.exp(B_LAW * h_mm)                      # eq. (7.2) as printed, h in mm
            q_max = m * p_cm * 1e6 * F_BRICK                     # eq. (7.1), N
            # The guide's method: constant Q at the tabulated angle, lever as slider, (7.3)-(7.8)
            ph = MPF(phi_deg) * mp.pi / 180
            alpha = mp.asin(g["r"] * mp.sin(ph) / g["l_sh"])     # eq. (7.5)
            p_lever = q_max * g["l"] / g["l_p"]                  # eq. (7.3)
            p_rod = p_lever / mp.cos(alpha)                      # eq. (7.4)
            t_tan = p_lever * mp.sin(alpha + ph) / mp.cos(alpha)  # eq. (7.6)
            m_guide = t_tan * g["r"]                             # eq. (7.7)
            row = {"variant": i, "h_mm": h_mm, "a_MPa": float(a), "m": m, "phi_deg": phi_deg,
                   "omega": float(w),
                   "p_max_MPa": f(p_cm), "p_max_MPa_if_h_in_mm": f(p_mm),
                   "p_in_guide_range_6_40": bool(P_VALID[0] <= p_cm <= P_VALID[1]),
                   "Q_max_N": f(q_max),
                   "work_per_stroke_J": {"constant": f(q_max * h),
                                         "pressure_law": f(m * a * 1e6 * F_BRICK *
                                                           (mp.exp(B_PER_M["cm"] * h) - 1) /
                                                           B_PER_M["cm"])},
                   "guide": {"alpha_deg": deg(alpha), "P_N": f(p_lever), "P1_N": f(p_rod),
                             "T_N": f(t_tan), "M_Nm": f(m_guide),
                             "N_kW": f(m_guide * w / (1000 * ETA * OVERLOAD))},
                   "readings": {}}
            b = B_PER_M["cm"]
            for (sense, lever), (s, d1, d2, ks) in kin.items():
                s_end = ks["s_end"]
                phc = compaction_start(s, s_end, h)
                entry = {"phi_c_deg": deg(phc), "tabulated_angle_before_compaction": bool(ph < phc)}
                if lever == "slider":
                    entry["phi_c_closed_form_diff"] = f(abs(phc - phi_c_closed_form(g, sense, h)))
                for force in FORCES:
                    if force == "constant":
                        pk = ks["phi_peak_velocity"]
                        cand = [phc] + ([pk] if pk > phc else [])
                        val = lambda p: q_max * d1(p)
                        work = q_max * h
                    else:
                        pk = ks["phi_law_cm"]
                        cand = [phc] + ([pk] if pk > phc else [])
                        val = lambda p: (m * a * 1e6 * F_BRICK * mp.exp(b * (h - (s_end - s(p))))
                                         * d1(p))
                        work = m * a * 1e6 * F_BRICK * (mp.exp(b * h) - 1) / b
                    best = max(cand, key=val)
                    mmax = val(best)
                    assert mmax >= work / (mp.pi - phc)        # mean over the stroke <= peak
                    entry[force] = {"M_max_Nm": f(mmax), "phi_deg": deg(best),
                                    "at": "compaction start" if best == phc else "interior",
                                    "N_kW": f(mmax * w / (1000 * ETA * OVERLOAD)),
                                    "mean_M_over_stroke_Nm": f(work / (mp.pi - phc))}
                # The guide's formula read literally: the constant force Q_max acts over
                # the whole working half-turn [0, pi], contact or not; its maximum is at
                # the peak of s' (one root of s'', asserted in kinematic_summary).
                pv = ks["phi_peak_velocity"]
                whole = q_max * d1(pv)
                entry["constant_whole_stroke"] = {"M_max_Nm": f(whole), "phi_deg": deg(pv),
                                                  "ratio_to_after_contact": f(whole / entry["constant"]["M_max_Nm"])}
                row["readings"][sense + "/" + lever] = entry
            rows.append(row)
        info["variants"] = rows
        info["constant_whole_stroke_over_after_contact"] = {
            key: [min(rw["readings"][key]["constant_whole_stroke"]["ratio_to_after_contact"] for rw in rows),
                  max(rw["readings"][key]["constant_whole_stroke"]["ratio_to_after_contact"] for rw in rows)]
            for key in rows[0]["readings"]}
        out[name] = info
        out[name]["_kin"] = kin
    return out


def dense_check(tables):
    """Float64 check: a 20001-point grid never exceeds the refined maxima (rel 1e-9)
    and comes within 1e-6 of them (default reading inner/slider, both forces)."""
    worst_over, worst_gap = 0.0, 0.0
    for name, g in PRESSES.items():
        r, lsh, l, lp = (float(g[k]) for k in ("r", "l_sh", "l", "l_p"))
        n = 20001
        phis = [math.pi * i / (n - 1) for i in range(n)]

        def s(p):
            return l / lp * (r * (1 - math.cos(p)) + lsh * (1 - math.sqrt(1 - (r * math.sin(p) / lsh) ** 2)))

        def ds(p):
            al = math.asin(r * math.sin(p) / lsh)
            return l / lp * r * math.sin(p + al) / math.cos(al)
        s_end = s(math.pi)
        for row in tables[name]["variants"]:
            h = row["h_mm"] / 1000
            q = row["Q_max_N"]
            base = row["m"] * row["a_MPa"] * 1e6 * 0.03
            for force in FORCES:
                best = 0.0
                for p in phis:
                    depth = h - (s_end - s(p))
                    if depth < 0:
                        continue
                    load = q if force == "constant" else base * math.exp(140.0 * depth)
                    best = max(best, load * ds(p))
                ref = row["readings"]["inner/slider"][force]["M_max_Nm"]
                worst_over = max(worst_over, best / ref - 1)
                worst_gap = max(worst_gap, 1 - best / ref)
    return {"grid_above_refined_max_rel": worst_over, "grid_below_refined_max_rel": worst_gap}


ROD_LIMIT = MPF("0.99")                  # lambda = r / l_sh < 1: the rod must reach the dead centres


def lambda_optimum(g, h_mm, force):
    """Stroke held (S = 2 r l / l_p fixed), lever as slider, inner sense: the peak
    torque per unit force depends on lambda = r / l_sh only. Golden section over
    lambda in [0.05, 0.99] (up to the rod's limit) for the least peak ds/dphi
    (constant) or e^{b depth} ds/dphi / e^{b h} (pressure law)."""
    s_k = 2 * g["r"] * g["l"] / g["l_p"]
    h = MPF(h_mm) / 1000
    b = B_PER_M["cm"]

    def peak(lam):
        gg = dict(g, l_sh=g["r"] / lam)
        s = lambda p: s_slider(p, gg, "inner")
        d1 = lambda p: mp.diff(s, p)
        phc = compaction_start(s, s_k, h)
        if force == "constant":
            fn = d1
        else:
            fn = lambda p: mp.exp(b * (h - (s_k - s(p)))) * d1(p) / mp.exp(b * h)
        return max_on_interval(fn, phc, mp.pi)

    lo, hi, n = MPF("0.05"), ROD_LIMIT, 47
    grid = [lo + (hi - lo) * i / n for i in range(n + 1)]
    vals = [peak(x) for x in grid]
    j = min(range(n + 1), key=lambda i: vals[i])
    if j in (0, n):
        return {"lambda_opt": f(grid[j]), "on_bound": True,
                "peak_per_unit_force_m": f(vals[j]),
                "at_printed_lambda": f(peak(g["r"] / g["l_sh"]))}
    lam = golden_min(peak, grid[j - 1], grid[j + 1], 30)
    return {"lambda_opt": f(lam), "on_bound": False, "peak_per_unit_force_m": f(peak(lam)),
            "at_printed_lambda": f(peak(g["r"] / g["l_sh"]))}


def lambda_interior_minimum(g, stroke):
    """Pressure law, stroke held at `stroke` through the lever (l = S l_p / (2 r)),
    slider, inner sense. Per unit force the torque is
        f(phi, lambda) = e^{b (s - S)} s'(phi),   s = s_slider(phi; l_sh = r / lambda),
    for every variant whose peak is interior (phi* > phi_c): a, m, F and h drop
    out. The peak P(lambda) = max_phi f is attained at the root phi* of
    b s'^2 + s'' = 0 and is smooth in lambda (envelope theorem: P' = df/dlambda
    at phi*), so the least peak solves the two stationarity equations
        b s'^2 + s'' = 0,   d/dlambda [b (s - S) + ln s'] = 0   at (phi*, lambda*),
    found by nested bracketed roots at 30 digits (mp.diff for every derivative).
    Checked: golden section on P itself (a different method, lambda to ~1e-13);
    P at lambda* +- 1e-4 above P(lambda*); a scan of P over lambda in
    [0.05, 0.99] falling before lambda* and rising after it; the peak over
    [phi_c, pi] by max_on_interval equal to the interior value for every depth of
    Table 7.2 (phi_c < phi* at every h)."""
    r, lp = g["r"], g["l_p"]
    b = B_PER_M["cm"]

    def geo(lam):
        return dict(g, l_sh=r / lam, l=stroke * lp / (2 * r))

    def travel_at(lam):
        gg = geo(lam)
        return lambda p: s_slider(p, gg, "inner")

    def phi_star(lam):
        s = travel_at(lam)
        fn = lambda p: b * mp.diff(s, p) ** 2 + mp.diff(s, p, 2)
        pk = mp.findroot(lambda p: mp.diff(s, p, 2), (MPF("0.3"), MPF(2)), solver="anderson")
        roots = bracket_roots(fn, pk, mp.pi - MPF("1e-6"), 40)
        assert len(roots) == 1, roots
        return roots[0]

    def peak(lam):
        s = travel_at(lam)
        p = phi_star(lam)
        return mp.exp(b * (s(p) - stroke)) * mp.diff(s, p)

    def slope(lam):                                  # dP/dlambda = df/dlambda at phi*
        p = phi_star(lam)
        return mp.diff(lambda L: b * (travel_at(L)(p) - stroke) + mp.log(mp.diff(travel_at(L), p)), lam)

    lo, hi, n = MPF("0.05"), ROD_LIMIT, 47
    grid = [lo + (hi - lo) * i / n for i in range(n + 1)]
    vals = [peak(x) for x in grid]
    j = min(range(n + 1), key=lambda i: vals[i])
    assert 0 < j < n
    falls = all(vals[i + 1] < vals[i] for i in range(j - 1))
    rises = all(vals[i + 1] > vals[i] for i in range(j + 1, n))
    lam = mp.findroot(slope, (grid[j - 1], grid[j + 1]), solver="anderson")
    golden = golden_min(peak, grid[j - 1], grid[j + 1], 70)
    p_opt = peak(lam)
    ph = phi_star(lam)
    s = travel_at(lam)
    depths = sorted({v[0] for v in VARIANTS})
    worst_phc, worst_gap = MPF(0), MPF(0)
    for h_mm in depths:                              # the peak is interior for every depth
        h = MPF(h_mm) / 1000
        phc = compaction_start(s, stroke, h)
        worst_phc = max(worst_phc, phc)
        fn = lambda p: mp.exp(b * (s(p) - stroke)) * mp.diff(s, p)
        worst_gap = max(worst_gap, abs(max_on_interval(fn, phc, mp.pi) / p_opt - 1))
    q1 = 4 * MPF("0.035") * 1e6 * F_BRICK * mp.exp(b * MPF("0.020"))      # variant 1, Q_max
    return {"stroke_m": f(stroke), "lambda_opt": f(lam), "lambda_opt_digits": mp.nstr(lam, 20),
            "rod_length_at_r_m": f(r / lam), "rod_angle_deg": deg(mp.asin(lam)),
            "phi_star_deg": deg(ph), "peak_per_unit_force_m": f(p_opt),
            "golden_section_lambda": f(golden), "golden_minus_root": f(golden - lam),
            "peak_rise_at_lambda_pm_1e-4_rel": [f(peak(lam - MPF("1e-4")) / p_opt - 1),
                                                f(peak(lam + MPF("1e-4")) / p_opt - 1)],
            "scan_falls_before_and_rises_after": bool(falls and rises),
            "latest_compaction_start_deg": deg(worst_phc),
            "grid_peak_over_every_depth_vs_interior_rel": f(worst_gap),
            "variant1_peak_torque_Nm": f(q1 * p_opt),
            "at_printed_lambda": f(peak(r / g["l_sh"])), "at_lambda_0.7": f(peak(MPF("0.7"))),
            "scan": [[f(x), f(v)] for x, v in zip(grid, vals)]}


def mu_scan(g, h_mm):
    """Four-bar reading, inner sense, stroke and lambda held: the peak torque per
    unit force against mu = r / l_p (l = S l_p / (2 r) keeps the stroke)."""
    s_k = 2 * g["r"] * g["l"] / g["l_p"]
    h, b = MPF(h_mm) / 1000, B_PER_M["cm"]
    rows = []
    for pivot in ("same", "opposite"):
        for mu in ("0.05", "0.1", "0.25", "0.5"):
            lp = g["r"] / MPF(mu)
            gg = dict(g, l_p=lp, l=s_k * lp / (2 * g["r"]))
            s = lambda p: s_four_bar(p, gg, "inner", pivot)
            d1 = lambda p: mp.diff(s, p)
            phc = compaction_start(s, s_k, h)
            res = {"pivot": pivot, "mu": float(mu)}
            for force in FORCES:
                if force == "constant":
                    fn = d1
                else:
                    fn = lambda p: mp.exp(b * (h - (s_k - s(p)))) * d1(p) / mp.exp(b * h)
                res[force] = f(max_on_interval(fn, phc, mp.pi))
            rows.append(res)
    return rows


# ---- Exercise 6: roller forming, eqs (6.1)-(6.12) ------------------------------
TABLE_6_1 = [  # L, B, H [m], v_form [m/s], v_cart [m/s], passes N
    ("3.0", "2.0", "0.10", "0.004", "0.23", 8), ("4.0", "2.0", "0.10", "0.003", "0.24", 10),
    ("4.0", "1.5", "0.08", "0.002", "0.25", 6), ("4.0", "1.2", "0.08", "0.003", "0.26", 6),
    ("4.5", "1.0", "0.10", "0.004", "0.27", 8), ("4.0", "1.0", "0.12", "0.005", "0.24", 10),
    ("4.5", "1.2", "0.12", "0.004", "0.28", 10), ("4.0", "1.4", "0.10", "0.003", "0.29", 8),
    ("4.0", "1.4", "0.12", "0.002", "0.25", 8), ("5.0", "1.2", "0.10", "0.005", "0.26", 10),
    ("4.5", "1.0", "0.10", "0.003", "0.27", 8), ("5.0", "1.0", "0.10", "0.004", "0.28", 10),
    ("3.0", "2.0", "0.12", "0.005", "0.23", 10), ("5.0", "1.2", "0.12", "0.003", "0.26", 10),
    ("4.0", "1.2", "0.10", "0.002", "0.28", 8), ("4.5", "1.0", "0.12", "0.004", "0.29", 10),
    ("5.0", "1.2", "0.10", "0.003", "0.24", 8), ("4.5", "1.4", "0.12", "0.004", "0.25", 10),
    ("4.0", "1.2", "0.12", "0.002", "0.26", 10), ("5.0", "1.4", "0.10", "0.005", "0.27", 6),
    ("4.0", "1.4", "0.10", "0.004", "0.28", 8), ("4.5", "1.4", "0.10", "0.003", "0.26", 8),
    ("5.0", "1.2", "0.12", "0.004", "0.24", 10), ("3.0", "1.5", "0.12", "0.003", "0.25", 10),
]
EX6 = {  # values chosen where the guide gives a range (docs/design/crank_press.md)
    "f": MPF("0.35"), "f1": MPF("0.58"), "tau0": MPF(300), "rho0": MPF(2400), "g": MPF("9.81"),
    "R_over_H": MPF("1.1"),          # R/H >= 1.1: the least roller allowed
    "k1_stage": MPF("0.375"),        # (6.1), N > 3: 0.3..0.45, midpoint
    "t_pass": MPF("6.5"),            # (6.3) t_PR 5..8 s, midpoint
    "t_feed": MPF("0.75"),           # (6.3) t_zas 0.5..1.0 s, midpoint
    "alpha1_deg": MPF(30),           # (6.5)
    "k1_safety": MPF("1.3"),         # (6.5) 1..1.6, midpoint
    "delta": MPF("0.015"),           # (6.4) gap: printed 0.01..0.2 (read 0.01..0.02 m), midpoint
    "initial_factor": MPF("1.5"), "initial_share": MPF("0.5"),   # (6.6) 1.4..1.6, 0.4..0.6
    "t1": MPF(70), "V_C": MPF("0.002"), "n_rollers": 4, "t_stop": MPF(2),   # (6.6)-(6.8)
    "theta": MPF("0.3"), "E": MPF("250e4"), "nu": MPF("0.3"),              # (6.10)-(6.12)
}


def exercise6(sign, over=None):
    c = dict(EX6, **(over or {}))
    bite = mp.atan((c["f"] + c["f1"]) / (1 - c["f"] * c["f1"]))   # = atan f + atan f1
    rows = []
    for i, (L_, B_, H_, vf_, vp_, npass) in enumerate(TABLE_6_1, 1):
        L, B, H, vf, vp = (MPF(x) for x in (L_, B_, H_, vf_, vp_))
        R = c["R_over_H"] * H
        expo = sign * (npass - 1) / (c["k1_stage"] * npass)
        h_n = R * (1 - mp.cos(bite)) * mp.exp(expo)                        # (6.1)
        t_pf = c["t_pass"] - c["t_feed"]                                   # (6.3)
        L_p = vf * t_pf * H / h_n                                          # (6.2)
        k = 2 + mp.sin(c["alpha1_deg"] * mp.pi / 180)
        den = L_p * c["rho0"] * c["g"] - 2 * c["tau0"] * k
        a = 2 * L_p * c["tau0"] * k * c["k1_safety"] / den                 # (6.5)
        row = {"variant": i, "R_p": f(R), "h_n_min": f(h_n), "h_n_over_H": f(h_n / H),
               "L_p": f(L_p), "a_denominator_Pa": f(den)}
        if den <= 0:
            row["status"] = "infeasible: (6.5) denominator <= 0, no outlet width exists"
            rows.append(row)
            continue
        L_X = 2 * R + a + 2 * c["delta"]                                   # (6.4)
        row.update({"a": f(a), "L_X": f(L_X), "crank_radius": f(L_X / 2)})
        # (6.6)-(6.9): productivity, remaining length read as L - L_p
        t2 = L_p * H * B / (c["V_C"] * (c["n_rollers"] + 1))                # (6.7)
        t3 = (L_X / vp + c["t_stop"]) * npass                              # (6.8)
        L_rest = L - L_p
        t4 = L_rest / vf                                                   # (6.9)
        prod = (c["initial_factor"] * L_p * B * H / (c["t1"] + t2 + t3)
                + (L_rest - c["initial_share"] * L_p) * B * H / t4)        # (6.6)
        # (6.10)-(6.12): capture angle from the fed layer, cos(phi) = 1 - h_n / R
        ph = mp.acos(1 - h_n / R)
        l_k = R * mp.sin(ph) / (1 - c["theta"])                            # (6.11)
        Fk = L_p * c["E"] * mp.sin(ph) ** 2 * (1 - c["theta"]) / (
            MPF("14.14") * (1 - c["nu"] ** 2) * c["theta"])                # (6.12), as printed
        N = (1 - 2 * c["theta"]) / (3 * R) * Fk * (2 * l_k + 3 * R * c["f"]) * vp * c["n_rollers"]
        t4_alt = MPF("0.35") / vf                                          # L_rest as printed (0.2..0.5 m)
        prod_alt = (c["initial_factor"] * L_p * B * H / (c["t1"] + t2 + t3)
                    + (MPF("0.35") - c["initial_share"] * L_p) * B * H / t4_alt)
        row.update({"t2": f(t2), "t3": f(t3), "t4": f(t4), "productivity_m3_per_s": f(prod),
                    "productivity_m3_per_s_L_rest_0.35m": f(prod_alt),
                    "capture_angle_deg": deg(ph), "l_K": f(l_k), "F_as_printed": f(Fk),
                    "N_compaction_W_as_printed": f(N), "status": "ok"})
        rows.append(row)
    return {"bite_angle_deg": deg(bite), "bite_limit_printed_1_minus_f_minus_f1_deg":
            deg(mp.atan((c["f"] + c["f1"]) / (1 - c["f"] - c["f1"]))),
            "chosen": {k: f(v) for k, v in EX6.items()}, "variants": rows}


def exercise6_ranges(delta=("0.01", "0.02")):
    """L_X over every corner of the guide's ranges. The gap delta is printed
    "0.01...0.2"; the default corners read it 0.01..0.02 m, ("0.01", "0.2")
    takes the print literally."""
    import itertools
    corners = {"k1_stage": ("0.3", "0.45"), "t_pass": ("5", "8"), "t_feed": ("0.5", "1.0"),
               "k1_safety": ("1", "1.6"), "delta": delta}
    lo = [None] * len(TABLE_6_1)
    hi = [None] * len(TABLE_6_1)
    for combo in itertools.product(*corners.values()):
        over = {k: MPF(v) for k, v in zip(corners, combo)}
        for i, row in enumerate(exercise6(-1, over)["variants"]):
            x = row["L_X"]
            lo[i] = x if lo[i] is None else min(lo[i], x)
            hi[i] = x if hi[i] is None else max(hi[i], x)
    return [{"variant": i + 1, "L_X_min": lo[i], "L_X_max": hi[i]} for i in range(len(lo))]


def exercise6_gap_and_dwell():
    """The printed gap range against the rollers it clears, and the stop t_ost of
    (6.8) against a crank drive, which has no dwell (t_ost = 0)."""
    base = exercise6(-1)["variants"]
    printed = exercise6_ranges(("0.01", "0.2"))
    at_02 = exercise6(-1, {"delta": MPF("0.2")})["variants"]
    no_dwell = exercise6(-1, {"t_stop": MPF(0)})["variants"]
    span = lambda xs: [min(xs), max(xs)]
    return {"printed_delta_0.01_0.2": {
                "L_X_over_corners": span([x for r in printed for x in (r["L_X_min"], r["L_X_max"])]),
                "at_delta_0.2_m": {"L_X": span([r["L_X"] for r in at_02]),
                                   "crank_radius": span([r["crank_radius"] for r in at_02]),
                                   "gaps_over_stroke": span([0.4 / r["L_X"] for r in at_02]),
                                   "gap_over_roller_diameter": span([0.2 / (2 * r["R_p"]) for r in at_02])}},
            "read_delta_0.01_0.02": {
                "L_X_over_corners": span([x for r in exercise6_ranges() for x in (r["L_X_min"], r["L_X_max"])]),
                "crank_radius_at_0.015": span([r["crank_radius"] for r in base])},
            "dwell": {"t3_with_t_ost_2s": span([r["t3"] for r in base]),
                      "t_ost_share_of_t3": span([2 * TABLE_6_1[i][5] / r["t3"] for i, r in enumerate(base)]),
                      "t3_crank_no_dwell": span([r["t3"] for r in no_dwell]),
                      "productivity_gain_no_dwell": span([n["productivity_m3_per_s"] /
                                                          r["productivity_m3_per_s"] - 1
                                                          for n, r in zip(no_dwell, base)])}}


def main():
    tables = press_tables()
    dense = dense_check(tables)
    opt = {}
    for name in PRESSES:
        for h_mm in (20, 50):
            for force in FORCES:
                opt["%s/h=%dmm/%s" % (name, h_mm, force)] = lambda_optimum(PRESSES[name], h_mm, force)
    interior = {}
    for name, g in PRESSES.items():
        for label, stroke in (("printed", g["S_printed"]), ("kinematic", 2 * g["r"] * g["l"] / g["l_p"])):
            interior["%s/stroke_%s" % (name, label)] = lambda_interior_minimum(g, stroke)
    mus = {name: mu_scan(PRESSES[name], 20) for name in PRESSES}
    for name in tables:
        del tables[name]["_kin"]
    out = {"source": "tests/ref/crank_press_ref.py (mpmath %d digits)" % mp.mp.dps,
           "constants": {"F_brick_m2": f(F_BRICK), "b_per_m": {k: f(v) for k, v in B_PER_M.items()},
                         "eta": f(ETA), "overload": f(OVERLOAD)},
           "default_reading": {"depth_unit": "cm", "pressing_end": "inner",
                               "lever": "slider", "force": "pressure_law"},
           "presses": tables, "dense_grid_check": dense,
           "lambda_optimum_stroke_held_inner_slider": opt,
           "lambda_interior_minimum_pressure_law": interior,
           "mu_scan_four_bar_inner_h20mm": mus,
           "exercise6": {"feed_exponent_negative": exercise6(-1),
                         "feed_exponent_as_printed": exercise6(+1),
                         "L_X_over_guide_ranges": exercise6_ranges(),
                         "gap_and_dwell": exercise6_gap_and_dwell()}}
    out["seconds"] = round(time.time() - T0, 1)
    json.dump(out, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()
