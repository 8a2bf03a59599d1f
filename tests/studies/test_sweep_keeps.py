"""Sweeps keep what they solved and claim nothing about what they did not; the command line
asks no more of the machine than it has, and refuses what it cannot read or write at once.

References: the store file itself (its lines counted while the sweep runs), the rows a sweep
returns, the number of cores the operating system gives this process, and the scene's own
validation (E = 0 is not a plate).
"""

from __future__ import annotations

import concurrent.futures as cf
import importlib
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

import plateqp as pq
from plateqp.studies import SweepInterrupted, sweep
from io_reference import run_cli

sweep_mod = importlib.import_module("plateqp.studies.sweep")
worker_mod = importlib.import_module("plateqp.studies.worker")


def small():
    return pq.Scene(name="small", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(4, 4),
                    edges={"left": "simple", "right": "simple"}, loads=[pq.UniformLoad(q=1.0)],
                    supports=[pq.Support(0.5, 0.5, gap=0.0), pq.Support(0.25, 0.25, gap=0.0)])


def scene_file(tmp_path) -> Path:
    f = tmp_path / "small.toml"
    small().to_toml(f)
    return f




def stored(path: Path) -> int:
    """Rows in a store file (lines after the header)."""
    try:
        return max(0, len(path.read_text().splitlines()) - 1)
    except OSError:
        return 0


# -- every row stored as it is solved, whatever the executor -------------------------------------

def test_each_row_is_stored_before_the_next_values_are_solved_on_a_users_executor(tmp_path, monkeypatch):
    store = tmp_path / "rows.jsonl"
    real = worker_mod.solve_value
    seen = []

    def solve_and_wait(ctx, value, warm=None):
        k = len(seen)
        deadline = time.monotonic() + 10.0
        while stored(store) < k and time.monotonic() < deadline:  # the rows solved before this one
            time.sleep(0.01)
        seen.append(stored(store))
        return real(ctx, value, warm)

    monkeypatch.setattr(worker_mod, "solve_value", solve_and_wait)
    values = [0.0001 * k for k in range(12)]
    with cf.ThreadPoolExecutor(max_workers=1) as ex:
        res = sweep(small(), "supports.1.gap", values, executor=ex, progress=False, refine_breakpoints=False,
                    store=store)
    assert len(res.rows) == 12 and stored(store) == 12
    assert seen == list(range(12)), "rows reached the store only when a chunk of values returned"


def test_an_interrupted_sweep_claims_nothing_about_rows_it_lacks(monkeypatch):
    real = sweep_mod.solve_value
    calls = []

    def stop_first(ctx, value, warm=None):
        if not calls:
            calls.append(value)
            raise KeyboardInterrupt
        return real(ctx, value, warm)

    monkeypatch.setattr(sweep_mod, "solve_value", stop_first)
    values = [0.0001 * k for k in range(2000)]
    with pytest.raises(SweepInterrupted) as info:
        sweep(small(), "supports.1.gap", values, executor="serial", progress=False)
    text = str(info.value.result)
    assert "the same for every value" not in text
    assert "not searched" in text or "interrupted" in text.splitlines()[-1]
    assert all(len(line) < 300 for line in text.splitlines()), "the table dumps the values not done"


def test_a_failed_value_is_not_counted_as_the_same_contact_set(monkeypatch):
    res = sweep(small(), "supports.1.gap", [0.0, 0.0001], executor="serial", progress=False)
    res.rows[1] = {**res.rows[1], "status": "error", "error": "RuntimeError: x", "active": None,
                   "reactions": None}
    res.breakpoints = []
    assert "the same for every value\n" not in str(res) + "\n"


# -- sweep --out: the format follows the extension ------------------------------------------------

@pytest.mark.parametrize("name", ["rows.zarr", "rows.csv", "rows"])
def test_sweep_out_that_is_not_netcdf_is_refused_before_any_work(capsys, tmp_path, name):
    pytest.importorskip("xarray")
    code, _, err = run_cli(capsys, "sweep", scene_file(tmp_path), "--param", "supports.1.gap", "--values",
                           "0,0.001", "--workers", "1", "--out", tmp_path / name)
    assert code == 2 and err.count("\n") == 1 and "netCDF" in err, err
    assert not (tmp_path / name).exists()


# -- sweep --range over invalid values ------------------------------------------------------------

@pytest.mark.parametrize("argv", [["--param", "plate.E", "--range", "1e7:0:3"],
                                  ["--param", "plate.h", "--values", "0.02,0.01,-0.01"],
                                  ["--param", "supports.*.stiffness", "--range", "1:-1:3"]])
def test_a_sweep_over_an_invalid_value_is_refused_before_any_solve(capsys, tmp_path, monkeypatch, argv):
    calls = []
    monkeypatch.setattr(sweep_mod, "solve_value", lambda *a, **k: calls.append(a) or (_ for _ in ()).throw(
        AssertionError("a value was solved")))
    code, _, err = run_cli(capsys, "sweep", scene_file(tmp_path), *argv, "--workers", "1")
    assert code == 2 and err.count("\n") == 1, err
    assert argv[1] in err and calls == []


# -- workers capped at the cores -----------------------------------------------------------------

def _record_workers(monkeypatch):
    asked = []
    real = sweep_mod.make_runner

    def record(executor, n, max_workers, payload):
        asked.append(max_workers)
        return real("serial", n, max_workers, payload)  # no processes started by the test

    monkeypatch.setattr(sweep_mod, "make_runner", record)
    return asked


def test_workers_are_capped_at_the_cores_unless_forced(capsys, tmp_path, monkeypatch):
    from plateqp.studies import parallel

    cores = parallel.available_cores()
    assert cores == (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count())
    asked = _record_workers(monkeypatch)
    argv = ["sweep", scene_file(tmp_path), "--param", "supports.1.gap", "--range", "0:0.001:8", "--no-refine"]
    code, _, err = run_cli(capsys, *argv, "--workers", str(cores + 30))
    assert code == 0, err
    assert asked == [cores] and "--force-workers" in err and err.count("\n") == 1
    code, _, err = run_cli(capsys, *argv, "--workers", str(cores + 30), "--force-workers")
    assert code == 0, err
    assert asked[-1] == cores + 30 and "core" in err and err.count("\n") == 1  # one warning line
    code, _, err = run_cli(capsys, *argv, "--workers", str(cores + 30), "--force-workers", "--quiet")
    assert code == 0 and err == ""
    code, _, err = run_cli(capsys, *argv, "--workers", "0")
    assert code == 2 and "--workers" in err


# -- special files as the scene ------------------------------------------------------------------

@pytest.mark.parametrize("command", ["solve", "sweep", "export", "regulate"])
def test_a_fifo_as_the_scene_is_refused_at_once(tmp_path, command):
    fifo = tmp_path / "scene.toml"
    os.mkfifo(fifo)
    extra = {"solve": [], "sweep": ["--param", "plate.h", "--values", "0.1"],
             "export": ["--out", str(tmp_path / "x.qps")], "regulate": ["--target", "1"]}[command]
    env = dict(os.environ, PYTHONPATH=str(Path(pq.__file__).parents[1]))
    try:
        p = subprocess.run([sys.executable, "-m", "plateqp.cli", command, str(fifo), *extra], capture_output=True,
                           text=True, timeout=60, env=env, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        pytest.fail("plateqp blocked on a FIFO given as the scene")
    assert p.returncode == 2 and p.stderr.count("\n") == 1 and "not a regular file" in p.stderr, p.stderr
