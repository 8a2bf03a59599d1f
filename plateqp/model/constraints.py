"""The two-sided supports of a model on any mesh: prescribed dofs from named edges and pins, and
the rigid motions those supports leave free.

Every mesh gives its boundary the same way (``mesh.boundary_edges()``: node pairs, outward unit
normals, boundary 0 outer or K + 1 for cut-out K, the segment of that boundary's shape) and
:func:`plateqp.model.geometry.edge_table` says which named edge holds each segment. One builder turns
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

from ..errors import PlateQPWarning, SceneError

W, WX, WY, WXY = (0, 0), (1, 0), (0, 1), (1, 1)


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
    held the holes' edges, which are now free unless named (``holeK``): the generator says
    whether it did (``all_held_holes``)."""
    from .generators import mesh_generator

    every = scene.edges.get("all")
    if every is None or every.kind == "free" or not domain.holes or not mesh_generator(scene).all_held_holes:
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
    (sorted by dof), on any mesh that gives ``boundary_edges()``, ``node_at`` and its ``domain``.
    A dof two supports prescribe differently (beyond 1e-12 relative) is a SceneError naming both."""
    table = edge_table(scene, mesh.domain)
    edges, normals, boundary, segment = mesh.boundary_edges()
    held = [(key, name, e) for key, (name, e) in table.items() if e.kind != "free"]
    who = [f"edges.{name}" for _, name, _ in held] + [f"pins.{i}" for i in range(len(scene.pins))]
    # each boundary edge's held edge (index into ``held``); both ends of each, edge by edge
    code = np.asarray(boundary, dtype=np.int64) << 32 | np.asarray(segment, dtype=np.int64)
    keys = np.array([k << 32 | s for (k, s), _, _ in held], dtype=np.int64)
    order = np.argsort(keys)
    pos = np.minimum(np.searchsorted(keys[order], code), max(len(keys) - 1, 0))
    hit = np.flatnonzero(keys[order][pos] == code) if len(keys) else np.zeros(0, dtype=int)
    idx = np.full(len(code), -1)
    idx[hit] = order[pos[hit]]
    ends, h = edges[hit].ravel(), np.repeat(idx[hit], 2)
    n2 = np.repeat(normals[hit], 2, axis=0)
    kind = np.array([e.kind for _, _, e in held] or [""])[h]
    w, slope = (np.array([getattr(e, a) for _, _, e in held] or [0.0])[h] for a in ("w", "slope"))
    clamp = kind == "clamped"
    rows = [(ends, W, w, h), (ends[clamp], WXY, np.zeros(clamp.sum()), h[clamp])]
    if getattr(element, "holds_tangent_slope", False):  # w constant along a straight edge
        simple = ~clamp
        along_y = np.abs(n2[:, 0]) > np.abs(n2[:, 1])  # a normal along x: the edge runs along y
        for order, mask in ((WY, simple & along_y), (WX, simple & ~along_y)):
            rows.append((ends[mask], order, np.zeros(mask.sum()), h[mask]))
    rows += _gradients(ends[clamp], n2[clamp], slope[clamp], h[clamp], who)
    for i, pin in enumerate(scene.pins):
        n = mesh.node_at(pin.x, pin.y)
        if n is None:  # pragma: no cover - validation puts every pin on a node
            raise SceneError(f"pins.{i}: no mesh node at ({pin.x}, {pin.y})")
        rows.append((np.array([n]), W, np.array([float(pin.w)]), np.array([len(held) + i])))
    return _settle(rows, element, who)


def _gradients(nodes, normals, slopes, who_idx, who) -> list:
    """∇w = (∂w/∂n) n at every node of clamped edges (:func:`gradient`): the nodes along a smooth
    boundary at once, the corners one by one."""
    if not len(nodes):
        return []
    order = np.argsort(nodes, kind="stable")
    nodes, normals, slopes, who_idx = nodes[order], normals[order], slopes[order], who_idx[order]
    uniq, start, count = np.unique(nodes, return_index=True, return_counts=True)
    mean = np.add.reduceat(normals, start, axis=0)
    norm = np.hypot(mean[:, 0], mean[:, 1])
    unit = mean / np.where(norm > 0, norm, 1.0)[:, None]
    cos = np.einsum("ij,ij->i", normals, np.repeat(unit, count, axis=0))
    smooth = (norm > 0) & (np.minimum.reduceat(cos, start) >= np.cos(np.radians(10.0)))
    g = (np.add.reduceat(slopes, start) / count)[:, None] * unit
    for k in np.flatnonzero(~smooth):
        sl = slice(start[k], start[k] + count[k])
        g[k] = gradient([(nm, sv, who[wi]) for nm, sv, wi in zip(normals[sl], slopes[sl], who_idx[sl])])
    first = who_idx[start]
    return [(uniq, WX, g[:, 0], first), (uniq, WY, g[:, 1], first)]


def _settle(rows, element, who) -> tuple[np.ndarray, np.ndarray]:
    """(fixed, values) from the prescriptions [(nodes, order, values, who index)], those of dof
    kinds the element does not have dropped; a SceneError where a dof's values differ by more
    than 1e-12 relative, naming the two supports."""
    kinds = list(element.node_dofs)
    nd = len(kinds)
    parts = [(nodes * nd + kinds.index(order), values, wi) for nodes, order, values, wi in rows
             if order in kinds and len(nodes)]
    if not parts:
        return np.zeros(0, dtype=int), np.zeros(0)
    dof, val, wi = (np.concatenate(v) for v in zip(*parts))
    by = np.argsort(dof, kind="stable")
    dof, val, wi = dof[by].astype(int), val[by].astype(float), wi[by]
    first = np.r_[True, dof[1:] != dof[:-1]]
    lead = np.maximum.accumulate(np.where(first, np.arange(len(dof)), 0))
    ref = val[lead]
    tol = 1e-12 * np.maximum(1.0, np.maximum(np.abs(val), np.abs(ref)))
    bad = np.flatnonzero(np.abs(val - ref) > tol)
    if bad.size:
        b = bad[0]
        raise SceneError(f"{who[wi[b]]} and {who[wi[lead[b]]]} prescribe different values of "
                         f"{element.dof_names[dof[b] % nd]} at their common node; make them agree")
    return dof[first], val[first]


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
