"""DKT (Discrete Kirchhoff Triangle) 9-dof plate element, Batoz, Bathe & Ho (1980).

Dofs per vertex: w, ∂w/∂x, ∂w/∂y (the dof set of ACM, so the contact code's scaling and rigid
modes hold unchanged). Sign convention: w positive downward; the "rotations" are the slopes
themselves, βx = ∂w/∂x, βy = ∂w/∂y (Batoz's θx = ∂w/∂y, θy = −∂w/∂x in the classical notation).

Construction (Batoz et al. 1980, IJNME 15, 1771): the slope field β is quadratic on the 6-node
triangle (vertices and edge midpoints); the Kirchhoff hypothesis is imposed discretely: β = ∇w at
the vertices (the nodal dofs), and at each edge midpoint the tangential slope is that of the
cubic w along the edge (Hermite from both ends' w and tangential slopes) while the normal slope
varies linearly along the edge. Curvatures κ = (βx,x, βy,y, βx,y + βy,x) are linear in the
element, so the stiffness ∫ Bᵀ D_b B dA is exact with the 3-point (edge midpoint) rule.
Moments M = −D_b κ as for the rectangles (:mod:`plateqp.model.elements.base`).

The deflection inside an element (for point loads off the nodes and w at any point) is the
cubic Hermite triangle on the same 9 dofs, its centroid value fixed by the rule that is exact for
quadratics, w_c = Σ w_i / 3 + Σ ∇w_i · (x_c − x_i) / 6. Uniform pressure is applied **lumped**:
q × area / 3 on each vertex's w, no moments (statically exact, force and moment; the same
tributary areas as a tensionless bed's springs, so a free plate on a uniform bed under uniform
pressure sinks by exactly q / k; the consistent load of the cubic was measured as accurate, within
0.3 % of it on the circular plates at R/16). DKT converges with order h² in deflection.
"""

from __future__ import annotations

import numpy as np

from .base import bending_matrix

#: 3-point rule at the edge midpoints (exact for quadratics): barycentric points, weights / area
MID_POINTS = np.array([[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]])
MID_WEIGHTS = np.full(3, 1.0 / 3.0)
EDGES = ((0, 1), (1, 2), (2, 0))  # midside node 3 + e on edge e
#: triangles a chunk of :meth:`DKT.stiffness` (its temporaries about a megabyte each)
CHUNK = 2048
_CUBIC = [(i, j) for n in range(4) for i in range(n, -1, -1) for j in (n - i,)]  # 10 monomials x^i y^j


def _as_tris(xy) -> np.ndarray:
    xy = np.asarray(xy, dtype=float)
    return xy[None] if xy.ndim == 2 else xy


