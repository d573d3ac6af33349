"""The linkage's kinematics: the constraint equations Phi(q, phi) = 0 with
their Jacobian and quadratic velocity terms, Newton on them, the transfer
functions q' and q'' from the Jacobian's linear systems, the design's
closed form used only to seed the branch at phi = 0, and the states,
points and slider coordinates along the cycle."""
import mpmath as mp

from .model import Mechanism
from .numeric import (GRID, MPF, add, cross, dot, lu_factor, lu_solve, mul, perp,
                      rot, sub)


class Kinematics(Mechanism):
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

    # ---- along the cycle: states, points, sliders ------------------------------
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

