"""The surface flexibility of a homogeneous isotropic elastic half-space (Boussinesq; the soil of
Zhemochkin's method): the settlements at points caused by uniform pressures over cells.

A point force P on the surface (modulus E, Poisson ratio ν) settles the surface at distance r by
w = P (1 − ν²)/(π E r); a uniform pressure q over a region Ω settles the point x by

.. math::

    w(x) = q \\, \\frac{1 - \\nu^2}{\\pi E} \\, I_\\Omega(x), \\qquad
    I_\\Omega(x) = \\iint_\\Omega \\frac{dA}{\\lvert x - \\xi \\rvert} .

**Signs and units.** Pressures and forces are positive pushing down into the half-space (a
plate's contact pressure), settlements positive downward (plateqp's w). Any consistent units:
:math:`I` is a length, a pressure flexibility (settlement per unit pressure) is length³/force,
a force flexibility (settlement per unit force) is length/force.

**The integral.** :func:`polygon_potential` gives :math:`I` exactly, in closed form, over a
simple polygon (either orientation) at any points: inside, outside, on an edge or at a vertex
(the integral is weakly singular, hence finite). In polar coordinates about the point, the
polygon is a signed sum of the triangles (point, A, B) over its edges A → B, and the triangle's
integral is :math:`\\int r(\\theta)\\,d\\theta = d\\,[\\operatorname{asinh}(s/d)]_{s_A}^{s_B}`, with
d the point's distance from the edge's line and s the coordinate along the edge from the foot of
the perpendicular. The difference of the two asinh is evaluated without cancellation within an
edge; across edges, far from a cell of size h the sum loses about r/h ulps (relative 1e-13 at
r/h = 1000). :func:`rectangle_potential` is Love's (1929) corner formula for an axis-aligned
rectangle, an independent route (it loses (r/h)² ulps far away).

**The matrices.** :func:`flexibility` gives the dense (m, m) matrix of points and cells (cell j
the tributary area of contact point j): ``H[i, j]`` is the settlement at ``points[i]`` of a unit
pressure over ``cells[j]``, so settlements = H @ pressures; ``per="force"`` gives H / area[j]
(settlements = H @ forces). On a grid of equal rectangles the matrix depends on index differences
only: :func:`grid_kernel` gives those values, and :class:`GridFlexibility` applies the matrix by
zero-padded FFT (the discrete convolution and FFT of Liu, Wang & Liu 2000, as in Polonsky &
Keer 1999), in O(N log N) work and O(N) memory, on all cells or a mask of them.

**Grid order** (as :class:`plateqp.model.grid.Grid`): cell (i, j), i along x, j along y, has its
centre at ((i + ½) hx, (j + ½) hy) and the flat index j·nx + i; grid views are (ny, nx) arrays.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.fft
from scipy.sparse.linalg import LinearOperator

from ..errors import ProblemError
from .crossings import check_simple

#: The largest dense matrix :func:`flexibility` builds unless told otherwise: 1 GiB (m ≈ 11 585).
DENSE_LIMIT = 2**30
#: Entries (points × cells) of one block of the dense build: its temporaries stay near 2 MB each.
BLOCK = 2**18
#: Polygons of up to this many vertices are checked for self-intersection all pairs of edges at
#: once, many polygons together; larger ones one at a time (:func:`.crossings.check_simple`).
BATCH_VERTICES = 16
#: Relative tolerance of the geometric checks (coordinates' rounding), as in :mod:`.crossings`.
TOL = 1e-12
#: A point nearer an edge's line than this fraction of its length is on it (its triangle is flat).
ON_LINE = 1e-250
PER = ("pressure", "force")


def _number(value, name: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ProblemError(f"{name}: {value!r} is not a number") from None
    return v


def boussinesq_factor(E: float, nu: float) -> float:
    """(1 − ν²)/(π E): the settlement at unit distance of a unit point force; ProblemError unless
    E > 0 is finite and −1 < ν ≤ 0.5."""
    E, nu = _number(E, "E"), _number(nu, "nu")
    if not (0 < E < math.inf):
        raise ProblemError(f"E: the half-space's modulus must be a finite number > 0, got {E!r}")
    if not (-1 < nu <= 0.5):
        raise ProblemError(f"nu: the half-space's Poisson ratio must lie in (-1, 0.5], got {nu!r}")
    return (1 - nu * nu) / (math.pi * E)


def _edge_terms(px, py, ax, ay, bx, by):
    """The signed integral of 1/r over the triangle (P, A, B), P = (px, py), for arrays that
    broadcast: d [asinh(s/|d|)] from s_A to s_B, d > 0 with P left of A → B; 0 where P is on the
    edge's line (a flat triangle)."""
    ex, ey = bx - ax, by - ay
    L = np.hypot(ex, ey)
    tx, ty = ex / L, ey / L
    ux, uy = ax - px, ay - py
    vx, vy = bx - px, by - py
    d = ux * ty - uy * tx
    sa, sb = ux * tx + uy * ty, vx * tx + vy * ty
    h = np.abs(d)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        # the foot of the perpendicular inside the edge: two positive terms; outside it (s_A, s_B
        # of one sign) asinh u − asinh v = asinh((u² − v²)/(u √(1 + v²) + v √(1 + u²))), s_B − s_A = L
        across = np.arcsinh(sb / h) + np.arcsinh(-sa / h)
        # r = √(s² + d²) from s and d, not from the coordinates: consistent with them when a
        # rounding leaves d ≠ 0 at a vertex (s = 0), where the denominator must not vanish
        beside = np.arcsinh(L * (sa + sb) / (sb * np.hypot(sa, d) + sa * np.hypot(sb, d)))
        return np.where(h > ON_LINE * L, d * np.where((sa < 0) & (sb > 0), across, beside), 0.0)


