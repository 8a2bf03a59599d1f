"""Sweeps on disk: each row written as it is solved, a stopped sweep keeps its rows and resumes.

References: statics (every row's reactions sum to the total load of the floating heave slab,
62 000 kgf) and an independent sweep of the same values run without a store; the netCDF file is
read back with xarray, not with plateqp.
"""

from __future__ import annotations

import importlib
import json

import numpy as np
import pytest

import plateqp as pq
from plateqp import scenes
from plateqp.cli import main
from plateqp.errors import ProblemError
from plateqp.studies import SweepInterrupted, sweep

#: the module (``plateqp.studies.sweep`` the name is the function, re-exported by the package)
sweep_mod = importlib.import_module("plateqp.studies.sweep")

VALUES = [-0.3, -0.2, -0.1, 0.0, 0.1]
TOTAL = 62000.0


@pytest.fixture(scope="module")
def heave():
    sc = pq.Scene.from_toml(scenes.path("heave"))
    sc.mesh.nx = sc.mesh.ny = 8
    return sc


@pytest.fixture(scope="module")
def fresh(heave):
    return sweep(heave, "supports.2.gap", VALUES, executor="serial", progress=False)


def _stop_after(monkeypatch, k):
    """solve_value raises KeyboardInterrupt (a Ctrl-C) on its (k+1)-th call; returns the call log."""
    calls = []
    real = sweep_mod.solve_value

    def fake(ctx, value, start):
        if len(calls) == k:
            raise KeyboardInterrupt
        calls.append(value)
        return real(ctx, value, start)

    monkeypatch.setattr(sweep_mod, "solve_value", fake)
    return calls


def _stored_rows(path):
    lines = path.read_text().splitlines()
    return json.loads(lines[0]), [json.loads(x) for x in lines[1:]]


def test_a_stopped_sweep_keeps_its_rows_on_disk_and_resumes(heave, fresh, tmp_path, monkeypatch):
    store = tmp_path / "rows.jsonl"
    _stop_after(monkeypatch, 2)
    with pytest.raises(SweepInterrupted) as info:
        sweep(heave, "supports.2.gap", VALUES, executor="serial", progress=False, store=store)
    assert info.value.result.interrupted["done"] == 2
    header, recs = _stored_rows(store)
    assert header["values"] == VALUES and [r["index"] for r in recs] == [0, 1]
    monkeypatch.undo()
    calls = _stop_after(monkeypatch, 99)  # counts the solves of the resumed run
    res = sweep(heave, "supports.2.gap", VALUES, executor="serial", progress=False, store=store)
    assert calls == VALUES[2:]  # only the values the stopped run lacked
    assert [r["index"] for r in _stored_rows(store)[1]] == [0, 1, 2, 3, 4]
    for row, ref in zip(res.rows, fresh.rows):
        assert sum(row["reactions"]) == pytest.approx(TOTAL, rel=1e-9)  # statics
        np.testing.assert_allclose(row["reactions"], ref["reactions"], rtol=1e-9, atol=1e-9 * TOTAL)
        assert row["active"] == ref["active"]
    assert [b["between"] for b in res.breakpoints] == [b["between"] for b in fresh.breakpoints]


def test_a_store_of_another_sweep_is_refused(heave, tmp_path):
    store = tmp_path / "rows.jsonl"
    sweep(heave, "supports.2.gap", VALUES[:2], executor="serial", progress=False, store=store)
    before = store.read_text()
    with pytest.raises(ProblemError, match="holds another sweep .*values"):
        sweep(heave, "supports.2.gap", VALUES, executor="serial", progress=False, store=store)
    other = pq.Scene.from_toml(scenes.path("heave"))
    other.mesh.nx = other.mesh.ny = 4
    with pytest.raises(ProblemError, match="holds another sweep .*scene"):
        sweep(other, "supports.2.gap", VALUES[:2], executor="serial", progress=False, store=store)
    assert store.read_text() == before  # nothing mixed in
    (tmp_path / "junk.jsonl").write_text("not json\n")
    with pytest.raises(ProblemError, match="not a plateqp sweep store"):
        sweep(heave, "supports.2.gap", VALUES[:2], executor="serial", progress=False, store=tmp_path / "junk.jsonl")


def test_a_line_cut_by_a_crash_is_solved_again(heave, fresh, tmp_path, monkeypatch):
    store = tmp_path / "rows.jsonl"
    sweep(heave, "supports.2.gap", VALUES, executor="serial", progress=False, store=store)
    text = store.read_text()
    store.write_text(text[: len(text) - len(text.splitlines()[-1]) // 2 - 1])  # the last row half written
    calls = _stop_after(monkeypatch, 99)
    res = sweep(heave, "supports.2.gap", VALUES, executor="serial", progress=False, store=store)
    assert calls == [VALUES[-1]]
    assert [r["index"] for r in _stored_rows(store)[1]] == [0, 1, 2, 3, 4]  # the file is whole again
    np.testing.assert_allclose(res.rows[-1]["reactions"], fresh.rows[-1]["reactions"], rtol=1e-9,
                               atol=1e-9 * TOTAL)


def test_cli_store_and_netcdf(tmp_path, capsys):
    xr = pytest.importorskip("xarray")
    out, store = tmp_path / "s.nc", tmp_path / "s.jsonl"
    argv = ["sweep", "heave", "--param", "supports.2.gap", "--values", "-0.3,-0.1,0.1", "--no-refine",
            "--json", "--store", str(store), "--out", str(out)]
    assert main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    ds = xr.open_dataset(out, engine="scipy")
    np.testing.assert_allclose(ds["value"].values, [-0.3, -0.1, 0.1])
    np.testing.assert_allclose(ds["reactions"].values, [r["reactions"] for r in d["rows"]], rtol=1e-12)
    np.testing.assert_allclose(ds["reactions"].values.sum(axis=1), TOTAL, rtol=1e-9)  # statics
    assert list(ds["n_contact"].values) == [sum(r["active"]) for r in d["rows"]]
    ds.close()
    # --out is checked before any work: an existing file is refused (exit 2) unless --force
    assert main(argv) == 2
    assert "exists" in capsys.readouterr().err
    assert main(argv + ["--force"]) == 0  # every row from the store: nothing solved again
