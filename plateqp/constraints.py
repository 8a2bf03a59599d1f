"""The two-sided supports of a model on any mesh: prescribed dofs from named edges and pins, and
the rigid motions those supports leave free.

Every mesh gives its boundary the same way (``mesh.boundary_edges()``: node pairs, outward unit
normals, boundary 0 outer or K + 1 for cut-out K, the segment of that boundary's shape) and
:func:`plateqp.geometry.edge_table` says which named edge holds each segment. One builder turns
that into prescribed dofs for every element; the element's dofs decide what can be prescribed:

- **simple**: w = the edge's ``w`` at its nodes. An element whose slope dofs are shared physical
  derivatives on straight, axis-parallel edges (ACM, BFS: ``holds_tangent_slope``) also
  prescribes the tangential slope (w is constant along the edge); DKT leaves the rotations free
  (imposing them on a curved edge would make the simple support converge to the clamped one:
  Babuška's paradox).
- **clamped**: w, and ∇w = (∂w/∂n) n with ∂w/∂n the edge's ``slope`` (:func:`gradient`); an
  element with a twist dof w,xy (BFS) also prescribes it zero (∂w/∂n constant along the edge).
- **free**: nothing. An edge no name holds is free: ``all`` holds the outer boundary only, a
  cut-out's edges (``holeK``) are free unless named.

A dof two supports prescribe with different values is a SceneError naming both.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .errors import PlateQPWarning, SceneError

W, WX, WY, WXY = (0, 0), (1, 0), (0, 1), (1, 1)


class _Prescribed:
    """dof → (value, who) with the conflict check."""

    def __init__(self, element):
        self.kinds = list(element.node_dofs)
        self.nd = len(self.kinds)
        self.names = element.dof_names
        self.values: dict[int, tuple[float, str]] = {}

    def put(self, node: int, order, value: float, who: str) -> None:
        if order not in self.kinds:
            return
        k = self.kinds.index(order)
        dof = int(node) * self.nd + k
        old = self.values.get(dof)
        if old is not None and abs(old[0] - value) > 1e-12 * max(1.0, abs(value), abs(old[0])):
            raise SceneError(f"{who} and {old[1]} prescribe different values of {self.names[k]} at their "
                             "common node; make them agree")
        self.values[dof] = (value, who)

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        fixed = np.array(sorted(self.values), dtype=int)
        return fixed, np.array([self.values[d][0] for d in fixed], dtype=float)


# -- edges of a plate, by name (every mesh) ------------------------------------------------------
#: ``outer`` / ``holeK`` a whole boundary; ``outer_I`` / ``holeK_I`` segment I of a polygon (from
#: vertex I to I + 1); ``outer_I-J`` / ``holeK_I-J`` segments I to J. Bare TOML keys, no quoting.
EDGE_KEY = re.compile(r"^(outer|hole(\d+))(?:_(\d+)(?:-(\d+))?)?$")


def edge_table(scene, domain) -> dict[tuple[int, int], tuple[str, object]]:
    """(boundary, segment) → (edge name, Edge) for every segment of every boundary that an edge
    name holds (a circle is one segment, 0), the same on every mesh. ``all`` holds the outer
    boundary only: the edges of a cut-out (a hole or an opening, ``holeK``) are free unless a
    name holds them. The most specific name wins: a segment range over a whole boundary
    (``outer``, ``holeK``, or a rectangle's ``left``/``right``/``bottom``/``top``, segments of
    ``outer``) over ``all``. A name that is not one of these, or a segment two names of the same
    kind hold, is a SceneError."""
    from .geometry import RECT_SEGMENTS, Circle, Polygon

    shapes = (domain.outer, *domain.holes)
    nseg = [len(s.vertices) if isinstance(s, Polygon) else 1 for s in shapes]
    levels: list[dict[tuple[int, int], str]] = [{}, {}, {}]  # all, boundary, segments
    for name in scene.edges:
        where = f"edges.{name}"
        if name == "all":
            targets, level = [(0, i) for i in range(nseg[0])], 0
        elif name in RECT_SEGMENTS and scene.plate.shape is None:
            targets, level = [(0, RECT_SEGMENTS.index(name))], 2
        else:
            m = EDGE_KEY.match(name)
            if m is None:
                names = "all, outer, outer_I, outer_I-J, holeK, holeK_I, holeK_I-J" + (
                    ", left, right, bottom, top" if scene.plate.shape is None else "")
                scene._fail(where, f"unknown edge; edges are {names}")
            k = 0 if m.group(2) is None else int(m.group(2)) + 1
            if k > len(domain.holes):
                scene._fail(where, f"there is no hole {k - 1} (the plate has {len(domain.holes)} holes and openings)")
            if m.group(3) is None:
                targets, level = [(k, i) for i in range(nseg[k])], 1
            else:
                i, j = int(m.group(3)), int(m.group(4) or m.group(3))
                if isinstance(shapes[k], Circle):
                    scene._fail(where, "a circle has no segments; name the whole boundary")
                if not i <= j < nseg[k]:
                    scene._fail(where, f"segments {i} to {j} are not segments 0 to {nseg[k] - 1} of that polygon")
                targets, level = [(k, s) for s in range(i, j + 1)], 2
        for t in targets:
            if t in levels[level]:
                scene._fail(where, f"edges.{levels[level][t]} holds segment {t[1]} of that boundary too; "
                            "name each segment once")
            levels[level][t] = name
    table = {}
    for level in levels:
        table.update({t: (name, scene.edges[name]) for t, name in level.items()})
    return table


def warn_changed_all(scene, domain) -> None:
    """Warn (once per scene text) where ``edges.all`` meant more before: on a triangle mesh it also
    held the holes' edges, which are now free unless named (``holeK``)."""
    every = scene.edges.get("all")
    if every is None or every.kind == "free" or not domain.holes or not scene.triangles:
        return
    named = {int(m.group(2)) for m in map(EDGE_KEY.match, scene.edges) if m is not None and m.group(2) is not None}
    free = [f"hole{k}" for k in range(len(domain.holes)) if k not in named]
    if free:
        warnings.warn(f"{scene.source + ': ' if scene.source else ''}edges.all holds the outer boundary only: "
                      f"the edges of {', '.join(free)} are free unless named (they were {every.kind} "
                      f"under edges.all before); to keep them {every.kind}, add "
                      + ", ".join(f'{h} = "{every.kind}"' for h in free) + " to [edges]",
                      PlateQPWarning, stacklevel=2)


