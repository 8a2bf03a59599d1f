"""Unstructured triangle meshes of shaped plates, made with gmsh (imported lazily).

:func:`mesh_domain` meshes a :class:`~plateqp.model.geometry.Domain` with gmsh's Python API (the
``shapes`` extra: ``pip install plateqp[shapes]``): target size h, circles as true arcs (boundary
nodes lie on the circle), given points (supports, point loads, pins) embedded as mesh nodes with
the mesh refined around them (size h/4 at the point, growing to h at 2h away), and given line
segments (a bed region's outline) followed by element edges: the boundary curves are split where
such a line ends on them, so that the line's end is a point of the boundary.

The mesh is deterministic: gmsh runs on one thread with fixed options (Frontal-Delaunay, no
random factor changes, no configuration files read), so the same scene gives the same mesh. gmsh
is initialised and finalised around every call (a session the caller opened is left open, and
only the model made here is removed), and never prints (``General.Terminal = 0``).

:class:`TriMesh` is the mesh: nodes, counter-clockwise triangles, boundary edges with their
outward unit normals and the boundary/segment each belongs to (see :mod:`plateqp.model.geometry`).
It has the names the contact code reads from a grid (``node_xy``, ``hx``, ``hy``, ``a``, ``b``).
"""

from __future__ import annotations

import itertools
import math
import threading
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..errors import SceneError
from .geometry import Domain, Polygon, _point_segment, inner_segments, lumped_region, region_outline

#: refinement around embedded points: size REFINE·h at the point, h from 2h away
REFINE = 0.25
#: nodes of a mesh per area / h², about (measured: 1.09 on the unit disc at h = 1/16)
NODES_PER_AREA = 1.2
_model_names = itertools.count()


def estimate_nodes(scene) -> float:
    """About how many nodes a triangle-meshed scene's mesh has (:data:`NODES_PER_AREA` area / h²)."""
    from .geometry import mesh_size, scene_domain

    return NODES_PER_AREA * scene_domain(scene).area / mesh_size(scene) ** 2


def import_gmsh():
    """gmsh's module, or a one-line SceneError saying how to install it."""
    try:
        import gmsh
    except ImportError:  # pragma: no cover - depends on the environment
        raise SceneError("a plate with a shape (or mesh.element = \"dkt\") needs gmsh: "
                         "pip install 'plateqp[shapes]' (or pip install gmsh)") from None
    return gmsh


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
    #: the summed element matrices are symmetric to rounding, not value for value
    symmetric_assembly = False
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
            domain, region_outline(scene.foundation.region))
        return mesh_domain(domain, mesh_size(scene), points, lines)

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
        """The stiffness on the dofs with ``pos`` ≥ 0 (``pos``: each dof's new index; ``ncol`` of
        them), in CSR: the element matrices of every triangle (``element.cell_stiffness``, batched)
        summed."""
        nd = element.ndof_node
        Ke = element.cell_stiffness(self.nodes[self.triangles], D, nu)
        dofs = pos[(self.triangles[:, :, None] * nd + np.arange(nd)).reshape(len(self.triangles), -1)]
        rows = np.repeat(dofs, dofs.shape[1], axis=1).ravel()
        cols = np.tile(dofs, (1, dofs.shape[1])).ravel()
        keep = (rows >= 0) & (cols >= 0)
        K = sp.csr_matrix((Ke.ravel()[keep], (rows[keep], cols[keep])), shape=(ncol, ncol))
        K.sum_duplicates()
        return K

    def tributary_areas(self, region) -> np.ndarray:
        """(n_nodes,) each node's tributary area of a bed on ``region`` (a box [x0, x1, y0, y1] or a
        polygon region; None: the whole plate): a third of every triangle, or of each triangle's
        part in the region, weighted as a patch load is (:func:`plateqp.model.geometry.lumped_region`).
        The region's outline is a line of the mesh (:meth:`from_scene`), so the region is a union
        of whole triangles and the areas sum to its area on the plate exactly."""
        if region is None:
            return np.bincount(self.triangles.ravel(), weights=np.repeat(self.areas() / 3, 3), minlength=self.n_nodes)
        hit, weights = lumped_region(self.nodes[self.triangles], region)
        area = np.bincount(self.triangles[hit].ravel(), weights=weights.ravel(), minlength=self.n_nodes)
        if not area.any():
            raise SceneError(f"foundation.region: {region} does not overlap the plate's mesh")
        return area

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


