"""Progress bars and log messages (plateqp.progress, ``plateqp --quiet`` / ``--verbose``).

A bar is drawn only when standard error is a terminal (here: a StringIO that says it is one)
and not under CI=true; nothing reaches standard error otherwise. ``--json`` stays JSON alone
while a bar is drawn. ``--quiet`` leaves errors only, ``--verbose`` shows the library's INFO
(and with -vv DEBUG) messages. The library never configures the root logger.
"""

from __future__ import annotations

import io
import json
import logging
import os
import subprocess
import sys
from pathlib import Path

import pytest

import plateqp as pq
from plateqp import progress, scenes
from plateqp.cli import main
from plateqp.cli.common import _output
from plateqp.studies import sweep

ROOT = Path(__file__).resolve().parents[2]
SWEEP = ["sweep", "heave", "--param", "supports.2.gap", "--values", "-0.3,0.1", "--no-refine", "--workers", "1"]


class FakeTTY(io.StringIO):
    def isatty(self):
        return True


def as_tty(monkeypatch) -> FakeTTY:
    """Standard error as a terminal, outside CI (called in the test itself: pytest's capture
    sets sys.stderr again between a fixture's setup and the test)."""
    monkeypatch.delenv("CI", raising=False)
    fake = FakeTTY()
    monkeypatch.setattr(sys, "stderr", fake)
    return fake


@pytest.fixture(scope="module")
def heave():
    sc = pq.Scene.from_toml(scenes.path("heave"))
    sc.mesh.nx = sc.mesh.ny = 8
    return sc


def test_hidden_when_stderr_is_not_a_terminal(heave, capsys, monkeypatch):
    monkeypatch.delenv("CI", raising=False)
    assert not sys.stderr.isatty()  # pytest's capture
    with progress.Progress(3, "steps") as bar:
        bar.update(3)
    assert list(progress.track(range(4), "items")) == [0, 1, 2, 3]
    sweep(heave, "supports.2.gap", [-0.3, 0.1], executor="serial", refine_breakpoints=False)  # progress=True
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("has_tqdm", [True, False], ids=["tqdm", "counter"])
def test_shown_on_a_terminal(heave, monkeypatch, has_tqdm):
    tty = as_tty(monkeypatch)
    if not has_tqdm:
        monkeypatch.setitem(sys.modules, "tqdm", None)  # as if tqdm were not installed
    sweep(heave, "supports.2.gap", [-0.3, 0.1], executor="serial", refine_breakpoints=False)
    text = tty.getvalue()
    assert "sweep supports.2.gap" in text
    if not has_tqdm:
        assert "sweep supports.2.gap: 2/2" in text
        assert text.endswith("\r") and text.rsplit("\r", 2)[-2].strip() == ""  # the line is wiped at the end


def test_hidden_under_ci_and_when_turned_off(monkeypatch):
    tty = as_tty(monkeypatch)
    monkeypatch.setenv("CI", "true")
    with progress.Progress(2, "steps") as bar:
        bar.update(2)
    monkeypatch.delenv("CI")
    was = progress.set_enabled(False)
    try:
        with progress.Progress(2, "steps") as bar:
            bar.update(2)
        assert not progress.shown()
    finally:
        progress.set_enabled(was)
    assert tty.getvalue() == ""
    assert progress.shown() and not progress.shown(enabled=False)


def test_track_counts_and_closes(monkeypatch):
    tty = as_tty(monkeypatch)
    monkeypatch.setitem(sys.modules, "tqdm", None)
    for _ in progress.track(iter(range(3)), "things"):  # no len: a counter without an end
        pass
    assert "things: 3" in tty.getvalue() and not progress._OPEN


def test_json_stays_clean_while_a_bar_is_drawn(capsys, monkeypatch):
    tty = as_tty(monkeypatch)
    assert main(SWEEP + ["--json"]) == 0
    d = json.loads(capsys.readouterr().out)  # JSON alone on standard output
    assert [r["value"] for r in d["rows"]] == [-0.3, 0.1]
    assert sum(d["rows"][0]["reactions"]) == pytest.approx(62000.0, rel=1e-9)  # statics of the heave slab
    assert "sweep supports.2.gap" in tty.getvalue()  # the bar went to standard error


