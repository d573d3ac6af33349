#!/usr/bin/python3
"""Config fuzzer for mechopt (docs/testing.md).

Mutates the shipped configs (configs/**/*.yaml) with a fixed seed, one to
three mutations each, structural (types, units, extreme numbers, deleted,
duplicated and foreign keys, lists for scalars, huge grids, swapped bounds,
other enum choices) and textual (a few byte edits). Runs `mechopt run M
--output D` and `mechopt eval M` on each mutant under a wall-time limit and a
file-size limit, and fails on: a signal, a hang, an output file over the cap,
an exit code other than 0, 2 or 1 with a one-line message, an exit 2 without
a located message (file:line), a non-finite number marked ok, and fewer than
half of the mutants reaching an evaluation. Mutant i depends only on (seed, i).
"""
import argparse
import collections
import copy
import csv
import glob
import json
import math
import multiprocessing
import os
import random
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FILE_CAP = 4 << 20    # an output file larger than this fails the mutant ...
ROW_BYTES = 1024      # ... except a file of rows (sweep.csv, history.csv, the store), which may add this per row
ROW_FILES = ("sweep.csv", "history.csv", "store.sqlite", "store.sqlite-wal")
FSIZE_LIMIT = 64 << 20  # RLIMIT_FSIZE: any write beyond it is SIGXFSZ (stdout included)
MEMORY_LIMIT = 2 << 30  # RLIMIT_AS
KEEP_BYTES = 64 << 10   # of stdout/stderr kept for a failing mutant
BASE_SAMPLES = 4096     # a DOE base config's samples at most

EXTREMES = ["1e308", "1e300", "-1e308", "1e-300", "5e-324", "0", "-0", "-1", "-1e-9", "nan",
            "inf", "-inf", "1e12", "-1e12", "1e-12", "2147483648", "4294967297", "1e20"]
UNITS = ["m", "mm", "cm", "rad", "deg", "rad/s", "rpm", "kg", "t", "kg/m", "N", "kN", "s", "ms",
         "furlong", "N m", "m/s", "J", "kN m s/rad", "MN*m/rad", "rev/min", "kgf", "kg/mm", "kgf/cm^2",
         "кгс/см²", "тс", "hp", "PS", "kg/m s", "m^", "m^x", "/s", "kg//m", "m^-99", "N·m·", "1/"]
CONVERSIONS = {"m": [("mm", 1e3), ("cm", 1e2)], "mm": [("m", 1e-3)], "cm": [("m", 1e-2)],
               "deg": [("rad", math.pi / 180)], "rad": [("deg", 180 / math.pi)],
               "rpm": [("rad/s", math.pi / 30), ("rev/min", 1.0)], "rad/s": [("rpm", 30 / math.pi)],
               "kg": [("t", 1e-3)], "N": [("kN", 1e-3), ("kgf", 1 / 9.80665)],
               "kN": [("N", 1e3), ("tf", 1 / 9.80665)], "s": [("ms", 1e3)],
               "kg/m": [("kg/mm", 1e-3)], "N m/rad": [("kN*m/rad", 1e-3)], "W": [("kW", 1e-3)]}
QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S.*)?$")
TEXT_CHARS = ":{}[],-#&*!|>'\"%@` \t\n0123456789.eE"


# ---------------------------------------------------------------- mutations

def paths(node, prefix=()):
    """Every (path, value) below node, containers and leaves."""
    out = []
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else []
    for k, v in items:
        out.append((prefix + (k,), v))
        out.extend(paths(v, prefix + (k,)))
    return out


def get(data, path):
    for k in path:
        data = data[k]
    return data


def put(data, path, value):
    get(data, path[:-1])[path[-1]] = value


def is_leaf(v):
    return not isinstance(v, (dict, list))


def number_of(v):
    """(number text, unit) of a number or a quantity string, else None."""
    if isinstance(v, bool) or v is None:
        return None
    if isinstance(v, (int, float)):
        return repr(v), ""
    m = QUANTITY.match(str(v))
    return (m.group(1), m.group(2) or "") if m else None


