"""gmsh's part of the triangle generator: a :class:`~plateqp.model.geometry.Domain` meshed with
gmsh's Python API (imported lazily), its arrays handed to :class:`plateqp.model.trimesh.TriMesh`.

See :mod:`plateqp.model.trimesh` for what the mesh promises (true arcs, embedded points and lines,
refinement, determinism); :mod:`plateqp.model.symmetry` for a symmetric domain's part and mirror.
"""

from __future__ import annotations

import itertools
import math
import threading
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..errors import SceneError
from .geometry import Domain, Polygon, _point_segment
from .symmetry import TOL as SYMMETRY_TOL
from .symmetry import boundary_of, build_part, read_triangles, unfold

#: refinement around embedded points: size REFINE·h at the point, h from 2h away
REFINE = 0.25
#: gmsh's 2-D algorithm: 6, Frontal-Delaunay, chosen by measurement against 5 (Delaunay), 1
#: (MeshAdapt), smoothing and Shewchuk's Triangle (docs/guide/shapes.md, "Which mesher"): Delaunay
#: meshes a third faster but its clamped annulus' error is 23 % larger.
ALGORITHM = 6
#: A large mesh (about :data:`SPLIT_FROM` nodes or more) is made at 2^SPLITS times the size asked
#: and each triangle then split in four (its edges halved, the midpoints of boundary edges put on
#: the true curve) SPLITS times by gmsh's ``refine``: a quarter of the time of meshing at the size
#: asked, the same smallest angle, the same accuracy (docs/guide/shapes.md, "Which mesher").
SPLITS = 1
SPLIT_FROM = 3_000
#: nodes of a mesh per area / h², about (measured: 1.09 on the unit disc at h = 1/16)
NODES_PER_AREA = 1.2
_model_names = itertools.count()
#: What a mesh is made of: nodes (n, 2), counter-clockwise triangles (nt, 3), boundary edges
#: (ne, 2) with their outward normals (ne, 2), boundary (ne,) and segment (ne,) of each edge, the
#: target size h and the meshed domain: :class:`plateqp.model.trimesh.TriMesh`'s fields, in order.
MeshArrays = tuple


def gmsh_options() -> tuple:
    """The settings of this module that shape a mesh (part of a kept mesh's key:
    :mod:`plateqp.model.mesh_cache`)."""
    return ("gmsh", ALGORITHM, SPLITS, SPLIT_FROM, REFINE, NODES_PER_AREA)


def import_gmsh():
    """gmsh's module, or a one-line SceneError saying how to install it."""
    try:
        import gmsh
    except ImportError:  # pragma: no cover - depends on the environment
        raise SceneError("a plate with a shape (or mesh.element = \"dkt\") needs gmsh: "
                         "pip install 'plateqp[shapes]' (or pip install gmsh)") from None
    return gmsh


def mesh_domain(domain: Domain, size: float, points=(), lines=(), mirrors=()) -> MeshArrays:
    """Mesh ``domain`` with gmsh at target size ``size``; every point of ``points`` becomes a node,
    every segment of ``lines`` ((x0, y0), (x1, y1)) runs along element edges.

    Points on the boundary are embedded in its curve, points inside in the surface (or in a line
    they lie on); a point at a polygon vertex is that vertex. Duplicates are merged. A line must
    lie inside the plate (:func:`plateqp.model.geometry.inner_segments`); its ends may touch the boundary.
    ``mirrors``: lines ((axis, c), ...) the domain, points and lines are symmetric about (checked
    by the scene: :func:`plateqp.model.symmetry.check_symmetry`); the mesh is then one part's,
    mirrored (:mod:`plateqp.model.symmetry`).
    """
    with _GMSH_LOCK:  # gmsh is one global session: one mesh at a time (threaded executors)
        return _mesh_domain(domain, size, points, lines, tuple(mirrors))


#: gmsh keeps one global session and model list: two threads meshing at once would clash.
_GMSH_LOCK = threading.RLock()