class DKT:
    """The Discrete Kirchhoff Triangle; every method takes vertex coordinates ``xy`` of shape
    (3, 2) or (nt, 3, 2), counter-clockwise."""

    name = "dkt"
    cell_type = "triangle"
    node_dofs = ((0, 0), (1, 0), (0, 1))
    dof_names = ("w", "wx", "wy")
    ndof_node = 3
    ndof = 9

    # -- geometry ---------------------------------------------------------------------------
    @staticmethod
    def _grad_l(xy):
        """(nt, 3, 2) gradients of the barycentric coordinates, and (nt,) areas."""
        x, y = xy[..., 0], xy[..., 1]
        b = np.stack([y[:, 1] - y[:, 2], y[:, 2] - y[:, 0], y[:, 0] - y[:, 1]], axis=1)
        c = np.stack([x[:, 2] - x[:, 1], x[:, 0] - x[:, 2], x[:, 1] - x[:, 0]], axis=1)
        area = 0.5 * (b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0])
        return np.stack([b, c], axis=2) / (2.0 * area)[:, None, None], area

    @staticmethod
    def slope_transform(xy) -> np.ndarray:
        """(nt, 12, 9): the slopes (βx at the 6 nodes, then βy at the 6 nodes) from the dofs."""
        xy = _as_tris(xy)
        nt = xy.shape[0]
        T = np.zeros((nt, 12, 9))
        for v in range(3):  # at the vertices β is the nodal slope
            T[:, v, 3 * v + 1] = 1.0
            T[:, 6 + v, 3 * v + 2] = 1.0
        for e, (i, j) in enumerate(EDGES):
            d = xy[:, j] - xy[:, i]
            L = np.hypot(d[:, 0], d[:, 1])
            s = d / L[:, None]
            # β_mid = 1.5 s (w_j − w_i)/L + (I/2 − 3/4 s sᵀ)(β_i + β_j)
            P = 0.5 * np.eye(2)[None] - 0.75 * s[:, :, None] * s[:, None, :]
            for r in range(2):  # r: x or y component of β
                row = 6 * r + 3 + e
                T[:, row, 3 * j] = 1.5 * s[:, r] / L
                T[:, row, 3 * i] = -1.5 * s[:, r] / L
                for v in (i, j):
                    T[:, row, 3 * v + 1] = P[:, r, 0]
                    T[:, row, 3 * v + 2] = P[:, r, 1]
        return T

    @staticmethod
    def _apply_slopes(bx, by, edges, out) -> np.ndarray:
        """A row on the 12 nodal slopes (weights ``bx`` on βx, ``by`` on βy at the 6 nodes, each
        (6, nt, npts), or None for zero) on the 9 dofs: the row times :meth:`slope_transform`,
        without forming it: its vertex rows pick a slope dof, its midside rows (β_mid =
        1.5 s (w_j − w_i)/L + (I/2 − 3/4 s sᵀ)(β_i + β_j)) have six entries each. Written into
        ``out`` (9, nt, npts), zeros on entry."""
        if bx is not None:
            out[1::3] = bx[:3]  # βx at the vertices: the dofs wx
        if by is not None:
            out[2::3] = by[:3]  # βy: wy
        for e, (i, j) in enumerate(EDGES):
            sxl, syl, axx, axy, ayy = edges[e]
            if by is None:
                w, px, py = bx[3 + e] * sxl, bx[3 + e] * axx, bx[3 + e] * axy
            elif bx is None:
                w, px, py = by[3 + e] * syl, by[3 + e] * axy, by[3 + e] * ayy
            else:
                w = bx[3 + e] * sxl + by[3 + e] * syl
                px = bx[3 + e] * axx + by[3 + e] * axy
                py = bx[3 + e] * axy + by[3 + e] * ayy
            out[3 * j] += w
            out[3 * i] -= w
            for v in (i, j):
                out[3 * v + 1] += px
                out[3 * v + 2] += py
        return out

    def _curvature_first(self, xy, lam) -> np.ndarray:
        """(9, 3, nt, npts): :meth:`curvature_matrix` with the dofs and the components first (each
        slab contiguous over the triangles and points)."""
        G, _ = self._grad_l(xy)  # (nt, 3, 2)
        # quadratic 6-node shape functions: N_v = L_v (2 L_v − 1), N_{3+e} = 4 L_i L_j
        dN_dL = np.zeros(lam.shape[:-1] + (6, 3))
        for v in range(3):
            dN_dL[..., v, v] = 4.0 * lam[..., v] - 1.0
        for e, (i, j) in enumerate(EDGES):
            dN_dL[..., 3 + e, i] = 4.0 * lam[..., j]
            dN_dL[..., 3 + e, j] = 4.0 * lam[..., i]
        nt = len(xy)
        if lam.ndim == 2:  # the same points in every triangle: one product
            npts = len(lam)
            dN = (np.swapaxes(G, 1, 2).reshape(2 * nt, 3) @ dN_dL.transpose(2, 0, 1).reshape(3, -1))
            dN = dN.reshape(nt, 2, npts, 6).transpose(1, 3, 0, 2)  # (2, 6, nt, npts)
        else:
            dN = np.einsum("tpnk,tkd->dntp", dN_dL, G)
        edges = []  # per edge, (nt, 1) to broadcast over the points: 1.5 s / L and I/2 − 3/4 s sᵀ
        for i, j in EDGES:
            d = xy[:, j] - xy[:, i]
            L = np.hypot(d[:, 0], d[:, 1])[:, None]
            sx, sy = d[:, 0:1] / L, d[:, 1:2] / L
            edges.append((1.5 * sx / L, 1.5 * sy / L, 0.5 - 0.75 * sx * sx, -0.75 * sx * sy, 0.5 - 0.75 * sy * sy))
        out = np.zeros((9, 3) + dN.shape[2:])
        self._apply_slopes(dN[0], None, edges, out[:, 0])  # κ1 = βx,x
        self._apply_slopes(None, dN[1], edges, out[:, 1])  # κ2 = βy,y
        self._apply_slopes(dN[1], dN[0], edges, out[:, 2])  # κ3 = βx,y + βy,x
        return out

    def curvature_matrix(self, xy, lam) -> np.ndarray:
        """(nt, npts, 3, 9): κ = (w,xx, w,yy, 2 w,xy) = B u_e at barycentric points ``lam``: (npts, 3),
        the same in every triangle, or (nt, npts, 3), each triangle its own."""
        xy = _as_tris(xy)
        lam = np.atleast_2d(np.asarray(lam, dtype=float))
        return np.ascontiguousarray(self._curvature_first(xy, lam).transpose(2, 3, 1, 0))

    # -- element matrices -------------------------------------------------------------------
    def stiffness(self, xy, D: float, nu: float) -> np.ndarray:
        """(nt, 9, 9) element stiffness ∫ Bᵀ D_b B dA (exact: B is linear, 3-point rule), exactly
        symmetric: with D_b = Lᵀ L (Cholesky), Σ_p w_p A (L B_p)ᵀ (L B_p), one product XᵀX over
        the stacked (component, point) rows X, in chunks of :data:`CHUNK` triangles (their
        temporaries stay in cache)."""
        xy = _as_tris(xy)
        nt = len(xy)
        L = np.linalg.cholesky(bending_matrix(D, nu)).T  # upper triangular, D_b = Lᵀ L
        K = np.empty((nt, 9, 9))
        for a in range(0, nt, CHUNK):
            part = xy[a:a + CHUNK]
            n = len(part)
            _, area = self._grad_l(part)
            C = self._curvature_first(part, MID_POINTS)  # (9 dofs, 3 components, n, 3 points)
            s = np.sqrt(MID_WEIGHTS[0] * area)[:, None]
            X = np.empty((3, 9, n, 3))  # L κ, scaled by √(w A)
            np.multiply(C[:, 0], L[0, 0], out=X[0])
            X[0] += L[0, 1] * C[:, 1]
            X[0] *= s
            np.multiply(C[:, 1], L[1, 1] * s, out=X[1])
            np.multiply(C[:, 2], L[2, 2] * s, out=X[2])
            X = np.ascontiguousarray(X.transpose(2, 0, 3, 1)).reshape(n, 9, 9)  # (triangle, rows, dofs)
            np.matmul(np.swapaxes(X, 1, 2), X, out=K[a:a + n])
        return K

    def shape(self, xy, lam) -> np.ndarray:
        """(nt, npts, 9): the cubic Hermite deflection shape functions at barycentric points
        ``lam`` (npts, 3), the same in every triangle, or (nt, npts, 3), each triangle its own."""
        xy = _as_tris(xy)
        lam = np.atleast_2d(np.asarray(lam, dtype=float))
        nt = xy.shape[0]
        origin = xy.mean(axis=1)  # local monomials about the centroid, scaled by the size
        scale = np.abs(xy - origin[:, None]).max(axis=(1, 2))

        def mono(p, dx=0, dy=0):  # p (nt, k, 2) → (nt, k, 10)
            u = (p[..., 0] - origin[:, None, 0]) / scale[:, None]
            v = (p[..., 1] - origin[:, None, 1]) / scale[:, None]
            out = np.zeros(p.shape[:2] + (10,))
            for m, (i, j) in enumerate(_CUBIC):
                if i >= dx and j >= dy:
                    ci = 1.0 if dx == 0 else float(i)
                    cj = 1.0 if dy == 0 else float(j)
                    out[..., m] = ci * cj * u ** (i - dx) * v ** (j - dy) / scale[:, None] ** (dx + dy)
            return out

        A = np.zeros((nt, 10, 10))
        A[:, 0:9:3] = mono(xy)
        A[:, 1:9:3] = mono(xy, 1, 0)
        A[:, 2:9:3] = mono(xy, 0, 1)
        A[:, 9] = mono(origin[:, None])[:, 0]
        E = np.zeros((nt, 10, 9))
        E[:, :9, :9] = np.eye(9)
        for v in range(3):  # w_c = Σ w_i / 3 + Σ ∇w_i · (x_c − x_i) / 6
            E[:, 9, 3 * v] = 1.0 / 3.0
            E[:, 9, 3 * v + 1] = (origin[:, 0] - xy[:, v, 0]) / 6.0
            E[:, 9, 3 * v + 2] = (origin[:, 1] - xy[:, v, 1]) / 6.0
        pts = np.einsum("pk,tkd->tpd" if lam.ndim == 2 else "tpk,tkd->tpd", lam, xy)
        return mono(pts) @ np.linalg.solve(A, E)

    def load(self, xy) -> np.ndarray:
        """(nt, 9) lumped loads of a unit pressure over each element: area / 3 on each vertex's w."""
        xy = _as_tris(xy)
        _, area = self._grad_l(xy)
        f = np.zeros((xy.shape[0], 9))
        f[:, 0::3] = area[:, None] / 3.0
        return f

    # -- the protocol every element answers (cells given by their corners' coordinates) --------
    def basis(self, xy, local, dx: int = 0, dy: int = 0) -> np.ndarray:
        """(npts, 9): the basis of ∂^(dx+dy) w / ∂x^dx ∂y^dy at points given by their triangle's
        vertices ``xy`` (npts, 3, 2) and barycentric coordinates ``local`` (npts, 3)
        (:meth:`plateqp.model.trimesh.TriMesh.locate`): w the cubic (a vertex's own w dof exactly at a
        vertex), the slopes (dx + dy = 1) and curvatures (dx + dy = 2) DKT's own, from its quadratic
        slope field β: w,x = βx, w,xx = βx,x, w,xy = (βx,y + βy,x)/2 (so moments and stresses are
        the element's M = −D_b κ)."""
        lam = np.asarray(local, dtype=float).reshape(-1, 3)
        if dx + dy == 1:
            N = self.slope_matrix(xy, lam[:, None, :])[:, 0, dy]
        elif dx + dy == 2:
            B = self.curvature_matrix(xy, lam[:, None, :])[:, 0]
            N = B[:, 0] if dx == 2 else B[:, 1] if dy == 2 else 0.5 * B[:, 2]
        else:
            N = self.shape(xy, lam[:, None, :])[:, 0]
        at_node = (lam.max(axis=1) >= 1.0 - 1e-12) & (dx + dy < 2)  # a vertex: its own dof, no rounding noise
        if at_node.any():
            N[at_node] = 0.0
            N[at_node, 3 * lam[at_node].argmax(axis=1) + list(self.node_dofs).index((dx, dy))] = 1.0
        return N

    def corner_curvatures(self, xy) -> np.ndarray:
        """(nt, 3, 3, 9): the curvatures (w,xx, w,yy, w,xy) of each triangle at each of its
        vertices (DKT's linear curvature field, :meth:`curvature_matrix` with κ3 = 2 w,xy halved)."""
        B = self.curvature_matrix(xy, np.eye(3)).copy()
        B[..., 2, :] *= 0.5
        return B

    def corner_w(self, xy) -> None:
        """None: a triangle's w at a vertex is the vertex's own w dof."""

    def cell_stiffness(self, xy, D: float, nu: float) -> np.ndarray:
        """(nt, 9, 9): :meth:`stiffness`."""
        return self.stiffness(xy, D, nu)

    def cell_load(self, xy) -> np.ndarray:
        """(nt, 9): :meth:`load`, a unit pressure lumped on each triangle."""
        return self.load(xy)

    def region_load(self, xy, region) -> tuple[np.ndarray, np.ndarray]:
        """(hit, loads): the triangles (indices into ``xy``) a unit pressure on ``region`` (a box
        [x0, x1, y0, y1], a polygon or a circle: :func:`plateqp.model.geometry.parse_region`) covers in
        part, and their loads (len(hit), 9), lumped on the vertices' w: over each triangle's part
        A_t in the region, ∫ λ_i dA = |A_t| λ_i(centroid of A_t) (λ the barycentric coordinates).
        The uniform load's lumping where the region covers a triangle; statically exact: the
        total is the region's area on the mesh, the moment that of the pressure on it."""
        from ..regions import lumped_region

        hit, weights = lumped_region(_as_tris(xy), region)
        f = np.zeros((hit.size, 9))
        f[:, 0::3] = weights
        return hit, f

    def slope_matrix(self, xy, lam) -> np.ndarray:
        """(nt, npts, 2, 9): the slope field β = (βx, βy) ≈ ∇w at barycentric points (as
        :meth:`curvature_matrix` takes them): the 6-node quadratic interpolation of the nodal slopes."""
        xy = _as_tris(xy)
        lam = np.atleast_2d(np.asarray(lam, dtype=float))
        N6 = np.concatenate([lam * (2 * lam - 1), 4 * lam[..., [0, 1, 2]] * lam[..., [1, 2, 0]]], axis=-1)
        T = self.slope_transform(xy).reshape(-1, 2, 6, 9)
        return np.einsum("pn,tdnk->tpdk" if lam.ndim == 2 else "tpn,tdnk->tpdk", N6, T)

    def moments(self, xy, u_e, lam, D: float, nu: float) -> np.ndarray:
        """(nt, npts, 3) moments (Mx, My, Mxy) = −D_b κ at barycentric points, from element dofs u_e (nt, 9)."""
        kappa = np.einsum("tpik,tk->tpi", self.curvature_matrix(xy, lam), np.atleast_2d(u_e))
        return -np.einsum("ij,tpj->tpi", bending_matrix(D, nu), kappa)
