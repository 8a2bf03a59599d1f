"""Triangle meshes from gmsh (plateqp.model.trimesh): true outlines, outward normals, embedded points,
local refinement, determinism, gmsh's state and output, and a clear error without gmsh."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.geometry import Circle, Domain, Polygon

gmsh = pytest.importorskip("gmsh")

from plateqp.model.trimesh import REFINE, mesh_domain  # noqa: E402

L_POLY = Polygon(((0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)))


@pytest.fixture(scope="module")
def disc():
    return mesh_domain(Domain(Circle(0.3, -0.2, 1.0)), 1 / 16, [(0.3, -0.2), (0.8, 0.1), (1.3, -0.2), (0.3, 0.8)])


def test_disc_mesh_is_valid_and_on_the_true_circle(disc):
    m = disc
    assert np.all(m.areas() > 0)  # counter-clockwise triangles
    r = np.hypot(m.nodes[m.edges.ravel(), 0] - 0.3, m.nodes[m.edges.ravel(), 1] + 0.2)
    assert np.abs(r - 1.0).max() < 1e-12  # boundary nodes on the circle itself
    # the inscribed polygon: area below π by about its chords' segments (n h² / 12 R, n ≈ 2π/h)
    assert 0 < math.pi - m.areas().sum() < 2 * math.pi * (1 / 16) ** 2 / 12 * 1.5
    # every boundary edge once, a closed loop: each boundary node in exactly two boundary edges
    assert np.all(np.bincount(m.edges.ravel())[np.unique(m.edges)] == 2)
    lengths = np.hypot(*(m.nodes[m.edges[:, 1]] - m.nodes[m.edges[:, 0]]).T)
    assert lengths.max() < 1.3 / 16 and lengths.min() > 0.5 / 16


def test_normals_are_outward_unit(disc):
    m = disc
    mid = 0.5 * (m.nodes[m.edges[:, 0]] + m.nodes[m.edges[:, 1]]) - [0.3, -0.2]
    radial = mid / np.hypot(*mid.T)[:, None]
    assert np.allclose(np.hypot(*m.normals.T), 1.0)
    assert np.einsum("ij,ij->i", m.normals, radial).min() > 0.999


def test_points_are_nodes_and_refined_around(disc):
    m = disc
    for x, y in [(0.3, -0.2), (0.8, 0.1), (1.3, -0.2), (0.3, 0.8)]:
        assert m.node_at(x, y) is not None
    k = m.node_at(0.8, 0.1)
    around = m.triangles[np.any(m.triangles == k, axis=1)]
    e = m.nodes[around] - m.nodes[around][:, [1, 2, 0]]
    assert np.hypot(*e.reshape(-1, 2).T).max() < 2.5 * REFINE / 16  # h/4 there, not h


def test_holes_and_segments():
    """An L-shape (exact: polygons mesh without error) with a round hole: area, boundaries, normals."""
    m = mesh_domain(Domain(L_POLY, (Circle(0.5, 0.5, 0.2),)), 0.1)
    assert m.areas().sum() == pytest.approx(3.0 - math.pi * 0.04, rel=2e-3)
    outer = m.boundary == 0
    assert set(m.segment[outer]) == set(range(6)) and set(m.boundary) == {0, 1}
    # hole normals point out of the plate: towards the hole's centre
    mid = 0.5 * (m.nodes[m.edges[~outer, 0]] + m.nodes[m.edges[~outer, 1]]) - 0.5
    assert np.all(np.einsum("ij,ij->i", m.normals[~outer], mid) < 0)
    # segment 2 is the edge y = 1 between x = 1 and 2, normal +y
    s2 = outer & (m.segment == 2)
    assert np.allclose(m.nodes[m.edges[s2].ravel(), 1], 1.0) and np.allclose(m.normals[s2], [0.0, 1.0])


def test_deterministic_quiet_and_finalised(capfd):
    d = Domain(L_POLY, (Circle(0.5, 0.5, 0.2),))
    a = mesh_domain(d, 0.2, [(1.5, 0.5), (0.5, 1.0)])
    b = mesh_domain(d, 0.2, [(1.5, 0.5), (0.5, 1.0)])
    assert np.array_equal(a.nodes, b.nodes) and np.array_equal(a.triangles, b.triangles)
    assert not gmsh.isInitialized()
    out = capfd.readouterr()
    assert out.out == "" and out.err == ""


def test_missing_gmsh_is_one_clear_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "gmsh", None)  # import gmsh now raises ImportError
    sc = pq.Scene(plate=pq.Plate(shape={"circle": [0, 0, 1.0]}), mesh=pq.MeshSpec(element="dkt", size=0.25),
                  loads=[pq.UniformLoad(1.0)], edges={"all": pq.Edge("clamped")})
    with pytest.raises(pq.SceneError, match=r"needs gmsh: pip install 'plateqp\[shapes\]'") as info:
        pq.solve(sc)
    assert "\n" not in str(info.value)


def test_a_gmsh_failure_is_one_clear_line(monkeypatch):
    import plateqp.model.gmsh_mesh as tm

    def fail(*args):
        raise Exception("Invalid boundary mesh (overlapping facets) on surface 1\nmore detail")

    monkeypatch.setattr(tm, "_mesh", fail)
    with pytest.raises(pq.SceneError, match=r"^mesh: gmsh could not mesh the plate at size 0.5 \(Invalid boundary") as info:
        mesh_domain(Domain(L_POLY), 0.5)
    assert "\n" not in str(info.value) and not gmsh.isInitialized()
