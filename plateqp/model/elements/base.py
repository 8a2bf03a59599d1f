"""Rectangular Kirchhoff plate elements built from a monomial basis and nodal Hermite dofs.

An element is fixed by two tables: the monomials ``ξ^i η^j`` of its interpolation and the
derivatives of w it carries at each corner node. The shape functions follow by inverting the
matrix that evaluates those dofs on the monomials. Everything else (stiffness, loads,
interpolation, curvatures) is the same code for every element.

Local coordinates: ξ = (x − x0)/hx, η = (y − y0)/hy in [0, 1]; corner nodes in the order
(0, 0), (1, 0), (1, 1), (0, 1). Nodal dofs are *physical* derivatives of w
(w, ∂w/∂x, ∂w/∂y, ∂²w/∂x∂y), so they are shared between neighbouring cells as they are.

Sign conventions: w positive downward (the direction of positive load). The slope dofs are
plain derivatives: ``wx`` = ∂w/∂x, ``wy`` = ∂w/∂y (the plate rotations of the classical
notation are θx = ∂w/∂y and θy = −∂w/∂x). Curvature vector κ = (w,xx, w,yy, 2 w,xy);
moments M = −D_b κ, i.e. Mx = −D(w,xx + ν w,yy), My = −D(w,yy + ν w,xx),
Mxy = −D(1 − ν) w,xy (Mx > 0 sags: tension at the bottom face).
"""

from __future__ import annotations

import numpy as np

CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])

# Gauss–Legendre rule on [0, 1]; 4 points integrate degree 7 exactly in each direction,
# enough for the stiffness and consistent loads of ACM and BFS.
_gp, _gw = np.polynomial.legendre.leggauss(4)
GAUSS_X = 0.5 * (_gp + 1.0)
GAUSS_W = 0.5 * _gw
#: the corners, 1e-9 of a cell inside it; the derivative orders of (w,xx, w,yy, w,xy)
_INSIDE = 1e-9 + (1.0 - 2e-9) * CORNERS
_CURVATURE_ORDERS = ((2, 0), (0, 2), (1, 1))


def _sizes(xy) -> list[tuple[tuple[float, float], np.ndarray]]:
    """Cells given by their corners (ncell, 4, 2), grouped by size: [((hx, hy), indices)]. Sides
    within 1e-9 of each other are one size (a grid's corners i·h differ from one another by a
    rounding), evaluated at the group's median."""
    xy = np.asarray(xy, dtype=float)
    hxy = np.column_stack([xy[:, 1, 0] - xy[:, 0, 0], xy[:, 3, 1] - xy[:, 0, 1]])
    if len(hxy) == 0:
        return [((1.0, 1.0), np.arange(0))]
    ref = np.median(hxy, axis=0)
    if np.all(np.abs(hxy - ref) <= 1e-9 * ref):  # one size: a grid
        return [(tuple(ref), np.arange(len(hxy)))]
    _, first, which = np.unique(np.round(np.log2(hxy) * 2**30), axis=0, return_index=True, return_inverse=True)
    which = which.ravel()
    return [(tuple(np.median(hxy[which == k], axis=0)), np.flatnonzero(which == k)) for k in range(len(first))]


def bending_matrix(D: float, nu: float) -> np.ndarray:
    """Constitutive matrix D_b with M = −D_b κ, κ = (w,xx, w,yy, 2w,xy)."""
    return D * np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]])


#: each element class's shape-function coefficients, worked out once per process (0.8 ms a
#: model: a Python loop over its monomials; a solve with a coarse prediction builds two models)
_COEF: dict[type, np.ndarray] = {}