def quantity(number, unit, rng):
    """A number (with its unit) as YAML data: a quantity string, a float or plain text."""
    if unit:
        return f"{number} {unit}"
    if number in ("nan", "inf", "-inf") and rng.random() < 0.5:
        return float(number)  # dumped as .nan / .inf
    try:
        return int(number)
    except ValueError:
        return float(number) if rng.random() < 0.5 else number


def numeric_leaves(data):
    return [(p, v) for p, v in paths(data) if is_leaf(v) and number_of(v) and p[0] != "problem"]


def m_extreme(data, rng, ctx):
    cand = numeric_leaves(data)
    if not cand:
        return None
    p, v = rng.choice(cand)
    num = rng.choice(EXTREMES)
    put(data, p, quantity(num, number_of(v)[1], rng))
    return f"extreme number {'.'.join(map(str, p))} = {num}"


def m_scale(data, rng, ctx):
    cand = [(p, v) for p, v in numeric_leaves(data) if p[0] == "model"]
    if not cand:
        return None
    p, v = rng.choice(cand)
    num, unit = number_of(v)
    f = rng.choice([0.5, 0.8, 1.25, 2, 1.01, 0.99])
    # A whole number stays whole (a count, a table row), so the mutant stays valid.
    scaled = repr(max(1, round(float(num) * f))) if isinstance(v, int) else repr(float(num) * f)
    put(data, p, quantity(scaled, unit, rng))
    return f"scaled {'.'.join(map(str, p))} x{f}"


def m_unit(data, rng, ctx):
    cand = numeric_leaves(data)
    if not cand:
        return None
    p, v = rng.choice(cand)
    num, unit = number_of(v)
    how = rng.choice(["swap", "strip", "glue", "double"])
    if how == "strip" and unit:
        new = quantity(num, "", rng)
    elif how == "glue" and unit:
        new = f"{num}{unit}"
    elif how == "double":
        new = f"{num} {unit or 'm'} {unit or 'm'}"
    else:
        how, new = "swap", f"{num} {rng.choice(UNITS)}"
    put(data, p, new)
    return f"unit {how} {'.'.join(map(str, p))}: {v!r} -> {new!r}"


def m_convert(data, rng, ctx):
    cand = [(p, v) for p, v in numeric_leaves(data) if number_of(v)[1] in CONVERSIONS]
    if not cand:
        return None
    p, v = rng.choice(cand)
    num, unit = number_of(v)
    to, f = rng.choice(CONVERSIONS[unit])
    new = f"{float(num) * f!r} {to}"
    put(data, p, new)
    return f"unit convert {'.'.join(map(str, p))}: {v!r} -> {new!r}"


def m_type(data, rng, ctx):
    cand = [(p, v) for p, v in paths(data)]
    if not cand:
        return None
    p, v = rng.choice(cand)
    new = rng.choice(["text", True, None, {"a": 1}, [1, 2], "", 3, -2.5, {}, []])
    put(data, p, new)
    return f"type {'.'.join(map(str, p))} -> {new!r}"


def m_delete(data, rng, ctx):
    cand = [p for p, v in paths(data) if isinstance(get(data, p[:-1]), dict)]
    if not cand:
        return None
    p = rng.choice(cand)
    del get(data, p[:-1])[p[-1]]
    return f"deleted {'.'.join(map(str, p))}"


def m_foreign(data, rng, ctx):
    mine = data.get("problem")
    others = [(k, v, where) for prob, keys in ctx["keys"].items() if prob != mine
              for where, kv in keys.items() for k, v in kv.items()]
    if not others:
        return None
    k, v, where = rng.choice(others)
    if not isinstance(data.get(where), dict):
        data[where] = {}
    data[where][k] = copy.deepcopy(v)
    return f"foreign key {where}.{k} = {v!r}"


