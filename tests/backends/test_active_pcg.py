"""The active-set PCG (plateqp.backends.active_pcg) on bound- and equality-constrained convex
QPs, against independent references: block principal pivoting (a direct method) on the LCP
without equalities, Clarabel (an interior-point solver) with them, and the KKT conditions by
their definitions; a set that does not settle is said, never called optimal."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from plateqp.backends.active_pcg import active_set_pcg
from plateqp.backends.bpp import bpp

clarabel = pytest.importorskip("clarabel")


def flexibility(m, seed, stiff=1.0):
    """A symmetric positive definite matrix with positive entries (a flexibility, not an
    M-matrix): a smooth kernel on m points on a line plus a diagonal."""
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(0, 1, m))
    M = np.exp(-np.abs(x[:, None] - x[None, :]) / 0.2) + stiff * 0.05 * np.eye(m)
    return M, x, rng


def clarabel_qp(M, q, G, b):
    m, k = len(q), G.shape[1]
    A = sp.vstack([sp.csc_matrix(G.T), -sp.eye(m)]).tocsc()
    s = clarabel.DefaultSettings()
    s.verbose, s.tol_gap_abs, s.tol_gap_rel, s.tol_feas = False, 1e-12, 1e-12, 1e-12
    sol = clarabel.DefaultSolver(sp.csc_matrix(np.triu(M)), q, A, np.concatenate([b, np.zeros(m)]),
                                 [clarabel.ZeroConeT(k), clarabel.NonnegativeConeT(m)], s).solve()
    return np.asarray(sol.x)


def kkt(M, q, x, G=None, alpha=None):
    g = M @ x + q - (0 if G is None else G @ alpha)
    scale = max(np.linalg.norm(q), 1.0)
    return x.min(), np.abs(np.minimum(x, g)).max() / scale


@pytest.mark.parametrize("seed", range(6))
def test_without_equalities_it_is_the_direct_method(seed):
    M, x_pts, rng = flexibility(60, seed)
    q = np.sin(7 * x_pts + seed) - 0.3  # about half the points lift off
    out = active_set_pcg(lambda v: M @ v, q, tol=1e-11)
    ref = bpp(M, q, accuracy="high").x
    assert out.status == "optimal", out.message
    np.testing.assert_allclose(out.x, ref, atol=1e-8 * np.abs(ref).max())
    assert (ref > 0).any() and (ref == 0).any()
    low, nat = kkt(M, q, out.x)
    assert low >= 0 and nat <= 1e-9


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("k", [1, 3])
def test_with_equalities_it_is_the_interior_point_answer(seed, k):
    """G's columns as a floating plate's rigid motions on the points (1, x, x²) and b a
    resultant: the answer and the multipliers satisfy Gᵀx = b and the KKT conditions."""
    M, x_pts, rng = flexibility(50, seed)
    G = np.vander(x_pts, 3, increasing=True)[:, :k]
    q = np.cos(5 * x_pts + seed)
    b = G.T @ rng.uniform(0.5, 1.5, 50)  # a resultant some positive forces carry
    out = active_set_pcg(lambda v: M @ v, q, G=G, b=b, tol=1e-11,
                         precond=lambda v: v / np.diag(M))
    ref = clarabel_qp(M, q, G, b)
    assert out.status == "optimal", out.message
    np.testing.assert_allclose(out.x, ref, atol=1e-6 * np.abs(ref).max())
    np.testing.assert_allclose(G.T @ out.x, b, rtol=1e-9)
    low, nat = kkt(M, q, out.x, G, out.alpha)
    assert low >= 0 and nat <= 1e-8


def test_a_preconditioner_changes_the_steps_not_the_answer():
    M, x_pts, _ = flexibility(80, 11, stiff=0.01)
    q = np.sin(9 * x_pts) - 0.2
    plain = active_set_pcg(lambda v: M @ v, q, tol=1e-11)
    exact = np.linalg.inv(M)
    pre = active_set_pcg(lambda v: M @ v, q, tol=1e-11, precond=lambda v: exact @ v)
    assert plain.status == pre.status == "optimal"
    np.testing.assert_allclose(pre.x, plain.x, atol=1e-8 * np.abs(plain.x).max())
    assert pre.iterations < plain.iterations


def test_a_set_that_cannot_hold_the_equalities_is_said_not_solved():
    """Every point pushed off (q > 0) but a resultant to carry: no set without a point holds
    Gᵀx = b; the method says so (the caller falls back), never "optimal"."""
    M, x_pts, _ = flexibility(20, 3)
    G = np.ones((20, 1))
    out = active_set_pcg(lambda v: M @ v, np.ones(20), G=G, b=np.array([1.0]), active=np.zeros(20, bool),
                         tol=1e-10)
    assert out.status != "optimal" or (abs(out.x.sum() - 1.0) < 1e-9 and out.x.min() >= 0)
