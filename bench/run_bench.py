#!/usr/bin/env python3
"""Runs the Google Benchmark cases and the Python peers in the same run, and
writes build/bench-results.json: one row per case with mechopt and peer
medians, their ratio (peer_seconds / mechopt_seconds) and each one's relative
error against the high-precision references (tools/reference_seed000.json,
tools/reference_seed002.json, bench/reference_press_sawmill.json).
Usage: /usr/bin/python3 bench/run_bench.py [--build build] [--repetitions 5]
       /usr/bin/python3 bench/run_bench.py --only press_sawmill   (the crank press,
       roller forming and the sawmill alone: their bench, peers, rows and docs block; a minute)
       /usr/bin/python3 bench/run_bench.py --only wp   (the drivers' work-precision alone:
       bench_drivers' WP/ cases, the peers' --wp cases, the two charts and docs/drivers.md)
"""
import argparse
import datetime
import json
import math
import os
import platform
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import doe_bench  # noqa: E402
import kink_map  # noqa: E402


def google_benchmark(binary, repetitions, benchmark_filter=None, min_time=0.1):
    out = subprocess.run([binary, "--benchmark_format=json",
                          f"--benchmark_repetitions={repetitions}",
                          f"--benchmark_min_time={min_time}"] +
                         ([f"--benchmark_filter={benchmark_filter}"] if benchmark_filter else []),
                         check=True, capture_output=True, text=True).stdout
    rows = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") == "median":
            unit = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
            rows[b["run_name"].replace("/iterations:1", "")] = {"seconds": b["real_time"] * unit, "value": b.get("value"),
                                   "steps": b.get("steps"), "ok": b.get("ok"),
                                   "gradient": b.get("gradient"),
                                   "evaluations": b.get("evaluations"), "iterations": b.get("iterations"),
                                   "error": b.get("error"), "converged": b.get("converged"),
                                   "multiplier": b.get("multiplier")}
    return rows


def write_work_precision_svg(path, scene, drivers, peers=(), notes=()):
    """Log-log chart: error against time, one line per driver (or method)
    over its knob (tolerance, grid points); hollow markers where it did not
    report convergence; errors of 0 drawn at 1e-17. The lines named in
    peers are dashed; notes: lines of text under the legend."""
    import math
    W, H, L, R, T, B = 820, 480, 80, 250, 40, 60
    floor = 1e-17  # an error of 0 (the reference's double exactly) is drawn here
    drivers = {d: [r for r in runs if r[1] is not None and r[1] == r[1]] for d, runs in drivers.items()}  # no NaN
    R = max(R, 40 + 7 * max(len(d) + (0 if runs else 11) for d, runs in drivers.items()))  # the legend's room
    W += R - 250
    pts = [(t, max(e, floor)) for runs in drivers.values() for t, e, _, _ in runs]
    xs = [math.log10(t) for t, _ in pts]
    ys = [math.log10(max(e, floor)) for _, e in pts]
    x0, x1 = math.floor(min(xs)), math.ceil(max(xs))
    y0, y1 = math.floor(min(ys)), math.ceil(max(ys))
    px = lambda v: L + (v - x0) / (x1 - x0) * (W - L - R)
    py = lambda v: H - B - (v - y0) / (y1 - y0) * (H - T - B)
    colors = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
              "#bcbd22", "#7f7f7f", "#aec7e8"]  # and the peers black
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
    out.append(f"<text x='{(L + W - R) / 2}' y='{H - 18}' text-anchor='middle'>time per run, median [s]</text>")
    out.append(f"<text transform='translate(18,{(T + H - B) / 2}) rotate(-90)' text-anchor='middle'>relative error [-]</text>")
    ours = [d for d in sorted(drivers) if d not in peers]
    for i, (driver, runs) in enumerate(sorted(drivers.items())):
        c = "#000000" if driver in peers else colors[ours.index(driver) % len(colors)]
        runs = sorted(runs, key=lambda r: r[3])
        line = " ".join(f"{px(math.log10(t))},{py(math.log10(max(e, floor)))}" for t, e, _, _ in runs)
        dash = " stroke-dasharray='6,3'" if driver in peers else ""
        if runs:
            out.append(f"<polyline fill='none' stroke='{c}' stroke-width='2'{dash} points='{line}'/>")
        for t, e, ok, _ in runs:
            out.append(f"<circle cx='{px(math.log10(t))}' cy='{py(math.log10(max(e, floor)))}' r='4' "
                       f"fill='{c if ok else 'white'}' stroke='{c}' stroke-width='2'/>")
        key = (f"<line x1='{W - R + 12}' y1='{T + 14 + 20 * i - 6}' x2='{W - R + 26}' y2='{T + 14 + 20 * i - 6}' "
               f"stroke='{c}' stroke-width='4' stroke-dasharray='4,2'/>" if driver in peers else
               f"<rect x='{W - R + 12}' y='{T + 14 + 20 * i - 8}' width='14' height='4' fill='{c}'/>")
        out.append(key + f"<text x='{W - R + 32}' y='{T + 14 + 20 * i}'>{driver}{'' if runs else ': no result'}</text>")
    for j, note in enumerate(notes):
        out.append(f"<text x='{W - R + 12}' y='{H - B - 16 * (len(notes) - j)}' font-size='11'>{note}</text>")
    out.append(f"<text x='{W - R + 12}' y='{H - B}' font-size='11'>hollow: did not converge"
               f"{'; dashed: peer' if peers else ''}</text>")
    out.append("</svg>")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def rel(a, b):
    return abs(a - b) / abs(b)


# ---------------------------------------------------------------------------
# The generated blocks of docs/performance.md and docs/drivers.md: every
# number those docs quote from a benchmark is written here, from this run.
# A block sits between
#   <!-- generated by bench/run_bench.py: NAME -->  and  <!-- end NAME -->
# and the prose around it is hand-written.

def fmt_time(seconds, smallest="us"):
    """Three significant digits in us (or the smallest unit given), ms or s."""
    for unit, scale in (("us", 1e-6), ("ms", 1e-3))[1 if smallest == "ms" else 0:]:
        if seconds / scale < 999.5:
            return f"{seconds / scale:.3g} {unit}"
    return f"{seconds:.3g} s"


def fmt_ms(seconds):
    ms = seconds * 1e3
    return f"{ms:.2f}" if ms < 10 else f"{ms:.1f}"


def fmt_err(e):
    return "-" if e is None or e != e else f"{e:.1e}"


def fmt_ratio(r):
    if r >= 100:
        return str(int(round(r, 2 - int(math.floor(math.log10(r))))))
    return f"{r:.0f}" if r >= 10 else f"{r:.1f}"


