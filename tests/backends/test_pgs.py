"""Tests of projected Gauss–Seidel / SOR (plateqp.backends.pgs): what is its own beyond the
shared LCP contract of tests/backends/test_lcp.py (hand-solved LCPs, BVLS and brute-force references,
degenerate problems, plates).

References: scipy's BVLS and problems built from a known solution (tests/lcp_reference.py); the
natural residual recomputed here from its definition.
"""

from __future__ import annotations

import numpy as np
import pytest
from lcp_reference import bvls_reference, floating_psd, from_solution, ill_conditioned, random_spd

from plateqp.backends import get_backend
from plateqp.backends import pgs as PGS
from plateqp.backends.base import LCP, Status


def solve(M, q, accuracy="high", **options):
    return get_backend("pgs").solve(LCP(M, q), accuracy=accuracy, options=options)


@pytest.mark.parametrize("seed", range(5))
def test_floating_psd_with_solution(seed):
    """Rigid motions in the null space (a floating plate): every solution has w = w*."""
    rng = np.random.default_rng(400 + seed)
    M, _ = floating_psd(40, rng)
    q, z_star, w_star = from_solution(M, rng, frac=0.6)
    p = PGS.pgs(M, q, accuracy="high")
    assert p.status is Status.OPTIMAL
    np.testing.assert_allclose(p.w, w_star, rtol=0, atol=1e-7 * np.abs(w_star).max())


def test_zero_diagonal_is_held_and_said():
    """M = 0: z cannot move w = −1; the component is held, the sweeps end on a limit, and
    solver_status says why."""
    sol = PGS.pgs(np.array([[0.0]]), np.array([-1.0]), max_iter=10)  # w = −1 whatever z
    assert sol.status is Status.MAX_ITER and "held" in sol.solver_status


def test_no_solution_runs_away_and_is_never_optimal():
    M, q = np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0])
    for acc in ("low", "default", "high"):
        sol = solve(M, q, acc, max_iter=3000)
        assert sol.status is Status.MAX_ITER
        assert sol.x is not None and sol.extras["natural_residual"] > 0.5  # z runs away, w = (−1, −1)


def test_pgs_warm_start():
    rng = np.random.default_rng(22)
    M = random_spd(50, rng)
    q = rng.standard_normal(50)
    z_ref = bvls_reference(M, q)
    sol = solve(M, q, "default", z0=z_ref)
    assert sol.status is Status.OPTIMAL and sol.iterations <= 1
    cold = solve(M, q, "default")
    assert cold.iterations > 5


# ----------------------------------------------------------------------------- limits


@pytest.mark.parametrize("accuracy", ["low", "default", "high"])
def test_pgs_reaches_each_preset(accuracy):
    rng = np.random.default_rng(31)
    M = random_spd(80, rng)
    q = rng.standard_normal(80)
    sol = solve(M, q, accuracy)
    tol = PGS.ACCURACY[accuracy]["tol"]
    assert sol.status is Status.OPTIMAL
    assert sol.extras["natural_residual"] <= tol
    # the same measure, computed here from the definition
    w = M @ sol.x + q
    r = np.abs(np.minimum(np.diag(M) * sol.x, w)).max() / max(np.abs(w).max(), np.abs(q).max())
    assert r <= tol * 1.001


def test_pgs_time_limit_gives_max_iter_with_x():
    M, q = ill_conditioned()
    sol = solve(M, q, "high", time_limit=0.2)
    assert sol.status is Status.MAX_ITER and "time limit" in sol.solver_status
    assert sol.x is not None and sol.w is not None and sol.solve_time < 2.0
    assert sol.extras["natural_residual"] > 1e-11
    sol = solve(M, q, "high", max_iter=7)
    assert sol.status is Status.MAX_ITER and sol.iterations == 7 and "sweep limit" in sol.solver_status
