"""sweep --exact (plateqp.studies.exact_sweep) factorises the plate once: the exact path's start
solve and the sweep's values share the model and its factorisation of K (the path's held systems
keep a factor of their own, :mod:`plateqp.studies.held`, at most one factorisation a piece); the
answers are those of cold solves and of the exact path followed on its own."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.linalg import cholmod
from plateqp.model.paths import set_param
from plateqp.scenes.families import grid_rigid
from plateqp.studies import exact_path, exact_sweep
from plateqp.studies.held import HeldFactor

CASES = {
    "condensed route": (lambda: grid_rigid(12, 3), "supports.1.gap", [-1e-3, 0.0, 1e-3, 2e-3]),
    "primal route": (lambda: grid_rigid(24, 12), "loads.0.q", [5.0, 10.0, 20.0]),
}


@pytest.fixture
def factorisations(monkeypatch):
    """[factorisations by the solves, by the path's held factors, the held factors' calls]"""
    count = [0, 0, 0]
    real, held_init, held_call = cholmod.Cholesky.factor, HeldFactor.__init__, HeldFactor.__call__
    of_held: list = []

    def counting(self, A):
        count[1 if any(self is c for c in of_held) else 0] += 1
        return real(self, A)

    def init(self, data):
        held_init(self, data)
        of_held.append(self.fac.chol)

    def call(self, *args):
        count[2] += 1
        return held_call(self, *args)

    monkeypatch.setattr(cholmod.Cholesky, "factor", counting)
    monkeypatch.setattr(HeldFactor, "__init__", init)
    monkeypatch.setattr(HeldFactor, "__call__", call)
    return count


@pytest.mark.parametrize("case", list(CASES))
def test_sweep_exact_factorises_k_once_and_answers_as_cold_solves(case, factorisations):
    make, path, values = CASES[case]
    scene = make()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        r = exact_sweep(scene, path, values, executor="serial", progress=False)
    assert factorisations[0] == 1, f"{factorisations[0]} factorisations of K for one K"
    assert 1 <= factorisations[1] <= factorisations[2], "more than one factorisation a held system"
    alone = exact_path(scene, path, values[0], values[-1])
    assert [b["at"] for b in r.exact.breakpoints] == pytest.approx([b["at"] for b in alone.breakpoints], rel=1e-12)
    assert [b["after"] for b in r.exact.breakpoints] == [b["after"] for b in alone.breakpoints]
    for v, row in zip(values, r.rows):
        assert row["status"] == "optimal" and row["kkt"]["ok"]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pq.PlateQPWarning)
            cold = pq.solve(set_param(scene, path, v))
        R = np.asarray(row["reactions"])
        assert np.abs(R - cold.reactions).max() <= 1e-10 * np.abs(cold.reactions).max(), v
        assert np.allclose(r.exact.reactions(v), R, rtol=0, atol=1e-8 * np.abs(R).max()), v