def _potential(px, py, verts: np.ndarray, sign) -> np.ndarray:
    """Σ over the edges of ``verts`` (..., k, 2), checked, times the orientation ``sign``."""
    k = verts.shape[-2]
    total = 0.0
    for e in range(k):
        a, b = verts[..., e, :], verts[..., (e + 1) % k, :]
        total = total + _edge_terms(px, py, a[..., 0], a[..., 1], b[..., 0], b[..., 1])
    return total * sign


# -- checking polygons --------------------------------------------------------------------------------------

def _fail(where: str, what: str):
    raise ProblemError(f"{where}: {what}")


def _segments_meet(p1, p2, p3, p4, tol):
    """Whether closed segments p1p2 and p3p4 share a point (arrays (..., 2); ``tol`` on the
    orientations, a squared length), as :func:`.crossings._segments_cross`, vectorised."""
    def orient(a, b, c):
        return (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0])

    def within(p, a, b, eps):
        lo, hi = np.minimum(a, b) - eps[..., None], np.maximum(a, b) + eps[..., None]
        return np.all((p >= lo) & (p <= hi), axis=-1)

    d1, d2, d3, d4 = orient(p3, p4, p1), orient(p3, p4, p2), orient(p1, p2, p3), orient(p1, p2, p4)
    proper = (((d1 > tol) & (d2 < -tol)) | ((d1 < -tol) & (d2 > tol))) & \
             (((d3 > tol) & (d4 < -tol)) | ((d3 < -tol) & (d4 > tol)))
    eps = np.sqrt(tol)
    touch = ((np.abs(d1) <= tol) & within(p1, p3, p4, eps)) | ((np.abs(d2) <= tol) & within(p2, p3, p4, eps)) | \
            ((np.abs(d3) <= tol) & within(p3, p1, p2, eps)) | ((np.abs(d4) <= tol) & within(p4, p1, p2, eps))
    return proper | touch