def m_list(data, rng, ctx):
    cand = [(p, v) for p, v in paths(data) if is_leaf(v) or isinstance(v, list)]
    if not cand:
        return None
    p, v = rng.choice(cand)
    new = (v[0] if v else None) if isinstance(v, list) else [v] * rng.choice([1, 2])
    put(data, p, new)
    return f"list/scalar {'.'.join(map(str, p))} -> {new!r}"


def m_grid(data, rng, ctx):
    variables = data.get("variables")
    if not isinstance(variables, dict) or not variables:
        return None
    names = list(variables)
    name = rng.choice(names)
    bounds = variables[name] if isinstance(variables[name], dict) else {}
    lo, hi = bounds.get("min", 0), bounds.get("max", 1)
    unit = (number_of(lo) or ("", ""))[1]
    how = rng.choice(["tiny_step", "huge_count", "empty", "reversed", "two_axes"])
    if how == "tiny_step":
        axis = {"from": lo, "to": hi, "step": f"{rng.choice(['1e-12', '1e-300', '5e-324', '1e-7'])} {unit}".strip()}
    elif how == "huge_count":
        axis = {"from": f"0 {unit}".strip(), "to": f"{rng.choice(['1e7', '1e12', '1e300'])} {unit}".strip(),
                "step": f"1 {unit}".strip()}
    elif how == "empty":
        axis = []
    elif how == "reversed":
        axis = {"from": hi, "to": lo, "step": f"0.1 {unit}".strip()}
    else:
        axis = {"from": lo, "to": hi, "step": f"1e-5 {unit}".strip()}
    study = data.get("study") if isinstance(data.get("study"), dict) else {}
    study["type"] = "sweep"
    study.pop("objectives", None)
    study.pop("points", None)
    grid = study.get("grid") if isinstance(study.get("grid"), dict) else {}
    grid[name] = axis
    if how == "two_axes":
        for other in names:
            ob = variables[other] if isinstance(variables[other], dict) else {}
            ou = (number_of(ob.get("min", 0)) or ("", ""))[1]
            grid[other] = {"from": ob.get("min", 0), "to": ob.get("max", 1), "step": f"1e-5 {ou}".strip()}
    study["grid"] = grid
    data["study"] = study
    return f"grid {how} on {name}: {axis!r}"


def m_bounds(data, rng, ctx):
    cand = [(p, v) for p, v in paths(data) if isinstance(v, dict) and ("min" in v or "max" in v)]
    if not cand:
        return None
    p, v = rng.choice(cand)
    how = rng.choice(["swap", "equal", "initial_outside"])
    if how == "swap" or "min" not in v or "max" not in v:
        v["min"], v["max"] = v.get("max"), v.get("min")
    elif how == "equal":
        v["max"] = v["min"]
    else:
        num, unit = number_of(v["max"]) or ("1", "")
        v["initial"] = quantity(repr(float(num) * 3 + 1), unit, rng)
    return f"bounds {how} {'.'.join(map(str, p))}: {v!r}"


def m_choice(data, rng, ctx, mild=True):
    """Another value of an enum-like key: one seen in a config of the same
    problem (mild), or any value seen for that key name, other libraries
    and study types included (hostile)."""
    prob = data.get("problem")  # an earlier mutation may have made it a list
    table = ctx["choices"].get(prob, {}) if mild and isinstance(prob, str) else ctx["any_choice"]
    cand = [(p, v) for p, v in paths(data) if isinstance(v, str) and isinstance(p[-1], str)
            and len(table.get(p[-1], ())) > 1 and not (mild and p[-1] in MILD_EXCLUDED)]
    if not cand:
        return None
    p, v = rng.choice(cand)
    new = rng.choice(sorted(table[p[-1]] - {v}))
    put(data, p, new)
    return f"choice {'.'.join(map(str, p))}: {v} -> {new}"


MILD_EXCLUDED = {"type", "library", "minimize", "maximize", "design"}


