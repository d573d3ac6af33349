#!/usr/bin/env python3
"""The benchmark gate of CI (`make bench-smoke`, a couple of minutes on 2
cores): every same-run comparison of run_bench.py against its numpy/scipy
peer, reduced (3 repetitions of 0.05 s), checked against
bench/smoke_gates.json. A case fails when mechopt's relative error against
its high-precision reference exceeds the case's stated tolerance, or when
its ratio (peer seconds / mechopt seconds, both from this run) falls below
its gate: half its target, or, where the target is not met yet, half of the
ratio measured when the gate was set (a regression floor, said so in the
file). Absolute times gate nothing. Writes build/bench-smoke.json.
Usage: /usr/bin/python3 bench/smoke.py [--build build]
"""
import argparse
import json
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import run_bench  # noqa: E402

BINARIES = ("bench_recuperative", "bench_conveyor", "bench_elastic", run_bench.PRESS_SAWMILL_BINARY)
PEERS = ("peer_recuperative.py", "peer_conveyor.py", "peer_elastic.py") + run_bench.PRESS_SAWMILL_PEERS


def measure(build, names):
    """Medians of the named benchmarks (3 repetitions, 0.05 s each)."""
    pattern = "^(" + "|".join(re.escape(n) for n in sorted(names)) + ")(/iterations:1)?$"
    m = {}
    for binary in BINARIES:
        m.update(run_bench.google_benchmark(os.path.join(build, "bin", binary), 3, pattern, 0.05))
    return m


def check(row, gate):
    """The reasons a row fails its gate (empty: it passes)."""
    why = []
    if row["ratio"] < gate["gate_ratio"]:
        why.append(f"ratio {row['ratio']:.3g}x < gate {gate['gate_ratio']:g}x")
    e = row["mechopt_error"]
    if "max_error" in gate and (e is None or not e <= gate["max_error"]):
        why.append(f"error {e:.2e} > tolerance {gate['max_error']:g}")
    return why


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(run_bench.ROOT, "build"))
    args = ap.parse_args()
    gates = json.load(open(os.path.join(HERE, "smoke_gates.json")))["cases"]
    print("bench-smoke: the peers ...", file=sys.stderr)
    peer = {}
    for script in PEERS:
        peer.update(json.loads(subprocess.run([sys.executable, os.path.join(HERE, script)],
                                              check=True, capture_output=True, text=True).stdout))
    cases = run_bench.comparison_cases(peer)
    missing = sorted(set(gates) ^ {c[0] for c in cases})
    if missing:
        sys.exit(f"bench-smoke: bench/smoke_gates.json and run_bench.comparison_cases differ in: {', '.join(missing)}")
    print("bench-smoke: mechopt's benchmarks ...", file=sys.stderr)
    m = measure(args.build, {c[1] for c in cases})
    rows = run_bench.case_rows(cases, m, peer)
    failed = 0
    print(f"{'case':34} {'ratio':>8} {'gate':>6} {'error':>9} {'tolerance':>9}  verdict")
    for r in rows:
        g = gates[r["case"]]
        why = check(r, g)
        r["gate"], r["failed"] = g, why
        failed += bool(why)
        e = "-" if r["mechopt_error"] is None else f"{r['mechopt_error']:.1e}"
        tol = f"{g['max_error']:.0e}" if "max_error" in g else "-"
        print(f"{r['case']:34} {r['ratio']:8.3g} {g['gate_ratio']:6g} {e:>9} {tol:>9}  "
              f"{'FAIL: ' + '; '.join(why) if why else 'ok'}")
    out = os.path.join(args.build, "bench-smoke.json")
    json.dump(rows, open(out, "w"), indent=1)
    print(f"bench-smoke: {len(rows) - failed} of {len(rows)} cases pass; written: {out}")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
