"""CHOLMOD (through its C API) reads 64-bit indices: the matrix it factorises holds one copy of
its pattern, at that width, not a 32-bit copy beside a widened one; the factor is unchanged."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from plateqp.backends.pdas.factor import SpringFactor
from plateqp.linalg.cholmod import lower
from plateqp.model.assembly import build_model
from plateqp.scenes import families


def test_triangle_holds_the_wide_pattern_after_analysis(seam_cholesky):
    chol = seam_cholesky
    model = build_model(families.grid_rigid(10, 3))
    K = sp.csc_matrix(model.K)
    s = 1.0 / np.sqrt(K.diagonal())
    A = lower(K, s, upper=chol.upper)
    ref = A.toarray()
    chol.analyse(A)
    assert A.indices.dtype == np.int64 and A.indptr.dtype == np.int64
    p, i = chol.direct._indices(A)
    assert np.shares_memory(A.indices, i) and np.shares_memory(A.indptr, p)
    np.testing.assert_array_equal(A.toarray(), ref)  # the same matrix, entry for entry
    chol.factor(A)
    b = np.arange(1.0, K.shape[0] + 1)
    Ssym = (ref + ref.T - np.diag(np.diag(ref)))
    x = chol.solve(b)
    np.testing.assert_allclose(Ssym @ x, b, rtol=1e-9, atol=1e-9 * np.abs(b).max())


def test_spring_factor_hands_cholmod_its_own_wide_pattern(seam_cholesky):
    chol = seam_cholesky
    model = build_model(families.grid_rigid(10, 3))
    K = sp.csc_matrix(model.K)
    B = sp.csr_matrix(model.contacts.B)
    f = SpringFactor(K, B, K.diagonal(), np.ones(B.shape[0]), 0.0, "cvxopt")
    assert f.chol is not None and f.chol.direct is not None
    w = np.linspace(0.0, 2.0, B.shape[0])
    H = f._matrix(w)
    assert H.indices.dtype == np.int64 and np.shares_memory(H.indices, f.indices)
    # H(w) = S (K + Bᵀ diag(w) B) S, one triangle of it
    S = sp.diags(f.s)
    full = (S @ (K + B.T @ sp.diags(w) @ B) @ S).toarray()
    if f.order is not None:  # kept permuted, its lower triangle (plateqp.linalg.Cholesky.analyse_permuted)
        o = f.order
        assert sorted(o.tolist()) == list(range(K.shape[0]))
        tri = np.tril(full[np.ix_(o, o)])
    else:
        tri = np.triu(full) if chol.upper else np.tril(full)
    np.testing.assert_allclose(H.toarray(), tri, rtol=1e-12, atol=1e-14 * np.abs(full).max())
