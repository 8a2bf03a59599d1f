"""The plan view of a shaped plate (a triangle mesh, ``mesh.element = "dkt"``): the true outline
with its holes, the triangles, the edges by kind, and its section lines.

:func:`plateqp.plotting.plan.plot_mesh` draws with the function here where the mesh picks it
(``mesh.plan_view``), so callers use one name for both kinds of mesh. The conventions are
theirs (supports filled in contact and hollow lifted off, coloured by the sign of their gap,
numbered from 1). The field maps are one path for every mesh (:mod:`.fields`); the section lines
are the mesh's own (``mesh.default_sections``: :func:`plateqp.model.views.cut_sections`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .data import _supports, _triangulation
from .marks import _draw_outline, _plan_axes
from .style import _figure, _fmt, _units

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..results import Result


# -- plan view --------------------------------------------------------------------------------
def plot_mesh_tri(result: Result, units=None, *, sections=None, annotate: bool = True,
                  numbers: bool | None = None) -> Figure:
    """The triangle mesh on the true outline, the two-sided edges by kind, pins, the supports
    (filled in contact, hollow lifted off, numbered from 1) and their reactions, the sections."""
    from matplotlib.collections import LineCollection
    from matplotlib.lines import Line2D

    from ..model.constraints import edge_table
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
    _plan_axes(ax, result, units, margin=0.1)
    title = f"{sc.name}: mesh and supports"
    if sup.n:
        title += f", {int(sup.active.sum())} of {sup.n} in contact"
    ax.set_title(title)
    fig.legend(handles=handles, loc="outside right upper", fontsize=8)
    return fig
