"""The equilibrated copy of a matrix shares the matrix's own indices, and a solve leaves the
model's stiffness matrix as it was (its values, indices and pointers, to the bit)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import plateqp as pq
from plateqp.backends import available_backends
from plateqp.linalg import pattern
from plateqp.model.assembly import build_model
from plateqp.scenes import families


def _spd(n: int = 30, seed: int = 0) -> sp.csc_matrix:
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=0.2, random_state=rng, format="csc")
    return sp.csc_matrix(A + A.T + n * sp.eye(n))


def test_scaled_shares_indices_and_keeps_values():
    K = _spd()
    K.sort_indices()
    s = np.linspace(0.5, 2.0, K.shape[0])
    out = pattern.scaled(K, s, 3.0)
    # the same pattern, the arrays themselves (nothing mutates them), values of 3 S K S
    assert np.shares_memory(out.indices, K.indices)
    assert np.shares_memory(out.indptr, K.indptr)
    ref = (3.0 * sp.diags(s) @ K @ sp.diags(s)).toarray()
    np.testing.assert_allclose(out.toarray(), ref, rtol=1e-15, atol=0)
    assert not np.shares_memory(out.data, K.data)


def test_scaled_of_unsorted_matrix_copies_its_indices():
    K = sp.csc_matrix(_spd())
    K.indices[K.indptr[0]:K.indptr[1]] = K.indices[K.indptr[0]:K.indptr[1]][::-1].copy()
    K.data[K.indptr[0]:K.indptr[1]] = K.data[K.indptr[0]:K.indptr[1]][::-1].copy()
    K.has_sorted_indices = False
    dense = K.toarray()
    out = pattern.scaled(K, np.full(K.shape[0], 2.0))
    np.testing.assert_array_equal(out.toarray(), 4.0 * dense)
    assert not np.shares_memory(out.indices, K.indices)


@pytest.mark.parametrize("scene, options", [
    (lambda: families.grid_rigid(12, 3), {}),
    (lambda: families.grid_rigid(12, 3), {"backend": "pdas"}),
    (lambda: families.grid_rigid(12, 3), {"backend": "clarabel"}),
    (lambda: families.grid_rigid(12, 3), {"backend": "qpsolvers:piqp"}),
    (lambda: families.grid_elastic(12, 3), {}),
])
def test_solve_leaves_model_K_unchanged(scene, options):
    if options.get("backend", "").startswith("qpsolvers") and options["backend"] not in available_backends():
        pytest.skip("qpsolvers:piqp is not installed")
    sc = scene()
    model = build_model(sc)
    K = model.K
    before = (K.data.copy(), K.indices.copy(), K.indptr.copy())
    r = pq.solve(sc, model=model, **options)
    assert r.kkt.ok or options.get("backend") == "qpsolvers:piqp"  # PIQP stops short of the accuracy asked
    assert model.K is K
    for a, b in zip(before, (K.data, K.indices, K.indptr)):
        np.testing.assert_array_equal(a, b)
