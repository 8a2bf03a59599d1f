r"""Soils whose surface has unknowns of its own: Pasternak's two-parameter foundation and the
elastic half-space, tensionless, on every mesh.

Winkler's bed (``model = "winkler"``) is a spring at each bed node: its flexibility 1/(k A)
sits on the contact row (:class:`plateqp.model.assembly.ContactOperator`'s ``rho``). Where the
soil's surface couples its points, a spring per point no longer says what the soil does: where
the plate lifts off, the surface beside the contact still moves (it is dragged by the shear
layer, or settles under the pressure nearby). So the soil's surface settlement v at each bed
node becomes an unknown of the model, beside the plate's dofs:

.. math::

    \min_{u, v}\ \tfrac12 u^T K u - f^T u + \tfrac12 v^T K_s v
    \quad\text{s.t.}\quad w_c(u) - v \le g_0 ,

with the soil's stiffness K_s symmetric positive definite. The multiplier of each row is the
force R ≥ 0 the soil and the plate press each other with (stationarity in v: K_s v = R): where
the plate lifts off R = 0 and v is the soil's own equilibrium under the pressures elsewhere, so
the soil never pulls the plate and never sticks to it. It is still a convex QP with linear
inequalities, so every formulation and every backend holds it: the soil's unknowns are dofs of
K (appended after the plate's free dofs; ``Model.n_soil`` of them) and the bed's rows of B gain
a −1 in their soil column. The KKT check covers them as it covers the plate's dofs.

**Pasternak** (``model = "pasternak"``): springs k joined by a shear layer of modulus c2
(Pasternak 1954; Kerr 1964): the soil's energy ½∫(k v² + c2 |∇v|²) dA over the bed. The spring
term keeps Winkler's nodal areas (so that c2 = 0 gives Winkler's answer exactly); the shear
term is the Laplacian's stiffness, linear on a triangle and bilinear on a quadrilateral, over
the bed's cells (the cells whose centre lies in the region and whose corners are all bed nodes).
The layer ends at the region's edge, free (no shear force across it: the soil beyond the region
is not modelled), and at a node whose deflection a two-sided support prescribes (that node's
bed force goes to the support, as for Winkler's bed).

**Elastic half-space** (``model = "halfspace"``): Boussinesq's solution: a pressure p over a
cell settles the surface at x by (1 − ν²)/(πE) ∫ p dA/|x − ξ|. Each bed node carries a uniform
pressure over its part of the bed's cells (a quarter of each bilinear cell at that corner, a
median-dual third of each triangle: the polygons of :func:`pressure_cells`), integrated exactly
(:mod:`plateqp.model.halfspace`); the settlements are taken at the nodes (collocation,
Zhemochkin's method). The flexibility in forces, H_F (settlement at node i per unit force on
node j's cell), is dense; K_s = H_F⁻¹ (symmetrised: on unequal cells collocation is not
exactly reciprocal). The dense block limits this route to a few thousand bed nodes
(:data:`HALFSPACE_DENSE_MAX`).

**The half-space held matrix-free** (a mesh that offers the operator: the rectangle grid, whose
pressure cells are a regular sub-grid, so H_F is a convolution applied by FFT). Above
:data:`HALFSPACE_OPERATOR_FROM` bed nodes the model keeps no soil unknowns: its bed's rows read
the plate's w alone, and ``Model.soil_flexibility`` holds H_F as an operator
(:func:`attach_operator`). Eliminating v = H_F R, the soil is a compliance on the contact rows,
as an elastic support's 1/c is, but a full one: gap = g0 + H_F R − w. The contact problem is
then solved in the contact forces (:mod:`plateqp.contact.pressures`), where the soil never
needs a matrix.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import ProblemError

#: the most bed nodes a half-space's dense stiffness is built for (m² doubles: 4000 → 128 MB,
#: with its flexibility and inverse alive at once about three times that)
HALFSPACE_DENSE_MAX = 4000
#: more bed nodes than this on a mesh that offers the half-space's operator (the grid) are held
#: matrix-free (:func:`attach_operator`); up to it the soil's unknowns join K, and every backend
#: and formulation takes the problem
HALFSPACE_OPERATOR_FROM = 1000


def couples(foundation) -> bool:
    """True if the soil's surface has unknowns of its own (not Winkler's independent springs)."""
    return foundation is not None and foundation.model != "winkler"


def region_cells(mesh, region) -> np.ndarray:
    """Indices into ``mesh.cells`` of the bed's cells: every cell of the plate (``region`` None),
    or those whose centre (the mean of its corners) lies in the region (its boundary included)."""
    cells = mesh.cells
    if region is None:
        return np.arange(len(cells))
    from .geometry import parse_region

    def fail(where, what):  # the scene was validated: a region that parses then does here
        raise ProblemError(f"{where}: {what}")

    shape = parse_region(region, "foundation.region", fail)
    c = mesh.nodes[cells].mean(axis=1)
    return np.flatnonzero(shape.contains(c[:, 0], c[:, 1]))


def laplacian_cells(xy: np.ndarray) -> np.ndarray:
    """(nc, k, k) the stiffness ∫∇N_i·∇N_j dA of each cell with corners ``xy`` (nc, k, 2):
    k = 3 linear triangles (exact), k = 4 bilinear quadrilaterals, corners counter-clockwise
    (2 × 2 Gauss points: exact on parallelograms)."""
    k = xy.shape[1]
    if k == 3:
        x, y = xy[..., 0], xy[..., 1]
        bx = np.stack([y[:, 1] - y[:, 2], y[:, 2] - y[:, 0], y[:, 0] - y[:, 1]], axis=1)
        by = np.stack([x[:, 2] - x[:, 1], x[:, 0] - x[:, 2], x[:, 1] - x[:, 0]], axis=1)
        area2 = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0])
        return (bx[:, :, None] * bx[:, None, :] + by[:, :, None] * by[:, None, :]) / (2.0 * np.abs(area2))[:, None, None]
    if k != 4:
        raise ProblemError(f"a shear layer on cells of {k} corners is not implemented (triangles and quadrilaterals are)")
    xi = np.array([-1.0, 1.0, 1.0, -1.0])
    eta = np.array([-1.0, -1.0, 1.0, 1.0])
    g = 1.0 / np.sqrt(3.0)
    out = np.zeros((xy.shape[0], 4, 4))
    for s in (-g, g):
        for t in (-g, g):
            dxi = 0.25 * xi * (1.0 + eta * t)  # ∂N/∂ξ, ∂N/∂η at (s, t)
            deta = 0.25 * eta * (1.0 + xi * s)
            J = np.stack([dxi @ xy, deta @ xy], axis=1)  # (nc, 2, 2): rows ∂x/∂ξ, ∂x/∂η
            det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
            inv = np.stack([np.stack([J[:, 1, 1], -J[:, 0, 1]], -1), np.stack([-J[:, 1, 0], J[:, 0, 0]], -1)], 1) / det[:, None, None]
            grad = np.einsum("cij,jn->cin", inv, np.stack([dxi, deta]))  # (nc, 2, 4)
            out += np.einsum("cin,cim->cnm", grad, grad) * np.abs(det)[:, None, None]
    return out


def _bed_cells(model, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(cells, corners): the bed's cells whose corners are all bed nodes, and their corners as
    positions in ``nodes`` (the soil's unknowns)."""
    mesh = model.grid
    pos = np.full(mesh.n_nodes, -1)
    pos[nodes] = np.arange(nodes.size)
    cells = region_cells(mesh, model.scene.foundation.region)
    corners = pos[mesh.plate_node_ids[mesh.cells[cells]]]
    keep = (corners >= 0).all(axis=1)
    return cells[keep], corners[keep]


