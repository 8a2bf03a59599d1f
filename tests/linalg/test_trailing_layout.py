"""The trailing block of a contacts-last factorisation as LAPACK reads it, and the dense
flexibility made from it: exact against NumPy's dense Cholesky and dense inverse.

References: NumPy's dense Cholesky of the (equilibrated) matrix, its dense Schur complement and
inverse; the mirror of a lower triangle by ``np.tril``.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from plateqp import linalg
from plateqp.linalg import SchurFactor
from plateqp.linalg.cholmod import Cholesky, lower
from plateqp.linalg.schur import symmetric_from_lower

LIBS = [lib for lib, have in (("sksparse", linalg.HAVE_CHOLMOD), ("cvxopt", linalg.HAVE_CVXOPT)) if have]


def laplacian(k: int, shift: float) -> sp.csc_matrix:
    T = sp.diags([-np.ones(k - 1), np.r_[1.0, 2 * np.ones(k - 2), 1.0], -np.ones(k - 1)], [-1, 0, 1])
    Id = sp.identity(k)
    return sp.csc_matrix(sp.kron(T, Id) + sp.kron(Id, T) + shift * sp.identity(k * k))


def spd(k: int = 9, seed: int = 0) -> sp.csc_matrix:
    d = 10.0 ** np.random.default_rng(seed).uniform(-3, 3, k * k)
    return sp.csc_matrix(sp.diags(d) @ laplacian(k, 0.05) @ sp.diags(d))


def rel(a, b) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())


@pytest.mark.parametrize("n", [1, 5, 127, 128, 129, 300])
def test_symmetric_from_lower_is_the_mirror_of_the_lower_triangle(n):
    A = np.random.default_rng(n).standard_normal((n, n))
    want = np.tril(A) + np.tril(A, -1).T
    for order in ("C", "F"):
        got = symmetric_from_lower(np.array(A, order=order))
        assert np.array_equal(got, want)


@pytest.mark.parametrize("lib", ["cvxopt"] if "cvxopt" in LIBS else [])
def test_trailing_block_is_column_major_and_the_dense_factors(lib):
    """The block is copied out in LAPACK's own (column-major) layout, zero above its diagonal,
    and equals NumPy's dense Cholesky factor's trailing block (one dense supernode at the end:
    the path that copies it by columns)."""
    K = spd(10)
    n, no = K.shape[0], 40
    A = lower(K, 1.0 / np.sqrt(K.diagonal()), upper=True)
    chol = Cholesky(lib)
    chol.analyse(A, natural=True)
    chol.factor(A)
    T = chol.trailing(no)
    Ad = A.toarray() + np.triu(A.toarray(), 1).T
    assert T.flags.f_contiguous
    assert np.all(np.triu(T, 1) == 0)
    assert rel(T, np.linalg.cholesky(Ad)[no:, no:]) < 1e-12
    b = np.arange(1.0, n + 1)
    assert rel(chol.solve(b), np.linalg.solve(Ad, b)) < 1e-10  # the factor still solves


@pytest.mark.parametrize("method", LIBS + ["blocks"])
def test_flexibility_of_rows_in_any_order_is_B_Kinv_Bt(method):
    """One row per unknown ordered last, the rows in another order than the unknowns: the
    flexibility from the trailing block's inverse is ``B K⁻¹ Bᵀ`` (dense reference), exactly
    symmetric."""
    K = spd(8, seed=3)
    n = K.shape[0]
    rng = np.random.default_rng(1)
    last = rng.choice(n, 20, replace=False)
    rows = rng.permutation(last)  # rows in another order than ``last``
    B = sp.csr_matrix((rng.uniform(0.5, 2.0, rows.size), (np.arange(rows.size), rows)), shape=(rows.size, n))
    S = SchurFactor(K, last, method=method)
    M = S.flexibility(B)
    want = B.toarray() @ np.linalg.solve(K.toarray(), B.T.toarray())
    assert np.array_equal(M, M.T)
    assert rel(M, want) < 1e-9
