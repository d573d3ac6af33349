#!/usr/bin/python3
"""The general linkage against the hand-written problems, in time.

Runs bench_linkage's rows with many short repetitions, randomly
interleaved (so a slow spell of the shared machine falls on both rows of
a pair alike), and prints for each pair the CPU time's minimum and
median over the repetitions and their ratios, linkage / hand-written.
The minimum is the run least disturbed by other work; the median what a
caller sees on the machine as it was.

    bench/linkage_ratios.py [--binary build/bin/bench_linkage] [--repetitions 40] [--min-time 0.05]
"""
import argparse
import json
import statistics
import subprocess
import sys

# (linkage row, hand-written row, what it is): bench_linkage.cpp's cases.
PAIRS = [
    ("1/0", "0/0", "slider-crank"),
    ("1/1", "0/1", "slider-crank, gradients"),
    ("3/0", "2/0", "conveyor with its means"),
    ("5/0", "4/0", "conveyor peaks"),
    ("5/1", "4/1", "conveyor peaks, gradients"),
    ("10/0", "9/0", "twin drive"),
    ("10/1", "9/1", "twin drive, gradients"),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default="build/bin/bench_linkage")
    ap.add_argument("--repetitions", type=int, default=40)
    ap.add_argument("--min-time", type=float, default=0.05)
    a = ap.parse_args()
    rows = sorted({r for p in PAIRS for r in p[:2]})
    pattern = "BM_Evaluate/(" + "|".join(rows) + ")$"
    out = subprocess.run(
        [a.binary, f"--benchmark_filter={pattern}", f"--benchmark_repetitions={a.repetitions}",
         f"--benchmark_min_time={a.min_time}", "--benchmark_enable_random_interleaving=true",
         "--benchmark_format=json"],
        check=True, capture_output=True, text=True).stdout
    times = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("run_type") != "iteration":
            continue
        row = b["run_name"].split("BM_Evaluate/")[1]
        times.setdefault(row, []).append(b["cpu_time"])  # microseconds (the rows' unit)
    print(f"{'pair':28s} {'hand min':>9s} {'linkage min':>11s} {'ratio':>6s}   "
          f"{'hand med':>9s} {'linkage med':>11s} {'ratio':>6s}")
    for g, h, what in PAIRS:
        if g not in times or h not in times:
            sys.exit(f"linkage_ratios: no times for rows {g} and {h}")
        gm, hm = min(times[g]), min(times[h])
        gd, hd = statistics.median(times[g]), statistics.median(times[h])
        print(f"{what:28s} {hm:9.3f} {gm:11.3f} {gm / hm:6.2f}   {hd:9.3f} {gd:11.3f} {gd / hd:6.2f}")


if __name__ == "__main__":
    main()
