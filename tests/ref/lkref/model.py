"""The linkage's description: quantities with units, and the YAML model read
into bodies, points, joints (revolute, prismatic, the crank's driver),
groups, masses and loads."""
import re

import mpmath as mp

from .numeric import MPF

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


class Mechanism:
    """The description; kinematics and dynamics build on it."""

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
