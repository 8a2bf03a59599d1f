"""plateqp.linalg.residual.Residual against exact rational arithmetic (``fractions.Fraction``).

The residual ``b − K x`` of a solve is where rounding hurts most: ``b`` and ``K x`` agree to
about cond·eps, so a double sum keeps only its rounding. The reference here sums every row's
products exactly, so the error of each computed residual entry is measured, not estimated;
it must stay below 1e-20 of the row's scale ``Σ|K_ij x_j| + |b_i|`` (a double sum reaches
1e-16, long double 1e-19: both fail it, which shows the test can).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from plateqp.model.assembly import build_model
from plateqp.scenes.families import grid_rigid
from plateqp.linalg import Factor
from plateqp.linalg.residual import Residual

BOUND = 1e-20


def exact_residual(K, b, x) -> np.ndarray:
    """b − K x summed exactly, then rounded to double."""
    K = sp.csr_matrix(K)
    out = np.empty(K.shape[0])
    for i in range(K.shape[0]):
        lo, hi = K.indptr[i], K.indptr[i + 1]
        out[i] = float(Fraction(float(b[i])) - sum((Fraction(float(v)) * Fraction(float(x[j]))
                                                    for j, v in zip(K.indices[lo:hi], K.data[lo:hi])), Fraction(0)))
    return out


def exact_errors(K, b, x, r) -> np.ndarray:
    """|r_i − (b − K x)_i| / (Σ_j |K_ij x_j| + |b_i|), each residual in exact arithmetic;
    ``b``, ``x``, ``r`` of shape (n,)."""
    K = sp.csr_matrix(K)
    out = np.empty(K.shape[0])
    for i in range(K.shape[0]):
        lo, hi = K.indptr[i], K.indptr[i + 1]
        terms = [Fraction(float(v)) * Fraction(float(x[j])) for j, v in zip(K.indices[lo:hi], K.data[lo:hi])]
        exact = Fraction(float(b[i])) - sum(terms, Fraction(0))
        scale = float(sum((abs(t) for t in terms), Fraction(0))) + abs(float(b[i]))
        out[i] = abs(float(Fraction(float(r[i])) - exact)) / scale if scale else abs(float(r[i]))
    return out


@pytest.fixture(scope="module")
def plate():
    """A 12² ACM plate's K (walls; deflections and rotations of unlike scale), its load, and
    the solution of K x = f from one raw factor solve (a residual of rounding size: the
    hardest case for a sum)."""
    model = build_model(grid_rigid(12, 3))
    K = sp.csc_matrix(model.K)
    f = np.asarray(model.f, dtype=float)
    return K, f, spla.spsolve(K, f)


def test_a_solve_s_residual_is_exact_to_1e_20_where_double_and_long_double_are_not(plate):
    K, f, x = plate
    err = exact_errors(K, f, x, Residual(K)(f, x))
    assert err.max() < BOUND
    # the same check on the plain double residual fails (the test can fail)
    assert exact_errors(K, f, x, f - K @ x).max() > 100 * BOUND
    # and on a long-double one too, where the platform has it wider than double
    if np.finfo(np.longdouble).eps < np.finfo(np.float64).eps:
        KL = sp.csc_matrix((K.data.astype(np.longdouble), K.indices, K.indptr), shape=K.shape)
        r_ld = (f.astype(np.longdouble) - KL @ x.astype(np.longdouble)).astype(float)
        assert exact_errors(K, f, x, r_ld).max() > 2 * BOUND


def test_columns_of_unlike_scale_csr_and_a_symmetric_pattern_vouched(plate):
    """Several right-hand sides at once (scales 1e-30 and 1e30: each column its own grid), K
    given as CSR, and the symmetric-pattern shortcut Factor takes."""
    K, f, x = plate
    rng = np.random.default_rng(0)
    X = np.column_stack([x * 1e-30, x * (1 + 1e-9 * rng.standard_normal(x.size)) * 1e30])
    B = np.column_stack([f * 1e-30, f * 1e30])
    for R in (Residual(sp.csr_matrix(K)), Residual(K, symmetric=True)):
        r = R(B, X)
        assert r.shape == B.shape
        for c in range(2):
            assert exact_errors(K, B[:, c], X[:, c], r[:, c]).max() < BOUND


def test_badly_scaled_matrix_and_an_asymmetric_pattern():
    """D K D with D over twelve orders of magnitude (the powers-of-two scaling balances it); a
    CSC matrix whose first row is much longer than any column (the row count, not the
    column count, bounds the exact sum)."""
    rng = np.random.default_rng(1)
    k = 10
    T = sp.diags([-np.ones(k - 1), 2 * np.ones(k), -np.ones(k - 1)], [-1, 0, 1])
    L = sp.kron(T, sp.identity(k)) + sp.kron(sp.identity(k), T) + 1e-3 * sp.identity(k * k)
    d = 10.0 ** rng.uniform(-6, 6, k * k)
    K = sp.csc_matrix(sp.diags(d) @ L @ sp.diags(d))
    b = rng.standard_normal(k * k) * d
    x = spla.spsolve(K, b)
    assert exact_errors(K, b, x, Residual(K)(b, x)).max() < BOUND
    # a long first row (every column has an entry in row 0; each column holds at most three)
    A = sp.lil_matrix((400, 400))
    A.setdiag(1.0 + rng.random(400))
    A[0, :] = 1.0 + rng.random(400)  # with x > 0, the partial sums of row 0 only grow
    A = sp.csc_matrix(A)
    xa = 1.0 + rng.random(400)
    ba = A @ xa  # rounded: the residual is small but not zero
    assert exact_errors(A, ba, xa, Residual(A)(ba, xa)).max() < 10 * BOUND  # 400 terms in row 0
    # vouching for a symmetric pattern it does not have bounds the sum by a column's count (2):
    # the sum of row 0 is no longer exact and its error is a double sum's
    assert exact_errors(A, ba, xa, Residual(A, symmetric=True)(ba, xa)).max() > 1000 * BOUND


def test_zero_and_non_finite_input():
    K = sp.csc_matrix(np.array([[4.0, 1.0], [1.0, 3.0]]))
    b = np.array([1.0, 2.0])
    assert np.array_equal(Residual(K)(b, np.zeros(2)), b)
    assert np.isnan(Residual(K)(b, np.array([np.nan, 1.0]))).any()
    Kinf = sp.csc_matrix(np.array([[np.inf, 1.0], [1.0, 3.0]]))
    R = Residual(Kinf)
    assert not R.exact  # nothing to split: the double product
    assert np.array_equal(R(b, np.array([0.0, 1.0])), b - Kinf @ np.array([0.0, 1.0]), equal_nan=True)


def test_factor_refines_to_rounding_on_a_plate():
    """Factor.solve on a 24² plate (a raw solve's error 1e-12): refinement on the split
    residual takes the answer to the exact solution's rounding (against a dense solve
    refined on residuals summed in rational arithmetic)."""
    model = build_model(grid_rigid(24, 3))
    K = sp.csc_matrix(model.K)
    f = np.asarray(model.f, dtype=float)
    Kd = K.toarray()
    x = np.linalg.solve(Kd, f)
    for _ in range(2):
        x = x + np.linalg.solve(Kd, exact_residual(K, f, x))
    fac = Factor(K)
    # 4e-21 measured: the same fixed point as refinement on exact residuals (five steps on
    # long-double residuals end 1e-16 away)
    assert np.abs(fac.solve(f) - x).max() / np.abs(x).max() < 1e-17
    assert np.abs(fac.solve(f, refine=0) - x).max() / np.abs(x).max() > 1e-13  # refinement did something
