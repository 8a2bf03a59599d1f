"""Symmetric meshes of symmetric plates: one part meshed, then mirrored in the plate's centre lines.

``[mesh] symmetry`` asks for a mesh that is its own mirror image: ``"x"`` in the line x = xc
(x ↦ 2 xc − x), ``"y"`` in the line y = yc, ``"xy"`` in both; (xc, yc) is the middle of the outer
boundary's extent (a circle's centre), the only lines an outline can be symmetric about.

:func:`check_symmetry` holds the scene to it: the outline, every cut-out (hole or opening), the
points the mesh puts a node at (supports, point loads, pins) and the bed region's outline inside
the plate must each have its mirror image in the scene, within :data:`TOL` of the plate's size;
else a SceneError names ``mesh.symmetry`` and the first item without one. Loads, gaps and
stiffnesses need not be symmetric: the option is about the mesh.

On triangles (:func:`build_part`, :func:`unfold`, :func:`boundary_of`, run by
:mod:`plateqp.model.trimesh`) gmsh meshes the part of the plate on one side of each line (its
OpenCASCADE kernel cuts the plate; the points and the bed's lines in the part are embedded, with
the refinement around every point of the whole plate, so the part is graded as the whole would
be), the nodes within :data:`TOL` of a line are put on it exactly, and the part is mirrored: an
image node's coordinate is ``2 c − x`` (exact to the last bit when the line is at 0, and when the
plate lies within [c, 4c] of a line at c ≠ 0, as a plate in the positive quadrant does: the
subtraction is then exact), the nodes on the line are shared. The kept part is the one on the far
side of each line from 0. The grid of equal cells is symmetric whenever the scene is, so there
the option only checks the scene.
"""

from __future__ import annotations

import numpy as np

from .geometry import Circle, Domain, Polygon, _point_segment, nearest_segment

#: the option's values: the lines mirrored in
MODES = ("x", "y", "xy")
#: a mirror image matches within TOL times the plate's size (as the mesher merges points)
TOL = 1e-9


def mirror_lines(domain: Domain, symmetry: str) -> tuple[tuple[int, float], ...]:
    """((axis, c), ...): the lines coordinate ``axis`` = c that ``symmetry`` names, through the
    middle of the outer boundary's extent."""
    o = domain.outer
    if isinstance(o, Circle):
        centre = (o.xc, o.yc)
    else:
        x0, x1, y0, y1 = o.bbox
        centre = (0.5 * (x0 + x1), 0.5 * (y0 + y1))
    return tuple((axis, centre[axis]) for axis in (0, 1) if "xy"[axis] in symmetry)


def reflect(p: np.ndarray, axis: int, c: float) -> np.ndarray:
    """Points ``p`` (n, 2) mirrored in the line coordinate ``axis`` = c: that coordinate 2c − x."""
    out = np.array(p, dtype=float, copy=True).reshape(-1, 2)
    out[:, axis] = 2.0 * c - out[:, axis]
    return out


def _line(axis: int, c: float) -> str:
    return f"the line {'xy'[axis]} = {c:g}"


# -- the scene's check ------------------------------------------------------------------------


def check_symmetry(sc, domain: Domain) -> None:
    """The scene ``sc`` (its fields checked) symmetric about the lines of ``sc.mesh.symmetry``
    (see the module docstring); ``domain``: its plate (:func:`plateqp.model.geometry.scene_domain`)."""
    from .geometry import inner_segments, mesh_size
    from .regions import region_outline

    tol = TOL * domain.size
    names = ["plate.shape"] + [f"holes.{i}" for i in range(len(sc.holes))] + \
        [f"openings.{i}" for i in range(len(sc.openings))]
    shapes = (domain.outer, *domain.holes)
    points = [(f"supports.{i + 1}", s.x, s.y) for i, s in enumerate(sc.supports)] + \
        [(f"loads.{i}", ld.x, ld.y) for i, ld in enumerate(sc.loads) if ld.type == "point"] + \
        [(f"pins.{i}", p.x, p.y) for i, p in enumerate(sc.pins)]
    f = sc.foundation
    lines = [] if f is None or f.region is None else inner_segments(domain, region_outline(f.region, mesh_size(sc)))
    xy = np.array([(x, y) for _, x, y in points], dtype=float).reshape(-1, 2)
    for axis, c in mirror_lines(domain, sc.mesh.symmetry):
        where = _line(axis, c)
        for name, s in zip(names, shapes):
            if not any(_same(_reflect_shape(s, axis, c), t, tol) for t in (shapes[:1] if name == names[0] else shapes[1:])):
                what = "the outline does not match" if name == names[0] else "no cut-out matches"
                sc._fail("mesh.symmetry", f"{name} is not symmetric about {where}: {what} its mirror image; "
                         "make the plate symmetric or remove mesh.symmetry")
        if len(xy):
            from scipy.spatial import cKDTree

            d, _ = cKDTree(xy).query(reflect(xy, axis, c))
            if (d > tol).any():
                i = int(np.argmax(d > tol))
                name, x, y = points[i]
                (u, v), = reflect([(x, y)], axis, c)
                sc._fail("mesh.symmetry", f"{name} at ({x:g}, {y:g}) has no mirror image in {where}: no support, "
                         f"point load or pin at ({u:g}, {v:g}); the mesh puts a node at each, so a symmetric mesh "
                         "needs them in mirrored pairs (or on the line)")
        if lines and _off_lines(lines, axis, c, tol):
            sc._fail("mesh.symmetry", f"foundation.region is not symmetric about {where}: the bed's outline on the "
                     "plate (a line of the mesh) does not match its mirror image")


