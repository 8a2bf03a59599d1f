"""The triangle mesh's assembled stiffness against facts independent of its route: the plain sum
of the element matrices (SciPy's COO duplicate summation), exact symmetry value for value (so the
model may say so and its CSR arrays serve as CSC), and a canonical CSR (sorted, no duplicates)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import plateqp as pq
from plateqp.model.assembly import build_model
pytest.importorskip("gmsh")


def scene(edges):
    holes = [{"circle": [0.6, 0.5, 0.15]}]
    return pq.Scene(name="tri", plate=pq.Plate(a=1.5, b=1.0, h=0.02, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=0.08), edges=edges, holes=holes,
                    loads=[pq.UniformLoad(1.0)], supports=[pq.Support(1.2, 0.3), pq.Support(0.2, 0.8)])


def coo_sum(model, pos, ncol):
    """Σ_e Aᵀ K_e A by SciPy's COO route: every element entry, duplicates summed."""
    mesh, el = model.grid, model.element
    Ke = el.cell_stiffness(mesh.nodes[mesh.triangles], model.scene.plate.D, model.scene.plate.nu)
    dofs = pos[(mesh.triangles[:, :, None] * 3 + np.arange(3)).reshape(len(mesh.triangles), -1)]
    rows, cols = np.repeat(dofs, 9, axis=1).ravel(), np.tile(dofs, (1, 9)).ravel()
    keep = (rows >= 0) & (cols >= 0)
    return sp.csr_matrix((Ke.ravel()[keep], (rows[keep], cols[keep])), shape=(ncol, ncol))


# free edges, w prescribed on a curve (a node's dofs partly fixed), every dof of a curve fixed
@pytest.mark.parametrize("edges", [{}, {"hole0": pq.Edge("simple")}, {"left": pq.Edge("clamped"), "top": pq.Edge("simple")}])
def test_triangle_stiffness_is_the_element_sum_exactly_symmetric_and_canonical(edges):
    model = build_model(scene(edges))
    K = model.K
    pos = np.full(model.n_full, -1)
    pos[model.free] = np.arange(model.n_free)
    ref = coo_sum(model, pos, model.n_free)
    assert K.shape == ref.shape
    assert abs(K - ref).max() <= 1e-14 * abs(ref).max()
    assert K.has_canonical_format and K.has_sorted_indices
    assert np.all(np.diff(K.indptr) > 0)
    KT = sp.csr_matrix(K.T)
    KT.sort_indices()
    assert np.array_equal(K.indptr, KT.indptr) and np.array_equal(K.indices, KT.indices)
    assert np.array_equal(K.data, KT.data)  # value for value, not just within rounding
    assert model.symmetric  # and the model says so, so the solve skips its transposition


def test_full_stiffness_has_every_dof_and_the_same_values():
    model = build_model(scene({"left": pq.Edge("clamped")}))
    Kf = model.K_full
    assert Kf.shape == (model.n_full, model.n_full)
    sub = Kf[model.free][:, model.free]
    assert abs(sub - model.K).max() == 0.0