def m_any_choice(data, rng, ctx):
    return m_choice(data, rng, ctx, mild=False)


def t_duplicate(text, rng):
    lines = text.split("\n")
    cand = [i for i, l in enumerate(lines) if re.match(r"^\s*[A-Za-z_]\w*:\s+\S", l)]
    if not cand:
        return None
    i = rng.choice(cand)
    key = lines[i].split(":")[0]
    lines.insert(i + 1, f"{key}: {rng.choice(['0.3 m', '1', 'nan', '-1', 'true', '1e308'])}")
    return "\n".join(lines), f"duplicate key line {i + 2}: {lines[i + 1].strip()!r}"


def t_bytes(text, rng):
    edits = []
    for _ in range(rng.randint(1, 3)):
        i = rng.randrange(len(text))
        how = rng.choice(["delete", "insert", "replace", "swap"])
        c = rng.choice(TEXT_CHARS)
        if how == "delete":
            text = text[:i] + text[i + 1:]
        elif how == "insert":
            text = text[:i] + c + text[i:]
        elif how == "replace":
            text = text[:i] + c + text[i + 1:]
        else:
            text = text[:i] + text[i + 1:i + 2] + text[i:i + 1] + text[i + 2:]
        edits.append(f"{how}@{i}" + (f" {c!r}" if how in ("insert", "replace") else ""))
    return text, "bytes " + ", ".join(edits)


LAUGHS = "__nested_aliases__"


def laughs(width=9, depth=12):
    """'Billion laughs': &a1 holds `width` *a0, &a2 `width` *a1, ..., `depth` deep (about 1 KB)."""
    y = "[&a0 [" + ", ".join(["lol"] * width) + "]"
    for d in range(1, depth + 1):
        y += f", &a{d} [" + ", ".join([f"*a{d - 1}"] * width) + "]"
    return y + "]"


def m_aliases(data, rng, ctx):
    """Nested aliases as the problem, as the model, or as one model value: the
    reader must refuse them at once (exit 2, located), not expand them."""
    where = [("problem",), ("model",)]
    if isinstance(data.get("model"), dict):
        where += [("model", k) for k, v in data["model"].items() if is_leaf(v)]
    path = rng.choice(where)
    put(data, path, LAUGHS)
    return f"nested aliases at {'.'.join(map(str, path))}"


# Hostile mutations mostly make a config invalid (the right answer is then
# exit 2 with a located message); mild ones keep it valid but different (it
# should run). A mutant has at most one hostile mutation, and 60% of the
# mutants none, so that most of them get past parsing to an evaluation.
HOSTILE = [(m_extreme, 18), (m_unit, 10), (m_type, 6), (m_delete, 6), (m_foreign, 5), (m_list, 5),
           (m_grid, 8), (m_bounds, 6), (m_any_choice, 5), (t_duplicate, 4), (t_bytes, 4), (m_aliases, 2)]
MILD = [(m_scale, 10), (m_convert, 6), (m_choice, 6)]
TEXTUAL = (t_duplicate, t_bytes)


def absolute_paths(node, directory):
    """Makes the relative file names of `points_file`, `from` and `base` keys absolute, in place."""
    if isinstance(node, dict):
        for k, v in node.items():
            if k in ("points_file", "from", "base") and isinstance(v, str) and v.endswith((".csv", ".yaml")) \
                    and not os.path.isabs(v):
                node[k] = os.path.normpath(os.path.join(directory, v))
            else:
                absolute_paths(v, directory)
    elif isinstance(node, list):
        for v in node:
            absolute_paths(v, directory)


