"""mechopt from Python: the problems of the command line, evaluated in C++.

    import mechopt
    p = mechopt.Problem(config="configs/recuperative_drive/rod_length.yaml")
    r = p.evaluate(X)          # X: (n, k) designs over p.variables
    r["mean_kinetic_energy"]   # one float64 array per metric, NaN where not ok
    r["status"]                # each design's status name ("ok", "cannot_assemble", ...)

docs/python.md is the reference.
"""
import glob
import json
import os
import sqlite3
import tempfile
import warnings

import numpy as np

from . import _core
from ._core import STATUS, ConfigError

__version__ = _core.__version__
__all__ = ["ConfigError", "Problem", "STATUS", "open_store", "optimize", "problems", "run"]


def problems():
    """Every registered problem: a list of dicts with its name, summary and
    parameters (the model table: name, unit, domain, default, doc, equation,
    choices, variable)."""
    return _core.registry()


class Problem:
    """A problem as a config makes it: Problem("slider_crank", model={...},
    variables={...}), or Problem(config="file.yaml") with model and
    variables laid over the file's (map by map, as a config's keys over its
    base). Values may carry units as in YAML: {"rod_length": "0.8 m"}."""

    def __init__(self, name=None, model=None, variables=None, config=None):
        if (name is None) == (config is None):
            raise TypeError("Problem: give a problem name or config=FILE (one of them)")
        over = {}
        if name is not None:
            over["problem"] = name
        if model is not None:
            over["model"] = model
        if variables is not None:
            over["variables"] = variables
        self._args = (name, model, variables, None if config is None else os.path.abspath(config))
        text = json.dumps(over, indent=2) if (over or config is None) else ""
        origin = "<mechopt.Problem(%s)>" % ("config=" + os.fspath(config) if config is not None else repr(name))
        self._p = _core.Problem(text, origin, self._args[3] or "")

    def __reduce__(self):  # pickled as what made it (a config by its absolute path)
        return (Problem, self._args)

    def __repr__(self):
        return "mechopt.Problem(%r, variables=%s)" % (self.name, [v["name"] for v in self.variables])

    @property
    def name(self):
        return self._p.name

    @property
    def metrics(self):
        """Every metric's name, in the problem's order."""
        return self._p.metrics

    @property
    def units(self):
        """Each metric's SI unit ("" for a ratio)."""
        return self._p.units

    @property
    def variables(self):
        """The design variables, X's columns: name, unit, lower, upper, initial (SI)."""
        return self._p.variables

    @property
    def initial(self):
        """The variables' initial values as the config writes them (what `mechopt eval` evaluates)."""
        return self._p.initial

    @property
    def parameters(self):
        """The model's parameter table (as problems() gives it, for this config)."""
        return self._p.parameters

    @property
    def settings(self):
        """Fidelity, numerical settings and fixed model values, as result.json records them."""
        return json.loads(self._p.settings_json)

    def evaluate(self, X, metrics=None, gradient=False, threads=0):
        """Evaluates the designs in X's rows (an (n, k) array over
        self.variables; one design may be a (k,) array) over `threads`
        threads (0: every core), without the GIL. Returns a dict: one float64
        array of n per metric (NaN where the design's status is not ok),
        with gradient=True a (n, k) array "d<metric>" per metric, "status"
        (each design's status name) and "message" (a list, "" where ok).
        metrics: names (default: every metric). Ctrl-C stops the batch and
        raises KeyboardInterrupt."""
        r = self._p.evaluate(X, list(metrics or []), bool(gradient), int(threads))
        r["status"] = np.array(STATUS, dtype=object)[r["status"]]
        return r


def run(config, output=None, threads=0, model=None, variables=None, quiet=False):
    """Runs a config's study as `mechopt run` does (an optimisation, a sweep,
    a pareto front or a DOE into OUTPUT/store.sqlite), into `output` (default:
    the config's output.directory), with model and variables laid over the
    config's; its lines go to stdout unless quiet. Returns result.json's
    content. Ctrl-C stops it: what was done is written, marked interrupted,
    and KeyboardInterrupt is raised."""
    p = Problem(config=config, model=model, variables=variables)
    return json.loads(p._p.run("", "", "" if output is None else os.fspath(output), int(threads), bool(quiet)))


