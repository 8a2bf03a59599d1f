"""Points on the boundary of a plate meshed in one part and mirrored (``[mesh] symmetry``): each
is a node on the mesh's boundary, in the kept part (embedded by gmsh's fragment, which splits the
boundary curve there) and in its mirror image, on a polygon and on a circle."""

from __future__ import annotations

import numpy as np
import pytest

from plateqp.model import trimesh
from plateqp.model.geometry import Circle, Domain, Polygon

pytest.importorskip("gmsh")


@pytest.fixture(autouse=True)
def nothing_kept():
    size, trimesh.MESHES.size = trimesh.MESHES.size, 0
    yield
    trimesh.MESHES.size = size


def _boundary_nodes(m):
    return m.nodes[np.unique(m.edges)]


@pytest.mark.parametrize("mirrors", [((0, 1.0),), ((0, 1.0), (1, 1.0))])
def test_points_on_a_square_s_sides_are_boundary_nodes(mirrors):
    square = Domain(Polygon(((0, 0), (2, 0), (2, 2), (0, 2))))
    pts = [(2.0, 0.3), (2.0, 1.7), (0.0, 0.3), (0.0, 1.7), (0.6, 0.0), (1.4, 0.0), (0.6, 2.0), (1.4, 2.0)]
    m = trimesh.mesh_domain(square, 1 / 8, pts, (), mirrors)
    edge = _boundary_nodes(m)
    for p in pts:
        assert np.hypot(*(edge - p).T).min() <= 1e-15
    # the mesh is its own mirror image: every node's image is a node
    for axis, c in mirrors:
        image = m.nodes.copy()
        image[:, axis] = 2 * c - image[:, axis]
        from scipy.spatial import cKDTree

        assert cKDTree(m.nodes).query(image)[0].max() <= 1e-14


def test_points_on_a_circle_of_a_mirrored_disc_are_boundary_nodes():
    disc = Domain(Circle(0.0, 0.0, 1.0))
    pts = [(np.cos(t), np.sin(t)) for t in (0.3, np.pi - 0.3, np.pi + 0.3, -0.3)]
    m = trimesh.mesh_domain(disc, 1 / 8, pts, (), ((0, 0.0), (1, 0.0)))
    edge = _boundary_nodes(m)
    for p in pts:
        assert np.hypot(*(edge - p).T).min() <= 1e-15