def _log_lines(quiet=False, verbose=0):
    err = io.StringIO()
    old = sys.stderr
    sys.stderr = err
    try:
        with _output(quiet, verbose):
            for level in (logging.DEBUG, logging.INFO, logging.WARNING, logging.ERROR):
                logging.getLogger("plateqp.somewhere").log(level, "message at %s", logging.getLevelName(level))
    finally:
        sys.stderr = old
    return err.getvalue()


def test_levels_of_quiet_default_and_verbose():
    quiet, default, v, vv = _log_lines(quiet=True), _log_lines(), _log_lines(verbose=1), _log_lines(verbose=2)
    assert "at ERROR" in quiet and "at WARNING" not in quiet
    assert "plateqp: message at WARNING" in default and "at INFO" not in default
    assert "at INFO" in v and "at DEBUG" not in v and "plateqp.somewhere" in v
    assert "at DEBUG" in vv
    top = logging.getLogger("plateqp")
    assert not top.handlers and top.level == logging.NOTSET  # restored


def test_cli_quiet_and_verbose_in_process(capsys):
    root = logging.getLogger()
    handlers = list(root.handlers)
    assert main(["--verbose"] + SWEEP) == 0
    err = capsys.readouterr().err
    assert "INFO plateqp.studies.sweep: sweep of supports.2.gap: 2 values" in err
    assert main(SWEEP + ["--quiet"]) == 0
    assert capsys.readouterr().err == ""
    assert main(SWEEP) == 0
    assert "INFO" not in capsys.readouterr().err
    assert root.handlers == handlers  # the root logger is the user's: never configured here
    with pytest.raises(SystemExit) as info:  # both: a usage error, as argparse gives
        main(["-q"] + SWEEP + ["-v"])
    assert info.value.code == 2 and "--quiet and --verbose" in capsys.readouterr().err


def test_cli_quiet_and_verbose_in_a_subprocess():
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    env.pop("CI", None)

    def run(*flags):
        r = subprocess.run([sys.executable, "-m", "plateqp.cli", *flags, *SWEEP, "--json"], capture_output=True,
                           text=True, env=env, timeout=300)
        assert r.returncode == 0, r.stderr
        json.loads(r.stdout)
        return r.stderr

    assert "INFO plateqp.studies.sweep: sweep of supports.2.gap" in run("-v")
    assert run("--quiet") == ""
    assert "INFO" not in run()


def test_the_library_never_configures_logging():
    for f in (ROOT / "plateqp").rglob("*.py"):
        text = f.read_text(encoding="utf-8")
        assert "basicConfig" not in text, f
        if f.parts[-2] != "cli":
            assert "addHandler" not in text and "logging.getLogger()" not in text, f


def _convergence(sc):
    from plateqp.studies import convergence

    convergence(sc, meshes=(4, 8))


def _exact(sc):
    from plateqp.studies import exact_path

    exact_path(sc, "supports.2.gap", -0.3, 0.1)


def _uniform(sc):
    from plateqp.studies import most_uniform_stiffness

    most_uniform_stiffness(sc, (1e3, 1e5), scan=3, xatol=0.5)


def _regulate(sc):
    assert main(["regulate", "heave", "--target", "2000", "--supports", "1,2"]) in (0, 5)


@pytest.mark.parametrize("run, line", [
    (_convergence, "meshes: 2/2"),
    (_exact, "exact path of supports.2.gap, % of the range: 100/100"),
    (_uniform, "most uniform stiffness: solves: 3"),
    (_regulate, "regulate: gaps, then the check: 2/2"),
], ids=["convergence", "exact-path", "uniform-stiffness", "regulate"])
def test_every_long_run_draws_a_bar_on_a_terminal(heave, monkeypatch, run, line):
    monkeypatch.setitem(sys.modules, "tqdm", None)  # the counter line: its text is deterministic
    tty = as_tty(monkeypatch)
    run(heave)
    assert line in tty.getvalue()
    assert not progress._OPEN  # closed at the end


def test_the_old_home_of_progress_still_imports():
    from plateqp.studies.parallel import Progress

    assert Progress is progress.Progress
