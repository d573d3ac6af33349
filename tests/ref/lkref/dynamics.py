"""The linkage's dynamics and cycle: the driving torque by virtual power and
by a global Newton-Euler solve (which gives every joint's reaction), the
frame and shaking forces, both checked against each other at every point;
the Newton continuation over the grid, the loads' kinks, extrema refined by
root search, and Gauss-Legendre means over the cycle."""
import sys

import mpmath as mp

from .kinematics import Kinematics
from .numeric import (G_STD, GL, GRID, KINK_GAP, MPF, TOL, add, cross, dot, illinois,
                      interp, lu_factor, lu_solve, mul, rot, sub)


class Linkage(Kinematics):
    # ---- loads, torque, reactions ----------------------------------------------
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

    # ---- the grid over the cycle ------------------------------------------------
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