def _check_polygons(polys: np.ndarray, names: list[str]) -> np.ndarray:
    """ProblemError naming the first bad polygon of ``polys`` (c, k, 2) unless each is simple, with
    k ≥ 3 finite vertices, no zero-length edge and an area; their signed areas (> 0 ccw, < 0 cw)."""
    c, k = polys.shape[:2]
    if k < 3:
        _fail(names[0], f"a polygon needs at least 3 vertices, got {k}")
    bad = ~np.isfinite(polys).all(axis=(1, 2))
    if bad.any():
        _fail(names[int(np.argmax(bad))], "the polygon's vertices must be finite numbers")
    v = polys - polys[:, :1]
    ext = np.ptp(v, axis=1).max(axis=1)
    edges = np.roll(v, -1, axis=1) - v
    length = np.hypot(edges[..., 0], edges[..., 1])
    zero = length <= TOL * ext[:, None]
    if zero.any():
        j, e = np.unravel_index(int(np.argmax(zero)), zero.shape)
        _fail(names[j], f"vertex {(e + 1) % k} repeats vertex {e} (a zero-length edge); give each vertex once")
    if k > BATCH_VERTICES:
        for j in range(c):
            seg = np.stack([v[j], np.roll(v[j], -1, axis=0)], axis=1)
            check_simple(seg, float(ext[j]), names[j], _fail)
    elif k > 3:
        i, m = np.triu_indices(k, 2)
        keep = ~((i == 0) & (m == k - 1))
        i, m = i[keep], m[keep]
        meet = _segments_meet(v[:, i], v[:, (i + 1) % k], v[:, m], v[:, (m + 1) % k], (TOL * ext**2)[:, None])
        if meet.any():
            j, p = np.unravel_index(int(np.argmax(meet)), meet.shape)
            _fail(names[j], f"self-intersecting: edge {i[p]} (vertices {i[p]}-{(i[p] + 1) % k}) meets edge "
                            f"{m[p]} (vertices {m[p]}-{(m[p] + 1) % k})")
    area2 = np.einsum("cki,cki->c", v, np.roll(v, -1, axis=1)[..., ::-1] * np.array([1.0, -1.0]))
    flat = np.abs(area2) <= TOL * ext**2
    if flat.any():
        _fail(names[int(np.argmax(flat))], "the polygon has no area (its vertices are collinear)")
    nxt = np.roll(edges, -1, axis=1)
    cross = edges[..., 0] * nxt[..., 1] - edges[..., 1] * nxt[..., 0]
    fold = (np.abs(cross) <= TOL * length * np.roll(length, -1, axis=1)) & (np.einsum("cki,cki->ck", edges, nxt) < 0)
    if fold.any():
        j, e = np.unravel_index(int(np.argmax(fold)), fold.shape)
        _fail(names[j], f"self-intersecting: edges {e} and {(e + 1) % k} fold back onto each other")
    return 0.5 * area2


def _as_polygon(polygon, name: str) -> np.ndarray:
    try:
        poly = np.asarray(polygon, dtype=float)
    except (TypeError, ValueError):
        raise ProblemError(f"{name}: not an array of vertices [[x, y], ...]") from None
    if poly.ndim != 2 or poly.shape[1] != 2:
        raise ProblemError(f"{name}: a polygon is a (k, 2) array of vertices [[x, y], ...], got shape {poly.shape}")
    return poly


# -- the integral over one polygon ------------------------------------------------------------------------

def polygon_potential(x, y, polygon) -> np.ndarray:
    """:math:`I = \\iint_\\Omega dA / \\lvert x - \\xi \\rvert` over the simple polygon Ω at the points (x, y).

    Parameters
    ----------
    x, y : array_like
        The field points' coordinates (arrays that broadcast); anywhere, on Ω's boundary too.
    polygon : array_like, shape (k, 2)
        The vertices of Ω in order, either orientation, each once (the ring is closed from the last
        vertex to the first); k ≥ 3, no zero-length edge, not self-intersecting.

    Returns
    -------
    ndarray
        I at each point, the broadcast shape of x and y: a length (the units of the coordinates),
        ≥ 0. The settlement under a uniform pressure q over Ω is q :func:`boussinesq_factor` · I.

    Raises
    ------
    ProblemError
        A degenerate polygon (too few vertices, collinear, a repeated vertex, self-intersecting),
        coordinates that are not finite.
    """
    poly = _as_polygon(polygon, "polygon")
    sign = np.sign(_check_polygons(poly[None], ["polygon"])[0])
    px, py = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    if not (np.isfinite(px).all() and np.isfinite(py).all()):
        raise ProblemError("x, y: the points' coordinates must be finite numbers")
    return np.asarray(_potential(px, py, poly, sign), dtype=float)


