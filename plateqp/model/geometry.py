"""Plate outlines of any shape: polygons and circles, holes, and their validation.

A shaped plate is an outer boundary (a counter-clockwise :class:`Polygon` or a :class:`Circle`)
with holes of the same two kinds. In a scene file::

    [plate]
    shape = { polygon = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]] }   # or { circle = [xc, yc, r] }

    [[holes]]
    circle = [0.5, 0.5, 0.2]

:func:`parse_shape` turns one such table into a shape and checks it (at least 3 and at most
:data:`MAX_VERTICES` vertices, counter-clockwise, not self-intersecting: :mod:`plateqp.model.crossings`;
a circle's r > 0); :func:`check_holes` checks that every
hole lies strictly inside the plate and that no two holes touch or overlap. Every failure is a
SceneError through the ``fail(where, what)`` callable the scene passes in (it names the field and
the file). :class:`Domain` answers "is this point on the plate?" for the scene's other checks.

A region (a patch load's, a bed's, a cut-out's) is a box [x0, x1, y0, y1], a polygon or a circle
in the same spelling: :func:`parse_region` reads and checks every one of them (the integrals
over a mesh's cells: :mod:`plateqp.model.regions`).

Boundaries are numbered for the mesh and the edge supports: 0 the outer boundary, k ≥ 1 hole
k − 1; a polygon's segment i runs from vertex i to vertex i + 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Callable

import numpy as np

from .crossings import check_simple, cross_any
from .parts import _short

Fail = Callable[[str, str], None]


@dataclass(frozen=True)
class Polygon:
    """A simple polygon, vertices counter-clockwise (``(n, 2)`` as a tuple of pairs)."""

    vertices: tuple[tuple[float, float], ...]

    @property
    def xy(self) -> np.ndarray:
        return np.array(self.vertices, dtype=float)

    @property
    def area(self) -> float:
        """Signed area (positive: counter-clockwise)."""
        x, y = self.xy.T
        return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))

    def segments(self) -> np.ndarray:
        """(n, 2, 2): segment i from vertex i to vertex i + 1."""
        p = self.xy
        return np.stack([p, np.roll(p, -1, axis=0)], axis=1)

    @cached_property
    def _index(self):
        """shapely's prepared polygon and an STRtree of its segments, for a polygon of more than
        :data:`INDEXED_VERTICES` vertices when shapely is installed (else None: loops over the
        segments, each a pass over the points)."""
        if len(self.vertices) <= INDEXED_VERTICES:
            return None
        try:
            import shapely
        except ImportError:
            return None
        poly = shapely.Polygon(self.vertices)
        shapely.prepare(poly)
        return shapely, poly, shapely.STRtree(shapely.linestrings(self.segments()))

    def contains(self, x, y, tol: float = 0.0) -> np.ndarray:
        """Points inside or within ``tol`` of the polygon (boundary included)."""
        x, y = np.atleast_1d(np.asarray(x, float)), np.atleast_1d(np.asarray(y, float))
        if self._index is not None:
            shp, poly, _ = self._index
            return shp.contains_xy(poly, x, y) | (self.distance(x, y) <= tol)
        seg = self.segments()
        inside = np.zeros(x.shape, dtype=bool)
        for (x0, y0), (x1, y1) in seg:  # even-odd ray casting along +x
            cross = (y0 > y) != (y1 > y)
            xc = x0 + (y - y0) * (x1 - x0) / np.where(y1 != y0, y1 - y0, 1.0)
            inside ^= cross & (x < xc)
        return inside | (self.distance(x, y) <= tol)

    def distance(self, x, y) -> np.ndarray:
        """Distance of points to the polygon's boundary."""
        x, y = np.atleast_1d(np.asarray(x, float)), np.atleast_1d(np.asarray(y, float))
        if self._index is not None:  # the nearest segment of each point, from the spatial index
            shp, _, tree = self._index
            (which, _), d = tree.query_nearest(shp.points(x.ravel(), y.ravel()), return_distance=True,
                                               all_matches=False)
            out = np.full(x.size, np.nan)
            out[which] = d
            return out.reshape(x.shape)
        return np.min([_point_segment(x, y, s) for s in self.segments()], axis=0)

    @property
    def bbox(self) -> tuple[float, float, float, float]:
        p = self.xy
        return float(p[:, 0].min()), float(p[:, 0].max()), float(p[:, 1].min()), float(p[:, 1].max())

    def to_dict(self) -> dict:
        return {"polygon": [list(v) for v in self.vertices]}


