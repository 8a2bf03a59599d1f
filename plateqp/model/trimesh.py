"""Unstructured triangle meshes of shaped plates, made with gmsh (imported lazily).

:func:`mesh_domain` meshes a :class:`~plateqp.model.geometry.Domain` with gmsh's Python API (the
``shapes`` extra: ``pip install plateqp[shapes]``): target size h, circles as true arcs (boundary
nodes lie on the circle), given points (supports, point loads, pins) embedded as mesh nodes with
the mesh refined around them (size h/4 at the point, growing to h at 2h away), and given line
segments (a bed region's outline) followed by element edges: the boundary curves are split where
such a line ends on them, so that the line's end is a point of the boundary. A mesh of
:data:`~plateqp.model.gmsh_mesh.SPLIT_FROM` nodes or more is the mesh at 2h with every triangle
split in four (:data:`~plateqp.model.gmsh_mesh.SPLITS`); the meshes of the last few geometries are
kept (:data:`MESHES`, :mod:`plateqp.model.mesh_cache`).

The mesh is deterministic: gmsh runs on one thread with fixed options (Frontal-Delaunay without
Laplacian smoothing, no random factor changes, no configuration files read), so the same scene gives the same mesh. gmsh
is initialised and finalised around every call (a session the caller opened is left open, and
only the model made here is removed), and never prints (``General.Terminal = 0``).

:class:`TriMesh` is the mesh: nodes, counter-clockwise triangles, boundary edges with their
outward unit normals and the boundary/segment each belongs to (see :mod:`plateqp.model.geometry`).
It has the names the contact code reads from a grid (``node_xy``, ``hx``, ``hy``, ``a``, ``b``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..errors import SceneError
from .blocks import block_pattern
from .geometry import Domain, inner_segments
from .gmsh_mesh import NODES_PER_AREA, REFINE  # noqa: F401 - REFINE: the refinement around embedded points, read by tests and docs
from .gmsh_mesh import gmsh_options
from .gmsh_mesh import mesh_domain as _gmsh_mesh_domain
from .mesh_cache import MeshCache, mesh_key
from .regions import lumped_region, region_outline
from .symmetry import mirror_lines


def estimate_nodes(scene) -> float:
    """About how many nodes a triangle-meshed scene's mesh has (:data:`NODES_PER_AREA` area / h²)."""
    from .geometry import mesh_size, scene_domain

    return NODES_PER_AREA * scene_domain(scene).area / mesh_size(scene) ** 2


