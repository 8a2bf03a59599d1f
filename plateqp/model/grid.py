"""Structured rectangular meshes with cell masks (cut-outs: holes and openings).

Nodes are numbered row by row: node (i, j) at (i·hx, j·hy) has index j·(nx + 1) + i.
Cells likewise: cell (i, j) spans [i·hx, (i+1)·hx] × [j·hy, (j+1)·hy], index j·nx + i, with
corner nodes in the element order (0,0), (1,0), (1,1), (0,1).
A node belongs to the plate if at least one of its cells is kept.

A cut-out (a ``[[holes]]`` shape or an ``[[openings]]`` box, numbered K in that order as in
:func:`plateqp.model.geometry.scene_domain`) removes every cell whose centre lies in it (boundary
included). The plate's boundary edges are the cell sides between a kept cell and the outside
(boundary 0, the rectangle's segment: 0 bottom, 1 right, 2 top, 3 left) or a cell a cut-out
removed (boundary K + 1, the cut-out's nearest segment), as on a triangle mesh
(:class:`plateqp.model.trimesh.TriMesh`): the edge supports name them the same way on both meshes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.sparse as sp


@dataclass
class Grid:
    a: float
    b: float
    nx: int
    ny: int
    cell_mask: np.ndarray  # (nx*ny,) bool: cell kept
    #: (nx*ny,) the cut-out that removed each cell (K, the first that holds its centre), −1 if kept
    cutout: np.ndarray | None = field(default=None, repr=False)
    #: the plate's :class:`~plateqp.model.geometry.Domain`: the rectangle less its cut-outs (their
    #: shapes, K = 0, 1, …: ``domain.holes``), parsed once
    domain: object = field(default=None, repr=False)

    @property
    def cutouts(self) -> tuple:
        """The cut-outs' shapes (:class:`~plateqp.model.geometry.Polygon` / ``Circle``), K = 0, 1, …"""
        return () if self.domain is None else self.domain.holes

    @classmethod
    def from_scene(cls, scene) -> Grid:
        from .geometry import scene_domain

        p, m = scene.plate, scene.mesh
        nx, ny = m.nx, m.ny
        hx, hy = p.a / nx, p.b / ny
        cx = (np.arange(nx) + 0.5) * hx
        cy = (np.arange(ny) + 0.5) * hy
        X, Y = (v.ravel() for v in np.meshgrid(cx, cy))  # row j, column i -> index j*nx + i
        domain = scene_domain(scene)
        shapes = domain.holes
        cut = np.full(X.shape, -1)
        for k, shape in enumerate(shapes):
            x0, x1, y0, y1 = shape.bbox
            near = np.flatnonzero((cut < 0) & (X >= x0) & (X <= x1) & (Y >= y0) & (Y <= y1))
            if near.size:
                inside = shape.contains(X[near], Y[near], 1e-12 * max(p.a, p.b))
                cut[near[inside]] = k
        return cls(p.a, p.b, nx, ny, cut < 0, cut, domain)

    # -- the generator's side of building a model (plateqp.model.assembly.build_model) ----------------
    #: the stiffness :meth:`assemble` gives is exactly symmetric, value for value
    symmetric_assembly = True

    @staticmethod
    def estimate_nodes(scene) -> int:
        """The nodes the grid of ``scene`` numbers (its dofs' nodes): (nx + 1)(ny + 1)."""
        return (scene.mesh.nx + 1) * (scene.mesh.ny + 1)

    @staticmethod
    def describe(scene) -> tuple[str, str, str]:
        """(field, the mesh in words, what makes it smaller) for a message about its size."""
        m = scene.mesh
        return "mesh", f"{m.nx} x {m.ny} {m.element} mesh", "use a coarser mesh"

    #: a point load stands anywhere in its cell, not at a node (a moved load keeps the mesh)
    points_are_nodes = False

    @staticmethod
    def size_note(scene) -> str:
        """Words after a refinement ladder's "nx x ny" (the cells say it all on a grid): ""."""
        return ""

    def summary(self, element: str) -> dict:
        """The mesh in numbers, for a file's metadata: cells a side and element."""
        return {"nx": int(self.nx), "ny": int(self.ny), "element": element}

    def summary_text(self, element: str, units: str = "") -> str:
        """The mesh in words, for a report (``units``: of length, unused on a grid)."""
        return f"mesh {self.nx} × {self.ny} {element.upper()}"

    @property
    def bbox(self) -> tuple[float, float, float, float]:
        """(x0, x1, y0, y1) of the plate: the rectangle a × b."""
        return 0.0, float(self.a), 0.0, float(self.b)

    def grid_view(self, values: np.ndarray) -> np.ndarray:
        """The (ny + 1, nx + 1) view of a nodal field, NaN off the plate (:meth:`to_grid`)."""
        return self.to_grid(values)

    # the meshes of a refinement ladder, counted in cells a side (plateqp.studies.refinement)
    @staticmethod
    def cells_a_side(scene) -> tuple[int, int]:
        """(nx, ny): the grid's cells."""
        return scene.mesh.nx, scene.mesh.ny

    @staticmethod
    def set_cells(scene, nx: int, ny: int) -> None:
        """Make ``scene`` (a copy) an nx × ny grid."""
        scene.mesh.nx, scene.mesh.ny = int(nx), int(ny)

    @staticmethod
    def start_cells(scene, cells: int) -> tuple[int, int]:
        """``cells`` on the shorter side, the other in proportion to the scene's own grid."""
        nx, ny = scene.mesh.nx, scene.mesh.ny
        if nx <= ny:
            return cells, max(cells, round(cells * ny / nx))
        return max(cells, round(cells * nx / ny)), cells

    @cached_property
    def cell_ids(self) -> np.ndarray:
        """(n_kept,) the grid index (j·nx + i) of each cell of :attr:`cells`."""
        return np.flatnonzero(self.cell_mask)

    def assemble(self, element, D: float, nu: float, pos: np.ndarray, ncol: int) -> sp.csr_matrix:
        """The stiffness on the dofs with ``pos`` ≥ 0 (``pos``: each dof's new index, increasing;
        ``ncol`` of them), in canonical CSR. Every cell of a grid has the same element matrix, so
        the matrix is built directly from the node-level stencil (:func:`_node_blocks`), exactly
        symmetric."""
        V, cnode = _node_blocks(self, element.stiffness(self.hx, self.hy, D, nu), element.ndof_node)
        return _csr_from_blocks(V, cnode, pos, ncol)

    def tributary_areas(self, region) -> np.ndarray:
        """(n_nodes,) each node's tributary area of a bed on ``region`` (None: the whole plate):
        a box [x0, x1, y0, y1] keeps the grid's cell rule, a quarter of every kept cell centred
        in it (:meth:`cells_centred_in`); a polygon or a circle
        (:func:`plateqp.model.geometry.parse_region`) gives each node the integral of its bilinear
        hat over each kept cell's part in the region (:func:`plateqp.model.regions.cell_hat_areas`:
        a quarter of each cell wholly in it; the areas sum to the region's area on the kept cells
        exactly, a circle's to rounding)."""
        from .regions import box_of, cell_hat_areas

        box = box_of(region)
        area = np.zeros(self.n_nodes)
        if region is None or box is not None:
            cells = np.flatnonzero(self.cell_mask) if region is None else self.cells_centred_in(*box)
            np.add.at(area, self.cell_nodes()[cells].ravel(), 0.25 * self.hx * self.hy)
            return area
        cells = np.flatnonzero(self.cell_mask)
        hit, weights = cell_hat_areas(self.nodes[self.cell_nodes()[cells]], region)
        np.add.at(area, self.cell_nodes()[cells[hit]].ravel(), weights.ravel())
        return area

    def halfspace_flexibility_operator(self, region, E: float, nu: float, nodes):
        """The force flexibility of a half-space bed on ``region`` at its ``nodes`` (the contact
        rows' order), matrix-free: an (m, m) symmetric LinearOperator equal to
        :func:`plateqp.model.soil.halfspace_flexibility`'s matrix to rounding, applied by FFT
        (:func:`plateqp.model.halfspace_grid.bed_flexibility`)."""
        from .halfspace_grid import bed_flexibility

        return bed_flexibility(self, region, E, nu, nodes)

    def boundary_edges(self):
        """The plate's boundary as every mesh gives it: (edges (ne, 2) node pairs, outward unit
        normals (ne, 2), boundary (ne,) 0 outer or K + 1 for cut-out K, segment (ne,) of that
        boundary's shape), computed once (the arrays are shared: read them, do not change them).
        See the module docstring."""
        return self._boundary_edges

    @cached_property
    def _boundary_edges(self):
        from .geometry import nearest_segment

        nx, ny = self.nx, self.ny
        kept = self.cell_mask.reshape(ny, nx)
        cut = (self.cutout if self.cutout is not None else np.where(self.cell_mask, -1, 0)).reshape(ny, nx)
        J, I = np.nonzero(kept)
        out = []
        # (di, dj) to the neighbour, the side's corners (as cell corner offsets), outward normal,
        # the rectangle's segment that side lies on
        for di, dj, (c0, c1), n, seg in ((0, -1, ((0, 0), (1, 0)), (0.0, -1.0), 0),
                                         (1, 0, ((1, 0), (1, 1)), (1.0, 0.0), 1),
                                         (0, 1, ((1, 1), (0, 1)), (0.0, 1.0), 2),
                                         (-1, 0, ((0, 1), (0, 0)), (-1.0, 0.0), 3)):
            i2, j2 = I + di, J + dj
            outside = (i2 < 0) | (i2 >= nx) | (j2 < 0) | (j2 >= ny)
            ii, jj = np.clip(i2, 0, nx - 1), np.clip(j2, 0, ny - 1)
            removed = ~outside & ~kept[jj, ii]
            hit = outside | removed
            a = (J[hit] + c0[1]) * (nx + 1) + I[hit] + c0[0]
            b = (J[hit] + c1[1]) * (nx + 1) + I[hit] + c1[0]
            k = np.where(outside[hit], 0, cut[jj[hit], ii[hit]] + 1)
            out.append((np.column_stack([a, b]), np.tile(n, (hit.sum(), 1)), k, np.full(hit.sum(), seg)))
        edges, normals, boundary, segment = (np.concatenate(v) for v in zip(*out))
        xy = self.node_xy()
        mid = 0.5 * (xy[edges[:, 0]] + xy[edges[:, 1]])
        for k, shape in enumerate(self.cutouts):
            on = np.flatnonzero(boundary == k + 1)
            if on.size:
                segment[on] = nearest_segment(shape, mid[on], normals[on], max(self.hx, self.hy))
        return edges, normals, boundary, segment

    @property
    def hx(self) -> float:
        return self.a / self.nx

    @property
    def hy(self) -> float:
        return self.b / self.ny

    @property
    def n_nodes(self) -> int:
        return (self.nx + 1) * (self.ny + 1)

    def node_xy(self) -> np.ndarray:
        """(n_nodes, 2) coordinates of all grid nodes."""
        i, j = np.meshgrid(np.arange(self.nx + 1), np.arange(self.ny + 1))
        return np.column_stack([i.ravel() * self.hx, j.ravel() * self.hy])

    def cell_nodes(self) -> np.ndarray:
        """(n_cells, 4) node indices of every cell (kept or not), element corner order."""
        i, j = np.meshgrid(np.arange(self.nx), np.arange(self.ny))
        n0 = (j * (self.nx + 1) + i).ravel()
        return np.column_stack([n0, n0 + 1, n0 + self.nx + 2, n0 + self.nx + 1])

    def node_mask(self) -> np.ndarray:
        """(n_nodes,) bool: node belongs to a kept cell (a copy: the caller may change it)."""
        return self._node_mask.copy()

    @cached_property
    def _node_mask(self) -> np.ndarray:
        mask = np.zeros(self.n_nodes, dtype=bool)
        mask[self.cell_nodes()[self.cell_mask].ravel()] = True
        return mask

    # -- the mesh as every generator gives it (plateqp.model.trimesh.TriMesh has the same names) ------
    cell_type = "quad"

    @property
    def grid_shape(self) -> tuple[int, int]:
        """(ny + 1, nx + 1): the grid view of a nodal field (:meth:`to_grid`)."""
        return (self.ny + 1, self.nx + 1)

    @cached_property
    def plate_node_ids(self) -> np.ndarray:
        """(n,) the grid index of each node of the plate (a node of a kept cell), in grid order:
        the mesh's nodes, as nodal fields and the dofs count them (node k's dofs are
        ``plate_node_ids[k] · ndof_node + i``)."""
        return np.flatnonzero(self._node_mask)

    @cached_property
    def nodes(self) -> np.ndarray:
        """(n, 2) coordinates of the plate's nodes (:attr:`plate_node_ids`)."""
        return self.node_xy()[self.plate_node_ids]

    @cached_property
    def cells(self) -> np.ndarray:
        """(n_kept, 4) the kept cells' corners as indices into :attr:`nodes`, element corner order."""
        new = np.full(self.n_nodes, -1)
        new[self.plate_node_ids] = np.arange(self.plate_node_ids.size)
        return new[self.cell_nodes()[self.cell_mask]]

    def triangulation(self) -> np.ndarray:
        """(2 n_kept, 3) counter-clockwise triangles on :attr:`nodes` (each quad split along its
        diagonal from corner 0 to corner 2): for drawing only."""
        c = self.cells
        return np.vstack([c[:, [0, 1, 2]], c[:, [0, 2, 3]]])

    def to_grid(self, values: np.ndarray) -> np.ndarray:
        """A nodal field (one value per plate node) on the (ny + 1, nx + 1) grid, NaN off the plate."""
        out = np.full(self.n_nodes, np.nan)
        out[self.plate_node_ids] = values
        return out.reshape(self.grid_shape)

    def nearest_other(self, pts: np.ndarray, m: int, reach: float) -> np.ndarray | None:
        """For each of the first ``m`` points, the distance to the nearest other point of ``pts``
        (0 where two are given at one place) among those nearer than ``reach``, ``inf`` where there
        is none; None unless every point is one of the grid's nodes as :meth:`node_xy` places it
        (to the bit). Each offset costs a pass over every node: for points that are many of them
        (a bed; a tree searches a few posts quicker).

        The nodes' coordinates are ``i hx`` and ``j hy``, so the distance from node ``(i, j)`` to
        node ``(i + di, j + dj)`` is ``sqrt(dx_i² + dy_j²)`` with ``dx_i = i hx − (i + di) hx`` and
        ``dy_j`` alike, as a tree or ``cdist`` computes it from the two points' coordinates (the
        same bits): one pass over the lattice for each offset shorter than ``reach`` (a bed's
        nodes at 512²: 15 ms, where a tree's bounded search took 0.13 s)."""
        if pts.shape[0] < 2:
            return None
        hx, hy, nx, ny = self.hx, self.hy, self.nx, self.ny
        i, j = np.rint(pts[:, 0] / hx), np.rint(pts[:, 1] / hy)
        if not (np.all((i >= 0) & (i <= nx) & (j >= 0) & (j <= ny))
                and np.array_equal(pts[:, 0], i * hx) and np.array_equal(pts[:, 1], j * hy)):
            return None
        node = j.astype(np.int64) * (nx + 1) + i.astype(np.int64)
        count = np.bincount(node, minlength=self.n_nodes)
        there = (count > 0).reshape(ny + 1, nx + 1)
        best = np.where(count > 1, 0.0, np.inf).reshape(ny + 1, nx + 1)  # another point at its own node
        xs, ys = np.arange(nx + 1) * hx, np.arange(ny + 1) * hy
        ki, kj = min(nx, int(reach // hx) + 1), min(ny, int(reach // hy) + 1)
        for di in range(-ki, ki + 1):
            for dj in range(-kj, kj + 1):
                # an offset whose own length is past the reach gives no distance below it
                if (di, dj) == (0, 0) or np.hypot(di * hx, dj * hy) >= reach * (1.0 + 1e-9):
                    continue
                a_i, b_i = slice(max(0, -di), nx + 1 - max(0, di)), slice(max(0, di), nx + 1 - max(0, -di))
                a_j, b_j = slice(max(0, -dj), ny + 1 - max(0, dj)), slice(max(0, dj), ny + 1 - max(0, -dj))
                dx, dy = xs[a_i] - xs[b_i], ys[a_j] - ys[b_j]
                d = np.sqrt(dy[:, None] * dy[:, None] + dx[None, :] * dx[None, :])
                d[~there[b_j, b_i]] = np.inf
                np.minimum(best[a_j, a_i], d, out=best[a_j, a_i])
        out = best.ravel()[node[:m]]
        out[out >= reach] = np.inf  # as the bounded search: nothing at or past the reach
        return out

    def node_at(self, x: float, y: float, rtol: float = 1e-9) -> int | None:
        """Index of the plate node at (x, y), or None if no kept node is there."""
        fi, fj = x / self.hx, y / self.hy
        i, j = round(fi), round(fj)
        if abs(fi - i) > rtol * max(1, self.nx) or abs(fj - j) > rtol * max(1, self.ny):
            return None
        if not (0 <= i <= self.nx and 0 <= j <= self.ny):
            return None
        n = j * (self.nx + 1) + i
        return n if self._node_mask[n] else None

    @cached_property
    def _kept_index(self) -> np.ndarray:
        return np.cumsum(self.cell_mask) - 1

    def locate(self, x, y):
        """(cell, local): each point's cell, as an index into :attr:`cells` (the kept cells; −1
        where off the plate), and its local coordinates (npts, 2) = (ξ, η) in that cell, as
        every mesh gives them (:meth:`plateqp.model.trimesh.TriMesh.locate`).

        A point on a cell boundary is given to a kept neighbour when there is one.
        """
        cell, xi, eta = self._grid_locate(x, y)
        return np.where(cell >= 0, self._kept_index[np.maximum(cell, 0)], -1), np.column_stack([xi, eta])

    def _grid_locate(self, x, y):
        """The grid's own cell index (j·nx + i, kept cells only; −1 off the plate) and (ξ, η)."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        y = np.atleast_1d(np.asarray(y, dtype=float))
        # clipped: a point far off the plate stays off it, and its cell index cannot overflow
        with np.errstate(over="ignore", invalid="ignore"):  # x near the largest double: x / hx is inf
            fx = np.clip(np.nan_to_num(x / self.hx, nan=-2.0), -2.0, self.nx + 2.0)
            fy = np.clip(np.nan_to_num(y / self.hy, nan=-2.0), -2.0, self.ny + 2.0)
        cell = np.full(x.shape, -1, dtype=int)
        xi = np.zeros(x.shape)
        eta = np.zeros(x.shape)
        eps = 1e-9
        # try the cell below-left of the point and its neighbours across a shared boundary
        for dx in (0, -1):
            for dy in (0, -1):
                i = np.floor(fx + eps).astype(int) + dx
                j = np.floor(fy + eps).astype(int) + dy
                ok = (cell < 0) & (i >= 0) & (i < self.nx) & (j >= 0) & (j < self.ny)
                lx, ly = fx - i, fy - j
                ok &= (lx >= -eps) & (lx <= 1 + eps) & (ly >= -eps) & (ly <= 1 + eps)
                c = np.where(ok, j * self.nx + i, 0)
                ok &= self.cell_mask[c]
                cell = np.where(ok, c, cell)
                xi = np.where(ok, np.clip(lx, 0, 1), xi)
                eta = np.where(ok, np.clip(ly, 0, 1), eta)
        return cell, xi, eta

    def covers(self, x: float, y: float) -> bool:
        """True if (x, y) lies on a kept cell (boundaries included)."""
        return bool(self._grid_locate(x, y)[0][0] >= 0)

    def cells_centred_in(self, x0: float, x1: float, y0: float, y1: float) -> np.ndarray:
        """Indices of the kept cells whose centre lies in [x0, x1] × [y0, y1] (bounds included)."""
        cc = np.flatnonzero(self.cell_mask)
        cx = (cc % self.nx + 0.5) * self.hx
        cy = (cc // self.nx + 0.5) * self.hy
        return cc[(cx >= x0) & (cx <= x1) & (cy >= y0) & (cy <= y1)]

    def cells_in(self, shape) -> np.ndarray:
        """Indices of the kept cells whose centre lies in the region ``shape`` (a
        :class:`~plateqp.model.geometry.Polygon` or ``Circle``; its boundary included)."""
        x0, x1, y0, y1 = shape.bbox
        if getattr(shape, "vertices", ()) and len(shape.vertices) == 4 and shape.area == (x1 - x0) * (y1 - y0):
            return self.cells_centred_in(x0, x1, y0, y1)  # a box
        cc = np.flatnonzero(self.cell_mask)
        cx = (cc % self.nx + 0.5) * self.hx
        cy = (cc // self.nx + 0.5) * self.hy
        return cc[shape.contains(cx, cy, 1e-12 * max(self.a, self.b))]

    def covers_area(self, x0: float, x1: float, y0: float, y1: float) -> bool:
        """True if the box [x0, x1] × [y0, y1] overlaps a kept cell with positive area."""
        i = np.arange(self.nx)
        j = np.arange(self.ny)
        ox = np.minimum(x1, (i + 1) * self.hx) - np.maximum(x0, i * self.hx) > 0
        oy = np.minimum(y1, (j + 1) * self.hy) - np.maximum(y0, j * self.hy) > 0
        hit = np.outer(oy, ox).ravel()  # index j*nx + i, like cell_mask
        return bool(np.any(hit & self.cell_mask))

    # -- what the scene's checks, the figures and the tables ask of every mesh (TriMesh too) ----
    @staticmethod
    def check_scene_fields(scene) -> None:
        """The scene-language rules of the grid: a plate shape or an element size needs triangles."""
        p, m = scene.plate, scene.mesh
        if p.shape is not None or m.size is not None:
            scene._fail("plate.shape" if p.shape is not None else "mesh.size",
                        'needs a triangle mesh: set mesh.element = "dkt"')

    @classmethod
    def cover(cls, scene) -> Grid:
        """What the point checks ask of the plate (``covers``, ``locate``, ``node_at``,
        ``covers_area``, ``cells_centred_in``, ``domain``): the scene's grid itself."""
        return cls.from_scene(scene)

    #: whether ``edges.all`` held the cut-outs' edges before: never on a grid (nothing changed)
    all_held_holes = False
    #: the demo's studies not yet run on this mesh, (name, why) pairs: none on a grid
    not_yet_studied: tuple = ()

    def caption(self, element: str) -> str:
        """The mesh in a figure's caption: "nx × ny mesh"."""
        return f"{self.nx} × {self.ny} mesh"

    def outline_paths(self) -> list[tuple[str, np.ndarray, bool]]:
        """The outline to draw, [(gid, points, closed)]: one entry "outline", the (m, 2, 2) sides
        of the kept cells on the plate's boundary, openings included, as separate segments."""
        from .views import cell_side_outline

        return [("outline", cell_side_outline(self), False)]

    def contour_position(self, xy: np.ndarray) -> tuple[np.ndarray, bool]:
        """Each point's arc length along the rectangle's boundary, anticlockwise from (0, 0), and
        whether all of three or more points stand on it (:func:`plateqp.model.views.contour_position`)."""
        from .views import contour_position

        return contour_position(xy, self.a, self.b)

    def default_sections(self, scene) -> list:
        """Section lines across the rectangle (:func:`plateqp.model.views.rectangle_sections`)."""
        from .views import rectangle_sections

        return rectangle_sections(scene, self.a, self.b)

    def field_layout(self, fields: dict, nodes: bool = False) -> tuple:
        """(dims, coords, fields) of nodal fields in a dataset: the grid view, or with ``nodes``
        one value per node (:mod:`plateqp.model.views`)."""
        from .views import grid_layout, node_layout

        return node_layout(self, fields) if nodes else grid_layout(self, fields)

    @staticmethod
    def plan_view(structured, shaped):
        """Of a figure's two plan views, the one that draws this mesh: ``structured`` (the grid's
        lines, removed cells hatched, the rectangle's sides)."""
        return structured


CORNER_IJ = ((0, 0), (1, 0), (1, 1), (0, 1))  # element corner order (di, dj)


def _node_blocks(grid, Ke, nd):
    """Node-level stencil of the assembled stiffness.

    Every kept cell has the same Ke, so the nd×nd block coupling node p to its neighbour
    p + (di, dj) (o = 3(dj+1) + di+1, ascending in node number) is the sum of Ke's corner blocks
    over the kept cells that hold both nodes; which of those exist is one of 16 patterns per node.
    Returns V (n_nodes, nd, 9, nd), cnode (n_nodes, 9) neighbour node or -1 where no block.
    """
    nn = grid.n_nodes
    kept = np.zeros((nn, 4))
    cn = grid.cell_nodes()[grid.cell_mask]
    for a in range(4):
        kept[cn[:, a], a] = 1.0  # the cell having node p as its corner a is kept
    T = np.zeros((4, nd, 9, nd))
    S = np.zeros((4, 9))
    for a, (ia, ja) in enumerate(CORNER_IJ):
        for b, (ib, jb) in enumerate(CORNER_IJ):
            o = 3 * (jb - ja + 1) + (ib - ia + 1)
            T[a, :, o, :] = Ke[a * nd:(a + 1) * nd, b * nd:(b + 1) * nd]
            S[a, o] = 1.0
    # a node's blocks depend only on which of its <= 4 cells are kept: 16 patterns. Sum each
    # pattern's corner blocks in ascending cell order (corners 2, 3, 1, 0 of the node), so the
    # (p, q) and (q, p) entries add the same numbers in the same order: K exactly symmetric.
    bits = (kept * np.array([1, 2, 4, 8])).sum(axis=1).astype(np.intp)
    table = np.zeros((16, nd * 9 * nd))
    Tf = T.reshape(4, -1)
    for pat in range(16):
        for a in (2, 3, 1, 0):
            if pat >> a & 1:
                table[pat] += Tf[a]
    V = table[bits].reshape(nn, nd, 9, nd)
    off = np.array([dj * (grid.nx + 1) + di for dj in (-1, 0, 1) for di in (-1, 0, 1)])
    cnode = np.where(kept @ S > 0, np.arange(nn)[:, None] + off, -1)
    return V, cnode


def _csr_from_blocks(V, cnode, pos, ncol):
    """Rows/cols: dofs with pos >= 0 (pos: new index per full dof, increasing). Canonical CSR."""
    nn, nd = V.shape[:2]
    posn = pos.reshape(nn, nd)
    G = np.where(cnode[:, :, None] >= 0, posn[np.maximum(cnode, 0)], -1).reshape(nn, 9 * nd)
    G = G.astype(np.int32)
    colok = G >= 0
    rowok = posn >= 0
    m = rowok[:, :, None] & colok[:, None, :]
    data = V.reshape(nn, nd, 9 * nd)[m]
    counts = np.broadcast_to(colok.sum(axis=1)[:, None], rowok.shape)[rowok]
    # the indices with room for one more a row after them (plateqp.linalg.pattern.extended_indices:
    # the primal QP's block_diag(K, I) then shares them, not a copy of 21 MB at 256²)
    indices = np.empty(data.size + counts.size, dtype=np.int32)[:data.size]
    indices[:] = np.broadcast_to(G[:, None, :], m.shape)[m]
    indptr = np.zeros(counts.size + 1, dtype=np.int32)
    np.cumsum(counts, out=indptr[1:])
    A = sp.csr_matrix((data, indices, indptr), shape=(counts.size, ncol))
    A.has_sorted_indices = True
    A.has_canonical_format = True
    return A
