"""Whether polygon segments cross: the checks behind a simple outline and holes that stay apart
(:mod:`plateqp.model.geometry`), in n log n with shapely's spatial index (STRtree): only segments that
come near each other are tested, not all n² / 2 pairs.

Segments are (n, 2, 2) arrays, segment i from ``seg[i, 0]`` to ``seg[i, 1]``. Two segments
"share a point" within a rounding tolerance of 1e-12 of the coordinates' scale
(:func:`_segments_cross`); failures go through the ``fail(where, what)`` callable of the scene.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

Fail = Callable[[str, str], None]


def _segments_cross(s, t) -> bool:
    """True if closed segments s and t share a point."""
    (p1, p2), (p3, p4) = np.asarray(s, float), np.asarray(t, float)

    def orient(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])

    d1, d2, d3, d4 = orient(p3, p4, p1), orient(p3, p4, p2), orient(p1, p2, p3), orient(p1, p2, p4)
    if ((d1 > 0) != (d2 > 0)) and ((d3 > 0) != (d4 > 0)) and 0 not in (d1, d2, d3, d4):
        return True
    scale = max(np.abs([p1, p2, p3, p4]).max(), 1e-300)
    on = 1e-12 * scale * scale
    for d, a, b, c in ((d1, p3, p4, p1), (d2, p3, p4, p2), (d3, p1, p2, p3), (d4, p1, p2, p4)):
        if abs(d) <= on and min(a[0], b[0]) - 1e-12 * scale <= c[0] <= max(a[0], b[0]) + 1e-12 * scale \
                and min(a[1], b[1]) - 1e-12 * scale <= c[1] <= max(a[1], b[1]) + 1e-12 * scale:
            return True
    return False


#: Without shapely the crossing checks test every pair of segments (n² / 2 pairs): they take
#: polygons of up to this many vertices, and ask for shapely beyond.
PAIRWISE_VERTICES = 500


def _close_pairs(a: np.ndarray, b: np.ndarray | None, tol: float) -> np.ndarray:
    """(k, 2) index pairs (i, j) of segments ``a[i]``, ``b[j]`` ((n, 2, 2) arrays) that may share
    a point: those within ``tol`` of each other, found with shapely's STRtree (a spatial index:
    n log n for an outline, not n² / 2 pairs); ``b`` None: pairs of ``a`` with itself, i < j.
    Without shapely every pair, for at most :data:`PAIRWISE_VERTICES` segments a side."""
    try:
        import shapely
    except ImportError:
        nb = len(a) if b is None else len(b)
        if max(len(a), nb) > PAIRWISE_VERTICES:
            raise _NeedShapely(max(len(a), nb)) from None
        i, j = (np.triu_indices(len(a), 1) if b is None else
                (np.repeat(np.arange(len(a)), nb), np.tile(np.arange(nb), len(a))))
        return np.column_stack([i, j])
    la = shapely.linestrings(a)
    tree = shapely.STRtree(la if b is None else shapely.linestrings(b))
    i, j = tree.query(la, predicate="dwithin", distance=tol)
    keep = i < j if b is None else np.ones(len(i), dtype=bool)
    order = np.lexsort((j[keep], i[keep]))
    return np.column_stack([i[keep][order], j[keep][order]])


class _NeedShapely(Exception):
    def __init__(self, n: int):
        super().__init__(f"{n} vertices: checking a polygon of more than {PAIRWISE_VERTICES} vertices needs "
                         "shapely (pip install 'plateqp[shapes]')")


def cross_any(a: np.ndarray, b: np.ndarray, where: str, fail: Fail) -> bool:
    """True if a segment of ``a`` shares a point with one of ``b`` (:func:`_segments_cross` on the
    pairs pairs_close finds)."""
    scale = max(np.abs(a).max(), np.abs(b).max(), np.ptp(np.concatenate([a, b]).reshape(-1, 2), axis=0).max())
    try:
        pairs = _close_pairs(a, b, 1e-9 * scale)
    except _NeedShapely as exn:
        fail(where, str(exn))
    return any(_segments_cross(a[i], b[j]) for i, j in pairs)


def check_simple(seg: np.ndarray, scale: float, where: str, fail: Fail) -> None:
    """No two segments of a closed polygon share a point but neighbours their vertex, nor do
    neighbours fold back onto each other; the first offending pair (i, j), i < j, is named."""
    n = len(seg)
    u = seg[:, 1] - seg[:, 0]
    w = np.roll(u, -1, axis=0)  # segment i + 1
    fold = (np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]) <= 1e-12 * scale**2) & (np.einsum("ij,ij->i", u, w) < 0)
    folds = sorted((i, i + 1) if i < n - 1 else (0, n - 1) for i in np.flatnonzero(fold))
    try:
        near = _close_pairs(seg, None, 1e-9 * scale)
    except _NeedShapely as exn:
        fail(where, str(exn))
    cross = next(((int(i), int(j)) for i, j in near if j != i + 1 and not (i == 0 and j == n - 1)
                  and _segments_cross(seg[i], seg[j])), None)
    if folds and (cross is None or folds[0] < cross):
        fail(where, f"self-intersecting: segments {folds[0][0]} and {folds[0][1]} fold back onto each other")
    if cross is not None:
        i, j = cross
        fail(where, f"self-intersecting: segment {i} (vertices {i}-{(i + 1) % n}) crosses "
             f"segment {j} (vertices {j}-{(j + 1) % n})")
