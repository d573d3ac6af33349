"""The linkage reference's output and command line: a config analysed into
the JSON that tests/test_linkage_reference.cpp reads (states at REPORT_DEG,
output metrics, cycle metrics), the selftest, and main."""
import json
import sys
import time

import mpmath as mp
import yaml

from .dynamics import Linkage
from .model import num
from .numeric import GRID, MPF, TOL, dot, sub

T0 = time.time()
REPORT_DEG = (0, 37, 90, 200, 300)


def fl(x):
    return mp.nstr(x, 20, min_fixed=-5, max_fixed=8) if x != 0 else "0"


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


def main(usage):
    if sys.argv[1:] == ["--selftest"]:
        sys.exit(selftest())
    if not sys.argv[1:]:
        sys.exit(usage)
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