def _mesh_domain(domain: Domain, size: float, points=(), lines=(), mirrors=()) -> MeshArrays:
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
        gmsh.option.setNumber("Mesh.Algorithm", ALGORITHM)
        gmsh.option.setNumber("Mesh.Smoothing", 0)  # no Laplacian passes: no gain in accuracy (benchmarks/README.md)
        gmsh.option.setNumber("Mesh.RandomFactor", 1e-9)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.ElementOrder", 1)
        gmsh.model.add(name)
        try:
            if mirrors:
                return _mesh_mirrored(gmsh, domain, float(size), points, lines, mirrors)
            return _mesh(gmsh, domain, float(size), points, lines)
        except Exception as exn:  # gmsh raises plain Exceptions with its own message
            raise SceneError(f"mesh: gmsh could not mesh the plate at size {size:g} ({str(exn).splitlines()[0]})") from exn
    finally:
        if owner:
            gmsh.finalize()
        else:  # pragma: no cover - a session the caller opened
            gmsh.model.setCurrent(name)
            gmsh.model.remove()


def _mesh(gmsh, domain: Domain, h: float, points, lines=()) -> MeshArrays:
    """The steps of :func:`mesh_domain` inside one gmsh model: the boundary curves, the embedded
    points and lines, the size field, the mesh, and the mesh read back."""
    tol = 1e-9 * domain.size
    curves = _boundary_curves(gmsh.model.geo, domain, lines, tol, points)
    surf = gmsh.model.geo.addPlaneSurface(curves.loops)
    gmsh.model.geo.synchronize()
    embedded = _embed(gmsh, surf, domain, curves, points, lines, tol)
    splits = _splits(domain, h)
    _size_field(gmsh, h, [t for t, _ in embedded], splits)
    _generate(gmsh, splits)
    return _read_mesh(gmsh, surf, curves.owner, h, domain)


def _mesh_mirrored(gmsh, domain: Domain, h: float, points, lines, mirrors) -> MeshArrays:
    """The steps of :func:`mesh_domain` for a symmetric domain: one part of it cut, meshed with the
    refinement of the whole, read back and mirrored in each line (:mod:`plateqp.model.symmetry`)."""
    tol = SYMMETRY_TOL * domain.size
    refined = build_part(gmsh, domain, points, lines, mirrors, tol)
    splits = _splits(domain, h)
    _size_field(gmsh, h, refined, splits)
    _generate(gmsh, splits)
    nodes, tris = unfold(*read_triangles(gmsh), mirrors, tol)
    return (nodes, tris, *boundary_of(nodes, tris, domain, h), h, domain)


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


def _boundary_curves(geo, domain: Domain, lines, tol: float, points=()) -> _Curves:
    """One gmsh curve per polygon segment (split where a line of ``lines`` ends on it or a point of
    ``points`` lies on it: a line must end at a point of the boundary's own curves to be meshed
    conformingly, and a point embedded in a curve is not made a node), a circle as arcs (split at
    the quarter points and there)."""
    c = _Curves({}, {}, [], [], [])
    ends = _distinct(np.array([e for seg in lines for e in seg] + list(points), dtype=float).reshape(-1, 2), tol)
    for k, shape in enumerate((domain.outer, *domain.holes)):
        on = [tuple(e) for e in ends[shape.distance(ends[:, 0], ends[:, 1]) <= tol].tolist()]
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
    line_tags, line_ends = _lines(geo, curves.vertices, lines, tol)
    pts = _distinct(np.asarray(list(points), dtype=float).reshape(-1, 2), tol)
    taken = np.array([(u, v) for u, v, _ in curves.vertices + line_ends], dtype=float).reshape(-1, 2)
    if len(pts) and len(taken):  # a boundary vertex or a line's end is a point already
        pts = pts[cKDTree(taken).query(pts)[0] > tol]
    boundary = np.zeros(len(pts), dtype=bool)
    for shape in (domain.outer, *domain.holes):
        boundary |= shape.distance(pts[:, 0], pts[:, 1]) <= tol
    line_of = np.full(len(pts), -1)  # the first line each point lies on
    for k, (_, seg) in reversed(list(enumerate(line_tags))):
        line_of[_point_segment(pts[:, 0], pts[:, 1], seg) <= tol] = k
    embedded = []
    for (x, y), on_boundary, k in zip(pts.tolist(), boundary, line_of):
        on = _curve_at(domain, curves.of, curves.geom, x, y, tol) if on_boundary else None
        if on is None and k >= 0:  # on an embedded line: a point of that line
            on = line_tags[k][0]
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


