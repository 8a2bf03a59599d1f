"""Plate elements, one file each; ``ELEMENTS`` maps a scene's ``mesh.element`` to a class.

ACM and BFS are rectangles (:class:`RectElement`); DKT is a triangle (:mod:`plateqp.elements.dkt`,
assembled by :mod:`plateqp.triassembly`).
"""

from .acm import ACM
from .base import RectElement, bending_matrix
from .bfs import BFS
from .dkt import DKT

ELEMENTS: dict[str, type] = {"acm": ACM, "bfs": BFS, "dkt": DKT}

__all__ = ["ACM", "BFS", "DKT", "ELEMENTS", "RectElement", "bending_matrix"]
