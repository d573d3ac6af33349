#!/usr/bin/env python3
"""Peer baseline for the batch DOE of the recuperative drive (seed 000): what a
user would write with chunked, vectorised numpy for the study of
/work/wt/peer_ref/config.yaml -- 10^6 unscrambled Sobol points over (rod
length, phase shift, crank radius, offset), every recuperative_drive metric
per design, rows written to SQLite -- at mechopt's accuracy:
  * cycle mean of T: periodic trapezoid on n = auto_cycle_points points
    (n = 45/acosh(l/(r+|e|)) rounded up to a multiple of 4, 16..4096; designs
    are grouped by n rounded up to 4 sizes per octave, never fewer points);
  * cycle means of M and M^2 (opposes_motion: |dx/dphi| kinks at the dead
    centres): Gauss-Legendre on each arc between the four dead centres (found
    in closed form, crank and rod collinear), max(12, 2 n L / 2 pi) nodes an
    arc as in mechopt (mechopt caps them at 128; see --gl-cap);
  * peaks of T and |M|: every grid local maximum that could be the highest
    (mechopt's margin rule), refined by a vectorised bracketed root search
    (Illinois regula falsi, bisection when it stalls) on the angle derivative:
    dT/dphi in closed form, dM/dphi by complex step.
Single thread. Prints one JSON object (rates in designs per second).
"""
import argparse
import os

os.environ.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")

import json  # noqa: E402
import math  # noqa: E402
import shutil  # noqa: E402
import sqlite3  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402
from scipy.stats import qmc  # noqa: E402

# Model of the config (the rest are recuperative_drive defaults: layout
# opposed, exact kinematics, rod as point masses).
W = 100 * math.pi / 30          # crank speed [rad/s]
MASS, Q = 1000.0, 80.0          # cart mass [kg], rod mass per length [kg/m]
FORCE = 3562.0 / 0.9            # F_B / eta [N]
# Factors in config order: rod_length, phase_shift, crank_radius, offset.
LO = np.array([0.3, 0.0, 0.1, -0.1])
HI = np.array([1.6, math.pi, 0.3, 0.1])
METRICS = ["peak_kinetic_energy", "mean_kinetic_energy", "least_mean_kinetic_energy", "k1", "k2",
           "k3", "peak_crank_torque", "mean_crank_torque", "rms_crank_torque", "crank_rod_ratio"]
FACTORS = ["rod_length", "phase_shift", "crank_radius", "offset"]
TWO_PI = 2 * math.pi


def drive(c, s, r, l, e, cd, sd):
    """T, dT/dphi and the resistance moment F/eta (|dx1| + |dx2|) at crank angle
    phi (c = cos phi, s = sin phi), seed 000 eqs (1)-(11), (16)-(21); broadcasts
    over designs x angles, and takes complex angles (then |dx| -> sign(Re dx) dx
    so that the complex step differentiates it)."""
    mv2 = mva = stat = 0
    for sg, cc, ss in ((1.0, c, s), (-1.0, c * cd - s * sd, s * cd + c * sd)):  # slider 2 mirrored
        h = r * ss + e                    # rod's vertical extent
        dh = r * cc
        k = 1 / np.sqrt(l * l - h * h)    # 1 / horizontal extent
        g = h * dh * k
        dx = -r * ss - sg * g             # slider d/dphi
        ddx = -r * cc - sg * (dh * dh - h * r * ss + g * g) * k
        dxs, ddxs = 0.5 * (dx - r * ss), 0.5 * (ddx - r * cc)  # rod centre
        mv2 = mv2 + MASS * dx * dx + Q * l * (dxs * dxs + 0.25 * dh * dh)
        mva = mva + MASS * dx * ddx + Q * l * (dxs * ddxs - 0.25 * dh * r * ss)
        stat = stat + (np.sign(dx.real) * dx if np.iscomplexobj(dx) else np.abs(dx))
    return 0.5 * W * W * mv2, W * W * mva, FORCE * stat


