"""The Python module against the command line: the same problems, the same
bits as `mechopt eval`, threads, errors, pickling, Ctrl-C. Run by ctest
(python.module) with PYTHONPATH=build/python, MECHOPT_SOURCE_DIR and
MECHOPT_BINARY set."""
import json
import math
import os
import pickle
import signal
import subprocess
import threading
import time
from concurrent.futures import ProcessPoolExecutor
import multiprocessing

import numpy as np
import pytest

import mechopt

from common import SOURCE, BINARY, TWIN, CONVEYOR


def cli_eval(config, sets=()):
    """`mechopt eval` as JSON: the independent path to the same numbers."""
    args = [BINARY, "eval", config]
    for key, value in sets:
        args += ["--set", "%s=%s" % (key, value)]
    return json.loads(subprocess.run(args, check=True, capture_output=True, text=True).stdout)


def test_problems_lists_the_registry_with_units():
    listed = {p["name"]: p for p in mechopt.problems()}
    for name in ("recuperative_drive", "conveyor_swing", "slider_crank", "linkage"):
        assert name in listed
    rod = {q["name"]: q for q in listed["recuperative_drive"]["parameters"]}["rod_length"]
    assert rod["unit"] == "m" and rod["variable"] and rod["default"] > 0


def test_problem_from_config_describes_itself():
    p = mechopt.Problem(config=TWIN)
    assert p.name == "recuperative_drive"
    assert [v["name"] for v in p.variables] == ["rod_length"]
    v = p.variables[0]
    assert (v["unit"], v["lower"], v["upper"], v["initial"]) == ("m", 0.5, 1.5, 0.8)
    assert "mean_kinetic_energy" in p.metrics and p.units["mean_kinetic_energy"] == "J"
    assert p.settings["model"]["layout"] == "opposed"
    assert {q["name"] for q in p.parameters} >= {"rod_length", "crank_radius", "layout"}


@pytest.mark.parametrize("config", [TWIN, CONVEYOR])
def test_initial_design_has_the_bits_of_mechopt_eval(config):
    p = mechopt.Problem(config=config)
    r = p.evaluate(p.initial)
    cli = cli_eval(config)
    assert r["status"][0] == cli["status"] == "ok"
    assert set(cli["metrics"]) <= set(p.metrics)
    for name, value in cli["metrics"].items():
        assert r[name][0] == value, name  # the same bits: JSON keeps a double's shortest round trip


def test_a_batch_over_threads_has_the_bits_of_mechopt_eval_per_design():
    p = mechopt.Problem(config=CONVEYOR)
    rng = np.random.default_rng(7)
    lo = np.array([v["lower"] for v in p.variables])
    hi = np.array([v["upper"] for v in p.variables])
    X = lo + (hi - lo) * rng.random((40, len(lo)))
    two = p.evaluate(X, threads=2)
    one = p.evaluate(X, threads=1)
    assert (two["status"] == one["status"]).all()
    for name in p.metrics:
        assert np.array_equal(two[name], one[name], equal_nan=True), name
    assert len(set(two["status"])) > 1  # the box holds feasible and infeasible designs alike
    names = [v["name"] for v in p.variables]
    for i in (0, 1, 2, int(np.argmax(two["status"] != "ok"))):
        cli = cli_eval(CONVEYOR, [(n, repr(x)) for n, x in zip(names, X[i])])
        assert two["status"][i] == cli["status"]
        if cli["status"] != "ok":
            assert two["message"][i] == cli.get("message", "")
            assert all(math.isnan(two[m][i]) for m in p.metrics if m not in cli["metrics"])
        for name, value in cli["metrics"].items():
            assert two[name][i] == value, (i, name)


def test_a_design_that_cannot_assemble_is_a_status_not_an_error():
    p = mechopt.Problem(config=TWIN, variables={"rod_length": {"min": "0.1 m", "max": "1.5 m"}})
    r = p.evaluate(np.array([[0.15], [0.8]]), metrics=["mean_kinetic_energy", "crank_rod_ratio"])
    assert list(r["status"]) == ["cannot_assemble", "ok"]
    assert math.isnan(r["mean_kinetic_energy"][0]) and r["mean_kinetic_energy"][1] > 0
    assert r["crank_rod_ratio"][0] == 0.2 / 0.15  # defined everywhere, as the drivers' constraint


def test_gradients_match_central_differences():
    p = mechopt.Problem(config=CONVEYOR)
    x = p.initial
    r = p.evaluate(x, metrics=["rms_drive_torque", "rocker_stroke"], gradient=True)
    assert r["drms_drive_torque"].shape == (1, len(x))
    for name in ("rms_drive_torque", "rocker_stroke"):
        for j in range(len(x)):
            h = 1e-6 * max(1.0, abs(x[j]))
            e = np.zeros(len(x))
            e[j] = h
            fd = (p.evaluate(x + e, metrics=[name])[name][0] - p.evaluate(x - e, metrics=[name])[name][0]) / (2 * h)
            assert r["d" + name][0, j] == pytest.approx(fd, rel=1e-6, abs=1e-6 * abs(r[name][0])), (name, j)


