#!/usr/bin/env python3
"""Independent reference for the general planar linkage (docs/design/linkage.md, issue 34).

Reads a `problem: linkage` YAML config and computes, in mpmath at 30 digits and
sharing no code with mechopt, without the design's closed-form group solutions:

- positions: every moving link is a body with a pose (x, y, theta) of its frame
  (the frames of the design's "Frames and signs"); every joint is a constraint
  between two bodies (revolute: 2 equations, prismatic: 2, the crank's driver:
  1), and the full system Phi(q, phi) = 0 is solved by Newton's method, started
  from the previous grid angle's solution (a second-order predictor). The closed
  form of the design is used ONLY at phi = 0 to seed the branch (`branch` or
  `near`); the branch's sign is then checked at every grid angle. A PRP group
  (two sliders pinned together, no branch) starts with both sliders at its
  first line's point.
- transfer functions per radian of phi: Phi_q q' = -Phi_phi and
  Phi_q q'' = -(Phi_q q')_q q' (the constraints' quadratic velocity terms);
  velocities are speed times them, accelerations speed^2 times.
- dynamics at the constant crank speed w: the driving torque (in the sense of
  rotation, `sense`) (a) by virtual power, M = w^2 sum(m G''.G' + J t'' t')
  - sum(generalised forces of gravity and loads); (b) by Newton-Euler: the 3
  equations of every link about its centre of mass, all joint reaction
  components and the driving torque unknown, one global linear solve. (a) and
  (b) must agree to 1e-20 (relative to the size of the terms) at every point,
  or the script stops. The shaking force (the forces the mechanism puts on the
  frame through the ground joints and the slider lines) and the shaking moment
  about the origin (their moments, the line couples and the motor's reaction
  -M) are checked against the momentum balance (weights + loads - momentum
  rate) to the same tolerance. Process loads are NOT counted as frame forces.
- cycle metrics on a 720-point grid, each extremum refined by an Illinois root
  search on its derivative (mp.diff at doubled precision, or the analytic s', s'')
  to ~1e-27 rad; kinks of the loads (s' = 0 for `when:` loads, s = a table row
  for tables) are located the same way and every quantity is also evaluated
  there, on both sides (a `when` load switches there). Means and RMS: Gauss-
  Legendre, 24 nodes on every piece between kinks, pieces no longer than
  pi/8; the 16-node value gives the reported error estimate (< 1e-15 relative).

Units: exactly those of UNITS below (m, mm, deg, rad, rev/min, rpm, rad/s,
kg, kg/m, kg m^2, N, kN, N m, kN m); a bare number is SI. PyYAML reads the
keys and values `on`/`off` as booleans: keys True are read back as `on`.
Loads supported: slider force (constant or `table: {over: position}`) with
`when: forward|return|always` (forward: ds/dphi > 0), link torque. Anything
else in the description is refused loudly.

Run: /usr/bin/python3 tests/ref/linkage_ref.py configs/linkage/watt2_sixbar.yaml \
       configs/linkage/stephenson3_sixbar.yaml configs/linkage/whitworth_shaper.yaml \
       configs/linkage/wedge_press.yaml > tests/ref/linkage_ref.json
     /usr/bin/python3 tests/ref/linkage_ref.py --selftest  (~45 s; slider-crank closed forms,
       transfer functions against mp.diff of the positions, Whitworth time ratio
       and mean torque = cutting work / 2 pi, the wedge's ram stroke)
"""
import json
import re
import sys
import time

import mpmath as mp
import yaml

mp.mp.dps = 30
MPF = mp.mpf
T0 = time.time()
GRID = 720
REPORT_DEG = (0, 37, 90, 200, 300)
G_STD = MPF("9.80665")
TOL = MPF(10) ** -20
KINK_GAP = MPF(10) ** -25         # one-sided values next to a load's kink
UNITS = {"": 1, "m": 1, "mm": MPF("0.001"), "rad": 1, "deg": mp.pi / 180, "rad/s": 1,
         "rev/min": mp.pi / 30, "rpm": mp.pi / 30, "kg": 1, "kg/m": 1, "kg m^2": 1,
         "N": 1, "kN": 1000, "N m": 1, "kN m": 1000}


def num(x):
    """A number with its unit ("0.2 m", "100 rev/min") in SI; a bare number is SI."""
    if isinstance(x, bool) or x is None:
        raise ValueError("not a quantity: %r" % (x,))
    if isinstance(x, (int, float)):
        return MPF(repr(x))
    m = re.fullmatch(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*", str(x))
    if not m or m.group(2) not in UNITS:
        raise ValueError("cannot read the quantity %r (units: %s)" % (x, sorted(UNITS)))
    return MPF(m.group(1)) * UNITS[m.group(2)]


def pair(x):
    return (num(x[0]), num(x[1]))


def on_keys(x):
    """PyYAML (YAML 1.1) reads the key `on` as True: give it its name back."""
    if isinstance(x, dict):
        return {("on" if k is True else k): on_keys(v) for k, v in x.items()}
    return [on_keys(v) for v in x] if isinstance(x, list) else x


def fl(x):
    return mp.nstr(x, 20, min_fixed=-5, max_fixed=8) if x != 0 else "0"


# ---- plane vectors as tuples ---------------------------------------------------
def add(a, b): return (a[0] + b[0], a[1] + b[1])
def sub(a, b): return (a[0] - b[0], a[1] - b[1])
def mul(k, a): return (k * a[0], k * a[1])
def dot(a, b): return a[0] * b[0] + a[1] * b[1]
def cross(a, b): return a[0] * b[1] - a[1] * b[0]
def perp(a): return (-a[1], a[0])
def rot(t, v): c, s = mp.cos(t), mp.sin(t); return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def lu_factor(rows, n):
    """Dense LU with partial pivoting of a square system given as dict rows."""
    a = [[r.get(c, MPF(0)) for c in range(n)] for r in rows]
    assert len(a) == n, "constraint count %d != unknowns %d" % (len(a), n)
    piv = list(range(n))
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(a[i][k]))
        if a[p][k] == 0:
            raise ArithmeticError("singular system (column %d)" % k)
        a[k], a[p], piv[k], piv[p] = a[p], a[k], piv[p], piv[k]
        for i in range(k + 1, n):
            f = a[i][k] / a[k][k]
            a[i][k] = f
            for j in range(k + 1, n):
                a[i][j] -= f * a[k][j]
    return a, piv