def energy_slope(phi, p):
    return drive(np.cos(phi), np.sin(phi), *p)[1]


def abs_moment_slope(phi, p, step=1e-30):
    """d|M|/dphi by complex step (exact to roundoff, kinks on either side)."""
    z = phi + 1j * step
    T, Mi, Ms = drive(np.cos(z), np.sin(z), *p)
    M = Mi + Ms
    return np.sign(M.real) * M.imag / step


def bracketed_root(g, a, b, ga, gb, p, tol=4e-15, max_iter=200):
    """Roots of g in [a, b] (ga > 0 > gb), vectorised: Illinois regula falsi,
    bisecting whenever the bracket has not halved in two steps."""
    x = 0.5 * (a + b)
    live = np.arange(a.size)
    side = np.zeros(a.size)
    w1 = w2 = np.full(a.size, np.inf)
    for _ in range(max_iter):
        width = b - a
        xi = np.where(width > 0.5 * w2, 0.5 * (a + b), a - ga * width / (gb - ga))
        w2, w1 = w1, width
        gx = g(xi, tuple(q[live] for q in p))
        x[live] = xi
        up = gx > 0                       # root lies right of xi
        gb = np.where(up & (side > 0), 0.5 * gb, gb)
        ga = np.where(~up & (side < 0), 0.5 * ga, ga)
        a, ga = np.where(up, xi, a), np.where(up, gx, ga)
        b, gb = np.where(up, b, xi), np.where(up, gb, gx)
        side = np.where(up, 1.0, -1.0)
        go = (b - a > tol) & (gx != 0)
        if not go.all():
            live, a, b, ga, gb, side, w1, w2 = (q[go] for q in (live, a, b, ga, gb, side, w1, w2))
        if live.size == 0:
            break
    return x


def candidates(v, n):
    """Grid local maxima that could be the highest (mechopt's global_max_angle:
    within a quarter of the largest second difference of the grid maximum;
    a flat top counts once): (row, grid index)."""
    prev, nxt = np.roll(v, 1, axis=1), np.roll(v, -1, axis=1)
    curv = np.abs(nxt - 2 * v + prev).max(axis=1, keepdims=True)
    top = (v >= prev) & (v >= nxt) & (v >= v.max(axis=1, keepdims=True) - 0.25 * curv)
    top[:, :-1] &= nxt[:, :-1] != v[:, :-1]
    return np.nonzero(top)


def refine_max(g, phi, h, p):
    """mechopt's refine_max on many grid maxima: the root of the slope g in
    [phi - h, phi] or [phi, phi + h], or phi when neither brackets one."""
    gk = g(phi, p)
    right = gk > 0
    other = g(np.where(right, phi + h, phi - h), p)
    a, b = np.where(right, phi, phi - h), np.where(right, phi + h, phi)
    ga, gb = np.where(right, gk, other), np.where(right, other, gk)
    ok = (ga > 0) & (gb < 0)
    out = phi.copy()
    out[ok] = bracketed_root(g, a[ok], b[ok], ga[ok], gb[ok], tuple(q[ok] for q in p))
    return out


def group_max(des, val):
    """Largest val per design; des is grouped (each design's rows contiguous)."""
    starts = np.flatnonzero(np.r_[True, des[1:] != des[:-1]])
    return des[starts], np.maximum.reduceat(val, starts)


