"""From a Scene to a Model: dof map, vectorised sparse assembly, loads, two-sided supports.

The memory check before it: :mod:`plateqp.model.memory`; the generator of a scene's mesh:
:mod:`plateqp.model.generators`.

Dofs: node n carries ``ndof_node`` dofs numbered ``n·ndof_node + k`` on the full grid.
Two-sided supports prescribe some of them (``fixed`` with ``values``); the rest of the plate's
dofs are ``free``. The Model holds, on the free dofs,

    K u = f − K_fc u_c          (the two-sided problem; u_c the prescribed values)

and the one-sided support operator B (deflection at each contact point, through the
element's interpolation) with the gaps g0 shifted by the prescribed dofs' contribution.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from .constraints import prescribed, rigid_modes
from .elements import ELEMENTS, RectElement
from ..errors import SceneError
from .generators import mesh_generator
from .memory import check_memory
from .scene import PatchLoad, PointLoad, Scene, UniformLoad
from .soil import attach, attach_operator, couples, halfspace_areas, halfspace_operator

if TYPE_CHECKING:  # pragma: no cover
    from .elements import DKT
    from .grid import Grid
    from .trimesh import TriMesh


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
    """A plate's two-sided problem on a mesh, K u = f on the free dofs, and its one-sided contact
    operator: what the contact code reads, the same on every mesh (``grid`` is the mesh: a
    :class:`~plateqp.model.grid.Grid` or a :class:`~plateqp.model.trimesh.TriMesh`, which answer the same
    names). Node n of the mesh's dof numbering carries dofs ``n · ndof_node + k``."""

    scene: Scene
    grid: Grid | TriMesh  # the mesh (either generator's; they answer the same names)
    element: RectElement | DKT  # an element of :data:`plateqp.model.elements.ELEMENTS`
    K: sp.csr_matrix  # free × free
    f: np.ndarray  # free loads, prescribed-dof contribution included
    free: np.ndarray  # full dof indices of the free dofs
    fixed: np.ndarray  # full dof indices of the prescribed dofs
    values: np.ndarray  # their prescribed values
    n_full: int
    cell_dofs: np.ndarray  # (n_cells, ndof) full dof indices of the plate's cells
    cells: np.ndarray  # the plate's cells, as the mesh indexes them
    f_full: np.ndarray  # consistent loads on all dofs (for reactions at prescribed dofs)
    # all dofs × all dofs, or a function that assembles it (:attr:`K_full`, on first use)
    _K_full: sp.csr_matrix | Callable[[], sp.csr_matrix] = field(repr=False)
    contacts: ContactOperator | None = None
    #: K is exactly symmetric, value for value (the mesh's assembly says so: the grid's does, see
    #: :meth:`plateqp.model.grid.Grid.assemble`), so its CSR arrays are its CSC arrays
    #: (:func:`plateqp.linalg.pattern.csc_of_symmetric`)
    symmetric: bool = False
    #: what the contact formulations derive from K and B alone (the condensed stiffness, the
    #: flexibility), kept for the next solve on this model or a copy of it that shares K and B
    #: (``dataclasses.replace`` shares this list: a sweep condenses once): [(K, B, kind, value)]
    derived: list = field(default_factory=list, repr=False, compare=False)
    #: the soil's surface unknowns (:mod:`plateqp.model.soil`: Pasternak, half-space), appended
    #: to K's dofs after the plate's free ones, one at each of ``soil_nodes`` (mesh nodes, the
    #: bed's contact rows in order); 0 and None for Winkler's springs or no bed
    n_soil: int = 0
    soil_nodes: np.ndarray | None = field(default=None, repr=False)
    #: a half-space held matrix-free (:func:`plateqp.model.soil.attach_operator`): the soil's
    #: force flexibility H_F on the bed's rows ``soil_rows`` (a LinearOperator, the user's units:
    #: settlement = H_F @ forces), K without soil unknowns; None otherwise
    soil_flexibility: object = field(default=None, repr=False, compare=False)
    soil_rows: np.ndarray | None = field(default=None, repr=False)

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
        """Full dof vector (prescribed values in place, dofs off the plate zero) of the plate's
        free dofs ``u_free`` (the soil's unknowns after them, if any, left out)."""
        u_free = u_free[:self.n_free]
        u = np.zeros(self.n_full if u_free.ndim == 1 else (self.n_full, u_free.shape[1]))
        u[self.free] = u_free
        u[self.fixed] = self.values if u_free.ndim == 1 else self.values[:, None]
        return u

    def unknowns(self, u_full: np.ndarray, compressions: np.ndarray | None = None) -> np.ndarray:
        """K's unknowns at a result: the plate's free dofs of ``u_full``, then (a soil with its
        own unknowns) the soil's settlements, a result's ``compressions`` on the bed's rows."""
        u = u_full[self.free]
        if not self.n_soil:
            return u
        return np.concatenate([u, np.asarray(compressions)[self.contacts.source == "bed"]])

    def on_unknowns(self, v_full: np.ndarray) -> np.ndarray:
        """A vector on every dof (a load) on K's unknowns: its free dofs, zeros for the soil's."""
        return np.concatenate([v_full[self.free], np.zeros(self.n_soil)]) if self.n_soil else v_full[self.free]

    def load_vector(self, scene: Scene) -> np.ndarray:
        """The load vector (all dofs) of ``scene.loads`` on this model's mesh and element, without
        assembling the stiffness (a model re-used with new loads): :func:`load_vector`."""
        return load_vector(scene, self.grid, self.element, self.cell_dofs, self.n_full)

    def interpolation(self, x, y, dx: int = 0, dy: int = 0) -> sp.csr_matrix:
        """(npts, n_full) sparse operator: the derivative ∂^(dx+dy) w / ∂x^dx ∂y^dy at points,
        from the full dofs (a SceneError for a point off the plate): :func:`interpolation`."""
        return interpolation(self.grid, self.element, self.cell_dofs, self.n_full, x, y, dx, dy)

    def bed_areas(self) -> np.ndarray:
        """(n_nodes,) each node's tributary area of the scene's tensionless bed (its region, the
        whole plate without one), by the mesh's rule (``mesh.tributary_areas``); for a half-space
        the areas its nodes press the soil over (:func:`plateqp.model.soil.halfspace_areas`)."""
        fnd = self.scene.foundation
        if fnd.model == "halfspace":
            return halfspace_areas(self.grid, fnd.region)
        return self.grid.tributary_areas(fnd.region)

    def rigid_modes(self) -> np.ndarray:
        """(n, k) basis of the rigid motions the two-sided supports leave free (k = 0..3 per
        piece; n = K's size: the soil's unknowns, if any, do not move in them):
        :func:`plateqp.model.constraints.rigid_modes`."""
        modes = rigid_modes(self)
        return np.vstack([modes, np.zeros((self.n_soil, modes.shape[1]))]) if self.n_soil else modes

    @property
    def dof_orders(self) -> np.ndarray:
        """(n,) each unknown of K's derivative order: 0 a deflection (the soil's unknowns
        too), 1 a slope, 2 a twist."""
        orders = np.array([dx + dy for dx, dy in self.element.node_dofs])
        return np.concatenate([orders[self.free % self.element.ndof_node], np.zeros(self.n_soil, dtype=orders.dtype)])


