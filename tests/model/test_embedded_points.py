"""Many points embedded in a triangle mesh at once (plateqp.model.gmsh_mesh._embed, vectorised):
each distinct point a node, a point within the tolerance of an earlier one merged with it, a point
at a boundary vertex that vertex, and a point on the boundary between vertices a node too (its
curve split there: a point embedded in a curve would not be one)."""

from __future__ import annotations

import numpy as np
import pytest

from plateqp.model import trimesh
from plateqp.model.geometry import Domain, Polygon

pytest.importorskip("gmsh")

SQUARE = Domain(Polygon(((0, 0), (1, 0), (1, 1), (0, 1))))


@pytest.fixture(autouse=True)
def nothing_kept():
    size, trimesh.MESHES.size = trimesh.MESHES.size, 0
    yield
    trimesh.MESHES.size = size


def test_many_points_are_nodes_once_each():
    g = np.linspace(0.05, 0.95, 20)
    grid = [(float(x), float(y)) for x in g for y in g]
    extra = [(0.0, 0.0), (1.0, 0.3), (0.3, 0.0), (0.0, 0.71)]  # a vertex, points on the boundary's segments
    near = [(x + 1e-12, y - 1e-12) for x, y in grid[::7]]  # within the tolerance of earlier points
    m = trimesh.mesh_domain(SQUARE, 1 / 16, grid + extra + near + grid[:5])
    plain = trimesh.mesh_domain(SQUARE, 1 / 16, grid + extra)
    assert np.array_equal(m.nodes, plain.nodes) and np.array_equal(m.triangles, plain.triangles)
    for x, y in grid + extra:
        k = m.node_at(x, y, rtol=1e-9)
        assert k is not None and np.allclose(m.nodes[k], (x, y), atol=1e-15)
    on_edge = m.nodes[np.unique(m.edges)]
    for x, y in extra:
        assert np.hypot(*(on_edge - (x, y)).T).min() == 0.0
    # the boundary keeps its segments' numbering: the bottom side's edges are segment 0, and so on
    mid = 0.5 * (m.nodes[m.edges[:, 0]] + m.nodes[m.edges[:, 1]])
    assert np.all(m.segment[mid[:, 1] == 0.0] == 0) and np.all(m.segment[mid[:, 0] == 0.0] == 3)


def test_points_on_a_circle_are_nodes_on_the_circle():
    from plateqp.model.geometry import Circle

    disc = Domain(Circle(0.0, 0.0, 1.0), (Circle(0.2, 0.1, 0.3),))
    pts = [(np.cos(0.3), np.sin(0.3)), (0.2 + 0.3 * np.cos(2.0), 0.1 + 0.3 * np.sin(2.0))]
    m = trimesh.mesh_domain(disc, 1 / 12, pts)
    for x, y in pts:
        assert np.hypot(*(m.nodes[np.unique(m.edges)] - (x, y)).T).min() <= 1e-15


def test_two_points_within_the_tolerance_on_the_boundary_are_one_node():
    m = trimesh.mesh_domain(SQUARE, 1 / 16, [(0.3, 0.0), (0.3 + 1e-13, 0.0), (1.0, 0.4)])
    plain = trimesh.mesh_domain(SQUARE, 1 / 16, [(0.3, 0.0), (1.0, 0.4)])
    assert np.array_equal(m.nodes, plain.nodes) and np.array_equal(m.triangles, plain.triangles)
    lengths = np.hypot(*(m.nodes[m.edges[:, 1]] - m.nodes[m.edges[:, 0]]).T)
    assert lengths.min() > 0.1 / 16
