"""What a figure reads from a result: the supports as arrays, the bed's contact nodes, the
nodes of the mesh, w sampled at points and on a refined grid, the spacing of the supports."""

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


def _nodes(result: Result):
    g = result.model.grid
    x = np.linspace(0.0, g.a, g.nx + 1)
    y = np.linspace(0.0, g.b, g.ny + 1)
    return np.meshgrid(x, y)


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


def _w_grid(result: Result, refine: int = 4):
    """(X, Y, W) on the mesh refined ``refine`` times per cell (the element's own interpolation)."""
    g = result.model.grid
    X, Y = np.meshgrid(np.linspace(0.0, g.a, refine * g.nx + 1), np.linspace(0.0, g.b, refine * g.ny + 1))
    return X, Y, _w_at(result, X, Y)


def support_spacing(xy: np.ndarray) -> float:
    """Median distance from a support to its nearest neighbour (inf for fewer than two)."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    if xy.shape[0] < 2:
        return math.inf
    d = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
    np.fill_diagonal(d, np.inf)
    return float(np.median(d.min(axis=1)))
