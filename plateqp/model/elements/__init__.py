"""Plate elements, one file each; ``ELEMENTS`` maps a scene's ``mesh.element`` to a class: the one
registry (the scene's choices, the mesh each element is assembled on).

Every element class names its ``cell_type`` ("quad": the structured rectangle grid,
:class:`plateqp.model.grid.Grid`; "triangle": a gmsh triangle mesh, :class:`plateqp.model.trimesh.TriMesh`), its
``node_dofs`` (the derivative orders (dx, dy) of w at each node, (0, 0) first, among (1, 0),
(0, 1), (1, 1)) and ``dof_names``. A new element is its module and one line below. ACM and BFS are
rectangles (:class:`RectElement`); DKT is a triangle (:mod:`plateqp.model.elements.dkt`).
"""

from .acm import ACM
from .base import RectElement, bending_matrix
from .bfs import BFS
from .dkt import DKT

ELEMENTS: dict[str, type] = {"acm": ACM, "bfs": BFS, "dkt": DKT}

__all__ = ["ACM", "BFS", "DKT", "ELEMENTS", "RectElement", "bending_matrix"]