@dataclass
class TriMesh:
    """A triangle mesh of a plate.

    Attributes
    ----------
    nodes : (n, 2) coordinates
    triangles : (nt, 3) node indices, counter-clockwise
    edges : (ne, 2) boundary edges (node pairs, in the direction of their boundary's curve)
    normals : (ne, 2) outward unit normal of each boundary edge
    boundary : (ne,) which boundary: 0 outer, k ≥ 1 hole k − 1
    segment : (ne,) which segment of a polygon boundary (0 for a circle)
    size : the target element size h
    domain : the meshed :class:`~plateqp.model.geometry.Domain`
    """

    nodes: np.ndarray
    triangles: np.ndarray
    edges: np.ndarray
    normals: np.ndarray
    boundary: np.ndarray
    segment: np.ndarray
    size: float
    domain: Domain
    _tree: object = field(default=None, repr=False, compare=False)
    #: the assembly's scatter patterns, [(pos, pattern)] (:meth:`assemble`): the last two kept
    _patterns: list = field(default_factory=list, repr=False, compare=False)

    # -- the mesh as every generator gives it (plateqp.model.grid.Grid has the same names) ---------
    cell_type = "triangle"
    #: an unstructured mesh has no grid view
    grid_shape = None

    @property
    def cells(self) -> np.ndarray:
        """(nt, 3) the triangles (indices into :attr:`nodes`)."""
        return self.triangles

    @property
    def plate_node_ids(self) -> np.ndarray:
        """(n,) every node is on the plate, and node k's dofs are ``k · ndof_node + i``."""
        return np.arange(self.n_nodes)

    def triangulation(self) -> np.ndarray:
        """(nt, 3) the triangles, for drawing."""
        return self.triangles

    def boundary_edges(self):
        """(edges, outward normals, boundary, segment) of the plate's boundary, as every mesh
        gives them (:meth:`plateqp.model.grid.Grid.boundary_edges`)."""
        return self.edges, self.normals, self.boundary, self.segment

    # -- the generator's side of building a model (plateqp.model.assembly.build_model) ----------------
    #: the assembled stiffness is symmetric value for value (:meth:`assemble`: summed by node blocks)
    symmetric_assembly = True
    estimate_nodes = staticmethod(lambda scene: estimate_nodes(scene))

    @classmethod
    def from_scene(cls, scene) -> TriMesh:
        """The scene's plate meshed by gmsh at its element size, with a node at every support,
        point load and pin, and the bed region's outline drawn into the mesh (:func:`mesh_domain`)."""
        from .geometry import mesh_size, scene_domain

        domain = scene_domain(scene)
        points = [(s.x, s.y) for s in scene.supports] + [(ld.x, ld.y) for ld in scene.loads
                                                         if ld.type == "point"] + [(p.x, p.y) for p in scene.pins]
        lines = [] if scene.foundation is None or scene.foundation.region is None else inner_segments(
            domain, region_outline(scene.foundation.region, mesh_size(scene)))
        mirrors = mirror_lines(domain, scene.mesh.symmetry) if scene.mesh.symmetry else ()
        return mesh_domain(domain, mesh_size(scene), points, lines, mirrors)

    # the meshes of a refinement ladder, counted in cells a side (plateqp.studies.refinement)
    @staticmethod
    def cells_a_side(scene) -> tuple[int, int]:
        """(n, n), n = L / h rounded, L the plate's larger bounding-box side and h the element
        size (halving h doubles n)."""
        from .geometry import mesh_size, scene_domain

        n = max(1, round(scene_domain(scene).size / mesh_size(scene)))
        return n, n

    @staticmethod
    def set_cells(scene, nx: int, ny: int) -> None:
        """Make ``scene`` (a copy) a mesh of element size h = L / nx (``mesh.nx`` and ``mesh.ny``
        then say nx)."""
        from .geometry import scene_domain

        scene.mesh.size = scene_domain(scene).size / int(nx)
        scene.mesh.nx = scene.mesh.ny = int(nx)

    @staticmethod
    def start_cells(scene, cells: int) -> tuple[int, int]:
        """(cells, cells): element size L / cells."""
        return cells, cells

    #: a node stands at every point load (:meth:`from_scene`): a moved load is a new mesh
    points_are_nodes = True

    @staticmethod
    def size_note(scene) -> str:
        """Words after a refinement ladder's "n x n": the element size."""
        return f" (element size {scene.mesh.size:g})"

    def summary(self, element: str) -> dict:
        """The mesh in numbers, for a file's metadata: element, size, nodes and triangles."""
        return {"element": element, "size": float(self.size), "nodes": self.n_nodes,
                "triangles": int(len(self.triangles))}

    def summary_text(self, element: str, units: str = "") -> str:
        """The mesh in words, for a report (``units``: of length)."""
        return (f"mesh: {len(self.triangles)} triangles, {self.n_nodes} nodes, size {self.size:g} {units}, "
                f"{element.upper()}")

    @property
    def bbox(self) -> tuple[float, float, float, float]:
        """(x0, x1, y0, y1) of the plate: its outer boundary's box."""
        x0, x1, y0, y1 = self.domain.outer.bbox
        return x0, x1, y0, y1

    def grid_view(self, values: np.ndarray) -> None:
        """None: a triangle mesh has no grid view of its nodal fields."""

    @staticmethod
    def describe(scene) -> tuple[str, str, str]:
        """(field, the mesh in words, what makes it smaller) for a message about its size."""
        from .geometry import mesh_size

        return "mesh.size", f"triangle mesh of size {mesh_size(scene):g}", "use a larger mesh.size"

    @property
    def cell_ids(self) -> np.ndarray:
        """(nt,) every triangle is a cell of the plate."""
        return np.arange(len(self.triangles))

    def assemble(self, element, D: float, nu: float, pos: np.ndarray, ncol: int) -> sp.csr_matrix:
        """The stiffness on the dofs with ``pos`` ≥ 0 (``pos``: each dof's new index, increasing;
        ``ncol`` of them), in canonical CSR, exactly symmetric: the element matrices of every
        triangle (``element.cell_stiffness``, batched) summed by node blocks through the mesh's
        scatter pattern for ``pos`` (:func:`plateqp.model.blocks.block_pattern`, worked out on
        the first assembly and kept with the mesh for the next)."""
        Ke = element.cell_stiffness(self.nodes[self.triangles], D, nu)
        pattern = next((pat for p, pat in self._patterns if p.shape == pos.shape and np.array_equal(p, pos)), None)
        if pattern is None or pattern.n != ncol:
            pattern = block_pattern(self.triangles, len(self.nodes), Ke.shape[1] // 3, pos, ncol)
            self._patterns[:] = [*self._patterns[-1:], (pos.copy(), pattern)]
        return pattern.assemble(Ke)

    def tributary_areas(self, region) -> np.ndarray:
        """(n_nodes,) each node's tributary area of a bed on ``region`` (a box [x0, x1, y0, y1], a
        polygon or a circle; None: the whole plate): a third of every triangle, or of each triangle's
        part in the region, weighted as a patch load is (:func:`plateqp.model.regions.lumped_region`).
        The region's outline is a line of the mesh (:meth:`from_scene`; a circle's inscribed polygon),
        so a box or a polygon is a union of whole triangles; the areas sum to the region's area on
        the plate exactly (a circle's to rounding)."""
        if region is None:
            return np.bincount(self.triangles.ravel(), weights=np.repeat(self.areas() / 3, 3), minlength=self.n_nodes)
        hit, weights = lumped_region(self.nodes[self.triangles], region)
        area = np.bincount(self.triangles[hit].ravel(), weights=weights.ravel(), minlength=self.n_nodes)
        if not area.any():
            raise SceneError(f"foundation.region: {region} does not overlap the plate's mesh")
        return area

    def halfspace_flexibility_operator(self, region, E: float, nu: float, nodes) -> None:
        """None: a triangle mesh has no matrix-free half-space flexibility (the dense route,
        :func:`plateqp.model.soil.halfspace_flexibility`, holds it)."""

    # -- the names the contact code reads from a grid ------------------------------------
    @property
    def n_nodes(self) -> int:
        return self.nodes.shape[0]

    @property
    def hx(self) -> float:
        return self.size

    @property
    def hy(self) -> float:
        return self.size

    @property
    def a(self) -> float:
        x0, x1, _, _ = self.domain.outer.bbox
        return x1 - x0

    @property
    def b(self) -> float:
        _, _, y0, y1 = self.domain.outer.bbox
        return y1 - y0

    def node_xy(self) -> np.ndarray:
        return self.nodes

    # -- queries ------------------------------------------------------------------------
    def areas(self) -> np.ndarray:
        p = self.nodes[self.triangles]
        return 0.5 * ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                      - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))

    def nearest_other(self, pts: np.ndarray, m: int, reach: float) -> None:
        """None: a triangle mesh's nodes are no lattice (:meth:`plateqp.model.grid.Grid.nearest_other`;
        a tree searches them)."""

    def node_at(self, x: float, y: float, rtol: float = 1e-6) -> int | None:
        """The node at (x, y) (within rtol·h), or None."""
        d = np.hypot(self.nodes[:, 0] - x, self.nodes[:, 1] - y)
        k = int(np.argmin(d))
        return k if d[k] <= rtol * self.size else None

    def locate(self, x, y):
        """Triangle index and barycentric coordinates (npts, 3) of points; −1 off the mesh."""
        from scipy.spatial import cKDTree

        x = np.atleast_1d(np.asarray(x, dtype=float))
        y = np.atleast_1d(np.asarray(y, dtype=float))
        p = self.nodes[self.triangles]
        if self._tree is None:
            self._tree = cKDTree(p.mean(axis=1))
        k = min(16, len(self.triangles))
        finite = np.isfinite(x) & np.isfinite(y)  # a non-finite point is off the mesh (the tree refuses it)
        _, cand = self._tree.query(np.column_stack([np.where(finite, x, 0.0), np.where(finite, y, 0.0)]), k=k)
        cand = cand.reshape(len(x), k)
        tri = np.full(len(x), -1)
        lam = np.zeros((len(x), 3))
        best = np.full(len(x), -np.inf)
        with np.errstate(over="ignore", invalid="ignore"):  # a point near the largest double: off the mesh
            for c in range(k):
                t = np.minimum(cand[:, c], len(self.triangles) - 1)  # the tree's "none" (a far point's inf)
                l_ = _barycentric(p[t], x, y)
                worst = l_.min(axis=1)
                better = worst > best
                tri = np.where(better, t, tri)
                lam = np.where(better[:, None], l_, lam)
                best = np.maximum(best, worst)
        tri = np.where((best >= -1e-9) & finite, tri, -1)
        lam = np.where(tri[:, None] >= 0, np.clip(np.nan_to_num(lam), 0.0, 1.0), 1.0 / 3.0)
        return tri, lam / lam.sum(axis=1, keepdims=True)

    # -- what the scene's checks, the figures and the tables ask of every mesh (Grid too) -------
    @staticmethod
    def check_scene_fields(scene) -> None:
        """The scene-language rules of triangles: every shape and element size meshes."""

    @staticmethod
    def cover(scene):
        """What the point checks ask of the plate: its region (:func:`.geometry.validate_shaped`)."""
        from .geometry import validate_shaped
        return validate_shaped(scene)

    #: whether ``edges.all`` held the cut-outs' edges before: yes on triangles (a warning says so)
    all_held_holes = True
    #: the demo's studies not yet run on this mesh, (name, why) pairs
    not_yet_studied = (("convergence", ("the convergence study halves the structured grid (nx × ny); it does not "
                                        "yet refine a triangle mesh (mesh.size)")),
                       ("comparison", ("the paper's statements (zones, sections 2 and 4, σ1 on a ring around the "
                                       "load) are measured on the structured grid's nodes; not yet on a triangle mesh")))

    def caption(self, element: str) -> str:
        """The mesh in a figure's caption: "triangle mesh (size h, ELEMENT)"."""
        return f"triangle mesh (size {self.size:g}, {element.upper()})"

    def outline_paths(self) -> list[tuple[str, np.ndarray, bool]]:
        """The outline to draw, [(gid, points, closed)]: the outer boundary ("outline") and each
        hole ("hole") as a closed loop of boundary nodes (:func:`.views.boundary_loops`)."""
        from .views import boundary_loops
        return [("outline" if k == 0 else "hole", pts, True) for k, pts in boundary_loops(self)]

    def contour_position(self, xy: np.ndarray) -> tuple[np.ndarray, bool]:
        """(zeros, False): a shaped plate's points are not placed along a rectangle's contour."""
        return np.zeros(len(xy)), False

    def default_sections(self, scene) -> list:
        """Section lines cut to the plate (:func:`plateqp.model.views.cut_sections`)."""
        from .views import cut_sections
        return cut_sections(self, scene)

    def field_layout(self, fields: dict, nodes: bool = False) -> tuple:
        """(dims, coords, fields) of nodal fields in a dataset: one value per node (no grid view)."""
        from .views import node_layout
        return node_layout(self, fields)

    @staticmethod
    def plan_view(structured, shaped):
        """Of a figure's two plan views, the one that draws this mesh: ``shaped``."""
        return shaped


