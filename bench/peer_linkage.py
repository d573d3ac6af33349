#!/usr/bin/env python3
"""Peer baseline for the general planar linkage (`problem: linkage`,
docs/design/linkage.md): the same group-by-group closed-form solution written
as a user would in numpy/scipy, vectorised over an array of crank angles.

- Reads the same YAML (PyYAML; `gravity: on` arrives as True) and the units
  these configs use (m, deg, rad, rev/min, rad/s, kg, kg/m, kg m^2, N, kN,
  N m, a table's `unit: [m, kN]` columns). Supports ground points, the crank
  (phase, speed, sense), links with a length, local points, mass/cg/inertia
  or mass_per_length (uniform bar), slider lines fixed to the ground, RRR /
  RRP / RPR groups with the design's branch conventions (`branch` or `near`),
  loads: a force on a slider (constant or a table over its position) with
  `when: forward|return|always` (forward: ds/dphi > 0) or `opposing: true`,
  a constant torque on a link; gravity 9.80665 m/s^2 along -y.
- Positions are second-order jets in the crank angle phi (value, d/dphi,
  d2/dphi2 as numpy arrays over the angles, exact arithmetic rules: no finite
  differences), so transfer functions are exact to round-off.
- Driving torque by virtual power: M = w^2 sum(m G''.G' + J t'' t')
  + g sum m G'_y - sum(loads' generalised forces).
- Cycle metrics: a grid of `GRID` angles; the peak |M| and each output's peak
  |acceleration| refined by scipy's bounded Brent (minimize_scalar, xatol
  1e-10) on every grid local maximum within 10% of the grid's largest; each
  output's extremes (x' = 0; stroke = max - min, link angles unwrapped) and
  the loads' kinks (s' = 0 of a `when`/opposing slider, s = a table row) by
  Newton with the jets' exact derivative, all brackets batched in one solve
  an iteration (bisection when a step leaves its grid cell); mean and RMS
  torque by Gauss-Legendre with `GAUSS` nodes on every piece between kinks
  (pieces <= pi/4).

evaluate(model) is the timed part: everything numerical at one design; the
YAML is read once by load(path). main() prints, per config, the metrics,
their relative errors against tests/ref/linkage_ref.json (mpmath, 30 digits)
and the median time of evaluate() (peer_timing.timed: timeit autorange, median
of 5 repeats), as JSON rows {case: {seconds, value, error, ...}} like the
other peers; --check adds the Gauss convergence (GAUSS vs 2 GAUSS nodes).

Measured (a shared 2-core container, load ~2.8, GRID 64, GAUSS 24, numpy
1.24, scipy 1.10), relative errors against the reference (the mean torque:
relative to the rms, the six-bars' mean being 0):
  watt2_sixbar:       peak torque 1.1e-15, rms 1.6e-16, mean 1.8e-16,
                      rocker2 stroke 4.7e-16, peak accel 1.2e-16
  stephenson3_sixbar: peak torque 3.7e-16, rms 2.8e-15, mean 1.6e-16,
                      slider stroke 5.2e-16 and peak accel 6.3e-16,
                      rocker stroke 0 and peak accel 1.7e-16
  whitworth_shaper:   peak torque 1.4e-16, rms 2.7e-16, mean 5.4e-16,
                      ram stroke 0, peak accel 2.3e-16
Gauss 24 vs 48 nodes a piece: the rms changes by <= 9e-16. Without the split
at the kinks (one piece per pi/4, 192 / 768 nodes) the rms is only 5e-7 / 1e-7
(Stephenson: table rows) and 7e-9 / 7e-10 (shaper: the `when` switch) off.
evaluate(): 12-27 ms a config (peer_timing.timed medians over runs; the
machine's load moves them by 2x), about 35-50 solves: one over the 64-point
grid, one over the Gauss nodes, 4-5 batched Newton steps for the kinks and
the extremes, ~23-38 one-angle solves inside scipy's bounded Brent.
"""
import argparse
import json
import math
import os
import re

