"""mechopt.run, mechopt.optimize and mechopt.open_store against the command
line: the same result.json, the same rows as `mechopt export`, the
readers' union of a store and its segments, Ctrl-C during a run."""
import io
import json
import os
import shutil
import signal
import sqlite3
import subprocess
import threading

import numpy as np
import pandas as pd
import pytest

import mechopt

from common import BINARY, TWIN

DOE = """problem: recuperative_drive
model: {crank_speed: 100 rpm, cart_mass: 1000 kg, rod_mass_per_length: 80 kg/m, efficiency: 0.9,
        cart_resistance: 3562 N, resistance: opposes_motion}
objective: {minimize: k1}
study:
  type: doe
  sampler: sobol
  samples: 300
  factors:
    rod_length: {min: 0.15 m, max: 1.6 m}
    phase_shift: {min: 0 deg, max: 180 deg}
  columns: [k1, mean_kinetic_energy, peak_crank_torque]
"""


def cli(*args):
    return subprocess.run([BINARY, *args], check=True, capture_output=True, text=True).stdout


def without_paths(result):
    """result.json without what names its directory or the time it took."""
    return {k: v for k, v in result.items() if k not in ("history", "charts", "wall_seconds")}


def test_run_returns_the_result_json_of_mechopt_run(tmp_path):
    got = mechopt.run(TWIN, output=tmp_path / "py", quiet=True)
    cli("run", TWIN, "--output", str(tmp_path / "cli"))
    with open(tmp_path / "cli" / "result.json") as f:
        expected = json.load(f)
    assert got["status"] == "converged" and got["run_status"] == "complete"
    assert without_paths(got) == without_paths(expected)
    with open(tmp_path / "py" / "result.json") as f:
        assert json.load(f) == got


def test_optimize_runs_the_same_study_from_python_data():
    p = mechopt.Problem(config=TWIN)
    got = mechopt.optimize(p, "mean_kinetic_energy",
                           driver={"library": "nlopt", "algorithm": "LD_SLSQP", "xtol_rel": 1e-12})
    expected = mechopt.run(TWIN, output=None, quiet=True)  # the config's own study: the same
    assert got["status"] == expected["status"] == "converged"
    assert got["variables"] == expected["variables"] and got["metrics"] == expected["metrics"]
    bounded = mechopt.optimize(p, {"minimize": "mean_kinetic_energy"},
                               constraints={"peak_crank_torque": {"max": "2600 N m"}})
    assert bounded["metrics"]["peak_crank_torque"] <= 2600 * (1 + 1e-6)
    with pytest.raises(mechopt.ConfigError, match="<mechopt.optimize>.*objective"):
        mechopt.optimize(p, "no_such_metric")


def doe_store(tmp_path):
    config = tmp_path / "doe.yaml"
    config.write_text(DOE)
    result = mechopt.run(str(config), output=tmp_path / "doe", threads=2, quiet=True)
    assert result["run_status"] == "complete"
    return config, tmp_path / "doe"


def test_open_store_reads_the_rows_of_mechopt_export(tmp_path):
    config, out = doe_store(tmp_path)
    df = mechopt.open_store(out)
    assert len(df) == 300 and list(df["idx"]) == list(range(300))
    csv = pd.read_csv(io.StringIO(cli("export", str(out / "store.sqlite"), "--canonical")),  # %.17g: exact
                      float_precision="round_trip")
    assert set(df.columns) == set(csv.columns) | {"wall_time"}
    for c in ("rod_length", "phase_shift", "k1", "mean_kinetic_energy", "peak_crank_torque"):
        assert np.array_equal(df[c].to_numpy(float), csv[c].to_numpy(float), equal_nan=True), c
    assert (df["status"] == csv["status"]).all()
    assert set(df["status"]) >= {"ok", "cannot_assemble"}
    units = df.attrs["units"]
    assert (units["rod_length"], units["phase_shift"], units["mean_kinetic_energy"], units["k1"]) == \
        ("m", "rad", "J", "")
    assert df.attrs["meta"]["problem"] == "recuperative_drive"


def test_open_store_takes_a_running_doe_s_segments_each_index_once(tmp_path):
    """A store and a segment as a running DOE leaves them: rows 0-199 in the
    store, 150-299 in a segment not yet folded (150-199 in both, as a fold
    killed between its commit and the segment's removal leaves them)."""
    _, out = doe_store(tmp_path)
    store = out / "store.sqlite"
    full = mechopt.open_store(out)
    segment = out / "store.seg-r00000-t0001-p000000.sqlite"
    shutil.copy(store, segment)
    with sqlite3.connect(segment) as db:
        db.execute("DELETE FROM samples WHERE idx < 150")
        db.execute("UPDATE samples SET wall_time = -1 WHERE idx < 200")
    with sqlite3.connect(store) as db:
        db.execute("DELETE FROM samples WHERE idx >= 200")
    df = mechopt.open_store(store)
    assert list(df["idx"]) == list(range(300))
    assert (df["wall_time"] >= 0).all()  # the store's copy of 150-199
    cols = [c for c in full.columns if c != "wall_time"]
    assert full[cols].equals(df[cols])
    other = out / "store.seg-r00000-t0002-p000000.sqlite"  # a segment of another run is refused
    shutil.copy(segment, other)
    with sqlite3.connect(other) as db:
        db.execute("UPDATE meta SET value = 'x' WHERE key = 'config_hash'")
    with pytest.raises(ValueError, match="another run"):
        mechopt.open_store(out)


def test_open_store_while_a_doe_writes_it(tmp_path):
    config = tmp_path / "big.yaml"
    config.write_text(DOE.replace("samples: 300", "samples: 400000"))
    out = tmp_path / "big"
    run = subprocess.Popen([BINARY, "run", str(config), "--output", str(out), "--threads", "2",
                            "--progress", "none"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        seen = []
        while run.poll() is None and len(seen) < 20:
            try:
                df = mechopt.open_store(out)
            except (FileNotFoundError, ValueError):  # not created yet, or no samples table yet
                continue
            assert df["idx"].is_unique
            seen.append(len(df))
        assert seen and seen == sorted(seen)
    finally:
        run.send_signal(signal.SIGINT)
        run.wait()
    df = mechopt.open_store(out)  # every row the stopped run committed
    assert df["idx"].is_unique and len(df) >= seen[-1]


def test_ctrl_c_stops_a_run_which_keeps_what_it_did(tmp_path):
    config = tmp_path / "sweep.yaml"
    config.write_text("""problem: recuperative_drive
model: {cycle_points: 20000}
variables: {rod_length: {min: 0.5 m, max: 1.5 m}}
objective: {minimize: k1}
study: {type: sweep, grid: {rod_length: {from: 0.5 m, to: 1.49999 m, step: 5e-5 m}}}
""")
    timer = threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        mechopt.run(str(config), output=tmp_path / "sweep", threads=2, quiet=True)
    timer.join()
    with open(tmp_path / "sweep" / "result.json") as f:
        assert json.load(f)["run_status"] == "interrupted"
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
