"""The nodal-average operator on a mesh of equal cells keeps one cell's corner matrix (not one
per cell), and its nodal fields are the plain means, over the cells around each node, of each
cell's corner values, computed here cell by cell from the element; on a mesh of unequal
cells (triangles) the same."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.model.recovery import CURVATURE_QUANTITIES, from_curvatures, nodal_operator
from plateqp.scenes.families import grid_elastic


def reference(model, u, plate, quantity):
    """Each cell's corner values from the element, averaged per node with np.add.at."""
    mesh = model.grid
    xy = mesh.nodes[mesh.cells]
    C = model.element.corner_curvatures(xy)  # (ncell, corners, 3, ndof)
    kappa = np.einsum("cvkd,cd->kcv", C, u[model.cell_dofs])
    vals = from_curvatures(plate, quantity, *kappa)
    n = len(mesh.plate_node_ids)
    total, count = np.zeros(n), np.zeros(n)
    np.add.at(total, mesh.cells.ravel(), vals.ravel())
    np.add.at(count, mesh.cells.ravel(), 1.0)
    out = np.full(n, np.nan)
    out[count > 0] = total[count > 0] / count[count > 0]
    return out


def held_bytes(op) -> int:
    """The bytes of the arrays an operator keeps (its model aside)."""
    size = 0
    for key, v in vars(op).items():
        if key == "model":
            continue
        if sp.issparse(v):
            v = v.tocsr()
            size += v.data.nbytes + v.indices.nbytes + v.indptr.nbytes
        elif isinstance(v, np.ndarray):
            size += v.nbytes
    return size


@pytest.mark.parametrize("element", ["acm", "dkt"])
@pytest.mark.parametrize("quantity", CURVATURE_QUANTITIES)
def test_nodal_fields_are_the_means_of_the_cells_corner_values(element, quantity):
    scene = grid_elastic(8, 2, element)
    model = build_model(scene)
    u = np.random.default_rng(3).standard_normal(model.n_full)
    got = nodal_operator(model)(u, scene.plate, quantity)
    want = reference(model, u, scene.plate, quantity)
    assert np.array_equal(np.isnan(got), np.isnan(want))
    ok = ~np.isnan(want)
    assert np.abs(got[ok] - want[ok]).max() <= 1e-12 * np.abs(want[ok]).max()


def test_equal_cells_keep_one_corner_matrix():
    """64² cells: one cell's corner matrix (4 corners × 3 curvatures × 12 dofs) is kept, not
    4096 copies of it (7 MB as a sparse operator)."""
    scene = grid_elastic(64, 5)
    model = build_model(scene)
    op = nodal_operator(model)
    op(np.ones(model.n_full), scene.plate, "s1")
    cells = model.grid.cells.shape[0]
    assert held_bytes(op) < cells * 4 * 3 * 12 * 8 / 4, f"{held_bytes(op)} bytes kept"
