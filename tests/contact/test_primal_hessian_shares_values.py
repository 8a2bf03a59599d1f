"""The primal QP's Hessian ``block_diag(K, I)`` of a plate on springs holds K's scaled values in
the array they were scaled into (room is left there for the springs' identity): no copy of them."""

import numpy as np
import scipy.sparse as sp

from plateqp.contact.formulations import Primal
from plateqp.contact.scaling import Scaled
from plateqp.model.assembly import build_model
from plateqp.scenes import families


def test_the_primal_hessian_reuses_the_scaled_values_and_is_block_diag_of_k_and_i():
    model = build_model(families.bed(12))
    data = Scaled.from_model(model)
    K = data.K.copy()
    values = data.K.data
    form = Primal(data)
    P = form.qp.P
    ne = int(np.count_nonzero(data.rho > 0))
    assert ne > 0
    assert np.shares_memory(P.data, values)
    ref = sp.block_diag([K, sp.identity(ne)], format="csc")
    assert abs(P - ref).max() == 0.0 and P.shape == ref.shape
    assert abs(data.K - K).max() == 0.0  # K itself unchanged


def test_without_springs_the_hessian_is_k_itself():
    data = Scaled.from_model(build_model(families.grid_rigid(8, 3)))
    K = data.K
    form = Primal(data)
    assert form.qp.P is K or np.shares_memory(form.qp.P.data, K.data)


def test_the_primal_rows_are_b_beside_the_springs_columns():
    """``G = [B  T]`` with T's column j holding −√ρ at spring row j: against SciPy's hstack, on a
    bed (every row a spring), on posts with some elastic (a few columns) and on rigid posts (none),
    stored entries and their order included."""
    scenes = [families.bed(10), families.grid_elastic(10, 3), families.grid_rigid(10, 3)]
    mixed = families.grid_rigid(10, 3)
    mixed.supports[1].stiffness = 1e6
    mixed.supports[4].stiffness = 1e7
    for scene in [*scenes, mixed]:
        data = Scaled.from_model(build_model(scene))
        el = np.flatnonzero(data.rho > 0)
        T = sp.csr_matrix((-np.sqrt(data.rho[el]), (el, np.arange(el.size))), shape=(data.m, el.size))
        want = sp.hstack([data.B, T], format="csc")
        G = Primal(data).qp.G
        assert G.shape == want.shape
        assert np.array_equal(G.indptr, want.indptr) and np.array_equal(G.indices, want.indices)
        assert np.array_equal(G.data, want.data)