@dataclass(frozen=True)
class Circle:
    """The disc of centre (xc, yc) and radius r > 0."""

    xc: float
    yc: float
    r: float

    @property
    def area(self) -> float:
        return math.pi * self.r**2

    def contains(self, x, y, tol: float = 0.0) -> np.ndarray:
        x, y = np.atleast_1d(np.asarray(x, float)), np.atleast_1d(np.asarray(y, float))
        return np.hypot(x - self.xc, y - self.yc) <= self.r + tol

    def distance(self, x, y) -> np.ndarray:
        x, y = np.atleast_1d(np.asarray(x, float)), np.atleast_1d(np.asarray(y, float))
        return np.abs(np.hypot(x - self.xc, y - self.yc) - self.r)

    @property
    def bbox(self) -> tuple[float, float, float, float]:
        return self.xc - self.r, self.xc + self.r, self.yc - self.r, self.yc + self.r

    def to_dict(self) -> dict:
        return {"circle": [self.xc, self.yc, self.r]}


Shape = Polygon | Circle


def rectangle(a: float, b: float) -> Polygon:
    """[0, a] × [0, b]; segments 0, 1, 2, 3 are the bottom, right, top and left edges."""
    return Polygon(((0.0, 0.0), (a, 0.0), (a, b), (0.0, b)))


#: the names of a rectangle's segments, in :func:`rectangle`'s order
RECT_SEGMENTS = ("bottom", "right", "top", "left")


def _point_segment(x, y, seg) -> np.ndarray:
    (x0, y0), (x1, y1) = seg
    dx, dy = x1 - x0, y1 - y0
    t = np.clip(((x - x0) * dx + (y - y0) * dy) / max(dx * dx + dy * dy, 1e-300), 0.0, 1.0)
    return np.hypot(x - x0 - t * dx, y - y0 - t * dy)


#: The most vertices a polygon (a plate's outline, a hole, a bed region) may have, and the plate's
#: boundaries all together: every boundary vertex becomes a mesh node, and no plate needs more.
MAX_VERTICES = 20_000
#: A polygon of more vertices than this answers :meth:`Polygon.contains` and
#: :meth:`Polygon.distance` with shapely's spatial index (when installed), not a loop over its
#: segments; the two agree to rounding.
INDEXED_VERTICES = 64
def _number(v, where: str, fail: Fail) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(float(v)):
        fail(where, f"must be a finite number (got {v!r:.60})")
    return float(v)