def mesh_domain(domain: Domain, size: float, points=(), lines=()) -> TriMesh:
    """Mesh ``domain`` with gmsh at target size ``size``; every point of ``points`` becomes a node,
    every segment of ``lines`` ((x0, y0), (x1, y1)) runs along element edges.

    Points on the boundary are embedded in its curve, points inside in the surface (or in a line
    they lie on); a point at a polygon vertex is that vertex. Duplicates are merged. A line must
    lie inside the plate (:func:`plateqp.model.geometry.inner_segments`); its ends may touch the boundary.
    """
    with _GMSH_LOCK:  # gmsh is one global session: one mesh at a time (threaded executors)
        return _mesh_domain(domain, size, points, lines)


#: gmsh keeps one global session and model list: two threads meshing at once would clash.
_GMSH_LOCK = threading.RLock()


def _mesh_domain(domain: Domain, size: float, points=(), lines=()) -> TriMesh:
    gmsh = import_gmsh()
    owner = not gmsh.isInitialized()
    if owner:
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    name = f"plateqp-{next(_model_names)}"
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.option.setNumber("Mesh.MaxNumThreads2D", 1)
        gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay
        gmsh.option.setNumber("Mesh.RandomFactor", 1e-9)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.ElementOrder", 1)
        gmsh.model.add(name)
        try:
            return _mesh(gmsh, domain, float(size), points, lines)
        except Exception as exn:  # gmsh raises plain Exceptions with its own message
            raise SceneError(f"mesh: gmsh could not mesh the plate at size {size:g} ({str(exn).splitlines()[0]})") from exn
    finally:
        if owner:
            gmsh.finalize()
        else:  # pragma: no cover - a session the caller opened
            gmsh.model.setCurrent(name)
            gmsh.model.remove()


def _mesh(gmsh, domain: Domain, h: float, points, lines=()) -> TriMesh:
    """The steps of :func:`mesh_domain` inside one gmsh model: the boundary curves, the embedded
    points and lines, the size field, the mesh, and the mesh read back."""
    tol = 1e-9 * domain.size
    curves = _boundary_curves(gmsh.model.geo, domain, lines, tol)
    surf = gmsh.model.geo.addPlaneSurface(curves.loops)
    gmsh.model.geo.synchronize()
    embedded = _embed(gmsh, surf, domain, curves, points, lines, tol)
    _size_field(gmsh, h, [t for t, _ in embedded])
    gmsh.model.mesh.generate(2)
    return _read_mesh(gmsh, surf, curves.owner, h, domain)


@dataclass
class _Curves:
    """The gmsh curves of a domain's boundaries: ``owner`` curve tag → (boundary, segment),
    ``geom`` curve tag → ("seg", p, q) or ("arc", a0, a1) (for :func:`_curve_at`), ``of`` the tags
    of each boundary, ``vertices`` [(x, y, point tag)], ``loops`` one curve loop a boundary."""

    owner: dict
    geom: dict
    of: list
    vertices: list
    loops: list


