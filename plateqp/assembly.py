"""From a Scene to a Model: dof map, vectorised sparse assembly, loads, two-sided supports.

Dofs: node n carries ``ndof_node`` dofs numbered ``n·ndof_node + k`` on the full grid.
Two-sided supports prescribe some of them (``fixed`` with ``values``); the rest of the plate's
dofs are ``free``. The Model holds, on the free dofs,

    K u = f − K_fc u_c          (the two-sided problem; u_c the prescribed values)

and the one-sided support operator B (deflection at each contact point, through the
element's interpolation) with the gaps g0 shifted by the prescribed dofs' contribution.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .elements import ELEMENTS, RectElement
from .errors import ResourceError, SceneError
from .mesh import Grid
from .scene import PatchLoad, PointLoad, Scene, UniformLoad

# derivative orders of the nodal dofs, shared by ACM and BFS (BFS adds (1, 1))
W, WX, WY, WXY = (0, 0), (1, 0), (0, 1), (1, 1)


@dataclass
class ContactOperator:
    """The one-sided contact points of a model, in the order: discrete supports, then bed nodes.

    ``B``: (m, n_free) sparse, deflection at each point from the free dofs; ``g0``: initial
    gaps as the free dofs see them, the scene's gaps less ``shift``, the deflection the
    prescribed dofs (edges, pins) alone give each point; ``rho``: flexibility 1/c (0 for
    rigid); ``xy``: (m, 2) positions; ``source``: "support" or "bed"; ``index``: the support's
    index in the scene, or the node.
    """

    B: sp.csr_matrix
    g0: np.ndarray
    rho: np.ndarray
    xy: np.ndarray
    source: np.ndarray
    index: np.ndarray
    shift: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.shift is None:
            self.shift = np.zeros(self.g0.shape[0])

    @property
    def m(self) -> int:
        return self.g0.shape[0]

    @property
    def rigid(self) -> np.ndarray:
        return self.rho == 0.0

    @property
    def scene_gaps(self) -> np.ndarray:
        """The gaps as the scene gives them (``g0 + shift``)."""
        return self.g0 + self.shift

    def with_gaps(self, gaps: np.ndarray, rho: np.ndarray | None = None) -> ContactOperator:
        """A copy with the scene gaps ``gaps`` (one per contact point; the shift is kept) and,
        if given, the flexibilities ``rho``; B and the positions are shared."""
        return dataclasses.replace(self, g0=np.asarray(gaps, dtype=float) - self.shift,
                                   rho=self.rho if rho is None else np.asarray(rho, dtype=float))


@dataclass
class Model:
    scene: Scene
    grid: Grid
    element: RectElement
    K: sp.csr_matrix  # free × free
    f: np.ndarray  # free loads, prescribed-dof contribution included
    free: np.ndarray  # full dof indices of the free dofs
    fixed: np.ndarray  # full dof indices of the prescribed dofs
    values: np.ndarray  # their prescribed values
    n_full: int
    cell_dofs: np.ndarray  # (n_kept_cells, ndof) full dof indices
    cells: np.ndarray  # kept cell indices
    f_full: np.ndarray  # consistent loads on all dofs (for reactions at prescribed dofs)
    # all dofs × all dofs, or a function that assembles it (:attr:`K_full`, on first use)
    _K_full: sp.csr_matrix | Callable[[], sp.csr_matrix] = field(repr=False)
    contacts: ContactOperator | None = None
    #: K is exactly symmetric, value for value (the rectangular assembly makes it so: see
    #: :func:`_node_blocks`), so its CSR arrays are its CSC arrays
    #: (:func:`plateqp.linalg.pattern.csc_of_symmetric`)
    symmetric: bool = False

    @property
    def K_full(self) -> sp.csr_matrix:
        """The stiffness on every dof (prescribed ones and those off the plate included: their
        rows give the reactions at prescribed dofs, ``K_full @ expand(u) − f_full``). Assembled
        on first use: a solve needs it only where a prescribed value is not zero."""
        if callable(self._K_full):
            self._K_full = self._K_full()
        return self._K_full

    @property
    def n_free(self) -> int:
        return self.free.shape[0]

    def expand(self, u_free: np.ndarray) -> np.ndarray:
        """Full dof vector (prescribed values in place, dofs off the plate zero)."""
        u = np.zeros(self.n_full if u_free.ndim == 1 else (self.n_full, u_free.shape[1]))
        u[self.free] = u_free
        u[self.fixed] = self.values if u_free.ndim == 1 else self.values[:, None]
        return u

    def load_vector(self, scene: Scene) -> np.ndarray:
        """The consistent load vector (all dofs) of ``scene.loads`` on this model's mesh and
        element, without assembling the stiffness (a model re-used with new loads)."""
        return _loads(scene, self.grid, self.element, self.cells, self.cell_dofs, self.n_full)

    def rigid_modes(self) -> np.ndarray:
        """(n_free, k) basis of the rigid motions the two-sided supports leave free (k = 0..3 per piece).

        A rigid motion w = α + βx + γy (slopes β, γ, twist 0) of each connected piece of the
        plate, restricted to the free dofs, with the prescribed dofs held at zero.
        """
        return _rigid_modes(self)

    def interpolation(self, x, y, dx: int = 0, dy: int = 0) -> sp.csr_matrix:
        """(npts, n_full) sparse operator: derivative of w at points, from full dofs."""
        cell, xi, eta = self.grid.locate(x, y)
        if np.any(cell < 0):
            bad = np.flatnonzero(cell < 0)[0]
            raise SceneError(f"point ({np.atleast_1d(x)[bad]}, {np.atleast_1d(y)[bad]}) is not on the plate")
        N = self.element.shape(xi, eta, self.grid.hx, self.grid.hy, dx, dy)
        dofs = self.grid_cell_dofs(cell)
        rows = np.repeat(np.arange(len(cell)), N.shape[1])
        return sp.csr_matrix((N.ravel(), (rows, dofs.ravel())), shape=(len(cell), self.n_full))

    def bed_areas(self) -> np.ndarray:
        """(n_nodes,) each node's tributary area of the scene's tensionless bed: a quarter of every
        kept cell centred in the bed's region (the whole plate without one) that has it as a corner."""
        grid, fnd = self.grid, self.scene.foundation
        x0, x1, y0, y1 = fnd.region if fnd.region is not None else (0.0, grid.a, 0.0, grid.b)
        area = np.zeros(grid.n_nodes)
        np.add.at(area, grid.cell_nodes()[grid.cells_centred_in(x0, x1, y0, y1)].ravel(), 0.25 * grid.hx * grid.hy)
        return area

    def grid_cell_dofs(self, cell: np.ndarray) -> np.ndarray:
        nd = self.element.ndof_node
        nodes = self.grid.cell_nodes()[cell]
        return (nodes[:, :, None] * nd + np.arange(nd)).reshape(len(cell), -1)


