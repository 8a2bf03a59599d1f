"""The rigid motions that move no active row, found without an m × m factor (a full SVD of a
bed's active rows asked for tens of GiB)."""

import tracemalloc

import numpy as np
import scipy.linalg

from plateqp.backends.pdas.motions import null_space


def test_null_space_matches_scipy_on_small_matrices():
    rng = np.random.default_rng(3)
    for m, k, rank in ((5, 3, 2), (2, 3, 2), (40, 3, 1), (10, 3, 3), (1, 3, 1)):
        X = rng.standard_normal((m, rank)) @ rng.standard_normal((rank, k))
        Z = null_space(X, 1e-10)
        ref = scipy.linalg.null_space(X, rcond=1e-10)
        assert Z.shape == (k - rank, k)
        assert np.allclose(X @ Z.T, 0.0, atol=1e-10 * np.abs(X).max())
        assert np.allclose(Z @ Z.T, np.eye(k - rank), atol=1e-12)
        # the same subspace as SciPy's: the projectors agree
        assert np.allclose(Z.T @ Z, ref @ ref.T, atol=1e-10)


def test_null_space_of_many_rows_allocates_no_square_factor():
    """20 000 rows of three rigid motions, one of them moving none: a full SVD would allocate
    20 000² doubles (3.2 GB); the QR route allocates about the matrix itself."""
    rng = np.random.default_rng(0)
    X = np.column_stack([rng.standard_normal(20_000), rng.standard_normal(20_000), np.zeros(20_000)])
    tracemalloc.start()
    Z = null_space(X, 1e-10)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert Z.shape == (1, 3) and abs(abs(Z[0, 2]) - 1.0) < 1e-12
    assert peak < 20 * X.nbytes  # 9.6 MB at most; the square factor alone would be 3.2 GB