def _distinct(pts: np.ndarray, tol: float) -> np.ndarray:
    """The points ``pts`` (n, 2) less each one within ``tol`` of an earlier point kept."""
    if len(pts) < 2:
        return pts
    keep = np.ones(len(pts), dtype=bool)
    pairs = cKDTree(pts).query_pairs(tol, output_type="ndarray")  # (i, j), i < j
    for i, j in pairs[np.argsort(pairs[:, 1], kind="stable")] if len(pairs) else ():
        if keep[i]:
            keep[j] = False
    return pts[keep]


def _splits(domain: Domain, h: float) -> int:
    """How many times the mesh of ``domain`` at size ``h`` is split: :data:`SPLITS` from about
    :data:`SPLIT_FROM` nodes, else none."""
    return SPLITS if NODES_PER_AREA * domain.area / h**2 >= SPLIT_FROM else 0


def _generate(gmsh, splits: int) -> None:
    """The 2-D mesh at the coarse size :func:`_size_field` set, split ``splits`` times."""
    gmsh.model.mesh.generate(2)
    for _ in range(splits):
        gmsh.model.mesh.refine()


def _size_field(gmsh, h: float, refined: list, splits: int = 0) -> None:
    """The mesh size: h everywhere, :data:`REFINE` · h at the points ``refined`` (tags), growing to h
    at 2h away; to be split ``splits`` times, the mesh of size H = 2^splits · h (REFINE · H at the
    points, growing to H at 2H away), so the split mesh is the coarse mesh's own, split."""
    field = gmsh.model.mesh.field
    scale = 2.0 ** splits
    f_const = field.add("MathEval")
    field.setString(f_const, "F", repr(scale * h))
    fields = [f_const]
    if refined:
        f_dist = field.add("Distance")
        field.setNumbers(f_dist, "PointsList", refined)
        f_thr = field.add("Threshold")
        field.setNumber(f_thr, "InField", f_dist)
        field.setNumber(f_thr, "SizeMin", scale * REFINE * h)
        field.setNumber(f_thr, "SizeMax", scale * h)
        field.setNumber(f_thr, "DistMin", 0.0)
        field.setNumber(f_thr, "DistMax", 2.0 * scale * h)
        fields.append(f_thr)
    f_min = field.add("Min")
    field.setNumbers(f_min, "FieldsList", fields)
    field.setAsBackgroundMesh(f_min)


def _read_mesh(gmsh, surf: int, curve_owner: dict, h: float, domain: Domain) -> MeshArrays:
    """The generated mesh's arrays (:data:`MeshArrays`): the nodes of its triangles numbered from 0,
    triangles turned counter-clockwise, boundary edges by curve with their outward normals."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    index = np.full(int(tags.max()) + 1, -1)
    xyz = coords.reshape(-1, 3)
    _, tri_nodes = gmsh.model.mesh.getElementsByType(2, surf)
    tri_tags = tri_nodes.astype(np.int64).reshape(-1, 3)
    mark = np.zeros(int(tags.max()) + 1, dtype=bool)  # the triangles' nodes, increasing (not np.unique's sort)
    mark[tri_tags] = True
    used = np.flatnonzero(mark)
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
    return nodes, tris, edges, normals, np.array(boundary), np.array(segment), h, domain


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
    """Unit normals of boundary edges, pointing away from the triangle that holds each edge
    (looked up among the triangles with two nodes on the boundary only)."""
    n = len(nodes)
    on = np.zeros(n, dtype=bool)
    on[edges] = True
    tris = tris[on[tris].sum(axis=1) >= 2]
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
