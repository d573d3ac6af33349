#!/usr/bin/env python3
"""Epsilon-constraint against evolutionary Pareto fronts (docs/drivers.md,
"Evolutionary fronts"): for the conveyor and the sawmill, runs the shipped
pareto.yaml (Ipopt, 101 points) and pareto_evolution.yaml under NSGA-II,
MOEA/D and NSPSO (pagmo, 100 designs, 100 generations, seed 1) through the
mechopt binary, each --repetitions times, and prints one Markdown row per
method: the normalised hypervolume, its ratio to the epsilon-constraint
front's, the designs evaluated, the median seconds of the front itself (the
evolutionary runs' two Ipopt optima apart, in their own column) and, for an
evolutionary front, the generation, designs and seconds at which its
hypervolume first came within 1% of the epsilon-constraint front's. Then the
disconnected front of conveyor_swing/pareto_gap.yaml: the epsilon-constraint
front from Ipopt, the same from ISRES polished by Ipopt, and NSGA-II, with
the least pressure angle each found and the pieces of the l_CO1 family on
its front.
Usage: /usr/bin/python3 bench/fronts.py [--binary build/bin/mechopt] [--repetitions 5] [--threads 1]
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROBLEMS = ["conveyor_swing", "balanced_slider_crank"]
ALGORITHMS = ["nsga2", "moead", "nspso"]


# The disconnected front's epsilon-constraint study with a global driver
# (each point ISRES, then Ipopt from its answer) in place of Ipopt alone.
GLOBAL_DRIVER = ("driver: {library: ipopt}",
                 "driver: {library: nlopt, algorithm: GN_ISRES, max_evaluations: 2000, polish: {library: ipopt}}")


def run(binary, config, threads, algorithm=None, replace=None):
    """result.json's pareto of one run; the algorithm (or `replace`'s text) replaced in a copy of the config."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(ROOT, "configs", config)
        if algorithm:
            replace = ("algorithm: nsga2", "algorithm: " + algorithm)
        if replace:
            text = open(path).read().replace(*replace)
            path = os.path.join(tmp, "config.yaml")
            with open(path, "w") as f:
                f.write(text)
        cmd = [binary, "run", path, "--output", os.path.join(tmp, "out")]
        if "pagmo" in open(path).read():
            cmd += ["--threads", str(threads)]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        with open(os.path.join(tmp, "out", "result.json")) as f:
            return json.load(f)["pareto"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "bin", "mechopt"))
    ap.add_argument("--repetitions", type=int, default=5)
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args()
    print("| problem | front | hypervolume | / epsilon | designs | seconds (median) | the two optima [s] "
          "| within 1% at: generation, designs, seconds |")
    print("|---|---|---:|---:|---:|---:|---:|---|")
    for problem in PROBLEMS:
        eps = [run(a.binary, problem + "/pareto.yaml", a.threads) for _ in range(a.repetitions)]
        target = eps[0]["hypervolume"]
        print(f"| {problem} | epsilon-constraint, Ipopt, {eps[0]['points_done']} points | {target:.5f} | 1 "
              f"| {eps[0]['evaluations']} | {statistics.median(r['seconds'] for r in eps):.3f} | (in the front) | |")
        for algorithm in ALGORITHMS:
            evo = [run(a.binary, problem + "/pareto_evolution.yaml", a.threads, algorithm)
                   for _ in range(a.repetitions)]
            hv = evo[0]["hypervolume"]
            reached = [h for h in evo[0]["history"] if h["hypervolume"] >= 0.99 * target]
            at = "never"
            if reached:
                g = reached[0]["generation"]
                seconds = statistics.median(r["history"][g - 1]["seconds"] for r in evo)
                at = f"{g}, {reached[0]['evaluations']}, {seconds:.3f}"
            print(f"| {problem} | {algorithm}, {len(evo[0]['points'])} points | {hv:.5f} | {hv / target:.4f} "
                  f"| {evo[0]['evaluations']} | {statistics.median(r['seconds'] for r in evo):.3f} "
                  f"| {statistics.median(r['anchor_seconds'] for r in evo):.3f} | {at} |")
    print()
    print("| conveyor_swing/pareto_gap | points | least max_pressure_angle [deg] | l_CO1 on the front [m] "
          "| designs | seconds (median) |")
    print("|---|---:|---:|---|---:|---:|")
    for label, config, replace in [("epsilon-constraint, Ipopt", "pareto_gap.yaml", None),
                                   ("epsilon-constraint, ISRES then Ipopt", "pareto_gap.yaml", GLOBAL_DRIVER),
                                   ("nsga2", "pareto_gap_evolution.yaml", None)]:
        runs = [run(a.binary, "conveyor_swing/" + config, a.threads, replace=replace) for _ in range(a.repetitions)]
        pts = runs[0]["points"]
        l = sorted({round(p["variables"]["l_co1"]["value"], 3) for p in pts})
        pieces, start = [], l[0]
        for prev, cur in zip(l, l[1:] + [None]):
            if cur is None or cur - prev > 0.05:
                pieces.append(f"{start:.3f}" if start == prev else f"{start:.3f}-{prev:.3f}")
                start = cur
        least = min(p["max_pressure_angle"] for p in pts) * 180 / math.pi
        print(f"| {label} | {len(pts)} | {least:.2f} | {', '.join(pieces)} | {runs[0]['evaluations']} "
              f"| {statistics.median(r['seconds'] for r in runs):.3f} |")


if __name__ == "__main__":
    main()
