#!/usr/bin/env python3
"""Does any driver say `converged` where it is not at an optimum?

Every shipped optimisation config (configs/**.yaml with `type: optimize`, not
a global-then-local chain) is
run from random start points (uniform in the variables' boxes, seed 7) with
each local driver. Every run that reports `converged` is then probed
independently of the driver's own checks: each variable is moved by 1% of its
range either way (the others held, inside the bounds) through `mechopt eval`,
and a probe that meets every constraint and lowers the objective by more than
1e-4 of it counts against the run; so does Ipopt run from the answer when it converges
lower by more than 1e-4. Configs with an equality constraint get only the
Ipopt check (a probe leaves the constraint).

  /usr/bin/python3 bench/driver_scan.py [--build build] [--starts 5] [--write-docs]

Prints one row per config and driver: statuses, converged runs a probe or
Ipopt improves (should be 0), the best and worst converged objective. Takes about
10 minutes on one core; --write-docs puts the table in docs/drivers.md.
"""
import argparse
import collections
import glob
import json
import os
import random
import re
import subprocess
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DRIVERS = ["LD_SLSQP", "LD_MMA", "LD_CCSAQ", "LN_COBYLA", "ipopt"]
STEP, CHANGE = 0.01, 1e-4


def with_driver(text, driver, out):
    spec = "{library: ipopt}" if driver == "ipopt" else "{library: nlopt, algorithm: %s}" % driver
    text = re.sub(r"driver: \{[^}]*\}", "driver: " + spec, text, count=1)
    return re.sub(r"directory: [^}\n]*", "directory: " + out, text)


def with_initial(text, x):
    for name, value in x.items():
        m = re.search(r"(\b%s:\s*\{)([^}]*)\}" % name, text)
        body = re.sub(r"\s*initial:\s*[^,}]+,?", "", m.group(2)).strip().strip(",").strip()
        text = text[:m.start()] + m.group(1) + "initial: %.17g, " % value + body + "}" + text[m.end():]
    return text


def meets(constraints, metrics):
    for k in constraints:
        v = metrics.get(k["metric"])
        if v is None:
            return False
        if "max" in k and v > k["max"] + 1e-6 * max(1, abs(k["max"])):
            return False
        if "min" in k and v < k["min"] - 1e-6 * max(1, abs(k["min"])):
            return False
    return True


def scan(binary, starts):
    work = tempfile.mkdtemp(prefix="driver_scan_")
    config, out = os.path.join(work, "config.yaml"), os.path.join(work, "out")
    rows = []

    def mechopt(*args):
        return subprocess.run([binary, *args], capture_output=True, text=True, timeout=600)

    for path in sorted(glob.glob(os.path.join(ROOT, "configs", "**", "*.yaml"), recursive=True)):
        text = open(path).read()
        if not re.search(r"type:\s*optimize", text) or "variables" not in text or "polish" in text:
            continue  # global-then-local chains: their local stages are the drivers scanned
        name = os.path.relpath(path, os.path.join(ROOT, "configs"))[:-5]
        open(config, "w").write(re.sub(r"directory: [^}\n]*", "directory: " + out, text))  # its own driver
        if mechopt("run", config).returncode != 0:
            continue
        first = json.load(open(os.path.join(out, "result.json")))
        box = first["variables"]
        constraints = first.get("constraints", [])
        probed = not any("equal" in k for k in constraints)
        metric, sense = first["objective"]["metric"], first["objective"]["sense"]
        sign = 1 if sense == "minimize" else -1
        rng = random.Random(7)
        points = [{n: v["min"] + (v["max"] - v["min"]) * rng.random() for n, v in box.items()} for _ in range(starts)]
        for driver in DRIVERS:
            row = {"config": name, "driver": driver, "statuses": collections.Counter(), "improved": 0,
                   "converged": [], "probed": probed}
            for x0 in points:
                open(config, "w").write(with_initial(with_driver(text, driver, out), x0))
                if mechopt("run", config).returncode != 0:
                    row["statuses"]["refused"] += 1
                    continue
                j = json.load(open(os.path.join(out, "result.json")))
                row["statuses"][j["status"]] += 1
                if j["status"] != "converged":
                    continue
                f = j["objective"]["value"]
                row["converged"].append(f)
                x = {n: v["value"] for n, v in j["variables"].items()}
                # Ipopt (epigraph rows for maxima over the cycle) from the answer.
                open(config, "w").write(with_initial(with_driver(text, "ipopt", out), x))
                if mechopt("run", config).returncode == 0:
                    p = json.load(open(os.path.join(out, "result.json")))
                    if p["status"] == "converged" and sign * (f - p["objective"]["value"]) > CHANGE * abs(f):
                        row["improved"] += 1
                        continue
                open(config, "w").write(with_initial(with_driver(text, driver, out), x0))
                for n, v in box.items() if probed else []:
                    lower = False
                    for side in (-1, 1):
                        y = x[n] + side * STEP * (v["max"] - v["min"])
                        if not v["min"] <= y <= v["max"]:
                            continue
                        sets = sum((["--set", "%s=%.17g" % (m, y if m == n else xm)] for m, xm in x.items()), [])
                        e = json.loads(mechopt("eval", config, *sets).stdout)
                        fy = e["metrics"].get(metric) if e.get("status") == "ok" else None
                        lower = lower or (fy is not None and meets(constraints, e["metrics"])
                                          and sign * (f - fy) > CHANGE * abs(f))
                    if lower:
                        row["improved"] += 1
                        break
            if row["statuses"].get("refused", 0) < starts:
                rows.append(row)
    return rows


def table(rows, starts):
    lines = [f"| config | driver | statuses ({starts} starts) | converged runs a probe or Ipopt improves | "
             "converged: best | converged: worst |", "|---|---|---|---|---|---|"]
    for r in rows:
        st = ", ".join(f"{k} {v}" for k, v in sorted(r["statuses"].items()) if k != "refused")
        c = r["converged"]
        improved = str(r["improved"]) + ("" if r["probed"] else " (Ipopt only: an equality)")
        best, worst = (f"{min(c):.8g}", f"{max(c):.8g}") if c else ("-", "-")
        lines.append(f"| {r['config']} | {r['driver']} | {st} | {improved} | {best} | {worst} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--starts", type=int, default=5)
    ap.add_argument("--write-docs", action="store_true")
    a = ap.parse_args()
    rows = scan(os.path.join(a.build, "bin", "mechopt"), a.starts)
    body = table(rows, a.starts)
    print(body)
    if a.write_docs:
        path = os.path.join(ROOT, "docs", "drivers.md")
        doc = open(path).read()
        begin = "<!-- generated by bench/driver_scan.py: driver_scan -->"
        end = "<!-- end driver_scan -->"
        doc = re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda _: f"{begin}\n\n{body}\n\n{end}", doc,
                     flags=re.S)
        open(path, "w").write(doc)
    return 1 if any(r["improved"] for r in rows) else 0


if __name__ == "__main__":
    raise SystemExit(main())