def _boundary_curves(geo, domain: Domain, lines, tol: float) -> _Curves:
    """One gmsh curve per polygon segment (split where a line of ``lines`` ends on it: a line must
    end at a point of the boundary's own curves to be meshed conformingly), a circle as arcs (split
    at the quarter points and where a line ends on it)."""
    c = _Curves({}, {}, [], [], [])
    ends = [e for seg in lines for e in seg]
    for k, shape in enumerate((domain.outer, *domain.holes)):
        on = [e for e in ends if shape.distance(*e)[0] <= tol]
        tags = []
        if isinstance(shape, Polygon):
            verts = []
            for i, (p0, p1) in enumerate(shape.segments()):
                d = p1 - p0
                cut = sorted({float((np.array(e) - p0) @ d / (d @ d)) for e in on
                              if float(_point_segment(e[0], e[1], (p0, p1))) <= tol})
                verts += [(tuple(p0), i)] + [(tuple(p0 + t * d), i) for t in cut if tol < t * np.hypot(*d) < np.hypot(*d) - tol]
            pts = [geo.addPoint(x, y, 0.0) for (x, y), _ in verts]
            c.vertices += [(x, y, t) for ((x, y), _), t in zip(verts, pts)]
            for n, ((xy, i), t) in enumerate(zip(verts, pts)):
                nxt = (n + 1) % len(pts)
                tag = geo.addLine(t, pts[nxt])
                c.owner[tag] = (k, i)
                c.geom[tag] = ("seg", np.array(xy), np.array(verts[nxt][0]))
                tags.append(tag)
        else:
            centre = geo.addPoint(shape.xc, shape.yc, 0.0)
            angles = sorted({0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi,
                             *(math.atan2(y - shape.yc, x - shape.xc) % (2 * math.pi) for x, y in on)})
            angles = [a_ for n, a_ in enumerate(angles) if n == 0 or a_ - angles[n - 1] > tol / shape.r]
            xy = [(shape.xc + shape.r * math.cos(t), shape.yc + shape.r * math.sin(t)) for t in angles]
            pts = [geo.addPoint(x, y, 0.0) for x, y in xy]
            c.vertices += [(x, y, t) for (x, y), t in zip(xy, pts)]
            for i in range(len(pts)):
                tag = geo.addCircleArc(pts[i], centre, pts[(i + 1) % len(pts)])
                c.owner[tag] = (k, 0)
                c.geom[tag] = ("arc", angles[i], angles[i + 1] if i + 1 < len(angles) else 2 * math.pi)
                tags.append(tag)
        c.of.append(tags)
        c.loops.append(geo.addCurveLoop(tags))
    return c


def _embed(gmsh, surf: int, domain: Domain, curves: _Curves, points, lines, tol: float) -> list:
    """Embed ``lines`` in the surface and every point of ``points`` (not already a boundary
    vertex or a line's end) in the curve it lies on, a line, or the surface. Returns the embedded
    points [(tag, curve or None)]."""
    geo = gmsh.model.geo
    embedded, seen = [], []
    line_tags, line_ends = _lines(geo, curves.vertices, lines, tol)
    for x, y in points:
        if any(math.hypot(x - u, y - v) <= tol for u, v in seen):
            continue
        seen.append((x, y))
        if any(math.hypot(x - u, y - v) <= tol for u, v, _ in curves.vertices + line_ends):
            continue
        on = _curve_at(domain, curves.of, curves.geom, x, y, tol)
        if on is None:  # on an embedded line: a point of that line
            on = next((c for c, (p, q) in line_tags if float(_point_segment(x, y, (p, q))) <= tol), None)
        # built-in kernel: new points after synchronize need another synchronize before embedding
        t = geo.addPoint(x, y, 0.0)
        embedded.append((t, on))
    geo.synchronize()
    if line_tags:
        gmsh.model.mesh.embed(1, [c for c, _ in line_tags], 2, surf)
    for t, on in embedded:
        if on is None:
            gmsh.model.mesh.embed(0, [t], 2, surf)
        else:
            gmsh.model.mesh.embed(0, [t], 1, on)
    return embedded


def _size_field(gmsh, h: float, refined: list) -> None:
    """The mesh size: h everywhere, :data:`REFINE` · h at the points ``refined`` (tags), growing
    to h at 2h away."""
    field = gmsh.model.mesh.field
    f_const = field.add("MathEval")
    field.setString(f_const, "F", repr(h))
    fields = [f_const]
    if refined:
        f_dist = field.add("Distance")
        field.setNumbers(f_dist, "PointsList", refined)
        f_thr = field.add("Threshold")
        field.setNumber(f_thr, "InField", f_dist)
        field.setNumber(f_thr, "SizeMin", REFINE * h)
        field.setNumber(f_thr, "SizeMax", h)
        field.setNumber(f_thr, "DistMin", 0.0)
        field.setNumber(f_thr, "DistMax", 2.0 * h)
        fields.append(f_thr)
    f_min = field.add("Min")
    field.setNumbers(f_min, "FieldsList", fields)
    field.setAsBackgroundMesh(f_min)


