"""The triangle meshes of the last few geometries, kept for the next solve of the same plate.

A sweep or a study that solves one plate again and again (another load, gap, stiffness or
thickness) meshes the same domain at the same size each time; :class:`MeshCache` hands back the
mesh made the first time. Its key is the geometry's exact description: the domain (outer
boundary and cut-outs, every coordinate as given), the element size, the points that must be
nodes, the lines that must be edges, the mirror lines, and gmsh's options that shape the mesh
(:mod:`plateqp.model.gmsh_mesh`); floats are compared exactly, so any change of the geometry,
however small, makes a new mesh. A kept mesh's arrays are read-only: nothing can change the
mesh a later solve is handed.
"""

from __future__ import annotations

import dataclasses
import threading
from collections import OrderedDict
from collections.abc import Callable

import numpy as np


def _floats(values) -> tuple:
    """A nested sequence of numbers as nested tuples of floats (NumPy scalars and ints alike)."""
    if isinstance(values, (list, tuple, np.ndarray)):
        return tuple(_floats(v) for v in values)
    return float(values)


def mesh_key(domain, size: float, points=(), lines=(), mirrors=(), options: tuple = ()) -> tuple | None:
    """The exact description of a mesh to make, or None when the domain is not hashable (then it
    is not kept)."""
    key = (domain, float(size), _floats(list(points)), _floats(list(lines)),
           tuple((int(axis), float(c)) for axis, c in mirrors), options)
    try:
        hash(key)
    except TypeError:
        return None
    return key


class MeshCache:
    """The meshes of the last ``size`` geometries (least recently used dropped first), keyed by
    :func:`mesh_key`. ``size = 0`` keeps none. Thread-safe; :meth:`clear` empties it."""

    def __init__(self, size: int = 3) -> None:
        self.size = int(size)
        self._meshes: OrderedDict = OrderedDict()
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    def __len__(self) -> int:
        return len(self._meshes)

    def clear(self) -> None:
        with self._lock:
            self._meshes.clear()

    def get(self, key: tuple | None, make: Callable[[], object]):
        """The mesh kept under ``key`` (a shallow copy: its own object, the same read-only arrays and
        lookup structures), or ``make()``'s, kept. A None key is never kept."""
        if key is None or self.size <= 0:
            return make()
        with self._lock:
            mesh = self._meshes.get(key)
            if mesh is not None:
                self._meshes.move_to_end(key)
                self.hits += 1
                return dataclasses.replace(mesh)
        mesh = make()
        for f in dataclasses.fields(mesh):
            value = getattr(mesh, f.name)
            if isinstance(value, np.ndarray):
                value.flags.writeable = False
        with self._lock:
            self.misses += 1
            self._meshes[key] = mesh
            while len(self._meshes) > self.size:
                self._meshes.popitem(last=False)
        return dataclasses.replace(mesh)