def _barycentric(p, x, y):
    (x1, y1), (x2, y2), (x3, y3) = p[:, 0].T, p[:, 1].T, p[:, 2].T
    det = (x2 - x1) * (y3 - y1) - (x3 - x1) * (y2 - y1)
    l2 = ((x - x1) * (y3 - y1) - (x3 - x1) * (y - y1)) / det
    l3 = ((x2 - x1) * (y - y1) - (x - x1) * (y2 - y1)) / det
    return np.column_stack([1.0 - l2 - l3, l2, l3])


#: the meshes of the last few geometries (:mod:`plateqp.model.mesh_cache`): a sweep or a study that
#: solves one plate again meshes it once; ``MESHES.clear()`` empties it, ``MESHES.size = 0`` turns it off
MESHES = MeshCache(3)


def mesh_domain(domain: Domain, size: float, points=(), lines=(), mirrors=()) -> TriMesh:
    """Mesh ``domain`` with gmsh at target size ``size`` (:func:`plateqp.model.gmsh_mesh.mesh_domain`:
    ``points`` become nodes, ``lines`` run along element edges, ``mirrors`` make it symmetric), or
    the mesh of the same exact geometry made before (:data:`MESHES`)."""
    key = mesh_key(domain, size, points, lines, mirrors, gmsh_options())
    return MESHES.get(key, lambda: TriMesh(*_gmsh_mesh_domain(domain, size, points, lines, mirrors)))