def prescribed(scene, mesh, element) -> tuple[np.ndarray, np.ndarray]:
    """(fixed, values): the full dof indices the two-sided supports prescribe and their values
    (sorted by dof), on any mesh that gives ``boundary_edges()`` and ``node_at``."""
    from .geometry import scene_domain

    out = _Prescribed(element)
    table = edge_table(scene, getattr(mesh, "domain", None) or scene_domain(scene))
    edges, normals, boundary, segment = mesh.boundary_edges()
    tangent = getattr(element, "holds_tangent_slope", False)
    clamped: dict[int, list] = {}  # node -> [(outward normal, slope, who)] of its clamped edges
    for (i, j), k, s, normal in zip(edges, boundary, segment, normals):
        name, e = table.get((int(k), int(s)), (None, None))
        if e is None or e.kind == "free":
            continue
        who = f"edges.{name}"
        for n in (i, j):
            out.put(n, W, e.w, who)
            if e.kind == "clamped":
                clamped.setdefault(int(n), []).append((normal, e.slope, who))
                out.put(n, WXY, 0.0, who)
            elif tangent:  # w constant along a straight edge: its tangential slope is zero
                out.put(n, WY if abs(normal[0]) > abs(normal[1]) else WX, 0.0, who)
    for n, held in clamped.items():
        gx, gy = gradient(held)
        out.put(n, WX, gx, held[0][2])
        out.put(n, WY, gy, held[0][2])
    for i, pin in enumerate(scene.pins):
        n = mesh.node_at(pin.x, pin.y)
        if n is None:  # pragma: no cover - validation puts every pin on a node
            raise SceneError(f"pins.{i}: no mesh node at ({pin.x}, {pin.y})")
        out.put(n, W, pin.w, f"pins.{i}")
    return out.arrays()