def parse_shape(value, where: str, fail: Fail) -> Shape:
    """A shape from its scene form ({polygon = [[x, y], ...]} or {circle = [xc, yc, r]}), or a
    Polygon/Circle given in Python; checked (see the module docstring)."""
    if isinstance(value, (Polygon, Circle)):
        value = value.to_dict()
    if not isinstance(value, dict) or len(value) != 1 or next(iter(value)) not in ("polygon", "circle"):
        fail(where, "must be { polygon = [[x, y], ...] } or { circle = [xc, yc, r] }")
    kind, data = next(iter(value.items()))
    where = f"{where}.{kind}"
    if kind == "circle":
        if not isinstance(data, (list, tuple)) or len(data) != 3:
            fail(where, f"must be [xc, yc, r] (got {data!r:.60})")
        xc, yc, r = (_number(v, f"{where}.{i}", fail) for i, v in enumerate(data))
        if r <= 0:
            fail(where, f"a degenerate circle: the radius must be > 0 (got {r!r})")
        return Circle(xc, yc, r)
    data = data.tolist() if isinstance(data, np.ndarray) else data
    if not isinstance(data, (list, tuple)) or len(data) < 3:
        fail(where, f"a polygon needs at least 3 vertices [[x, y], ...] (got {data!r:.60})")
    if len(data) > MAX_VERTICES:
        fail(where, f"{len(data)} vertices, more than any plate needs (at most {MAX_VERTICES}); simplify the outline")
    verts = []
    for i, v in enumerate(data):
        if not isinstance(v, (list, tuple)) or len(v) != 2:
            fail(f"{where}.{i}", f"a vertex must be [x, y] (got {v!r:.60})")
        verts.append((_number(v[0], f"{where}.{i}.0", fail), _number(v[1], f"{where}.{i}.1", fail)))
    poly = Polygon(tuple(verts))
    seg = poly.segments()
    n = len(seg)
    scale = max(np.abs(poly.xy).max(), np.ptp(poly.xy, axis=0).max())
    length = np.hypot(*(seg[:, 1] - seg[:, 0]).T)
    if (length <= 1e-12 * scale).any():
        i = int(np.argmax(length <= 1e-12 * scale))
        fail(f"{where}.{i}", f"vertex {i} repeats vertex {(i + 1) % n}: remove one")
    check_simple(seg, scale, where, fail)
    if abs(poly.area) <= 1e-12 * scale**2:
        fail(where, "the polygon has no area")
    if poly.area < 0:
        fail(where, "the vertices run clockwise; list them counter-clockwise (reverse the list)")
    return poly


def _inside_strictly(inner: Shape, outer: Shape, where: str, fail: Fail) -> bool:
    """True if ``inner`` lies inside ``outer`` without touching its boundary."""
    if isinstance(outer, Circle):
        if isinstance(inner, Circle):
            return math.hypot(inner.xc - outer.xc, inner.yc - outer.yc) + inner.r < outer.r
        return bool(np.all(np.hypot(inner.xy[:, 0] - outer.xc, inner.xy[:, 1] - outer.yc) < outer.r))
    if isinstance(inner, Circle):
        return bool(outer.contains(inner.xc, inner.yc)[0] and outer.distance(inner.xc, inner.yc)[0] > inner.r)
    if cross_any(inner.segments(), outer.segments(), where, fail):
        return False
    return bool(outer.contains(*inner.xy[0])[0])


def _disjoint(s: Shape, t: Shape, where: str, fail: Fail) -> bool:
    """True if two shapes neither overlap nor touch."""
    if isinstance(s, Circle) and isinstance(t, Circle):
        return math.hypot(s.xc - t.xc, s.yc - t.yc) > s.r + t.r
    if isinstance(s, Circle) or isinstance(t, Circle):
        c, p = (s, t) if isinstance(s, Circle) else (t, s)
        return not p.contains(c.xc, c.yc)[0] and p.distance(c.xc, c.yc)[0] > c.r
    if cross_any(s.segments(), t.segments(), where, fail):
        return False
    return not (t.contains(*s.xy[0])[0] or s.contains(*t.xy[0])[0])


def check_holes(outer: Shape, holes: list[Shape], fail: Fail, names: list[str] | None = None) -> None:
    """Every hole strictly inside the plate; no two holes overlapping or touching. ``names``:
    each hole's field (default ``holes.I``)."""
    names = names or [f"holes.{i}" for i in range(len(holes))]
    for i, h in enumerate(holes):
        if not _inside_strictly(h, outer, names[i], fail):
            fail(names[i], "the hole is not inside the plate: it lies outside it, crosses or touches its boundary")
    for i, h in enumerate(holes):
        for j in range(i):
            if not _disjoint(h, holes[j], names[i], fail):
                fail(names[i], f"overlaps or touches {names[j]}; merge them into one hole or move them apart")


