"""pdas's linear algebra in halves and blocks: the Woodbury columns of the sparse method as
forward halves of a solve, the condensed method's rows ordered last as they stand, and
Lawson–Hanson's triangular solves through LAPACK directly.

References: a fresh factorisation of the changed matrix (Woodbury against no Woodbury), the
dense ``B K⁻¹ Bᵀ`` (NumPy), ``scipy.linalg.solve_triangular``, and Lemke's method on the
condensed LCP for the whole solve.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.linalg as sla

import plateqp as pq
from plateqp import linalg
from plateqp.backends.pdas.dense import DenseDual, _lower_solve
from plateqp.backends.pdas.factor import SpringFactor
from plateqp.backends.pdas.reduced import ReducedQP
from plateqp.contact.formulations import formulate
from plateqp.contact.scaling import Scaled
from plateqp.model.assembly import build_model
from plateqp.scenes import families as F

CVXOPT = pytest.mark.skipif(not linalg.HAVE_CVXOPT, reason="CHOLMOD through cvxopt is not installed")


def reduced(scene) -> ReducedQP:
    return ReducedQP(formulate(Scaled.from_model(build_model(scene)), "primal").problem({"qp"}), None)


def rel(a, b) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())


@CVXOPT
def test_woodbury_columns_are_forward_halves_and_solve_like_a_fresh_factor():
    """A few rows changed on cvxopt's CHOLMOD: the kept columns ``Y`` give the capacitance as
    ``YᵀY = U H(w₀)⁻¹ Uᵀ`` (forward halves of a solve, not whole solves), and the corrected solve
    is that of a factor of ``H(w)`` made afresh."""
    pb = reduced(F.bed(12))
    W = 1e3 * pb.k
    w0 = np.where(np.arange(pb.m) % 3 == 0, W, 0.0)
    fac = SpringFactor(pb.K, pb.B, pb.Kd, pb.c, 1e-12, "cvxopt")
    fac.set(w0)
    rows = np.array([1, 2, 4, 5])
    w1 = w0.copy()
    w1[rows] = W[rows]
    fac.set(w1)
    assert fac.lr is not None and fac.stats["lowrank"] == 1
    Y = fac.lr[1]
    U = pb.B[rows].toarray()
    H0 = fac._solve(U.T)  # H(w₀)⁻¹ Uᵀ by whole solves with the factor of w₀
    assert rel(Y.T @ Y, U @ H0) < 1e-10
    b = np.random.default_rng(0).standard_normal(pb.K.shape[0])
    fresh = SpringFactor(pb.K, pb.B, pb.Kd, pb.c, 1e-12, "cvxopt")
    fresh.set(w1)
    assert rel(fac.solve(b), fresh.solve(b)) < 1e-9
    B2 = np.random.default_rng(1).standard_normal((pb.K.shape[0], 3))
    assert rel(fac.solve(B2), fresh.solve(B2)) < 1e-9  # blocks of right-hand sides too


@CVXOPT
def test_condensed_orders_one_dof_rows_last_as_the_rows_stand():
    """Rigid posts, one dof a row: the dofs go last in the rows' own order (no reordering of M),
    and M is ``B K⁻¹ Bᵀ + diag(ρ)`` (dense reference)."""
    pb = reduced(F.grid_rigid(8, 5))
    cond = DenseDual(pb, 4000)
    assert np.array_equal(cond.fac.last, pb.B.indices)
    K = pb.K.toarray()
    want = pb.B.toarray() @ np.linalg.solve(K, pb.B.T.toarray()) + np.diag(pb.rho)
    assert rel(cond.M, want) < 1e-9


@pytest.mark.parametrize("k", [1, 2, 17, 60])
def test_lower_solve_is_scipys_triangular_solve(k):
    """On a leading block of a larger row-major buffer (as Lawson–Hanson keeps its factor), both
    ways round, to the bit."""
    rng = np.random.default_rng(k)
    buf = np.zeros((64, 64))
    A = rng.standard_normal((k, k))
    buf[:k, :k] = np.linalg.cholesky(A @ A.T + k * np.eye(k))
    b = rng.standard_normal(k)
    L = buf[:k, :k]
    assert np.array_equal(_lower_solve(L, b), sla.solve_triangular(L, b, lower=True, check_finite=False))
    assert np.array_equal(_lower_solve(L, b, trans=True),
                          sla.solve_triangular(L, b, lower=True, trans="T", check_finite=False))


def test_many_posts_condensed_pdas_agrees_with_lemke():
    """The whole solve on a 12 × 12 post grid (pdas's condensed method) against Lemke's method on
    the condensed LCP: the same reactions, and pdas's answer meets 1e-10."""
    scene = F.grid_rigid(16, 12)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        a = pq.solve(scene, backend="pdas", accuracy=1e-10)
        b = pq.solve(scene, backend="lemke", formulation="condensed", accuracy=1e-8)
    assert a.extras["method"] == "condensed"
    assert a.kkt.ok
    assert np.array_equal(a.active, b.active)
    assert rel(a.reactions, b.reactions) < 1e-7


def test_the_triangular_solve_of_an_empty_set_is_empty():
    """Lawson–Hanson's first step solves on an empty set: LAPACK's TRTRS is not asked (SciPy
    1.15's wrapper refused its leading dimension 0 with info −8)."""
    for trans in (False, True):
        x = _lower_solve(np.zeros((0, 0)), np.zeros(0), trans=trans)
        assert x.shape == (0,)
