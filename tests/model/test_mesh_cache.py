"""The kept triangle meshes (plateqp.model.mesh_cache, plateqp.model.trimesh.MESHES): a plate solved
again is meshed once, any change of its geometry or of gmsh's options meshes anew (the mesh then
equals one made with nothing kept), and a kept mesh cannot be changed by its user."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import plateqp as pq
from plateqp.model import gmsh_mesh, trimesh
from plateqp.model.assembly import build_model

pytest.importorskip("gmsh")


def plate(**change) -> pq.Scene:
    """A disc with a hole on two posts under q and P; ``change`` replaces parts of it."""
    parts = dict(shape={"circle": [0.0, 0.0, 1.0]}, holes=[{"circle": [0.3, 0.1, 0.2]}], size=1 / 12,
                 supports=[pq.Support(-0.5, 0.0), pq.Support(0.0, -0.6)], P=(100.0, -0.2, 0.4), symmetry=None)
    parts.update(change)
    return pq.Scene(name="kept", plate=pq.Plate(shape=parts["shape"], h=0.02, E=1e7, nu=0.3), holes=parts["holes"],
                    mesh=pq.MeshSpec(element="dkt", size=parts["size"], symmetry=parts["symmetry"]),
                    edges={"all": pq.Edge("simple")}, supports=parts["supports"],
                    loads=[pq.UniformLoad(5.0), pq.PointLoad(*parts["P"])])


@pytest.fixture
def calls(monkeypatch):
    """The meshes gmsh makes during a test, counted (the kept ones emptied first and after)."""
    made = []
    real = gmsh_mesh.mesh_domain

    def counted(*args, **kw):
        made.append(args)
        return real(*args, **kw)

    monkeypatch.setattr(trimesh, "_gmsh_mesh_domain", counted)
    trimesh.MESHES.clear()
    yield made
    trimesh.MESHES.clear()


def fresh(scene) -> trimesh.TriMesh:
    """The scene's mesh with nothing kept."""
    size, trimesh.MESHES.size = trimesh.MESHES.size, 0
    try:
        return trimesh.TriMesh.from_scene(scene)
    finally:
        trimesh.MESHES.size = size


def same_mesh(a, b) -> bool:
    return (a.nodes.shape == b.nodes.shape and np.array_equal(a.nodes, b.nodes) and np.array_equal(a.triangles, b.triangles)
            and np.array_equal(a.edges, b.edges) and np.array_equal(a.boundary, b.boundary))


def test_a_plate_solved_again_is_meshed_once(calls):
    first = pq.solve(plate())
    again = pq.solve(plate(P=(250.0, -0.2, 0.4)))  # another load at the same point: the same mesh
    assert len(calls) == 1
    assert same_mesh(first.model.grid, again.model.grid)
    assert same_mesh(again.model.grid, fresh(plate()))
    size, trimesh.MESHES.size = trimesh.MESHES.size, 0
    try:  # the answer is the one a plate meshed anew gives, to the last bit
        anew = pq.solve(plate(P=(250.0, -0.2, 0.4)))
    finally:
        trimesh.MESHES.size = size
    assert np.array_equal(again.reactions, anew.reactions) and np.array_equal(again.u, anew.u)


@pytest.mark.parametrize("change", [
    {"shape": {"circle": [0.0, 0.0, 1.0 + 1e-12]}},                    # the outline, by a rounding
    {"holes": [{"circle": [0.3, 0.1 + 1e-9, 0.2]}]},                   # a cut-out moved
    {"holes": []},                                                     # a cut-out removed
    {"shape": {"polygon": [[-1, -1], [1, -1], [1, 1], [-1, 1]]}},      # another kind of outline
    {"size": 1 / 12 * (1 + 1e-12)},                                    # the element size
    {"supports": [pq.Support(-0.5, 0.0), pq.Support(0.0, -0.6 + 1e-9)]},  # a point that must be a node
    {"P": (100.0, -0.2, 0.41)},                                        # a point load moved
], ids=["radius", "hole-moved", "hole-removed", "polygon", "size", "support", "point-load"])
def test_a_changed_geometry_is_meshed_anew(calls, change):
    kept = trimesh.TriMesh.from_scene(plate())
    changed = trimesh.TriMesh.from_scene(plate(**change))
    assert len(calls) == 2
    assert same_mesh(trimesh.TriMesh.from_scene(plate()), kept) and len(calls) == 2  # the first is still kept
    assert same_mesh(changed, fresh(plate(**change)))
    if "size" not in change and "shape" not in change:
        assert not same_mesh(changed, kept)


def test_gmsh_options_and_symmetry_are_part_of_the_key(calls, monkeypatch):
    scene = plate(holes=[], supports=[], P=(100.0, 0.0, 0.0))
    whole = trimesh.TriMesh.from_scene(scene)
    monkeypatch.setattr(gmsh_mesh, "ALGORITHM", 5)
    delaunay = trimesh.TriMesh.from_scene(scene)
    monkeypatch.setattr(gmsh_mesh, "ALGORITHM", 6)
    mirrored = trimesh.TriMesh.from_scene(plate(holes=[], supports=[], P=(100.0, 0.0, 0.0), symmetry="xy"))
    assert len(calls) == 3
    assert not same_mesh(whole, delaunay) and not same_mesh(whole, mirrored)


def test_a_kept_mesh_cannot_be_changed_by_its_user(calls):
    mesh = trimesh.TriMesh.from_scene(plate())
    with pytest.raises(ValueError):
        mesh.nodes[0, 0] = 5.0
    with pytest.raises(ValueError):
        mesh.triangles[0] = mesh.triangles[1]
    other = trimesh.TriMesh.from_scene(plate())
    assert other is not mesh and same_mesh(other, mesh)
    other.size = 0.5  # its own object: a field set on one is not set on the other
    assert mesh.size == pytest.approx(1 / 12)


def test_the_kept_meshes_are_few_and_the_oldest_goes_first(calls):
    sizes = [1 / 4, 1 / 5, 1 / 6, 1 / 7]
    for s in sizes:
        trimesh.TriMesh.from_scene(plate(size=s, holes=[]))
    assert len(trimesh.MESHES) == trimesh.MESHES.size == 3
    trimesh.TriMesh.from_scene(plate(size=sizes[-1], holes=[]))  # kept
    trimesh.TriMesh.from_scene(plate(size=sizes[0], holes=[]))  # dropped: meshed again
    assert len(calls) == len(sizes) + 1


def test_the_stiffness_of_a_kept_mesh_is_assembled_for_each_plate(calls):
    """The kept mesh keeps its assembly's pattern too: another thickness on it gives the stiffness a
    fresh mesh gives, scaled by h³ exactly as D is."""
    thin = build_model(plate())
    thick_scene = plate()
    thick_scene.plate = dataclasses.replace(thick_scene.plate, h=0.04)
    thick = build_model(thick_scene)
    assert len(calls) == 1
    ratio = thick_scene.plate.D / plate().plate.D
    assert math.isclose(ratio, 8.0)
    assert abs(thick.K - ratio * thin.K).max() <= 1e-12 * abs(thick.K).max()
    trimesh.MESHES.clear()
    assert abs(build_model(thick_scene).K - thick.K).max() == 0.0
