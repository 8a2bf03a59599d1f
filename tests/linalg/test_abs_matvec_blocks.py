"""``|K| x`` by blocks of rows handed straight to SciPy's CSR kernel: the same numbers as
``abs(K) @ x`` (SciPy's own product), with no sparse matrix built per block."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from plateqp.linalg import pattern


def symmetric(n: int = 300, seed: int = 0) -> sp.csc_matrix:
    A = sp.random(n, n, density=0.05, random_state=seed, format="csc")
    A.data -= 0.5
    return sp.csc_matrix(A + A.T + sp.identity(n))


@pytest.mark.parametrize("chunk", [7, 100, 1 << 18])
@pytest.mark.parametrize("fmt", ["csc", "csr"])
def test_abs_matvec_builds_no_matrix_per_block(monkeypatch, chunk, fmt):
    K = symmetric().asformat(fmt)
    rng = np.random.default_rng(1)
    x, X = rng.standard_normal(K.shape[0]), rng.standard_normal((K.shape[0], 3))
    want, want_X = abs(K) @ x, abs(K) @ X

    def refuse(*args, **kwargs):
        raise AssertionError("a sparse matrix was built for a block")

    monkeypatch.setattr(pattern.sp, "csr_matrix", refuse)
    np.testing.assert_allclose(pattern.abs_matvec(K, x, chunk), want, rtol=1e-14)
    np.testing.assert_allclose(pattern.abs_matvec(K, X, chunk), want_X, rtol=1e-14)
