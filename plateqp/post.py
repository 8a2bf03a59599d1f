r"""Fields recovered from the curvatures, and their averages at the nodes.

Moments follow the convention of :mod:`plateqp.elements.base`: :math:`M = -D_b\,\kappa` with
κ = (w,xx, w,yy, 2 w,xy), so Mx > 0 sags. Surface stresses are those of the bottom face
(z = +h/2, the side of positive w): σ = 6 M / h². Principal stresses σ1 ≥ σ2 of the bottom
face, with the angle θ1 of σ1 from the x axis:

.. math::

    \sigma_{1,2} = \tfrac12(\sigma_x + \sigma_y) \pm
    \sqrt{\tfrac14(\sigma_x - \sigma_y)^2 + \tau_{xy}^2}.

Moments are discontinuous between cells (ACM is non-conforming; DKT's curvatures are linear
in each triangle). A nodal value (:class:`NodalOperator`) is the average, over the cells around
a node, of each cell's own value at its corner there. On every mesh a nodal field is a (n,)
array, one value per node of the plate in the order of ``mesh.nodes`` (on the structured grid
the nodes of the kept cells, in grid order; ``Grid.to_grid`` gives its (ny + 1, nx + 1) view,
NaN off the plate). The operator is built once per mesh, so that many solutions on one mesh (a
sweep) cost a sparse product each.
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


#: The corners of a quad cell in the order of Grid.cell_nodes, in cell coordinates.
_CORNERS = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))


class NodalOperator:
    """Nodal averages of the fields of one mesh (the structured grid or a triangle mesh).

    Every cell gives its own value at each of its corners, and a node's value is the plain
    mean over the cells that hold it. Values come as (n,) arrays, one per node of the plate in
    the order of ``mesh.nodes``. The operator from the full dofs to the cells' corner
    curvatures (w,xx, w,yy, w,xy) is built on first use and kept, so that many solutions on
    one mesh (a sweep) cost a sparse product each. Valid for every model that shares the mesh,
    element and kept cells of ``model`` (an adapted model of a sweep).

    How a cell gives its corner values depends only on its element: a quad (ACM, BFS) is
    evaluated just inside (1e-9 of a cell) each corner through the model's interpolation, w
    included; a triangle (DKT) gives its linear curvature field at its vertices
    (:meth:`~plateqp.elements.dkt.DKT.curvature_matrix`), and w is the node's own dof.

    Parameters
    ----------
    model : :class:`~plateqp.assembly.Model` (on any mesh)
    """

    def __init__(self, model) -> None:
        mesh = model.grid
        self.model = model
        self.n_nodes = len(mesh.plate_node_ids)
        self._ids = mesh.plate_node_ids
        self._nd = model.element.ndof_node
        cells = mesh.cells
        self._w = None
        self._curv = None
        self._points = None
        if mesh.cell_type == "triangle":
            self._curv = _triangle_vertex_curvatures(model)
            corner_nodes = cells.ravel()  # vertex v of triangle k at 3 k + v, as its rows
        else:
            x0 = (model.cells % mesh.nx) * mesh.hx
            y0 = (model.cells // mesh.nx) * mesh.hy
            self._points = [(x0 + (1e-9 + (1 - 2e-9) * cx) * mesh.hx, y0 + (1e-9 + (1 - 2e-9) * cy) * mesh.hy)
                            for cx, cy in _CORNERS]  # just inside each corner of each cell
            corner_nodes = cells.T.ravel()  # corner 0 of every cell, then corner 1, ...
        # averaging: (n, n_corners) with 1/count at (node, each of its corners)
        cnt = np.bincount(corner_nodes, minlength=self.n_nodes).astype(float)
        self._on = cnt > 0
        A = sp.csr_matrix((np.ones(corner_nodes.size), (corner_nodes, np.arange(corner_nodes.size))),
                          shape=(self.n_nodes, corner_nodes.size))
        self._average = sp.diags(np.where(self._on, 1.0 / np.where(self._on, cnt, 1.0), 0.0)) @ A

    @property
    def shape(self) -> tuple[int]:
        """(n,): one value per node of the plate."""
        return (self.n_nodes,)

    def _op(self, orders) -> sp.csr_matrix:
        """The quad corner points' interpolation (w and its derivatives ``orders``), stacked as
        [order 0: corners 0..3; order 1: corners 0..3; ...], from the full dofs."""
        m = self.model
        return sp.vstack([m.interpolation(x, y, dx, dy) for dx, dy in orders for x, y in self._points],
                         format="csr")

    def _averaged(self, values: np.ndarray) -> np.ndarray:
        out = self._average @ values
        out[~self._on] = np.nan
        return out

    def __call__(self, u: np.ndarray, plate, quantity: str = "w") -> np.ndarray:
        """(n,) nodal values of ``quantity`` (one of :data:`QUANTITIES`) of the full dof vector
        ``u`` of a plate (``plate``: its :class:`~plateqp.scene.Plate`), in ``mesh.nodes`` order."""
        check_quantity(quantity)
        if quantity == "w":
            if self._points is None:  # a triangle's w at its vertex is the node's own dof
                return nodal_w(self.model, u)
            if self._w is None:
                self._w = self._op(((0, 0),))
            return self._averaged(self._w @ u)
        if self._curv is None:
            self._curv = self._op(((2, 0), (0, 2), (1, 1)))
        kxx, kyy, kxy = (self._curv @ u).reshape(3, -1)
        return self._averaged(from_curvatures(plate, quantity, kxx, kyy, kxy))


def _triangle_vertex_curvatures(model) -> sp.csr_matrix:
    """(9 nt, n_full): the curvatures (w,xx, w,yy, w,xy) of each triangle at each of its
    vertices, row c · (3 nt) + 3 k + v for curvature c of vertex v of triangle k."""
    t = model.grid.cells
    nt = len(t)
    B = model.element.curvature_matrix(model.grid.nodes[t], np.eye(3)).copy()  # (nt, 3, 3, 9)
    B[..., 2, :] *= 0.5  # κ3 = 2 w,xy -> w,xy
    rows = (np.arange(3)[None, None, :, None] * 3 * nt + 3 * np.arange(nt)[:, None, None, None]
            + np.arange(3)[None, :, None, None])
    rows = np.broadcast_to(rows, B.shape)
    cols = np.broadcast_to(model.cell_dofs[:, None, None, :], B.shape)
    return sp.csr_matrix((B.ravel(), (rows.ravel(), cols.ravel())), shape=(9 * nt, model.n_full))


def nodal_operator(model) -> NodalOperator:
    """The nodal-average operator of ``model`` (any mesh): :class:`NodalOperator`."""
    return NodalOperator(model)


def nodal_w(model, u: np.ndarray) -> np.ndarray:
    """(n,) w at the plate's nodes (``mesh.nodes`` order): each node's own dof."""
    ids = model.grid.plate_node_ids
    return np.asarray(u, dtype=float)[ids * model.element.ndof_node].copy()


__all__ = ["CURVATURE_QUANTITIES", "NodalOperator", "QUANTITIES", "check_quantity",
           "from_curvatures", "moments", "nodal_operator", "nodal_w", "principal", "stresses"]
