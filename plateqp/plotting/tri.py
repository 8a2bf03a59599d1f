"""The figures of a result on a triangle mesh (``mesh.element = "dkt"``): the plan view on the true
outline with its holes, contour maps (``tricontourf``), the deflection surface (``plot_trisurf``).

The public functions of :mod:`.plan` and :mod:`.fields` hand a triangle-mesh result to the
functions here, so callers use one name for both kinds of mesh. The conventions are theirs (w
positive down, supports filled in contact and hollow lifted off, coloured by the sign of their
gap, numbered from 1). Fields come at the mesh's nodes: w is the node's own dof, stresses are
averaged over the triangles around a node (:class:`plateqp.post.TriNodalOperator`).

Section lines on a shaped plate (:func:`tri_sections`) are the horizontal and vertical lines
through the rows of supports (or the centre of the plate), cut to the longest stretch of each
that lies on the plate, so that every point of a section is on the plate.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .data import _supports
from .marks import _supports_on_surface
from .style import (ONE_SIDED, TWO_SIDED, _fig_legend, _figure, _fmt, _frame, _lab, _levels, _name, _range,
                    _stress_unit, _symmetric_or_not, _units, _w_label)

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..results import Result


def on_triangles(result) -> bool:
    """Whether ``result`` lies on a triangle mesh."""
    from ..trimesh import TriMesh

    return isinstance(getattr(result.model, "grid", None), TriMesh)


def outline_loops(mesh) -> list[tuple[int, np.ndarray]]:
    """The boundary as closed loops of node coordinates: [(boundary, (n, 2) points)], 0 the outer
    boundary, k ≥ 1 hole k − 1 (the mesh's boundary nodes in order along each loop)."""
    out = []
    for k in np.unique(mesh.boundary):
        e = mesh.edges[mesh.boundary == k]
        nxt = {int(i): int(j) for i, j in e}
        start = int(e[0, 0])
        seq, n = [start], nxt[start]
        while n != start and len(seq) <= len(e):
            seq.append(n)
            n = nxt.get(n, start)
        out.append((int(k), mesh.nodes[seq]))
    return out


def _triangulation(result):
    from matplotlib.tri import Triangulation

    mesh = result.model.grid
    return Triangulation(mesh.nodes[:, 0], mesh.nodes[:, 1], mesh.triangles)


def _bbox(result):
    x0, x1, y0, y1 = result.model.grid.domain.outer.bbox
    return x0, x1, y0, y1


def _draw_outline(ax, result, lw: float = 1.2):
    """The outer boundary and the holes as unfilled polygons (gid "outline" and "hole")."""
    from matplotlib.patches import Polygon

    for k, pts in outline_loops(result.model.grid):
        ax.add_patch(Polygon(pts, closed=True, fill=(k > 0), facecolor="white", edgecolor="k", lw=lw, zorder=2,
                             gid="outline" if k == 0 else "hole"))


def tri_plan_axes(ax, result, units, title: str | None = None, margin: float = 0.04):
    x0, x1, y0, y1 = _bbox(result)
    m = margin * max(x1 - x0, y1 - y0)
    _frame(ax, (x0 - m, x1 + m), (y0 - m, y1 + m), units, title)


# -- plan view --------------------------------------------------------------------------------
def plot_mesh_tri(result: Result, units=None, *, sections=None, annotate: bool = True,
                  numbers: bool | None = None) -> Figure:
    """The triangle mesh on the true outline, the two-sided edges by kind, pins, the supports
    (filled in contact, hollow lifted off, numbered from 1) and their reactions, the sections."""
    from matplotlib.collections import LineCollection
    from matplotlib.lines import Line2D

    from ..constraints import edge_table
    from .marks import _draw_supports, _legend_handles, _norm_sections

    L, F = _units(units)
    sc = result.scene
    mesh = result.model.grid
    fig = _figure((8.6, 7.0))
    fig._plateqp_tight = True
    ax = fig.add_subplot()
    ax.triplot(_triangulation(result), color="0.8", lw=0.4, zorder=1)
    _draw_outline(ax, result)
    handles = [Line2D([], [], color="0.8", lw=0.8, label=f"{len(mesh.triangles)} triangles, "
                      f"{mesh.n_nodes} nodes (size {mesh.size:g}, {sc.mesh.element.upper()})")]
    table = edge_table(sc, mesh.domain)
    styles = {"simple": {"color": "tab:green", "lw": 4}, "clamped": {"color": "tab:purple", "lw": 6}}
    for kind, style in styles.items():
        segs = [mesh.nodes[[i, j]] for (i, j), k, s in zip(mesh.edges, mesh.boundary, mesh.segment)
                if (e := table.get((int(k), int(s)), (None, None))[1]) is not None and e.kind == kind]
        if segs:
            ax.add_collection(LineCollection(segs, zorder=3, capstyle="butt", gid=f"edge-{kind}", **style))
            handles.append(Line2D([], [], label=f"{kind} edge (two-sided)", **style))
    if sc.pins:
        ax.scatter([p.x for p in sc.pins], [p.y for p in sc.pins], marker="s", s=50, c="tab:green",
                   edgecolors="k", zorder=5)
        handles.append(Line2D([], [], ls="none", marker="s", mfc="tab:green", mec="k", label="pin (two-sided)"))
    sup = _supports(result)
    _draw_supports(ax, result, size=60 if sup.n <= 40 else 34)
    handles += _legend_handles(result)
    if numbers is None:
        numbers = 0 < sup.n <= 64
    for i in range(sup.n):
        if annotate and sup.active[i]:
            ax.annotate(_fmt(sup.R[i]), sup.xy[i], xytext=(7, 5), textcoords="offset points", fontsize=8,
                        color="tab:brown", zorder=7, gid="reaction")
        if numbers:
            ax.annotate(str(i + 1), sup.xy[i], xytext=(-7, -9), textcoords="offset points", fontsize=7,
                        color="0.35", ha="right", zorder=7, gid="support-number")
    if annotate and sup.active.any():
        handles.append(Line2D([], [], ls="none", marker="$R$", color="tab:brown",
                              label="reaction R" + (f" ({F})" if F else "")))
    if numbers and sup.n:
        handles.append(Line2D([], [], ls="none", marker="$7$", color="0.35", label="support number"))
    secs = _norm_sections(sections, result)
    for k, (_label, p0, p1) in enumerate(secs, 1):
        ax.plot([p0[0], p1[0]], [p0[1], p1[1]], color="tab:purple", lw=1.0, ls=(0, (6, 3)), zorder=2)
        ax.annotate(str(k), p0, xytext=(-10, 0), textcoords="offset points", fontsize=8, color="tab:purple",
                    ha="right", va="center", annotation_clip=False,
                    bbox={"boxstyle": "circle,pad=0.2", "fc": "white", "ec": "tab:purple", "lw": 0.8}, zorder=8)
    if secs:
        handles.append(Line2D([], [], color="tab:purple", lw=1.0, ls=(0, (6, 3)), label="section line (numbered)"))
    tri_plan_axes(ax, result, units, margin=0.1)
    title = f"{sc.name}: mesh and supports"
    if sup.n:
        title += f", {int(sup.active.sum())} of {sup.n} in contact"
    ax.set_title(title)
    fig.legend(handles=handles, loc="outside right upper", fontsize=8)
    return fig


# -- fields -----------------------------------------------------------------------------------
def _contours_in_outline(ax, tri, field, lev, cmap, norm, result, linewidth):
    """Filled contours of ``field`` with their lines, inside the plate's outline (drawn unfilled)."""
    cf = ax.tricontourf(tri, field, levels=lev, cmap=cmap, norm=norm)
    ax.tricontour(tri, field, levels=lev, colors="k", linewidths=linewidth)
    _draw_outline(ax, result)
    for p in ax.patches:
        if p.get_gid() == "outline":
            p.set_fill(False)
    return cf


def _contour_pair(result, two_sided, units, fields, levels, title, cbar_label, extra_handles=(), mark_max=None):
    from .marks import _draw_supports, _legend_handles

    pairs = [(result, _name(result))] + ([(two_sided, TWO_SIDED)] if two_sided is not None else [])
    fig = _figure((6.0 * len(pairs) + 1.2, 6.2))
    axs = fig.subplots(1, len(pairs), squeeze=False)[0]
    tri = _triangulation(result)
    lev = _levels(fields, levels)
    norm, cmap = _symmetric_or_not(lev[0], lev[-1])
    cf = None
    for ax, (r, sub), f in zip(axs, pairs, fields):
        cf = _contours_in_outline(ax, tri, f, lev, cmap, norm, r, 0.4)
        _draw_supports(ax, r, all_active=(r is not result), size=32)
        if mark_max is not None:
            mark_max(ax, r, f)
        tri_plan_axes(ax, r, units, sub)
    cb = fig.colorbar(cf, ax=list(axs), shrink=0.85)
    cb.set_label(cbar_label)
    _fig_legend(fig, _legend_handles(result) + list(extra_handles))
    fig.suptitle(title)
    return fig


def plot_contours_tri(result: Result, two_sided: Result | None = None, units=None, *, levels: int = 20) -> Figure:
    """Contour maps of w at the nodes (``tricontourf``), one-sided and two-sided on the same levels."""
    fields = [result.w_nodes()] + ([two_sided.w_nodes()] if two_sided is not None else [])
    return _contour_pair(result, two_sided, units, fields, levels,
                         f"{result.scene.name}: contour lines of w" + (" (right: every support made two-sided)"
                                                                      if two_sided is not None else ""),
                         _w_label(units), mark_max=None)


def plot_principal_tri(result: Result, two_sided: Result | None = None, units=None, *, quantity: str = "s1",
                       levels: int = 14) -> Figure:
    """σ1 (or another nodal quantity) of the one-sided and two-sided results (``tricontourf``)."""
    from matplotlib.lines import Line2D

    name = {"s1": "σ1", "s2": "σ2", "sx": "σx", "sy": "σy", "txy": "τxy"}.get(quantity, quantity)
    unit = _stress_unit(units)
    fields = [result.nodal(quantity)] + ([two_sided.nodal(quantity)] if two_sided is not None else [])

    def mark(ax, r, f):
        k = int(np.nanargmax(f))
        x, y = r.model.grid.nodes[k]
        ax.plot(x, y, marker="+", color="k", ms=12, mew=1.5, zorder=7)
        ax.annotate(f"max {name} = {_fmt(f[k])}" + (f" {unit}" if unit else ""), (x, y), xytext=(8, 8),
                    textcoords="offset points", fontsize=8, zorder=8,
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "0.5", "alpha": 0.85})

    extra = [Line2D([], [], ls="none", marker="+", color="k", ms=10, mew=1.5, label=f"largest {name}")]
    return _contour_pair(result, two_sided, units, fields, levels,
                         f"{result.scene.name}: principal stress {name} (bottom face; tension > 0)",
                         _lab(f"{name}, bottom face", unit), extra, mark)