def optimize(problem, objective, constraints=None, driver=None, output=None, quiet=True):
    """One optimisation of `problem` (its variables, from their initial
    values) as an optimize study runs it: objective "metric" (minimised),
    {"minimize": metric} or {"maximize": metric}; constraints {metric:
    {"max": v}, ...} (values with units as in YAML); driver as a config's
    study.driver (default: the problem's default algorithm). Writes the
    study's files into `output` (default: a temporary directory, removed
    after) and returns result.json's content: "variables" (the design
    found), "metrics" (its metrics), "status", "message", "evaluations"."""
    study = {"objective": {"minimize": objective} if isinstance(objective, str) else objective,
             "study": {"type": "optimize"}}
    if constraints:
        study["constraints"] = constraints
    if driver:
        study["study"]["driver"] = driver
    text = json.dumps(study, indent=2)
    if output is not None:
        return json.loads(problem._p.run(text, "<mechopt.optimize>", os.fspath(output), 0, bool(quiet)))
    with tempfile.TemporaryDirectory(prefix="mechopt-") as d:
        return json.loads(problem._p.run(text, "<mechopt.optimize>", d, 0, bool(quiet)))


def _read_rows(file):
    """A store file's samples and meta, read-only; None where the file is gone."""
    try:
        db = sqlite3.connect("file:%s?mode=ro" % file, uri=True)
    except sqlite3.OperationalError:
        return None
    try:
        rows = db.execute("SELECT * FROM samples")
        names = [d[0] for d in rows.description]
        data = rows.fetchall()
        meta = dict(db.execute("SELECT key, value FROM meta").fetchall())
    except sqlite3.OperationalError:  # gone, or not a store (yet): no samples table
        return None
    finally:
        db.close()
    return names, data, meta


def open_store(path):
    """A DOE's store (DIR or DIR/store.sqlite) as a pandas DataFrame, one row
    per sample by index: the store file and the segments a running DOE
    writes beside it, each index once, everything committed so far (it
    reads a store another run is still writing). Columns as in the store
    (idx, status, wall_time, message, the factors, the metrics; the rows'
    checksums left out); df.attrs["units"] gives each column's SI unit and
    df.attrs["meta"] the store's meta (config, problem, sampler, seed, ...)."""
    import pandas as pd

    file = os.fspath(path)
    if os.path.isdir(file):
        file = os.path.join(file, "store.sqlite")
    if not os.path.exists(file):
        raise FileNotFoundError("no DOE store at %s" % file)
    stem = os.path.splitext(file)[0]
    # The segments first, then the store: rows a fold moves meanwhile are in
    # the store's snapshot, read after (the readers' rule, docs/doe.md).
    segments = sorted(glob.glob(glob.escape(stem) + ".seg-*.sqlite"))
    parts = [_read_rows(f) for f in segments]
    store = _read_rows(file)
    if store is None:
        raise ValueError("%s is not a mechopt store (no samples table)" % file)
    names, _, meta = store
    frames = [pd.DataFrame.from_records(store[1], columns=names)]
    for f, part in zip(segments, parts):
        if part is None:  # folded since it was listed: its rows are in the store's snapshot
            continue
        if part[2].get("config_hash") != meta.get("config_hash") or part[0] != names:
            raise ValueError("%s is a segment of another run than %s (config_hash %s against %s)"
                             % (f, file, part[2].get("config_hash"), meta.get("config_hash")))
        frames.append(pd.DataFrame.from_records(part[1], columns=names))
    df = pd.concat(frames, ignore_index=True).drop_duplicates("idx", keep="first")  # the store's copy kept
    df = df.drop(columns="checksum").sort_values("idx").reset_index(drop=True)
    df.attrs["meta"] = meta
    df.attrs["units"] = _store_units(meta, file, df.columns)
    return df


def _store_units(meta, file, columns):
    """Each column's SI unit, from the problem the store's config makes."""
    units = {"idx": "", "status": "", "wall_time": "s", "message": ""}
    try:
        p = _core.Problem(meta["config"], file, "")
    except (KeyError, ConfigError) as e:  # a store without its config, or one that no longer loads
        warnings.warn("%s: the columns' units are unknown (%s)" % (file, e))
        p = None
    if p is not None:
        units.update({q["name"]: q["unit"] for q in p.parameters})
        units.update({v["name"]: v["unit"] for v in p.variables})
        units.update(p.units)
    return {c: units.get(c) for c in columns}