def test_model_values_from_a_dict_with_units():
    by_name = mechopt.Problem("recuperative_drive",
                              model={"crank_radius": "0.2 m", "crank_speed": "100 rpm", "cart_mass": "1000 kg",
                                     "rod_mass_per_length": "80 kg/m", "efficiency": 0.9,
                                     "cart_resistance": "3562 N", "phase_shift": "90 deg", "rod_length": "800 mm",
                                     "layout": "opposed"},
                              variables={"rod_length": {"min": "0.5 m", "max": "1.5 m"}})
    from_file = mechopt.Problem(config=TWIN)
    a, b = by_name.evaluate([0.8]), from_file.evaluate([0.8])
    for name in from_file.metrics:
        assert a[name][0] == b[name][0], name


def test_bad_input_raises_located_errors():
    with pytest.raises(mechopt.ConfigError, match="no_such_problem"):
        mechopt.Problem("no_such_problem")
    with pytest.raises(mechopt.ConfigError, match=r"model\.rod_length"):
        mechopt.Problem(config=TWIN, model={"rod_length": "-1 m"})
    with pytest.raises(ValueError):  # ConfigError is a ValueError
        mechopt.Problem(config=TWIN, model={"rod_lenght": "1 m"})
    with pytest.raises(mechopt.ConfigError, match="nowhere.yaml"):
        mechopt.Problem(config=os.path.join(SOURCE, "nowhere.yaml"))
    p = mechopt.Problem(config=CONVEYOR)
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        p.evaluate(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="unknown metric 'peak_torque'"):
        p.evaluate(p.initial, metrics=["peak_torque"])
    with pytest.raises(TypeError):
        mechopt.Problem()


def test_any_layout_of_x_gives_the_same_numbers():
    p = mechopt.Problem(config=CONVEYOR)
    X = np.stack([p.initial, p.initial * 1.01, p.initial * 0.99])
    c = p.evaluate(X)
    f = p.evaluate(np.asfortranarray(X))
    lists = p.evaluate(X.tolist())
    for name in p.metrics:
        assert np.array_equal(c[name], f[name], equal_nan=True)
        assert np.array_equal(c[name], lists[name], equal_nan=True)


def evaluate_in_worker(problem, x):
    return problem.evaluate(x)["mean_kinetic_energy"][0]


def test_a_problem_pickles_into_other_processes():
    p = mechopt.Problem(config=TWIN, model={"cart_mass": "1200 kg"})
    q = pickle.loads(pickle.dumps(p))
    assert q.evaluate([0.9])["mean_kinetic_energy"][0] == p.evaluate([0.9])["mean_kinetic_energy"][0]
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        got = list(pool.map(evaluate_in_worker, [p, p], [[0.7], [0.9]]))
    assert got == [p.evaluate([0.7])["mean_kinetic_energy"][0], p.evaluate([0.9])["mean_kinetic_energy"][0]]


def big_batch(p, n):
    return np.tile(p.initial, (n, 1)) * np.linspace(0.98, 1.02, n)[:, None]


def test_evaluate_releases_the_gil():
    p = mechopt.Problem(config=CONVEYOR)
    X = big_batch(p, 4000)
    done = threading.Event()
    ticks = []

    def run():
        p.evaluate(X, threads=1)
        done.set()

    t = threading.Thread(target=run)
    t.start()
    while not done.is_set():  # Python runs while the batch is evaluated
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    t.join()
    assert len(ticks) > 5


def test_ctrl_c_stops_a_batch_and_gives_python_its_handler_back():
    p = mechopt.Problem(config=CONVEYOR)
    X = big_batch(p, 200000)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        p.evaluate(X, threads=2)
    assert time.perf_counter() - t0 < 5  # stopped, not finished (the batch takes far longer)
    timer.join()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    with pytest.raises(KeyboardInterrupt):  # Python's own handler is back
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(1)
    assert p.evaluate(p.initial)["status"][0] == "ok"  # the stop request is cleared


def test_one_problem_serves_python_threads_at_once(tmp_path):
    """A Problem is shared: evaluate and run from several Python threads at
    once give what they give one at a time."""
    p = mechopt.Problem(config=CONVEYOR)
    X = big_batch(p, 300)
    alone = p.evaluate(X, threads=1)
    twin = mechopt.Problem(config=TWIN)
    ran_alone = twin._p.run("", "", str(tmp_path / "alone"), 1, True)
    results, runs, errors = [None] * 4, [None] * 2, []

    def evaluate(i):
        try:
            results[i] = p.evaluate(X, threads=1)
        except Exception as e:  # noqa: BLE001 (reported below)
            errors.append(e)

    def run(i):
        try:
            runs[i] = twin._p.run("", "", str(tmp_path / ("run%d" % i)), 1, True)
        except Exception as e:  # noqa: BLE001
            errors.append(e)

    threads = [threading.Thread(target=evaluate, args=(i,)) for i in range(4)]
    threads += [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    for r in results:
        for name in p.metrics:
            assert np.array_equal(r[name], alone[name], equal_nan=True), name
    for r in runs:
        a, b = json.loads(r), json.loads(ran_alone)
        assert a["variables"] == b["variables"] and a["metrics"] == b["metrics"]