#: Peak memory of building and solving a scene, per dof of its grid: measured (resident set
#: size, grid_rigid family, auto backend) 11.7 KB at 128², 9.9 KB at 256², 9.2 KB at 512².
BYTES_PER_DOF = 12_000
#: The environment variable that overrides the memory limit (bytes, or with a K/M/G/T suffix).
MEMORY_ENV = "PLATEQP_MAX_MEMORY"


def estimate_memory(scene: Scene) -> int:
    """Bytes a build and solve of ``scene`` is expected to need at its peak (see BYTES_PER_DOF)."""
    if scene.triangles:
        from .trimesh import estimate_nodes
        return int(BYTES_PER_DOF * 3 * estimate_nodes(scene))
    nd = len(ELEMENTS[scene.mesh.element].node_dofs)
    return int(BYTES_PER_DOF * (scene.mesh.nx + 1) * (scene.mesh.ny + 1) * nd)


def memory_limit() -> int:
    """The memory a solve may plan to use: ``$PLATEQP_MAX_MEMORY`` if set, else 80 % of this
    machine's physical memory (no limit where that cannot be read)."""
    text = os.environ.get(MEMORY_ENV, "").strip()
    if text:
        return parse_bytes(text, MEMORY_ENV)
    try:
        return int(0.8 * os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return 2**63 - 1


def parse_bytes(text: str, where: str) -> int:
    """'8G', '512M', '1.5e9' → bytes; a SceneError naming ``where`` otherwise."""
    t = str(text).strip().upper().removesuffix("B")
    mult = {"K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}.get(t[-1:], 1)
    try:
        value = float(t[:-1] if t[-1:] in "KMGT" else t) * mult
    except ValueError:
        value = float("nan")
    if not (value > 0 and np.isfinite(value)):
        raise SceneError(f"{where}: {text!r} is not an amount of memory (e.g. 8G, 512M, 2e9)")
    return int(value)


def human_bytes(n: float) -> str:
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= size:
            return f"{n / size:.1f} {unit}"
    return f"{n:.0f} B"


def check_memory(scene: Scene) -> None:
    """ResourceError before any allocation if ``scene`` would need more memory than allowed."""
    need, limit = estimate_memory(scene), memory_limit()
    if need > limit:
        raise ResourceError(f"mesh: a {scene.mesh.nx} x {scene.mesh.ny} {scene.mesh.element} mesh needs about "
                            f"{human_bytes(need)} to build and solve, above the limit of {human_bytes(limit)}; "
                            f"use a coarser mesh, or raise the limit (--max-memory or ${MEMORY_ENV})")


#: Model builders of the elements that are not on the rectangular grid, by ``mesh.element``; a
#: module registers its own on import (:mod:`plateqp.triassembly` "dkt", imported by ``plateqp``),
#: so that this module does not import it (no import cycle).
MESH_BUILDERS: dict[str, Callable[[Scene], Model]] = {}


def build_model(scene: Scene) -> Model:
    """Assemble the stiffness, loads, two-sided constraints and contact operator of a scene
    (after :func:`check_memory`: a mesh too large for the machine is refused before assembly).
    A scene on another mesh is built by its builder in :data:`MESH_BUILDERS` (triangles, DKT:
    :func:`plateqp.triassembly.build_tri_model`)."""
    if scene.mesh.element in MESH_BUILDERS:
        return MESH_BUILDERS[scene.mesh.element](scene)
    check_memory(scene)
    grid = Grid.from_scene(scene)
    el = ELEMENTS[scene.mesh.element]()
    nd = el.ndof_node
    p = scene.plate
    hx, hy = grid.hx, grid.hy
    n_full = grid.n_nodes * nd

    cells = np.flatnonzero(grid.cell_mask)
    nodes = grid.cell_nodes()[cells]
    cell_dofs = (nodes[:, :, None] * nd + np.arange(nd)).reshape(len(cells), -1)

    f_full = _loads(scene, grid, el, cells, cell_dofs, n_full)

    fixed, values = _prescribed(scene, grid, el)
    node_mask = grid.node_mask()
    on_plate = np.repeat(node_mask, nd)
    is_fixed = np.zeros(n_full, dtype=bool)
    is_fixed[fixed] = True
    free = np.flatnonzero(on_plate & ~is_fixed)

    # stiffness: every cell has the same element matrix; CSR built directly from node blocks
    V, cnode = _node_blocks(grid, el.stiffness(hx, hy, p.D, p.nu), nd)

    def K_full():  # off-plate rows empty; the node blocks made again (not kept with the model)
        Vf, cf = _node_blocks(grid, el.stiffness(hx, hy, p.D, p.nu), nd)
        return _csr_from_blocks(Vf, cf, np.arange(n_full), n_full)

    pos = np.full(n_full, -1)
    pos[free] = np.arange(free.size)
    K = _csr_from_blocks(V, cnode, pos, free.size)
    f = f_full[free]  # (a copy)
    if np.any(values != 0):  # the prescribed values' loads on the free dofs
        u_c = np.zeros(n_full)
        u_c[fixed] = values
        K_full = K_full()
        f -= (K_full @ u_c)[free]
    model = Model(scene, grid, el, K, f, free, fixed, values, n_full, cell_dofs, cells, f_full, K_full)
    model.symmetric = True  # _node_blocks adds (p, q) and (q, p) in the same order
    model.contacts = _contacts(scene, model)
    return model


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
    indices = np.broadcast_to(G[:, None, :], m.shape)[m]
    counts = np.broadcast_to(colok.sum(axis=1)[:, None], rowok.shape)[rowok]
    indptr = np.zeros(counts.size + 1, dtype=np.int32)
    np.cumsum(counts, out=indptr[1:])
    A = sp.csr_matrix((data, indices, indptr), shape=(counts.size, ncol))
    A.has_sorted_indices = True
    A.has_canonical_format = True
    return A


def _loads(scene, grid, el, cells, cell_dofs, n_full) -> np.ndarray:
    hx, hy = grid.hx, grid.hy
    f = np.zeros(n_full)
    for ld in scene.loads:
        if isinstance(ld, UniformLoad):
            fe = el.load(hx, hy)
            f += np.bincount(cell_dofs.ravel(), weights=np.tile(ld.q * fe, len(cells)), minlength=n_full)
        elif isinstance(ld, PatchLoad):
            ci = cells % grid.nx
            cj = cells // grid.nx
            x0 = np.clip((ld.x0 - ci * hx) / hx, 0, 1)
            x1 = np.clip((ld.x1 - ci * hx) / hx, 0, 1)
            y0 = np.clip((ld.y0 - cj * hy) / hy, 0, 1)
            y1 = np.clip((ld.y1 - cj * hy) / hy, 0, 1)
            hit = (x1 > x0) & (y1 > y0)
            if np.any(hit):
                fe = el.load(hx, hy, np.column_stack([x0, x1, y0, y1])[hit])
                np.add.at(f, cell_dofs[hit], ld.q * fe)
        elif isinstance(ld, PointLoad):
            cell, xi, eta = grid.locate(ld.x, ld.y)
            N = el.shape(xi, eta, hx, hy)[0]
            nodes = grid.cell_nodes()[cell[0]]
            dofs = (nodes[:, None] * el.ndof_node + np.arange(el.ndof_node)).ravel()
            np.add.at(f, dofs, ld.P * N)
    return f


def _prescribed(scene, grid, el):
    """Prescribed dofs and values from edges and pins; conflicts at corners are errors."""
    nd = el.ndof_node
    kinds = list(el.node_dofs)
    node_mask = grid.node_mask()
    presc: dict[int, tuple[float, str]] = {}

    def put(node, order, value, who):
        if order not in kinds or not node_mask[node]:
            return
        dof = node * nd + kinds.index(order)
        if dof in presc and abs(presc[dof][0] - value) > 1e-14 * max(1.0, abs(value)):
            raise SceneError(f"{who} and {presc[dof][1]} prescribe different values of "
                             f"{el.dof_names[kinds.index(order)]} at their common node; make them agree")
        presc[dof] = (value, who)

    nx, ny = grid.nx, grid.ny
    edge_nodes = {
        "left": [j * (nx + 1) for j in range(ny + 1)],
        "right": [j * (nx + 1) + nx for j in range(ny + 1)],
        "bottom": list(range(nx + 1)),
        "top": [ny * (nx + 1) + i for i in range(nx + 1)],
    }
    # (tangential slope order, normal slope order, sign of ∂/∂n relative to the slope dof)
    geometry = {"left": (WY, WX, -1.0), "right": (WY, WX, 1.0), "bottom": (WX, WY, -1.0), "top": (WX, WY, 1.0)}
    for name, e in scene.side_edges().items():
        if e.kind == "free":
            continue
        tang, normal, sign = geometry[name]
        who = f"edges.{name}"
        for n in edge_nodes[name]:
            put(n, W, e.w, who)
            put(n, tang, 0.0, who)  # w constant along the edge
            if e.kind == "clamped":
                put(n, normal, sign * e.slope, who)
                put(n, WXY, 0.0, who)  # the normal slope is constant along the edge
    for i, pin in enumerate(scene.pins):
        put(grid.node_at(pin.x, pin.y), W, pin.w, f"pins.{i}")
    fixed = np.array(sorted(presc), dtype=int)
    values = np.array([presc[d][0] for d in fixed], dtype=float)
    return fixed, values


def _rigid_modes(model: Model) -> np.ndarray:
    grid, el = model.grid, model.element
    nd = el.ndof_node
    kinds = list(el.node_dofs)
    cn = grid.cell_nodes()[model.cells]
    n = grid.n_nodes
    # connectivity of nodes through kept cells: each cell's first node to its others (the same
    # components as every pair, with 3 edges a cell instead of 16)
    r = np.repeat(cn[:, 0], cn.shape[1] - 1)
    c = cn[:, 1:].ravel()
    A = sp.csr_matrix((np.ones(r.size), (r, c)), shape=(n, n))
    _, label = connected_components(A, directed=False)
    node_mask = grid.node_mask()
    xy = grid.node_xy()
    fixed_node = model.fixed // nd
    fixed_kind = model.fixed % nd
    free_pos = -np.ones(model.n_full, dtype=int)
    free_pos[model.free] = np.arange(model.n_free)
    modes = []
    for comp in np.unique(label[node_mask]):
        in_comp = label[model.fixed // nd] == comp
        rows = []
        for node, k in zip(fixed_node[in_comp], fixed_kind[in_comp]):
            order = kinds[k]
            if order == W:
                rows.append([1.0, xy[node, 0], xy[node, 1]])
            elif order == WX:
                rows.append([0.0, 1.0, 0.0])
            elif order == WY:
                rows.append([0.0, 0.0, 1.0])
        R = np.array(rows).reshape(-1, 3)
        # null space of the constraints on (α, β, γ)
        _, s, vt = np.linalg.svd(R if len(R) else np.zeros((1, 3)), full_matrices=len(R) < 3)  # vt 3 × 3
        s_full = np.zeros(3)
        s_full[: len(s)] = s
        null = vt[s_full <= 1e-10 * max(1.0, s_full.max())]
        comp_nodes = np.flatnonzero((label == comp) & node_mask)
        for a, b, g in null:
            v = np.zeros(model.n_full)
            v[comp_nodes * nd + kinds.index(W)] = a + b * xy[comp_nodes, 0] + g * xy[comp_nodes, 1]
            v[comp_nodes * nd + kinds.index(WX)] = b
            v[comp_nodes * nd + kinds.index(WY)] = g
            modes.append(v[model.free])
    return np.array(modes).T.reshape(model.n_free, len(modes))


def _contacts(scene: Scene, model: Model) -> ContactOperator | None:
    if not scene.one_sided:
        return None
    grid = model.grid
    nd = model.element.ndof_node
    free_pos = -np.ones(model.n_full, dtype=int)
    free_pos[model.free] = np.arange(model.n_free)
    u_c = np.zeros(model.n_full)
    u_c[model.fixed] = model.values
    blocks, g0, rho, xy, source, index = [], [], [], [], [], []
    if scene.supports:
        sx = np.array([s.x for s in scene.supports])
        sy = np.array([s.y for s in scene.supports])
        Bf = model.interpolation(sx, sy)
        blocks.append(Bf)
        g0.append(np.array([s.gap for s in scene.supports]))
        rho.append(np.array([0.0 if s.rigid else 1.0 / s.stiffness for s in scene.supports]))
        xy.append(np.column_stack([sx, sy]))
        source += ["support"] * len(sx)
        index.append(np.arange(len(sx)))
    if scene.foundation is not None:
        fnd = scene.foundation
        area = model.bed_areas()
        nodes = np.flatnonzero(area > 0)
        wdof = nodes * nd
        nodes = nodes[free_pos[wdof] >= 0]  # a node whose w is prescribed gives its bed force to that support
        pts = grid.node_xy()[nodes]
        blocks.append(sp.csr_matrix((np.ones(len(nodes)), (np.arange(len(nodes)), nodes * nd)),
                                    shape=(len(nodes), model.n_full)))
        g0.append(fnd.gap_at(pts[:, 0], pts[:, 1]))
        rho.append(1.0 / (fnd.k * area[nodes]))
        xy.append(pts)
        source += ["bed"] * len(nodes)
        index.append(nodes)
    Bfull = sp.vstack(blocks).tocsr()
    shift = Bfull @ u_c
    g0 = np.concatenate(g0) - shift
    B = Bfull[:, model.free].tocsr()
    B.eliminate_zeros()
    empty = np.flatnonzero(np.diff(B.indptr) == 0)
    if empty.size:
        i = empty[0]
        raise SceneError(f"supports.{i + 1}: lies on a two-sided support (w is prescribed there), "
                         "so it can never act; remove it or the two-sided support")
    return ContactOperator(B, g0, np.concatenate(rho), np.vstack(xy), np.array(source), np.concatenate(index), shift)
