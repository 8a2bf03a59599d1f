"""A triangle handed to CHOLMOD already permuted, analysed in its natural order: CHOLMOD's
numeric factorisation then reads it where it lies (no permuted copy beside the factor), and
the factor still solves in the matrix's own order. Checked against dense NumPy."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from plateqp.backends.pdas.factor import SpringFactor
from plateqp.contact.formulations import _with_identity
from plateqp.linalg import Cholesky, SchurFactor
from plateqp.linalg.cholmod import _header, lower
from plateqp.linalg.pattern import csc_of_symmetric
from plateqp.linalg.seam import view
from plateqp.model.assembly import build_model
from plateqp.scenes import families

_NATURAL = 0  # CHOLMOD's code of the natural ordering (cholmod.h)


def _plate():
    K = sp.csc_matrix(build_model(families.grid_rigid(6, 3)).K)
    return K, 1.0 / np.sqrt(K.diagonal())


def _ordering(chol: Cholesky) -> int:
    """The ``ordering`` field of the factor's ``cholmod_factor`` (after its 22 size/pointer fields)."""
    return int(view(chol.direct.L.value + 22 * 8, 1, np.int32)[0])


def test_permuted_lower_is_the_permuted_matrix_lower_triangle(seam_cholesky):
    chol = seam_cholesky
    K, s = _plate()
    A = lower(K, s, upper=True)
    U = A.toarray()
    full = U + np.triu(U, 1).T  # the symmetric matrix A is the upper triangle of
    p = np.random.default_rng(0).permutation(K.shape[0])
    M = chol.permuted_lower(A, p)
    assert M.indices.dtype == np.int64 and M.indptr.dtype == np.int64 and M.has_sorted_indices
    np.testing.assert_array_equal(M.toarray(), np.tril(full[np.ix_(p, p)]))
    # other values on the same pattern: each stored entry's position, moved with it
    pos = chol.permuted_lower(A, p, np.arange(A.nnz, dtype=float)).data.astype(np.int64)
    np.testing.assert_array_equal(A.data[pos], M.data)
    with pytest.raises(ValueError, match="upper triangle"):
        chol.permuted_lower(lower(K, s), p)


def test_a_factor_analysed_permuted_is_natural_and_solves_in_the_matrix_order(seam_cholesky):
    chol = seam_cholesky
    K, s = _plate()
    n = K.shape[0]
    full = (s[:, None] * K.toarray()) * s[None, :]
    A = lower(K, s, upper=True)
    order = chol.order(A)
    Ap = chol.permuted_lower(A, order)
    chol.forget_matrix()
    chol.analyse_permuted(Ap, order)
    chol.factor(Ap)
    # CHOLMOD's natural ordering: its factorisation reads a lower triangle as it is (no copy)
    assert _ordering(chol) == _NATURAL
    np.testing.assert_array_equal(view(int(_header(chol.direct.L.value)[0][2]), n, np.int64), np.arange(n))
    b = np.random.default_rng(1).standard_normal((n, 3))
    x = np.linalg.solve(full, b)
    np.testing.assert_allclose(chol.solve(b), x, rtol=1e-10, atol=1e-12 * np.abs(x).max())
    np.testing.assert_allclose(chol.backward(chol.forward(b[:, 0])), x[:, 0], rtol=1e-10,
                               atol=1e-12 * np.abs(x).max())
    # forward works in the factor's order: y = L⁻¹ P b, its trailing block that of numpy's factor
    L = np.linalg.cholesky(full[np.ix_(order, order)])
    np.testing.assert_allclose(chol.forward(b[:, 0]), np.linalg.solve(L, b[order, 0]), rtol=1e-10, atol=1e-12)
    no = n - 9
    np.testing.assert_allclose(chol.trailing(no), L[no:, no:], rtol=1e-10, atol=1e-13)
    # a block permuted in place (a caller's block made for the solve): the same columns
    B = np.asfortranarray(b.copy())
    np.testing.assert_allclose(chol.forward(B, overwrite=True), np.linalg.solve(L, b[order]), rtol=1e-10, atol=1e-12)