def shear_laplacian(model, nodes: np.ndarray) -> sp.csr_matrix:
    """L, the Laplacian's stiffness ∫∇v·∇v dA over the bed's cells (the module's text) on the
    soil's points ``nodes``, exactly symmetric."""
    mesh = model.grid
    cells, corners = _bed_cells(model, nodes)
    Ke = laplacian_cells(mesh.nodes[mesh.cells[cells]])
    k = corners.shape[1]
    rows = np.repeat(corners, k, axis=1).ravel()
    cols = np.tile(corners, (1, k)).ravel()
    m = nodes.size
    L = sp.csr_matrix((Ke.ravel(), (rows, cols)), shape=(m, m))
    return ((L + L.T) * 0.5).tocsr()


def pasternak_stiffness(model, nodes: np.ndarray, area: np.ndarray) -> sp.csr_matrix:
    """K_s = k diag(area) + c2 L over the soil's unknowns at ``nodes`` (mesh node numbers, the
    bed's contact order) with tributary ``area``; L the shear layer's Laplacian (the module's
    text). Exactly symmetric."""
    fnd = model.scene.foundation
    Ks = fnd.shear * shear_laplacian(model, nodes) + sp.diags(fnd.k * area)
    Ks = Ks.tocsr()
    Ks.sum_duplicates()
    Ks.sort_indices()
    return Ks


def soil_stiffness(model, nodes: np.ndarray, area: np.ndarray) -> sp.csr_matrix:
    """The soil's stiffness K_s on its unknowns at the bed's ``nodes`` (the scene's model)."""
    fnd = model.scene.foundation
    if fnd.model == "pasternak":
        return pasternak_stiffness(model, nodes, area)
    return halfspace_stiffness(model, nodes)


def pressure_cells(mesh, region) -> tuple[np.ndarray, np.ndarray]:
    """(owner, polygons): the bed's cells cut into one polygon per corner, each the part of its
    cell nearest that corner (the corner, the midpoints of its two edges and the cell's centre:
    a quarter of a parallelogram, a median-dual third of a triangle), ``owner`` the corner's mesh
    node (the numbering of the dofs), ``polygons`` (n, 4, 2) counter-clockwise."""
    cells = region_cells(mesh, region)
    xy = mesh.nodes[mesh.cells[cells]]  # (nc, k, 2)
    k = xy.shape[1]
    centre = xy.mean(axis=1)
    nxt, prv = np.roll(xy, -1, axis=1), np.roll(xy, 1, axis=1)
    polys = np.stack([xy, 0.5 * (xy + nxt), np.repeat(centre[:, None], k, axis=1), 0.5 * (xy + prv)], axis=2)
    owner = mesh.plate_node_ids[mesh.cells[cells]]
    return owner.ravel(), polys.reshape(-1, 4, 2)