def table(header, body):
    return "\n".join(["| " + " | ".join(header) + " |", "|" + "---|" * len(header)] +
                     ["| " + " | ".join(str(c) for c in row) + " |" for row in body])


def machine_line():
    """Date, machine and command of this run, one line."""
    cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                if line.startswith("model name")), "unknown CPU")
    # numpy dispatches sin, cos, exp ... to AVX-512 kernels where the CPU has
    # them, which about doubles the peers' speed: the ratios depend on it.
    cpu += " with AVX-512" if " avx512f" in open("/proc/cpuinfo").read() else " without AVX-512"
    gxx = subprocess.run(["g++", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    import numpy
    import scipy
    command = " ".join([sys.executable, os.path.relpath(os.path.abspath(sys.argv[0]), ROOT)] + sys.argv[1:])
    return (f"Generated by `{command}` (`make bench`) on {datetime.date.today().isoformat()}: "
            f"nproc {len(os.sched_getaffinity(0))}, {cpu}, {gxx}, Python {platform.python_version()}, "
            f"numpy {numpy.__version__}, scipy {scipy.__version__}.")


def join_and(items):
    items = list(items)
    return "none" if not items else items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def performance_blocks(m, peer, debian, row, tcp, peak_elastic, lstar, l_co1_star):
    blocks = {}
    header = ["case", "mechopt", "peer", "ratio", "mechopt error", "peer error", "peer method"]
    line = lambda label, case, method: [label, fmt_time(row[case]["mechopt_seconds"]),
                                        fmt_time(row[case]["peer_seconds"]), fmt_ratio(row[case]["ratio"]),
                                        fmt_err(row[case]["mechopt_error"]), fmt_err(row[case]["peer_error"]),
                                        method]
    blocks["recuperative"] = table(header, [
        line("cycle mean T_cp, 32 points", "cycle_mean", "numpy trapezoid, 32 points"),
        line("cycle mean T_cp, 16 points", "cycle_mean_16_points", "numpy trapezoid, 16 points"),
        line("cycle mean vs adaptive quadrature", "cycle_mean_vs_quad", "scipy.integrate.quad, epsrel 1e-12"),
        line("cycle mean + exact gradient (2 variables)", "cycle_mean_gradient",
             "central differences of the numpy mean"),
        line("all cycle metrics (refined T_max, moments)", "cycle_peak",
             "numpy grid + minimize_scalar refine (T_max only)"),
        line("rod-length optimum, LD_SLSQP", "rod_length_optimum", "scipy minimize_scalar (bounded), xatol 1e-12"),
        line("rod-length optimum, LD_LBFGS", "rod_length_optimum_lbfgs", "same"),
        line("rod-length optimum, `library: line` (Brent on the derivative)", "rod_length_optimum_line", "same")])
    blocks["conveyor"] = table(header, [
        line("peak \\|M\\| and max pressure angle, variant 1, 48 points", "swing_peak_moment",
             "numpy loop-closure formulas, 48 points + minimize_scalar refine (peak only)"),
        line("all swing metrics (adds mean \\|M\\|, RMS)", "swing_all_metrics", "as above, peak only"),
        line("optimum of peak \\|M\\| under [gamma] <= 60 deg, LD_SLSQP", "swing_optimum",
             "scipy SLSQP, finite-difference gradients, ftol 1e-12")])
    blocks["problem_evaluate"] = table(["case", "time"], [
        ["`BM_ProblemEvaluate`: value and gradient through the Problem interface (28 points, one variable)",
         fmt_time(row["problem_evaluate_28"]["mechopt_seconds"])],
        ["`BM_MeanKineticEnergyGradient/28`: the model alone, value and gradient",
         fmt_time(row["cycle_mean_gradient_28"]["mechopt_seconds"])]])

    # Targets of the recuperative drive, judged on this run's rows.
    points = sorted((int(k.split("/")[1]), a["seconds"], rel(a["value"], tcp))
                    for k, a in m.items() if k.startswith("BM_MeanKineticEnergy/"))
    within = [p for p in points if p[2] <= 1e-12]
    best = min(within, key=lambda p: p[1]) if within else None
    t1 = (f"**{'met' if best and best[1] <= 0.5e-6 else 'not met'}** "
          + (f"(fastest within 1e-12: {fmt_time(best[1])} at {fmt_err(best[2])} with {best[0]} points)" if best
             else "(no point count reaches 1e-12)"))
    opt_rows = sorted((k.split("/")[1], a["seconds"], a["evaluations"], rel(a["value"], lstar))
                      for k, a in m.items() if k.startswith("BM_RodLengthOptimum/"))
    meets = [o for o in opt_rows if o[3] <= 1e-10 and o[1] <= 50e-6]
    t2 = ("**met by " + join_and(f"{o[0]}" for o in meets) + "** (" +
          "; ".join(f"{o[0]} {fmt_time(o[1])} at {fmt_err(o[3])}" for o in meets) + ")" if meets else "**not met**")
    others = [o for o in opt_rows if o not in meets]
    if others:
        t2 += "; not by " + join_and(f"{o[0]} ({fmt_time(o[1])} at {fmt_err(o[3])})"
                                     for o in sorted(others, key=lambda o: o[1]))
    peer_cases = [("cycle mean, 32 points", "cycle_mean"), ("cycle mean, 16 points", "cycle_mean_16_points"),
                  ("cycle mean vs adaptive quadrature", "cycle_mean_vs_quad"),
                  ("cycle mean + gradient", "cycle_mean_gradient"), ("all cycle metrics", "cycle_peak"),
                  ("rod-length optimum, LD_SLSQP", "rod_length_optimum"),
                  ("rod-length optimum, LD_LBFGS", "rod_length_optimum_lbfgs"),
                  ("rod-length optimum, line", "rod_length_optimum_line")]
    as_good = lambda r: r["mechopt_error"] <= max(r["peer_error"], 1e-15)  # both at roundoff: equal
    fast = [(label, row[c]) for label, c in peer_cases if row[c]["ratio"] >= 100 and as_good(row[c])]
    slow = [(label, row[c]) for label, c in peer_cases if not (row[c]["ratio"] >= 100 and as_good(row[c]))]
    desc = lambda label, r: (f"{label} ({fmt_ratio(r['ratio'])}x, error {fmt_err(r['mechopt_error'])} "
                             f"against the peer's {fmt_err(r['peer_error'])})")
    t3 = ("**met** for " + join_and(desc(*x) for x in fast) if fast else "**not met** for any case")
    if slow:
        t3 += ("; **not met** for " if fast else ", including ") + join_and(desc(*x) for x in slow)
    mean32, mean16 = m["BM_MeanKineticEnergy/32"]["seconds"], m["BM_MeanKineticEnergy/16"]["seconds"]
    blocks["recuperative_targets"] = "\n".join([
        f"- one cycle evaluation <= 0.5 us at relative error <= 1e-12: {t1};",
        f"- the rod-length optimum to 1e-10 relative in <= 50 us: {t2};",
        f"- >= 100x faster than the peer at equal or better accuracy (both errors at or below 1e-15 count "
        f"as equal): {t3}.",
        "",
        f"Where the time goes: the peer takes {fmt_time(peer['cycle_mean_16']['seconds'])} at 16 points and "
        f"{fmt_time(peer['cycle_mean']['seconds'])} at 32; mechopt {fmt_time(mean16)} and {fmt_time(mean32)}, "
        f"{(mean32 - mean16) / 16 / 2 * 1e9:.1f} ns per added point and slider; the exact gradient costs "
        f"{m['BM_MeanKineticEnergyGradient/32']['seconds'] / mean32:.1f}x the value (32 points); LD_SLSQP takes "
        f"{int(m['BM_RodLengthOptimum/LD_SLSQP']['evaluations'])} evaluations for the optimum."])
    blocks["conveyor_summary"] = (
        f"For the conveyor: the peak evaluation is {fmt_ratio(row['swing_peak_moment']['ratio'])}x the peer, "
        f"all swing metrics {fmt_ratio(row['swing_all_metrics']['ratio'])}x, and the optimisation "
        f"{fmt_ratio(row['swing_optimum']['ratio'])}x with an error "
        f"{row['swing_optimum']['peer_error'] / row['swing_optimum']['mechopt_error']:.0e} times smaller "
        f"than the peer's.")
    blocks["quadrature_points"] = table(["points", "time", "error"],
                                        [[n, fmt_time(t), fmt_err(e)] for n, t, e in points])
    blocks["rod_length_optimisers"] = table(
        ["algorithm", "time", "evaluations", "error of l*"],
        [[a, fmt_time(t), int(n), fmt_err(e)] for a, t, n, e in sorted(opt_rows, key=lambda o: o[1])])
    conv = sorted(((k.split("/")[1], a["seconds"], a["evaluations"], rel(a["value"], l_co1_star))
                   for k, a in m.items() if k.startswith("BM_SwingOptimum/")), key=lambda o: o[1])
    blocks["conveyor_optimisers"] = table(["algorithm", "time", "evaluations", "error"],
                                          [[a, fmt_time(t), int(n), fmt_err(e)] for a, t, n, e in conv])

    # Elastic drive.
    e = lambda case: row[case]
    el = [("steady state as the configs run it (ARKODE ERK, rtol 1e-8) vs LSODA at rtol 1e-8", "elastic_steady_state"),
          ("same, vs RK45 (Dormand-Prince 5(4), our ERK's method) at rtol 1e-8", "elastic_steady_state_vs_rk45"),
          ("same, vs Radau at rtol 1e-8", "elastic_steady_state_vs_radau")]
    ms = lambda seconds: fmt_time(seconds, "ms")
    body = [[label, ms(e(c)["mechopt_seconds"]), ms(e(c)["peer_seconds"]), fmt_ratio(e(c)["ratio"]),
             fmt_err(e(c)["mechopt_error"]), fmt_err(e(c)["peer_error"])] for label, c in el]
    first = True
    for method in ("lsoda", "rk45", "radau"):
        r = row.get("elastic_steady_1e-6_vs_" + method)
        if not r:
            continue
        ours = r["mechopt_benchmark"].split(": ", 1)[1].rstrip(")").removeprefix("mechopt ")
        theirs = r["peer_method"].split(": ", 1)[1].split(")")[0]
        label = (f"**matched accuracy**: each side's fastest run within 1e-6 (ours: {ours}), "
                 f"vs {method.upper() if method != 'radau' else 'Radau'} ({theirs})" if first else
                 f"matched accuracy, vs {method.upper() if method != 'radau' else 'Radau'} ({theirs})")
        first = False
        body.append([label, ms(r["mechopt_seconds"]), ms(r["peer_seconds"]), fmt_ratio(r["ratio"]),
                     fmt_err(r["mechopt_error"]), fmt_err(r["peer_error"])])
    g = e("elastic_steady_from_startup_guess")
    body.append(["steady state from a 3 s start-up guess (`warmup: 3 s`), ERK rtol 1e-8",
                 ms(g["mechopt_seconds"]), "-", "-", fmt_err(g["mechopt_error"]), "-"])
    s = e("elastic_startup_3s")
    body.append(["start-up, 3 s, 1 ms output (BDF, rtol 1e-8) vs LSODA", ms(s["mechopt_seconds"]),
                 ms(s["peer_seconds"]), fmt_ratio(s["ratio"]), "-", "-"])
    blocks["elastic"] = (table(["case", "mechopt", "peer", "ratio", "mechopt error", "peer error"], body) +
                         f"\n\nReference (the peer's Radau at rtol 1e-12, this run): {peak_elastic:.11g} N m. "
                         f"Largest Floquet multiplier of the configs' steady state (`BM_ElasticSteady`): "
                         f"{m['BM_ElasticSteady']['multiplier']:.1e}.")
    labels = {"bdf": "CVODE BDF", "adams": "CVODE Adams", "erk": "ARKODE ERK"}
    within = []
    for method in ("erk", "adams", "bdf"):
        ok = [(a["seconds"], rel(a["value"], peak_elastic), int(k.split("/")[2])) for k, a in m.items()
              if k.startswith(f"WPE/{method}/") and a["ok"] and rel(a["value"], peak_elastic) <= 1e-6]
        if ok:
            within.append((labels[method],) + min(ok))
    met = [w for w in within if w[1] <= 0.5e-3]
    steady = e("elastic_steady_state")
    t1 = (f"**{'met' if met else 'not met'}** (each method's fastest within 1e-6: " +
          "; ".join(f"{w[0]} {fmt_time(w[1], 'ms')} at {fmt_err(w[2])}, rtol 1e-{w[3]}" for w in sorted(within, key=lambda w: w[1])) +
          f"; the configs' ERK at rtol 1e-8: {fmt_time(steady['mechopt_seconds'], 'ms')} at "
          f"{fmt_err(steady['mechopt_error'])})")
    vs = [(method.upper() if method != "radau" else "Radau", row["elastic_steady_1e-6_vs_" + method]["ratio"])
          for method in ("lsoda", "rk45", "radau") if "elastic_steady_1e-6_vs_" + method in row]
    yes = [f"{n} ({fmt_ratio(r)}x)" for n, r in vs if r >= 100]
    no = [f"{n} ({fmt_ratio(r)}x)" for n, r in vs if r < 100]
    t2 = ("**met against " + join_and(yes) + "**" if yes else "") + \
         ((", " if yes else "") + "**not met against " + join_and(no) + "**" if no else "")
    blocks["elastic_targets"] = "\n".join([
        f"- a steady-state evaluation to 1e-6 in <= 0.5 ms: {t1};",
        f"- at least 100x the peer at matched accuracy (the peer running the same algorithm): {t2}."])
    if debian:
        cases = [("steady state, ERK rtol 1e-8", "WPE/erk/8"), ("steady state, BDF rtol 1e-8", "WPE/bdf/8"),
                 ("steady state from a 3 s start-up guess", "BM_ElasticSteadyFromStartup"),
                 ("start-up, 3 s, BDF", "BM_ElasticStartup")]
        blocks["sundials_builds"] = table(
            ["case", "Debian's libsundials (no optimisation)", "built by `tools/build_sundials.sh` (-O2)", "ratio"],
            [[f"{label} ({int(m[bm]['steps'])} steps)", fmt_time(debian[bm]["seconds"], "ms"),
              fmt_time(m[bm]["seconds"], "ms"),
              f"{debian[bm]['seconds'] / m[bm]['seconds']:.1f}"] for label, bm in cases])
    else:
        blocks["sundials_builds"] = ("Not measured in this run: no build linked with Debian's libsundials "
                                     "(`cmake -S . -B build-debian-sundials -DCMAKE_BUILD_TYPE=Release`, "
                                     "then `cmake --build build-debian-sundials --target bench_elastic`).")
    tols = range(5, 11)
    wbody = []
    for method in ("bdf", "adams", "erk"):
        cells = []
        for tol in tols:
            a = m.get(f"WPE/{method}/{tol}")
            cells.append("-" if not a else f"{fmt_ms(a['seconds'])} ms, {fmt_err(rel(a['value'], peak_elastic))}"
                         if a["ok"] else f"fails ({fmt_ms(a['seconds'])} ms)")
        wbody.append([labels[method] + (" (DP5)" if method == "erk" else "")] + cells)
    for method in ("lsoda", "rk45", "radau"):
        cells = []
        for tol in tols:
            p = peer.get(f"steady_{method}_{tol}")
            cells.append("-" if not p else f"{fmt_ms(p['seconds'])} ms, {fmt_err(rel(p['value'], peak_elastic))}")
        wbody.append([f"scipy {method.upper() if method != 'radau' else 'Radau'} (peer)"] + cells)
    blocks["elastic_work_precision"] = table(["method"] + [f"rtol 1e-{t}" if t == 5 else f"1e-{t}" for t in tols],
                                             wbody)
    # Where each method works: MAP/<method>/c1e<k>/zeta<z>, one run each.
    zetas = ("0.05", "1")
    mbody, fails = [], []
    for ce in range(3, 11):
        cells = []
        for method in ("bdf", "adams", "erk"):
            for z in zetas:
                a = m[f"MAP/{method}/c1e{ce}/zeta{z}"]
                if a["ok"]:
                    cells.append(fmt_ms(a["seconds"]))
                else:
                    cells.append(f"**fails** ({int(a['steps'])} steps, {fmt_ms(a['seconds'])} ms)")
                    fails.append(f"{labels[method]} at c = 1e{ce}, zeta {z}")
        mbody.append([f"1e{ce}"] + cells)
    blocks["elastic_map"] = table(["c [N m/rad]", "BDF, zeta 0.05", "BDF, zeta 1", "Adams, 0.05", "Adams, 1",
                                   "ERK, 0.05", "ERK, 1"], mbody)
    cheapest = []
    for z in zetas:
        runs = []
        for ce in range(3, 11):
            ok = [(m[f"MAP/{meth}/c1e{ce}/zeta{z}"]["seconds"], labels[meth].split()[-1]) for meth in ("bdf", "adams", "erk")
                  if m[f"MAP/{meth}/c1e{ce}/zeta{z}"]["ok"]]
            runs.append((ce, min(ok)[1] if ok else "none"))
        groups = []
        for ce, name in runs:
            if groups and groups[-1][2] == name:
                groups[-1][1] = ce
            else:
                groups.append([ce, ce, name])
        cheapest.append(f"zeta {z}: " + ", ".join(
            f"{n} at c = 1e{a}" + (f"-1e{b}" if b != a else "") for a, b, n in groups))
    steps = ", ".join(f"{labels[meth]} {int(m[f'MAP/{meth}/c1e10/zeta1']['steps'])}"
                      + ("" if m[f"MAP/{meth}/c1e10/zeta1"]["ok"] else " (fails)") for meth in ("bdf", "adams", "erk"))
    blocks["elastic_map"] += ("\n\nFailures in this run: " + join_and(fails) + ". Cheapest method that works, " +
                              "; ".join(cheapest) + f". Steps at c = 1e10, zeta 1: {steps}.")
    return blocks


def drivers_blocks(m, peer):
    """The drivers' work-precision tables: per driver (and the scene's peer)
    the loosest tolerance that reaches 1e-8, and the tolerance of its best
    error where that is ten times better; drivers that never reach 1e-8:
    their best. The summary: who is fastest, and the peer against mechopt at
    the peer's best accuracy."""
    blocks = {}
    scenes, peers = wp_scenes(m, peer)
    label = lambda scene, d: {"ipopt": "ipopt (L-BFGS)" if scene == "rod_length" else "ipopt, epigraph",
                              "ipopt_mumps": "ipopt with MUMPS" if scene == "rod_length" else "ipopt, epigraph, MUMPS",
                              "ipopt_plain": "ipopt, plain (no epigraph)",
                              "peer": f"peer: {PEER_WP[scene][2]}"}.get(d, d.replace("_", " ", 1))
    names = {"rod_length": "rod length", "conveyor_l_co1": "conveyor l_CO1"}
    summary, matched = [], []
    for scene, drivers in scenes.items():
        tol_name = lambda d, t: wp_tol(scene, d, t)
        body, first_to, never, best_of = [], [], [], []  # body: (driver's first time, tolerance, row)
        for d, runs in list(drivers.items()) + ([("peer", peers[scene])] if scene in peers else []):
            ours = d != "peer"  # the peer: in the table, not in the drivers' summary
            good = [r for r in runs if r[4] and r[3] <= 1e-8]
            conv = [r for r in runs if r[4]]
            best = min(conv, key=lambda r: r[3]) if conv else None
            if good:
                body.append((good[0][1], good[0][0], [label(scene, d), tol_name(d, good[0][0]), fmt_time(good[0][1]),
                                                      good[0][2], fmt_err(good[0][3])]))
                if ours:
                    first_to.append((good[0][1], label(scene, d), tol_name(d, good[0][0])))
                if best[3] < good[0][3] / 10:
                    body.append((good[0][1], best[0], [label(scene, d), tol_name(d, best[0]), fmt_time(best[1]),
                                                       best[2], fmt_err(best[3])]))
            elif best:
                body.append((best[1], best[0], [label(scene, d), tol_name(d, best[0]), fmt_time(best[1]), best[2],
                                                fmt_err(best[3]) + " (its best)"]))
                if ours:
                    never.append(f"{label(scene, d)} (at best {fmt_err(best[3])})")
            else:
                r = runs[-1]
                body.append((r[1], r[0], [label(scene, d), f"any ({tol_name(d, runs[0][0])} to 1e-{r[0]})", fmt_time(r[1]),
                                    r[2], f"not converged at any tolerance (figures at {tol_name(d, r[0])})"]))
                if ours:
                    never.append(f"{label(scene, d)} (does not converge)")
            if best and ours:
                best_of.append((best[3], label(scene, d)))
        mt = wp_matched(drivers, peers.get(scene, []))
        if mt:
            target, theirs, (d, r), ratio = mt
            matched.append(f"- {names[scene]}, against the peer ({PEER_WP[scene][2]}, `bench/{PEER_WP[scene][0]}`): "
                           f"its best error {fmt_err(theirs[3])} ({tol_name('peer', theirs[0])}, {fmt_time(theirs[1])}); "
                           f"mechopt's fastest run within that, {label(scene, d)} ({tol_name(d, r[0])}, "
                           f"{fmt_time(r[1])}, error {fmt_err(r[3])}): **{fmt_ratio(ratio)}x**.")
        blocks["wp_" + scene] = table(["driver", "tolerance", "time", "evaluations", "error"],
                                      [b for _, _, b in sorted(body, key=lambda x: x[:2])])
        first_to.sort()
        summary.append(f"- {names[scene]}: fastest to 1e-8 " + join_and(f"{n} ({tol}, {fmt_time(t)})" for t, n, tol in first_to[:2])
                       + "; never to 1e-8: " + join_and(never) + "; 1e-10 or better at some tolerance: "
                       + join_and(n for e, n in sorted(best_of) if e <= 1e-10) + ".")
    summary += matched
    ratios = []
    for scene, drivers in scenes.items():
        ip = dict((r[0], r) for r in drivers.get("ipopt", []))
        sq = dict((r[0], r) for r in drivers.get("nlopt_LD_SLSQP", []))
        if 8 in ip and 8 in sq:
            ratios.append((scene, ip[8][1] / ip[8][2], sq[8][1] / sq[8][2], ip[8][1] / sq[8][1]))
    summary.append("- time per evaluation at tolerance 1e-8, Ipopt against NLopt's LD_SLSQP: " + "; ".join(
        f"{names[s]} {fmt_time(a)} against {fmt_time(b)} (the whole run {fmt_ratio(r)}x longer)" for s, a, b, r in ratios) + ".")
    blocks["wp_summary"] = "\n".join(summary)
    # Ipopt's iteration, dense KKT solver against MUMPS (tol 1e-8): the whole
    # run's time over Ipopt's iterations.
    rows = []
    for scene, drivers in scenes.items():
        for d, solver in (("ipopt", "dense (mechopt's)"), ("ipopt_mumps", "MUMPS (Ipopt's)")):
            r = dict((x[0], x) for x in drivers.get(d, [])).get(8)
            if r and r[5]:
                rows.append([names[scene], solver, fmt_time(r[1]), r[5], fmt_time(r[1] / r[5]), r[2],
                             fmt_err(r[3]) if r[4] else "not converged"])
    blocks["ipopt_iteration"] = table(["problem", "KKT solver", "run", "iterations", "per iteration",
                                       "evaluations", "error"], rows)
    return blocks


# The crank press and the roller-forming machine (seed 003) and the sawmill's
# balanced slider-crank (seed 004): bench/bench_press_sawmill.cpp against
# bench/peer_crank_press.py, bench/peer_roller_forming.py and
# bench/peer_balanced_slider_crank.py, errors against
# bench/reference_press_sawmill.json (printed by tests/ref/*_ref.py).
PRESS_SAWMILL_BINARY = "bench_press_sawmill"
PRESS_SAWMILL_PEERS = ("peer_crank_press.py", "peer_roller_forming.py", "peer_balanced_slider_crank.py")


def press_sawmill_cases():
    """(case, mechopt benchmark, peer case, reference, peer method, label) of the press, the roller-forming
    machine and the sawmill."""
    ref = json.load(open(os.path.join(HERE, "reference_press_sawmill.json")))
    press, saw = ref["crank_press"], ref["balanced_slider_crank"]
    grid = "numpy, 64 cells over [phi_c, pi], brentq for phi_c"
    return [
        ("press_peak_constant", "BM_PressPeakTorque/0", "press_peak_constant", press["peak_torque_constant"],
         grid + " (the peak is at phi_c)",
         "press SM-816, variant 1: peak torque, constant force"),
        ("press_peak_pressure_law", "BM_PressPeakTorque/1", "press_peak_pressure_law",
         press["peak_torque_pressure_law"], grid + " + minimize_scalar refine",
         "press SM-816, variant 1: peak torque, pressure law (7.2)"),
        ("roller_forming_table", "BM_RollerFormingTable", "roller_forming_table",
         ref["roller_forming"]["crank_radius_sum"], "numpy, the chain (6.1)-(6.12) vectorised over the 24 variants",
         "roller forming, Table 6.1: every metric of the 24 variants (error of the summed crank radii)"),
        ("sawmill_peak_torque", "BM_SawmillMetrics/0", "sawmill_peak_torque", saw["peak_balancing_torque"],
         "numpy Newton-Euler, 72 points + minimize_scalar refine",
         "sawmill, improved mechanism: peak \\|M_b\\| alone"),
        ("sawmill_all_metrics", "BM_SawmillMetrics/1", "sawmill_all_metrics", saw["peak_balancing_torque"],
         "as above, 17 of the 25 metrics (no n_d, k_d, min or max cam force), each peak refined",
         "sawmill, improved and original: all metrics (error of peak \\|M_b\\|)"),
    ]


def references():
    """High-precision references of seeds 000 and 002: T_cp and T_max at
    l = 0.8 m, dT_cp/dl there, the rod-length optimum l*, the peak swing
    moment of variant 1 and the l_CO1 optimum."""
    ref = json.load(open(os.path.join(ROOT, "tools", "reference_seed000.json")))
    t08 = next(r for r in ref["table1"] if r["rod_length"] == 0.8)
    tcp, tmax = float(t08["mean_kinetic_energy"]), float(t08["peak_kinetic_energy"])
    grad = float(ref["mean_kinetic_energy_gradient_l08"])
    lstar = float(ref["rod_length_optimum"])
    ref2 = json.load(open(os.path.join(ROOT, "tools", "reference_seed002.json")))
    peak_v1 = float(ref2["variants"][0]["peak_moment"])
    l_co1_star = float(ref2["l_co1_optimum"])
    return tcp, tmax, grad, lstar, peak_v1, l_co1_star


def comparison_cases(peer):
    """(case, mechopt benchmark, peer case, reference, what the peer does) of
    every same-run comparison against a peer."""
    tcp, tmax, grad, lstar, peak_v1, l_co1_star = references()
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
        ("rod_length_optimum_line", "BM_RodLengthOptimum/line", "rod_length_optimum", lstar,
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
    cases += press_sawmill_cases()
    return cases


def case_rows(cases, m, peer):
    rows = []
    for case, bm, pc, reference, peer_method, *_ in cases:
        a, p = m[bm], peer[pc]
        value = a["gradient"] if case == "cycle_mean_gradient" else a["value"]
        rows.append({"case": case, "mechopt_benchmark": bm, "peer_method": peer_method,
                     "mechopt_seconds": a["seconds"], "peer_seconds": p["seconds"],
                     "ratio": p["seconds"] / a["seconds"],
                     "mechopt_error": rel(value, reference) if reference else None,
                     "peer_error": rel(p["value"], reference) if reference else None})
    return rows


def press_sawmill_block(row, m):
    cases = press_sawmill_cases()
    body = [[label, fmt_time(row[c]["mechopt_seconds"]), fmt_time(row[c]["peer_seconds"]),
             fmt_ratio(row[c]["ratio"]), fmt_err(row[c]["mechopt_error"]), fmt_err(row[c]["peer_error"]), method]
            for c, _, _, _, method, label in cases]
    r = [row[c[0]]["ratio"] for c in cases]
    slider, four_bar = m["BM_PressPeakTorque/1"], m["BM_PressPeakTorque/2"]
    return (table(["case", "mechopt", "peer", "ratio", "mechopt error", "peer error", "peer method"], body) +
            f"\n\nRatios here run from {fmt_ratio(min(r))}x to {fmt_ratio(max(r))}x. The press's third "
            f"fidelity knob, the exact four-bar lever in place of the slider (pressure law, pivot on the crank "
            f"pin's side), costs {fmt_time(four_bar['seconds'])} against {fmt_time(slider['seconds'])} and moves "
            f"the peak torque by {100 * (four_bar['value'] / slider['value'] - 1):+.1f}%.")


def grid_chart(name, title, m, pattern, reference, knob, peer_points):
    """docs/img/work_precision_NAME.svg: mechopt's error against time over a
    grid (its benchmarks match `pattern`, whose one group is the grid's
    size), and each peer's point: peer_points is [(label, peer row)]."""
    runs = [(a["seconds"], rel(a["value"], reference), True, int(g.group(1)))
            for bm, a in m.items() for g in [re.fullmatch(pattern, bm)] if g]
    if not runs:
        return
    lines = {f"mechopt, over {knob}": runs}
    for label, p in peer_points:
        lines[label] = [(p["seconds"], rel(p["value"], reference), True, 0)]
    path = os.path.join(ROOT, "docs", "img", f"work_precision_{name}.svg")
    write_work_precision_svg(path, title, lines)
    print(f"chart: {os.path.relpath(path, ROOT)}", file=sys.stderr)


def press_sawmill_charts(m, peer):
    """Work against precision of the press's and the sawmill's peaks over
    their grids, each with the peer's point at its own grid."""
    ref = json.load(open(os.path.join(HERE, "reference_press_sawmill.json")))
    grid_chart("press", "press SM-816, variant 1, peak torque (pressure law)", m, r"BM_PressGrid/(\d+)",
               ref["crank_press"]["peak_torque_pressure_law"], "grid cells",
               [("numpy peer, 64 cells", peer["press_peak_pressure_law"])])
    grid_chart("sawmill", "sawmill, peak balancing torque", m, r"BM_SawmillGrid/(\d+)",
               ref["balanced_slider_crank"]["peak_balancing_torque"], "points per turn",
               [("numpy peer, 72 points", peer["sawmill_peak_torque"])])


def run_press_sawmill(build, repetitions):
    m = google_benchmark(os.path.join(build, "bin", PRESS_SAWMILL_BINARY), repetitions)
    peer = {}
    for script in PRESS_SAWMILL_PEERS:
        peer.update(json.loads(subprocess.run([sys.executable, os.path.join(HERE, script)],
                                              check=True, capture_output=True, text=True).stdout))
    return m, peer


def run_peer(script, *args):
    """A peer's JSON rows {case: {seconds, value, ...}}."""
    return json.loads(subprocess.run([sys.executable, os.path.join(HERE, script), *args],
                                     check=True, capture_output=True, text=True).stdout)


# The drivers' work-precision (bench/bench_drivers.cpp, WP/<scene>/<driver>/<-log10 tol>)
# and each scene's peer over its own knob (the peer script's --wp cases,
# CASE<-log10 knob>): scene -> (script, CASE, label, knob).
PEER_WP = {"rod_length": ("peer_recuperative.py", "rod_length_optimum_xatol_", "scipy minimize_scalar (bounded)",
                          "xatol"),
           "conveyor_l_co1": ("peer_conveyor.py", "swing_optimum_ftol_", "scipy SLSQP", "ftol")}


# Lines under a chart's legend: what it leaves out.
WP_NOTES = {"conveyor_l_co1": ["no line driver: it takes one", "variable with bounds only", ""]}


def wp_tol(scene, driver, tol):
    """A work-precision run's knob: the peer's own, Ipopt's KKT tolerance, or xtol_rel."""
    knob = PEER_WP[scene][3] if driver == "peer" else "tol" if driver.startswith("ipopt") else "xtol"
    return f"{knob} 1e-{tol}"


def wp_scenes(m, peer):
    """scene -> {driver: [(-log10 tol, seconds, evaluations, error, converged, iterations)]}, mechopt's
    drivers, and scene -> the same of its peer (errors against the references bench_drivers.cpp uses)."""
    scenes = {}
    for name, a in m.items():
        if name.startswith("WP/"):
            _, scene, driver, tol = name.split("/")
            scenes.setdefault(scene, {}).setdefault(driver, []).append(
                (int(tol), a["seconds"], int(a["evaluations"]), a["error"],
                 bool(a["converged"]) and a["error"] == a["error"], int(a.get("iterations") or 0)))
    _, _, _, lstar, _, l_co1_star = references()
    x_star = {"rod_length": lstar, "conveyor_l_co1": l_co1_star}
    peers = {}
    for scene, (_, case, _, _) in PEER_WP.items():
        for name, p in peer.items():
            if name.startswith(case):
                peers.setdefault(scene, []).append((int(name[len(case):]), p["seconds"], p["evaluations"],
                                                    rel(p["value"], x_star[scene]), p["converged"], 0))
    return ({s: {d: sorted(r) for d, r in ds.items()} for s, ds in scenes.items()},
            {s: sorted(r) for s, r in peers.items()})


def wp_matched(drivers, peer_runs):
    """At the peer's best accuracy (its least error of a converged run, 1e-15 at the least: both at
    roundoff count as equal): the peer's fastest converged run within it and mechopt's (any driver,
    any tolerance), as (target, peer run, (driver, run), peer seconds / ours), or None."""
    ok = [r for r in peer_runs if r[4]]
    if not ok:
        return None
    target = max(min(r[3] for r in ok), 1e-15)
    theirs = min((r for r in ok if r[3] <= target), key=lambda r: r[1])
    ours = min(((d, r) for d, runs in drivers.items() for r in runs if r[4] and r[3] <= target),
               key=lambda x: x[1][1], default=None)
    return ours and (target, theirs, ours, theirs[1] / ours[1][1])


def work_precision(m, peer):
    """The rows wp_* of bench-results.json and the charts
    docs/img/work_precision_<scene>.svg: every driver and the scene's peer."""
    scenes, peers = wp_scenes(m, peer)
    rows = []
    for scene, drivers in scenes.items():
        for driver, runs in drivers.items():
            for tol, seconds, evaluations, error, _, _ in runs:
                a = m[f"WP/{scene}/{driver}/{tol}"]
                rows.append({"case": f"wp_{scene}_{driver}_tol1e-{tol}", "mechopt_benchmark": f"WP/{scene}/{driver}/{tol}",
                             "mechopt_seconds": seconds, "evaluations": evaluations,
                             "mechopt_error": error, "converged": bool(a["converged"])})
        script, case, label, knob = PEER_WP[scene]
        for tol, seconds, evaluations, error, converged, _ in peers.get(scene, []):
            rows.append({"case": f"wp_{scene}_peer_{knob}1e-{tol}", "peer_method": f"{label}, {knob} 1e-{tol} "
                         f"(bench/{script})", "mechopt_seconds": None, "peer_seconds": seconds,
                         "evaluations": evaluations, "peer_error": error, "converged": converged})
        lines = {d: [(t, e, ok, tol) for tol, t, _, e, ok, _ in runs] for d, runs in drivers.items()}
        notes = list(WP_NOTES.get(scene, []))
        if scene in peers:
            lines[f"{label} (peer)"] = [(t, e, ok, tol) for tol, t, _, e, ok, _ in peers[scene]]
            mt = wp_matched(drivers, peers[scene])
            if mt:
                target, theirs, (driver, ours), ratio = mt
                notes += [f"within the peer's best error, {fmt_err(theirs[3])}:",
                         f"peer {fmt_time(theirs[1])} ({wp_tol(scene, 'peer', theirs[0])}),",
                         f"{driver} {fmt_time(ours[1])} ({wp_tol(scene, driver, ours[0])}): {fmt_ratio(ratio)}x"]
        path = os.path.join(ROOT, "docs", "img", f"work_precision_{scene}.svg")
        write_work_precision_svg(path, scene, lines, peers=[f"{label} (peer)"], notes=notes)
        print(f"chart: {os.path.relpath(path, ROOT)}", file=sys.stderr)
    return rows


def print_rows(rows):
    print(f"{'case':34s} {'mechopt':>11s} {'peer':>11s} {'ratio':>7s} {'mech err':>9s} {'peer err':>9s}")
    for r in rows:
        fmt = lambda v: "-" if v is None or v != v else f"{v:.1e}"
        peer_s = f"{r['peer_seconds'] * 1e6:9.2f}us" if "peer_seconds" in r else f"{'-':>11s}"
        ratio = f"{r['ratio']:7.1f}" if "ratio" in r else f"{'-':>7s}"
        mech_s = f"{r['mechopt_seconds'] * 1e6:9.3f}us" if r.get("mechopt_seconds") else f"{'-':>11s}"
        print(f"{r['case']:34s} {mech_s} {peer_s} {ratio} "
              f"{fmt(r.get('mechopt_error')):>9s} {fmt(r.get('peer_error')):>9s}")


def doc_blocks(m, peer, debian, rows, tcp, peak_elastic, lstar, l_co1_star):
    row = {r["case"]: r for r in rows}
    line = machine_line()
    perf = performance_blocks(m, peer, debian, row, tcp, peak_elastic, lstar, l_co1_star)
    perf["press_sawmill"] = press_sawmill_block(row, m)
    return {"docs/performance.md": {"machine": line, **perf},
            "docs/drivers.md": {"machine": line, **drivers_blocks(m, peer)}}


def write_blocks(path, blocks, partial=False):
    """Replaces each block's content; every block in the file must be written
    (partial: only the blocks given, each of which must be in the file)."""
    text = open(path).read()
    found = re.findall(r"<!-- generated by bench/run_bench\.py: (\S+) -->", text)
    missing, unknown = set(blocks) - set(found), set() if partial else set(found) - set(blocks)
    if missing or unknown or len(found) != len(set(found)):
        sys.exit(f"{path}: generated blocks do not match the script (missing {sorted(missing)}, "
                 f"unknown {sorted(unknown)}, found {found})")
    for name, body in blocks.items():
        text = re.sub(rf"(<!-- generated by bench/run_bench\.py: {re.escape(name)} -->\n).*?(<!-- end {re.escape(name)} -->)",
                      lambda mt: mt.group(1) + "\n" + body.strip("\n") + "\n\n" + mt.group(2), text, count=1, flags=re.S)
    with open(path, "w") as f:
        f.write(text)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--repetitions", type=int, default=5)
    ap.add_argument("--debian-build", default=os.path.join(ROOT, "build-debian-sundials"),
                    help="a build linked with Debian's libsundials (cmake -S . -B DIR, no SUNDIALS_DIR); "
                         "its bench_elastic fills performance.md's SUNDIALS table when present")
    ap.add_argument("--no-docs", action="store_true",
                    help="do not write the generated blocks of docs/performance.md and docs/drivers.md")
    ap.add_argument("--only", choices=["press_sawmill", "wp"],
                    help="run one group alone: its bench and peers, its rows in build/bench-results-NAME.json "
                         "and its docs (press_sawmill: its block of docs/performance.md, with this run's machine "
                         "line in it; wp: the drivers' two work-precision charts and docs/drivers.md, machine line "
                         "included)")
    args = ap.parse_args()
    if args.only == "press_sawmill":
        print("running bench_press_sawmill and its peers ...", file=sys.stderr)
        m, peer = run_press_sawmill(args.build, args.repetitions)
        if not args.no_docs:
            press_sawmill_charts(m, peer)
        rows = case_rows(press_sawmill_cases(), m, peer)
        out = os.path.join(args.build, "bench-results-press_sawmill.json")
        json.dump(rows, open(out, "w"), indent=1)
        print_rows(rows)
        print(f"written: {out}")
        if not args.no_docs:
            write_blocks(os.path.join(ROOT, "docs", "performance.md"),
                         {"press_sawmill": press_sawmill_block({r["case"]: r for r in rows}, m) +
                                           "\n\nThis block alone: " + machine_line().replace(" (`make bench`)", "")}, partial=True)
            print("written: docs/performance.md (block press_sawmill)")
        return
    if args.only == "wp":
        print("running bench_drivers' WP/ cases and the peers' work-precision cases ...", file=sys.stderr)
        m = google_benchmark(os.path.join(args.build, "bin", "bench_drivers"), 3, "^WP/")
        peer = {}
        for script, *_ in PEER_WP.values():
            peer.update(run_peer(script, "--wp"))
        rows = work_precision(m, peer)
        out = os.path.join(args.build, "bench-results-wp.json")
        json.dump(rows, open(out, "w"), indent=1)
        print_rows(rows)
        print(f"written: {out}")
        if not args.no_docs:
            path = os.path.join(ROOT, "docs", "drivers.md")
            write_blocks(path, {"machine": machine_line().replace(" (`make bench`)", ""), **drivers_blocks(m, peer)})
            print(f"written: {os.path.relpath(path, ROOT)}")
        return
    tcp, tmax, grad, lstar, peak_v1, l_co1_star = references()

    print("running Google Benchmark cases ...", file=sys.stderr)
    m = {}
    for binary in ("bench_recuperative", "bench_conveyor", "bench_drivers", "bench_elastic", PRESS_SAWMILL_BINARY):
        m.update(google_benchmark(os.path.join(args.build, "bin", binary),
                                  3 if binary == "bench_drivers" else args.repetitions))
    # The same cases on Debian's unoptimised libsundials, when such a build exists.
    debian = {}
    debian_bin = os.path.join(args.debian_build, "bin", "bench_elastic")
    if os.path.exists(debian_bin):
        print(f"running {os.path.relpath(debian_bin, ROOT)} (Debian's libsundials) ...", file=sys.stderr)
        debian = google_benchmark(debian_bin, args.repetitions, "BM_|WPE/(erk|bdf)/8$")
    print("running the Python peers ...", file=sys.stderr)
    peer = {}
    for script in ("peer_recuperative.py", "peer_conveyor.py", "peer_elastic.py") + PRESS_SAWMILL_PEERS:
        peer.update(run_peer(script))
    for script, *_ in PEER_WP.values():
        peer.update(run_peer(script, "--wp"))

    cases = comparison_cases(peer)
    peak_elastic = peer["reference"]["value"]
    rows = case_rows(cases, m, peer)
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
    # What a driver pays per evaluation, and the model's share of it.
    for case, bm in (("problem_evaluate_28", "BM_ProblemEvaluate"),
                     ("cycle_mean_gradient_28", "BM_MeanKineticEnergyGradient/28")):
        rows.append({"case": case, "mechopt_benchmark": bm, "mechopt_seconds": m[bm]["seconds"]})
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
    # (seconds, error, method, -log10 rtol) of the fastest run within 1e-6
    fastest = lambda label, runs: min(((t, e, label, tol) for t, e, _, tol in runs if e <= 1e-6), default=None)
    ours = min(filter(None, (fastest(k, r) for k, r in wpe.items())), default=None)
    for method, runs in sorted(peer_wp.items()):
        theirs = fastest(method, runs)
        if ours and theirs:
            rows.append({"case": "elastic_steady_1e-6_vs_" + method.split()[1],
                         "mechopt_benchmark": f"WPE (fastest within 1e-6: {ours[2]}, rtol 1e-{ours[3]})",
                         "peer_method": f"{method} (fastest within 1e-6: rtol 1e-{theirs[3]}), the same algorithm",
                         "mechopt_seconds": ours[0], "peer_seconds": theirs[0], "ratio": theirs[0] / ours[0],
                         "mechopt_error": ours[1], "peer_error": theirs[1]})
    if wpe:
        path = os.path.join(ROOT, "docs", "img", "work_precision_elastic_steady.svg")
        write_work_precision_svg(path, "elastic drive steady state", {**wpe, **peer_wp})
    rows += work_precision(m, peer)
    if not args.no_docs:
        press_sawmill_charts(m, peer)
        grid_chart("cycle_mean", "recuperative drive, mean kinetic energy, l = 0.8 m", m,
                   r"BM_MeanKineticEnergy/(\d+)", tcp, "grid points",
                   [("numpy trapezoid, 32 points", peer["cycle_mean"]),
                    ("numpy trapezoid, 16 points", peer["cycle_mean_16"]),
                    ("scipy quad, epsrel 1e-12", peer["cycle_mean_quad"])])
        grid_chart("swing_peak", "conveyor variant 1, peak balancing moment", m, r"BM_SwingMetrics/(\d+)/0",
                   peak_v1, "grid points", [("numpy peer, 48 points + refine", peer["swing_peak"])])
    print("running the batch DOE cases (bench/doe_bench.py) ...", file=sys.stderr)
    doe_rows = doe_bench.run(args.build, doe_bench.REPETITIONS, not args.no_docs)
    print("running each driver from 49 start points on a kink (bench/kink_map.py) ...", file=sys.stderr)
    kink_rows = kink_map.run(args.build, not args.no_docs)
    out = os.path.join(args.build, "bench-results.json")
    json.dump(rows + doe_rows + kink_rows, open(out, "w"), indent=1)
    print_rows(rows)
    print(f"written: {out}")
    if not args.no_docs:
        for path, blocks in doc_blocks(m, peer, debian, rows, tcp, peak_elastic, lstar, l_co1_star).items():
            write_blocks(os.path.join(ROOT, path), blocks)
            print(f"written: {path}")


if __name__ == "__main__":
    main()