def interpolation(mesh, element, cell_dofs: np.ndarray, n_full: int, x, y, dx: int = 0, dy: int = 0) -> sp.csr_matrix:
    """(npts, n_full) sparse operator, from the full dofs, at points (x, y): ∂^(dx+dy) w / ∂x^dx ∂y^dy
    by the element's basis in the cell the mesh locates each point in (on a cell boundary: one
    neighbour's), on any mesh (``mesh.locate``, ``mesh.cells``, ``mesh.nodes``) and element
    (``element.basis``). A point off the plate, or a derivative of order above 2, is a SceneError."""
    if dx + dy > 2:
        raise SceneError(f"derivatives of w of order {dx + dy} > 2 do not exist in a plate element")
    x = np.atleast_1d(np.asarray(x, dtype=float))
    y = np.atleast_1d(np.asarray(y, dtype=float))
    cell, local = mesh.locate(x, y)
    if np.any(cell < 0):
        bad = np.flatnonzero(cell < 0)[0]
        raise SceneError(f"point ({x[bad]}, {y[bad]}) is not on the plate")
    N = element.basis(mesh.nodes[mesh.cells[cell]], local, dx, dy)
    rows = np.repeat(np.arange(len(cell)), N.shape[1])
    A = sp.csr_matrix((N.ravel(), (rows, cell_dofs[cell].ravel())), shape=(len(cell), n_full))
    A.eliminate_zeros()
    return A