#: How a region (a patch load's, a bed's, a cut-out's) is written: the message of a value that is none of them
FORMS = "[x0, x1, y0, y1], { polygon = [[x, y], ...] } or { circle = [xc, yc, r] }"


def parse_region(value, where: str, fail: Fail) -> Shape:
    """The shape of a region in any of its forms, [x0, x1, y0, y1] (its rectangle),
    {polygon = [[x, y], ...]} or {circle = [xc, yc, r]} (a Polygon or Circle given in Python too),
    checked: a box's bounds finite and increasing, a polygon simple and counter-clockwise, a
    circle's radius > 0 (:func:`parse_shape`). Failures name ``where`` through ``fail``."""
    if isinstance(value, (Polygon, Circle)):
        return parse_shape(value, where, fail)
    if isinstance(value, dict):
        if len(value) != 1 or next(iter(value)) not in ("polygon", "circle"):
            fail(where, f"must be {FORMS} (got {_short(value)})")
        return parse_shape(value, where, fail)
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if not isinstance(value, (list, tuple)) or len(value) != 4:
        fail(where, f"must be {FORMS} (got {_short(value)})")
    for j, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(float(v)):
            fail(f"{where}.{j}", f"must be a finite number (got {_short(v)})")
    x0, x1, y0, y1 = (float(v) for v in value)
    if not (x0 < x1 and y0 < y1):
        fail(where, "needs x0 < x1 and y0 < y1")
    return Polygon(((x0, y0), (x1, y0), (x1, y1), (x0, y1)))


