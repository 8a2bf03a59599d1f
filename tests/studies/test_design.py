"""Inverse design (plateqp.studies.design): regulated gaps checked by an independent contact
solve of the scene they give; the most uniform stiffness against a scan of independent solves."""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.studies import most_uniform_stiffness, regulate_gaps, set_param
from study_scenes import STIFF, contour, solve


def _check_regulated(reg, supports, target):
    R = solve(reg.scene, accuracy="high").reactions  # the independent check
    np.testing.assert_allclose(R[supports], target, rtol=1e-6, atol=1e-6 * np.max(target))
    return R


def test_regulate_gaps_equal_contour_reactions_on_a_floating_plate():
    sc = contour()
    R0 = solve(sc).reactions
    assert R0.std() / R0.mean() > 0.5  # the corners lift off on rigid supports
    target = 10.0 / 16  # q a b spread equally
    reg = regulate_gaps(sc, target)
    assert reg.reachable
    _check_regulated(reg, np.arange(16), np.full(16, target))


def test_regulate_gaps_held_plate_any_target_some_supports():
    sup = [pq.Support(x, y, stiffness=(5e3 if x > 0.5 else "rigid"))
           for x in (0.25, 0.5, 0.75) for y in (0.25, 0.5, 0.75)]
    sc = pq.Scene(plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(8, 8),
                  edges={"left": pq.Edge("simple"), "right": pq.Edge("simple")},
                  loads=[pq.UniformLoad(q=10.0)], supports=sup)
    target = np.array([0.3, 0.9, 0.5, 0.2])
    chosen = [0, 2, 4, 8]
    reg = regulate_gaps(sc, target, supports=chosen)
    R = _check_regulated(reg, chosen, target)
    others = [1, 3, 5, 6, 7]
    np.testing.assert_allclose(R[others], reg.other_reactions, rtol=1e-6, atol=1e-9)
    assert [s.gap for k, s in enumerate(reg.scene.supports) if k in others] == [0.0] * 5  # untouched


def test_regulate_gaps_projects_an_unbalanced_target_onto_equilibrium():
    # an eccentric load: equal contour reactions cannot balance its moment
    sc = contour(stiffness=1e4, loads=[pq.UniformLoad(q=10.0), pq.PointLoad(P=5.0, x=0.75, y=0.5)])
    reg = regulate_gaps(sc, 15.0 / 16)
    assert not reg.reachable and reg.projection > 0.05
    R = reg.reactions
    xy = np.array([(s.x, s.y) for s in sc.supports])
    assert R.sum() == pytest.approx(15.0, rel=1e-9)  # force balance
    assert R @ xy[:, 0] == pytest.approx(10.0 * 0.5 + 5.0 * 0.75, rel=1e-9)  # moment balance
    _check_regulated(reg, np.arange(16), R)


def test_regulate_gaps_floating_plate_with_unregulated_supports():
    sc = contour()
    reg = regulate_gaps(sc, 0.5, supports=[1, 2, 3, 5, 6, 7])
    R = _check_regulated(reg, [1, 2, 3, 5, 6, 7], reg.reactions)
    assert R.sum() == pytest.approx(10.0, rel=1e-9)


def test_most_uniform_stiffness_against_a_scan():
    # a plate on an elastic contour and a central column: stiff contour supports load the
    # mid-sides, soft ones the corners, in between the pressure is most uniform
    sc = contour(pins=[pq.Pin(0.5, 0.5)])
    best = most_uniform_stiffness(sc, (10.0, 1e6))
    cs = np.geomspace(10.0, 1e6, 41)
    cv = []
    for c in cs:
        R = solve(set_param(sc, STIFF, c)).reactions
        cv.append(R.std() / R.mean())
    k = int(np.argmin(cv))
    assert 0 < k < len(cs) - 1  # an interior optimum
    assert cs[k - 1] < best.c < cs[k + 1] and not best.at_bound
    assert best.cv <= min(cv) + 1e-12
    R = solve(set_param(sc, STIFF, best.c)).reactions
    assert R.std() / R.mean() == pytest.approx(best.cv, rel=1e-9)
    # without the column the plate floats on equal springs: softer is always more uniform
    assert most_uniform_stiffness(contour(), (10.0, 1e6), scan=9).at_bound


def test_regulate_gaps_needs_no_cvxpy(monkeypatch):
    """The projection onto equilibrium is solved in-house (Lemke), so it runs without cvxpy."""
    monkeypatch.setitem(__import__("sys").modules, "cvxpy", None)  # `import cvxpy` now fails
    sc = contour(stiffness=1e4, loads=[pq.UniformLoad(q=10.0), pq.PointLoad(P=5.0, x=0.75, y=0.5)])
    reg = regulate_gaps(sc, 15.0 / 16, backend="lemke")
    assert not reg.reachable
    assert reg.reactions.sum() == pytest.approx(15.0, rel=1e-9)
    _check_regulated(reg, np.arange(16), reg.reactions)


def test_regulate_gaps_cannot_balance_an_uplift():
    sc = contour(loads=[pq.UniformLoad(q=-10.0)])  # the load lifts the floating plate off
    with pytest.raises(pq.NoEquilibriumError, match="no reactions R ≥ 0 of these supports balance the load"):
        regulate_gaps(sc, 1.0)


@pytest.mark.parametrize("seed, n_other", [(0, 0), (1, 0), (2, 3), (3, 5)])
def test_project_reactions_meets_its_optimality_conditions(seed, n_other):
    """The projection's KKT conditions, checked as a certificate (the problem is convex):
    R ≥ 0, A R = b, and multipliers y with λ = P (R − R*) − Aᵀ y ≥ 0, zero where R > 0."""
    from plateqp.studies.design import project_reactions

    rng = np.random.default_rng(seed)
    r, k = 8, 3
    n = r + n_other
    A = rng.normal(size=(k, n))
    A[0] = np.abs(A[0]) + 0.1  # a force balance: every reaction pushes the same way
    b = A @ rng.uniform(0.0, 2.0, n)  # feasible
    target = rng.uniform(0.0, 2.0, r) * (rng.uniform(size=r) > 0.3)
    target *= 2.0 * b[0] / (A[0, :r] @ target)  # twice the force the supports may carry: unreachable
    R = project_reactions(A, b, target, n_other)
    scale = np.abs(R).max()
    assert R.min() >= 0
    np.testing.assert_allclose(A @ R, b, rtol=0, atol=1e-10 * np.abs(b).max())
    grad = np.concatenate([R[:r] - target, np.zeros(n_other)])
    pos = R > 1e-10 * scale
    y, *_ = np.linalg.lstsq(A[:, pos].T, grad[pos], rcond=None)
    lam = grad - A.T @ y
    np.testing.assert_allclose(lam[pos], 0.0, atol=1e-9 * max(1.0, np.abs(grad).max()))
    assert lam[~pos].min(initial=0.0) >= -1e-9 * max(1.0, np.abs(grad).max())
    assert (A[0, :r] @ R[:r]) <= b[0] * (1 + 1e-12) and not np.allclose(R[:r], target)  # a real projection
