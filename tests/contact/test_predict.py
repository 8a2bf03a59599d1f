"""A coarse mesh's contact set as pdas's first set (plateqp.contact.predict, option ``predict``),
and pdas's warm start on soft rows (the Newton phase's first factor).

External references: statics (the bed carries the column: Σ R = P, Σ R x = P x_P, Σ R y = P y_P),
the contact conditions themselves (R ≥ 0, gap ≥ 0, R·gap = 0), and an independent formulation
(the condensed LCP solved by bpp, a different method on a different problem). The prediction is
a start, never the answer: every test checks that a start known to be wrong ends at the same
answer as no start at all.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.scenes import families as F
from plateqp.model.assembly import build_model
from plateqp.contact import predict as P
from plateqp.errors import ProblemError

pytest.importorskip("cvxopt")  # the sparse method's factor on the default install


def solve(scene, **kw):
    kw.setdefault("accuracy", 1e-10)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene, **kw)


def assert_bed_statics(res):
    """The springs carry the column load exactly (F.bed has no other load or support)."""
    R, xy = res.reactions, res.model.contacts.xy
    np.testing.assert_allclose(R.sum(), F.P, rtol=1e-9)
    np.testing.assert_allclose(R @ xy[:, 0], F.P * F.PX, rtol=1e-9)
    np.testing.assert_allclose(R @ xy[:, 1], F.P * F.PY, rtol=1e-9)


def assert_contact(res):
    """R ≥ 0, gap ≥ 0 (a spring: its compression R ρ closes it), R · gap = 0, to rounding."""
    R, gap = res.reactions, res.gaps
    scale_g = np.abs(res.model.contacts.scene_gaps).max() + np.abs(res.compressions).max() + 1e-300
    assert R.min() >= -1e-10 * R.max()
    assert gap.min() >= -1e-9 * scale_g
    assert np.abs(R * gap).max() <= 1e-9 * R.max() * scale_g


def same_answer(a, b, rtol=1e-8):
    scale = np.abs(b.reactions).max()
    assert np.abs(a.reactions - b.reactions).max() <= rtol * scale
    assert np.array_equal(a.active, b.active)


@pytest.fixture(scope="module")
def bed_64():
    sc = F.bed(64)
    return sc, solve(sc, options={"predict": False})


def test_a_large_bed_starts_from_the_coarse_mesh_and_factorises_once(bed_64, monkeypatch):
    """F.bed(64): 4225 soft springs (≥ ROWS_MIN), so ``predict="auto"`` solves the 16² mesh first;
    its set is (nearly) the answer's, so pdas factorises once (a cold start: at least twice, the
    two-sided matrix and then the set it settles on). Same answer, and statics holds. (Whether the few
    rows left are a low-rank correction or a refactorisation is the factor's choice by measured
    times; on a 64² plate that choice is made certain here, as the cost rule is not under test.)"""
    from plateqp.backends.pdas import factor as pdas_factor

    monkeypatch.setattr(pdas_factor, "LOWRANK_COST", 1e9)
    sc, cold = bed_64
    res = solve(sc)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert res.extras["predicted"]["mesh"] == [16, 16]
    assert res.extras["factorisations"] == 1 and cold.extras["factorisations"] >= 2
    assert res.times["predict"] > 0
    assert_bed_statics(res)
    assert_contact(res)
    same_answer(res, cold)


def test_the_predicted_set_is_nearly_the_answers(bed_64):
    """The 16² mesh's contact set read at the 64² mesh's springs: a handful of 4225 wrong."""
    sc, cold = bed_64
    A, info = P.predicted_set(build_model(sc))
    assert info["mesh"] == [16, 16] and info["rows"] == int(A.sum())
    assert 0 < np.sum(A != cold.active) <= 0.01 * A.size


def test_a_coarse_start_agrees_with_the_condensed_problem():
    """32² bed, ``predict=True`` (below ROWS_MIN: "auto" would not), against bpp on the condensed LCP."""
    sc = F.bed(32)
    res = solve(sc, backend="pdas", options={"predict": True})
    ref = solve(sc, backend="bpp", formulation="condensed", accuracy=1e-8)
    assert res.extras["predicted"]["mesh"] == [8, 8]
    assert res.status == ref.status == pq.Status.OPTIMAL
    assert res.extras["hold_check"] == "rigid motions"  # the free slab held, judged without a solve
    same_answer(res, ref, rtol=1e-7)
    assert_bed_statics(res)


def bump_bed(n):
    """F.bed with a narrow heave (radius 0.45 m, 10 mm, on the 8 m slab) where the slab lifts off:
    the soil pushes up into the plate between the nodes of a mesh of 1 m cells, so that mesh
    does not see it, nor the slab it lifts around it: its contact set is wrong there."""
    sc = F.bed(n)
    sc.foundation = pq.Foundation(k=F.BED_MODULUS, gap={"profile": "bump", "x": 1.5, "y": 1.5, "radius": 0.45,
                                                        "depth": 0.01})
    sc.validate()
    return sc


def test_a_feature_finer_than_the_coarse_cells_costs_iterations_not_the_answer():
    sc = bump_bed(32)
    model = build_model(sc)
    A, _ = P.predicted_set(model)
    res = solve(sc, backend="pdas", options={"predict": True})
    cold = solve(sc, backend="pdas", options={"predict": False})
    ref = solve(sc, backend="bpp", formulation="condensed", accuracy=1e-8)
    near = np.hypot(model.contacts.xy[:, 0] - 1.5, model.contacts.xy[:, 1] - 1.5) < 0.45
    assert np.sum(A[near] != res.active[near]) >= 2 and np.sum(A != res.active) >= 20  # a bad prediction
    assert res.extras["first_phase_steps"] >= 1
    assert res.status == ref.status == pq.Status.OPTIMAL and res.kkt.ok
    same_answer(res, cold)
    same_answer(res, ref, rtol=1e-7)
    assert_bed_statics(res)
    assert_contact(res)


def test_a_bad_warm_start_on_soft_rows_costs_pcg_not_factorisations(monkeypatch):
    """pdas's warm start on a bed: every tenth spring of the answer's set flipped. The Newton
    phase starts on the factor of that set and finds the answer with at most one factorisation
    more (plain exchanges from it refactorise on every change of more than LOWRANK_MAX rows).

    The factor chooses between a low-rank correction and a refactorisation, and the Newton phase
    stops, by times it measures; on a loaded machine a small change was once refactorised (3
    factorisations). Both choices are pinned here (a correction whenever its rows allow, no time
    budget on the Newton phase) so that the count reads the method, not the machine's load."""
    from plateqp.backends.pdas import factor, sparse

    monkeypatch.setattr(factor, "LOWRANK_COST", float("inf"))
    monkeypatch.setattr(sparse, "NEWTON_BUDGET", float("inf"))
    sc = F.bed(32)
    ref = solve(sc, backend="bpp", formulation="condensed", accuracy=1e-8)
    A = ref.active.copy()
    A[::10] ^= True
    res = solve(sc, backend="pdas", options={"active": A})
    assert res.extras["first_phase"] == "newton" and res.extras["first_phase_steps"] >= 1
    assert res.extras["factorisations"] <= 2
    same_answer(res, ref, rtol=1e-7)
    exact = solve(sc, backend="pdas", options={"active": ref.active})
    assert exact.extras["first_phase_steps"] == 0 and exact.extras["factorisations"] == 1
    same_answer(exact, ref, rtol=1e-7)