def load_vector(scene: Scene, mesh, element, cell_dofs: np.ndarray, n_full: int) -> np.ndarray:
    """The load vector (all ``n_full`` dofs) of ``scene.loads`` on any mesh and element: a uniform
    pressure by the element's load of each cell (``element.cell_load``), a patch (a box, a polygon
    or a circle) by the element's integral over each cell's part in it (``element.region_load``),
    a point load by the interpolation at its point (:func:`interpolation`)."""
    f = np.zeros(n_full)
    xy = mesh.nodes[mesh.cells] if any(not isinstance(ld, PointLoad) for ld in scene.loads) else None
    for ld in scene.loads:
        if isinstance(ld, UniformLoad):
            f += np.bincount(cell_dofs.ravel(), weights=(ld.q * element.cell_load(xy)).ravel(), minlength=n_full)
        elif isinstance(ld, PatchLoad):
            hit, fe = element.region_load(xy, ld.extent)
            np.add.at(f, cell_dofs[hit], ld.q * fe)
        elif isinstance(ld, PointLoad):
            f += ld.P * interpolation(mesh, element, cell_dofs, n_full, ld.x, ld.y).toarray().ravel()
    return f


def build_model(scene: Scene, soil_operator: bool | None = None) -> Model:
    """Mesh a scene (after :func:`check_memory`: a mesh too large for the machine is refused
    before any allocation) and assemble its stiffness on the free dofs (``mesh.assemble``), its
    loads (:func:`load_vector`), its two-sided supports (:func:`plateqp.model.constraints.prescribed`)
    and its contact operator; the same steps on every mesh. ``soil_operator``: a half-space bed
    held matrix-free (True: wherever the mesh offers the operator; False: never; None: above
    :data:`plateqp.model.soil.HALFSPACE_OPERATOR_FROM` bed nodes)."""
    check_memory(scene)
    mesh = mesh_generator(scene).from_scene(scene)
    el = ELEMENTS[scene.mesh.element]()
    nd = el.ndof_node
    D, nu = scene.plate.D, scene.plate.nu
    n_full = mesh.n_nodes * nd
    cell_dofs = (mesh.plate_node_ids[mesh.cells][:, :, None] * nd + np.arange(nd)).reshape(len(mesh.cells), -1)
    f_full = load_vector(scene, mesh, el, cell_dofs, n_full)
    fixed, values = prescribed(scene, mesh, el)
    is_free = np.zeros(n_full, dtype=bool)
    is_free[(mesh.plate_node_ids[:, None] * nd + np.arange(nd)).ravel()] = True
    is_free[fixed] = False
    free = np.flatnonzero(is_free)
    pos = np.full(n_full, -1)
    pos[free] = np.arange(free.size)
    K = mesh.assemble(el, D, nu, pos, free.size)

    def K_full():  # every dof (off-plate rows empty): assembled on first use, not kept meanwhile
        return mesh.assemble(el, D, nu, np.arange(n_full), n_full)

    f = f_full[free]  # (a copy)
    if np.any(values != 0):  # the prescribed values' loads on the free dofs
        u_c = np.zeros(n_full)
        u_c[fixed] = values
        K_full = K_full()
        f -= (K_full @ u_c)[free]
    model = Model(scene, mesh, el, K, f, free, fixed, values, n_full, cell_dofs, mesh.cell_ids, f_full, K_full,
                  symmetric=mesh.symmetric_assembly)
    model.contacts = _contacts(scene, model)
    if couples(scene.foundation):
        c = model.contacts
        rows = np.flatnonzero(c.source == "bed")
        H = halfspace_operator(model, c.index[rows], soil_operator)
        if H is not None:
            attach_operator(model, rows, c.index[rows], H)
        else:
            attach(model, rows, c.index[rows], model.bed_areas()[c.index[rows]])
    return model


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
        rho.append(np.zeros(len(nodes)) if couples(fnd) else 1.0 / (fnd.k * area[nodes]))  # coupled: soil dofs
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
