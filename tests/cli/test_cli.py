"""The command line: JSON contracts of DESIGN.md, one-line errors with non-zero exit codes."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

import plateqp as pq
from plateqp import scenes
from io_reference import run_cli

SLAB_W = 0.0040624  # Timoshenko: SS square, uniform load, centre w × q a⁴/D




def test_solve_json_two_sided(capsys):
    code, out, _ = run_cli(capsys, "solve", str(scenes.path("slab")), "--json", "--probe", "0.5,0.5")
    assert code == 0
    d = json.loads(out)
    for key in ("scene", "backend", "formulation", "accuracy", "status", "w_max", "w_max_x", "w_max_y",
                "probes", "reactions", "active", "gaps", "kkt", "times"):
        assert key in d
    sc = scenes.load("slab")
    q = sc.loads[0].q
    ref = SLAB_W * q * sc.plate.a**4 / sc.plate.D
    assert d["probes"][0]["w"] == pytest.approx(ref, rel=2e-3)
    assert (d["w_max_x"], d["w_max_y"]) == (0.5, 0.5)
    assert set(d["times"]) == {"build", "solve", "total"}


def test_solve_json_contact(capsys, tmp_path):
    code, out, _ = run_cli(capsys, "solve", str(scenes.path("heave")), "--backend", "lemke",
                           "--formulation", "condensed", "--accuracy", "high", "--json")
    assert code == 0
    d = json.loads(out)
    sc = scenes.load("heave")
    total = sum(ld.P for ld in sc.loads if ld.type == "point") + sum(
        ld.q * sc.plate.a * sc.plate.b for ld in sc.loads if ld.type == "uniform")
    assert sum(d["reactions"]) == pytest.approx(total, rel=1e-9)  # a floating plate: statics
    assert d["kkt"]["ok"] and d["status"] == "optimal"
    assert len(d["active"]) == len(d["gaps"]) == len(sc.supports)
    gaps, R = np.array(d["gaps"]), np.array(d["reactions"])
    assert np.all(gaps >= -1e-9 * np.abs(gaps).max()) and np.abs(gaps * R).max() < 1e-9 * np.abs(gaps).max() * R.max()


def test_backends_json(capsys):
    code, out, _ = run_cli(capsys, "backends", "--json")
    assert code == 0
    rows = json.loads(out)["backends"]
    lemke = next(r for r in rows if r["name"] == "lemke")
    assert lemke["installed"] and lemke["formulations"] == ["condensed", "dual"]
    assert all(set(r) == {"name", "formulations", "installed", "version"} for r in rows)


@pytest.mark.parametrize("text,needle,code", [
    ("[plate]\nh = -1.0\n", "plate.h", 2),
    ("[plate]\nthickness = 1.0\n", "plate.thickness", 2),
    ("[[loads]]\ntype = 'point'\nP = -5.0\nx = 0.5\ny = 0.5\n"
     "[[supports]]\nx = 0.0\ny = 0.0\n[[supports]]\nx = 1.0\ny = 0.0\n[[supports]]\nx = 0.0\ny = 1.0\n",
     "net uplift", 3),
])
def test_errors_are_one_line(capsys, tmp_path, text, needle, code):
    f = tmp_path / "bad.toml"
    f.write_text(text)
    got, out, err = run_cli(capsys, "solve", str(f), "--backend", "lemke")
    assert got == code
    assert needle in err and err.count("\n") == 1
    if code == 2:  # a scene error names the file too
        assert str(f) in err


def test_unknown_backend_exit_code(capsys):
    code, _, err = run_cli(capsys, "solve", str(scenes.path("heave")), "--backend", "nonesuch")
    assert code == 2 and "lemke" in err and err.count("\n") == 1  # bad input, one line naming what is there


def test_demo_writes_reports(capsys, tmp_path):
    code, out, _ = run_cli(capsys, "demo", "heave", "--out", str(tmp_path))
    assert code == 0 and "two-sided comparison" in out
    rep = json.loads((tmp_path / "heave.json").read_text())
    assert rep["one_sided"]["status"] == "optimal" and "two_sided" in rep


def test_lemke_trace_through_solve():
    sc = scenes.load("heave")
    res = pq.solve(sc, backend="lemke", formulation="condensed", options={"trace": True})
    trace = res.extras["trace"]
    assert len(trace) == res.iterations and trace[0]["entering"][0] == "z0"


# -- hostile input: one line on stderr, the right exit code, nothing written astray ------

SMALL = """\
name = {name}
[plate]
a = 1.0
b = 1.0
h = 0.02
E = 1.0e7
nu = 0.3
[mesh]
nx = 4
ny = 4
[edges]
left = "simple"
[[loads]]
type = "uniform"
q = 1.0
[[supports]]
x = 1.0
y = 0.0
gap = {gap}
[[supports]]
x = 1.0
y = 1.0
gap = {gap}
"""


def small(tmp_path, name='"small"', gap=0.0, file="s.toml"):
    path = tmp_path / file
    path.write_text(SMALL.format(name=name, gap=gap))
    return path


def one_line_error(code, err, expect_code=2):
    assert code == expect_code, err
    assert err.count("\n") == 1 and err.startswith("plateqp: ") and "Traceback" not in err, err


@pytest.mark.parametrize("name", ['"../../ESCAPED"', '"/tmp/plateqp-abs-ESCAPED"', '"a/b\\\\c"', '".hidden"'])
def test_scene_name_never_leaves_out(capsys, tmp_path, name):
    scene = small(tmp_path, name=name)
    out = tmp_path / "deep" / "out"
    code, _, err = run_cli(capsys, "solve", str(scene), "--out", str(out))
    assert code == 0, err
    written = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file())
    assert all(p.parts[:2] == ("deep", "out") or p.name == "s.toml" for p in written), written
    n_files = 4 if importlib.util.find_spec("meshio") else 2  # .json, -w.npy (.vtu, -supports.vtu)
    assert len(list(out.iterdir())) == n_files and not any(p.name.startswith(".") for p in out.iterdir())
    assert not (tmp_path / "ESCAPED.json").exists() and not Path("/tmp/plateqp-abs-ESCAPED.json").exists()


def test_out_is_checked_first_and_never_overwritten(capsys, tmp_path):
    scene = small(tmp_path)
    out = tmp_path / "out"
    assert run_cli(capsys, "solve", str(scene), "--out", str(out))[0] == 0
    before = (out / "small.json").read_bytes()
    code, _, err = run_cli(capsys, "solve", str(scene), "--out", str(out), "--accuracy", "high")
    one_line_error(code, err)
    assert "small.json exists" in err and "--force" in err and (out / "small.json").read_bytes() == before
    code, _, err = run_cli(capsys, "solve", str(scene), "--out", str(out), "--accuracy", "high", "--force")
    assert code == 0 and json.loads((out / "small.json").read_text())["accuracy"] == "high"
    code, _, err = run_cli(capsys, "solve", str(scene), "--out", str(scene))  # a file, not a folder
    one_line_error(code, err)
    assert "not a folder" in err
    code, _, err = run_cli(capsys, "solve", str(scene), "--out", str(scene / "sub"))  # under a file
    one_line_error(code, err)


@pytest.mark.parametrize("opts", ["{bad", "[1,2]", "1", '"x"'])
def test_bad_options_json(capsys, tmp_path, opts):
    code, _, err = run_cli(capsys, "solve", str(small(tmp_path)), "--options", opts)
    one_line_error(code, err)
    assert "--options" in err


@pytest.mark.parametrize("path", ["", ".", "/dev/zero"])
def test_scene_path_that_is_not_a_scene(capsys, path):
    code, _, err = run_cli(capsys, "solve", path)
    one_line_error(code, err)


def test_unbounded_sweep_is_refused(capsys, tmp_path):
    code, _, err = run_cli(capsys, "sweep", str(small(tmp_path)), "--param", "supports.1.gap", "--range", "0:1:1000000")
    one_line_error(code, err)
    assert "--max-values" in err


def test_memory_limit_flag(capsys, tmp_path):
    code, _, err = run_cli(capsys, "solve", str(small(tmp_path)), "--max-memory", "1K")
    one_line_error(code, err)
    assert "above the limit" in err
    code, _, err = run_cli(capsys, "solve", str(small(tmp_path)), "--max-memory", "lots")
    one_line_error(code, err)


def run_subprocess(*argv):
    """The command in a fresh process, so that what C libraries print on file descriptor 1 is seen."""
    import os
    import subprocess
    import sys
    from pathlib import Path as P

    env = dict(os.environ, PYTHONPATH=str(P(__file__).resolve().parents[2]))
    r = subprocess.run([sys.executable, "-m", "plateqp.cli", *argv], capture_output=True, text=True, env=env,
                       timeout=300)
    return r.returncode, r.stdout, r.stderr


@pytest.mark.parametrize("backend, gap", [("qpsolvers:highs", 0.0), ("cvxpy:HIGHS", 0.0), ("osqp", 1.0)])
def test_json_alone_on_stdout_whatever_the_solver_prints(tmp_path, backend, gap):
    """HiGHS prints its banner on stdout; OSQP prints "Polishing not needed" when nothing touches
    (gap 1.0: every support far below the plate)."""
    if backend not in pq.available_backends():
        pytest.skip(f"{backend} is not installed")
    code, out, err = run_subprocess("solve", str(small(tmp_path, gap=gap)), "--backend", backend,
                                    "--formulation", "primal", "--json")
    assert code in (0, 5), err
    d = json.loads(out)
    assert d["backend"] == backend


def test_negative_values_are_values_not_options(capsys):
    """``--values -0.2,0`` (a heave) is read as the values, not as an unknown option; the row at
    the scene's own gap is the scene's own solve."""
    code, out, err = run_cli(capsys, "sweep", "heave", "--param", "supports.2.gap", "--values", "-0.2,0",
                             "--no-refine", "--json")
    assert code == 0, err
    rows = json.loads(out)["rows"]
    assert [r["value"] for r in rows] == [-0.2, 0.0]
    ref = pq.solve(pq.Scene.from_toml(scenes.path("heave")))
    np.testing.assert_allclose(rows[0]["reactions"], ref.reactions, rtol=1e-9, atol=1e-9 * abs(ref.reactions).max())
    code, out, err = run_cli(capsys, "solve", "heave", "--probe", "-1,5")
    assert code == 2 and "--probe -1,5" in err and err.count("\n") == 1  # checked before any work


def test_probe_in_a_hole_is_refused_before_any_work(capsys, tmp_path):
    p = tmp_path / "disc.toml"
    p.write_text('name = "disc"\n[plate]\nshape = { circle = [0.0, 0.0, 1.0] }\nh = 0.02\nE = 1e7\nnu = 0.3\n'
                 '[mesh]\nelement = "dkt"\nsize = 0.25\n[edges]\nall = "simple"\n'
                 '[[holes]]\ncircle = [0.5, 0.0, 0.2]\n[[loads]]\ntype = "uniform"\nq = 1.0\n')
    code, out, err = run_cli(capsys, "solve", str(p), "--probe", "0.5,0.05", "--out", str(tmp_path / "o"))
    assert code == 2 and "--probe 0.5,0.05" in err and "hole" in err and out == ""
    assert not (tmp_path / "o").exists()  # nothing made: refused before the folder and the solve
