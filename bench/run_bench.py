#!/usr/bin/env python3
"""Runs the Google Benchmark cases and the Python peers in the same run, and
writes build/bench-results.json: one row per case with mechopt and peer
medians, their ratio (peer_seconds / mechopt_seconds) and each one's relative
error against the high-precision references (tools/reference_seed000.json,
tools/reference_seed002.json).
Usage: /usr/bin/python3 bench/run_bench.py [--build build] [--repetitions 5]
"""
import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def google_benchmark(binary, repetitions):
    out = subprocess.run([binary, "--benchmark_format=json",
                          f"--benchmark_repetitions={repetitions}",
                          "--benchmark_min_time=0.1"],
                         check=True, capture_output=True, text=True).stdout
    rows = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") == "median":
            unit = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
            rows[b["run_name"].replace("/iterations:1", "")] = {"seconds": b["real_time"] * unit, "value": b.get("value"),
                                   "steps": b.get("steps"), "ok": b.get("ok"),
                                   "gradient": b.get("gradient"),
                                   "evaluations": b.get("evaluations"),
                                   "error": b.get("error"), "converged": b.get("converged")}
    return rows


def write_work_precision_svg(path, scene, drivers):
    """Log-log chart: error of the optimal variable against time, one line per
    driver over its tolerances; hollow markers where the driver did not
    report convergence."""
    import math
    W, H, L, R, T, B = 820, 480, 80, 250, 40, 60
    pts = [(t, e) for runs in drivers.values() for t, e, _, _ in runs if e and e > 0]
    floor = 1e-17
    xs = [math.log10(t) for t, _ in pts]
    ys = [math.log10(max(e, floor)) for _, e in pts]
    x0, x1 = math.floor(min(xs)), math.ceil(max(xs))
    y0, y1 = math.floor(min(ys)), math.ceil(max(ys))
    px = lambda v: L + (v - x0) / (x1 - x0) * (W - L - R)
    py = lambda v: H - B - (v - y0) / (y1 - y0) * (H - T - B)
    colors = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"]
    out = [f"<svg xmlns='http://www.w3.org/2000/svg' width='{W}' height='{H}' font-family='sans-serif' font-size='12'>",
           "<rect width='100%' height='100%' fill='white'/>",
           f"<text x='{W / 2}' y='22' text-anchor='middle' font-size='15'>{scene}: error against time</text>",
           f"<rect x='{L}' y='{T}' width='{W - L - R}' height='{H - T - B}' fill='none' stroke='black'/>"]
    for v in range(x0, x1 + 1):
        out.append(f"<line x1='{px(v)}' y1='{T}' x2='{px(v)}' y2='{H - B}' stroke='#ddd'/>"
                   f"<text x='{px(v)}' y='{H - B + 16}' text-anchor='middle'>1e{v} s</text>")
    for v in range(y0, y1 + 1, 2):
        out.append(f"<line x1='{L}' y1='{py(v)}' x2='{W - R}' y2='{py(v)}' stroke='#ddd'/>"
                   f"<text x='{L - 6}' y='{py(v) + 4}' text-anchor='end'>1e{v}</text>")
    out.append(f"<text x='{(L + W - R) / 2}' y='{H - 18}' text-anchor='middle'>time per run (median)</text>")
    out.append(f"<text transform='translate(18,{(T + H - B) / 2}) rotate(-90)' text-anchor='middle'>relative error</text>")
    for i, (driver, runs) in enumerate(sorted(drivers.items())):
        c = colors[i % len(colors)]
        runs = sorted(runs, key=lambda r: r[3])
        line = " ".join(f"{px(math.log10(t))},{py(math.log10(max(e, floor)))}" for t, e, _, _ in runs if e)
        out.append(f"<polyline fill='none' stroke='{c}' stroke-width='2' points='{line}'/>")
        for t, e, ok, _ in runs:
            if e:
                out.append(f"<circle cx='{px(math.log10(t))}' cy='{py(math.log10(max(e, floor)))}' r='4' "
                           f"fill='{c if ok else 'white'}' stroke='{c}' stroke-width='2'/>")
        out.append(f"<rect x='{W - R + 12}' y='{T + 14 + 20 * i - 8}' width='14' height='4' fill='{c}'/>"
                   f"<text x='{W - R + 32}' y='{T + 14 + 20 * i}'>{driver}</text>")
    out.append(f"<text x='{W - R + 12}' y='{H - B}' font-size='11'>hollow: did not converge</text>")
    out.append("</svg>")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def rel(a, b):
    return abs(a - b) / abs(b)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--repetitions", type=int, default=5)
    args = ap.parse_args()
    ref = json.load(open(os.path.join(ROOT, "tools", "reference_seed000.json")))
    t08 = next(r for r in ref["table1"] if r["rod_length"] == 0.8)
    tcp, tmax = float(t08["mean_kinetic_energy"]), float(t08["peak_kinetic_energy"])
    grad = float(ref["mean_kinetic_energy_gradient_l08"])
    lstar = float(ref["rod_length_optimum"])

    ref2 = json.load(open(os.path.join(ROOT, "tools", "reference_seed002.json")))
    peak_v1 = float(ref2["variants"][0]["peak_moment"])
    l_co1_star = float(ref2["l_co1_optimum"])

    print("running Google Benchmark cases ...", file=sys.stderr)
    m = {}
    for binary in ("bench_recuperative", "bench_conveyor", "bench_drivers", "bench_elastic"):
        m.update(google_benchmark(os.path.join(args.build, "bin", binary),
                                  3 if binary == "bench_drivers" else args.repetitions))
    print("running the Python peers ...", file=sys.stderr)
    peer = {}
    for script in ("peer_recuperative.py", "peer_conveyor.py", "peer_elastic.py"):
        peer.update(json.loads(subprocess.run([sys.executable, os.path.join(HERE, script)],
                                              check=True, capture_output=True, text=True).stdout))

    # case, mechopt benchmark, peer case, reference, what the peer does
    cases = [
        ("cycle_mean", "BM_MeanKineticEnergy/32", "cycle_mean", tcp,
         "numpy trapezoid, 32 points"),
        ("cycle_mean_16_points", "BM_MeanKineticEnergy/16", "cycle_mean_16", tcp,
         "numpy trapezoid, 16 points"),
        ("cycle_mean_vs_quad", "BM_MeanKineticEnergy/32", "cycle_mean_quad", tcp,
         "scipy.integrate.quad, epsrel 1e-12"),
        ("cycle_mean_gradient", "BM_MeanKineticEnergyGradient/32", "cycle_mean_gradient", grad,
         "central differences of the numpy mean"),
        ("cycle_peak", "BM_CycleMetrics", "cycle_peak", tmax,
         "numpy grid + scipy minimize_scalar"),
        ("rod_length_optimum", "BM_RodLengthOptimum/LD_SLSQP", "rod_length_optimum", lstar,
         "scipy minimize_scalar (bounded), xatol 1e-12"),
        ("rod_length_optimum_lbfgs", "BM_RodLengthOptimum/LD_LBFGS", "rod_length_optimum", lstar,
         "scipy minimize_scalar (bounded), xatol 1e-12"),
        ("swing_peak_moment", "BM_SwingMetrics/48/0", "swing_peak", peak_v1,
         "numpy loop-closure formulas, 48 points + minimize_scalar refine"),
        ("swing_all_metrics", "BM_SwingMetrics/48/1", "swing_peak", peak_v1,
         "as above (the peer computes the peak only)"),
        ("swing_optimum", "BM_SwingOptimum/LD_SLSQP", "swing_optimum", l_co1_star,
         "scipy SLSQP, finite-difference gradients, ftol 1e-12"),
    ]
    peak_elastic = peer["reference"]["value"]  # scipy Radau at rtol 1e-12 (bench/peer_elastic.py)
    same = "solve_ivp {} rtol 1e-8, the same steady-state algorithm (events for the extrema)"
    cases += [
        ("elastic_steady_state", "BM_ElasticSteady", "steady_lsoda_8", peak_elastic, same.format("LSODA")),
        ("elastic_steady_state_vs_rk45", "BM_ElasticSteady", "steady_rk45_8", peak_elastic,
         same.format("RK45 (Dormand-Prince 5(4), as mechopt's erk)")),
        ("elastic_steady_state_vs_radau", "BM_ElasticSteady", "steady_radau_8", peak_elastic, same.format("Radau")),
        ("elastic_startup_3s", "BM_ElasticStartup", "startup_lsoda", None,
         "solve_ivp LSODA rtol 1e-8, 3 s, 1 ms output"),
    ]
    rows = []
    for case, bm, pc, reference, peer_method in cases:
        a, p = m[bm], peer[pc]
        value = a["gradient"] if case == "cycle_mean_gradient" else a["value"]
        rows.append({"case": case, "mechopt_benchmark": bm, "peer_method": peer_method,
                     "mechopt_seconds": a["seconds"], "peer_seconds": p["seconds"],
                     "ratio": p["seconds"] / a["seconds"],
                     "mechopt_error": rel(value, reference) if reference else None,
                     "peer_error": rel(p["value"], reference) if reference else None})
    # Work-precision rows: quadrature points against error, and each optimiser.
    for name, a in m.items():
        if name.startswith("BM_MeanKineticEnergy/"):
            rows.append({"case": "cycle_mean_points_" + name.split("/")[1],
                         "mechopt_benchmark": name, "mechopt_seconds": a["seconds"],
                         "mechopt_error": rel(a["value"], tcp)})
        for prefix, reference in (("BM_RodLengthOptimum/", lstar), ("BM_SwingOptimum/", l_co1_star)):
            if name.startswith(prefix):
                rows.append({"case": "optimizer_" + name.split("/")[0][3:] + "_" + name.split("/")[1],
                             "mechopt_benchmark": name, "mechopt_seconds": a["seconds"],
                             "evaluations": a["evaluations"],
                             "mechopt_error": rel(a["value"], reference)})
    a = m["BM_ElasticSteadyFromStartup"]
    rows.append({"case": "elastic_steady_from_startup_guess", "mechopt_benchmark": "BM_ElasticSteadyFromStartup",
                 "mechopt_seconds": a["seconds"], "mechopt_error": rel(a["value"], peak_elastic)})
    # The elastic drive's steady state over methods and tolerances, and the
    # map of where each method works.
    for name, a in m.items():
        if name.startswith("WPE/") or name.startswith("MAP/"):
            rows.append({"case": "elastic_" + name.replace("/", "_").lower(), "mechopt_benchmark": name,
                         "mechopt_seconds": a["seconds"], "steps": a["steps"], "ok": bool(a["ok"]),
                         # MAP rows are other designs: no reference there
                         "mechopt_error": rel(a["value"], peak_elastic) if a["ok"] and name.startswith("WPE/") else None})
    wpe = {}
    for name, a in m.items():
        if name.startswith("WPE/") and a["ok"]:
            _, method, tol = name.split("/")
            label = {"bdf": "CVODE BDF", "adams": "CVODE Adams", "erk": "ARKODE ERK (DP5)"}[method]
            wpe.setdefault("mechopt " + label, []).append((a["seconds"], rel(a["value"], peak_elastic), True, int(tol)))
    # Matched accuracy: each side's fastest run (over its tolerance grid) whose
    # peak is within 1e-6 of the reference.
    peer_wp = {}
    for name, p in peer.items():
        if name.startswith("steady_") and name.count("_") == 2:
            _, method, tol = name.split("_")
            peer_wp.setdefault("scipy " + method, []).append((p["seconds"], rel(p["value"], peak_elastic), True, int(tol)))
            rows.append({"case": f"elastic_peer_{method}_{tol}", "peer_method": f"solve_ivp {method} rtol 1e-{tol}",
                         "mechopt_seconds": None, "peer_seconds": p["seconds"],
                         "peer_error": rel(p["value"], peak_elastic)})
    fastest = lambda runs: min(((t, e) for t, e, _, _ in runs if e <= 1e-6), default=None)
    ours = min(filter(None, (fastest(r) for r in wpe.values())), default=None)
    for method, runs in sorted(peer_wp.items()):
        theirs = fastest(runs)
        if ours and theirs:
            rows.append({"case": "elastic_steady_1e-6_vs_" + method.split()[1], "mechopt_benchmark": "WPE (fastest within 1e-6)",
                         "peer_method": method + " (fastest within 1e-6), the same algorithm",
                         "mechopt_seconds": ours[0], "peer_seconds": theirs[0], "ratio": theirs[0] / ours[0],
                         "mechopt_error": ours[1], "peer_error": theirs[1]})
    if wpe:
        path = os.path.join(ROOT, "docs", "img", "work_precision_elastic_steady.svg")
        write_work_precision_svg(path, "elastic drive steady state", {**wpe, **peer_wp})
    # Work-precision of every driver: WP/<scene>/<driver>/<-log10 tol>.
    wp = {}
    for name, a in m.items():
        if name.startswith("WP/"):
            _, scene, driver, tol = name.split("/")
            rows.append({"case": f"wp_{scene}_{driver}_tol1e-{tol}", "mechopt_benchmark": name,
                         "mechopt_seconds": a["seconds"], "evaluations": a["evaluations"],
                         "mechopt_error": a["error"], "converged": bool(a["converged"])})
            wp.setdefault(scene, {}).setdefault(driver, []).append(
                (a["seconds"], a["error"], bool(a["converged"]), int(tol)))
    for scene, drivers in wp.items():
        path = os.path.join(ROOT, "docs", "img", f"work_precision_{scene}.svg")
        write_work_precision_svg(path, scene, drivers)
        print(f"chart: {os.path.relpath(path, ROOT)}", file=sys.stderr)
    out = os.path.join(args.build, "bench-results.json")
    json.dump(rows, open(out, "w"), indent=1)
    print(f"{'case':34s} {'mechopt':>11s} {'peer':>11s} {'ratio':>7s} {'mech err':>9s} {'peer err':>9s}")
    for r in rows:
        fmt = lambda v: "-" if v is None or v != v else f"{v:.1e}"
        peer_s = f"{r['peer_seconds'] * 1e6:9.2f}us" if "peer_seconds" in r else f"{'-':>11s}"
        ratio = f"{r['ratio']:7.1f}" if "ratio" in r else f"{'-':>7s}"
        mech_s = f"{r['mechopt_seconds'] * 1e6:9.3f}us" if r.get("mechopt_seconds") else f"{'-':>11s}"
        print(f"{r['case']:34s} {mech_s} {peer_s} {ratio} "
              f"{fmt(r.get('mechopt_error')):>9s} {fmt(r.get('peer_error')):>9s}")
    print(f"written: {out}")


if __name__ == "__main__":
    main()