def _reflect_shape(s, axis: int, c: float):
    if isinstance(s, Circle):
        xc, yc = reflect([(s.xc, s.yc)], axis, c)[0]
        return Circle(float(xc), float(yc), s.r)
    return Polygon(tuple(map(tuple, reflect(s.xy, axis, c)[::-1])))


def _same(s, t, tol: float) -> bool:
    """Two shapes alike within ``tol``: circles of one centre and radius, polygons of one vertex set."""
    if isinstance(s, Circle) or isinstance(t, Circle):
        return isinstance(s, Circle) and isinstance(t, Circle) and \
            max(abs(s.xc - t.xc), abs(s.yc - t.yc), abs(s.r - t.r)) <= tol
    if len(s.vertices) != len(t.vertices) or max(abs(u - v) for u, v in zip(s.bbox, t.bbox)) > tol:
        return False
    from scipy.spatial import cKDTree

    return bool((cKDTree(t.xy).query(s.xy)[0] <= tol).all() and (cKDTree(s.xy).query(t.xy)[0] <= tol).all())


def _off_lines(lines, axis: int, c: float, tol: float) -> bool:
    """True if a mirrored segment of ``lines`` (its ends and middle) leaves the union of them."""
    seg = np.array(lines, dtype=float)  # (n, 2 ends, 2)
    probes = reflect(np.concatenate([seg[:, 0], seg[:, 1], seg.mean(axis=1)]), axis, c)
    near = np.full(len(probes), np.inf)
    for p, q in seg:
        near = np.minimum(near, _point_segment(probes[:, 0], probes[:, 1], (p, q)))
    return bool((near > tol).any())


# -- the triangle mesh ------------------------------------------------------------------------


def _kept(axis: int, c: float) -> float:
    """+1 or −1: the side of the line kept, the far side from 0 (:func:`reflect` exact there)."""
    return 1.0 if c >= 0 else -1.0


def _clip(p: np.ndarray, q: np.ndarray, mirrors, tol: float):
    """The part of the segment p–q on the kept side of every line (an end within ``tol`` of a line
    put on it), or None."""
    p, q = p.copy(), q.copy()
    for axis, c in mirrors:
        s = _kept(axis, c)
        for e in (p, q):
            e[axis] = c if abs(e[axis] - c) <= tol else e[axis]
        dp, dq = s * (p[axis] - c), s * (q[axis] - c)
        if min(dp, dq) < 0 and max(dp, dq) <= 0:
            return None  # on the other side (or touching the line from there)
        if min(dp, dq) < 0:  # crosses the line: cut it there, the cut exactly on it
            cut = p + dp / (dp - dq) * (q - p)
            cut[axis] = c
            p, q = (cut, q) if dp < 0 else (p, cut)
    return p, q