def _read_mesh(gmsh, surf: int, curve_owner: dict, h: float, domain: Domain) -> TriMesh:
    """The generated mesh as a :class:`TriMesh`: the nodes of its triangles numbered from 0,
    triangles turned counter-clockwise, boundary edges by curve with their outward normals."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    index = np.full(int(tags.max()) + 1, -1)
    xyz = coords.reshape(-1, 3)
    _, tri_nodes = gmsh.model.mesh.getElementsByType(2, surf)
    tri_tags = tri_nodes.astype(np.int64).reshape(-1, 3)
    used = np.unique(tri_tags)
    index[used] = np.arange(len(used))
    pos = np.full(int(tags.max()) + 1, -1)
    pos[tags.astype(np.int64)] = np.arange(len(tags))
    nodes = xyz[pos[used], :2].copy()
    tris = index[tri_tags]
    p = nodes[tris]
    signed = ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
              - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    tris[signed < 0] = tris[signed < 0][:, [0, 2, 1]]

    edges, boundary, segment = [], [], []
    for c, (k, i) in sorted(curve_owner.items()):
        _, en = gmsh.model.mesh.getElementsByType(1, c)
        e = index[en.astype(np.int64).reshape(-1, 2)]
        edges.append(e)
        boundary += [k] * len(e)
        segment += [i] * len(e)
    edges = np.vstack(edges)
    normals = _outward_normals(nodes, tris, edges)
    return TriMesh(nodes, tris, edges, normals, np.array(boundary), np.array(segment), h, domain)


def _lines(geo, vertex_tags, lines, tol: float):
    """gmsh lines for the segments ``lines``: [(tag, (p, q))], and their new end points [(x, y, tag)].
    Ends shared by two segments or at a boundary curve's point (the boundary was split there)
    are one gmsh point."""
    ends: list[tuple[float, float, int]] = []
    out = []

    def point(x, y):
        for u, v, t in vertex_tags + ends:
            if math.hypot(x - u, y - v) <= tol:
                return t
        t = geo.addPoint(x, y, 0.0)
        ends.append((x, y, t))
        return t

    for p, q in lines:
        a, b = point(*p), point(*q)
        if a != b:
            out.append((geo.addLine(a, b), (p, q)))
    return out, ends


def _curve_at(domain: Domain, curves_of, curve_geom, x: float, y: float, tol: float):
    """The gmsh curve tag a point on the boundary lies on, or None for an interior point."""
    for k, shape in enumerate((domain.outer, *domain.holes)):
        if shape.distance(x, y)[0] > tol:
            continue
        best, where = None, math.inf
        for c in curves_of[k]:
            g = curve_geom[c]
            if g[0] == "seg":
                d = float(_point_segment(x, y, (g[1], g[2])))
            else:
                ang = math.atan2(y - shape.yc, x - shape.xc) % (2 * math.pi)
                d = 0.0 if g[1] <= ang <= g[2] else math.inf
            if d < where:
                best, where = c, d
        return best
    return None


def _outward_normals(nodes, tris, edges) -> np.ndarray:
    """Unit normals of boundary edges, pointing away from the triangle that holds each edge."""
    n = len(nodes)
    ends = [(0, 1, 2), (1, 2, 0), (2, 0, 1)]  # each triangle edge (a, b) and its third vertex
    a = np.concatenate([tris[:, i] for i, _, _ in ends])
    b = np.concatenate([tris[:, j] for _, j, _ in ends])
    opp = np.concatenate([tris[:, k] for _, _, k in ends])
    key = np.minimum(a, b).astype(np.int64) * n + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    want = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64) * n + np.maximum(edges[:, 0], edges[:, 1])
    third = opp[order[np.searchsorted(key[order], want)]]
    d = nodes[edges[:, 1]] - nodes[edges[:, 0]]
    n = np.column_stack([d[:, 1], -d[:, 0]]) / np.hypot(d[:, 0], d[:, 1])[:, None]
    inward = nodes[third] - nodes[edges[:, 0]]
    flip = np.einsum("ij,ij->i", n, inward) > 0
    n[flip] *= -1.0
    return n
