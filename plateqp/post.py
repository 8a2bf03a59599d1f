r"""Fields recovered from the curvatures, and their averages at the nodes.

Moments follow the convention of :mod:`plateqp.elements.base`: :math:`M = -D_b\,\kappa` with
κ = (w,xx, w,yy, 2 w,xy), so Mx > 0 sags. Surface stresses are those of the bottom face
(z = +h/2, the side of positive w): σ = 6 M / h². Principal stresses σ1 ≥ σ2 of the bottom
face, with the angle θ1 of σ1 from the x axis:

.. math::

    \sigma_{1,2} = \tfrac12(\sigma_x + \sigma_y) \pm
    \sqrt{\tfrac14(\sigma_x - \sigma_y)^2 + \tau_{xy}^2}.

For the ACM element moments are discontinuous between cells (non-conforming). A nodal value
(:class:`NodalOperator`) is the average, over the kept cells around a node, of each cell's own
value just inside its corner at that node; NaN at nodes off the plate. The operator holds the
interpolation at those points, built once per mesh, so that many solutions on one mesh (a
sweep) cost a sparse product each.

On a triangle mesh (:class:`~plateqp.triassembly.TriModel`, the DKT element) :class:`TriNodalOperator`
does the same: each triangle's own curvatures at each of its three vertices (DKT's linear
curvature field, :meth:`~plateqp.elements.dkt.DKT.curvature_matrix`), averaged over the triangles
around each node; w is the node's own dof. Values come as (n_nodes,) arrays in the mesh's node
order, every node on the plate.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .elements import bending_matrix

#: The quantities :func:`from_curvatures` and :class:`NodalOperator` know (besides "w").
CURVATURE_QUANTITIES = ("Mx", "My", "Mxy", "sx", "sy", "txy", "s1", "s2")
#: Every named field: the deflection and those recovered from the curvatures.
QUANTITIES = ("w",) + CURVATURE_QUANTITIES


def check_quantity(quantity: str) -> None:
    """A ValueError naming the known quantities if ``quantity`` is not one of them."""
    if quantity not in QUANTITIES:
        raise ValueError(f"unknown quantity {quantity!r}; choose one of {sorted(QUANTITIES)}")


def moments(plate, kxx, kyy, kxy) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(Mx, My, Mxy) per unit length from the curvatures (w,xx, w,yy, w,xy): M = −D_b κ."""
    Db = bending_matrix(plate.D, plate.nu)
    kxx, kyy, kxy = np.asarray(kxx), np.asarray(kyy), np.asarray(kxy)
    Mx = -(Db[0, 0] * kxx + Db[0, 1] * kyy)
    My = -(Db[1, 0] * kxx + Db[1, 1] * kyy)
    Mxy = -Db[2, 2] * 2.0 * kxy
    return Mx, My, Mxy


def stresses(plate, kxx, kyy, kxy) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(σx, σy, τxy) on the bottom face from the curvatures: 6 M / h²."""
    c = 6.0 / plate.h**2
    return tuple(c * m for m in moments(plate, kxx, kyy, kxy))


def principal(sx, sy, txy) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(σ1, σ2, θ1): principal stresses σ1 ≥ σ2 and the angle of σ1 from x (radians)."""
    sx, sy, txy = np.asarray(sx), np.asarray(sy), np.asarray(txy)
    c = 0.5 * (sx + sy)
    r = np.hypot(0.5 * (sx - sy), txy)
    return c + r, c - r, 0.5 * np.arctan2(2.0 * txy, sx - sy)


def from_curvatures(plate, quantity: str, kxx, kyy, kxy) -> np.ndarray:
    """One of :data:`CURVATURE_QUANTITIES` from the curvatures (w,xx, w,yy, w,xy)."""
    if quantity in ("Mx", "My", "Mxy"):
        return moments(plate, kxx, kyy, kxy)[("Mx", "My", "Mxy").index(quantity)]
    if quantity in ("sx", "sy", "txy"):
        return stresses(plate, kxx, kyy, kxy)[("sx", "sy", "txy").index(quantity)]
    if quantity in ("s1", "s2"):
        return principal(*stresses(plate, kxx, kyy, kxy))[("s1", "s2").index(quantity)]
    check_quantity(quantity)
    raise ValueError(f"{quantity!r} is not recovered from the curvatures")


#: The cell corners in the order of Grid.cell_nodes, in cell coordinates.
_CORNERS = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))


