r"""The force flexibility of a half-space bed on a grid, applied by FFT without forming the matrix.

A ``[foundation] model = "halfspace"`` bed on a :class:`plateqp.model.grid.Grid` presses the soil
as :func:`plateqp.model.soil.halfspace_flexibility` says: each bed cell is cut into four quarter
rectangles (hx/2 × hy/2), each owned by the cell corner it touches; a bed node's force spreads
uniformly over the quarters it owns (their total area A_j); the settlements are taken at the
nodes. :func:`bed_flexibility` gives that matrix, ½(H + Hᵀ), as a
:class:`scipy.sparse.linalg.LinearOperator`, equal to the dense one to rounding, in O(m) memory
besides the padded FFT arrays (never an m² array).

**The convolution.** Quarter (a, b) of cell (c_i, c_j) (a, b ∈ {0, 1}: its corner along x and y)
is owned by node (c_i + a, c_j + b) and settles node (i, j) under a unit pressure by

.. math::

    k_{ab}(i - c_i, j - c_j) = \frac{1 - \nu^2}{\pi E}
    \iint_{R_{ab}} \frac{dA}{\lvert ((i - c_i) h_x, (j - c_j) h_y) - \xi \rvert},
    \qquad R_{ab} = [\tfrac{a}{2} h_x, \tfrac{a + 1}{2} h_x] \times [\tfrac{b}{2} h_y, \tfrac{b + 1}{2} h_y],

a function of the index offsets only. With u = x / A on the node lattice and P_ab the pressure
field of the quarters at corner (a, b) (u at their owner; 0 outside the bed's cells and for
a node not in ``nodes``: a node whose deflection is prescribed presses no soil),

.. math::

    (H x)_{ij} = \sum_{ab} (k_{ab} * P_{ab})_{ij}, \qquad
    (H^T y)_n = \frac{1}{A_n} \sum_{ab} [\text{quarter } (ab) \text{ at } n \text{ in the bed}]\,
    (k_{ab} \star Y)_{n - (a, b)},

four discrete convolutions summed, and four correlations (⋆) of the nodes' values Y: ten real FFTs
of a grid padded to at least 2 ny × 2 nx per product (the DC-FFT of Liu, Wang & Liu 2000; four
where the bed is every cell of the grid, :class:`_WholeBed`), the
kernels' transforms computed once. The kernels are Boussinesq's integral exact over each quarter
(:func:`plateqp.model.halfspace.polygon_potential`, the dense route's own formula).

**Orders.** Grid order as :class:`~plateqp.model.grid.Grid`: node (i, j) has index j (nx + 1) + i,
cell (i, j) index j nx + i; ``nodes`` are node indices in the order the contact rows use.
"""

from __future__ import annotations

import numpy as np
import scipy.fft

from ..errors import ProblemError
from .halfspace import SymmetricOperator, boussinesq_factor, polygon_potential
from .soil import region_cells

#: The quarters of a cell, (a, b): the corner they touch along x and along y; in reverse order
#: each quarter's mirror (1 − a, 1 − b), whose kernel is k_ab(1 − d) (:func:`quarter_kernels`).
QUARTERS = ((0, 0), (1, 0), (0, 1), (1, 1))
#: Points of one block of the kernels' evaluation: its temporaries stay near 2 MB each.
BLOCK = 2**18
#: Bytes a block of columns of one product may take in padded FFT arrays.
BLOCK_BYTES = 2**27


