"""What a figure reads from a result: the supports as arrays, the bed's contact nodes, the
mesh's nodes as a matplotlib Triangulation and its cells' sides, the plate's bounding box, w
sampled at points, the spacing of the supports."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from ..results import Result


@dataclass
class _Supports:
    """The discrete one-sided supports of a result, as arrays (scene order)."""

    xy: np.ndarray
    g0: np.ndarray
    active: np.ndarray
    R: np.ndarray
    s: np.ndarray  # spring compression (0 for rigid)
    rigid: np.ndarray
    stiffness: np.ndarray  # NaN for rigid

    @property
    def n(self) -> int:
        return self.xy.shape[0]


def _supports(result: Result) -> _Supports:
    sc = result.scene
    n = len(sc.supports)
    xy = np.array([[s.x, s.y] for s in sc.supports], dtype=float).reshape(n, 2)
    g0 = np.array([s.gap for s in sc.supports], dtype=float)
    rigid = np.array([s.rigid for s in sc.supports], dtype=bool)
    c = np.array([np.nan if s.rigid else float(s.stiffness) for s in sc.supports])
    if result.reactions.size >= n:
        active = np.asarray(result.active[:n], dtype=bool)
        R = np.asarray(result.reactions[:n], dtype=float)
        s = np.asarray(result.compressions[:n], dtype=float) if result.compressions.size >= n else np.zeros(n)
    else:
        active, R, s = np.ones(n, dtype=bool), np.zeros(n), np.zeros(n)
    return _Supports(xy, g0, active, R, s, rigid, c)


def _bed(result: Result):
    """(xy, active) of the tensionless bed's contact nodes, if any."""
    m = result.model.contacts
    if m is None or result.active.size == 0:
        return np.zeros((0, 2)), np.zeros(0, dtype=bool)
    bed = m.source == "bed"
    return m.xy[bed], np.asarray(result.active, dtype=bool)[bed]


def _triangulation(result: Result):
    """The matplotlib Triangulation of the plate's nodes (``mesh.nodes``) on every mesh: the
    triangles of a triangle mesh, or a grid's kept quads each split in two for drawing."""
    from matplotlib.tri import Triangulation

    mesh = result.model.grid
    return Triangulation(mesh.nodes[:, 0], mesh.nodes[:, 1], mesh.triangulation())


def _cell_edges(mesh) -> np.ndarray:
    """(m, 2) the cells' sides as pairs of indices into ``mesh.nodes``, each once (a quad's
    four sides, no diagonal)."""
    c = mesh.cells
    e = np.vstack([c[:, [k, (k + 1) % c.shape[1]]] for k in range(c.shape[1])])
    return np.unique(np.sort(e, axis=1), axis=0)


def _bbox(result: Result) -> tuple[float, float, float, float]:
    """(x0, x1, y0, y1) of the plate, as its mesh gives it (``mesh.bbox``)."""
    return result.model.grid.bbox


def _point_loads(scene):
    return [ld for ld in scene.loads if ld.type == "point"]


def _w_at(result: Result, x, y) -> np.ndarray:
    """w at points (arrays), NaN where there is no plate (openings)."""
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    cell = result.model.grid.locate(x.ravel(), y.ravel())[0]
    out = np.full(x.size, np.nan)
    ok = cell >= 0
    if ok.any():
        out[ok] = np.atleast_1d(result.deflection(x.ravel()[ok], y.ravel()[ok]))
    return out.reshape(x.shape)


def support_spacing(xy: np.ndarray) -> float:
    """Median distance from a support to its nearest neighbour (inf for fewer than two)."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    if xy.shape[0] < 2:
        return math.inf
    d = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
    np.fill_diagonal(d, np.inf)
    return float(np.median(d.min(axis=1)))
