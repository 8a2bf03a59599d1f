"""The mesh generators by cell type, and a scene's mesh counted in cells a side (the studies by
mesh halving): the one place that picks the generator of a scene."""

from __future__ import annotations

import copy

from .elements import ELEMENTS
from .grid import Grid
from .scene import Scene
from .trimesh import TriMesh


#: The mesh generator of each ``cell_type`` (:data:`plateqp.model.elements.ELEMENTS`): its class
#: answers ``from_scene``, ``estimate_nodes``, ``describe``, and its meshes the names every mesh
#: answers (nodes, cells, locate, boundary_edges, assemble, tributary_areas, …).
GENERATORS = {"quad": Grid, "triangle": TriMesh}


def mesh_generator(scene: Scene):
    """The generator that meshes ``scene`` (:data:`GENERATORS`, by its element's cell type)."""
    return GENERATORS[ELEMENTS[scene.mesh.element].cell_type]


def mesh_cells(scene: Scene) -> tuple[int, int]:
    """The mesh of a scene as the studies by mesh halving count it, in cells a side: (nx, ny) of
    a grid; on triangles (n, n), n = L / h rounded (halving h doubles n)."""
    return mesh_generator(scene).cells_a_side(scene)


def with_cells(scene: Scene, nx: int, ny: int) -> Scene:
    """A validated copy of ``scene`` meshed nx × ny cells a side (:func:`mesh_cells`; on
    triangles the element size L / nx)."""
    sc = copy.deepcopy(scene)
    mesh_generator(scene).set_cells(sc, nx, ny)
    sc.validate()
    return sc


def start_cells(scene: Scene, cells: int = 4) -> tuple[int, int]:
    """The first mesh of a refinement ladder: ``cells`` on the shorter side, the other in
    proportion to the scene's own grid (on triangles (cells, cells))."""
    return mesh_generator(scene).start_cells(scene, cells)
