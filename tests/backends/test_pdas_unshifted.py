"""pdas's sparse method without the proximal shift where every row is soft and the plate is held
(``driver._unshifted``): the factor is that of ``K + B_Aᵀ ρ_A⁻¹ B_A`` itself, so a set's step is
one solve, exact to rounding. The answers are those of an independent formulation (bpp on the
condensed LCP); a sweep of the bed's gap pays at most one solve per value after the first (the
shifted factor needed two: one for the set, one to refine away σ D u and the penalty's share of
each row), none once the values' right-hand sides span what was solved; and where the rows do not hold a floating plate the shifted method runs as before."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
import plateqp.backends.pdas as pdas_backend
from plateqp.backends.pdas import driver, factor
from plateqp.model.paths import set_param
from plateqp.studies.sweep import sweep
from study_scenes import bed

pytestmark = pytest.mark.skipif(not pq.linalg.bindings(), reason="no CHOLMOD binding")

GAPS = [0.003, 0.0035, 0.004, 0.0045, 0.005]


def quiet(fn, *a, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return fn(*a, **kw)


@pytest.fixture
def solves(monkeypatch):
    """The solves with the sparse method's factor, one count per call of the pdas backend."""
    per_call: list[int] = []
    real_solve, real_pdas = factor.SpringFactor.solve, pdas_backend.pdas

    def counted(self, *a, **k):
        per_call[-1] += 1
        return real_solve(self, *a, **k)

    def pdas(*a, **k):
        per_call.append(0)
        return real_pdas(*a, **k)

    monkeypatch.setattr(factor.SpringFactor, "solve", counted)
    monkeypatch.setattr(pdas_backend, "pdas", pdas)
    return per_call


def bump(depth: float) -> pq.Scene:
    """bed() with a round heave of the soil (radius 0.2 m at (0.3, 0.3)) instead of the plane:
    its depth moves the contact set."""
    sc = bed(24)
    sc.foundation = pq.Foundation(2.0e4, gap={"profile": "bump", "x": 0.3, "y": 0.3, "radius": 0.2, "depth": depth})
    sc.validate()
    return sc


DEPTHS = [0.0, 0.001, 0.002, 0.006, 0.01]
SWEEP = dict(backend="pdas", accuracy=1e-10, executor="serial", progress=False, refine_breakpoints=False)


def same_as_condensed(active, reactions, scene):
    """The contact set and reactions of bpp on the condensed LCP (an independent formulation,
    solved to 1e-8: its own residual floor is about 2e-10 here)."""
    ref = quiet(pq.solve, scene, backend="bpp", formulation="condensed", accuracy=1e-8)
    assert ref.status == pq.Status.OPTIMAL
    assert np.array_equal(np.asarray(active, dtype=bool), ref.active)
    assert np.abs(np.asarray(reactions) - ref.reactions).max() <= 1e-7 * np.abs(ref.reactions).max()


@pytest.mark.parametrize("depth", [0.0, 0.006])
def test_the_unshifted_answer_is_the_condensed_lcps(depth):
    res = quiet(pq.solve, bump(depth), backend="pdas", accuracy=1e-10)
    assert res.extras["shift"] == 0.0 and res.extras["hold_check"] == "rigid motions"
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert not res.active.all() and res.active.any()  # part of the plate lifts off
    same_as_condensed(res.active, res.reactions, bump(depth))
    assert res.reactions.sum() == pytest.approx(20.0 + 200.0, rel=1e-10)  # the load, on a free plate


def test_a_sweep_of_the_soils_heave_is_the_condensed_lcps():
    res = quiet(sweep, bump(0.0), "foundation.gap.depth", DEPTHS, **SWEEP)
    assert all(r["status"] == "optimal" and r["kkt_worst"] <= 1e-10 for r in res.rows)
    assert len({tuple(r["active"]) for r in res.rows}) > 1  # the heave moves the contact set
    for d, row in zip(DEPTHS, res.rows):
        same_as_condensed(row["active"], row["reactions"], bump(d))


def test_a_planar_gap_sweep_pays_no_solve_per_value_after_the_second(solves):
    """The benchmark's bed sweep (bench_sweep_reuse: the gap's slope): a planar gap moves a free
    plate rigidly, so every value has the first one's reactions (statics and kinematics: no
    strain changes), and its step, on the kept factor of that set, is the minimiser of
    f + Bᵀ W (g + t dg), the plate's move as a body taken first (sparse._body_motion): the
    plane's tilt is all body motion, the rest of the right-hand side the same at every value,
    so one solve at the second value, then none (SpringFactor.solve_in_span). (The reactions'
    balance along the plate's rigid motions may still want a correction: the three columns
    H⁻¹V, solved once on the kept factor, at the second value: one block solve more, then none.)"""
    scene = bed(24)
    res = quiet(sweep, scene, "foundation.gap.gx", GAPS, **SWEEP)
    assert all(r["status"] == "optimal" and r["kkt_worst"] <= 1e-10 for r in res.rows)
    assert len(solves) == len(GAPS)  # one solve of the problem a value
    # (the first is a cold solve)
    assert solves[1] <= 2 and solves[2:] == [0] * (len(GAPS) - 2), f"solves per value: {solves}"
    R0 = np.array(res.rows[0]["reactions"])
    for row in res.rows[1:]:
        assert row["active"] == res.rows[0]["active"]
        assert np.abs(np.array(row["reactions"]) - R0).max() <= 1e-9 * np.abs(R0).max()
    same_as_condensed(res.rows[-1]["active"], res.rows[-1]["reactions"], set_param(scene, "foundation.gap.gx", GAPS[-1]))


def test_rows_that_let_a_floating_plate_move_go_to_the_shifted_method():
    """A warm start of three collinear rows leaves the free plate a rigid turn: the unshifted
    matrix would be singular, so the shifted method solves it, from that start, as before."""
    scene = bed(12)
    cold = quiet(pq.solve, scene, backend="pdas", accuracy=1e-10)
    start = np.zeros(cold.active.size, dtype=bool)
    start[:3] = True  # three nodes of the first row of the mesh: on one line
    res = quiet(pq.solve, scene, backend="pdas", accuracy=1e-10, options={"active": start})
    assert "shift" not in res.extras
    assert res.status == pq.Status.OPTIMAL and np.array_equal(res.active, cold.active)
    assert np.abs(res.reactions - cold.reactions).max() <= 1e-9 * np.abs(cold.reactions).max()


def test_an_unshifted_run_that_does_not_end_held_is_solved_again_shifted(monkeypatch):
    """Where the final set is not found to hold the plate, the unshifted answer is not kept:
    the shifted method solves the problem from the same start (and its trace has no steps of
    the run given up)."""
    scene = bed(12)
    calls = {"n": 0}
    real = driver.rows_hold

    def holds_at_first_only(*a, **k):
        calls["n"] += 1
        return calls["n"] == 1 and real(*a, **k)

    monkeypatch.setattr(driver, "rows_hold", holds_at_first_only)
    res = quiet(pq.solve, scene, backend="pdas", accuracy=1e-10)
    monkeypatch.setattr(driver, "rows_hold", real)
    assert calls["n"] == 2 and "shift" not in res.extras
    assert res.status == pq.Status.OPTIMAL
    same_as_condensed(res.active, res.reactions, scene)
