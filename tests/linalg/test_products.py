"""Products remembered inside one solve (plateqp.linalg.products).

References: SciPy's own product K @ x (the value every call must equal), and the count of the
products computed (a fact of the code path, read through the ``compute`` callable).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from plateqp.linalg.products import remembered, remembering, times


def matrix(n=40, seed=0) -> sp.csc_matrix:
    A = sp.random(n, n, density=0.2, random_state=seed, format="csc")
    return sp.csc_matrix(A + A.T + n * sp.eye(n))


def counted(K, x, kind="K"):
    calls = []

    def compute():
        calls.append(1)
        return K @ x

    return remembered(K, x, kind, compute), len(calls)


def test_equal_vectors_on_one_matrix_are_one_product_inside_the_scope():
    K = matrix()
    x = np.random.default_rng(1).standard_normal(K.shape[0])
    with remembering():
        y1, n1 = counted(K, x)
        y2, n2 = counted(K, x.copy())  # equal values, another array
        y3, n3 = counted(sp.csc_matrix(K), x)  # a matrix made from K: views of its arrays
    assert (n1, n2, n3) == (1, 0, 0)
    np.testing.assert_array_equal(y1, K @ x)
    assert y2 is y1 and y3 is y1


def test_a_changed_vector_or_another_matrix_is_a_new_product():
    K = matrix()
    x = np.random.default_rng(2).standard_normal(K.shape[0])
    with remembering():
        counted(K, x)
        x[3] += 1e-12  # changed in place: a new vector
        y, n = counted(K, x)
        assert n == 1
        np.testing.assert_array_equal(y, K @ x)
        other = K.copy()  # the same values in other memory: not known to be the same matrix
        assert counted(other, x)[1] == 1
        assert counted(K, x, kind="abs")[1] == 1  # another product of K, by name


def test_outside_the_scope_every_product_is_computed():
    K = matrix()
    x = np.ones(K.shape[0])
    assert counted(K, x)[1] == 1 and counted(K, x)[1] == 1
    with remembering():
        counted(K, x)
    assert counted(K, x)[1] == 1  # the scope's products are dropped when it ends
    np.testing.assert_array_equal(times(K, x), K @ x)


def test_a_remembered_product_cannot_be_changed_by_its_reader():
    K = matrix()
    x = np.ones(K.shape[0])
    with remembering():
        y = times(K, x)
        with pytest.raises(ValueError):
            y += 1.0
        np.testing.assert_array_equal(times(K, x), K @ x)


def test_a_dead_matrix_is_never_mistaken_for_a_new_one_in_its_memory():
    x = np.ones(40)
    with remembering():
        for seed in range(20):  # each matrix freed before the next is made (memory may be reused)
            K = matrix(seed=seed)
            np.testing.assert_allclose(times(K, x), K @ x, rtol=1e-15)
            del K