def quarter_kernels(nx: int, ny: int, hx: float, hy: float, E: float, nu: float) -> np.ndarray:
    """The settlements k_ab of a unit pressure over the quarter (a, b) of a cell at the nodes, by
    index offsets (the module's text).

    Returns
    -------
    ndarray, shape (4, 2 ny, 2 nx)
        ``K[q, ny − 1 + dj, nx − 1 + di]`` = k_ab(di, dj) for quarter q = :data:`QUARTERS` [q],
        di in −(nx − 1) … nx, dj in −(ny − 1) … ny: every offset from a cell to a node of the grid.
    """
    factor = boussinesq_factor(E, nu)
    # g(p, q): the integral over [0, hx/2] × [0, hy/2] at the point (p hx/2, q hy/2), p, q ≥ 1; the
    # mirror about the quarter's middle gives p ≤ 0: g(p) = g(1 − p), and in q likewise
    quarter = [[0.0, 0.0], [hx / 2, 0.0], [hx / 2, hy / 2], [0.0, hy / 2]]
    px = np.arange(1, 2 * nx + 1) * (hx / 2)
    g = np.empty((2 * ny, 2 * nx))
    rows = max(1, BLOCK // (2 * nx))
    for r0 in range(0, 2 * ny, rows):
        qy = np.arange(r0 + 1, min(2 * ny, r0 + rows) + 1)[:, None] * (hy / 2)
        g[r0:r0 + rows] = polygon_potential(px[None, :], qy, quarter)
    g *= factor

    def index(n, a):  # offsets d = −(n − 1) … n to the quarter's point p = 2d − a, folded to p ≥ 1
        p = 2 * (np.arange(2 * n) - (n - 1)) - a
        return np.where(p >= 1, p, 1 - p) - 1

    return np.stack([g[np.ix_(index(ny, b), index(nx, a))] for a, b in QUARTERS])


class BedFlexibility(SymmetricOperator):
    """½(H + Hᵀ), the force flexibility of a half-space bed's nodes on a grid (:func:`bed_flexibility`).

    ``op @ x``: the settlements at the bed's nodes (in ``nodes`` order) under the forces x on them
    (positive down). Symmetric: its own adjoint. ``diagonal()`` gives the matrix's diagonal.

    Attributes
    ----------
    nodes : ndarray of int
        The bed's nodes (mesh node indices), the order of x and of the answer.
    area : ndarray
        (m,) each node's pressed area A_j (its quarters in the bed's cells).
    fft_shape : tuple of int
        The padded grid of the FFTs, at least (2 ny, 2 nx).
    """

    def __init__(self, nx: int, ny: int, hx: float, hy: float, E: float, nu: float,
                 bed: np.ndarray, nodes: np.ndarray) -> None:
        self.nx, self.ny = nx, ny
        self.nodes = nodes
        kernels = quarter_kernels(nx, ny, hx, hy, E, nu)
        self.fft_shape = (scipy.fft.next_fast_len(2 * ny, real=True), scipy.fft.next_fast_len(2 * nx, real=True))
        Ny, Nx = self.fft_shape
        iy, ix = (np.arange(2 * ny) - (ny - 1)) % Ny, (np.arange(2 * nx) - (nx - 1)) % Nx
        self._kernel_hat = np.empty((4, Ny, Nx // 2 + 1), dtype=complex)
        for q in range(4):
            wrapped = np.zeros(self.fft_shape)
            wrapped[np.ix_(iy, ix)] = kernels[q]
            self._kernel_hat[q] = scipy.fft.rfft2(wrapped)
        pressing = np.zeros((ny + 1) * (nx + 1), dtype=bool)
        pressing[nodes] = True
        pressing = pressing.reshape(ny + 1, nx + 1)
        #: (4, ny, nx) quarter (a, b) of each cell presses: the cell in the bed, its owner in nodes
        self._active = np.stack([bed & pressing[b:b + ny, a:a + nx] for a, b in QUARTERS])
        count = self._scatter(self._active[None].astype(float))[0]
        self.area = count.ravel()[nodes] * (hx * hy / 4)
        idle = np.flatnonzero(self.area == 0)
        if idle.size:
            raise ProblemError(f"nodes: node {int(nodes[idle[0]])} (position {int(idle[0])}) presses no bed cell; "
                               "give the nodes of the bed's cells only")
        self._inv_area = np.zeros((ny + 1) * (nx + 1))
        self._inv_area[nodes] = 1.0 / self.area
        self._inv_area = self._inv_area.reshape(ny + 1, nx + 1)
        # a node is a corner of each of its quarters: quarter (a, b) at offset (a, b) from its cell
        own = np.array([kernels[q, ny - 1 + b, nx - 1 + a] for q, (a, b) in enumerate(QUARTERS)])
        diagonal = self._scatter((self._active * own[:, None, None])[None])[0] * self._inv_area
        self._diagonal = diagonal.ravel()[nodes]
        self._whole = _WholeBed(self, pressing) if bed.all() else None
        super().__init__(dtype=np.float64, shape=(nodes.size, nodes.size))

    def _scatter(self, fields: np.ndarray) -> np.ndarray:
        """(k, ny + 1, nx + 1): the sum over the quarters q of ``fields[:, q]`` (k, 4, ny, nx) at their owners."""
        ny, nx = self.ny, self.nx
        out = np.zeros((fields.shape[0], ny + 1, nx + 1))
        for q, (a, b) in enumerate(QUARTERS):
            out[:, b:b + ny, a:a + nx] += fields[:, q]
        return out

    def diagonal(self) -> np.ndarray:
        """(m,) the matrix's diagonal (H's own: symmetrising keeps it), exact."""
        return self._diagonal.copy()

    def _shape_error(self, what: str, shape: tuple, n: int) -> str:
        return f"x: a {what} of shape {shape} for {n} bed nodes; give one value per node, in the order of nodes"

    def settlements(self, forces) -> np.ndarray:
        """H @ ``forces``: the settlements at the nodes under the nodes' forces (m,) or (m, k),
        collocated, before symmetrising (Boussinesq's answer; the operator is ½(H + Hᵀ))."""
        F = np.asarray(forces, dtype=float)
        if F.ndim not in (1, 2) or F.shape[0] != self.shape[1]:
            raise ProblemError(f"forces: an array of shape {F.shape} for {self.shape[1]} bed nodes; give one "
                               "value per node (or a column per load case), in the order of nodes")
        return self._blocks(F.reshape(F.shape[0], -1), symmetric=False).reshape(F.shape)

    def _matmat(self, X):
        return self._blocks(np.asarray(X, dtype=float), symmetric=True)

    def _blocks(self, X: np.ndarray, symmetric: bool) -> np.ndarray:
        out = np.empty_like(X)
        cols = max(1, BLOCK_BYTES // (5 * 8 * self.fft_shape[0] * self.fft_shape[1]))
        for c0 in range(0, X.shape[1], cols):
            out[:, c0:c0 + cols] = self._apply(X[:, c0:c0 + cols].T, symmetric).T
        return out

    def _forward(self, f: np.ndarray) -> np.ndarray:
        """The transform of ``f`` (..., rows, cols) zero-padded to :attr:`fft_shape` (its zero rows
        skipped along x: rfft2's value)."""
        Ny, Nx = self.fft_shape
        return scipy.fft.fft(scipy.fft.rfft(f, n=Nx, axis=-1), n=Ny, axis=-2)

    def _inverse(self, F: np.ndarray, rows: int, cols: int) -> np.ndarray:
        """The first ``rows`` × ``cols`` of the inverse transform of ``F`` (irfft2's, the other rows
        not transformed along x)."""
        return scipy.fft.irfft(scipy.fft.ifft(F, axis=-2)[..., :rows, :], n=self.fft_shape[1], axis=-1)[..., :cols]

    def _apply(self, X: np.ndarray, symmetric: bool) -> np.ndarray:
        """(k, m) ½(H + Hᵀ) (``symmetric``) or H applied to the rows of ``X`` (k, m)."""
        ny, nx = self.ny, self.nx
        if symmetric and self._whole is not None:
            return self._whole.apply(X)
        k = X.shape[0]
        Y = np.zeros((k, (ny + 1) * (nx + 1)))
        Y[:, self.nodes] = X
        Y = Y.reshape(k, ny + 1, nx + 1)
        u = Y * self._inv_area
        P = np.stack([np.where(self._active[q], u[:, b:b + ny, a:a + nx], 0.0) for q, (a, b) in enumerate(QUARTERS)],
                     axis=1)
        spectra = self._forward(P)
        del P
        spectra *= self._kernel_hat
        Hx = self._inverse(spectra.sum(axis=1), ny + 1, nx + 1)
        if not symmetric:
            return Hx.reshape(k, -1)[:, self.nodes]
        # Hᵀ: the correlation of Y with k_ab, which is the convolution with its mirror's kernel
        # (k_ab(d) = k_a'b'(1 − d), a' = 1 − a, b' = 1 − b) read one node further on
        spectra = self._forward(Y)[:, None] * self._kernel_hat[::-1]  # the mirrors (QUARTERS reversed)
        corr = self._inverse(spectra, ny + 1, nx + 1)[:, :, 1:, 1:]
        del spectra
        HTy = self._scatter(np.where(self._active, corr, 0.0)) * self._inv_area
        return 0.5 * (Hx + HTy).reshape(k, -1)[:, self.nodes]


def bed_flexibility(mesh, region, E: float, nu: float, nodes) -> BedFlexibility:
    """The force flexibility H_F of a half-space bed's nodes on a grid, matrix-free.

    Parameters
    ----------
    mesh : plateqp.model.grid.Grid
        The plate's grid (its kept cells: holes and openings remove cells).
    region : list or dict or None
        The bed's region, as ``[foundation] region`` (a box, a polygon, a circle; None: the whole
        plate): its cells are those whose centre lies in it (:func:`plateqp.model.soil.region_cells`).
    E, nu : float
        The half-space's modulus (> 0) and Poisson ratio (−1 < ν ≤ 0.5).
    nodes : array_like of int
        The bed's nodes (mesh node indices, distinct), in the contact rows' order: the ``nodes``
        :func:`plateqp.model.soil.halfspace_flexibility` takes. Each must own a quarter of a bed
        cell; a corner of a bed cell not among them presses no soil.

    Returns
    -------
    BedFlexibility
        An (m, m) symmetric float64 LinearOperator: ``op @ x`` equals
        ``soil.halfspace_flexibility(model, nodes) @ x`` to rounding.

    Raises
    ------
    ProblemError
        Bad E or ν (named), ``nodes`` not distinct node indices of the grid, a node that owns no
        quarter of a bed cell.
    """
    boussinesq_factor(E, nu)
    try:
        nodes = np.asarray(nodes)
    except (TypeError, ValueError):
        raise ProblemError("nodes: not an array of node indices") from None
    n_nodes = (mesh.nx + 1) * (mesh.ny + 1)
    if nodes.ndim != 1 or not (nodes.size == 0 or np.issubdtype(nodes.dtype, np.integer)):
        raise ProblemError(f"nodes: a 1-D array of node indices, got {nodes.dtype} of shape {nodes.shape}")
    nodes = nodes.astype(np.intp)
    if nodes.size and not (0 <= nodes.min() and nodes.max() < n_nodes):
        raise ProblemError(f"nodes: node indices lie in 0 … {n_nodes - 1}, got {int(nodes.min())} … {int(nodes.max())}")
    if np.unique(nodes).size != nodes.size:
        raise ProblemError("nodes: each node once (a node index repeats)")
    bed = np.zeros(mesh.nx * mesh.ny, dtype=bool)
    bed[mesh.cell_ids[region_cells(mesh, region)]] = True
    return BedFlexibility(mesh.nx, mesh.ny, mesh.hx, mesh.hy, E, nu, bed.reshape(mesh.ny, mesh.nx), nodes)


class _WholeBed:
    """½(H + Hᵀ) of a bed over every cell of the grid in four FFTs a product (two for H, two for Hᵀ)
    instead of ten.

    Every node owns its quarters of all the cells it touches, so H's four convolutions of the
    quarters' fields are one convolution of the nodes' pressures u with the sum of the four kernels,
    each shifted to its corner (a product of spectra with phases), less the quarters of the cells
    beyond the grid that this sum counts: those of the grid's edge rows and columns of nodes, lines
    whose transforms are one 1-D FFT each (and a corner node's single value). Hᵀ likewise: one
    correlation with the shifted sum, less the same quarters read off single rows and columns of
    its inverse transform (a weighted sum of the spectrum, one 1-D FFT). Only the lines and corners
    whose nodes press are corrected. Exact as the general route is, to rounding."""

    def __init__(self, op: BedFlexibility, pressing: np.ndarray) -> None:
        ny, nx = op.ny, op.nx
        Ny, Nx = op.fft_shape
        self.op = op
        ky, kx = np.arange(Ny), np.arange(Nx // 2 + 1)

        def ey(r):  # the transform along y of a unit value at row r (r may be negative: wrapped)
            return np.exp(-2j * np.pi * ky * r / Ny)[:, None]

        def ex(c):
            return np.exp(-2j * np.pi * kx * c / Nx)[None, :]

        kh = op._kernel_hat
        # H: quarter (a, b) of cell c is u at c + (a, b); the cell beyond the grid is row rb / column rc,
        # its node row ub = rb + b / column ua = rc + a
        rb, ub = {0: ny, 1: -1}, {0: ny, 1: 0}
        rc, ua = {0: nx, 1: -1}, {0: nx, 1: 0}
        self.kc = sum(kh[q] * ey(-b) * ex(-a) for q, (a, b) in enumerate(QUARTERS))
        rows_on = {b: bool(pressing[ub[b]].any()) for b in (0, 1)}
        cols_on = {a: bool(pressing[:, ua[a]].any()) for a in (0, 1)}
        self.rows = [(ub[b], sum(kh[q] * ey(rb[b]) * ex(-a) for q, (a, bb) in enumerate(QUARTERS) if bb == b))
                     for b in (0, 1) if rows_on[b]]
        self.cols = [(ua[a], sum(kh[q] * ey(-b) * ex(rc[a]) for q, (aa, b) in enumerate(QUARTERS) if aa == a))
                     for a in (0, 1) if cols_on[a]]
        self.corners = [((ub[b], ua[a]), kh[q] * ey(rb[b]) * ex(rc[a])) for q, (a, b) in enumerate(QUARTERS)
                        if pressing[ub[b], ua[a]]]
        # Hᵀ: quarter (a, b) reads the correlation with its mirror's kernel at node n − (b − 1, a − 1); the
        # cells beyond the grid are those of node row Jb / column Ia
        mirror = kh[::-1]
        shifted = [mirror[q] * ey(b - 1) * ex(a - 1) for q, (a, b) in enumerate(QUARTERS)]
        self.kt = sum(shifted)
        Jb, Ia = {0: ny, 1: 0}, {0: nx, 1: 0}
        w = np.full(kx.size, 2.0)
        w[0] = 1.0
        if Nx % 2 == 0:
            w[-1] = 1.0

        def at_row(J):  # the weights that read row J of the inverse transform (÷ Ny: ifft's)
            return np.conj(ey(J)) / Ny

        def at_col(i):  # the weights that read column i of the inverse transform along x (irfft's)
            return w[None, :] * np.conj(ex(i)) / Nx

        self.trows = [(Jb[b], sum(shifted[q] for q, (a, bb) in enumerate(QUARTERS) if bb == b) * at_row(Jb[b]))
                      for b in (0, 1) if rows_on[b]]
        self.tcols = [(Ia[a], sum(shifted[q] for q, (aa, b) in enumerate(QUARTERS) if aa == a) * at_col(Ia[a]))
                      for a in (0, 1) if cols_on[a]]
        self.tcorners = [((Jb[b], Ia[a]), shifted[q] * at_row(Jb[b]) * at_col(Ia[a]))
                         for q, (a, b) in enumerate(QUARTERS) if pressing[Jb[b], Ia[a]]]

    def apply(self, X: np.ndarray) -> np.ndarray:
        op = self.op
        ny, nx = op.ny, op.nx
        Ny, Nx = op.fft_shape
        k = X.shape[0]
        Y = np.zeros((k, (ny + 1) * (nx + 1)))
        Y[:, op.nodes] = X
        Y = Y.reshape(k, ny + 1, nx + 1)
        u = Y * op._inv_area
        S = op._forward(u) * self.kc
        for row, Kr in self.rows:
            S -= Kr * scipy.fft.rfft(u[:, row, :], n=Nx, axis=-1)[:, None, :]
        for col, Kc in self.cols:
            S -= Kc * scipy.fft.fft(u[:, :, col], n=Ny, axis=-1)[:, :, None]
        for (row, col), Kq in self.corners:
            S += Kq * u[:, row, col][:, None, None]
        Hx = op._inverse(S, ny + 1, nx + 1)
        T = op._forward(Y)
        full = op._inverse(T * self.kt, ny + 1, nx + 1)
        for row, Kr in self.trows:
            full[:, row, :] -= scipy.fft.irfft(np.einsum("kyx,yx->kx", T, Kr), n=Nx, axis=-1)[:, :nx + 1]
        for col, Kc in self.tcols:
            full[:, :, col] -= scipy.fft.ifft(np.einsum("kyx,yx->ky", T, Kc), axis=-1)[:, :ny + 1].real
        for (row, col), Kq in self.tcorners:
            full[:, row, col] += np.einsum("kyx,yx->k", T, Kq).real
        return 0.5 * (Hx + full * op._inv_area).reshape(k, -1)[:, op.nodes]
