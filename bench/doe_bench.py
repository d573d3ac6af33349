#!/usr/bin/env python3
"""Batch DOE throughput (docs/performance.md, "Batch design of experiments"),
run by run_bench.py or alone:

  /usr/bin/python3 bench/doe_bench.py [--build build] [--repetitions 7]

- designs per second of each configs/doe/ problem, every metric and the
  store, on 1 thread, on 2 threads and on 2 MPI ranks, with the scaling
  efficiency rate(2) / (2 rate(1)) (--threads N runs N threads in all, each
  evaluating and committing to a file of its own: N threads, N cores); as a
  control, two separate 1 thread runs at once (the sum of their rates over
  twice one run's: what the machine's two cores give work that shares
  nothing, measured in the same rounds); the
  recuperative DOE runs its first quarter (--shard 0/4: 250 000 designs),
  the others whole;
- the store's rows per second against its column count (bench_doe_store);
- a same-run peer for the recuperative DOE (bench/doe/peer_recuperative_doe.py):
  chunked numpy computing the same metrics, checked against mechopt's rows,
  and writing them to SQLite.
Rates are medians over the repetitions of the run (`rate` in result.json:
samples / seconds from the first sample to the end of the fold),
the labels of a case interleaved (1 thread, 2 threads, 2 processes, 2
ranks, again), so
that a shared machine's drifting load weighs on the efficiencies' both
sides alike; the peer's too (it runs as many times; its first run checks
the values).
"""
import argparse
import json
import os
import shutil
import sqlite3
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
REPETITIONS = 7  # a 0.3 s run moves by several percent on a shared machine
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}

# name, config, --shard (None: all of it)
CASES = [("recuperative_drive", "configs/doe/recuperative_drive.yaml", "0/4"),
         ("conveyor_swing", "configs/doe/conveyor_swing.yaml", None),
         ("elastic_drive", "configs/doe/elastic_drive.yaml", None)]


def run_doe(binary, config, out, threads, shard, ranks=1, processes=1):
    """One run into a fresh `out`: (result.json, whole-process seconds).
    With processes > 1, as many separate runs of the same work at once, each
    into its own directory (out, out-1, ..): the first one's result.json
    with `rate` the sum of theirs, and the slowest one's seconds."""
    outs = [out] + [f"{out}-{k}" for k in range(1, processes)]
    cmds = []
    for o in outs:
        shutil.rmtree(o, ignore_errors=True)
        cmd = [binary, "run", os.path.join(ROOT, config), "--output", o, "--progress", "none",
               "--threads", str(threads)] + (["--shard", shard] if shard else [])
        cmds.append(["mpirun", "-n", str(ranks), "--oversubscribe"] + cmd if ranks > 1 else cmd)
    errs = [tempfile.TemporaryFile() for _ in cmds]
    t0 = time.perf_counter()
    procs = [subprocess.Popen(c, stdout=subprocess.DEVNULL, stderr=e, env={**os.environ, **MPI_ENV})
             for c, e in zip(cmds, errs)]
    codes = [p.wait() for p in procs]
    seconds = time.perf_counter() - t0
    for c, code, e in zip(cmds, codes, errs):
        if code != 0:
            e.seek(0)
            sys.exit(f"doe_bench: {' '.join(c)}: exit {code}: {e.read().decode()[-2000:]}")
    results = [json.load(open(os.path.join(o, "result.json"))) for o in outs]
    first = dict(results[0])
    first["rate"] = sum(r["rate"] for r in results)
    return first, seconds


def mean_sample_seconds(store):
    """Mean wall time of one evaluation in the store (the model alone)."""
    with sqlite3.connect(store) as db:
        return db.execute("select avg(wall_time) from samples").fetchone()[0]


def write_path_rates(build):
    """{benchmark name: rows/s} of bench_doe_store's write path: N producers
    into files of their own, the fold, merge (medians of 3)."""
    out = subprocess.run([os.path.join(build, "bin", "bench_doe_store"),
                          "--benchmark_filter=BM_Producers|BM_Fold|BM_Merge",
                          "--benchmark_format=json", "--benchmark_repetitions=3",
                          "--benchmark_report_aggregates_only=true"],
                         check=True, capture_output=True, text=True).stdout
    return {b["run_name"].split("/iterations")[0]: b["rows_per_second"]
            for b in json.loads(out)["benchmarks"] if b.get("aggregate_name") == "median"}


