#!/usr/bin/env python3
"""Where each driver fails on a nonsmooth maximum (docs/drivers.md, "Kinks"),
run by run_bench.py or alone:

  /usr/bin/python3 bench/kink_map.py [--build build] [--no-docs]

configs/recuperative_drive/rod_and_phase.yaml (least peak kinetic energy over
rod length and phase shift; three peaks over the cycle are equal at the
optimum) run from a 7 x 7 grid of start points by each driver, as a user runs
it (`mechopt run`): each run's status and peak energy. Writes
docs/img/kink_map_rod_and_phase.svg (status over the two start values, one
panel a driver) and the block `kink_map` of docs/drivers.md.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

import doe_bench  # write_block

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CONFIG = os.path.join(ROOT, "configs", "recuperative_drive", "rod_and_phase.yaml")
STUDY = "study: {type: optimize, driver: {library: nlopt, algorithm: LD_SLSQP, xtol_rel: 1e-12}}"
START = "phase_shift: 90 deg, rod_length: 0.8 m"
OPTIMUM = 2770.28  # J, docs/reproduction.md (a 0.05 deg x 0.1 m grid confirms it)
RODS = [0.7, 0.833, 0.967, 1.1, 1.233, 1.367, 1.5]  # m (r/l <= 0.3 needs l >= 0.667 m)
PHASES = [35, 53, 72, 90, 108, 127, 145]  # deg
DRIVERS = [("LD_SLSQP", "{library: nlopt, algorithm: LD_SLSQP, xtol_rel: 1e-12}"),
           ("ipopt, epigraph", "{library: ipopt, epigraph: true}"),
           ("LN_COBYLA", "{library: nlopt, algorithm: LN_COBYLA, xtol_rel: 1e-12}"),
           ("LD_MMA", "{library: nlopt, algorithm: LD_MMA, xtol_rel: 1e-12}"),
           ("ipopt, bare max", "{library: ipopt, epigraph: false}")]
COLORS = {"converged": "#2ca02c", "stopped_on_kink": "#ff7f0e", "stopped_on_slope": "#17becf",
          "failure": "#d62728", "infeasible": "#9467bd", "max_evaluations": "#7f7f7f"}


def run_all(binary):
    """{driver: [(rod, phase, status, peak energy or None)]}"""
    text = open(CONFIG).read()
    if STUDY not in text or START not in text:
        sys.exit(f"kink_map: {CONFIG} changed: update STUDY and START here")
    work = tempfile.mkdtemp(prefix="kink_map_")
    out = {}
    try:
        for label, driver in DRIVERS:
            runs = []
            for rod in RODS:
                for phase in PHASES:
                    config = text.replace(STUDY, "study: {type: optimize, driver: " + driver + "}")
                    config = config.replace(START, f"phase_shift: {phase} deg, rod_length: {rod} m")
                    path = os.path.join(work, "config.yaml")
                    open(path, "w").write(config)
                    dest = os.path.join(work, "out")
                    shutil.rmtree(dest, ignore_errors=True)
                    subprocess.run([binary, "run", path, "--output", dest], check=True, capture_output=True)
                    j = json.load(open(os.path.join(dest, "result.json")))
                    value = j["objective"]["value"]
                    runs.append((rod, phase, j["status"], value if isinstance(value, float) else None))
            out[label] = runs
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return out


def write_svg(path, results):
    cell, gap, left, top = 30, 36, 70, 50
    panel = cell * len(RODS)
    width = left + len(results) * (panel + gap) + 10
    height = top + cell * len(PHASES) + 110
    out = [f"<svg xmlns='http://www.w3.org/2000/svg' width='{width}' height='{height}' "
           "font-family='sans-serif' font-size='11'>",
           "<rect width='100%' height='100%' fill='white'/>",
           f"<text x='{width / 2}' y='18' text-anchor='middle' font-size='14'>rod_and_phase.yaml: "
           "each driver's status from 49 start points (cell text: peak T above the optimum, %)</text>"]
    for p, (label, runs) in enumerate(results.items()):
        x0 = left + p * (panel + gap)
        out.append(f"<text x='{x0 + panel / 2}' y='{top - 8}' text-anchor='middle' font-size='12'>{label}</text>")
        for rod, phase, status, value in runs:
            i, k = RODS.index(rod), PHASES.index(phase)
            x, y = x0 + i * cell, top + (len(PHASES) - 1 - k) * cell
            out.append(f"<rect x='{x}' y='{y}' width='{cell - 1}' height='{cell - 1}' "
                       f"fill='{COLORS.get(status, '#000000')}'/>")
            if value is not None:
                excess = 100 * (value / OPTIMUM - 1)
                out.append(f"<text x='{x + cell / 2}' y='{y + cell / 2 + 4}' text-anchor='middle' font-size='9' "
                           f"fill='white'>{excess:.1f}</text>")
        for i, rod in enumerate(RODS):
            if i % 2 == 0:
                out.append(f"<text x='{x0 + i * cell + cell / 2}' y='{top + cell * len(PHASES) + 14}' "
                           f"text-anchor='middle'>{rod:.2f}</text>")
        out.append(f"<text x='{x0 + panel / 2}' y='{top + cell * len(PHASES) + 30}' text-anchor='middle'>"
                   "start rod length [m]</text>")
    for k, phase in enumerate(PHASES):
        out.append(f"<text x='{left - 6}' y='{top + (len(PHASES) - 1 - k) * cell + cell / 2 + 4}' "
                   f"text-anchor='end'>{phase}</text>")
    out.append(f"<text transform='translate(22,{top + cell * len(PHASES) / 2}) rotate(-90)' "
               "text-anchor='middle'>start phase shift [deg]</text>")
    legend_y = top + cell * len(PHASES) + 60
    present = {r[2] for runs in results.values() for r in runs}
    for n, (status, color) in enumerate((s, c) for s, c in COLORS.items() if s in present):
        x = left + n * 150
        out.append(f"<rect x='{x}' y='{legend_y - 10}' width='12' height='12' fill='{color}'/>"
                   f"<text x='{x + 18}' y='{legend_y}'>{status}</text>")
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def block(results):
    lines = ["| driver | converged | stopped_on_kink | failure | other | converged: worst peak T | "
             "stopped_on_kink: median peak T |", "|---|---|---|---|---|---|---|"]
    for label, runs in results.items():
        count = lambda s: sum(1 for r in runs if r[2] == s)
        other = len(runs) - count("converged") - count("stopped_on_kink") - count("failure")
        conv = [r[3] for r in runs if r[2] == "converged" and r[3] is not None]
        kink = sorted(r[3] for r in runs if r[2] == "stopped_on_kink" and r[3] is not None)
        worst = f"{max(conv):.2f} J" if conv else "-"
        median = f"{kink[len(kink) // 2]:.2f} J" if kink else "-"
        lines.append(f"| {label} | {count('converged')} | {count('stopped_on_kink')} | {count('failure')} | "
                     f"{other} | {worst} | {median} |")
    return "\n".join(lines)


def write_block(path, body):
    doe_bench.write_block(path, body, "kink_map", "bench/kink_map.py")


def run(build, write_docs):
    """Rows for build/bench-results.json; with write_docs, the chart and drivers.md's block."""
    results = run_all(os.path.join(build, "bin", "mechopt"))
    if write_docs:
        write_svg(os.path.join(ROOT, "docs", "img", "kink_map_rod_and_phase.svg"), results)
        write_block(os.path.join(ROOT, "docs", "drivers.md"), block(results))
        print("written: docs/img/kink_map_rod_and_phase.svg, docs/drivers.md (kink_map)", file=sys.stderr)
    return [{"case": f"kink_map_{label.replace(', ', '_').replace(' ', '_')}",
             "statuses": {s: sum(1 for r in runs if r[2] == s) for s in {r[2] for r in runs}}}
            for label, runs in results.items()]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--no-docs", action="store_true")
    a = ap.parse_args()
    results = run_all(os.path.join(a.build, "bin", "mechopt"))
    if not a.no_docs:
        write_svg(os.path.join(ROOT, "docs", "img", "kink_map_rod_and_phase.svg"), results)
        write_block(os.path.join(ROOT, "docs", "drivers.md"), block(results))
    print(block(results))


if __name__ == "__main__":
    main()