def test_the_contacts_last_factor_takes_its_triangle_permuted(seam_cholesky):
    K, _ = _plate()
    last = np.random.default_rng(2).permutation(K.shape[0])[:7]
    fac = SchurFactor(K, last, method="cvxopt")
    assert fac.chol.vorder is not None and _ordering(fac.chol) == _NATURAL
    Kd = K.toarray()
    o = np.setdiff1d(np.arange(K.shape[0]), last)
    S = Kd[np.ix_(last, last)] - Kd[np.ix_(last, o)] @ np.linalg.solve(Kd[np.ix_(o, o)], Kd[np.ix_(o, last)])
    np.testing.assert_allclose(fac.schur(), S, rtol=1e-9, atol=1e-9 * np.abs(S).max())
    b = np.random.default_rng(3).standard_normal(K.shape[0])
    np.testing.assert_allclose(fac.solve(b, refine=1), np.linalg.solve(Kd, b), rtol=1e-10)
    # shifted and with a proximal term: the diagonal added in the factor's order
    sh = SchurFactor(K, last, method="cvxopt", shift=0.5, prox=0.1)
    D = np.sqrt(np.diag(Kd))
    Kp = Kd + 0.1 * np.diag(np.diag(Kd))
    Sp = Kp[np.ix_(last, last)] - Kp[np.ix_(last, o)] @ np.linalg.solve(Kp[np.ix_(o, o)], Kp[np.ix_(o, last)])
    Dl = D[last]
    np.testing.assert_allclose(sh.schur(equilibrated=True), Sp / np.outer(Dl, Dl), rtol=1e-9, atol=1e-10)


@pytest.mark.parametrize("rows", ["one unknown", "several unknowns"])
def test_the_spring_factor_keeps_its_triangle_permuted(rows, seam_cholesky):
    """The kept triangle, its rows' positions moved with it: on the diagonal (a bed's rows) or
    off it (rows that read several unknowns of one element), each ``H(w)`` is the permuted
    matrix's lower triangle and its factor solves ``K + σ diag(K) + Bᵀ diag(w) B``."""
    model = build_model(families.grid_rigid(8, 3))
    K = sp.csc_matrix(model.K)
    n = K.shape[0]
    if rows == "one unknown":
        B = sp.csr_matrix(model.contacts.B)
    else:  # each row on three unknowns of one node (a node's block is stored whole in K)
        rng = np.random.default_rng(4)
        nodes = rng.choice(n // 3, size=12, replace=False)
        cols = (3 * nodes[:, None] + np.arange(3)).ravel()
        B = sp.csr_matrix((rng.uniform(0.5, 2.0, cols.size), cols, np.arange(0, cols.size + 1, 3)), shape=(12, n))
    sigma = 1e-6
    f = SpringFactor(K, B, K.diagonal(), np.ones(B.shape[0]), sigma, "cvxopt")
    assert f.order is not None
    w = np.linspace(0.5, 2.0, B.shape[0])
    Hfull = (K + sp.diags(sigma * K.diagonal()) + B.T @ sp.diags(w) @ B).toarray()
    S = f.s
    o = f.order
    np.testing.assert_allclose(f._matrix(w).toarray(), np.tril(((S[:, None] * Hfull) * S[None, :])[np.ix_(o, o)]),
                               rtol=1e-13, atol=1e-15 * np.abs(Hfull).max())
    f.refactor(w)
    b = np.random.default_rng(5).standard_normal(n)
    x = f.solve(b)
    np.testing.assert_allclose(Hfull @ x, b, rtol=0, atol=1e-8 * np.abs(b).max())
    np.testing.assert_allclose(f.base, f._on(f.base).data)  # the in-place sum restored the kept values


def test_the_primal_hessian_shares_the_assembly_index_array():
    """``block_diag(K, I)`` on the indices the grid's assembly made with room after them: no
    copy of K's pattern; the same matrix as SciPy's block_diag; K's own view unchanged."""
    model = build_model(families.bed(6))
    K = csc_of_symmetric(model.K, model.symmetric)  # as the pipeline reads it: the assembly's arrays
    before = K.indices.copy()
    P = _with_identity(K, 5)
    assert np.shares_memory(P.indices, K.indices)
    np.testing.assert_array_equal(P.toarray(), sp.block_diag([K, sp.identity(5)]).toarray())
    np.testing.assert_array_equal(K.indices, before)
    # a K without that room: its indices copied, the same matrix
    K2 = sp.csc_matrix((K.data.copy(), K.indices.copy(), K.indptr.copy()), shape=K.shape)
    P2 = _with_identity(K2, 5)
    assert not np.shares_memory(P2.indices, K2.indices)
    np.testing.assert_array_equal(P2.toarray(), P.toarray())