def store_rates(build):
    """{(metrics, rows a transaction): (columns, rows/s)} of bench_doe_store's
    BM_Append/METRICS/ROWS."""
    out = subprocess.run([os.path.join(build, "bin", "bench_doe_store"), "--benchmark_filter=BM_Append",
                          "--benchmark_format=json", "--benchmark_min_time=0.5",
                          "--benchmark_repetitions=3", "--benchmark_report_aggregates_only=true"],
                         check=True, capture_output=True, text=True).stdout
    rates = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") == "median":
            _, metrics, batch = b["run_name"].split("/")[:3]
            rates[(int(metrics), int(batch))] = (int(b["columns"]), b["rows_per_second"])
    return rates


def measure(build, repetitions):
    binary = os.path.join(build, "bin", "mechopt")
    mpi = shutil.which("mpirun") is not None
    work = tempfile.mkdtemp(prefix="doe_bench_")
    rows = []
    try:
        for name, config, shard in CASES:
            # label: (threads, ranks, processes). "2 processes" is the
            # control: two separate 1 thread runs of the same work at once
            # (two stores), what the machine's two cores give to work that
            # shares nothing, in the same rounds as the 2 thread run.
            runs = {"1 thread": (1, 1, 1), "2 threads": (2, 1, 1), "2 processes": (1, 1, 2)}
            if mpi:
                runs["2 ranks"] = (1, 2, 1)
            # Interleaved (each label, then again): a machine whose load
            # drifts over the minute moves every label alike.
            rates, walls, evaluations = ({label: [] for label in runs} for _ in range(3))
            for _ in range(repetitions):
                for label, (threads, ranks, processes) in runs.items():
                    j, wall = run_doe(binary, config, os.path.join(work, name), threads, shard, ranks, processes)
                    if j["ranks"] != ranks:
                        sys.exit(f"doe_bench: {name} {label}: {j['ranks']} ranks ran (mechopt built without MPI?)")
                    rates[label].append(j["rate"])
                    walls[label].append(wall)
                    evaluations[label].append(mean_sample_seconds(os.path.join(work, name, "store.sqlite")))
            med = {}
            for label, (threads, ranks, processes) in runs.items():
                med[label] = statistics.median(rates[label])
                row = {"case": f"doe_{name}_{label.replace(' ', '_')}", "config": config, "shard": shard,
                       "samples": j["evaluated"], "threads": threads, "ranks": ranks, "processes": processes,
                       "designs_per_second": med[label], "designs_per_minute": 60 * med[label],
                       "process_seconds": statistics.median(walls[label]),
                       "mean_evaluation_seconds": statistics.median(evaluations[label])}
                if label != "1 thread":
                    row["efficiency"] = med[label] / (2 * med["1 thread"])
                    # Each round's own: how far a shared machine moves it.
                    row["efficiency_rounds"] = [r / (2 * r1) for r, r1 in zip(rates[label], rates["1 thread"])]
                rows.append(row)
            if name == "recuperative_drive":  # the peer checks its values against this run's store
                peer = peer_runs(j["evaluated"], os.path.join(work, name, "store.sqlite"), repetitions)
                one = next(r for r in rows if r["case"] == "doe_recuperative_drive_1_thread")
                two = next(r for r in rows if r["case"] == "doe_recuperative_drive_2_threads")
                rows.append({"case": "doe_recuperative_peer", "peer_method": peer_method(peer),
                             "samples": peer["designs"],
                             "peer_compute_per_second": peer["compute_rate"],
                             "peer_end_to_end_per_second": peer["total_rate"],
                             "peer_compute_per_second_runs": peer["compute_rates"],
                             "peer_max_rel_diff": peer.get("max_rel_diff"),
                             "compute_ratio_per_core": 1 / (peer["compute_rate"] * one["mean_evaluation_seconds"]),
                             "end_to_end_ratio_1_thread": one["designs_per_second"] / peer["total_rate"],
                             "end_to_end_ratio_2_threads": two["designs_per_second"] / peer["total_rate"]})
    finally:
        shutil.rmtree(work, ignore_errors=True)
    for (metrics, batch), (columns, rate) in sorted(store_rates(build).items(), key=lambda kv: (-kv[0][1], kv[0][0])):
        rows.append({"case": f"doe_store_append_{columns}_columns_{batch}_rows", "columns": columns,
                     "metrics": metrics, "batch_rows": batch, "rows_per_second": rate})
    for name, rate in write_path_rates(build).items():
        rows.append({"case": "doe_store_" + name.replace("/", "_"), "rows_per_second": rate})
    return rows


