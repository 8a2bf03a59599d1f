"""The mesh generator of each element's cell type: the structured grid (:class:`~plateqp.model.grid.Grid`)
for "quad", gmsh's triangles (:class:`~plateqp.model.trimesh.TriMesh`) for "triangle".

A generator's class answers the scene-language rules of its meshes (``check_scene_fields``,
``cover``, ``all_held_holes``), ``from_scene``, ``estimate_nodes``, ``describe``; its meshes the
names every mesh answers (nodes, cells, locate, boundary_edges, assemble, tributary_areas, …).
Validation and assembly ask the generator, never which kind it is."""

from __future__ import annotations

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
