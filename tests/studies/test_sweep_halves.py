"""A sweep on the condensed method's kept factor (posts: pdas with the contact dofs last) pays, per
value after the first, at most two triangular halves of K's factor, and usually one: the value's
reactions are refined on the trailing unknowns alone (B u needs only them: a dense triangular
solve of the trailing block), so that the one backward half that gives the deflection is the
last. A gap or spring sweep's load is the one the factor solved before; a sweep of one load's
magnitude scales its first half instead of solving it again; a refinement step whose
stationarity residual is already rounding corrects the reactions alone (half a solve, not two
halves). Every value is the cold solve's, to rounding, and passes the KKT check."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.linalg import schur
from plateqp.model.paths import set_param
from plateqp.scenes.families import grid_elastic, grid_rigid
from plateqp.studies.sweep import sweep

pytestmark = pytest.mark.skipif(not pq.linalg.bindings(), reason="no CHOLMOD binding")

ACC = 1e-10

CASES = {
    "gap": (lambda: grid_rigid(24, 5), "supports.1.gap", [-1e-3, -5e-4, 0.0, 5e-4, 1e-3, 2e-3]),
    "load": (lambda: grid_rigid(24, 5), "loads.0.q", [5.0, 8.0, 12.0, 20.0, 30.0, 45.0]),
    "stiffness": (lambda: grid_elastic(24, 5), "supports.*.stiffness", [1e4, 3e4, 1e5, 3e5, 1e6, 3e6]),
}


@pytest.fixture
def halves(monkeypatch):
    """Counts the triangular halves of the Schur factor's solves (a whole solve is two)."""
    count = {"n": 0}
    forward, backward, whole = schur.SchurFactor.forward, schur.SchurFactor.backward, schur.SchurFactor.solve

    def fw(self, *a, **k):
        count["n"] += 1
        return forward(self, *a, **k)

    def bw(self, *a, **k):
        count["n"] += 1
        return backward(self, *a, **k)

    def sv(self, *a, **k):
        count["n"] += 2
        return whole(self, *a, **k)

    monkeypatch.setattr(schur.SchurFactor, "forward", fw)
    monkeypatch.setattr(schur.SchurFactor, "backward", bw)
    monkeypatch.setattr(schur.SchurFactor, "solve", sv)
    return count


def run(scene, path, values, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return sweep(scene, path, values, backend="pdas", accuracy=ACC, executor="serial", progress=False,
                     refine_breakpoints=False, **kw)


def halves_per_value(scene, path, values, first, halves):
    """The sweep of ``values`` (every row OPTIMAL) and its triangular halves of K's factor per
    value after the first ``first`` (those counted apart, in a sweep of their own)."""
    run(scene, path, values[:first])
    before = halves["n"]
    halves["n"] = 0
    res = run(scene, path, values)
    assert all(r["status"] == "optimal" for r in res.rows)
    return res, (halves["n"] - before) / (len(values) - first)


def assert_cold(scene, path, values, rows, rtol):
    """Each row's reactions those of a cold solve of its value, to ``rtol`` of the largest, and
    its contact set the same."""
    for v, row in zip(values, rows):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pq.PlateQPWarning)
            cold = pq.solve(set_param(scene, path, v), backend="pdas", accuracy=ACC)
        R, Rc = np.array(row["reactions"]), cold.reactions
        assert np.abs(R - Rc).max() <= rtol * np.abs(Rc).max(), f"{path} = {v}: reactions off the cold solve's"
        assert row["active"] == [bool(a) for a in cold.active]


@pytest.mark.parametrize("case", list(CASES))
def test_one_half_per_value_after_the_first(case, halves):
    """A gap or spring sweep from the second value on, a load sweep from the third (its loads
    span a plane, known once two are solved): one half per value (at most two, the bound a
    value may take with a refinement step, follows), and each value the cold solve's."""
    make, path, values = CASES[case]
    scene = make()
    res, per_value = halves_per_value(scene, path, values, 2 if case == "load" else 1, halves)
    assert per_value <= 1.0, f"{per_value} halves of K's factor per value after the first"
    assert_cold(scene, path, values, res.rows, 1e-9)


@pytest.mark.parametrize("case", list(CASES))
def test_each_value_is_the_cold_solve(case):
    make, path, values = CASES[case]
    scene = make()
    hot = run(scene, path, values)
    for v, row in zip(values, hot.rows):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pq.PlateQPWarning)
            cold = pq.solve(set_param(scene, path, v), backend="pdas", accuracy=ACC)
        assert row["status"] == "optimal" and row["kkt_worst"] <= ACC
        assert row["active"] == [bool(a) for a in cold.active]
        R, Rc = np.array(row["reactions"]), cold.reactions
        assert np.abs(R - Rc).max() <= 1e-10 * np.abs(Rc).max()
        assert row["w_max"] == pytest.approx(float(cold.to_dict()["w_max"]), rel=1e-10)


def test_exact_sweep_values_share_the_path_start_factor(halves, monkeypatch):
    """``sweep --exact``: the path's start solve keeps its factor in the model the values adapt,
    so every value, the first included, pays two halves at most."""
    from plateqp.studies import homotopy

    inner = homotopy.sweep

    def counted(*a, **k):
        halves["n"] = 0  # the values' solves alone, not the path's
        return inner(*a, **k)

    monkeypatch.setattr(homotopy, "sweep", counted)
    make, path, values = CASES["gap"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        res = homotopy.exact_sweep(make(), path, values, backend="pdas", accuracy=ACC, executor="serial",
                                   progress=False)
    assert all(r["status"] == "optimal" for r in res.rows)
    assert halves["n"] / len(values) <= 2.0, f"{halves['n'] / len(values)} halves of K's factor per value"
