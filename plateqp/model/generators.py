"""The mesh generator of each element's cell type: the structured grid (:class:`~plateqp.model.grid.Grid`)
for "quad", gmsh's triangles (:class:`~plateqp.model.trimesh.TriMesh`) for "triangle".

A generator's class answers the scene-language rules of its meshes (``check_scene_fields``,
``cover``, ``all_held_holes``), ``from_scene``, ``estimate_nodes``, ``describe``; its meshes the
names every mesh answers (nodes, cells, locate, boundary_edges, assemble, tributary_areas, …).
Validation and assembly ask the generator, never which kind it is. The studies by mesh halving
count a scene's mesh in cells a side (:func:`mesh_cells`, :func:`with_cells`, :func:`start_cells`)."""

from __future__ import annotations

import copy

from ..errors import SceneError
from .elements import ELEMENTS
from .grid import Grid
from .trimesh import TriMesh

#: The mesh generator of each ``cell_type`` (:data:`plateqp.model.elements.ELEMENTS`).
GENERATORS = {"quad": Grid, "triangle": TriMesh}


def mesh_generator(scene):
    """The generator that meshes ``scene`` (:data:`GENERATORS`, by its element's cell type); an
    unknown element is a SceneError naming ``mesh.element``."""
    element = scene.mesh.element
    if not isinstance(element, str) or element not in ELEMENTS:
        raise SceneError(f"mesh.element: unknown element {element!r}; choose one of {tuple(ELEMENTS)}")
    return GENERATORS[ELEMENTS[element].cell_type]


def mesh_cells(scene) -> tuple[int, int]:
    """The mesh of a scene as the studies by mesh halving count it, in cells a side: (nx, ny) of
    a grid; on triangles (n, n), n = L / h rounded (halving h doubles n)."""
    return mesh_generator(scene).cells_a_side(scene)


def with_cells(scene, nx: int, ny: int):
    """A validated copy of ``scene`` meshed nx × ny cells a side (:func:`mesh_cells`; on
    triangles the element size L / nx)."""
    sc = copy.deepcopy(scene)
    mesh_generator(scene).set_cells(sc, nx, ny)
    sc.validate()
    return sc


def start_cells(scene, cells: int = 4) -> tuple[int, int]:
    """The first mesh of a refinement ladder: ``cells`` on the shorter side, the other in
    proportion to the scene's own grid (on triangles (cells, cells))."""
    return mesh_generator(scene).start_cells(scene, cells)