def test_a_warm_start_a_few_rows_off_goes_to_the_exact_steps():
    """Three springs of the answer's set flipped: the warm start's own minimiser moves them back,
    and the exact steps take them at once, no Newton step; the answer is bpp's on the condensed
    LCP. (Whether they do it by a low-rank correction or a refactorisation is the factor's
    choice by measured times, which on a 32² plate differ from run to run.)"""
    sc = F.bed(32)
    ref = solve(sc, backend="bpp", formulation="condensed", accuracy=1e-8)
    A = ref.active.copy()
    on, off = np.flatnonzero(A), np.flatnonzero(~A)
    A[[on[0], on[len(on) // 2], off[len(off) // 2]]] ^= True
    res = solve(sc, backend="pdas", options={"active": A, "trace": True})
    assert res.extras["first_phase"] == "newton" and res.extras["first_phase_steps"] == 0
    assert res.extras["trace"][0]["infeasible"] >= 1  # the warm start was not the answer's set
    assert np.array_equal(res.active, ref.active)
    same_answer(res, ref, rtol=1e-7)


def test_elastic_posts_on_a_bed_with_a_coarse_start():
    """Soft elastic posts (F.grid_elastic) over a bed settled 1 mm: the same answer as a cold start."""
    sc = F.grid_elastic(32, 9)
    sc.foundation = pq.Foundation(k=F.BED_MODULUS, gap=0.001)
    sc.validate()
    res = solve(sc, backend="pdas", options={"predict": True})
    cold = solve(sc, backend="pdas", options={"predict": False})
    assert res.extras["predicted"]["mesh"] == [8, 8]
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    same_answer(res, cold)


def test_springs_off_the_coarse_plate_are_predicted_open():
    """A bed under a plate with an opening that removes a whole cell of the 8² mesh but only part
    of it on 32²: the fine springs left there are off the coarse plate."""
    sc = F.bed(32)
    sc.openings = [pq.Opening(3.3, 3.9, 3.3, 3.9)]
    sc.validate()
    model = build_model(sc)
    xy = model.contacts.xy
    off = build_model(P.with_mesh(sc, 8, 8)).grid.locate(xy[:, 0], xy[:, 1])[0] < 0
    assert off.sum() >= 3
    A, info = P.predicted_set(model)
    assert info["mesh"] == [8, 8] and not A[off].any()
    res = solve(sc, backend="pdas", options={"predict": True})
    cold = solve(sc, backend="pdas", options={"predict": False})
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    same_answer(res, cold)
    assert_bed_statics(res)


def test_a_coarse_mesh_that_cannot_be_built_leaves_a_cold_start():
    """A post next to that opening is on the 32² plate but in the removed cell of the 8² mesh:
    the coarse scene fails validation; the solve starts cold and says why."""
    sc = F.bed(32)
    sc.openings = [pq.Opening(3.3, 3.9, 3.3, 3.9)]
    sc.supports = [pq.Support(3.25, 3.25, gap=0.0)]
    sc.validate()
    res = solve(sc, backend="pdas", options={"predict": True})
    cold = solve(sc, backend="pdas", options={"predict": False})
    assert res.extras["predicted"]["why"].startswith("the coarse mesh failed: SceneError")
    # the cold start's path: its active sets (not its factorisations, which a low-rank choice by
    # measured times may change from run to run)
    assert res.extras["first_phase"] == cold.extras["first_phase"] and res.iterations == cold.iterations
    same_answer(res, cold)


def test_the_option_is_checked_and_says_why_it_did_not_apply(bed_64):
    sc, _ = bed_64
    with pytest.raises(ProblemError, match="predict"):
        solve(F.bed(16), options={"predict": "yes"})
    small = solve(F.bed(32))
    assert "fewer than" in small.extras["predicted"]["why"] or "coarse" in small.extras["predicted"]["why"]
    warm = solve(F.bed(16), backend="pdas", options={"predict": True, "active": np.ones(289, dtype=bool)})
    assert warm.extras["predicted"]["why"] == "a warm start was given"
    rigid = solve(F.grid_rigid(64, 30), backend="pdas", formulation="primal", options={"predict": "auto"})
    assert rigid.extras["predicted"]["why"].startswith("900 contact rows")
    cond = solve(F.bed(16), backend="bpp", formulation="condensed", options={"predict": True})
    assert "only pdas on the primal" in cond.extras["predicted"]["why"]


def test_a_triangle_meshed_bed_with_a_coarse_start():
    """DKT on a gmsh mesh (element size 1/32: 1297 springs), its coarse mesh of size 1/8: the
    same answer as a cold start, and the bed carries the point load (Σ R = P, Σ R x = P x_P)."""
    pytest.importorskip("gmsh")
    sq = [[0, 0], [1, 0], [1, 1], [0, 1]]
    sc = pq.Scene(plate=pq.Plate(shape={"polygon": sq}, h=0.01, E=1e7, nu=0.3),
                  mesh=pq.MeshSpec(element="dkt", size=1 / 32), loads=[pq.PointLoad(1.0, 0.3, 0.6)],
                  foundation=pq.Foundation(k=1e4, gap={"profile": "linear", "g0": 0.0, "gx": 1e-4, "gy": 5e-5}))
    res = solve(sc, backend="pdas", options={"predict": True})
    cold = solve(sc, backend="pdas", options={"predict": False})
    assert res.extras["predicted"]["mesh"] == [8, 8]
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok and 0.05 < res.active.mean() < 0.95
    same_answer(res, cold)
    xy = res.model.contacts.xy
    np.testing.assert_allclose([res.reactions.sum(), res.reactions @ xy[:, 0], res.reactions @ xy[:, 1]],
                               [1.0, 0.3, 0.6], rtol=1e-9)


@pytest.mark.parametrize("n, predict", [(64, True), (128, "auto")])
def test_a_coarse_mesh_without_equilibrium_leaves_the_fine_solve_to_start_cold(n, predict):
    """A free plate on a bed strip x ∈ [0.27, 0.515] under a point load at x = 0.51: the fine
    mesh's bed reaches x = 0.5156 and carries it, the coarse mesh's cells end at x = 0.5 and its
    plate would tip off them (NoEquilibriumError there). The prediction is then given up, never
    the solve: the answer is the cold start's, and statics holds (Σ R = P, Σ R x = P x_P). At
    128² the strip has 4128 springs, so ``predict="auto"`` (the default) takes this route. (A
    stiff bed: on a soft one, k = 2e4, the plate's tilt dwarfs its bending, the stationarity's
    rounding floor is 2.8e-8 at 128² and two cold solves differed by 5e-5 of the largest
    reaction.)"""
    P, xP = 20.0, 0.51
    sc = pq.Scene(name="strip", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                  edges={}, loads=[pq.PointLoad(P, xP, 0.5)],
                  foundation=pq.Foundation(2.0e7, region=[0.27, 0.515, 0.0, 1.0]))
    sc.validate()
    res = solve(sc, options={"predict": predict})
    cold = solve(sc, options={"predict": False})
    why = res.extras["predicted"]["why"]
    assert why.startswith("the coarse mesh failed: NoEquilibriumError"), why
    assert res.model.contacts.xy[:, 0].max() > xP
    R, xy = res.reactions, res.model.contacts.xy
    np.testing.assert_allclose(R.sum(), P, rtol=1e-8)
    np.testing.assert_allclose(R @ xy[:, 0], P * xP, rtol=1e-8)
    assert_contact(res)
    same_answer(res, cold, rtol=1e-7)