import numpy as np
import yaml
from scipy import optimize

from peer_timing import timed

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
G_STD = 9.80665
GRID = 64
GAUSS = 24
MAX_PIECE = math.pi / 4
UNITS = {"": 1.0, "m": 1.0, "mm": 1e-3, "rad": 1.0, "deg": math.pi / 180, "rad/s": 1.0,
         "rev/min": math.pi / 30, "rpm": math.pi / 30, "kg": 1.0, "kg/m": 1.0, "kg m^2": 1.0,
         "N": 1.0, "kN": 1e3, "N m": 1.0, "kN m": 1e3}
CONFIGS = ("watt2_sixbar", "stephenson3_sixbar", "whitworth_shaper")


# ---------------------------------------------------------------- description

def num(x, unit=None):
    """A quantity ("0.2 m", "90 rev/min") in SI; a bare number is SI (or in `unit`)."""
    if isinstance(x, bool) or x is None:
        raise ValueError(f"not a quantity: {x!r}")
    if isinstance(x, (int, float)):
        return float(x) * (UNITS[unit] if unit else 1.0)
    m = re.fullmatch(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*", str(x))
    if not m or m.group(2) not in UNITS:
        raise ValueError(f"cannot read the quantity {x!r}")
    return float(m.group(1)) * UNITS[m.group(2) or (unit or "")]


def pair(x):
    return (num(x[0]), num(x[1]))


def flag(x):
    return x is True or (isinstance(x, str) and x.lower() in ("on", "true", "yes"))


def load(path):
    """The model of a `problem: linkage` config: plain numbers, read once."""
    with open(path) as f:
        cfg = yaml.safe_load(f)
    m = cfg["model"]
    cr = m["crank"]
    model = {
        "name": os.path.splitext(os.path.basename(path))[0],
        "gravity": G_STD if flag(m.get("gravity", False)) else 0.0,
        "ground": {k: pair(v) for k, v in m.get("ground", {}).items()},
        "crank": {"link": cr["link"], "pivot": cr["pivot"], "joint": cr["joint"],
                  "phase": num(cr.get("phase", 0)), "speed": num(cr["speed"]),
                  "sense": {"ccw": 1.0, "cw": -1.0}[cr.get("sense", "ccw")]},
        "links": {}, "groups": [], "loads": [], "outputs": list(m.get("outputs", []))}
    for name, d in m["links"].items():
        lk = {"length": num(d["length"]) if "length" in d else None,
              "points": {p: pair(v) for p, v in d.get("points", {}).items()},
              "offset": num(d.get("offset", 0)), "mass": 0.0, "cg": (0.0, 0.0), "inertia": 0.0}
        if "mass" in d and "mass_per_length" in d:
            raise ValueError(f"link {name}: mass and mass_per_length")
        if "mass_per_length" in d:
            L = lk["length"]
            lk["mass"] = num(d["mass_per_length"]) * L
            lk["cg"], lk["inertia"] = (L / 2, 0.0), lk["mass"] * L * L / 12
        elif "mass" in d:
            lk["mass"] = num(d["mass"])
            lk["cg"] = pair(d["cg"]) if "cg" in d else (0.0, 0.0)
            lk["inertia"] = num(d.get("inertia", 0))
        if "line" in d:
            ln = d["line"]
            if ln.get("fixed_to", "ground") != "ground":
                raise NotImplementedError(f"link {name}: a line fixed to {ln['fixed_to']}")
            lk["line"] = {"through": ln["through"], "angle": num(ln.get("angle", 0)),
                          "offset": num(ln.get("offset", 0))}
        model["links"][name] = lk
    for g in m["groups"]:
        rec = {"type": g["type"], "links": list(g["links"])}
        if g["type"] == "RRR":
            rec.update(from_=list(g["from"]), joint=g["joint"])
        elif g["type"] == "RRP":
            rec.update(from_=[g["from"]], joint=g["joint"])
        elif g["type"] == "RPR":
            rec.update(from_=[g["from"]], pivot=g["pivot"])
        else:
            raise NotImplementedError(f"group {g['type']}")
        if g["type"] != "RPR":
            if ("branch" in g) == ("near" in g):
                raise ValueError(f"group {g['links']}: give exactly one of branch, near")
            rec["branch"] = float(g["branch"]) if "branch" in g else None
            rec["near"] = pair(g["near"]) if "near" in g else None
        model["groups"].append(rec)
    for key, d in (m.get("loads") or {}).items():
        ld = {"key": key, "link": d["link"], "when": d.get("when", "always"),
              "opposing": flag(d.get("opposing", False))}
        if ld["when"] not in ("forward", "return", "always"):
            raise ValueError(f"load {key}: when {ld['when']}")
        if "torque" in d:
            ld.update(kind="torque", value=num(d["torque"]))
        elif "force" in d:
            ld.update(kind="force", value=num(d["force"]))
        elif "table" in d:
            tb = d["table"]
            if tb.get("over") != "position":
                raise NotImplementedError(f"load {key}: table over {tb.get('over')}")
            ux, uf = tb.get("unit", ["", ""])
            rows = sorted((num(r[0], ux), num(r[1], uf)) for r in tb["rows"])
            ld.update(kind="table", xs=np.array([r[0] for r in rows]), fs=np.array([r[1] for r in rows]))
        else:
            raise NotImplementedError(f"load {key}: {sorted(d)}")
        model["loads"].append(ld)
    resolve_branches(model)
    return model


# ---------------------------------------------------------------- jets

class Jet:
    """A value with its first and second derivatives in phi (numpy arrays)."""
    __slots__ = ("v", "d", "dd")

    def __init__(self, v, d, dd):
        self.v, self.d, self.dd = v, d, dd

    def __add__(a, b):
        if isinstance(b, Jet):
            return Jet(a.v + b.v, a.d + b.d, a.dd + b.dd)
        return Jet(a.v + b, a.d, a.dd)
    __radd__ = __add__

    def __sub__(a, b):
        if isinstance(b, Jet):
            return Jet(a.v - b.v, a.d - b.d, a.dd - b.dd)
        return Jet(a.v - b, a.d, a.dd)

    def __rsub__(a, b):
        return Jet(b - a.v, -a.d, -a.dd)

    def __neg__(a):
        return Jet(-a.v, -a.d, -a.dd)

    def __mul__(a, b):
        if isinstance(b, Jet):
            return Jet(a.v * b.v, a.d * b.v + a.v * b.d, a.dd * b.v + 2 * a.d * b.d + a.v * b.dd)
        return Jet(a.v * b, a.d * b, a.dd * b)
    __rmul__ = __mul__

    def __truediv__(a, b):
        if isinstance(b, Jet):
            q = a.v / b.v
            qd = (a.d - q * b.d) / b.v
            return Jet(q, qd, (a.dd - 2 * qd * b.d - q * b.dd) / b.v)
        return Jet(a.v / b, a.d / b, a.dd / b)

    def __rtruediv__(a, b):
        q = b / a.v
        qd = -q * a.d / a.v
        return Jet(q, qd, -(2 * qd * a.d + q * a.dd) / a.v)

    def sqrt(a):
        r = np.sqrt(a.v)
        rd = a.d / (2 * r)
        return Jet(r, rd, (a.dd - 2 * rd * rd) / (2 * r))


def const(c, n):
    return Jet(np.full(n, c), np.zeros(n), np.zeros(n))


class Frame:
    """A link's frame: origin (x, y) jets, unit x axis (ex, ey) jets."""
    __slots__ = ("ox", "oy", "ex", "ey")

    def __init__(self, ox, oy, ex, ey):
        self.ox, self.oy, self.ex, self.ey = ox, oy, ex, ey

    def point(self, u, v):
        return (self.ox + u * self.ex - v * self.ey, self.oy + u * self.ey + v * self.ex)

    def angle(self):
        """(t, t', t''): t wrapped to (-pi, pi]; t' = e x e', t'' = e x e''."""
        ex, ey = self.ex, self.ey
        return (np.arctan2(ey.v, ex.v), ex.v * ey.d - ey.v * ex.d, ex.v * ey.dd - ey.v * ex.dd)


# ---------------------------------------------------------------- the chain

def rrr(P, Q, a, b, branch):
    dx, dy = Q[0] - P[0], Q[1] - P[1]
    D2 = dx * dx + dy * dy
    al = (D2 + (a * a - b * b)) / D2 * 0.5          # along / D
    h = (a * a / D2 - al * al).sqrt() * branch       # h / D
    return (P[0] + al * dx - h * dy, P[1] + al * dy + h * dx)


def rrp(P, line, a, branch):
    T, ux, uy, off = line
    wx, wy = P[0] - (T[0] - off * uy), P[1] - (T[1] + off * ux)
    wn = wy * ux - wx * uy
    s = (wx * ux + wy * uy) + (a * a - wn * wn).sqrt() * branch
    return s, (T[0] - off * uy + s * ux, T[1] + off * ux + s * uy)


def rpr(A, Q, off):
    dx, dy = A[0] - Q[0], A[1] - Q[1]
    d2 = dx * dx + dy * dy
    s = (d2 - off * off).sqrt()
    return s, ((s * dx + off * dy) / d2, (s * dy - off * dx) / d2)


def line_of(model, name, pts):
    ln = model["links"][name]["line"]
    T = model["ground"][ln["through"]] if ln["through"] in model["ground"] else None
    if T is None:
        raise NotImplementedError(f"line of {name}: through a moving point")
    return (T, math.cos(ln["angle"]), math.sin(ln["angle"]), ln["offset"])


def resolve_branches(model):
    """`near`: the branch whose joint lies nearer the point at phi = 0."""
    for g in model["groups"]:
        if g["type"] != "RPR" and g["branch"] is None:
            best = None
            for br in (1.0, -1.0):
                g["branch"] = br
                st = solve(model, np.zeros(1))
                x, y = st["points"][g["joint"]]
                dist = (x.v[0] - g["near"][0]) ** 2 + (y.v[0] - g["near"][1]) ** 2
                if best is None or dist < best[0]:
                    best = (dist, br)
            g["branch"] = best[1]


def solve(model, phi):
    """Every point, link frame and slider coordinate as jets at the angles phi."""
    n = phi.shape[0]
    cr = model["crank"]
    pts = {k: (const(x, n), const(y, n)) for k, (x, y) in model["ground"].items()}
    frames, sliders = {}, {}
    t = cr["phase"] + cr["sense"] * phi
    c, s = np.cos(t), np.sin(t)
    w = cr["sense"]
    e = (Jet(c, -w * s, -c), Jet(s, w * c, -s))    # sense^2 = 1
    O = pts[cr["pivot"]]
    L = model["links"][cr["link"]]["length"]
    pts[cr["joint"]] = (O[0] + L * e[0], O[1] + L * e[1])
    fixed_links = []

    def place(name, fr):
        frames[name] = fr
        for p, (u, v) in model["links"][name]["points"].items():
            pts[p] = fr.point(u, v)

    place(cr["link"], Frame(O[0], O[1], e[0], e[1]))
    for g in model["groups"]:
        l1, l2 = g["links"]
        if g["type"] == "RRR":
            P, Q = pts[g["from_"][0]], pts[g["from_"][1]]
            a, b = model["links"][l1]["length"], model["links"][l2]["length"]
            B = rrr(P, Q, a, b, g["branch"])
            pts[g["joint"]] = B
            place(l1, Frame(P[0], P[1], (B[0] - P[0]) * (1 / a), (B[1] - P[1]) * (1 / a)))
            place(l2, Frame(Q[0], Q[1], (B[0] - Q[0]) * (1 / b), (B[1] - Q[1]) * (1 / b)))
        elif g["type"] == "RRP":
            P = pts[g["from_"][0]]
            a = model["links"][l1]["length"]
            line = line_of(model, l2, pts)
            sc, B = rrp(P, line, a, g["branch"])
            pts[g["joint"]] = B
            sliders[l2] = sc
            place(l1, Frame(P[0], P[1], (B[0] - P[0]) * (1 / a), (B[1] - P[1]) * (1 / a)))
            place(l2, Frame(B[0], B[1], const(line[1], n), const(line[2], n)))
            fixed_links.append(l2)
        else:  # RPR: block l1 pinned at A slides on guide l2 about Q
            A, Q = pts[g["from_"][0]], pts[g["pivot"]]
            sc, u = rpr(A, Q, model["links"][l2]["offset"])
            sliders[l1] = sc
            place(l2, Frame(Q[0], Q[1], u[0], u[1]))
            place(l1, Frame(A[0], A[1], u[0], u[1]))
    return {"points": pts, "frames": frames, "sliders": sliders, "fixed": fixed_links}


def torque(model, st):
    """Driving torque at constant speed by virtual power, in the crank's sense."""
    w2, g = model["crank"]["speed"] ** 2, model["gravity"]
    M = 0.0
    for name, lk in model["links"].items():
        fr = st["frames"][name]
        if lk["mass"]:
            Gx, Gy = fr.point(*lk["cg"])
            M = M + lk["mass"] * (w2 * (Gx.dd * Gx.d + Gy.dd * Gy.d) + g * Gy.d)
        if lk["inertia"] and name not in st["fixed"]:
            _, td, tdd = fr.angle()
            M = M + w2 * lk["inertia"] * tdd * td
    for ld in model["loads"]:
        if ld["kind"] == "torque":
            rate = st["frames"][ld["link"]].angle()[1]
            F = ld["value"]
        else:
            sc = st["sliders"][ld["link"]]
            rate = sc.d
            F = ld["value"] if ld["kind"] == "force" else np.interp(sc.v, ld["xs"], ld["fs"])
        if ld["opposing"]:
            F = -abs(F) * np.sign(rate)
        if ld["when"] == "forward":
            F = np.where(rate > 0, F, 0.0)
        elif ld["when"] == "return":
            F = np.where(rate < 0, F, 0.0)
        M = M - F * rate
    return M


def output(model, st, name):
    """(coordinate, d, dd) of an output: a slider's s, a link's angle."""
    if name in st["sliders"]:
        sc = st["sliders"][name]
        return sc.v, sc.d, sc.dd
    return st["frames"][name].angle()


# ---------------------------------------------------------------- cycle metrics

def at(model, p):
    return solve(model, np.array([p]))


def grid_peaks(vals, frac=0.9):
    """Indices of the periodic grid's local maxima within frac of the largest."""
    top = vals.max()
    loc = (vals >= np.roll(vals, 1)) & (vals >= np.roll(vals, -1)) & (vals >= frac * top)
    return np.nonzero(loc)[0]


def refine_max(f, phis, vals, h):
    """The largest of f, refined by bounded Brent around each grid candidate."""
    best = vals.max()
    for k in grid_peaks(vals):
        r = optimize.minimize_scalar(lambda p: -f(p), bounds=(phis[k] - h, phis[k] + h),
                                     method="bounded", options={"xatol": 1e-10})
        best = max(best, -r.fun)
    return best


def brackets(vals, phis):
    """Grid cells [a, a + h] where vals changes sign (periodic), and the sign at a."""
    nxt = np.roll(vals, -1)
    ks = np.nonzero((vals > 0) & (nxt <= 0) | (vals < 0) & (nxt >= 0))[0]
    return [(phis[k], phis[k] + (phis[1] - phis[0]), np.sign(vals[k])) for k in ks]


def newton_roots(model, probs):
    """Roots of every problem (a, b, sign of f(a), fn) at once: fn(state) gives
    (f, f') over the batch (exact: f' from the jets), one solve per iteration;
    Newton kept inside its bracket (bisection when a step leaves it)."""
    if not probs:
        return np.zeros(0)
    a = np.array([p[0] for p in probs])
    b = np.array([p[1] for p in probs])
    sa = np.array([p[2] for p in probs])
    x = (a + b) / 2
    for _ in range(100):
        st = solve(model, x)
        f, fd = np.empty_like(x), np.empty_like(x)
        for i, p in enumerate(probs):
            fi, fdi = p[3](st)
            f[i], fd[i] = fi[i], fdi[i]
        left = np.sign(f) == sa
        a, b = np.where(left, x, a), np.where(left, b, x)
        with np.errstate(divide="ignore", invalid="ignore"):
            xn = x - f / fd
        bad = ~np.isfinite(xn) | (xn < a) | (xn > b)
        xn = np.where(bad, (a + b) / 2, xn)
        xn[f == 0] = x[f == 0]
        done = np.all(np.abs(xn - x) < 1e-11)
        x = xn
        if done:  # the last step was below 1e-11: Newton's error now ~1e-20
            break
    return x


def kink_problems(model, phis, st):
    """The loads' kinks: s' = 0 (when-switch, opposing), s = a table row."""
    out = []
    for ld in model["loads"]:
        n = ld["link"]
        if ld["kind"] == "torque":
            if ld["when"] != "always" or ld["opposing"]:
                fn = lambda s, n=n: s["frames"][n].angle()[1:]
                out += [(a, b, sg, fn) for a, b, sg in brackets(fn(st)[0], phis)]
            continue
        sc = st["sliders"][n]
        if ld["when"] != "always" or ld["opposing"]:
            fn = lambda s, n=n: (s["sliders"][n].d, s["sliders"][n].dd)
            out += [(a, b, sg, fn) for a, b, sg in brackets(sc.d, phis)]
        if ld["kind"] == "table":
            for x in ld["xs"]:
                fn = lambda s, n=n, x=x: (s["sliders"][n].v - x, s["sliders"][n].d)
                out += [(a, b, sg, fn) for a, b, sg in brackets(sc.v - x, phis)]
    return out


def pieces(kk):
    """[a, b] pieces of [0, 2 pi) (or of a period starting at the first kink) no longer than MAX_PIECE."""
    edges = list(kk) + [kk[0] + 2 * math.pi] if kk else [0.0, 2 * math.pi]
    out = []
    for a, b in zip(edges[:-1], edges[1:]):
        m = max(1, math.ceil((b - a) / MAX_PIECE))
        out += [(a + (b - a) * i / m, a + (b - a) * (i + 1) / m) for i in range(m)]
    return out


_LEGGAUSS = {}


def gauss_means(model, kk, nodes):
    """Mean and RMS torque: Gauss-Legendre on every piece between kinks."""
    if nodes not in _LEGGAUSS:  # nodes and weights: set up once, like the YAML
        _LEGGAUSS[nodes] = np.polynomial.legendre.leggauss(nodes)
    x, wq = _LEGGAUSS[nodes]
    ps = pieces(kk)
    a = np.array([p[0] for p in ps])[:, None]
    b = np.array([p[1] for p in ps])[:, None]
    phi = ((a + b) / 2 + (b - a) / 2 * x[None, :]).ravel()
    wt = ((b - a) / 2 * wq[None, :]).ravel() / (2 * math.pi)
    M = torque(model, solve(model, phi))
    return float(wt @ M), math.sqrt(float(wt @ (M * M)))


def evaluate(model, grid=GRID, nodes=GAUSS):
    """The timed part: every metric at the model's design."""
    h = 2 * math.pi / grid
    phis = np.arange(grid) * h
    st = solve(model, phis)
    M = torque(model, st)
    w = model["crank"]["speed"]
    res = {"peak_drive_torque": refine_max(lambda p: abs(torque(model, at(model, p))[0]), phis, np.abs(M), h)}
    # one batch of roots: the loads' kinks and the outputs' extremes (x' = 0)
    probs = kink_problems(model, phis, st)
    nk = len(probs)
    owner = []
    for name in model["outputs"]:
        fn = lambda s, name=name: output(model, s, name)[1:]
        br = brackets(fn(st)[0], phis)
        probs += [(a, b, sg, fn) for a, b, sg in br]
        owner += [name] * len(br)
    r = newton_roots(model, probs)
    kk = sorted(set(np.mod(r[:nk], 2 * math.pi)))
    res["mean_drive_torque"], res["rms_drive_torque"] = gauss_means(model, kk, nodes)
    sr = solve(model, r[nk:]) if len(r) > nk else None
    for name in model["outputs"]:
        x, xd, xdd = output(model, st, name)
        slider = name in st["sliders"]
        xu = x if slider else np.unwrap(x)
        ext = [xu.max(), xu.min()]
        if sr is not None:
            xr = output(model, sr, name)[0]
            for i, o in enumerate(owner):
                if o == name:
                    v = xr[i]
                    if not slider:  # the unwrapped branch nearest the grid's
                        k = int(round(r[nk + i] / h)) % grid
                        v += 2 * math.pi * round((xu[k] - v) / (2 * math.pi))
                    ext.append(v)
        res[f"{name}_stroke"] = max(ext) - min(ext)
        res[f"{name}_peak_acceleration"] = w * w * refine_max(
            lambda p: abs(output(model, at(model, p), name)[2][0]), phis, np.abs(xdd), h)
    res["kinks"] = len(kk)
    return res


# ---------------------------------------------------------------- report

def reference_values(ref, name, model):
    c = ref["configs"][name]
    out = {"peak_drive_torque": c["cycle"]["peak_drive_torque"]["value"],
           "mean_drive_torque": c["cycle"]["mean_drive_torque"],
           "rms_drive_torque": c["cycle"]["rms_drive_torque"]}
    for o in model["outputs"]:
        out[f"{o}_stroke"] = c["outputs"][o]["stroke"]
        out[f"{o}_peak_acceleration"] = c["outputs"][o]["peak_acceleration"]["value"]
    return {k: float(v) for k, v in out.items()}


def rel(a, b, scale):
    return abs(a - b) / max(abs(b), scale)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--check", action="store_true", help="also the Gauss convergence (GAUSS vs 2 GAUSS)")
    args = ap.parse_args()
    with open(os.path.join(ROOT, "tests", "ref", "linkage_ref.json")) as f:
        ref = json.load(f)
    out = {}
    for name in CONFIGS:
        model = load(os.path.join(ROOT, "configs", "linkage", name + ".yaml"))
        evaluate(model)  # warm: the Gauss nodes
        seconds, res = timed(lambda: evaluate(model))
        refs = reference_values(ref, name, model)
        # the mean is zero for the conservative six-bars: relative to the rms
        errs = {k: rel(res[k], v, refs["rms_drive_torque"] if k == "mean_drive_torque" else 0.0)
                for k, v in refs.items()}
        row = {"seconds": seconds, "value": res["peak_drive_torque"], "error": errs["peak_drive_torque"],
               "metrics": {k: v for k, v in res.items()}, "errors": errs,
               "max_error": max(errs.values())}
        if args.check:
            hi = evaluate(model, nodes=2 * GAUSS)
            row["gauss_change_rms"] = rel(res["rms_drive_torque"], hi["rms_drive_torque"], 0.0)
        out[f"linkage_{name}"] = row
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