def sample_points(shape: Shape, n: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """Points inside a region, to ask whether it covers some plate: the centres of an n × n
    lattice of its bounding box that it contains (and a circle's centre); a region too thin for
    them, its vertices."""
    x0, x1, y0, y1 = shape.bbox
    X, Y = np.meshgrid(x0 + (np.arange(n) + 0.5) * (x1 - x0) / n, y0 + (np.arange(n) + 0.5) * (y1 - y0) / n)
    X, Y = X.ravel(), Y.ravel()
    keep = shape.contains(X, Y)
    xs, ys = X[keep], Y[keep]
    if isinstance(shape, Circle):
        xs, ys = np.append(xs, shape.xc), np.append(ys, shape.yc)
    elif not keep.any():
        xs, ys = shape.xy[:, 0], shape.xy[:, 1]
    return xs, ys


@dataclass(frozen=True)
class Domain:
    """The plate's region: ``outer`` less ``holes`` (boundaries belong to the plate)."""

    outer: Shape
    holes: tuple[Shape, ...] = ()

    @property
    def size(self) -> float:
        x0, x1, y0, y1 = self.outer.bbox
        return max(x1 - x0, y1 - y0)

    @property
    def area(self) -> float:
        return self.outer.area - sum(h.area for h in self.holes)

    def covers(self, x, y) -> np.ndarray:
        """(npts,) bool: the points lie on the plate (within 1e-9 of its size of a boundary)."""
        tol = 1e-9 * self.size
        ok = self.outer.contains(x, y, tol)
        for h in self.holes:
            ok &= ~h.contains(x, y) | (h.distance(x, y) <= tol)
        return ok


# -- the scene's side: a shaped (triangle-meshed) scene's checks ------------------------------


def cutout_shapes(scene) -> list[Shape]:
    """A scene's cut-outs, K = 0, 1, …: its ``[[holes]]`` (polygons, circles), then its
    ``[[openings]]`` (each the box [x0, x1] × [y0, y1]). One concept with two spellings: the
    edges of cut-out K are ``holeK`` on every mesh."""
    holes = [parse_shape(h, f"holes.{i}", scene._fail) for i, h in enumerate(scene.holes)]
    return holes + [parse_region([o.x0, o.x1, o.y0, o.y1], f"openings.{i}", scene._fail)
                    for i, o in enumerate(scene.openings)]


def scene_domain(scene) -> Domain:
    """The Domain of a scene: its shape (or the rectangle [0, a] × [0, b]) less its cut-outs
    (:func:`cutout_shapes`)."""
    p = scene.plate
    outer = parse_shape(p.shape, "plate.shape", scene._fail) if p.shape is not None else rectangle(p.a, p.b)
    holes = tuple(cutout_shapes(scene))
    total = sum(len(s.vertices) for s in (outer, *holes) if isinstance(s, Polygon))
    if total > MAX_VERTICES:
        scene._fail("holes", f"the plate's boundaries have {total} vertices in all, more than any plate needs "
                    f"(at most {MAX_VERTICES}); simplify the outlines")
    return Domain(outer, holes)


def nearest_segment(shape: Shape, points: np.ndarray, normals: np.ndarray, h: float) -> np.ndarray:
    """(npts,) the segment of ``shape`` each boundary edge of a mesh lies along: the nearest to
    its midpoint ``points``, where an edge near a corner is as near two segments, the one whose
    normal agrees with the edge's outward ``normals`` (the plate's outward normal on a cut-out's
    boundary points into it). A circle is one segment, 0."""
    if not isinstance(shape, Polygon):
        return np.zeros(len(points), dtype=int)
    seg = shape.segments()
    d = np.stack([_point_segment(points[:, 0], points[:, 1], s) for s in seg], axis=1)
    t = seg[:, 1] - seg[:, 0]
    inward = np.column_stack([-t[:, 1], t[:, 0]]) / np.hypot(t[:, 0], t[:, 1])[:, None]  # left of a ccw side
    agree = normals @ inward.T  # 1 where the plate's outward normal points into the cut-out across it
    return np.argmin(d + 0.5 * h * (1.0 - agree), axis=1)


class Region:
    """A Domain with the names the scene's point checks ask a grid for (``covers``, ``locate``,
    ``node_at``, ``cells_in``): any point of the plate can carry a pin, the mesher puts a node
    there."""

    def __init__(self, domain: Domain, size: float):
        self.domain = domain
        self.hx = self.hy = size
        x0, x1, y0, y1 = domain.outer.bbox
        self.a = self.b = 2.0 * max(abs(x0), abs(x1), abs(y0), abs(y1), domain.size)
        self.cell_mask = np.ones(1, dtype=bool)

    def covers(self, x: float, y: float) -> bool:
        return bool(self.domain.covers(x, y)[0])

    def locate(self, x, y):
        return np.where(self.domain.covers(x, y), 0, -1), None, None

    def node_at(self, x: float, y: float) -> int:
        return 0

    def cells_in(self, shape: Shape) -> np.ndarray:
        """Not empty if the region ``shape`` overlaps the plate (points inside it lie on the
        plate: :func:`sample_points`): a bed there has triangles, the mesh following its outline."""
        return np.ones(int(self.domain.covers(*sample_points(shape)).any()), dtype=int)


def validate_shaped(scene) -> Region:
    """The shape-specific checks of a scene with ``mesh.element`` a triangle element: the shape,
    the holes and openings and the mesh size. Returns the
    Region for the point checks."""
    p, m = scene.plate, scene.mesh
    fail = scene._fail
    domain = scene_domain(scene)
    # shapes given in Python as Polygon/Circle are kept in their scene form (as TOML gives them)
    if p.shape is not None:
        p.shape = domain.outer.to_dict() if isinstance(p.shape, (Polygon, Circle)) else p.shape
    scene.holes = [h.to_dict() if isinstance(h, (Polygon, Circle)) else h for h in scene.holes]
    check_holes(domain.outer, list(domain.holes), fail,
                [f"holes.{i}" for i in range(len(scene.holes))] + [f"openings.{i}" for i in range(len(scene.openings))])
    if p.shape is not None:
        x0, x1, y0, y1 = domain.outer.bbox
        p.a, p.b = x1 - x0, y1 - y0  # the length scales of a shaped plate: its bounding box
    if m.size is None:
        if p.shape is not None:
            fail("mesh.size", "a plate with a shape needs the element size h: [mesh] size = h")
    else:
        scene._num("mesh.size", m.size, positive=True, physical=True)
        if m.size > domain.size:
            fail("mesh.size", f"{m.size!r} is larger than the plate ({domain.size:g})")
        n = domain.area / (0.433 * m.size**2)
        if n > 1e7:
            fail("mesh.size", f"{m.size!r} would make about {n:.1g} triangles, more than any plate needs")
    return Region(domain, mesh_size(scene))


def mesh_size(scene) -> float:
    """The element size h of a triangle-meshed scene: ``mesh.size``, or for a rectangle without
    one the larger cell side of its nx × ny grid."""
    m, p = scene.mesh, scene.plate
    return float(m.size) if m.size is not None else max(p.a / m.nx, p.b / m.ny)


def _crossings(shape: Shape, p: np.ndarray, q: np.ndarray) -> list[float]:
    """Parameters t in (0, 1) where the segment p + t (q − p) meets the boundary of ``shape``."""
    d = q - p
    out = []
    if isinstance(shape, Circle):
        f = p - (shape.xc, shape.yc)
        a, b, c = d @ d, 2 * f @ d, f @ f - shape.r**2
        disc = b * b - 4 * a * c
        if disc > 0:
            out += [(-b - math.sqrt(disc)) / (2 * a), (-b + math.sqrt(disc)) / (2 * a)]
        return out
    for s0, s1 in shape.segments():
        e = s1 - s0
        den = d[0] * e[1] - d[1] * e[0]
        if abs(den) > 1e-14 * math.sqrt((d @ d) * (e @ e)):
            w = s0 - p
            t, u = (w[0] * e[1] - w[1] * e[0]) / den, (w[0] * d[1] - w[1] * d[0]) / den
            if -1e-12 <= u <= 1 + 1e-12:
                out.append(t)
        else:  # parallel: the ends of a collinear overlap
            out += [float((s0 - p) @ d / (d @ d)), float((s1 - p) @ d / (d @ d))]
    return out


def inner_segments(domain: Domain, outline: np.ndarray) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """The pieces of a closed polygonal outline ((n, 2) vertices) that run strictly inside the
    plate (off its boundaries: the outer one and the holes'), as segments: the lines a mesh must
    follow for a region's edge to lie on element edges."""
    out = []
    tol = 1e-9 * domain.size
    shapes = (domain.outer, *domain.holes)
    for p, q in zip(outline, np.roll(outline, -1, axis=0)):
        ts = sorted({0.0, 1.0, *(t for sh in shapes for t in _crossings(sh, p, q) if 0.0 < t < 1.0)})
        for t0, t1 in zip(ts[:-1], ts[1:]):
            if (t1 - t0) * np.hypot(*(q - p)) <= tol:
                continue
            m = p + 0.5 * (t0 + t1) * (q - p)
            if domain.covers(*m)[0] and min(sh.distance(*m)[0] for sh in shapes) > tol:
                a, b = p + t0 * (q - p), p + t1 * (q - p)
                out.append(((float(a[0]), float(a[1])), (float(b[0]), float(b[1]))))
    return out


def tidy_dict(scene, d: dict) -> None:
    """The TOML dict of a scene (:meth:`Scene.to_dict`) without the shape fields it does not use:
    no ``shape`` or ``size`` when unset, no ``a``, ``b`` on a shaped plate (they follow from the
    shape), and the holes when there are some."""
    if scene.plate.shape is None:
        del d["plate"]["shape"]
    else:
        del d["plate"]["a"], d["plate"]["b"]
    if scene.mesh.size is None:
        del d["mesh"]["size"]
    if scene.holes:
        d["holes"] = [h.to_dict() if isinstance(h, (Polygon, Circle)) else dict(h) for h in scene.holes]