def context(configs, algorithms):
    """Model/variable keys per problem, and every value seen per enum-like key."""
    keys = collections.defaultdict(lambda: {"model": {}, "variables": {}})
    choices = collections.defaultdict(lambda: collections.defaultdict(set))
    for data in configs.values():
        prob = data.get("problem")
        for where in ("model", "variables"):
            keys[prob][where].update(data.get(where) or {})
        for p, v in paths(data):
            if isinstance(v, str) and isinstance(p[-1], str) and not number_of(v) and p[-1] not in (
                    "problem", "directory", "source"):
                choices[prob][p[-1]].add(v)
    any_choice = collections.defaultdict(set)
    for prob in choices:
        choices[prob]["algorithm"] |= set(algorithms)
        for k, vs in choices[prob].items():
            any_choice[k] |= vs
    any_choice["library"] |= {"nlopt", "ipopt"}
    any_choice["type"] |= {"optimize", "sweep", "pareto"}
    return {"keys": {k: dict(v) for k, v in keys.items()}, "choices": choices, "any_choice": any_choice}


def make_mutant(seed, i, bases, ctx):
    """Mutant i: (base name, YAML text, [descriptions]); depends only on seed, i."""
    rng = random.Random(f"{seed}:{i}")
    name = sorted(bases)[i % len(bases)]
    data = copy.deepcopy(bases[name])
    done, text_ops = [], []
    count = rng.choice([1, 1, 2, 3])
    for k in range(count):
        ops = HOSTILE if k == 0 and rng.random() < 0.4 else MILD
        for _attempt in range(10):
            op = rng.choices([o for o, _ in ops], [w for _, w in ops])[0]
            if op in TEXTUAL:
                text_ops.append(op)
                break
            what = op(data, rng, ctx)
            if what:
                done.append(what)
                break
    text = yaml.safe_dump(data, sort_keys=False, default_flow_style=False, width=1000).replace(LAUGHS, laughs())
    for op in text_ops:
        r = op(text, rng)
        if r:
            text, what = r
            done.append(what)
    return name, text, done


# ---------------------------------------------------------------- running

CPU_LIMIT = [30]  # seconds of CPU per command (--timeout); the wall-time limit is 3x that


def limits():
    resource.setrlimit(resource.RLIMIT_CPU, (CPU_LIMIT[0], CPU_LIMIT[0] + 2))
    resource.setrlimit(resource.RLIMIT_FSIZE, (FSIZE_LIMIT, FSIZE_LIMIT))
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def execute(cmd, cwd, stem, timeout):
    """Runs cmd in cwd, stdout/stderr to files, under the CPU, file-size and memory
    limits and a wall-time limit; returns (code, signal, timed_out, seconds)."""
    t0 = time.time()
    with open(os.path.join(cwd, stem + ".out"), "wb") as o, open(os.path.join(cwd, stem + ".err"), "wb") as e:
        p = subprocess.Popen(cmd, cwd=cwd, stdout=o, stderr=e, stdin=subprocess.DEVNULL,
                             preexec_fn=limits, start_new_session=True)
        try:
            rc = p.wait(3 * timeout)
            timed_out = rc in (-signal.SIGXCPU, -signal.SIGKILL)  # over the CPU limit
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            rc = p.wait()
            timed_out = True
    return (rc if rc >= 0 else None), (-rc if rc < 0 else 0), timed_out, time.time() - t0


def read(path, limit=KEEP_BYTES):
    try:
        with open(path, "rb") as f:
            return f.read(limit).decode("utf-8", "replace")
    except OSError:
        return ""


def finite_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def finite_cell(s):
    try:
        return math.isfinite(float(s))
    except ValueError:
        return False