def round_up(m):
    """m >= 8 rounded up to 4 sizes an octave (12, 14, 16, 20, ..., 28, 32, 40, ...)."""
    step = 2 ** (np.floor(np.log2(m)).astype(int) - 2)
    return -(-m // step) * step


GRIDS, RULES = {}, {}


def grid(n):
    if n not in GRIDS:
        phi = TWO_PI * np.arange(n) / n
        GRIDS[n] = np.cos(phi), np.sin(phi)
    return GRIDS[n]


def rule(m):
    if m not in RULES:
        RULES[m] = np.polynomial.legendre.leggauss(m)
    return RULES[m]


def compute(x, gl_cap):
    """All metrics (columns in METRICS order, NaN where cannot_assemble) for
    factor rows x, and the assembly mask."""
    l, dphi, r, e = x.T
    out = np.full((len(x), len(METRICS)), np.nan)
    ratio = (r + np.abs(e)) / l
    out[:, 9] = ratio
    ok = ratio < 1
    least = 4 * MASS * r * r * W * W / math.pi**2
    out[ok, 2] = least[ok]
    j = np.flatnonzero(ok)
    l, r, e, cd, sd = l[j], r[j], e[j], np.cos(dphi[j]), np.sin(dphi[j])
    n = np.clip(4 * np.ceil(45 / np.arccosh(1 / ratio[j]) / 4), 16, 4096).astype(int)
    nb = round_up(n)
    meanT = np.empty(j.size)
    cand = {"T": [], "M": []}             # (design, grid angle, spacing) per candidate
    for size in np.unique(nb):
        rows = np.flatnonzero(nb == size)
        c, s = grid(size)
        p = tuple(q[rows, None] for q in (r, l, e, cd, sd))
        T, Mi, Ms = drive(c, s, *p)
        meanT[rows] = T.mean(axis=1)
        for key, v in (("T", T), ("M", np.abs(Mi + Ms))):
            i, k = candidates(v, size)
            cand[key].append((rows[i], TWO_PI / size * k, np.full(k.size, TWO_PI / size)))
    p = (r, l, e, cd, sd)
    peak = {}
    for key, slope in (("T", energy_slope), ("M", abs_moment_slope)):
        des, phi, h = (np.concatenate(q) for q in zip(*cand[key]))
        pk = tuple(q[des] for q in p)
        phi = refine_max(slope, phi, h, pk)
        T, Mi, Ms = drive(np.cos(phi), np.sin(phi), *pk)
        peak[key] = np.empty(j.size)
        first, peak[key][first] = group_max(des, T if key == "T" else np.abs(Mi + Ms))
    # Dead centres (crank and rod collinear): sin psi = -e/(l+r) stretched,
    # e/(l-r) folded; slider 2 runs at psi = phi + dphi and is mirrored.
    ends = []
    for sg, shift in ((1.0, 0.0), (-1.0, np.arctan2(sd, cd))):
        for sn, cs in ((-e / (l + r), sg), (e / (l - r), -sg)):
            ends.append(np.arctan2(sn, cs * np.sqrt(1 - sn * sn)) - shift)
    ends = np.sort(np.mod(np.stack(ends, axis=1), TWO_PI), axis=1)
    start = ends.ravel()
    length = (np.roll(ends, -1, axis=1) - ends + np.array([0, 0, 0, TWO_PI])).ravel()
    des = np.repeat(np.arange(j.size), 4)
    m = np.maximum(12, np.ceil(2 * np.repeat(n, 4) * length / TWO_PI)).astype(int)
    if gl_cap:
        m = np.minimum(m, gl_cap)
    # An arc needing more than 64 nodes is split into equal panels of 64.
    panels = -(-m // 64)
    des, start, length = (np.repeat(q, panels) for q in (des, start, length / panels))
    start += length * (np.arange(des.size) - np.repeat(np.cumsum(panels) - panels, panels))
    m = round_up(np.repeat(-(-m // panels), panels))
    sumM, sumM2 = np.zeros(j.size), np.zeros(j.size)
    for size in np.unique(m):
        arcs = np.flatnonzero(m == size)
        node, weight = rule(size)
        half = 0.5 * length[arcs, None]
        phi = start[arcs, None] + half * (1 + node)
        T, Mi, Ms = drive(np.cos(phi), np.sin(phi), *(q[des[arcs], None] for q in p))
        M = (Mi + Ms) * half
        sumM += np.bincount(des[arcs], M @ weight, j.size)
        sumM2 += np.bincount(des[arcs], (M * (Mi + Ms)) @ weight, j.size)
    out[j, 0] = peak["T"]
    out[j, 1] = meanT
    out[j, 3] = peak["T"] / meanT
    out[j, 4] = meanT / least[j]
    out[j, 5] = peak["T"] / least[j]
    out[j, 6] = peak["M"]
    out[j, 7] = sumM / TWO_PI
    out[j, 8] = np.sqrt(sumM2 / TWO_PI)
    return out, ok


def open_store(path):
    for f in (path, path + "-wal", path + "-shm"):
        if os.path.exists(f):
            os.remove(f)
    db = sqlite3.connect(path)
    db.execute("pragma journal_mode=WAL")
    db.execute("pragma synchronous=NORMAL")   # as mechopt's store: fsync at checkpoints
    db.execute("create table samples(idx integer primary key, status text not null, "
               + ", ".join(f"{c} real" for c in FACTORS + METRICS) + ")")
    return db


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--samples", type=int, default=10**6)
    ap.add_argument("--chunk", type=int, default=65536)
    ap.add_argument("--store", help="SQLite file to write (default: a temporary file, removed)")
    ap.add_argument("--check", help="mechopt's store of the same study: report max relative differences")
    ap.add_argument("--gl-cap", type=int, default=0,
                    help="cap Gauss-Legendre nodes per arc as mechopt does (128); default: no cap")
    args = ap.parse_args()
    tmp = None if args.store else tempfile.mkdtemp()
    path = args.store or os.path.join(tmp, "store.sqlite")
    db = open_store(path)
    insert = f"insert into samples values ({', '.join('?' * (2 + len(FACTORS) + len(METRICS)))})"
    sobol = qmc.Sobol(d=4, scramble=False)
    warnings.filterwarnings("ignore", category=UserWarning)  # chunks need not be powers of 2
    compute_s = write_s = 0.0
    results = [] if args.check else None
    for lo in range(0, args.samples, args.chunk):
        t0 = time.perf_counter()
        x = LO + sobol.random(min(args.chunk, args.samples - lo)) * (HI - LO)
        vals, ok = compute(x, args.gl_cap)
        t1 = time.perf_counter()
        status = np.where(ok, "ok", "cannot_assemble").tolist()
        cols = [range(lo, lo + len(x)), status, *x.T.tolist(), *vals.T.tolist()]  # NaN binds as NULL
        with db:
            db.executemany(insert, zip(*cols))
        t2 = time.perf_counter()
        compute_s += t1 - t0
        write_s += t2 - t1
        if results is not None:
            results.append(np.column_stack([x, vals]))
    db.close()
    out = {"designs": args.samples, "compute_seconds": compute_s, "total_seconds": compute_s + write_s,
           "compute_rate": args.samples / compute_s, "total_rate": args.samples / (compute_s + write_s),
           "chunk": args.chunk}
    if args.check:
        ref = sqlite3.connect(args.check)
        want = np.array(ref.execute(f"select {', '.join(FACTORS + METRICS)} from samples "
                                    "where idx < ? order by idx",
                                    (args.samples,)).fetchall(), dtype=float)  # NULL -> NaN
        got = np.concatenate(results)
        with np.errstate(invalid="ignore", divide="ignore"):
            rel = np.abs(got - want) / np.abs(want)
        same = (got == want) | (np.isnan(got) & np.isnan(want))
        rel[same] = 0
        out["max_rel_diff"] = {c: float(np.nanmax(np.where(np.isnan(rel[:, i]), np.inf, rel[:, i])))
                               for i, c in enumerate(FACTORS + METRICS)}
    out["numpy"] = np.__version__
    if tmp:
        shutil.rmtree(tmp)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
