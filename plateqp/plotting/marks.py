"""What every plan-view map shares (grid or triangles): the supports' markers (filled in contact,
hollow lifted off, shaped and coloured by the sign of their gap), the bed's contact nodes, point
loads, their legend entries, the normalised section lines, the axes over the plate and the
plate's outline."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .data import _bbox, _bed, _point_loads, _supports
from .style import _frame, _gap_style

if TYPE_CHECKING:  # pragma: no cover
    from ..results import Result


def _draw_supports(ax, result: Result, *, all_active: bool = False, size: float = 42):
    """Support markers on a plan view: filled in contact, hollow lifted off, shaped by gap sign."""
    sup = _supports(result)
    on = np.ones(sup.n, dtype=bool) if all_active else sup.active
    kind = np.sign(sup.g0)
    for k in (-1.0, 0.0, 1.0):
        col, mk, _ = _gap_style(k)
        for filled in (True, False):
            sel = (kind == k) & (on == filled)
            if sel.any():
                ax.scatter(sup.xy[sel, 0], sup.xy[sel, 1], s=size, marker=mk, edgecolors=col,
                           facecolors=(col if filled else "white"), linewidths=1.2, zorder=5, clip_on=False)
    bxy, bon = _bed(result)
    if bxy.size:
        on = np.ones_like(bon) if all_active else bon
        ax.scatter(bxy[on, 0], bxy[on, 1], s=6, c="k", marker=".", zorder=4, clip_on=False)
        ax.scatter(bxy[~on, 0], bxy[~on, 1], s=6, facecolors="none", edgecolors="0.4", marker="o",
                   linewidths=0.5, zorder=4, clip_on=False)
    for ld in _point_loads(result.scene):
        ax.scatter(ld.x, ld.y, s=90, marker="X", c="tab:orange", edgecolors="k", linewidths=0.8, zorder=6)


def _legend_handles(result: Result, *, all_active: bool = False):
    """Legend entries for the support markers present in a figure."""
    from matplotlib.lines import Line2D

    sup = _supports(result)
    hs = []
    kinds = {_gap_style(g)[2] for g in sup.g0}
    txt = {"level": "support, level (g0 = 0)", "heaved": "support, heaved (g0 < 0)",
           "settled": "support, settled (g0 > 0)"}
    for g0 in (0.0, -1.0, 1.0):
        col, mk, kind = _gap_style(g0)
        if kind in kinds:
            hs.append(Line2D([], [], ls="none", marker=mk, mec=col, mfc=col, label=txt[kind]))
    if sup.n:
        hs.append(Line2D([], [], ls="none", marker="s", mec="0.45", mfc="0.45", label="filled: in contact"))
        if not all_active and not sup.active.all():
            hs.append(Line2D([], [], ls="none", marker="s", mec="0.45", mfc="white", label="hollow: lifted off"))
    bxy, _ = _bed(result)
    if bxy.size:
        hs.append(Line2D([], [], ls="none", marker=".", color="k", label="bed node"))
    if _point_loads(result.scene):
        hs.append(Line2D([], [], ls="none", marker="X", mfc="tab:orange", mec="k", ms=9, label="point load"))
    return hs



def _norm_sections(sections, result):
    if sections is None:
        return []
    out = []
    for sec in sections:
        if len(sec) == 3:
            lab, p0, p1 = sec
        else:
            p0, p1 = sec
            lab = f"({p0[0]:g}, {p0[1]:g}) – ({p1[0]:g}, {p1[1]:g})"
        out.append((str(lab), (float(p0[0]), float(p0[1])), (float(p1[0]), float(p1[1]))))
    return out


def _supports_on_surface(ax, result: Result, handles: list) -> None:
    """The one-sided supports on a 3-d deflection surface (filled in contact, hollow lifted off),
    and their legend entries appended to ``handles``."""
    from matplotlib.lines import Line2D

    sup = _supports(result)
    if not sup.n:
        return
    wsup = np.atleast_1d(result.deflection(sup.xy[:, 0], sup.xy[:, 1]))
    on = sup.active
    ax.scatter(sup.xy[on, 0], sup.xy[on, 1], wsup[on], c="k", s=18, depthshade=False, zorder=4)
    ax.scatter(sup.xy[~on, 0], sup.xy[~on, 1], wsup[~on], facecolors="white", edgecolors="k", s=18,
               depthshade=False, zorder=4)
    handles.append(Line2D([], [], ls="none", marker="o", mec="k", mfc="k", label="support in contact"))
    if not on.all():
        handles.append(Line2D([], [], ls="none", marker="o", mec="k", mfc="white", label="support lifted off"))


# -- axes and outline shared by the plan-view maps ---------------------------------------------
def _plan_axes(ax, result: Result, units, title: str | None = None, margin: float = 0.04):
    """Equal-aspect axes over the plate's bounding box with a margin, labelled with ``units``."""
    x0, x1, y0, y1 = _bbox(result)
    m = margin * max(x1 - x0, y1 - y0)
    _frame(ax, (x0 - m, x1 + m), (y0 - m, y1 + m), units, title)


def _draw_outline(ax, result: Result, lw: float = 1.2):
    """The plate's outline as its mesh gives it (``mesh.outline_paths()``): closed loops as
    polygons (the outer boundary gid "outline", holes gid "hole" filled white), separate sides as
    one line collection (gid "outline": a grid's kept cells' boundary sides, openings included)."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Polygon

    for gid, pts, closed in result.model.grid.outline_paths():
        if closed:
            ax.add_patch(Polygon(pts, closed=True, fill=(gid == "hole"), facecolor="white", edgecolor="k", lw=lw,
                                 zorder=2, gid=gid))
        else:
            ax.add_collection(LineCollection(pts, colors="k", linewidths=lw, zorder=2, gid=gid))