def peer_runs(samples, store, repetitions):
    """The peer `repetitions` times on the samples of mechopt's run (the first
    checks its values against mechopt's store): the first run's JSON with
    the median rates, as mechopt's are medians."""
    runs = []
    for k in range(repetitions):
        cmd = [sys.executable, os.path.join(HERE, "doe", "peer_recuperative_doe.py"), "--samples", str(samples)]
        runs.append(json.loads(subprocess.run(cmd + (["--check", store] if k == 0 else []),
                                              check=True, capture_output=True, text=True).stdout))
    peer = dict(runs[0])
    for key in ("compute_rate", "total_rate"):
        peer[key] = statistics.median(r[key] for r in runs)
    peer["compute_rates"] = [r["compute_rate"] for r in runs]
    return peer


def peer_method(peer):
    return (f"numpy {peer.get('numpy', '')} chunks of {peer['chunk']} designs x crank angles, the same "
            "quadrature and refined maxima, rows to SQLite (WAL) by executemany, one process")


def fmt_rate(r):
    return f"{r / 1e3:.1f}k/s" if r < 1e6 else f"{r / 1e6:.2f}M/s"


def block(rows):
    """The markdown of performance.md's generated block `doe`."""
    by = {r["case"]: r for r in rows}
    lines = ["| problem (samples) | 1 thread | 2 threads | efficiency | control: 2 processes | 2 ranks | efficiency "
             "| one evaluation |", "|---|---|---|---|---|---|---|---|"]
    for name, config, shard in CASES:
        one, two, control = (by[f"doe_{name}_{label}"] for label in ("1_thread", "2_threads", "2_processes"))
        ranks = by.get(f"doe_{name}_2_ranks")
        lines.append(f"| {name} ({one['samples']}) | {fmt_rate(one['designs_per_second'])} | "
                     f"{fmt_rate(two['designs_per_second'])} | {two['efficiency']:.0%} | {control['efficiency']:.0%} | "
                     + (f"{fmt_rate(ranks['designs_per_second'])} | {ranks['efficiency']:.0%}" if ranks else "- | -")
                     + f" | {one['mean_evaluation_seconds'] * 1e6:.1f} us |")
    spread = [f"{name} {fmt_range(by[f'doe_{name}_2_threads']['efficiency_rounds'])} "
              f"(control {fmt_range(by[f'doe_{name}_2_processes']['efficiency_rounds'])})" for name, _, _ in CASES]
    lines += ["", "Efficiency 1 -> 2 threads in each interleaved round (1 thread, 2 threads, 2 processes, "
              "2 ranks, then again): " + ", ".join(spread) + "."]
    peer = by["doe_recuperative_peer"]
    two = by["doe_recuperative_drive_2_threads"]
    diffs = peer["peer_max_rel_diff"] or {}
    worst = max(diffs.items(), key=lambda kv: kv[1], default=("-", float("nan")))
    lines += ["", "| recuperative DOE, same run | mechopt | numpy peer | ratio | target |", "|---|---|---|---|---|",
              f"| compute per core (designs/s) | {fmt_rate(1 / by['doe_recuperative_drive_1_thread']['mean_evaluation_seconds'])} "
              f"| {fmt_rate(peer['peer_compute_per_second'])} | {peer['compute_ratio_per_core']:.1f} | >= 10 |",
              f"| end to end, 1 thread (designs/s) | {fmt_rate(by['doe_recuperative_drive_1_thread']['designs_per_second'])} "
              f"| {fmt_rate(peer['peer_end_to_end_per_second'])} | {peer['end_to_end_ratio_1_thread']:.1f} | >= 5 |",
              f"| end to end, 2 threads (designs/min) | {two['designs_per_minute'] / 1e6:.1f}M | | | >= 20M |",
              "", f"The peer's values agree with mechopt's rows to {worst[1]:.1e} relative at worst ({worst[0]}); "
              f"peer: {peer['peer_method']}; its rates are medians of {len(peer['peer_compute_per_second_runs'])} "
              f"runs (compute {', '.join(fmt_rate(r) for r in sorted(peer['peer_compute_per_second_runs']))}).",
              "", "| store columns | rows a transaction | rows/s (append) |", "|---|---|---|"]
    for r in rows:
        if r["case"].startswith("doe_store_append_"):
            lines.append(f"| {r['columns']} | {r['batch_rows']} | {fmt_rate(r['rows_per_second'])} |")
    rate = {r["case"][len("doe_store_BM_"):]: r["rows_per_second"] for r in rows if r["case"].startswith("doe_store_BM_")}
    append = next(r["rows_per_second"] for r in rows if r["case"] == "doe_store_append_20_columns_20000_rows")
    if rate:
        lines += ["", "| store write path (20 columns) | rows/s | against | target |", "|---|---|---|---|"]
        for n in (1, 2, 3, 4):
            if f"Producers_{n}_0" in rate:
                lines.append(f"| {n} producer{'s' if n > 1 else ''}, a file each | {fmt_rate(rate[f'Producers_{n}_0'])} | "
                             f"{rate[f'Producers_{n}_0'] / rate['Producers_1_0']:.2f}x one | "
                             f"{'>= 1.8x with 2' if n == 2 else ''} |")
        if "Producers_2_1" in rate:
            lines.append(f"| control: 2 processes, a store each | {fmt_rate(rate['Producers_2_1'])} | "
                         f"{rate['Producers_2_1'] / rate['Producers_1_0']:.2f}x one | |")
        lines += [f"| fold, runs of indices appended | {fmt_rate(rate['Fold_0'])} | "
                  f"{rate['Fold_0'] / rate['Fold_1']:.2f}x interleaved | |",
                  f"| fold, two writers interleaved in 4096-row chunks | {fmt_rate(rate['Fold_1'])} | | |",
                  f"| one producer and the fold along with it | {fmt_rate(rate['FoldAlong_1'])} | "
                  f"{rate['FoldAlong_1'] / rate['FoldAlong_0']:.2f}x folding after | |",
                  f"| one producer, then the fold | {fmt_rate(rate['FoldAlong_0'])} | | |",
                  f"| merge of 4 shards of 250 000 rows | {fmt_rate(rate['Merge'])} | "
                  f"{rate['Merge'] / append:.2f}x append | >= 0.5x |"]
    return "\n".join(lines)