def rectangle_potential(x, y, x0: float, x1: float, y0: float, y1: float) -> np.ndarray:
    """:math:`I` over the rectangle [x0, x1] × [y0, y1] at the points (x, y), by Love's (1929)
    corner formula, a signed sum over the four corners (x_c, y_c):

    .. math::

        I = \\sum_c \\pm F(x_c - x, y_c - y), \\qquad
        F(u, v) = u \\operatorname{asinh} \\frac{v}{\\lvert u \\rvert}
                + v \\operatorname{asinh} \\frac{u}{\\lvert v \\rvert},

    F being Steinbrenner's corner integral (odd in u and in v; + at (x1, y1) and (x0, y0)). An
    independent route to :func:`polygon_potential`, exact too; but far from the rectangle its four
    terms cancel by about (r/h)², so prefer the polygon route there. Units and signs as
    :func:`polygon_potential`; ProblemError unless x0 < x1 and y0 < y1 are finite.
    """
    c = [_number(t, n) for t, n in ((x0, "x0"), (x1, "x1"), (y0, "y0"), (y1, "y1"))]
    if not (all(math.isfinite(t) for t in c) and c[0] < c[1] and c[2] < c[3]):
        raise ProblemError(f"x0, x1, y0, y1: a rectangle needs finite x0 < x1 and y0 < y1, got {c}")
    px, py = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))

    def F(u, v):
        au, av = np.abs(u), np.abs(v)
        with np.errstate(divide="ignore", invalid="ignore"):
            return (np.where(au > 0, u * np.arcsinh(v / au), 0.0) + np.where(av > 0, v * np.arcsinh(u / av), 0.0))

    x0, x1, y0, y1 = c
    return F(x1 - px, y1 - py) - F(x0 - px, y1 - py) - F(x1 - px, y0 - py) + F(x0 - px, y0 - py)


# -- the dense matrix of points and cells -----------------------------------------------------------------

def _check_per(per) -> str:
    if per not in PER:
        raise ProblemError(f"per: {per!r} is not one of {', '.join(PER)} (settlement per unit pressure or force)")
    return per


def _points(points) -> np.ndarray:
    try:
        pts = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise ProblemError("points: not an array of points [[x, y], ...]") from None
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ProblemError(f"points: an (m, 2) array of points [[x, y], ...], got shape {pts.shape}")
    if not np.isfinite(pts).all():
        raise ProblemError("points: the coordinates must be finite numbers")
    return pts


