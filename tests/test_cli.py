"""The command line: JSON contracts of DESIGN.md, one-line errors with non-zero exit codes."""

from __future__ import annotations

import json

import numpy as np
import pytest

import plateqp as pq
from plateqp import scenes
from plateqp.cli import main

SLAB_W = 0.0040624  # Timoshenko: SS square, uniform load, centre w × q a⁴/D


def run_cli(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


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
    assert code == 4 and "lemke" in err


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