def check_outputs(outdir, fails):
    """Non-finite numbers marked ok in result.json, sweep.csv and pareto.csv."""
    res = os.path.join(outdir, "result.json")
    if os.path.exists(res):
        try:
            with open(res) as f:
                j = json.load(f)
        except (ValueError, OSError) as err:
            fails.append(("run: result.json not JSON", str(err)[:200]))
            j = {}
        if j.get("design_status") == "ok":
            bad = [k for k, v in (j.get("metrics") or {}).items() if not finite_number(v)]
            if bad:
                fails.append(("run: non-finite metric with design_status ok", ", ".join(bad)))
        pareto = j.get("pareto") or {}
        f1, f2 = (pareto.get("objectives") or [None, None])[:2]
        for row in pareto.get("points") or []:
            if row.get("status") == "converged" and not (finite_number(row.get(f1)) and finite_number(row.get(f2))):
                fails.append(("run: non-finite pareto point marked converged", json.dumps(row)[:200]))
                break
    for name, ok in (("sweep.csv", "ok"), ("pareto.csv", "converged")):
        path = os.path.join(outdir, name)
        if not os.path.exists(path):
            continue
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                bad = [k for k, v in row.items() if k != "status" and not finite_cell(v)]
                if row.get("status") == ok and bad:
                    fails.append((f"run: non-finite value in {name} row marked {ok}", ", ".join(bad[:5])))
                    break


LOCATED = re.compile(r"^mechopt: error: (\S*mutant\.yaml):(\d+)(:\d+)?: ")
MESSAGE1 = re.compile(r"^mechopt: (error|failed): ")
INTERNAL = re.compile(r"std::|bad_alloc|_M_|basic_string|vector::|what\(\)")
HEADER = re.compile(r"^mechopt \S+ — ", re.M)


def judge(cmd, code, sig, timed_out, work, stem, fails):
    """Exit code, signal, hang and message checks of one command."""
    err = read(os.path.join(work, stem + ".err")).strip()
    lines = [l for l in err.splitlines() if l.strip()]
    if timed_out:
        fails.append((f"{cmd}: hang (over the CPU or wall-time limit)", (read(os.path.join(work, stem + ".out")).strip().splitlines() or [""])[-1][:200]))
    elif sig == signal.SIGXFSZ:
        fails.append((f"{cmd}: output over {FSIZE_LIMIT >> 20} MB (SIGXFSZ)", ""))
    elif sig:
        fails.append((f"{cmd}: signal {signal.Signals(sig).name}", (lines or [""])[-1][:200]))
    elif code == 2:
        if not (lines and LOCATED.match(lines[0])):
            fails.append((f"{cmd}: exit 2 without a located message", (lines or ["(no message)"])[0][:200]))
        elif len(lines) > 1:
            fails.append((f"{cmd}: exit 2 message over several lines", " / ".join(lines)[:200]))
    elif code == 1:
        if not (len(lines) == 1 and MESSAGE1.match(lines[0])):
            fails.append((f"{cmd}: exit 1 without a one-line 'mechopt: error|failed:' message", (lines or ["(no message)"])[-1][:200]))
        elif INTERNAL.search(lines[0]):
            fails.append((f"{cmd}: exit 1 with an internal message", lines[0][:200]))
    elif code != 0:
        fails.append((f"{cmd}: exit {code}", (lines or [""])[-1][:200]))