def lu_solve(lu, b):
    a, piv = lu
    n = len(a)
    y = [b[piv[i]] for i in range(n)]
    for i in range(n):
        y[i] -= sum((a[i][j] * y[j] for j in range(i)), MPF(0))
    for i in reversed(range(n)):
        y[i] = (y[i] - sum((a[i][j] * y[j] for j in range(i + 1, n)), MPF(0))) / a[i][i]
    return y


def illinois(f, a, b, fa=None, fb=None, tol=MPF(10) ** -27):
    """Root of f in the bracket [a, b] (regula falsi, Illinois variant)."""
    fa = f(a) if fa is None else fa
    fb = f(b) if fb is None else fb
    if fa == 0 or fb == 0:
        return a if fa == 0 else b
    if fa * fb > 0:
        raise ArithmeticError("no sign change in [%s, %s]" % (a, b))
    c_old = a
    for _ in range(300):
        c = (a * fb - b * fa) / (fb - fa)
        fc = f(c)
        if fc == 0 or abs(c - c_old) < tol:
            return c
        if fc * fb < 0:
            a, fa = b, fb
        else:
            fa /= 2
        b, fb, c_old = c, fc, c
    raise ArithmeticError("Illinois did not converge")


def gauss_legendre(n):
    """Nodes and weights on [-1, 1] (Newton on P_n from Chebyshev guesses)."""
    xs, ws = [], []
    for i in range(1, n + 1):
        x = mp.cos(mp.pi * (i - MPF(1) / 4) / (n + MPF(1) / 2))
        for _ in range(100):
            p0, p1 = MPF(1), x
            for k in range(2, n + 1):
                p0, p1 = p1, ((2 * k - 1) * x * p1 - (k - 1) * p0) / k
            dp = n * (x * p1 - p0) / (x * x - 1)
            dx = p1 / dp
            x -= dx
            if abs(dx) < MPF(10) ** -28:
                break
        xs.append(x)
        ws.append(2 / ((1 - x * x) * dp * dp))
    return xs, ws


GL = {n: gauss_legendre(n) for n in (16, 24)}