def plot_difference_tri(result: Result, two_sided: Result, units=None, *, levels: int = 20) -> Figure:
    """w(one-sided) − w(two-sided) at the nodes as a contour map (``tricontourf``)."""
    from .marks import _draw_supports, _legend_handles

    L = _units(units)[0]
    fig = _figure((7.6, 7.4))
    ax = fig.add_subplot()
    dW = result.w_nodes() - two_sided.w_nodes()
    lev = _levels([dW], levels)
    norm, cmap = _symmetric_or_not(lev[0], lev[-1])
    tri = _triangulation(result)
    cf = _contours_in_outline(ax, tri, dW, lev, cmap, norm, result, 0.35)
    _draw_supports(ax, result, size=40)
    cb = fig.colorbar(cf, ax=ax, shrink=0.85)
    cb.set_label(_lab("w one-sided − w two-sided", L) + ", positive down")
    tri_plan_axes(ax, result, units, f"{result.scene.name}: one-sided minus two-sided deflection\n"
                                     f"(max |Δw| = {np.nanmax(np.abs(dW)):.3g})")
    _fig_legend(fig, _legend_handles(result))
    return fig


def plot_surface_tri(result: Result, two_sided: Result | None = None, units=None, *, elev: float = 32.0,
                     azim: float | None = None) -> Figure:
    """The deflection surface over the triangles (``plot_trisurf``), the z axis inverted; the
    two-sided result as the mesh's edges at its deflection (dashed)."""
    import mpl_toolkits.mplot3d  # noqa: F401  (registers the 3d projection)
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    L = _units(units)[0]
    fig = _figure((8.4, 6.4))
    fig._plateqp_tight = True
    ax = fig.add_subplot(projection="3d", computed_zorder=False)
    mesh = result.model.grid
    W = result.w_nodes()
    fields = [W] + ([two_sided.w_nodes()] if two_sided is not None else [])
    lo, hi = _range(fields)
    norm, cmap = _symmetric_or_not(lo, hi)
    surf = ax.plot_trisurf(mesh.nodes[:, 0], mesh.nodes[:, 1], W, triangles=mesh.triangles, cmap=cmap, norm=norm,
                           linewidth=0.0, antialiased=False, alpha=0.92, zorder=1)
    what = (ONE_SIDED + " (surface)") if result.scene.one_sided else "deflection w (surface)"
    handles = [Patch(facecolor=surf.get_cmap()(0.7), edgecolor="0.3", label=what)]
    if two_sided is not None:
        W2 = two_sided.w_nodes()
        t = mesh.triangles
        e = np.unique(np.sort(np.vstack([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1), axis=0)
        P = np.column_stack([mesh.nodes, W2])
        ax.add_collection3d(Line3DCollection(P[e], colors="k", linewidths=0.15, alpha=0.4, zorder=3))
        handles.append(Line2D([], [], color="k", lw=0.6, alpha=0.6, label=TWO_SIDED + " (mesh lines)"))
    _supports_on_surface(ax, result, handles)
    pad = 0.04 * (hi - lo)
    ax.set_zlim(hi + pad, lo - pad)  # inverted: w positive down is drawn downward
    ax.view_init(elev=elev, azim=-60.0 if azim is None else azim)
    ax.set_xlabel(_lab("x", L))
    ax.set_ylabel(_lab("y", L))
    ax.set_zlabel(_lab("w", L) + "\n(down, axis inverted)", labelpad=18)
    x0, x1, y0, y1 = _bbox(result)
    ax.set_box_aspect((1.0, (y1 - y0) / (x1 - x0), 0.55))
    cb = fig.colorbar(surf, ax=ax, shrink=0.6, pad=0.16)
    cb.set_label(_w_label(units))
    ax.legend(handles=handles, loc="upper left", fontsize=8, framealpha=0.9)
    ax.set_title(f"{result.scene.name}: deflection w"
                 + (" (one-sided coloured, two-sided mesh lines)" if two_sided is not None else ""))
    return fig


# -- section lines ----------------------------------------------------------------------------
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


def tri_sections(result) -> list[tuple[str, tuple[float, float], tuple[float, float]]]:
    """Section lines on a shaped plate: the rows of supports (2 to 6 distinct y with two or more
    supports each), else the horizontal and vertical lines through the largest point load (or
    the centre of the plate's bounding box), each cut to its longest stretch on the plate."""
    mesh = result.model.grid
    x0, x1, y0, y1 = _bbox(result)
    sup = _supports(result)
    lines = []
    if sup.n:
        ys, counts = np.unique(np.round(sup.xy[:, 1], 9), return_counts=True)
        if 2 <= ys.size <= 6 and np.all(counts >= 2):
            lines = [(f"y = {y:g}", (x0, float(y)), (x1, float(y))) for y in ys]
    if not lines:
        pl = [ld for ld in result.scene.loads if ld.type == "point"]
        if pl:
            ld = max(pl, key=lambda p: abs(p.P))
            xc, yc = ld.x, ld.y
        else:
            xc, yc = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
        lines = [(f"y = {yc:g}", (x0, yc), (x1, yc)), (f"x = {xc:g}", (xc, y0), (xc, y1))]
    out = []
    for lab, p0, p1 in lines:
        cut = _on_plate_stretch(mesh, p0, p1)
        if cut is not None:
            out.append((lab, *cut))
    return out