class NodalOperator:
    """Nodal averages of the fields of one mesh.

    Each kept cell is evaluated just inside (1e-9 of a cell) each of its four corners, so
    that it contributes its own value, and the values at a node are averaged over the kept
    cells around it. The interpolation operators at those points are built on first use
    (for w, and stacked for w,xx, w,yy, w,xy) and kept. Valid for every model that shares
    the grid, element and kept cells of ``model`` (an adapted model of a sweep).

    Parameters
    ----------
    model : :class:`~plateqp.assembly.Model`
    """

    def __init__(self, model) -> None:
        g, cells = model.grid, model.cells
        self.model = model
        self.shape = (g.ny + 1, g.nx + 1)
        self.nc = cells.size
        cn = g.cell_nodes()[cells]
        x0 = (cells % g.nx) * g.hx
        y0 = (cells // g.nx) * g.hy
        self._points = []
        for cx, cy in _CORNERS:
            xi = 1e-9 + (1 - 2e-9) * cx  # just inside the cell
            eta = 1e-9 + (1 - 2e-9) * cy
            self._points.append((x0 + xi * g.hx, y0 + eta * g.hy))
        # averaging: (n_nodes, 4 nc) with 1/count at (node, its corner point), corners stacked
        nodes = cn.T.ravel()  # corner 0 of every cell, then corner 1, ...
        cnt = np.bincount(nodes, minlength=g.n_nodes).astype(float)
        self._on = cnt > 0
        A = sp.csr_matrix((np.ones(nodes.size), (nodes, np.arange(nodes.size))), shape=(g.n_nodes, nodes.size))
        self._average = sp.diags(np.where(self._on, 1.0 / np.where(self._on, cnt, 1.0), 0.0)) @ A
        self._w = None
        self._curv = None

    def _op(self, orders) -> sp.csr_matrix:
        """The corner points' interpolation (w and its derivatives ``orders``), stacked as
        [order 0: corners 0..3; order 1: corners 0..3; ...], from the full dofs."""
        m = self.model
        return sp.vstack([m.interpolation(x, y, dx, dy) for dx, dy in orders for x, y in self._points],
                         format="csr")

    def _averaged(self, values: np.ndarray) -> np.ndarray:
        out = self._average @ values
        out[~self._on] = np.nan
        return out.reshape(self.shape)

    def __call__(self, u: np.ndarray, plate, quantity: str = "w") -> np.ndarray:
        """(ny+1, nx+1) nodal values of ``quantity`` (one of :data:`QUANTITIES`) of the full
        dof vector ``u`` of a plate (``plate``: its :class:`~plateqp.scene.Plate`)."""
        check_quantity(quantity)
        if quantity == "w":
            if self._w is None:
                self._w = self._op(((0, 0),))
            return self._averaged(self._w @ u)
        if self._curv is None:
            self._curv = self._op(((2, 0), (0, 2), (1, 1)))
        kxx, kyy, kxy = (self._curv @ u).reshape(3, -1)
        return self._averaged(from_curvatures(plate, quantity, kxx, kyy, kxy))


class TriNodalOperator:
    """Nodal averages of the fields of one triangle mesh (the triangle analogue of :class:`NodalOperator`).

    Each triangle's curvatures (w,xx, w,yy, w,xy) at its three vertices are taken from the
    element (its own value there, not a neighbour's), the fields recovered from them, and each
    node's value is the plain mean over the triangles that hold it. The operator from the full
    dofs to those 3 × n_triangles vertex curvatures is built once. Valid for every model on the
    same mesh.

    Parameters
    ----------
    model : :class:`~plateqp.triassembly.TriModel`
    """

    def __init__(self, model) -> None:
        mesh = model.grid
        self.model = model
        t = mesh.triangles
        nt, n = len(t), mesh.n_nodes
        self.n_nodes = n
        xy = mesh.nodes[t]
        B = model.element.curvature_matrix(xy, np.eye(3))  # (nt, 3 vertices, 3 curvatures, 9)
        B = B.copy()
        B[..., 2, :] *= 0.5  # κ3 = 2 w,xy -> w,xy
        # rows: curvature c of vertex v of triangle k at c * (3 nt) + 3 k + v
        rows = (np.arange(3)[None, None, :, None] * 3 * nt + 3 * np.arange(nt)[:, None, None, None]
                + np.arange(3)[None, :, None, None])
        rows = np.broadcast_to(rows, B.shape)
        cols = np.broadcast_to(model.cell_dofs[:, None, None, :], B.shape)
        self._curv = sp.csr_matrix((B.ravel(), (rows.ravel(), cols.ravel())), shape=(9 * nt, model.n_full))
        nodes = t.ravel()  # vertex v of triangle k at 3 k + v, as the rows above
        cnt = np.bincount(nodes, minlength=n).astype(float)
        self._on = cnt > 0
        A = sp.csr_matrix((np.ones(nodes.size), (nodes, np.arange(nodes.size))), shape=(n, nodes.size))
        self._average = sp.diags(np.where(self._on, 1.0 / np.where(self._on, cnt, 1.0), 0.0)) @ A
        self._nd = model.element.ndof_node

    def __call__(self, u: np.ndarray, plate, quantity: str = "w") -> np.ndarray:
        """(n_nodes,) nodal values of ``quantity`` (one of :data:`QUANTITIES`) of the full dof
        vector ``u`` of a plate (``plate``: its :class:`~plateqp.scene.Plate`)."""
        check_quantity(quantity)
        if quantity == "w":
            return np.asarray(u[0::self._nd][: self.n_nodes], dtype=float).copy()
        kxx, kyy, kxy = (self._curv @ u).reshape(3, -1)
        out = self._average @ from_curvatures(plate, quantity, kxx, kyy, kxy)
        out[~self._on] = np.nan
        return out


def nodal_operator(model):
    """The nodal-average operator of ``model``: :class:`TriNodalOperator` on a triangle mesh,
    :class:`NodalOperator` on the structured grid."""
    from .trimesh import TriMesh

    return TriNodalOperator(model) if isinstance(model.grid, TriMesh) else NodalOperator(model)


def nodal_w(model, u: np.ndarray) -> np.ndarray:
    """w at every plate node from the nodal dofs (NaN off the plate), shape (ny+1, nx+1)."""
    g = model.grid
    nd = model.element.ndof_node
    w = u[0::nd][: g.n_nodes].astype(float).copy()
    w[~g.node_mask()] = np.nan
    return w.reshape(g.ny + 1, g.nx + 1)


__all__ = ["CURVATURE_QUANTITIES", "NodalOperator", "QUANTITIES", "TriNodalOperator", "check_quantity",
           "from_curvatures", "moments", "nodal_operator", "nodal_w", "principal", "stresses"]