def write_block(path, body, name="doe", script="bench/doe_bench.py"):
    """Replaces the block between `<!-- generated by SCRIPT: NAME -->` and
    `<!-- end NAME -->` in path."""
    text = open(path).read()
    begin, end = f"<!-- generated by {script}: {name} -->\n", f"<!-- end {name} -->"
    if text.count(begin) != 1 or text.count(end) != 1:
        sys.exit(f"{path}: expected one block '{begin.strip()}' .. '{end}'")
    head, rest = text.split(begin)
    with open(path, "w") as f:
        f.write(head + begin + "\n" + body.strip("\n") + "\n\n" + end + rest.split(end, 1)[1])


def fmt_range(values):
    """'88-97%' for the lowest and highest of fractions."""
    return f"{min(values):.0%}".rstrip("%") + f"-{max(values):.0%}"


def run(build, repetitions, write_docs):
    """The rows for build/bench-results.json; with write_docs, performance.md's block."""
    rows = measure(build, repetitions)
    if write_docs:
        write_block(os.path.join(ROOT, "docs", "performance.md"), block(rows))
        print("written: docs/performance.md (doe)", file=sys.stderr)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--repetitions", type=int, default=REPETITIONS)
    ap.add_argument("--no-docs", action="store_true", help="do not write docs/performance.md's block")
    a = ap.parse_args()
    rows = run(a.build, a.repetitions, not a.no_docs)
    print(json.dumps(rows, indent=1))
    print(block(rows))


if __name__ == "__main__":
    main()
