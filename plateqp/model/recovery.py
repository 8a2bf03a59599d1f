r"""Fields recovered from the curvatures, and their averages at the nodes.

Moments follow the convention of :mod:`plateqp.model.elements.base`: :math:`M = -D_b\,\kappa` with
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
    if quantity in ("s1", "s2"):  # principal's σ1 or σ2 (its angle not computed)
        sx, sy, txy = stresses(plate, kxx, kyy, kxy)
        c, r = 0.5 * (sx + sy), np.hypot(0.5 * (sx - sy), txy)
        return c + r if quantity == "s1" else c - r
    check_quantity(quantity)
    raise ValueError(f"{quantity!r} is not recovered from the curvatures")


class NodalOperator:
    """Nodal averages of the fields of one mesh (the structured grid or a triangle mesh).

    Every cell gives its own value at each of its corners, and a node's value is the plain
    mean over the cells that hold it. Values come as (n,) arrays, one per node of the plate in
    the order of ``mesh.nodes``. The operator from the full dofs to the cells' corner
    curvatures (w,xx, w,yy, w,xy) is built on first use and kept, so that many solutions on
    one mesh (a sweep) cost a product each: on a mesh of equal cells (the structured grid) one
    cell's corner matrix applied to every cell's dofs, else a sparse operator. Valid for every model that shares the mesh,
    element and kept cells of ``model`` (an adapted model of a sweep).

    A cell's corner values are its element's answer, one call on every mesh:
    ``element.corner_curvatures(xy)`` (a quad (ACM, BFS) evaluated just inside, 1e-9 of a
    cell, each corner; a triangle (DKT) its linear curvature field at its vertices) and
    ``element.corner_w(xy)`` (None where a corner's w is its node's own dof, as on DKT).

    Parameters
    ----------
    model : :class:`~plateqp.model.assembly.Model` (on any mesh)
    """

    def __init__(self, model) -> None:
        mesh = model.grid
        self.model = model
        self.n_nodes = len(mesh.plate_node_ids)
        self._ids = mesh.plate_node_ids
        self._nd = model.element.ndof_node
        cells = mesh.cells
        self._xy = mesh.nodes[cells]
        self._w = None
        self._curv = None
        self._w_at_nodes = model.element.corner_w(self._xy[:1]) is None  # a corner's w is its node's dof
        corner_nodes = cells.ravel()  # corner v of cell k at k · corners + v, as its columns
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

    def _op(self, values: np.ndarray) -> sp.csr_matrix:
        """The cells' corner values ``values`` (ncell, corners, k, ndof) as one operator from the
        full dofs: row i · (ncell · corners) + c · corners + v for value i of corner v of cell c."""
        nc, nv, k, _ = values.shape
        rows = (np.arange(k)[None, None, :, None] * (nc * nv) + (np.arange(nc)[:, None, None, None] * nv
                + np.arange(nv)[None, :, None, None]))
        cols = self.model.cell_dofs[:, None, None, :]
        rows, cols = np.broadcast_arrays(rows, cols)
        return sp.csr_matrix((values.ravel(), (rows.ravel(), cols.ravel())), shape=(k * nc * nv, self.model.n_full))

    def _averaged(self, values: np.ndarray) -> np.ndarray:
        out = self._average @ values
        out[~self._on] = np.nan
        return out

    def __call__(self, u: np.ndarray, plate, quantity: str = "w") -> np.ndarray:
        """(n,) nodal values of ``quantity`` (one of :data:`QUANTITIES`) of the full dof vector
        ``u`` of a plate (``plate``: its :class:`~plateqp.model.scene.Plate`), in ``mesh.nodes`` order."""
        check_quantity(quantity)
        if quantity == "w":
            if self._w_at_nodes:
                return nodal_w(self.model, u)
            if self._w is None:
                self._w = self._op(self.model.element.corner_w(self._xy)[:, :, None])
            return self._averaged(self._w @ u)
        if self._curv is None:
            self._curv = self._curvatures_op(self.model.element.corner_curvatures(self._xy))
        if isinstance(self._curv, np.ndarray):  # one cell's (corners · 3, ndof): every cell's
            nc, nv = self._xy.shape[:2]
            kxx, kyy, kxy = (np.asarray(u, dtype=float)[self.model.cell_dofs] @ self._curv.T).reshape(nc * nv, 3).T
        else:
            kxx, kyy, kxy = (self._curv @ u).reshape(3, -1)
        return self._averaged(from_curvatures(plate, quantity, kxx, kyy, kxy))

    def _curvatures_op(self, values: np.ndarray):
        """The corner curvatures' operator: where every cell's corner values are the first
        cell's (a mesh of equal cells: the structured grid), that cell's (corners · 3, ndof)
        matrix, applied to each cell's dofs; else the sparse operator of :meth:`_op`."""
        if values.shape[0] and np.array_equal(values, np.broadcast_to(values[:1], values.shape)):
            return np.ascontiguousarray(values[0].reshape(-1, values.shape[-1]))
        return self._op(values)


def nodal_operator(model) -> NodalOperator:
    """The nodal-average operator of ``model`` (any mesh): :class:`NodalOperator`."""
    return NodalOperator(model)


def nodal_w(model, u: np.ndarray) -> np.ndarray:
    """(n,) w at the plate's nodes (``mesh.nodes`` order): each node's own dof."""
    ids = model.grid.plate_node_ids
    return np.asarray(u, dtype=float)[ids * model.element.ndof_node].copy()


__all__ = ["CURVATURE_QUANTITIES", "NodalOperator", "QUANTITIES", "check_quantity",
           "from_curvatures", "moments", "nodal_operator", "nodal_w", "principal", "stresses"]
