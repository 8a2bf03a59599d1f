"""A saddle-point system with more held rows than the dofs they act on is singular: it is said
with a SingularMatrixError, and nothing is printed (SuperLU factorised such a system
and its solve called BLAS with negative sizes: "On entry to DTRSV parameter number 6 had an
illegal value", 44 lines for 20 000 rigid supports on a 16² plate)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.sparse as sp

import plateqp as pq
from plateqp.errors import SingularMatrixError
from plateqp.linalg import solve_saddle


def test_more_rigid_rows_than_dofs_is_singular_and_silent(capfd):
    rng = np.random.default_rng(1)
    n, m = 12, 20
    Q = rng.standard_normal((n, n))
    K = sp.csc_matrix(Q @ Q.T + n * np.eye(n))
    B = sp.csr_matrix(rng.standard_normal((m, n)))
    with pytest.raises(SingularMatrixError, match="more rows than the dofs"):
        solve_saddle(K, B, np.zeros(m), np.ones(n), np.zeros(m))
    out = capfd.readouterr()
    assert "illegal value" not in out.out + out.err  # BLAS's xerbla writes to either


def test_twenty_thousand_rigid_supports_on_a_16x16_plate_print_nothing(capfd):
    """141 × 141 rigid posts under a free 16² plate: the KKT check's exact solve of its contact
    set (kkt.close_pairs_error) met the singular system."""
    xs = np.linspace(0.0, 1.0, 141)
    scene = pq.Scene(name="posts", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(16, 16),
                     loads=[pq.UniformLoad(10.0)], supports=[pq.Support(float(x), float(y)) for x in xs for y in xs])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pq.solve(scene, backend="clarabel", formulation="primal")
    assert res.status != pq.Status.OPTIMAL or res.kkt.ok
    out = capfd.readouterr()
    assert "illegal value" not in out.out + out.err  # BLAS's xerbla writes to either