def run_mutant(job):
    i, base, text, what, binary, timeout, keep = job
    CPU_LIMIT[0] = int(timeout)
    work = tempfile.mkdtemp(prefix=f"fuzz{i:04d}-")
    try:
        with open(os.path.join(work, "mutant.yaml"), "w") as f:
            f.write(text)
        fails = []
        outdir = os.path.join(work, "out")
        r = execute([binary, "run", "mutant.yaml", "--output", outdir], work, "run", timeout)
        judge("run", *r[:3], work, "run", fails)
        e = execute([binary, "eval", "mutant.yaml"], work, "eval", timeout)
        judge("eval", *e[:3], work, "eval", fails)
        check_outputs(outdir, fails)
        if e[0] == 0:
            try:
                ev = json.loads(read(os.path.join(work, "eval.out"), FSIZE_LIMIT))
                if ev.get("status") == "ok":
                    bad = [k for k, v in (ev.get("metrics") or {}).items() if not finite_number(v)]
                    if bad:
                        fails.append(("eval: non-finite metric with status ok", ", ".join(bad)))
            except ValueError as err:
                fails.append(("eval: output not JSON", str(err)[:200]))
        # Rows the run reports (a sweep's or a batch's): files of rows grow with them.
        rows = 0
        for dirpath, _, files in os.walk(work):
            if "result.json" in files:
                try:
                    res = json.loads(read(os.path.join(dirpath, "result.json"), FSIZE_LIMIT))
                    rows = max(rows, int((res.get("sweep") or {}).get("evaluated", 0)), int(res.get("done", 0) or 0),
                               int(res.get("evaluations", 0) or 0))
                except (ValueError, TypeError, AttributeError):
                    pass
        for dirpath, _, files in os.walk(work):
            for fn in files:
                path = os.path.join(dirpath, fn)
                size = os.path.getsize(path)
                cap = FILE_CAP + (ROW_BYTES * rows if fn in ROW_FILES else 0)
                if size > cap and fn not in ("run.out", "run.err", "eval.out", "eval.err"):
                    fails.append((f"run: output file over {FILE_CAP >> 20} MB (+{ROW_BYTES} bytes a row for files of rows)",
                                  f"{os.path.relpath(path, work)}: {size} bytes"))
        reached = r[0] == 0 or (r[0] == 1 and bool(HEADER.search(read(os.path.join(work, "run.out"), 4096))))
        if fails and keep:
            dest = os.path.join(keep, f"{i:04d}")
            shutil.rmtree(dest, ignore_errors=True)
            os.makedirs(dest)
            for fn in ("mutant.yaml", "run.out", "run.err", "eval.out", "eval.err"):
                with open(os.path.join(dest, fn), "w") as f:
                    f.write(read(os.path.join(work, fn)))
            if os.path.isdir(outdir):
                shutil.copytree(outdir, os.path.join(dest, "out"),
                                ignore=lambda d, names: [n for n in names
                                                         if os.path.getsize(os.path.join(d, n)) > FILE_CAP])
            with open(os.path.join(dest, "what.txt"), "w") as f:
                f.write(f"mutant {i} of configs/{base}\nmutations:\n" + "".join(f"  {w}\n" for w in what))
                f.write(f"run: exit {r[0]} signal {r[1]} timed_out {r[2]} ({r[3]:.1f} s)\n")
                f.write(f"eval: exit {e[0]} signal {e[1]} timed_out {e[2]} ({e[3]:.1f} s)\n")
                f.write("failures:\n" + "".join(f"  {c}: {d}\n" for c, d in fails))
        return {"id": i, "base": base, "mutations": what, "failures": fails, "reached": reached,
                "run_exit": r[0], "run_signal": r[1], "run_hang": r[2], "eval_exit": e[0], "seconds": r[3] + e[3]}
    finally:
        shutil.rmtree(work, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=os.path.join(ROOT, "build/bin/mechopt"))
    ap.add_argument("-n", type=int, default=300, help="number of mutants")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=os.cpu_count())
    ap.add_argument("--timeout", type=int, default=30,
                    help="CPU seconds per command (wall-time limit: 3x); over it is a hang")
    ap.add_argument("--out", default=os.path.join(ROOT, "build/fuzz"), help="failing mutants go here")
    ap.add_argument("--only", default="", help="comma-separated mutant ids to run (same seed)")
    ap.add_argument("--print", dest="show", type=int, default=None, help="print mutant ID and exit")
    ap.add_argument("--min-reached", type=float, default=0.5)
    ap.add_argument("--configs", default="configs/**/*.yaml",
                    help="the configs to mutate, a glob under the root (e.g. 'configs/linkage/*.yaml')")
    a = ap.parse_args()

    binary = os.path.abspath(a.binary)
    files = sorted(glob.glob(os.path.join(ROOT, a.configs), recursive=True))
    if not files:
        sys.exit("fuzz_configs: no configs match %s" % a.configs)
    bases = {}
    for path in files:
        with open(path) as f:
            data = yaml.safe_load(f)
        # A shipped DOE of 10^6 designs would spend the fuzzer's time evaluating,
        # not parsing: its mutants start from the first BASE_SAMPLES samples.
        study = data.get("study") or {}
        if isinstance(study.get("samples"), int) and study["samples"] > BASE_SAMPLES:
            study["samples"] = BASE_SAMPLES
        # The mutant is written in a work directory: the files a config names
        # relative to itself (a points file, a linked config) are named
        # absolutely, so that a mutant reaches its evaluation.
        absolute_paths(data, os.path.dirname(path))
        bases[os.path.relpath(path, os.path.join(ROOT, "configs"))] = data
    listing = subprocess.run([binary, "list"], capture_output=True, text=True, check=True).stdout
    algorithms = re.search(r"nlopt:(.*)", listing).group(1).split()
    ctx = context(bases, algorithms)
    if a.show is not None:
        base, text, what = make_mutant(a.seed, a.show, bases, ctx)
        print(f"# mutant {a.show} (seed {a.seed}) of configs/{base}\n" + "".join(f"# {w}\n" for w in what) + text)
        return 0
    ids = [int(x) for x in a.only.split(",") if x] or list(range(a.n))
    shutil.rmtree(a.out, ignore_errors=True)
    os.makedirs(a.out)
    jobs = [(i, *make_mutant(a.seed, i, bases, ctx), binary, a.timeout, a.out) for i in ids]
    t0 = time.time()
    with multiprocessing.Pool(max(1, a.jobs)) as pool:
        results = sorted(pool.imap_unordered(run_mutant, jobs), key=lambda r: r["id"])
    seconds = time.time() - t0

    failed = [r for r in results if r["failures"]]
    reached = sum(r["reached"] for r in results)
    classes = collections.defaultdict(list)
    for r in failed:
        for c in sorted({c for c, _ in r["failures"]}):
            classes[c].append(r)
    n = len(results)
    print(f"fuzz_configs: {n} mutants of {len(bases)} configs, seed {a.seed}, {a.jobs} workers, "
          f"{seconds:.0f} s")
    print(f"  pass {n - len(failed)}/{n} ({100 * (n - len(failed)) / n:.1f}%), fail {len(failed)}")
    print(f"  reached evaluation {reached}/{n} ({100 * reached / n:.1f}%; gate >= {100 * a.min_reached:.0f}%)")
    codes = collections.Counter("hang" if r["run_hang"] else "signal" if r["run_signal"] else r["run_exit"]
                                for r in results)
    print("  run exit codes: " + ", ".join(f"{k}: {v}" for k, v in sorted(codes.items(), key=str)))
    if classes:
        print("failures by class (mutant ids; each kept in " + a.out + "/ID):")
        for c, rs in sorted(classes.items(), key=lambda kv: -len(kv[1])):
            print(f"  {len(rs):4d}  {c}: " + " ".join(str(r["id"]) for r in rs[:12]) + (" ..." if len(rs) > 12 else ""))
            example = rs[0]
            detail = next(d for cc, d in example["failures"] if cc == c)
            print(f"        e.g. {example['id']} ({example['base']}; {'; '.join(example['mutations'])}): {detail}")
    with open(os.path.join(a.out, "summary.json"), "w") as f:
        json.dump({"mutants": n, "seed": a.seed, "seconds": seconds, "passed": n - len(failed),
                   "reached": reached, "classes": {c: [r["id"] for r in rs] for c, rs in classes.items()},
                   "results": results}, f, indent=1)
    ok = not failed and reached >= a.min_reached * n
    if reached < a.min_reached * n:
        print(f"fuzz_configs: FAIL: only {reached} of {n} mutants reached an evaluation")
    print(f"fuzz_configs: {'PASS' if ok else 'FAIL'} (details: {a.out}/summary.json; "
          f"one mutant: tools/fuzz_configs.py --seed {a.seed} --print ID)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
