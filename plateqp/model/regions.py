"""Regions: the areas a patch load, a tensionless bed and a cut-out cover, written one way
wherever a scene takes one, and the integrals over each mesh cell's part in a region.

    region = [x0, x1, y0, y1]                  # a box
    region = { polygon = [[x, y], ...] }       # a simple polygon, counter-clockwise
    region = { circle = [xc, yc, r] }          # a disc (a plate shape's and a hole's spelling)

:func:`plateqp.model.geometry.parse_region` checks one and returns its
:class:`~plateqp.model.geometry.Polygon` (a box: its rectangle) or
:class:`~plateqp.model.geometry.Circle`; every failure names the field (``loads.0.region``,
``foundation.region``, ``openings.1``) through the scene's ``fail``, for all three uses.

:func:`part_moments` integrates exactly: the monomial moments ∫∫ u^i v^j dA of a convex cell's
part in a region, by Green's theorem along the part's boundary (∫∫ u^i v^j du dv =
∮ u^(i+1) v^j / (i + 1) dv). A polygon region is clipped by the cell (Sutherland–Hodgman, the
cell being convex); its straight pieces are integrated by Gauss–Legendre, exact for these
polynomials. A circle is followed as it is, never replaced by a polygon: the cell's sides
inside the disc and the circle's arcs inside the cell, the arcs by Gauss–Legendre in the angle
(:data:`ARC_POINTS` points: the integrand is a trigonometric polynomial of degree ≤ 8, integrated
to rounding). So a circular patch's total force is q × its area on the plate to rounding.
:func:`split_cells` sorts cells into those wholly in a region and those its boundary crosses;
only the latter are integrated piece by piece. :func:`lumped_region` gives the triangles' lumped
weights of a region (the DKT patch load, a triangle mesh's bed areas), :func:`cell_hat_areas`
the rectangles' bilinear weights (a grid's bed on a polygon or a circle).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SceneError
from .geometry import Circle, Polygon, Shape, parse_region

#: Gauss–Legendre points along a straight piece (exact to degree 9) and along an arc
_SEG_X, _SEG_W = np.polynomial.legendre.leggauss(5)
ARC_POINTS = 40
_ARC_X, _ARC_W = np.polynomial.legendre.leggauss(ARC_POINTS)


def as_shape(value) -> Shape:
    """The shape of a region a validated scene holds (a bad one: a SceneError)."""
    if isinstance(value, (Polygon, Circle)):
        return value

    def fail(where, what):
        raise SceneError(f"{where}: {what}")

    return parse_region(value, "region", fail)


def box_of(value) -> tuple[float, float, float, float] | None:
    """(x0, x1, y0, y1) of a region written as a box, else None."""
    if isinstance(value, (list, tuple)) and len(value) == 4 and not isinstance(value, dict):
        return tuple(float(v) for v in value)
    return None


def outline(shape: Shape, h: float) -> np.ndarray:
    """(n, 2) a closed outline of the region, counter-clockwise, for a mesh to follow: a
    polygon's vertices; a circle's inscribed polygon of sides about ``h`` (at least 12)."""
    if isinstance(shape, Polygon):
        return shape.xy
    n = max(12, math.ceil(2 * math.pi * shape.r / h))
    t = 2 * math.pi * np.arange(n) / n
    return np.column_stack([shape.xc + shape.r * np.cos(t), shape.yc + shape.r * np.sin(t)])


# -- integrals over the cells' parts in a region ---------------------------------------------


def split_cells(xy: np.ndarray, shape: Shape) -> tuple[np.ndarray, np.ndarray]:
    """(whole, cut): the cells (convex, vertices ``xy`` (n, k, 2)) wholly in the region and
    those its boundary may cross (nearer to it than their own size); the rest lie outside."""
    cent = xy.mean(axis=1)
    reach = np.hypot(*(xy - cent[:, None]).transpose(2, 0, 1)).max(axis=1)
    x0, x1, y0, y1 = shape.bbox
    near = np.flatnonzero((cent[:, 0] >= x0 - reach) & (cent[:, 0] <= x1 + reach)
                          & (cent[:, 1] >= y0 - reach) & (cent[:, 1] <= y1 + reach))
    cut = np.zeros(len(xy), dtype=bool)
    if near.size:
        cut[near] = shape.distance(cent[near, 0], cent[near, 1]) <= reach[near] * (1 + 1e-9)
    whole = np.zeros(len(xy), dtype=bool)
    if near.size:
        whole[near] = ~cut[near] & shape.contains(cent[near, 0], cent[near, 1])
    return np.flatnonzero(whole), np.flatnonzero(cut)


def _clip(P: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The closed chain P (n, 2) clipped to the left of the line a → b (one Sutherland–Hodgman
    step: each vertex kept if inside, preceded by the crossing where its edge crosses)."""
    d = (b[0] - a[0]) * (P[:, 1] - a[1]) - (b[1] - a[1]) * (P[:, 0] - a[0])
    prev, dp = np.roll(P, 1, axis=0), np.roll(d, 1)
    inside = d >= 0
    cross = inside != (dp >= 0)
    f = np.where(cross, dp / np.where(cross, dp - d, 1.0), 0.0)
    both = np.stack([prev + f[:, None] * (P - prev), P], axis=1)
    return both[np.column_stack([cross, inside])]