class RectElement:
    """Base class: subclasses set ``name``, ``monomials`` and ``node_dofs``."""

    name: str = ""
    cell_type: str = "quad"
    monomials: tuple[tuple[int, int], ...] = ()
    node_dofs: tuple[tuple[int, int], ...] = ()  # derivative orders (dx, dy) per nodal dof
    dof_names: tuple[str, ...] = ()
    #: the slope dofs are physical derivatives shared along straight, axis-parallel edges: a
    #: simple edge (w constant along it) also prescribes the tangential slope
    #: (:mod:`plateqp.model.constraints`)
    holds_tangent_slope: bool = True

    def __init__(self) -> None:
        coef = _COEF.get(type(self))
        if coef is None:
            # A[k, m]: dof k evaluated on monomial m, in reference coordinates
            nd = len(self.node_dofs)
            A = np.zeros((4 * nd, len(self.monomials)))
            for c, (xi, eta) in enumerate(CORNERS):
                for d, (dx, dy) in enumerate(self.node_dofs):
                    A[c * nd + d] = self._monomial_values(np.array([xi]), np.array([eta]), dx, dy)[0]
            # coefficients of shape function k: column k of inv(A)
            coef = np.linalg.inv(A)
            coef.setflags(write=False)
            _COEF[type(self)] = coef
        self._coef = coef

    @property
    def ndof_node(self) -> int:
        return len(self.node_dofs)

    @property
    def ndof(self) -> int:
        return 4 * len(self.node_dofs)

    # -- polynomial machinery -------------------------------------------------------------
    def _monomial_values(self, xi: np.ndarray, eta: np.ndarray, dx: int, dy: int) -> np.ndarray:
        """(npts, nmono): ∂^{dx+dy}/∂ξ^dx∂η^dy of each monomial at the points."""
        out = np.zeros((xi.size, len(self.monomials)))
        for m, (i, j) in enumerate(self.monomials):
            if i < dx or j < dy:
                continue
            ci = np.prod(np.arange(i - dx + 1, i + 1)) if dx else 1.0
            cj = np.prod(np.arange(j - dy + 1, j + 1)) if dy else 1.0
            out[:, m] = ci * cj * xi ** (i - dx) * eta ** (j - dy)
        return out

    def _dof_scale(self, hx: float, hy: float) -> np.ndarray:
        """Reference dof = scale × physical dof (∂/∂ξ = hx ∂/∂x)."""
        s = np.array([hx**dx * hy**dy for dx, dy in self.node_dofs])
        return np.tile(s, 4)

    def shape(self, xi, eta, hx: float, hy: float, dx: int = 0, dy: int = 0) -> np.ndarray:
        """(npts, ndof): ∂^{dx+dy} N / ∂x^dx ∂y^dy at local points, for physical dofs."""
        xi = np.atleast_1d(np.asarray(xi, dtype=float))
        eta = np.atleast_1d(np.asarray(eta, dtype=float))
        N = self._monomial_values(xi, eta, dx, dy) @ self._coef
        return N * self._dof_scale(hx, hy) / (hx**dx * hy**dy)

    def curvature_matrix(self, xi, eta, hx: float, hy: float) -> np.ndarray:
        """(npts, 3, ndof): κ = (w,xx, w,yy, 2 w,xy) = B u_e at the points."""
        return np.stack(
            [
                self.shape(xi, eta, hx, hy, 2, 0),
                self.shape(xi, eta, hx, hy, 0, 2),
                2.0 * self.shape(xi, eta, hx, hy, 1, 1),
            ],
            axis=1,
        )

    # -- the protocol every element answers (cells given by their corners' coordinates) --------
    def basis(self, xy, local, dx: int = 0, dy: int = 0) -> np.ndarray:
        """(npts, ndof): ∂^(dx+dy) N / ∂x^dx ∂y^dy of each point's cell, the points given by their
        cell's corners ``xy`` (npts, 4, 2) and their local coordinates ``local`` (npts, 2) = (ξ, η)
        (:meth:`plateqp.model.grid.Grid.locate`). Cells of one size share one evaluation."""
        local = np.asarray(local, dtype=float).reshape(-1, 2)
        out = np.empty((local.shape[0], self.ndof))
        for (sx, sy), at in _sizes(xy):
            out[at] = self.shape(local[at, 0], local[at, 1], sx, sy, dx, dy)
        return out

    def corner_curvatures(self, xy) -> np.ndarray:
        """(ncell, 4, 3, ndof): the curvatures (w,xx, w,yy, w,xy) of each cell (corners ``xy``
        (ncell, 4, 2)) at each of its corners, evaluated just inside it (1e-9 of the cell) so
        that the value is the cell's own."""
        return self._per_size(xy, lambda sx, sy: np.stack(
            [self.shape(_INSIDE[:, 0], _INSIDE[:, 1], sx, sy, dx, dy) for dx, dy in _CURVATURE_ORDERS], axis=1))

    def corner_w(self, xy) -> np.ndarray:
        """(ncell, 4, ndof): w of each cell just inside each of its corners (as
        :meth:`corner_curvatures`)."""
        return self._per_size(xy, lambda sx, sy: self.shape(_INSIDE[:, 0], _INSIDE[:, 1], sx, sy))

    def cell_stiffness(self, xy, D: float, nu: float) -> np.ndarray:
        """(ncell, ndof, ndof): :meth:`stiffness` of each cell (corners ``xy`` (ncell, 4, 2))."""
        return self._per_size(xy, lambda sx, sy: self.stiffness(sx, sy, D, nu))

    def cell_load(self, xy) -> np.ndarray:
        """(ncell, ndof): the consistent load of a unit pressure over each cell."""
        return self._per_size(xy, lambda sx, sy: self.load(sx, sy))

    def region_load(self, xy, region) -> tuple[np.ndarray, np.ndarray]:
        """(hit, loads): the cells (indices into ``xy``) a unit pressure on ``region`` covers in
        part, and their consistent loads (len(hit), ndof), integrated exactly over each cell's part
        in it: a box [x0, x1, y0, y1] by :meth:`load` on the sub-box; a polygon or a circle
        (:func:`plateqp.model.geometry.parse_region`) by the moments of each cut cell's part
        (:func:`plateqp.model.regions.part_moments`: a circle's arcs to rounding), whole cells by
        :meth:`load`."""
        from ..regions import as_shape, box_of

        xy = np.asarray(xy, dtype=float)
        box = box_of(region)
        hits, loads = [], []
        for (sx, sy), at in _sizes(xy):
            if box is not None:
                hit, fe = self._box_load(xy[at], box, sx, sy)
            else:
                hit, fe = self._shape_load(xy[at], as_shape(region), sx, sy)
            hits.append(at[hit])
            loads.append(fe)
        if not hits:
            return np.zeros(0, dtype=int), np.zeros((0, self.ndof))
        return np.concatenate(hits), np.vstack(loads)

    def _box_load(self, xy, box, sx: float, sy: float):
        x0, x1, y0, y1 = box
        ox, oy = xy[:, 0, 0], xy[:, 0, 1]
        b = np.column_stack([np.clip((x0 - ox) / sx, 0, 1), np.clip((x1 - ox) / sx, 0, 1),
                             np.clip((y0 - oy) / sy, 0, 1), np.clip((y1 - oy) / sy, 0, 1)])
        hit = np.flatnonzero((b[:, 1] > b[:, 0]) & (b[:, 3] > b[:, 2]))
        return hit, self.load(sx, sy, b[hit]) if hit.size else np.zeros((0, self.ndof))

    def _shape_load(self, xy, shape, sx: float, sy: float):
        """Cells of one size (sx, sy): the whole ones' :meth:`load`, each cut one's ∫ N dA over its
        part, Σ_m (∫∫ ξ^i η^j dA) × the shape functions' monomial coefficients."""
        from ..regions import part_moments, split_cells

        whole, cut = split_cells(xy, shape)
        I, J = np.array(self.monomials).T
        scale = self._dof_scale(sx, sy)
        parts = []
        for c in cut:
            M = part_moments(xy[c], shape, xy[c, 0], (sx, sy), int(max(I.max(), J.max())))
            parts.append((c, M[0, 0], (M[I, J] @ self._coef) * scale))
        cut_hit = [c for c, area, _ in parts if area > 1e-10 * sx * sy]
        fe = [f for _, area, f in parts if area > 1e-10 * sx * sy]
        hit = np.concatenate([whole, np.array(cut_hit, dtype=int)])
        out = np.vstack([np.tile(self.load(sx, sy), (len(whole), 1))] + ([np.array(fe)] if fe else []))
        return hit, out

    def _per_size(self, xy, make) -> np.ndarray:
        groups = _sizes(xy)
        out = np.empty((len(np.asarray(xy)),) + np.shape(make(*groups[0][0])))
        for (sx, sy), at in groups:
            out[at] = make(sx, sy)
        return out

    # -- element matrices -------------------------------------------------------------------
    def _gauss(self):
        xi, eta = np.meshgrid(GAUSS_X, GAUSS_X, indexing="ij")
        w = np.outer(GAUSS_W, GAUSS_W)
        return xi.ravel(), eta.ravel(), w.ravel()

    def stiffness(self, hx: float, hy: float, D: float, nu: float) -> np.ndarray:
        """Element stiffness ∫ Bᵀ D_b B dA (exact Gauss quadrature)."""
        xi, eta, w = self._gauss()
        B = self.curvature_matrix(xi, eta, hx, hy)
        Db = bending_matrix(D, nu)
        K = np.einsum("p,pik,ij,pjl->kl", w, B, Db, B) * hx * hy
        return 0.5 * (K + K.T)

    def load(self, hx: float, hy: float, boxes=None) -> np.ndarray:
        """Consistent loads of a unit pressure over local sub-boxes.

        ``boxes``: (m, 4) rows (ξ0, ξ1, η0, η1) within [0, 1]²; None means the whole cell.
        Returns (m, ndof), or (ndof,) when ``boxes`` is None.
        """
        single = boxes is None
        boxes = np.array([[0.0, 1.0, 0.0, 1.0]]) if single else np.atleast_2d(np.asarray(boxes, float))
        gx, gy, w = self._gauss()
        x0, x1, y0, y1 = boxes.T
        xi = x0[:, None] + (x1 - x0)[:, None] * gx[None, :]
        eta = y0[:, None] + (y1 - y0)[:, None] * gy[None, :]
        N = self.shape(xi.ravel(), eta.ravel(), hx, hy).reshape(len(boxes), len(w), self.ndof)
        out = np.einsum("p,mpk->mk", w, N) * ((x1 - x0) * (y1 - y0) * hx * hy)[:, None]
        return out[0] if single else out
