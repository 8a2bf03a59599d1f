"""Plate elements, one file each; ``ELEMENTS`` maps a scene's ``mesh.element`` to a class."""

from .acm import ACM
from .base import RectElement, bending_matrix
from .bfs import BFS

ELEMENTS: dict[str, type[RectElement]] = {"acm": ACM, "bfs": BFS}

__all__ = ["ACM", "BFS", "ELEMENTS", "RectElement", "bending_matrix"]
