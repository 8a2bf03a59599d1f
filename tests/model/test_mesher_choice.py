"""The choice of gmsh's 2-D algorithm (plateqp.model.gmsh_mesh.ALGORITHM, Frontal-Delaunay): its
meshes keep the quality measured for it (benchmarks/README.md, "Meshers": no triangle with an
angle under 20° on the bench disc, the square with a hole or a mirrored disc), the verification
cases on triangles pass on it, and its answers agree with gmsh's Delaunay (the algorithm measured
against it) within the discretisation error of both."""

from __future__ import annotations

import math

import numpy as np
import pytest

import plateqp as pq
from plateqp.model import gmsh_mesh
from plateqp.model.trimesh import TriMesh
from plateqp.studies.verify import _solve, cases, run_case

gmsh = pytest.importorskip("gmsh")

#: the smallest angle measured on every default mesh (R/16 … R/128 disc, square with a hole): 23°
MIN_ANGLE = 20.0


def min_angles(nodes, tris) -> np.ndarray:
    """(nt,) each triangle's smallest angle in degrees."""
    p = nodes[tris]
    out = []
    for i in range(3):
        u, w = p[:, (i + 1) % 3] - p[:, i], p[:, (i + 2) % 3] - p[:, i]
        out.append(np.degrees(np.arctan2(np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]), (u * w).sum(axis=1))))
    return np.min(out, axis=0)


def posts_disc(n: int, symmetry: str | None = None) -> pq.Scene:
    """The benchmark's disc: R = 1 on 12 posts at r = 0.7, q and an off-centre P (or a central P
    when mirrored, to stay symmetric)."""
    posts = [pq.Support(0.7 * math.cos(math.pi * k / 6), 0.7 * math.sin(math.pi * k / 6)) for k in range(12)]
    point = pq.PointLoad(100.0, 0.0, 0.0) if symmetry else pq.PointLoad(100.0, 0.1, 0.2)
    return pq.Scene(name="disc", plate=pq.Plate(shape={"circle": [0.0, 0.0, 1.0]}, h=0.02, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=1.0 / n, symmetry=symmetry), edges={"all": pq.Edge("simple")},
                    loads=[pq.UniformLoad(5.0), point], supports=posts)


def holed_square(n: int) -> pq.Scene:
    return pq.Scene(name="holed", plate=pq.Plate(shape={"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]]}, h=0.02, E=1e7, nu=0.3),
                    holes=[{"circle": [0.5, 0.5, 0.2]}], mesh=pq.MeshSpec(element="dkt", size=1.0 / n),
                    edges={"all": pq.Edge("simple"), "hole0": pq.Edge("free")}, loads=[pq.UniformLoad(1.0)])


@pytest.fixture
def delaunay(monkeypatch):
    """gmsh's Delaunay (algorithm 5) in place of the default for one test."""
    monkeypatch.setattr(gmsh_mesh, "ALGORITHM", 5)


def test_the_default_is_frontal_delaunay():
    assert gmsh_mesh.ALGORITHM == 6


@pytest.mark.parametrize("scene", [posts_disc(16), posts_disc(16, symmetry="xy"), holed_square(32)],
                         ids=["disc", "mirrored-disc", "holed-square"])
def test_no_triangle_has_an_angle_under_the_measured_bound(scene):
    mesh = TriMesh.from_scene(scene)
    assert min_angles(mesh.nodes, mesh.triangles).min() >= MIN_ANGLE


def test_the_algorithm_is_the_one_gmsh_runs(delaunay):
    """The constant is what gmsh is told: Delaunay's mesh of the same disc is another mesh."""
    other = TriMesh.from_scene(posts_disc(16))
    gmsh_mesh.ALGORITHM = 6
    default = TriMesh.from_scene(posts_disc(16))
    assert len(other.nodes) != len(default.nodes)


@pytest.mark.parametrize("name", ["disc-clamped-uniform", "disc-simple-point", "annulus-clamped"])
def test_verification_cases_pass_on_small_meshes(name):
    case = next(c for c in cases() if c.name == name)
    rows = run_case(case, quick=True)
    assert rows[-1].error <= case.tol
    assert rows[-1].error < rows[0].error  # the error falls as the mesh halves


@pytest.mark.parametrize("name", ["disc-simple-uniform", "annulus-simple"])
def test_agrees_with_delaunay_within_discretisation_error(name, monkeypatch):
    """On one mesh size, Frontal-Delaunay's and Delaunay's answers differ by no more than their
    errors against the closed form put together (and both meshes converge to it)."""
    case = next(c for c in cases() if c.name == name)
    ref = float(case.reference())
    got = {}
    for algorithm in (6, 5):
        monkeypatch.setattr(gmsh_mesh, "ALGORITHM", algorithm)
        got[algorithm] = float(case.value(_solve(case, case.scene(16))))
    errors = [abs(v - ref) for v in got.values()]
    assert abs(got[6] - got[5]) <= sum(errors)
    assert max(errors) <= case.tol * abs(ref)