def gradient(held) -> np.ndarray:
    """∇w at a node of clamped edges [(outward normal, ∂w/∂n, who)]: w is constant along each, so
    ∇w = (∂w/∂n) n. Along a smooth boundary (normals within 10°: a curve's two chords, or a
    straight edge) n is their mean direction and the slope their mean; at a corner every edge
    asks its own (∂w/∂n) n, and they must agree (only zero slopes meet at a clamped corner)."""
    N = np.array([h[0] for h in held], dtype=float)
    s = np.array([h[1] for h in held], dtype=float)
    mean = N.sum(axis=0)
    norm = np.linalg.norm(mean)
    if norm > 0 and np.all(N @ mean / norm >= np.cos(np.radians(10.0))):
        return s.mean() * mean / norm
    g = s[:, None] * N
    bad = np.flatnonzero(np.abs(g - g[0]).max(axis=1) > 1e-12 * max(np.abs(g).max(), 1e-300))
    if bad.size:
        raise SceneError(f"{held[0][2]} and {held[bad[0]][2]} prescribe different slopes at their common corner "
                         "(w is constant along each clamped edge); make the slopes there zero")
    return g[0]


def rigid_modes(model) -> np.ndarray:
    """(n_free, k) basis of the rigid motions w = α + βx + γy (slopes β, γ, twist 0) of each
    connected piece of the plate that its prescribed dofs allow (k = 0..3 per piece), restricted
    to the free dofs, with the prescribed dofs held at zero. On any mesh (``mesh.cells`` on
    ``mesh.nodes``, node k's dofs from ``mesh.plate_node_ids``)."""
    mesh, el = model.grid, model.element
    kinds = list(el.node_dofs)
    nd = len(kinds)
    ids = mesh.plate_node_ids
    cells = mesh.cells
    n = ids.size
    # connectivity of nodes through cells: each cell's first node to its others
    r = np.repeat(cells[:, 0], cells.shape[1] - 1)
    A = sp.csr_matrix((np.ones(r.size), (r, cells[:, 1:].ravel())), shape=(n, n))
    _, label = connected_components(A, directed=False)
    compact = np.full(model.n_full // nd, -1)
    compact[ids] = np.arange(n)
    xy = mesh.nodes
    fixed_node = compact[model.fixed // nd]
    fixed_kind = model.fixed % nd
    rows_of = {W: lambda p: [1.0, *xy[p]], WX: lambda p: [0.0, 1.0, 0.0], WY: lambda p: [0.0, 0.0, 1.0]}
    modes = []
    for comp in np.unique(label):
        here = label[fixed_node] == comp
        R = np.array([rows_of[kinds[k]](p) for p, k in zip(fixed_node[here], fixed_kind[here])
                      if kinds[k] in rows_of]).reshape(-1, 3)
        _, s, vt = np.linalg.svd(R if len(R) else np.zeros((1, 3)), full_matrices=len(R) < 3)  # vt 3 × 3
        s_full = np.zeros(3)
        s_full[: len(s)] = s
        nodes = np.flatnonzero(label == comp)
        dof = ids[nodes] * nd
        for a, b, g in vt[s_full <= 1e-10 * max(1.0, s_full.max())]:
            v = np.zeros(model.n_full)
            v[dof + kinds.index(W)] = a + b * xy[nodes, 0] + g * xy[nodes, 1]
            v[dof + kinds.index(WX)] = b
            v[dof + kinds.index(WY)] = g
            modes.append(v[model.free])
    return np.array(modes).T.reshape(model.n_free, len(modes))