def polygon_areas(polys: np.ndarray) -> np.ndarray:
    """(n,) the areas of polygons (n, k, 2) counter-clockwise (the shoelace formula)."""
    x, y = polys[..., 0], polys[..., 1]
    return 0.5 * (x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y).sum(axis=1)


def halfspace_areas(mesh, region) -> np.ndarray:
    """(n_nodes,) each node's share of the bed's cells (:func:`pressure_cells`): the areas over
    which a half-space bed's nodes press the soil."""
    owner, polys = pressure_cells(mesh, region)
    return np.bincount(owner, weights=polygon_areas(polys), minlength=mesh.n_nodes)


def halfspace_flexibility(model, nodes: np.ndarray) -> np.ndarray:
    """(m, m) H_F: the soil's settlement at bed node i per unit force spread uniformly over node
    j's pressure cells (Boussinesq's solution integrated exactly over each polygon,
    :func:`plateqp.model.halfspace.flexibility`), symmetrised."""
    from .halfspace import flexibility

    fnd = model.scene.foundation
    mesh = model.grid
    m = nodes.size
    if m > HALFSPACE_DENSE_MAX:
        raise ProblemError(f"foundation: a half-space under {m} bed nodes needs a dense {m} x {m} flexibility "
                           f"({3 * 8 * m * m / 1e9:.1f} GB with its inverse); this route takes at most "
                           f"{HALFSPACE_DENSE_MAX} nodes: use a coarser mesh or a smaller region")
    pos = np.full(mesh.n_nodes, -1)
    pos[nodes] = np.arange(m)
    owner, polys = pressure_cells(mesh, fnd.region)
    col = pos[owner]
    keep = col >= 0  # a node whose deflection is prescribed presses no soil here
    H = flexibility(mesh.node_xy()[nodes], polys[keep], fnd.E, fnd.nu, per="force", owner=col[keep],
                    max_bytes=8 * HALFSPACE_DENSE_MAX**2)
    return 0.5 * (H + H.T)


def halfspace_stiffness(model, nodes: np.ndarray) -> sp.csr_matrix:
    """K_s = H_F⁻¹ (the module's text; :func:`halfspace_flexibility`), dense, stored as a CSR
    matrix, exactly symmetric."""
    import scipy.linalg as sla

    H = halfspace_flexibility(model, nodes)
    c, low = sla.cho_factor(H)
    Ks = sla.cho_solve((c, low), np.eye(H.shape[0]))
    return sp.csr_matrix(0.5 * (Ks + Ks.T))


def attach(model, bed_rows: np.ndarray, nodes: np.ndarray, area: np.ndarray) -> None:
    """Give ``model`` the soil's unknowns: K becomes blockdiag(K, K_s), f gains zeros, the bed's
    contact rows (``bed_rows``, at ``nodes``) gain −1 in their soil column; ``model.n_soil`` set."""
    Ks = soil_stiffness(model, nodes, area)
    m = nodes.size
    K = sp.block_diag([model.K, Ks], format="csr")
    K.sort_indices()
    model.K = K
    model.f = np.concatenate([model.f, np.zeros(m)])
    c = model.contacts
    E = sp.csr_matrix((-np.ones(m), (bed_rows, np.arange(m))), shape=(c.m, m))
    c.B = sp.hstack([c.B, E], format="csr")
    model.n_soil = m
    model.soil_nodes = nodes


def halfspace_operator(model, nodes: np.ndarray, wanted: bool | None = None):
    """H_F of the bed ``nodes`` as an operator (the mesh's own matrix-free route:
    ``mesh.halfspace_flexibility_operator``), or None where the mesh offers none, where not
    ``wanted``, or (``wanted`` None) where the bed is small enough for the soil's unknowns
    (:data:`HALFSPACE_OPERATOR_FROM`)."""
    fnd = model.scene.foundation
    if fnd.model != "halfspace" or wanted is False or (wanted is None and nodes.size <= HALFSPACE_OPERATOR_FROM):
        return None
    return model.grid.halfspace_flexibility_operator(fnd.region, fnd.E, fnd.nu, nodes)


def attach_operator(model, bed_rows: np.ndarray, nodes: np.ndarray, H) -> None:
    """Hold the half-space matrix-free: ``model.soil_flexibility`` = H_F (forces on the bed's
    rows ``bed_rows`` to the soil's settlements there), no soil unknowns in K, the bed's rows
    reading the plate's w (their spring stays 0: the soil is the operator's)."""
    model.soil_flexibility = H
    model.soil_rows = bed_rows
    model.soil_nodes = nodes