def _polygon_pieces(cell: np.ndarray, poly: Polygon) -> list:
    P = poly.xy
    for k in range(len(cell)):
        P = _clip(P, cell[k], cell[(k + 1) % len(cell)])
        if len(P) == 0:
            return []
    return [("seg", P[i], P[(i + 1) % len(P)]) for i in range(len(P))]


def _inside_cell(cell: np.ndarray, p: np.ndarray) -> bool:
    e = np.roll(cell, -1, axis=0) - cell
    return bool(np.all(e[:, 0] * (p[1] - cell[:, 1]) - e[:, 1] * (p[0] - cell[:, 0]) >= 0))


def _circle_pieces(cell: np.ndarray, c: Circle) -> list:
    """The boundary of cell ∩ disc, counter-clockwise: the cell's sides inside the disc, then the
    circle's arcs inside the cell (the cell convex: the disc meets each side in one interval)."""
    pieces, angles = [], []
    centre = np.array([c.xc, c.yc])
    for k in range(len(cell)):
        p, q = cell[k], cell[(k + 1) % len(cell)]
        d, f = q - p, p - centre
        A, B, C = d @ d, 2 * f @ d, f @ f - c.r**2
        disc = B * B - 4 * A * C
        if disc <= 0:
            continue
        t0, t1 = (-B - math.sqrt(disc)) / (2 * A), (-B + math.sqrt(disc)) / (2 * A)
        lo, hi = max(t0, 0.0), min(t1, 1.0)
        if hi > lo:
            pieces.append(("seg", p + lo * d, p + hi * d))
        angles += [math.atan2(*(f + t * d)[::-1]) for t in (t0, t1) if 0.0 <= t <= 1.0]
    if not angles:
        if _inside_cell(cell, centre) and not (np.hypot(*(cell - centre).T) <= c.r).all():
            pieces.append(("arc", 0.0, 2 * math.pi))  # the disc inside the cell
        return pieces
    angles = sorted(set(angles))
    for a, b in zip(angles, angles[1:] + [angles[0] + 2 * math.pi]):
        m = 0.5 * (a + b)
        if b > a and _inside_cell(cell, centre + c.r * np.array([math.cos(m), math.sin(m)])):
            pieces.append(("arc", a, b))
    return pieces


def part_moments(cell: np.ndarray, shape: Shape, origin, scale, p: int) -> np.ndarray:
    """(p + 1, p + 1): M[i, j] = ∫∫ u^i v^j dx dy over the part of the convex cell (vertices
    ``cell`` (k, 2), counter-clockwise) in the region, u = (x − ox)/sx, v = (y − oy)/sy."""
    (ox, oy), (sx, sy) = origin, scale
    pieces = _circle_pieces(cell, shape) if isinstance(shape, Circle) else _polygon_pieces(cell, shape)
    us, vs, ws = [], [], []
    for kind, a, b in pieces:
        if kind == "seg":
            t = 0.5 * (_SEG_X + 1.0)
            us.append((a[0] + t * (b[0] - a[0]) - ox) / sx)
            vs.append((a[1] + t * (b[1] - a[1]) - oy) / sy)
            ws.append(0.5 * _SEG_W * (b[1] - a[1]) / sy)
        else:
            th = a + 0.5 * (_ARC_X + 1.0) * (b - a)
            us.append((shape.xc + shape.r * np.cos(th) - ox) / sx)
            vs.append((shape.yc + shape.r * np.sin(th) - oy) / sy)
            ws.append(0.5 * (b - a) * _ARC_W * shape.r * np.cos(th) / sy)
    if not us:
        return np.zeros((p + 1, p + 1))
    u, v, w = np.concatenate(us), np.concatenate(vs), np.concatenate(ws)
    k = np.arange(p + 1)
    U = u[:, None] ** (k + 1) / (k + 1)
    V = v[:, None] ** k
    return (U * w[:, None]).T @ V * (sx * sy)