def _cell_groups(cells, m: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The cells checked and grouped by their number of vertices: [(column indices, (c, k, 2)
    vertices, signed areas)]."""
    if isinstance(cells, np.ndarray) and cells.ndim == 3:
        polys = [cells.astype(float)] if cells.shape[-1] == 2 else None
        ids = [np.arange(len(cells))]
        if polys is None:
            raise ProblemError(f"cells: an (m, k, 2) array of polygons, got shape {cells.shape}")
    else:
        try:
            seq = [_as_polygon(c, f"cells[{j}]") for j, c in enumerate(cells)]
        except TypeError:
            raise ProblemError("cells: a sequence of polygons, one (k, 2) array of vertices per point") from None
        ks = np.array([len(p) for p in seq], dtype=int)
        ids = [np.flatnonzero(ks == k) for k in np.unique(ks)]
        polys = [np.stack([seq[j] for j in idx]) for idx in ids]
    n = sum(len(i) for i in ids)
    if m >= 0 and n != m:
        raise ProblemError(f"cells: {n} cells for {m} points; give one cell (the tributary area) per point")
    return [(idx, p, _check_polygons(p, [f"cells[{j}]" for j in idx])) for idx, p in zip(ids, polys)]


def flexibility(points, cells, E: float, nu: float, *, per: str = "pressure",
                max_bytes: int = DENSE_LIMIT, owner=None) -> np.ndarray:
    """The dense surface flexibility of the half-space at ``points`` under uniform loads over ``cells``.

    Parameters
    ----------
    points : array_like, shape (m, 2)
        The contact points (x, y).
    cells : sequence of m polygons, or array (m, k, 2)
        Cell j is the tributary area of point j: its vertices in order, as in
        :func:`polygon_potential` (cells may have different numbers of vertices).
    E, nu : float
        The half-space's Young's modulus (> 0) and Poisson ratio (−1 < ν ≤ 0.5).
    per : {"pressure", "force"}
        ``"pressure"``: ``H[i, j]`` is the settlement at point i of a unit pressure (force/area 1)
        over cell j, settlements = H @ pressures (length³/force). ``"force"``: of a unit force
        spread uniformly over cell j, H[:, j] / area[j], settlements = H @ forces (length/force).
    max_bytes : int
        The refusal's limit on the matrix's 8 m² bytes (default :data:`DENSE_LIMIT`).
    owner : array_like of int, optional
        A point's tributary area made of several polygons (a mesh node's parts of its cells):
        ``owner[c]`` is the point (column) polygon c belongs to; the polygons of one point load
        it together, uniformly over their union (``per="force"``: over their total area). Any
        number of polygons then; every point must own at least one.

    Returns
    -------
    ndarray, shape (m, m)
        H, settlement positive downward under pressures positive downward. On equal cells each
        symmetric about its point (a grid's rectangles and their centres) H is symmetric (and, on
        the grids of the tests, positive definite: observed, not proven); otherwise reciprocity
        holds in forces to the cells' second moments, H[i, j] A_j − H[j, i] A_i = O(A h² / r³).

    Raises
    ------
    ProblemError
        Bad E, ν, points or cells (named), or a matrix above ``max_bytes``, before it is built.
    """
    factor = boussinesq_factor(E, nu)
    per = _check_per(per)
    pts = _points(points)
    m = len(pts)
    if 8 * m * m > max_bytes:
        raise ProblemError(f"points: a dense flexibility of m = {m} cells needs {8 * m * m} bytes, above the limit "
                           f"of {max_bytes} bytes (max_bytes); on a grid use GridFlexibility")
    if owner is None:
        H = np.empty((m, m))
        for idx, polys, area in _cell_groups(cells, m):
            scale = factor * np.sign(area) / (np.abs(area) if per == "force" else 1.0)
            rows = max(1, BLOCK // len(idx))
            for r0 in range(0, m, rows):
                px, py = pts[r0:r0 + rows, :1], pts[r0:r0 + rows, 1:]
                H[r0:r0 + rows, idx] = _potential(px, py, polys[None], 1.0) * scale
        return H
    import scipy.sparse as sp

    owner = np.asarray(owner)
    groups = _cell_groups(cells, len(owner) if owner.ndim == 1 else -1)
    if owner.ndim != 1 or not np.issubdtype(owner.dtype, np.integer) or (owner.size and not 0 <= owner.min() <= owner.max() < m):
        raise ProblemError(f"owner: one point index in 0 … {m - 1} per polygon, got {owner!r}"[:200])
    total = np.zeros(m)
    for idx, _, area in groups:
        np.add.at(total, owner[idx], np.abs(area))
    if np.any(total == 0):
        raise ProblemError(f"owner: point {int(np.flatnonzero(total == 0)[0])} owns no polygon")
    H = np.zeros((m, m))
    for idx, polys, area in groups:
        own = owner[idx]
        gather = sp.csr_matrix((factor * np.sign(area) / (total[own] if per == "force" else 1.0),
                                (np.arange(len(idx)), own)), shape=(len(idx), m))
        rows = max(1, BLOCK // len(idx))
        for r0 in range(0, m, rows):
            px, py = pts[r0:r0 + rows, :1], pts[r0:r0 + rows, 1:]
            H[r0:r0 + rows] += (gather.T @ _potential(px, py, polys[None], 1.0).T).T
    return H


# -- the grid of equal rectangles -------------------------------------------------------------------------

def _grid_args(nx, ny, hx, hy) -> tuple[int, int, float, float]:
    out = []
    for v, n in ((nx, "nx"), (ny, "ny")):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise ProblemError(f"{n}: the number of cells must be an integer ≥ 1, got {v!r}")
        out.append(int(v))
    for v, n in ((hx, "hx"), (hy, "hy")):
        h = _number(v, n)
        if not (0 < h < math.inf):
            raise ProblemError(f"{n}: the cell size must be a finite number > 0, got {v!r}")
        out.append(h)
    return out[0], out[1], out[2], out[3]


def grid_kernel(nx: int, ny: int, hx: float, hy: float, E: float, nu: float, *,
                per: str = "pressure") -> np.ndarray:
    """The flexibility of a grid of nx × ny equal cells hx × hy with their points at the centres,
    by index differences.

    Parameters
    ----------
    nx, ny : int
        The number of cells along x and along y (≥ 1).
    hx, hy : float
        The cells' sides (> 0).
    E, nu, per
        As :func:`flexibility`.

    Returns
    -------
    ndarray, shape (2 ny − 1, 2 nx − 1)
        ``K[ny − 1 + dj, nx − 1 + di]``: the settlement at the centre of cell (i + di, j + dj) of a
        unit pressure (``per="force"``: a unit force) over cell (i, j); the centre [ny − 1, nx − 1]
        is the diagonal. Even in di and in dj; rows along y, as the grid views.
        H[j·nx + i, l·nx + k] = K[ny − 1 + j − l, nx − 1 + i − k].
    """
    factor = boussinesq_factor(E, nu)
    nx, ny, hx, hy = _grid_args(nx, ny, hx, hy)
    scale = factor / (hx * hy) if _check_per(per) == "force" else factor
    rect = np.array([[-hx / 2, -hy / 2], [hx / 2, -hy / 2], [hx / 2, hy / 2], [-hx / 2, hy / 2]])
    dj, di = np.meshgrid(np.arange(ny) * hy, np.arange(nx) * hx, indexing="ij")
    quarter = _potential(di, dj, rect, 1.0) * scale
    K = np.empty((2 * ny - 1, 2 * nx - 1))
    K[ny - 1:, nx - 1:] = quarter
    K[ny - 1:, :nx] = quarter[:, ::-1]
    K[:ny, nx - 1:] = quarter[::-1]
    K[:ny, :nx] = quarter[::-1, ::-1]
    return K


class SymmetricOperator(LinearOperator):
    """A symmetric LinearOperator (its own adjoint) whose products check their argument's shape
    (a ProblemError in the subclass's words, :meth:`_shape_error`) and are computed by
    ``_matmat`` alone (a vector as a one-column matrix)."""

    def _shape_error(self, what: str, shape: tuple, n: int) -> str:
        raise NotImplementedError

    def _check(self, x, ndim: int):
        x = np.asarray(x)
        n = self.shape[1]
        if not ((x.ndim == ndim or (ndim == 1 and x.shape == (n, 1))) and x.shape[0] == n):
            raise ProblemError(self._shape_error("vector" if ndim == 1 else "matrix", x.shape, n))
        return x

    def matvec(self, x):
        return super().matvec(self._check(x, 1))

    def matmat(self, X):
        return super().matmat(self._check(X, 2))

    def _matvec(self, x):
        return self._matmat(np.asarray(x, dtype=float).reshape(-1, 1)).reshape(np.shape(x))

    def _rmatvec(self, x):
        return self._matvec(x)

    def _adjoint(self):
        return self


class GridFlexibility(SymmetricOperator):
    """The flexibility of a grid of equal rectangles, applied by FFT without forming the matrix.

    ``op @ p`` equals ``flexibility(centres, cells, E, nu, per=per) @ p`` over the cells of
    ``mask`` (all cells without one): p holds the pressures (``per="force"``: forces) of the kept
    cells in grid order (flat index j·nx + i, skipping the others), the answer their settlements;
    cells outside the mask carry nothing and are not returned. A scipy LinearOperator (``matvec``,
    ``matmat``, ``@``, usable by ``scipy.sparse.linalg.cg``), symmetric (its own adjoint).

    The kernel (:func:`grid_kernel`) is laid out by wrap-around on a grid of at least
    (2 ny − 1) × (2 nx − 1) and transformed once (rfft2); each product zero-pads p to that grid,
    multiplies the transforms and keeps the first ny × nx values of the inverse: the discrete
    convolution, exact to rounding (Liu, Wang & Liu 2000), O(N log N) work and O(N) memory.

    Parameters
    ----------
    nx, ny : int
        The number of cells along x and along y.
    hx, hy : float
        The cells' sides.
    E, nu : float
        The half-space, as :func:`flexibility`.
    mask : array_like of bool, shape (ny, nx) or (nx · ny,), optional
        The cells in the contact region (default: all).
    per : {"pressure", "force"}
        What p holds, as :func:`flexibility`.

    Attributes
    ----------
    kernel : ndarray, shape (2 ny − 1, 2 nx − 1)
        :func:`grid_kernel`.
    mask : ndarray of bool, shape (ny, nx)
        The kept cells.
    kept : ndarray of int
        The kept cells' flat indices j·nx + i, increasing: the order of p.
    """

    def __init__(self, nx: int, ny: int, hx: float, hy: float, E: float, nu: float, *,
                 mask=None, per: str = "pressure") -> None:
        self.kernel = grid_kernel(nx, ny, hx, hy, E, nu, per=per)
        self.nx, self.ny, self.hx, self.hy = _grid_args(nx, ny, hx, hy)
        nx, ny = self.nx, self.ny
        if mask is None:
            mask = np.ones((ny, nx), dtype=bool)
        mask = np.asarray(mask)
        if mask.dtype != bool or mask.shape not in ((ny, nx), (nx * ny,)):
            raise ProblemError(f"mask: a boolean array of shape ({ny}, {nx}) or ({nx * ny},), got {mask.dtype} "
                               f"of shape {mask.shape}")
        self.mask = mask.reshape(ny, nx).copy()
        self.kept = np.flatnonzero(self.mask.ravel())
        self.fft_shape = (scipy.fft.next_fast_len(2 * ny - 1, real=True),
                          scipy.fft.next_fast_len(2 * nx - 1, real=True))
        Ny, Nx = self.fft_shape
        K, wrapped = self.kernel, np.zeros(self.fft_shape)
        wrapped[:ny, :nx] = K[ny - 1:, nx - 1:]
        wrapped[:ny, Nx - nx + 1:] = K[ny - 1:, :nx - 1]
        wrapped[Ny - ny + 1:, :nx] = K[:ny - 1, nx - 1:]
        wrapped[Ny - ny + 1:, Nx - nx + 1:] = K[:ny - 1, :nx - 1]
        self._kernel_hat = scipy.fft.rfft2(wrapped)
        n = len(self.kept)
        super().__init__(dtype=np.float64, shape=(n, n))

    def diagonal(self) -> np.ndarray:
        """The matrix's diagonal: one value, the kernel's centre, for every kept cell."""
        return np.full(self.shape[0], self.kernel[self.ny - 1, self.nx - 1])

    def _shape_error(self, what: str, shape: tuple, n: int) -> str:
        return f"GridFlexibility: a {what} of shape {shape} for {n} cells; give one value per kept cell ({n}), in grid order"

    def _matmat(self, X):
        X = np.asarray(X, dtype=float)
        ny, nx = self.ny, self.nx
        out = np.empty_like(X)
        cols = max(1, (BLOCK * 16) // (self.fft_shape[0] * self.fft_shape[1]))
        for c0 in range(0, X.shape[1], cols):
            block = X[:, c0:c0 + cols]
            grid = np.zeros((block.shape[1], ny * nx))
            grid[:, self.kept] = block.T
            spectrum = scipy.fft.rfft2(grid.reshape(-1, ny, nx), s=self.fft_shape) * self._kernel_hat
            w = scipy.fft.irfft2(spectrum, s=self.fft_shape)[:, :ny, :nx].reshape(-1, ny * nx)
            out[:, c0:c0 + cols] = w[:, self.kept].T
        return out