def _shape(occ, s) -> int:
    """An OpenCASCADE surface of a shape."""
    if isinstance(s, Circle):
        return occ.addDisk(s.xc, s.yc, 0.0, s.r, s.r)
    pts = [occ.addPoint(x, y, 0.0) for x, y in s.vertices]
    curves = [occ.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
    return occ.addPlaneSurface([occ.addCurveLoop(curves)])


def build_part(gmsh, domain: Domain, points, lines, mirrors, tol: float) -> list[int]:
    """The part of ``domain`` on the kept side of every line of ``mirrors`` in the current gmsh
    model (OpenCASCADE), with the points of ``points`` and the segments of ``lines`` there embedded
    (those on a line put on it exactly). Returns the tags of the points to refine around: those of
    the part and their mirror images (points of their own, outside the part)."""
    occ = gmsh.model.occ
    plate = [(2, _shape(occ, domain.outer))]
    if domain.holes:
        plate, _ = occ.cut(plate, [(2, _shape(occ, h)) for h in domain.holes])
    x0, x1, y0, y1 = domain.outer.bbox
    lo, hi = [x0 - domain.size, y0 - domain.size], [x1 + domain.size, y1 + domain.size]
    for axis, c in mirrors:
        (lo if _kept(axis, c) > 0 else hi)[axis] = c
    box = occ.addRectangle(lo[0], lo[1], 0.0, hi[0] - lo[0], hi[1] - lo[1])
    part, _ = occ.intersect(plate, [(2, box)])
    kept = np.array(points, dtype=float).reshape(-1, 2)
    for axis, c in mirrors:
        kept[np.abs(kept[:, axis] - c) <= tol, axis] = c
        kept = kept[_kept(axis, c) * (kept[:, axis] - c) >= 0]
    if len(kept) > 1:  # one point of each cluster within tol
        from scipy.spatial import cKDTree

        kept = np.delete(kept, sorted({j for _, j in cKDTree(kept).query_pairs(tol)}), axis=0)
    segs = [s for s in (_clip(np.asarray(p, float), np.asarray(q, float), mirrors, tol) for p, q in lines)
            if s is not None and np.hypot(*(s[1] - s[0])) > tol]
    tags = [occ.addPoint(x, y, 0.0) for x, y in kept]
    seg_tags = [occ.addLine(occ.addPoint(*p, 0.0), occ.addPoint(*q, 0.0)) for p, q in segs]
    _, where = occ.fragment(part, [(0, t) for t in tags] + [(1, t) for t in seg_tags])
    refined = [where[len(part) + i][0][1] for i in range(len(tags))]
    images = kept
    for axis, c in mirrors:
        off = images[:, axis] != c
        images = np.concatenate([images, reflect(images[off], axis, c)])
    refined += [occ.addPoint(x, y, 0.0) for x, y in images[len(kept):]]
    occ.synchronize()
    return refined


def read_triangles(gmsh) -> tuple[np.ndarray, np.ndarray]:
    """(nodes (n, 2), counter-clockwise triangles (nt, 3)) of the generated mesh, numbered from 0
    over the triangles' nodes."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    _, tri_nodes = gmsh.model.mesh.getElementsByType(2)
    tri = tri_nodes.astype(np.int64).reshape(-1, 3)
    used = np.unique(tri)
    index = np.full(int(tags.max()) + 1, -1)
    index[used] = np.arange(len(used))
    pos = np.full(int(tags.max()) + 1, -1)
    pos[tags.astype(np.int64)] = np.arange(len(tags))
    nodes = coords.reshape(-1, 3)[pos[used], :2].copy()
    return nodes, _ccw(nodes, index[tri])


def _ccw(nodes, tris):
    p = nodes[tris]
    signed = ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
              - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    tris[signed < 0] = tris[signed < 0][:, [0, 2, 1]]
    return tris


def unfold(nodes: np.ndarray, tris: np.ndarray, mirrors, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """The mesh of a part mirrored in each line of ``mirrors`` in turn: nodes within ``tol`` of a
    line put on it and shared with the image, the image's nodes at :func:`reflect` of the part's,
    its triangles turned back counter-clockwise."""
    nodes = nodes.copy()
    for axis, c in mirrors:
        on = np.abs(nodes[:, axis] - c) <= tol
        nodes[on, axis] = c
    for axis, c in mirrors:
        off = np.flatnonzero(nodes[:, axis] != c)
        image = np.arange(len(nodes))
        image[off] = len(nodes) + np.arange(len(off))
        nodes = np.concatenate([nodes, reflect(nodes[off], axis, c)])
        tris = np.concatenate([tris, image[tris][:, [0, 2, 1]]])
    return nodes, tris


def boundary_of(nodes: np.ndarray, tris: np.ndarray, domain: Domain, h: float):
    """(edges, outward normals, boundary, segment) of a mesh of ``domain``: the edges of one
    triangle each, the outer boundary's counter-clockwise and a hole's along its own shape's
    (counter-clockwise) direction, as gmsh's curves run; each on the boundary nearest its middle,
    and on a polygon the segment :func:`plateqp.model.geometry.nearest_segment` finds."""
    a = np.concatenate([tris[:, 0], tris[:, 1], tris[:, 2]])
    b = np.concatenate([tris[:, 1], tris[:, 2], tris[:, 0]])
    key = np.minimum(a, b) * len(nodes) + np.maximum(a, b)
    _, first, count = np.unique(key, return_index=True, return_counts=True)
    once = first[count == 1]
    edges = np.column_stack([a[once], b[once]])  # the plate on the left
    d = nodes[edges[:, 1]] - nodes[edges[:, 0]]
    normals = np.column_stack([d[:, 1], -d[:, 0]]) / np.hypot(d[:, 0], d[:, 1])[:, None]
    mid = 0.5 * (nodes[edges[:, 0]] + nodes[edges[:, 1]])
    shapes = (domain.outer, *domain.holes)
    boundary = np.argmin(np.stack([s.distance(mid[:, 0], mid[:, 1]) for s in shapes]), axis=0)
    segment = np.zeros(len(edges), dtype=int)
    for k, s in enumerate(shapes):  # the normal pointing into a hole, out of the outer boundary's plate
        hit = boundary == k
        segment[hit] = nearest_segment(s, mid[hit], normals[hit] if k else -normals[hit], h)
    edges[boundary > 0] = edges[boundary > 0][:, ::-1]
    order = np.lexsort((segment, boundary))
    return edges[order], normals[order], boundary[order], segment[order]