def lumped_region(tris: np.ndarray, region) -> tuple[np.ndarray, np.ndarray]:
    """(hit, weights): the triangles (nt, 3, 2) a unit pressure on ``region`` (any form)
    covers in part, and each one's vertex weights (len(hit), 3): over the triangle's part A_t in
    the region, ∫ λ_i dA = |A_t| λ_i(centroid of A_t) (λ the barycentric coordinates).
    Statically exact: the weights sum to the region's area on the triangles, their moment is its
    moment (a circle's to rounding: :func:`part_moments`)."""
    tris = np.asarray(tris, dtype=float)
    shape = as_shape(region)
    p = tris
    area = 0.5 * np.abs((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                        - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    whole, cut = split_cells(tris, shape)
    out_a = np.zeros(len(tris))
    out_c = tris.mean(axis=1)
    out_a[whole] = area[whole]
    for t in cut:
        M = part_moments(tris[t], shape, tris[t, 0], (1.0, 1.0), 1)
        if M[0, 0] > 1e-10 * area[t]:  # not a sliver of round-off along a shared edge
            out_a[t] = min(M[0, 0], area[t])
            out_c[t] = tris[t, 0] + np.array([M[1, 0], M[0, 1]]) / M[0, 0]
    hit = np.flatnonzero(out_a > 0.0)
    p = tris[hit]
    (x1, y1), (x2, y2), (x3, y3) = p[:, 0].T, p[:, 1].T, p[:, 2].T
    det = (x2 - x1) * (y3 - y1) - (x3 - x1) * (y2 - y1)
    x, y = out_c[hit, 0], out_c[hit, 1]
    l2 = ((x - x1) * (y3 - y1) - (x3 - x1) * (y - y1)) / det
    l3 = ((x2 - x1) * (y - y1) - (x - x1) * (y2 - y1)) / det
    return hit, out_a[hit, None] * np.column_stack([1.0 - l2 - l3, l2, l3])


def cell_hat_areas(cells: np.ndarray, region) -> tuple[np.ndarray, np.ndarray]:
    """(hit, weights): the rectangles (n, 4, 2; corners (0, 0), (1, 0), (1, 1), (0, 1) of the cell)
    a region covers in part, and each corner's ∫ φ dA over the cell's part in it (len(hit), 4), φ
    the corner's bilinear hat: a quarter of the cell each where the cell is wholly in the region.
    The weights sum to the region's area on the cells; their moment is its moment."""
    cells = np.asarray(cells, dtype=float)
    shape = as_shape(region)
    whole, cut = split_cells(cells, shape)
    sx, sy = cells[:, 1, 0] - cells[:, 0, 0], cells[:, 3, 1] - cells[:, 0, 1]
    out = np.zeros((len(cells), 4))
    out[whole] = 0.25 * (sx[whole] * sy[whole])[:, None]
    for c in cut:
        M = part_moments(cells[c], shape, cells[c, 0], (sx[c], sy[c]), 1)
        if M[0, 0] > 1e-10 * sx[c] * sy[c]:  # not a sliver of round-off along a shared side
            m00, m10, m01, m11 = M[0, 0], M[1, 0], M[0, 1], M[1, 1]
            out[c] = [m00 - m10 - m01 + m11, m10 - m11, m11, m01 - m11]
    hit = np.flatnonzero(out.sum(axis=1) > 0.0)
    return hit, out[hit]


def region_outline(region, h: float) -> np.ndarray:
    """The outline of a region (any form) for a mesh of element size ``h`` to follow: :func:`outline`."""
    return outline(as_shape(region), h)
