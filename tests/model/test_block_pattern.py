"""The triangle assembly's scatter pattern (plateqp.model.blocks) and the batched DKT stiffness
(plateqp.model.elements.dkt): a pattern worked out once sums any cells' matrices as SciPy's COO
route does, exactly symmetric and canonical, whatever dofs are dropped; a mesh keeps its pattern
for the next assembly and works out another for other kept dofs; the element matrices, made in
chunks, are the quadrature of Bᵀ D_b B triangle by triangle."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from plateqp.model import trimesh
from plateqp.model.blocks import block_pattern
from plateqp.model.elements import DKT
from plateqp.model.elements.base import bending_matrix
from plateqp.model.elements.dkt import CHUNK, MID_POINTS, MID_WEIGHTS
from plateqp.model.geometry import Circle, Domain

pytest.importorskip("gmsh")


@pytest.fixture(scope="module")
def mesh():
    size, trimesh.MESHES.size = trimesh.MESHES.size, 0
    try:
        return trimesh.mesh_domain(Domain(Circle(0.0, 0.0, 1.0), (Circle(0.3, 0.2, 0.25),)), 1 / 10, [(-0.4, -0.3)])
    finally:
        trimesh.MESHES.size = size


def cross(u, v) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def symmetric_matrices(nc: int, seed: int) -> np.ndarray:
    a = np.random.default_rng(seed).standard_normal((nc, 9, 9))
    return a + np.swapaxes(a, 1, 2)  # exactly symmetric


def coo(Ke, cells, pos, ncol) -> sp.csr_matrix:
    dofs = pos[(cells[:, :, None] * 3 + np.arange(3)).reshape(len(cells), -1)]
    rows, cols = np.repeat(dofs, 9, axis=1).ravel(), np.tile(dofs, (1, 9)).ravel()
    keep = (rows >= 0) & (cols >= 0)
    return sp.csr_matrix((Ke.ravel()[keep], (rows[keep], cols[keep])), shape=(ncol, ncol))


def positions(n_dofs: int, dropped) -> tuple[np.ndarray, int]:
    kept = np.ones(n_dofs, dtype=bool)
    kept[list(dropped)] = False
    pos = np.full(n_dofs, -1)
    pos[kept] = np.arange(kept.sum())
    return pos, int(kept.sum())


@pytest.mark.parametrize("drop", ["none", "some w", "whole nodes"])
def test_one_pattern_sums_any_matrices_as_scipy_does(mesh, drop):
    n = len(mesh.nodes)
    dropped = {"none": [], "some w": list(range(0, 3 * n, 7 * 3)), "whole nodes": list(range(3 * 5, 3 * 40))}[drop]
    pos, ncol = positions(3 * n, dropped)
    pattern = block_pattern(mesh.triangles, n, 3, pos, ncol)
    for seed in (1, 2):  # the same pattern, two sets of matrices
        Ke = symmetric_matrices(len(mesh.triangles), seed)
        K = pattern.assemble(Ke)
        ref = coo(Ke, mesh.triangles, pos, ncol)
        assert K.shape == ref.shape and K.nnz == ref.nnz
        assert abs(K - ref).max() <= 1e-13 * abs(ref).max()
        row = np.repeat(np.arange(ncol), np.diff(K.indptr))
        assert np.all(np.diff(K.indices)[row[1:] == row[:-1]] > 0)  # canonical: each row's columns increase
        KT = sp.csr_matrix(K.T)
        KT.sort_indices()
        assert np.array_equal(K.indptr, KT.indptr) and np.array_equal(K.indices, KT.indices)
        assert np.array_equal(K.data, KT.data)


def test_a_mesh_keeps_its_pattern_for_the_same_dofs_only(mesh, monkeypatch):
    made = []
    real = trimesh.block_pattern
    monkeypatch.setattr(trimesh, "block_pattern", lambda *a: made.append(a) or real(*a))
    m = trimesh.TriMesh(*(getattr(mesh, f) for f in ("nodes", "triangles", "edges", "normals", "boundary", "segment",
                                                     "size", "domain")))
    n = 3 * len(m.nodes)
    pos, ncol = positions(n, range(0, n, 9))
    el = DKT()
    K1 = m.assemble(el, 1.0, 0.3, pos, ncol)
    K2 = m.assemble(el, 2.0, 0.25, pos, ncol)
    assert len(made) == 1
    Ke2 = el.stiffness(m.nodes[m.triangles], 2.0, 0.25)
    assert abs(K2 - coo(Ke2, m.triangles, pos, ncol)).max() <= 1e-13 * abs(K2).max()
    assert K1.shape == K2.shape
    other, ncol2 = positions(n, range(1, n, 5))
    K3 = m.assemble(el, 2.0, 0.25, other, ncol2)
    assert len(made) == 2
    assert abs(K3 - coo(Ke2, m.triangles, other, ncol2)).max() <= 1e-13 * abs(K3).max()


def test_the_chunked_stiffness_is_the_quadrature_triangle_by_triangle():
    """More triangles than a chunk (the last chunk short): each element matrix is
    Σ_p w_p A B_pᵀ D_b B_p with B_p from the element's own curvature matrix, exactly symmetric."""
    rng = np.random.default_rng(3)
    nt = CHUNK + 7
    xy = np.array([[0.0, 0.0], [1.0, 0.0], [0.3, 0.8]]) + 0.3 * rng.standard_normal((nt, 3, 2))
    xy[:, [1, 2]] = np.where((cross(xy[:, 1] - xy[:, 0], xy[:, 2] - xy[:, 0]) < 0)[:, None, None],
                             xy[:, [2, 1]], xy[:, [1, 2]])  # counter-clockwise
    el = DKT()
    D, nu = 3.5, 0.27
    K = el.stiffness(xy, D, nu)
    B = el.curvature_matrix(xy, MID_POINTS)  # (nt, 3 points, 3, 9)
    area = 0.5 * cross(xy[:, 1] - xy[:, 0], xy[:, 2] - xy[:, 0])
    ref = np.einsum("p,tpik,ij,tpjl->tkl", MID_WEIGHTS, B, bending_matrix(D, nu), B) * area[:, None, None]
    assert np.abs(K - ref).max() <= 1e-13 * np.abs(ref).max()
    assert np.array_equal(K, np.swapaxes(K, 1, 2))
    assert np.array_equal(el.stiffness(xy[-3:], D, nu), K[-3:])  # a triangle's matrix does not depend on its chunk
