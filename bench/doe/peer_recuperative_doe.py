#!/usr/bin/env python3
"""Peer baseline for the batch DOE of the recuperative drive (seed 000): what a
user would write with chunked, vectorised numpy for the study of
configs/doe/recuperative_drive.yaml -- 10^6 unscrambled Sobol points over (rod
length, phase shift, crank radius, offset), every recuperative_drive metric
per design, rows written to SQLite -- at mechopt's accuracy or better:
  * cycle mean of T: periodic trapezoid on n = auto_cycle_points points
    (45/acosh(l/(r+|e|)) rounded up to a multiple of 4, 16..4096); designs
    are grouped by n rounded up to 4 sizes an octave (never fewer points);
  * cycle means of M and M^2 (resistance opposing the motion: |dx/dphi| has
    kinks at the dead centres): Gauss-Legendre on each arc between the four
    dead centres (in closed form: crank and rod collinear) with mechopt's
    max(12, 2 n L / 2 pi) nodes an arc, as panels of at most 64 nodes;
  * peaks of T and |M|: samples on the grid merged with the dead centres;
    next to every local maximum that could be the highest (mechopt's margin
    rule) and every dead centre (where |M| has kinks), the maxima on both
    sides are refined by a vectorised bracketed root search (Illinois regula
    falsi) on the angle derivative: dT/dphi in closed form, d|M|/dphi by
    complex step.
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
    """T, dT/dphi and the slider velocities dx1, dx2 (per radian) at crank angle
    phi (c = cos phi, s = sin phi), seed 000 eqs (1)-(11), (18)-(20); the
    moment of eq. (21) is M = dT/dphi + F/eta (|dx1| + |dx2|) (resistance
    opposing the motion). Broadcasts over designs x angles; takes complex
    angles for the complex step."""
    mv2 = mva = 0
    dx = []
    for sg, cc, ss in ((1.0, c, s), (-1.0, c * cd - s * sd, s * cd + c * sd)):  # slider 2 mirrored
        h = r * ss + e                    # rod's vertical extent
        dh = r * cc
        k = 1 / np.sqrt(l * l - h * h)    # 1 / horizontal extent
        g = h * dh * k
        v = -r * ss - sg * g              # slider d/dphi
        dv = -r * cc - sg * (dh * dh - h * r * ss + g * g) * k
        vs, dvs = 0.5 * (v - r * ss), 0.5 * (dv - r * cc)  # rod centre, horizontal
        mv2 = mv2 + MASS * v * v + Q * l * (vs * vs + 0.25 * dh * dh)
        mva = mva + MASS * v * dv + Q * l * (vs * dvs - 0.25 * dh * r * ss)
        dx.append(v)
    return 0.5 * W * W * mv2, W * W * mva, dx[0], dx[1]


def energy_and_moment(phi, p):
    T, Ti, dx1, dx2 = drive(np.cos(phi), np.sin(phi), *p[:5])
    return T, Ti + FORCE * (np.abs(dx1) + np.abs(dx2))


def energy_slope(phi, p):
    return drive(np.cos(phi), np.sin(phi), *p[:5])[1]


def abs_moment_slope(phi, p, step=1e-30):
    """d|M|/dphi by complex step, |dx_i| taken as p[5+i] dx_i (the signs on
    the arc between dead centres being searched: one-sided at its ends)."""
    z = phi + 1j * step
    _, Ti, dx1, dx2 = drive(np.cos(z), np.sin(z), *p[:5])
    M = Ti + FORCE * (p[5] * dx1 + p[6] * dx2)
    return np.sign(M.real) * M.imag / step


def bracketed_root(g, a, b, ga, gb, p, tol=1e-9, max_iter=100):
    """Roots of g in [a, b] (ga > 0 > gb), vectorised: Illinois regula falsi,
    bisecting whenever the bracket has not halved in two steps. The roots are
    smooth maxima: an angle within tol puts f within f'' tol^2 / 2 of them."""
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


def candidates(phi, v, curv, also):
    """Samples v (rows at sorted angles phi over one revolution) next to which
    a maximum could be the highest (a maximum in [phi_k, phi_k+1] lies within
    h^2 |f''| / 8 of v_k or v_k+1; curv = largest |second difference| on the
    uniform grid estimates h^2 |f''|, doubled as in mechopt's global_max_angle):
    local maxima (a flat top counts once), and where `also` if a neighbour is
    high enough. Returns (row, angle, angle before, angle after, value,
    value before, value after)."""
    prev, nxt = np.roll(v, 1, axis=1), np.roll(v, -1, axis=1)
    low = v.max(axis=1, keepdims=True) - 0.25 * curv
    top = (v >= prev) & (v >= nxt) & (v >= low)
    top[:, :-1] &= nxt[:, :-1] != v[:, :-1]
    i, k = np.nonzero(top | also & (np.maximum(prev, nxt) >= low))
    n = phi.shape[1]
    before = phi[i, k - 1] - np.where(k == 0, TWO_PI, 0)
    after = phi[i, (k + 1) % n] + np.where(k == n - 1, TWO_PI, 0)
    return i, phi[i, k], before, after, v[i, k], v[i, k - 1], v[i, (k + 1) % n]


def refine_max(f, slope, phi, before, after, value, fbefore, fafter, p):
    """Largest of f at phi and at its maxima in [before, phi] and [phi, after]
    (f smooth inside each): roots of the slope where it changes from + to -."""
    best = value.copy()
    for a, b, fa, fb in ((before, phi, fbefore, value), (phi, after, value, fafter)):
        a, b = a.copy(), b.copy()
        pa = p[:5] + tuple(np.sign(drive(np.cos(0.5 * (a + b)), np.sin(0.5 * (a + b)), *p[:5])[2:]))
        ga, gb = slope(a, pa), slope(b, pa)
        # Same slope sign at both ends, yet f turned: two extrema within the
        # interval (a grid too coarse there); bracket the best of 32 sub-steps.
        hid = np.flatnonzero((ga > 0) & (gb > 0) & (fb < fa) | (ga < 0) & (gb < 0) & (fb > fa))
        if hid.size:
            ph = tuple(q[hid] for q in pa)
            sub = a[hid, None] + (b - a)[hid, None] * np.linspace(0, 1, 33)
            k = np.clip(f(sub, tuple(q[:, None] for q in ph)).argmax(axis=1), 1, 31)
            a[hid], b[hid] = sub[np.arange(hid.size), k - 1], sub[np.arange(hid.size), k + 1]
            ga[hid], gb[hid] = slope(a[hid], ph), slope(b[hid], ph)
        ok = (ga > 0) & (gb < 0)
        x = bracketed_root(slope, a[ok], b[ok], ga[ok], gb[ok], tuple(q[ok] for q in pa))
        best[ok] = np.maximum(best[ok], f(x, tuple(q[ok] for q in p)))
    return best


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
        GRIDS[n] = phi, np.cos(phi), np.sin(phi)
    return GRIDS[n]


def rule(m):
    if m not in RULES:
        RULES[m] = np.polynomial.legendre.leggauss(m)
    return RULES[m]


def dead_centres(r, l, e, cd, sd):
    """Crank angles in [0, 2 pi) where a slider stops (crank and rod collinear:
    sin psi = -e/(l+r) stretched, e/(l-r) folded; slider 2 runs at
    psi = phi + dphi and is mirrored), sorted: (designs, 4)."""
    ends = []
    for sg, shift in ((1.0, 0.0), (-1.0, np.arctan2(sd, cd))):
        for sn, cs in ((-e / (l + r), sg), (e / (l - r), -sg)):
            ends.append(np.arctan2(sn, cs * np.sqrt(1 - sn * sn)) - shift)
    return np.sort(np.mod(np.stack(ends, axis=1), TWO_PI), axis=1)


def compute(x):
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
    p = r[j], l[j], e[j], np.cos(dphi[j]), np.sin(dphi[j])
    n = np.clip(4 * np.ceil(45 / np.arccosh(1 / ratio[j]) / 4), 16, 4096).astype(int)
    ends = dead_centres(*p)
    # Uniform grid (designs grouped by n rounded up): the mean of T, and the
    # candidate maxima of T and |M| on the grid merged with the dead centres.
    # |M| has kinks there, which may hide a maximum between a dead centre and
    # its neighbours: each dead centre is a candidate too.
    nb = round_up(n)
    meanT = np.empty(j.size)
    cand = {"T": [], "M": []}
    for size in np.unique(nb):
        rows = np.flatnonzero(nb == size)
        phi, c, s = grid(size)
        pr = tuple(q[rows, None] for q in p)
        T, Ti, dx1, dx2 = drive(c, s, *pr)
        M = np.abs(Ti + FORCE * (np.abs(dx1) + np.abs(dx2)))
        meanT[rows] = T.mean(axis=1)
        Te, Me = energy_and_moment(ends[rows], pr)
        angles = np.concatenate([np.broadcast_to(phi, T.shape), ends[rows]], axis=1)
        order = np.argsort(angles, axis=1, kind="stable")
        angles = np.take_along_axis(angles, order, axis=1)
        for key, v, ve in (("T", T, Te), ("M", M, np.abs(Me))):
            curv = np.abs(np.roll(v, 1, axis=1) - 2 * v + np.roll(v, -1, axis=1))
            curv = curv.max(axis=1, keepdims=True)
            merged = np.take_along_axis(np.concatenate([v, ve], axis=1), order, axis=1)
            i, *rest = candidates(angles, merged, curv, (order >= size) & (key == "M"))
            cand[key].append((rows[i], *rest))
    peak = {}
    for key, slope in (("T", energy_slope), ("M", abs_moment_slope)):
        des, *c = (np.concatenate(q) for q in zip(*cand[key]))
        f = (lambda x, q: energy_and_moment(x, q)[0]) if key == "T" else \
            (lambda x, q: np.abs(energy_and_moment(x, q)[1]))
        value = refine_max(f, slope, *c, tuple(q[des] for q in p))
        first, best = group_max(des, value)  # every design has a candidate: first = 0..
        peak[key] = np.empty(j.size)
        peak[key][first] = best
    # Means of M and M^2: Gauss-Legendre on the arcs between dead centres,
    # max(12, 2 n L / 2 pi) nodes an arc (panels of at most 64 nodes).
    start = ends.ravel()
    length = (np.roll(ends, -1, axis=1) - ends + np.array([0, 0, 0, TWO_PI])).ravel()
    des = np.repeat(np.arange(j.size), 4)
    m = np.maximum(12, np.ceil(2 * np.repeat(n, 4) * length / TWO_PI)).astype(int)
    panels = -(-m // 64)
    des, start, length = (np.repeat(q, panels) for q in (des, start, length / panels))
    start += length * (np.arange(des.size) - np.repeat(np.cumsum(panels) - panels, panels))
    m = round_up(np.repeat(-(-m // panels), panels))
    sumM, sumM2 = np.zeros(j.size), np.zeros(j.size)
    for size in np.unique(m):
        arcs = np.flatnonzero(m == size)
        node, weight = rule(size)
        half = 0.5 * length[arcs, None]
        pa = tuple(q[des[arcs], None] for q in p)
        M = energy_and_moment(start[arcs, None] + half * (1 + node), pa)[1]
        sumM += np.bincount(des[arcs], (M * half) @ weight, j.size)
        sumM2 += np.bincount(des[arcs], (M * M * half) @ weight, j.size)
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
    args = ap.parse_args()
    tmp = None if args.store else tempfile.mkdtemp()
    path = args.store or os.path.join(tmp, "store.sqlite")
    db = open_store(path)
    insert = f"insert into samples values ({', '.join('?' * (2 + len(FACTORS) + len(METRICS)))})"
    sobol = qmc.Sobol(d=4, scramble=False)
    warnings.filterwarnings("ignore", message="The balance properties")  # chunks of any size
    compute_s = write_s = 0.0
    results = [] if args.check else None
    for lo in range(0, args.samples, args.chunk):
        t0 = time.perf_counter()
        x = LO + sobol.random(min(args.chunk, args.samples - lo)) * (HI - LO)
        vals, ok = compute(x)
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
        # The columns mechopt's run stores (its config's `columns`, and the
        # objective's and constraints' metrics), compared where both have them.
        stored = {row[1] for row in ref.execute("pragma table_info(samples)")}
        names = [c for c in FACTORS + METRICS if c in stored]
        want = np.array(ref.execute(f"select {', '.join(names)} from samples "
                                    "where idx < ? order by idx",
                                    (args.samples,)).fetchall(), dtype=float)  # NULL -> NaN
        got = np.concatenate(results)[:, [(FACTORS + METRICS).index(c) for c in names]]
        with np.errstate(invalid="ignore", divide="ignore"):
            rel = np.abs(got - want) / np.abs(want)
        same = (got == want) | (np.isnan(got) & np.isnan(want))
        rel[same] = 0
        rel[np.isnan(rel)] = np.inf          # NULL on one side only
        out["max_rel_diff"] = dict(zip(names, rel.max(axis=0).tolist()))
        out["rows_over_1e-9"] = dict(zip(names, (rel > 1e-9).sum(axis=0).tolist()))
    out["numpy"] = np.__version__
    if tmp:
        shutil.rmtree(tmp)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
