"""Large triangle meshes are gmsh's mesh at twice the size, each triangle split in four
(plateqp.model.gmsh_mesh.SPLITS, SPLIT_FROM): the split mesh holds the coarse mesh's nodes and
four times its triangles, keeps its outline on the true curve, its points as nodes and its
smallest angle, and answers the closed forms as closely as a mesh made at the size asked."""

from __future__ import annotations

import math

import numpy as np
import pytest

from plateqp.model import gmsh_mesh, trimesh
from plateqp.model.geometry import Circle, Domain, Polygon
from plateqp.studies.verify import _solve, cases

pytest.importorskip("gmsh")

from test_mesher_choice import MIN_ANGLE, min_angles  # noqa: E402

#: an L with a square opening and a round hole
L_HOLED = Domain(Polygon(((0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2))),
                 (Polygon(((0.2, 0.2), (0.6, 0.2), (0.6, 0.5), (0.2, 0.5))), Circle(1.5, 0.5, 0.2)))
ANNULUS = Domain(Circle(0.0, 0.0, 1.0), (Circle(0.2, 0.1, 0.3),))


@pytest.fixture(autouse=True)
def nothing_kept():
    """Every mesh here made by gmsh (none handed back from the kept ones)."""
    size, trimesh.MESHES.size = trimesh.MESHES.size, 0
    yield
    trimesh.MESHES.size = size


def mesh(domain, h, points=(), split=True, monkeypatch=None):
    if not split:
        monkeypatch.setattr(gmsh_mesh, "SPLIT_FROM", math.inf)
    try:
        return trimesh.mesh_domain(domain, h, points)
    finally:
        if not split:
            monkeypatch.undo()


def large(domain) -> float:
    """A size at which ``domain``'s mesh is split."""
    return math.sqrt(gmsh_mesh.NODES_PER_AREA * domain.area / gmsh_mesh.SPLIT_FROM) * 0.95


@pytest.mark.parametrize("domain, points", [(ANNULUS, [(-0.5, 0.0), (0.5, -0.5)]), (L_HOLED, [(0.8, 0.8), (0.3, 1.5)])],
                         ids=["annulus", "holed-L"])
def test_a_large_mesh_is_the_mesh_at_twice_the_size_split_in_four(domain, points, monkeypatch):
    assert domain.covers(*np.array(points).T).all()
    h = large(domain)
    fine = mesh(domain, h, points)
    coarse = mesh(domain, 2 * h, points, split=False, monkeypatch=monkeypatch)
    assert all(fine.node_at(x, y) is not None for x, y in points)
    assert len(fine.triangles) == 4 * len(coarse.triangles)
    assert len(fine.edges) == 2 * len(coarse.edges)
    # every coarse node is a node of the fine mesh, where it was
    found = {tuple(p) for p in fine.nodes}
    assert all(tuple(p) in found for p in coarse.nodes)
    assert np.isclose(fine.areas().sum(), coarse.areas().sum(), rtol=0.01)
    assert np.all(fine.areas() > 0)
    assert min_angles(fine.nodes, fine.triangles).min() >= min(MIN_ANGLE, min_angles(coarse.nodes, coarse.triangles).min() - 1e-6)


def test_a_split_mesh_keeps_its_outline_on_the_circle_and_its_points_as_refined_nodes():
    domain = Domain(Circle(0.3, -0.2, 1.0))
    points = [(0.3, -0.2), (0.8, 0.1), (0.3, 0.5)]
    h = large(domain)
    m = mesh(domain, h, points)
    assert gmsh_mesh.NODES_PER_AREA * domain.area / h**2 >= gmsh_mesh.SPLIT_FROM
    r = np.hypot(m.nodes[m.edges.ravel(), 0] - 0.3, m.nodes[m.edges.ravel(), 1] + 0.2)
    assert np.abs(r - 1.0).max() < 1e-12
    for x, y in points:
        k = m.node_at(x, y)
        assert k is not None
        around = m.triangles[np.any(m.triangles == k, axis=1)]
        e = m.nodes[around] - m.nodes[around][:, [1, 2, 0]]
        assert np.hypot(*e.reshape(-1, 2).T).max() < 2.5 * gmsh_mesh.REFINE * h  # refined there: about h / 4, not h


def test_a_small_mesh_is_not_split(monkeypatch):
    domain = Domain(Circle(0.0, 0.0, 1.0))
    h = large(domain) * 1.2
    default = mesh(domain, h)
    unsplit = mesh(domain, h, split=False, monkeypatch=monkeypatch)
    assert np.array_equal(default.nodes, unsplit.nodes) and np.array_equal(default.triangles, unsplit.triangles)


@pytest.mark.parametrize("name", ["disc-clamped-uniform", "disc-simple-point", "annulus-clamped", "l-shape-clamped"])
def test_the_split_mesh_answers_the_closed_form_as_closely_as_the_mesh_at_the_size_asked(name, monkeypatch):
    """At R/32 (split by default): within the case's tolerance, and its error no more than a
    quarter above the unsplit mesh's (measured: 0.9 to 1.1 times it, docs/guide/shapes.md)."""
    case = next(c for c in cases() if c.name == name)
    scene = case.scene(32)
    assert trimesh.estimate_nodes(scene) >= gmsh_mesh.SPLIT_FROM
    ref = float(case.reference())
    split = abs(float(case.value(_solve(case, scene))) - ref) / abs(ref)
    monkeypatch.setattr(gmsh_mesh, "SPLIT_FROM", math.inf)
    whole = abs(float(case.value(_solve(case, case.scene(32)))) - ref) / abs(ref)
    assert split <= case.tol
    assert split <= 1.25 * whole
