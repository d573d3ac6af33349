"""mechopt from Python: the problems of the command line, evaluated in C++.

    import mechopt
    p = mechopt.Problem(config="configs/recuperative_drive/rod_length.yaml")
    r = p.evaluate(X)          # X: (n, k) designs over p.variables
    r["mean_kinetic_energy"]   # one float64 array per metric, NaN where not ok
    r["status"]                # each design's status name ("ok", "cannot_assemble", ...)

docs/python.md is the reference.
"""
import json
import os

import numpy as np

from . import _core
from ._core import STATUS, ConfigError

__version__ = _core.__version__
__all__ = ["ConfigError", "Problem", "STATUS", "problems"]


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
