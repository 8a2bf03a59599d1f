"""What a mesh shows of itself to figures and tables, computed here for the meshes' own answers
(:class:`plateqp.model.grid.Grid` and :class:`plateqp.model.trimesh.TriMesh` call these; code
downstream asks the mesh, never which kind it is):

- the plate's outline: the cells' sides that belong to one cell only (:func:`cell_side_outline`),
  or the boundary's closed loops in order (:func:`boundary_loops`);
- the position of points along a rectangle's contour (:func:`contour_position`);
- default section lines: across the whole rectangle (:func:`rectangle_sections`), or cut to the
  longest stretch of each line on the plate (:func:`cut_sections`);
- the layout of nodal fields in a dataset: one value per node (:func:`node_layout`) or the grid
  view (:func:`grid_layout`).
"""

from __future__ import annotations

import numpy as np

Section = tuple[str, tuple[float, float], tuple[float, float]]


# -- the outline ------------------------------------------------------------------------------
def cell_side_outline(mesh) -> np.ndarray:
    """(m, 2, 2) the sides of ``mesh.cells`` that belong to one cell only, as point pairs: the
    plate's boundary, holes and openings included."""
    c = mesh.cells
    e = np.sort(np.vstack([c[:, [k, (k + 1) % c.shape[1]]] for k in range(c.shape[1])]), axis=1)
    uniq, count = np.unique(e, axis=0, return_counts=True)
    return mesh.nodes[uniq[count == 1]]


def boundary_loops(mesh) -> list[tuple[int, np.ndarray]]:
    """The boundary as closed loops of node coordinates: [(boundary, (n, 2) points)], 0 the outer
    boundary, k ≥ 1 hole k − 1 (the mesh's boundary nodes in order along each loop)."""
    edges, _, boundary, _ = mesh.boundary_edges()
    out = []
    for k in np.unique(boundary):
        e = edges[boundary == k]
        nxt = {int(i): int(j) for i, j in e}
        start = int(e[0, 0])
        seq, n = [start], nxt[start]
        while n != start and len(seq) <= len(e):
            seq.append(n)
            n = nxt.get(n, start)
        out.append((int(k), mesh.nodes[seq]))
    return out


def contour_position(xy: np.ndarray, a: float, b: float) -> tuple[np.ndarray, bool]:
    """Arc length along the rectangle [0, a] × [0, b]'s boundary, anticlockwise from (0, 0), and
    whether all points (three or more) are on it."""
    if xy.shape[0] < 3:
        return np.zeros(xy.shape[0]), False
    tol = 1e-9 * max(a, b)
    x, y = xy[:, 0], xy[:, 1]
    bottom, right, top, left = y <= tol, x >= a - tol, y >= b - tol, x <= tol
    if not np.all(bottom | right | top | left):
        return np.zeros(xy.shape[0]), False
    pos = np.where(bottom, x, np.where(right, a + y, np.where(top, a + b + (a - x), 2 * a + b + (b - y))))
    pos = np.where(bottom & left, 0.0, pos)
    return pos, True


# -- section lines ----------------------------------------------------------------------------
def _rows(scene, x0: float, x1: float) -> list[Section]:
    """Lines along the rows of supports: 2 to 6 distinct y with two or more supports each."""
    xy = np.array([[s.x, s.y] for s in scene.supports], dtype=float).reshape(-1, 2)
    if not len(xy):
        return []
    ys, counts = np.unique(np.round(xy[:, 1], 9), return_counts=True)
    if 2 <= ys.size <= 6 and np.all(counts >= 2):
        return [(f"y = {y:g}", (x0, float(y)), (x1, float(y))) for y in ys]
    return []


def _load_point(scene, centre: tuple[float, float]) -> tuple[float, float]:
    """The largest point load's place, or ``centre`` where there is none."""
    pl = [ld for ld in scene.loads if ld.type == "point"]
    if not pl:
        return centre
    ld = max(pl, key=lambda p: abs(p.P))
    return ld.x, ld.y


def rectangle_sections(scene, a: float, b: float) -> list[Section]:
    """Section lines across the rectangle [0, a] × [0, b]: the rows of supports (2 to 6 distinct
    y with two or more supports each, the source paper's sections 1–5), else the horizontal and
    vertical lines through the largest point load (or the centre), the bottom edge if supports
    stand on it, and the diagonal."""
    rows = _rows(scene, 0.0, a)
    if rows:
        return rows
    xl, yl = _load_point(scene, (a / 2, b / 2))
    out = [(f"y = {yl:g}", (0.0, yl), (a, yl)), (f"x = {xl:g}", (xl, 0.0), (xl, b))]
    if any(abs(s.y) <= 1e-9 * max(a, b) for s in scene.supports):
        out.append(("y = 0 (edge)", (0.0, 0.0), (a, 0.0)))
    out.append(("diagonal", (0.0, 0.0), (a, b)))
    return out


def cut_sections(mesh, scene) -> list[Section]:
    """Section lines on any plate: the rows of supports, else the horizontal and vertical lines
    through the largest point load (or the centre of the plate's bounding box), each cut to its
    longest stretch on the plate (``mesh.locate``), so that every point of a section is on it."""
    x0, x1, y0, y1 = mesh.bbox
    lines = _rows(scene, x0, x1)
    if not lines:
        xc, yc = _load_point(scene, (0.5 * (x0 + x1), 0.5 * (y0 + y1)))
        lines = [(f"y = {yc:g}", (x0, yc), (x1, yc)), (f"x = {xc:g}", (xc, y0), (xc, y1))]
    out = []
    for lab, p0, p1 in lines:
        cut = _on_plate_stretch(mesh, p0, p1)
        if cut is not None:
            out.append((lab, *cut))
    return out


def _on_plate_stretch(mesh, p0, p1, n: int = 801):
    """The longest stretch of the segment p0 → p1 on the plate, as (q0, q1), or None."""
    t = np.linspace(0.0, 1.0, n)
    x = p0[0] + t * (p1[0] - p0[0])
    y = p0[1] + t * (p1[1] - p0[1])
    inside = mesh.locate(x, y)[0] >= 0
    best, start, run = None, None, 0
    for i, ok in enumerate(np.append(inside, False)):
        if ok and start is None:
            start = i
        elif not ok and start is not None:
            if i - start > run and i - 1 > start:
                best, run = (start, i - 1), i - start
            start = None
    if best is None:
        return None
    return (float(x[best[0]]), float(y[best[0]])), (float(x[best[1]]), float(y[best[1]]))


# -- nodal fields in a dataset ----------------------------------------------------------------
def node_layout(mesh, fields: dict) -> tuple[tuple[str, ...], dict, dict]:
    """(dims, coords, fields): one value per node (``mesh.nodes`` order), dimension ``node``
    with coordinates ``x`` and ``y`` (units L)."""
    coords = {"x": ("node", mesh.nodes[:, 0].copy(), {"units": "L"}),
              "y": ("node", mesh.nodes[:, 1].copy(), {"units": "L"})}
    return ("node",), coords, dict(fields)


def grid_layout(mesh, fields: dict) -> tuple[tuple[str, ...], dict, dict]:
    """(dims, coords, fields): the grid view, dimensions ``y`` and ``x`` (the grid lines'
    coordinates, units L), each field ``mesh.to_grid`` of it (NaN off the plate)."""
    coords = {"x": ("x", np.arange(mesh.nx + 1) * mesh.hx, {"units": "L"}),
              "y": ("y", np.arange(mesh.ny + 1) * mesh.hy, {"units": "L"})}
    return ("y", "x"), coords, {q: mesh.to_grid(v) for q, v in fields.items()}
