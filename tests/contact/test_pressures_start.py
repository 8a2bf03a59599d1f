"""The matrix-free half-space's start from the mesh with half the cells a side
(plateqp.contact.pressures.coarse_start): it changes the work, never the answer, and it is only
a start: the answer alone is checked (the coarser solve is not refined to the asked accuracy
nor checked itself), and a start that cannot be had leaves a cold solve."""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.contact import pressures
from plateqp.model import soil

from test_pressures import CASES, slab  # noqa: E402  (the same scenes)


@pytest.fixture
def started(monkeypatch):
    """Every half-space bed held matrix-free and started from the coarser mesh, however small."""
    monkeypatch.setattr(soil, "HALFSPACE_OPERATOR_FROM", 0)
    monkeypatch.setattr(pressures, "START_MIN", 50)


@pytest.mark.parametrize("name", list(CASES)[:2])  # (the third's 5 × 5 coarser mesh does not solve)
def test_a_started_solve_is_the_cold_one(name, started):
    scene = CASES[name]
    warm = pq.solve(scene, accuracy=1e-9)
    cold = pq.solve(scene, accuracy=1e-9, options={"x0": np.zeros(warm.model.contacts.m)})
    assert warm.extras["started"] == "given" and warm.status == cold.status == pq.Status.OPTIMAL
    scale = np.abs(cold.reactions).max()
    np.testing.assert_allclose(warm.reactions, cold.reactions, atol=1e-7 * scale)
    np.testing.assert_array_equal(warm.active, cold.active)


def test_the_start_is_not_checked_as_an_answer(started, monkeypatch):
    """One KKT check and one result per solve: the coarser mesh's forces are a start, solved to
    :data:`pressures.START_TOL` without the accurate product's refinement."""
    reports = []
    real = pressures.kkt_report

    def counted(*args, **kwargs):
        reports.append(args[0].m)
        return real(*args, **kwargs)
    monkeypatch.setattr(pressures, "kkt_report", counted)
    res = pq.solve(slab(n=20), accuracy=1e-9)
    assert res.status == pq.Status.OPTIMAL and res.extras["started"] == "given"
    assert reports == [res.model.contacts.m]


def test_a_start_without_its_coarser_mesh_leaves_a_cold_solve(started, monkeypatch):
    """The coarser mesh cannot be solved (here: its solver reports no convergence): no start,
    the same answer."""
    def fails(model, tol):
        return None
    monkeypatch.setattr(pressures, "_start_forces", fails)
    scene = slab(n=12)
    res = pq.solve(scene, accuracy=1e-9)
    assert res.status == pq.Status.OPTIMAL and res.extras["started"] == "cold"