class Linkage:
    def __init__(self, cfg, name):
        if cfg.get("problem") != "linkage":
            raise ValueError("%s: not a linkage config" % name)
        m = on_keys(cfg["model"])
        self.name, self.links = name, m["links"]
        grav = m.get("gravity", False)
        self.gravity = grav is True or grav == "on"
        self.names, self.body = ["ground"], {"ground": 0}
        self.points = {p: (0, pair(xy)) for p, xy in m.get("ground", {}).items()}
        self.joints, self.slider_joint, self.groups = [], {}, []
        self.joint_key = {}                         # rev joint -> (POINT_LINK, sign to the force on LINK)
        cr = m["crank"]
        c = self.add_link(cr["link"])
        self.crank, self.phase, self.speed = c, num(cr.get("phase", 0)), num(cr["speed"])
        self.sense = {"ccw": 1, "cw": -1}[cr.get("sense", "ccw")]
        self.pivot = cr["pivot"]
        self.pin(c, (0, 0), cr["pivot"])
        self.joints.append(("drv", c))
        self.points[cr["joint"]] = (c, (self.length(c), 0))
        self.register_points([c])
        for g in m["groups"]:
            self.add_group(g)
        unused = set(self.links) - set(self.names)
        if unused:
            raise ValueError("links in no group: %s" % sorted(unused))
        self.nq = 3 * (len(self.names) - 1)
        self.inertia = {b: self.body_data(b) for b in range(1, len(self.names))}
        self.loads = [self.read_load(k, v) for k, v in (m.get("loads") or {}).items()]
        if m.get("springs"):
            raise NotImplementedError("springs are not in this reference")
        self.outputs = cfg.get("outputs", m.get("outputs", []))
        self.grid = None

    # ---- description -----------------------------------------------------
    def add_link(self, name):
        if name in self.body or name not in self.links:
            raise ValueError("link %r unknown or used twice" % name)
        self.body[name] = len(self.names)
        self.names.append(name)
        return self.body[name]

    def register_points(self, bodies):
        """A link's own points become known once the link is solved."""
        for b in bodies:
            for p, uv in (self.links[self.names[b]].get("points") or {}).items():
                if p in self.points:
                    raise ValueError("point %r defined twice" % p)
                self.points[p] = (b, pair(uv))

    def length(self, b):
        return num(self.links[self.names[b]]["length"])

    def pin(self, i, si, pname):
        j, sj = self.points[pname]
        self.joints.append(("rev", i, si, j, sj))
        self.joint_key[len(self.joints) - 1] = ("%s_%s" % (pname, self.names[i]), 1)

    def add_group(self, g):
        t, (n1, n2) = g["type"], g["links"]
        b1, b2 = self.add_link(n1), self.add_link(n2)
        rec = {"type": t, "bodies": (b1, b2), "key": "%s,%s" % (n1, n2),
               "branch": g.get("branch"), "near": pair(g["near"]) if "near" in g else None}
        if (rec["branch"] is None) == (rec["near"] is None) and t not in ("RPR", "PRP"):
            raise ValueError("group %s: give exactly one of branch, near" % rec["key"])
        if t == "RRR":
            p, q = g["from"]
            rec.update(P=p, Q=q, a=self.length(b1), b=self.length(b2))
            self.pin(b1, (0, 0), p)
            self.pin(b2, (0, 0), q)
            self.joints.append(("rev", b1, (rec["a"], 0), b2, (rec["b"], 0)))
            self.joint_key[len(self.joints) - 1] = ("%s_%s" % (g["joint"], n2), -1)
            self.points[g["joint"]] = (b1, (rec["a"], 0))
        elif t == "RRP":
            on, tl, alpha, off = self.line(n2)
            rec.update(P=g["from"], a=self.length(b1), line_body=on, T=tl, alpha=alpha, off=off)
            self.pin(b1, (0, 0), g["from"])
            self.joints.append(("rev", b1, (rec["a"], 0), b2, (0, 0)))
            self.joint_key[len(self.joints) - 1] = ("%s_%s" % (g["joint"], n1), 1)
            self.slider_joint[b2] = len(self.joints)
            self.joints.append(("pri", b2, on, alpha, tl, off))
            self.points[g["joint"]] = (b2, (0, 0))
        elif t == "PRP":                            # two sliders pinned at their origins
            rec.update(lines=(self.line(n1), self.line(n2)))
            self.joints.append(("rev", b2, (0, 0), b1, (0, 0)))
            self.joint_key[len(self.joints) - 1] = ("%s_%s" % (g["joint"], n2), 1)
            for b, (on, tl, alpha, off) in zip((b1, b2), rec["lines"]):
                self.slider_joint[b] = len(self.joints)
                self.joints.append(("pri", b, on, alpha, tl, off))
            self.points[g["joint"]] = (b1, (0, 0))
        elif t == "RPR":
            off = num(self.links[n2].get("offset", 0))
            rec.update(A=g["from"], Q=g["pivot"], off=off)
            self.pin(b1, (0, 0), g["from"])
            self.pin(b2, (0, 0), g["pivot"])
            self.slider_joint[b1] = len(self.joints)
            self.joints.append(("pri", b1, b2, MPF(0), (0, 0), off))
        else:
            raise NotImplementedError("group type %s" % t)
        self.groups.append(rec)
        self.register_points([b1, b2])

    def line(self, name):
        """A slider's line: its body, its point there (local), its angle and offset."""
        line = on_keys(self.links[name]["line"])
        on = self.body[line.get("fixed_to", "ground")]
        tb, tl = self.points[line["through"]]
        if tb != on:
            raise ValueError("line of %s: %s is not a point of %s" % (name, line["through"], line.get("fixed_to")))
        return on, tl, num(line.get("angle", 0)), num(line.get("offset", 0))

    def body_data(self, b):
        d = self.links[self.names[b]]
        if "mass_per_length" in d:
            if "mass" in d:
                raise ValueError("%s: mass and mass_per_length" % self.names[b])
            L = self.length(b)
            mass = num(d["mass_per_length"]) * L
            return mass, (L / 2, MPF(0)), mass * L * L / 12
        if b in self.slider_joint and "cg" in d:
            raise ValueError("%s: a slider's mass sits at its pin (no cg)" % self.names[b])
        return num(d.get("mass", 0)), pair(d["cg"]) if "cg" in d else (MPF(0), MPF(0)), num(d.get("inertia", 0))

    def read_load(self, key, d):
        d = on_keys(d)
        if "link" not in d or d.get("opposing") or set(d) - {"link", "force", "torque", "table", "when"}:
            raise NotImplementedError("load %s: %s" % (key, d))
        b = self.body[d["link"]]
        ld = {"key": key, "body": b, "when": d.get("when", "always")}
        if "torque" in d:
            ld.update(kind="torque", value=num(d["torque"]))
        elif "force" in d or "table" in d:
            if b not in self.slider_joint:
                raise ValueError("load %s: %s is not a slider" % (key, d["link"]))
            if "force" in d:
                ld.update(kind="force", value=num(d["force"]))
            else:
                tb = d["table"]
                if tb["over"] != "position":
                    raise NotImplementedError("table over %s" % tb["over"])
                ux, uf = (UNITS[u] for u in tb["unit"])
                ld.update(kind="table", rows=sorted((num(r[0]) * ux, num(r[1]) * uf) for r in tb["rows"]))
        if ld["when"] not in ("forward", "return", "always") or (ld["kind"] == "torque" and ld["when"] != "always"):
            raise NotImplementedError("load %s: when %s" % (key, ld["when"]))
        return ld

    # ---- constraints -------------------------------------------------------
    @staticmethod
    def pose(q, b):
        if b == 0:
            return (MPF(0), MPF(0)), MPF(0)
        k = 3 * (b - 1)
        return (q[k], q[k + 1]), q[k + 2]

    @staticmethod
    def put(row, b, cx, cy, ct):
        if b:
            for k, c in zip(range(3 * (b - 1), 3 * b), (cx, cy, ct)):
                row[k] = row.get(k, 0) + c

    def equations(self, q, phi, qd=None):
        """[(value, Jacobian row {column: coefficient}, quadratic velocity term)]."""
        out = []
        for jt in self.joints:
            if jt[0] == "rev":                      # r_i + R_i s_i = r_j + R_j s_j
                _, i, si, j, sj = jt
                (ri, ti), (rj, tj) = self.pose(q, i), self.pose(q, j)
                ai, aj = rot(ti, si), rot(tj, sj)
                val = sub(add(ri, ai), add(rj, aj))
                rem = (0, 0)
                if qd is not None:
                    wi, wj = self.pose(qd, i)[1], self.pose(qd, j)[1]
                    rem = sub(mul(-wi * wi, ai), mul(-wj * wj, aj))
                for k in (0, 1):
                    row = {}
                    self.put(row, i, int(k == 0), int(k == 1), perp(ai)[k])
                    self.put(row, j, -int(k == 0), -int(k == 1), -perp(aj)[k])
                    out.append((val[k], row, rem[k]))
            elif jt[0] == "pri":                    # slider i on a line of body j
                _, i, j, al, tl, off = jt
                (ri, ti), (rj, tj) = self.pose(q, i), self.pose(q, j)
                at, n = rot(tj, tl), rot(tj + al, (0, 1))
                d = sub(ri, add(rj, at))
                row = {}
                self.put(row, i, 0, 0, 1)
                self.put(row, j, 0, 0, -1)
                out.append((ti - tj - al, row, 0))
                row = {}
                self.put(row, i, n[0], n[1], 0)
                self.put(row, j, -n[0], -n[1], -dot(perp(at), n) + dot(d, perp(n)))
                rem = 0
                if qd is not None:
                    (vi, _), (vj, wj) = self.pose(qd, i), self.pose(qd, j)
                    dd = sub(vi, add(vj, mul(wj, perp(at))))
                    rem = dot(at, n) * wj * wj + 2 * dot(dd, perp(n)) * wj - dot(d, n) * wj * wj
                out.append((dot(d, n) - off, row, rem))
            else:                                   # driver: theta_c = phase + sense phi
                row = {}
                self.put(row, jt[1], 0, 0, 1)
                out.append((self.pose(q, jt[1])[1] - self.phase - self.sense * phi, row, 0))
        return out

    def kin(self, phi, q):
        """Newton on Phi(q, phi) = 0 from q; then q' and q'' from the Jacobian."""
        small = mp.ldexp(1, -mp.mp.prec // 2 - 8)
        last = False
        for it in range(60):
            eq = self.equations(q, phi)
            lu = lu_factor([e[1] for e in eq], self.nq)
            dq = lu_solve(lu, [-e[0] for e in eq])
            q = [a + b for a, b in zip(q, dq)]
            if last:
                break
            last = max(abs(x) for x in dq) < small
        else:
            raise ArithmeticError("%s: Newton failed at phi = %s" % (self.name, phi))
        eq = self.equations(q, phi)
        if max(abs(e[0]) for e in eq) > mp.ldexp(1, -mp.mp.prec + 24):
            raise ArithmeticError("%s: residual too large at phi = %s" % (self.name, phi))
        lu = lu_factor([e[1] for e in eq], self.nq)
        qd = lu_solve(lu, [self.sense if jt[0] == "drv" and k == 0 else MPF(0)
                           for jt in self.joints for k in range(1 if jt[0] == "drv" else 2)])
        qdd = lu_solve(lu, [-e[2] for e in self.equations(q, phi, qd)])
        return {"phi": phi, "q": q, "qd": qd, "qdd": qdd}

    def world(self, q, pname):
        b, s = self.points[pname]
        r, t = self.pose(q, b)
        return add(r, rot(t, s))

    def seed(self):
        """phi = 0 start: the design's closed form, used only to pick the branch."""
        q = [MPF(0)] * self.nq

        def setpose(b, r, t):
            q[3 * (b - 1):3 * b] = [r[0], r[1], t]

        setpose(self.crank, self.world(q, self.pivot), self.phase)
        for g in self.groups:
            b1, b2 = g["bodies"]
            if g["type"] == "RRR":
                P, Q = self.world(q, g["P"]), self.world(q, g["Q"])
                d = sub(Q, P)
                D = mp.sqrt(dot(d, d))
                al = (g["a"] ** 2 - g["b"] ** 2 + D * D) / (2 * D)
                e = mul(1 / D, d)
                h = mp.sqrt(g["a"] ** 2 - al * al)
                roots = {k: add(P, add(mul(al, e), mul(k * h, perp(e)))) for k in (1, -1)}
                B = self.pick(g, roots)
                setpose(b1, P, mp.atan2(*reversed(sub(B, P))))
                setpose(b2, Q, mp.atan2(*reversed(sub(B, Q))))
            elif g["type"] == "RRP":
                P = self.world(q, g["P"])
                ro, to = self.pose(q, g["line_body"])
                T = add(ro, rot(to, g["T"]))
                u, n = rot(to + g["alpha"], (1, 0)), rot(to + g["alpha"], (0, 1))
                w = sub(sub(P, T), mul(g["off"], n))
                r = mp.sqrt(g["a"] ** 2 - dot(w, n) ** 2)
                roots = {k: add(add(T, mul(g["off"], n)), mul(dot(w, u) + k * r, u)) for k in (1, -1)}
                B = self.pick(g, roots)
                setpose(b1, P, mp.atan2(*reversed(sub(B, P))))
                setpose(b2, B, to + g["alpha"])
            elif g["type"] == "PRP":                # no closed form: both at the first line's point
                for b, (on, tl, al, off) in zip((b1, b2), g["lines"]):
                    ro, to = self.pose(q, on)
                    setpose(b, add(ro, rot(to, tl)), to + al)
                setpose(b2, self.pose(q, b1)[0], self.pose(q, b2)[1])
            else:
                A, Q = self.world(q, g["A"]), self.world(q, g["Q"])
                d = sub(A, Q)
                s = mp.sqrt(dot(d, d) - g["off"] ** 2)
                u = mul(1 / dot(d, d), sub(mul(s, d), mul(g["off"], perp(d))))
                setpose(b2, Q, mp.atan2(u[1], u[0]))
                setpose(b1, A, mp.atan2(u[1], u[0]))
        return q

    @staticmethod
    def pick(g, roots):
        if g["near"] is not None:
            return min(roots.values(), key=lambda B: dot(sub(B, g["near"]), sub(B, g["near"])))
        return roots[int(g["branch"])]

    def branch_sign(self, q, g):
        """The sign the branch rule speaks of; constant along a continuous solution."""
        b1, b2 = g["bodies"]
        if g["type"] == "RRR":
            P, Q = self.world(q, g["P"]), self.world(q, g["Q"])
            B = add(self.pose(q, b1)[0], rot(self.pose(q, b1)[1], (g["a"], 0)))
            return mp.sign(cross(sub(Q, P), sub(B, P)))
        if g["type"] == "RRP":
            P, (B, _) = self.world(q, g["P"]), self.pose(q, b2)
            return mp.sign(dot(sub(B, P), rot(self.pose(q, b2)[1], (1, 0))))
        return 1

    # ---- along the cycle ---------------------------------------------------
    def run_grid(self):
        """Newton continuation over the 720-point grid (721 states: phi = 2 pi closes)."""
        h = 2 * mp.pi / GRID
        st = self.kin(MPF(0), self.seed())
        self.signs = [self.branch_sign(st["q"], g) for g in self.groups]
        self.grid = [st]
        for k in range(1, GRID + 1):
            st = self.kin(k * h, self.predict(self.grid[-1], k * h))
            if [self.branch_sign(st["q"], g) for g in self.groups] != self.signs:
                raise ArithmeticError("%s: a group changed branch near %s deg" % (self.name, k / 2))
            self.grid.append(st)
        for a, b in zip(self.grid[0]["q"], self.grid[-1]["q"]):   # closes up to whole turns
            turns = (b - a) / (2 * mp.pi)
            assert abs(turns - mp.nint(turns)) < TOL, "%s: the cycle does not close" % self.name
        self.kinks = self.find_kinks()
        self.looks = [self.look(st) for st in self.grid[:GRID]]      # checks (a) == (b) at each

    @staticmethod
    def predict(st, phi):
        dp = phi - st["phi"]
        return [a + b * dp + c * dp * dp / 2 for a, b, c in zip(st["q"], st["qd"], st["qdd"])]

    def state(self, phi):
        k = min(GRID, max(0, int(mp.nint(phi * GRID / (2 * mp.pi)))))
        return self.kin(phi, self.predict(self.grid[k], phi))

    def point(self, st, b, s):
        """A point [u, v] of body b: position, first and second transfer functions."""
        (r, t), (v, om), (a, al) = (self.pose(st[x], b) for x in ("q", "qd", "qdd"))
        rs = rot(t, s)
        return r, add(r, rs), add(v, mul(om, perp(rs))), add(add(a, mul(al, perp(rs))), mul(-om * om, rs))

    def slider(self, st, b):
        """The slider's line coordinate s (from the line's point T along u) and s', s''."""
        _, i, j, al, tl, off = self.joints[self.slider_joint[b]]
        _, T, Td, Tdd = self.point(st, j, tl)
        (ri, vi, ai), (tj, wj, aj) = ([self.pose(st[x], i)[0] for x in ("q", "qd", "qdd")],
                                      [self.pose(st[x], j)[1] for x in ("q", "qd", "qdd")])
        u = rot(tj + al, (1, 0))
        d, dd, ddd = sub(ri, T), sub(vi, Td), sub(ai, Tdd)
        return (dot(d, u), dot(dd, u) + dot(d, perp(u)) * wj,
                dot(ddd, u) + 2 * dot(dd, perp(u)) * wj + dot(d, perp(u)) * aj - dot(d, u) * wj * wj)

    @staticmethod
    def load_on(ld, sl):
        return ld["when"] == "always" or (sl[1] > 0 if ld["when"] == "forward" else sl[1] < 0)

    def look(self, st, active=None, ne=True):
        """Everything at one state; `active` overrides the loads' when-switches (one-sided values)."""
        w, g = self.speed, G_STD if self.gravity else 0
        nb = len(self.names)
        lk = {"phi": st["phi"], "links": {}, "points": {}, "sliders": {}, "trans": {}, "press": {}}
        for b in range(1, nb):
            lk["links"][self.names[b]] = tuple(self.pose(st[x], b)[1] for x in ("q", "qd", "qdd"))
        for p, (b, s) in self.points.items():
            if b:
                lk["points"][p] = self.point(st, b, s)[1:]
        sl = {b: self.slider(st, b) for b in self.slider_joint}
        lk["sliders"] = {self.names[b]: v for b, v in sl.items()}
        for gr in self.groups:
            t1, t2 = (lk["links"][self.names[b]][0] for b in gr["bodies"])
            e1, e2 = rot(t1, (1, 0)), rot(t2, (1, 0))
            if gr["type"] == "RRR":
                lk["trans"][gr["key"]] = mp.atan2(abs(cross(e1, e2)), abs(dot(e1, e2)))
            elif gr["type"] == "RRP":
                lk["press"][gr["key"]] = mp.atan2(abs(cross(e2, e1)), abs(dot(e1, e2)))
            elif gr["type"] == "PRP":               # the pin's force along n1 against u2
                lk["press"][gr["key"]] = mp.atan2(abs(dot(e1, e2)), abs(cross(e1, e2)))
        # bodies: centre of mass, its transfer functions; kinetic energy; virtual power
        ke = mvp = scale = MPF(0)
        ext, fsum, msum, rhs = {}, (0, 0), MPF(0), []
        fin, mIn = (MPF(0), MPF(0)), MPF(0)            # the inertia forces' resultant and moment about O
        for b in range(1, nb):
            m, c, J = self.inertia[b]
            _, G, Gd, Gdd = self.point(st, b, c)
            _, om, al = lk["links"][self.names[b]]
            ke += w * w * (m * dot(Gd, Gd) + J * om * om) / 2
            terms = (w * w * m * dot(Gdd, Gd), w * w * J * al * om, -m * g * Gd[1])
            mvp += terms[0] + terms[1] + m * g * Gd[1]
            scale += sum(abs(x) for x in terms)
            ext[b] = [(0, -m * g), MPF(0)]                       # force, moment about G
            fsum = add(fsum, sub((0, -m * g), mul(m * w * w, Gdd)))
            msum += cross(G, sub((0, -m * g), mul(m * w * w, Gdd))) - J * w * w * al
            rhs.append((G, m * w * w, Gdd, J * w * w * al))
            fin = sub(fin, mul(m * w * w, Gdd))
            mIn += -cross(G, mul(m * w * w, Gdd)) - J * w * w * al
        for n, ld in enumerate(self.loads):
            b = ld["body"]
            r, v = self.point(st, b, (0, 0))[1:3]
            t, om = lk["links"][self.names[b]][:2]
            on = active[n] if active is not None else self.load_on(ld, sl.get(b, (0, 0)))
            if not on:
                continue
            if ld["kind"] == "torque":
                mvp -= ld["value"] * om
                scale += abs(ld["value"] * om)
                ext[b][1] += ld["value"]
                msum += ld["value"]
                continue
            F = ld["value"] if ld["kind"] == "force" else interp(ld["rows"], sl[b][0])
            Fv = mul(F, rot(t, (1, 0)))
            mvp -= dot(Fv, v)
            scale += abs(dot(Fv, v))
            ext[b][0] = add(ext[b][0], Fv)
            ext[b][1] += cross(sub(r, rhs[b - 1][0]), Fv)
            fsum, msum = add(fsum, Fv), msum + cross(r, Fv)
        lk.update(M=mvp, KE=ke, Fin=fin, Min=mIn)
        if ne:
            self.newton_euler(st, lk, ext, rhs, fsum, msum, max(scale, 1))
        return lk

    def newton_euler(self, st, lk, ext, rhs, fsum, msum, scale):
        """All links' 3 equations, all reaction components and the driving torque unknown."""
        nb = len(self.names)
        rows, cols, acts = [dict() for _ in range(3 * (nb - 1))], 0, []
        for jt in self.joints:
            if jt[0] == "rev":                      # F on i from j at the pin; -F on j
                _, i, si, j, sj = jt
                P = self.point(st, i, si)[1]
                for b, sg in ((i, 1), (j, -1)):
                    if b:
                        d = sub(P, rhs[b - 1][0])
                        k = 3 * (b - 1)
                        rows[k][cols], rows[k + 1][cols + 1] = sg, sg
                        rows[k + 2][cols], rows[k + 2][cols + 1] = -sg * d[1], sg * d[0]
                acts.append((jt, cols, P))
                cols += 2
            elif jt[0] == "pri":                    # N n at the pin and a couple C on i; minus on j
                _, i, j, al, tl, off = jt
                P, n = self.point(st, i, (0, 0))[1], rot(self.pose(st["q"], j)[1] + al, (0, 1))
                for b, sg in ((i, 1), (j, -1)):
                    if b:
                        k = 3 * (b - 1)
                        rows[k][cols], rows[k + 1][cols] = sg * n[0], sg * n[1]
                        rows[k + 2][cols] = sg * cross(sub(P, rhs[b - 1][0]), n)
                        rows[k + 2][cols + 1] = sg
                acts.append((jt, cols, (P, n)))
                cols += 2
            else:
                rows[3 * (jt[1] - 1) + 2][cols] = 1
                acts.append((jt, cols, None))
                cols += 1
        b_ = []
        for b in range(1, nb):
            G, mw2, Gdd, Jal = rhs[b - 1]
            F, Mz = ext[b]
            b_ += [mw2 * Gdd[0] - F[0], mw2 * Gdd[1] - F[1], Jal - Mz]
        x = lu_solve(lu_factor(rows, cols), b_)
        fsh, msh = (MPF(0), MPF(0)), MPF(0)       # what the mechanism puts on the frame
        for jt, c, geo in acts:
            if jt[0] == "drv":
                lk["M_ne"] = self.sense * x[c]
                msh -= x[c]
            elif jt[0] == "rev" and jt[3] == 0:
                fsh, msh = sub(fsh, (x[c], x[c + 1])), msh - cross(geo, (x[c], x[c + 1]))
            elif jt[0] == "pri" and jt[2] == 0:
                fsh, msh = sub(fsh, mul(x[c], geo[1])), msh - cross(geo[0], mul(x[c], geo[1])) - x[c + 1]
        lk.update(Fsh=fsh, Msh=msh)
        lk["reactions"], lk["slides"] = {}, {}       # acts: one per joint, in joint order
        for ji, (jt, c, geo) in enumerate(acts):
            if jt[0] == "rev":
                key, sg = self.joint_key[ji]
                lk["reactions"][key] = (sg * x[c], sg * x[c + 1])
            elif jt[0] == "pri":
                lk["slides"][self.names[jt[1]]] = (x[c], x[c + 1])
        bad = [(k, a, b) for k, a, b in (("torque", lk["M"], lk["M_ne"]), ("shaking Fx", fsh[0], fsum[0]),
                                         ("shaking Fy", fsh[1], fsum[1]), ("shaking M", msh, msum))
               if abs(a - b) > TOL * scale * 10]
        if bad:
            sys.exit("%s: CHECK FAILED at phi = %s: %s" % (self.name, lk["phi"], bad))
        lk["check"] = max(abs(lk["M"] - lk["M_ne"]), abs(msh - msum)) / scale

    # ---- cycle metrics -------------------------------------------------------
    def find_kinks(self):
        """Angles where a load has a kink or switches: s' = 0 (when-loads), s = a table row."""
        h, fns = 2 * mp.pi / GRID, []
        for ld in self.loads:
            if ld["kind"] != "torque":
                b = ld["body"]
                if ld["when"] != "always":
                    fns.append(lambda st, b=b: self.slider(st, b)[1])
                for x, _ in ld.get("rows", []):
                    fns.append(lambda st, b=b, x=x: self.slider(st, b)[0] - x)
        out = []
        for f in fns:
            v = [f(st) for st in self.grid]
            for k in range(GRID):
                if v[k] == 0:
                    out.append(k * h)
                elif v[k] * v[k + 1] < 0:
                    out.append(illinois(lambda p: f(self.state(p)), k * h, (k + 1) * h, v[k], v[k + 1]))
        return sorted(out)

    def sides(self, phi):
        """The loads' switch states just before and just after phi."""
        return [tuple(self.load_on(ld, self.slider(self.state(phi + e), ld["body"]) if ld["kind"] != "torque"
                                   else None) for ld in self.loads) for e in (-KINK_GAP, KINK_GAP)]

    def extremum(self, f, sign, ne=False, df=None):
        """(value, phi) of the maximum of sign * f(look) over the cycle: grid, refine, kinks."""
        h, tp = 2 * mp.pi / GRID, 2 * mp.pi
        vals = [sign * f(lk) for lk in self.looks]
        j = max(range(GRID), key=lambda k: vals[k])
        best = (vals[j], j * h)
        a, b = (j - 1) * h, (j + 1) * h
        der = df or (lambda p: mp.diff(lambda x: f(self.look(self.state(x), ne=ne)), p))
        cut = sorted(k + s for k in self.kinks for s in (-tp, 0, tp) if a < k + s < b)
        for lo, hi in zip([a] + cut, cut + [b]):    # f is smooth between kinks: stay off them
            lo, hi = lo + (lo != a) * KINK_GAP, hi - (hi != b) * KINK_GAP
            da, db = der(lo), der(hi)
            if sign * da > 0 > sign * db:
                p = illinois(der, lo, hi, da, db)
                best = max(best, (sign * f(self.look(self.state(p), ne=ne)), p))
        for k in self.kinks:
            for act in self.sides(k):
                best = max(best, (sign * f(self.look(self.state(k), act, ne)), k))
        return sign * best[0], best[1] % tp

    def cycle_means(self, fs):
        """Means over the cycle, Gauss-Legendre per piece: (24-node value, |24 - 16|)."""
        tp = 2 * mp.pi
        cuts = self.kinks or [MPF(0)]
        sums = {n: [MPF(0)] * len(fs) for n in GL}
        for a, b in zip(cuts, cuts[1:] + [cuts[0] + tp]):
            m = int(mp.ceil((b - a) / (mp.pi / 8)))
            for i in range(m):
                lo, hi = a + (b - a) * i / m, a + (b - a) * (i + 1) / m
                for n, (xs, ws) in GL.items():
                    for x, wt in zip(xs, ws):
                        lk = self.look(self.state(mp.fmod((lo + hi) / 2 + (hi - lo) / 2 * x, tp)), ne=False)
                        for k, f in enumerate(fs):
                            sums[n][k] += wt * (hi - lo) / 2 * f(lk)
        return [(s / tp, abs(s - t) / tp) for s, t in zip(sums[24], sums[16])]


def interp(rows, s):
    if s <= rows[0][0]:
        return rows[0][1]
    for (x0, y0), (x1, y1) in zip(rows, rows[1:]):
        if s <= x1:
            return y0 + (y1 - y0) * (s - x0) / (x1 - x0)
    return rows[-1][1]


# ---- output ------------------------------------------------------------------
def at_angle(lk):
    pts = {p: {"x": fl(P[0]), "y": fl(P[1]), "dx": fl(Pd[0]), "dy": fl(Pd[1]),
               "ddx": fl(Pdd[0]), "ddy": fl(Pdd[1])} for p, (P, Pd, Pdd) in lk["points"].items()}
    return {"points": pts,
            "links": {n: {"angle": fl(mp.atan2(mp.sin(t), mp.cos(t))), "d": fl(d), "dd": fl(dd)}
                      for n, (t, d, dd) in lk["links"].items()},
            "sliders": {n: {"s": fl(s), "d": fl(d), "dd": fl(dd)} for n, (s, d, dd) in lk["sliders"].items()},
            "drive_torque_virtual_power": fl(lk["M"]), "drive_torque_newton_euler": fl(lk["M_ne"]),
            "kinetic_energy": fl(lk["KE"]), "frame_force": {"x": fl(lk["Fsh"][0]), "y": fl(lk["Fsh"][1])},
            "frame_moment": fl(lk["Msh"]),
            "shaking_force": {"x": fl(lk["Fin"][0]), "y": fl(lk["Fin"][1])}, "shaking_moment": fl(lk["Min"]),
            "reactions": {k: {"x": fl(f[0]), "y": fl(f[1])} for k, f in lk["reactions"].items()},
            "slides": {k: {"normal": fl(f[0]), "couple": fl(f[1])} for k, f in lk["slides"].items()},
            "transmission_angle": {k: fl(v) for k, v in lk["trans"].items()},
            "pressure_angle": {k: fl(v) for k, v in lk["press"].items()}}


def ext(v, p):
    return {"value": fl(v), "phi_deg": fl(p * 180 / mp.pi)}


def output_metrics(lk, o):
    """Stroke, peak |velocity|, peak |acceleration|, time ratio of output link o."""
    w, tp = lk.speed, 2 * mp.pi
    if lk.body[o] in lk.slider_joint:
        f = lambda x: x["sliders"][o]
        jet = lambda p: lk.slider(lk.state(p), lk.body[o])
        unit = "m"
    else:
        f = lambda x: x["links"][o]
        jet = lambda p: tuple(lk.pose(lk.state(p)[k], lk.body[o])[1] for k in ("q", "qd", "qdd"))
        unit = "rad"
    lo = lk.extremum(lambda x: f(x)[0], -1, df=lambda p: jet(p)[1])
    hi = lk.extremum(lambda x: f(x)[0], 1, df=lambda p: jet(p)[1])
    v = lk.extremum(lambda x: abs(f(x)[1]), 1, df=lambda p: mp.sign(jet(p)[1]) * jet(p)[2])
    a = lk.extremum(lambda x: abs(f(x)[2]), 1)
    fwd = (hi[1] - lo[1]) % tp
    return {"unit": unit, "stroke": fl(hi[0] - lo[0]), "min": ext(*lo), "max": ext(*hi),
            "peak_velocity": ext(w * v[0], v[1]), "peak_acceleration": ext(w * w * a[0], a[1]),
            "time_ratio": fl(fwd / (tp - fwd))}, (hi[0] - lo[0], w * w * a[0], a[1], fwd / (tp - fwd))


def analyse(path, report=True):
    with open(path) as f:
        lk = Linkage(yaml.safe_load(f), path.rsplit("/", 1)[-1].rsplit(".", 1)[0])
    t0 = time.time()
    lk.run_grid()
    res = {"file": path, "speed_rad_s": fl(lk.speed), "gravity": lk.gravity,
           "kinks_deg": [fl(k * 180 / mp.pi) for k in lk.kinks],
           "worst_check_relative": mp.nstr(max(x["check"] for x in lk.looks), 3)}
    res["at_deg"] = {str(d): at_angle(lk.look(lk.state(MPF(d) * mp.pi / 180))) for d in REPORT_DEG}
    outs = {o: output_metrics(lk, o) for o in lk.outputs}
    res["outputs"] = {o: v[0] for o, v in outs.items()}
    if report:
        m = lk.extremum(lambda x: abs(x["M"]), 1)
        ke = lk.extremum(lambda x: x["KE"], 1)
        fsh = lk.extremum(lambda x: mp.sqrt(dot(x["Fin"], x["Fin"])), 1)
        msh = lk.extremum(lambda x: abs(x["Min"]), 1)
        reac = {k: ext(*lk.extremum(lambda x, k=k: mp.sqrt(dot(x["reactions"][k], x["reactions"][k])), 1, ne=True))
                for k in lk.looks[0]["reactions"]}
        (mean, e1), (ms, e2), (kem, e3) = lk.cycle_means([lambda x: x["M"], lambda x: x["M"] ** 2,
                                                         lambda x: x["KE"]])
        res["cycle"] = {
            "peak_drive_torque": ext(*m), "mean_drive_torque": fl(mean), "rms_drive_torque": fl(mp.sqrt(ms)),
            "quad_error_estimate": {"mean": mp.nstr(e1, 3), "mean_square": mp.nstr(e2, 3),
                                    "mean_kinetic_energy": mp.nstr(e3, 3)},
            "peak_kinetic_energy": ext(*ke), "mean_kinetic_energy": fl(kem),
            "peak_shaking_force": ext(*fsh), "peak_shaking_moment": ext(*msh), "peak_reaction": reac,
            "min_transmission_angle": {g["key"]: ext(*lk.extremum(lambda x, k=g["key"]: x["trans"][k], -1))
                                       for g in lk.groups if g["type"] == "RRR"},
            "max_pressure_angle": {g["key"]: ext(*lk.extremum(lambda x, k=g["key"]: x["press"][k], 1))
                                   for g in lk.groups if g["type"] in ("RRP", "PRP")}}
    res["seconds"] = round(time.time() - t0, 1)
    return lk, res, {o: v[1] for o, v in outs.items()}


def selftest():
    """Closed forms of the centred slider-crank, jets against mp.diff, the Whitworth ratio, the wedge."""
    fails = []

    def check(what, a, b, tol):
        ok = abs(a - b) <= tol * max(1, abs(b))
        print("%-58s %s  %s" % (what, "ok  " if ok else "FAIL", mp.nstr(abs(a - b), 3)), file=sys.stderr)
        fails.extend([] if ok else [what])

    lk, res, outs = analyse("configs/linkage/slider_crank.yaml", report=False)
    r, l, w = lk.length(lk.crank), lk.length(lk.body["rod"]), lk.speed
    stroke, amax, aphi, _ = outs["ram"]
    check("slider_crank: stroke = 2 r", stroke, 2 * r, MPF(10) ** -25)
    check("slider_crank: peak acceleration = r w^2 (1 + r/l)", amax, r * w * w * (1 + r / l), TOL)
    check("slider_crank: ... at phi = 0", mp.sin(aphi), 0, MPF(10) ** -15)
    xb = lambda p: r * mp.cos(p) + mp.sqrt(l * l - (r * mp.sin(p)) ** 2)
    for d in (0, 37, 123, 250):
        p = MPF(d) * mp.pi / 180
        s = lk.slider(lk.state(p), lk.body["ram"])
        for n in range(3):
            check("slider_crank: x_B^(%d) closed form, phi = %d deg" % (n, d), s[n], mp.diff(xb, p, n), TOL)
    for path in ("configs/linkage/slider_crank.yaml", "configs/linkage/watt2_sixbar.yaml",
                 "configs/linkage/stephenson3_sixbar.yaml", "configs/linkage/whitworth_shaper.yaml",
                 "configs/linkage/wedge_press.yaml"):
        with open(path) as f:
            k = Linkage(yaml.safe_load(f), path)
        k.grid = [k.kin(MPF(0), k.seed())] * (GRID + 1)
        for d in (1, 5, 20):     # within the Newton predictor's reach of phi = 0
            p = MPF(d) / 10
            st = k.state(p)
            for i in range(k.nq):
                for n, key in ((1, "qd"), (2, "qdd")):
                    check("%s: q[%d]^(%d) vs mp.diff at phi = %s" % (path.split("/")[-1], i, n, p),
                          st[key][i], mp.diff(lambda x: k.state(x)["q"][i], p, n), MPF(10) ** -15)
    lk, res, outs = analyse("configs/linkage/whitworth_shaper.yaml")
    cut = [ld["value"] for ld in lk.loads if ld["when"] == "forward"][0]
    check("whitworth: mean torque = cutting work / 2 pi", num(res["cycle"]["mean_drive_torque"]),
          -cut * outs["ram"][0] / (2 * mp.pi), MPF(10) ** -18)
    O2, O4, r = lk.world(lk.grid[0]["q"], lk.pivot), lk.points["O4"][1], lk.length(lk.crank)
    c, T = mp.sqrt(dot(sub(O4, O2), sub(O4, O2))), lk.joints[lk.slider_joint[lk.body["ram"]]][4]
    check("whitworth: O4 on the ram line, O2O4 across it", abs(O4[1] - T[1]) + abs(O4[0] - O2[0]), 0, TOL)
    check("whitworth: time ratio (pi + 2 asin(c/r)) / (pi - 2 asin(c/r))", outs["ram"][3],
          (mp.pi + 2 * mp.asin(c / r)) / (mp.pi - 2 * mp.asin(c / r)), MPF(10) ** -20)
    lk, res, outs = analyse("configs/linkage/wedge_press.yaml", report=False)
    check("wedge_press: ram stroke = tan(20.5 deg) wedge stroke", outs["ram"][0],
          mp.tan(MPF("20.5") * mp.pi / 180) * outs["wedge"][0], TOL)
    print("selftest: %s" % ("FAILED: %s" % fails if fails else "all ok"), file=sys.stderr)
    return 1 if fails else 0


def main():
    if sys.argv[1:] == ["--selftest"]:
        sys.exit(selftest())
    if not sys.argv[1:]:
        sys.exit(__doc__)
    out = {"source": "tests/ref/linkage_ref.py (mpmath %d digits, Newton on the constraints)" % mp.mp.dps,
           "conventions": {"transfer_functions": "per radian of phi; velocity = speed * d, acceleration = speed^2 * dd",
                           "drive_torque": "on the crank, positive in the sense of rotation (sense)",
                           "frame": "forces of the mechanism on the frame at ground joints and slider lines;"
                                    " moment about the origin incl. the line couples and the motor reaction -M;"
                                    " process loads not included",
                           "shaking": "the inertia forces' resultant -sum m a_G and its moment about the origin"
                                      " -sum (J alpha + G x m a_G)",
                           "reactions": "POINT_LINK: force on LINK from the body that carries POINT (the link"
                                        " defining it: the crank its joint, an RRR group's first link its joint, an"
                                        " RRP group's slider its pin, a PRP group's first slider its pin; or"
                                        " the ground)",
                           "slides": "on the slider (block) from its line's body (guide): normal along rot90(u),"
                                     " couple",
                           "angles": "rad; link angles at the listed phi wrapped to (-pi, pi], metrics unwrapped",
                           "slider_s": "(pin - line point T) . u", "grid": GRID},
           "configs": {}}
    for path in sys.argv[1:]:
        lk, res, _ = analyse(path)
        out["configs"][lk.name] = res
        print("%s: %.0f s" % (path, time.time() - T0), file=sys.stderr)
    out["seconds"] = round(time.time() - T0, 1)
    json.dump(out, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()
