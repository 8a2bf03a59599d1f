"""Fields over the plate: the deflection surface (axonometric), contour maps of w, principal
stresses, and the one-sided minus two-sided difference map.

One path for every mesh: the fields are the nodal values of the result (one per node of the
plate, ``mesh.nodes`` order), drawn on a matplotlib ``Triangulation`` of ``mesh.nodes`` and
``mesh.triangulation()`` (a structured grid's quads split along a diagonal for drawing only;
openings and holes have no triangles), with ``tricontourf`` and ``plot_trisurf``.

w is positive **downward**, so the surface's z axis is inverted and every colour bar says
so; one-sided results are coloured, two-sided ones the mesh's cell edges at their deflection
or the right-hand panel, on the same levels and colour scale.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .data import _bbox, _cell_edges, _triangulation
from .marks import _draw_outline, _draw_supports, _legend_handles, _plan_axes, _supports_on_surface
from .style import (ONE_SIDED, TWO_SIDED, _fig_legend, _figure, _fmt, _lab, _levels, _name, _range,
                    _stress_unit, _symmetric_or_not, _units, _w_label)

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..results import Result


# -- axonometric deflection surface -----------------------------------------------------------
def plot_deflection_surface(result: Result, two_sided: Result | None = None, units=None, *,
                            elev: float = 32.0, azim: float | None = None) -> Figure:
    """Axonometric view of w: one-sided as a coloured surface, two-sided as the cells' edges.

    The z axis is inverted (w positive down is drawn downward). ``azim`` (degrees, matplotlib's
    convention): by default the view puts the largest one-sided |w|, when it lies off the
    centre, in front if it is a dip (w > 0) and at the back if it is a rise (w < 0), so that
    the rest of the plate hides neither.
    """
    import mpl_toolkits.mplot3d  # noqa: F401  (registers the 3d projection)

    L = _units(units)[0]
    fig = _figure((8.4, 6.4))
    fig._plateqp_tight = True
    # computed_zorder off: the two-sided lines and the supports are drawn over the surface
    ax = fig.add_subplot(projection="3d", computed_zorder=False)
    mesh = result.model.grid
    W = result.w_nodes()
    fields = [W] + ([two_sided.w_nodes()] if two_sided is not None else [])
    lo, hi = _range(fields)
    norm, cmap = _symmetric_or_not(lo, hi)
    surf = ax.plot_trisurf(_triangulation(result), W, cmap=cmap, norm=norm, linewidth=0.0, antialiased=False,
                           alpha=0.92, zorder=1)
    handles = []
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    what = (ONE_SIDED + " (surface)") if result.scene.one_sided else "deflection w (surface)"
    handles.append(Patch(facecolor=surf.get_cmap()(0.7), edgecolor="0.3", label=what))
    if two_sided is not None:  # the cells' sides at the two-sided deflection
        from mpl_toolkits.mplot3d.art3d import Line3DCollection

        P = np.column_stack([mesh.nodes, fields[1]])
        ax.add_collection3d(Line3DCollection(P[_cell_edges(mesh)], colors="k", linewidths=0.4, alpha=0.6, zorder=3))
        handles.append(Line2D([], [], color="k", lw=0.8, alpha=0.6, label=TWO_SIDED + " (cell edges)"))
    _supports_on_surface(ax, result, handles)
    pad = 0.04 * (hi - lo)
    ax.set_zlim(hi + pad, lo - pad)  # inverted: w positive down is drawn downward
    ax.view_init(elev=elev, azim=_auto_azim(result) if azim is None else azim)
    ax.set_xlabel(_lab("x", L))
    ax.set_ylabel(_lab("y", L))
    from matplotlib.ticker import FuncFormatter, MaxNLocator

    ax.zaxis.set_major_locator(MaxNLocator(6))
    ax.zaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}"))
    ax.tick_params(axis="z", pad=6)
    ax.set_zlabel(_lab("w", L) + "\n(down, axis inverted)", labelpad=18)
    x0, x1, y0, y1 = _bbox(result)
    ax.set_box_aspect((1.0, (y1 - y0) / (x1 - x0), 0.55))
    cb = fig.colorbar(surf, ax=ax, shrink=0.6, pad=0.16)  # room for a z label on the right
    cb.set_label(_w_label(units))
    ax.legend(handles=handles, loc="upper left", fontsize=8, framealpha=0.9)
    ax.set_title(f"{result.scene.name}: deflection w"
                 + (" (one-sided coloured, two-sided cell edges)" if two_sided is not None else ""))
    return fig


def _auto_azim(result: Result) -> float:
    """A view direction that shows the largest deflection (see :func:`plot_deflection_surface`)."""
    x0, x1, y0, y1 = _bbox(result)
    w, x, y = result.w_max()
    a, b = x1 - x0, y1 - y0
    dx, dy = x - 0.5 * (x0 + x1), y - 0.5 * (y0 + y1)
    if np.hypot(dx / a, dy / b) < 0.2:
        return -60.0  # matplotlib's default: the corner (a, 0) in front
    if w < 0:
        dx, dy = -dx, -dy
    # the viewer sits at azimuth atan2 of the direction it looks from; 15° off the diagonal
    corner = np.degrees(np.arctan2(np.sign(dy) or 1.0, np.sign(dx) or 1.0))
    return float(corner - 15.0)


# -- contour maps ---------------------------------------------------------------------------
def _contours(ax, tri, field, lev, cmap, norm, result, linewidth, labels: bool = False):
    """Filled contours of a nodal ``field`` with their lines, and the plate's outline."""
    cf = ax.tricontourf(tri, field, levels=lev, cmap=cmap, norm=norm)
    cs = ax.tricontour(tri, field, levels=lev, colors="k", linewidths=linewidth)
    if labels:
        ax.clabel(cs, cs.levels[::2], fontsize=7, fmt=lambda v: f"{v:.3g}")
    _draw_outline(ax, result)
    return cf


def _contour_pair(result, two_sided, units, fields, levels, title, cbar_label, *, extra_handles=(),
                  mark=None, subtitle=None, labels=False):
    """One panel per result (one-sided, then two-sided) on the same levels and colours."""
    pairs = [(result, _name(result))] + ([(two_sided, TWO_SIDED)] if two_sided is not None else [])
    fig = _figure((6.0 * len(pairs) + 1.2, 6.2))
    axs = fig.subplots(1, len(pairs), squeeze=False)[0]
    tri = _triangulation(result)
    lev = _levels(fields, levels)
    norm, cmap = _symmetric_or_not(lev[0], lev[-1])
    cf = None
    for ax, (r, sub), f in zip(axs, pairs, fields):
        cf = _contours(ax, tri, f, lev, cmap, norm, r, 0.4, labels)
        _draw_supports(ax, r, all_active=(r is not result), size=32)
        if mark is not None:
            mark(ax, r, f)
        _plan_axes(ax, r, units, sub if subtitle is None else subtitle(r, sub))
    cb = fig.colorbar(cf, ax=list(axs), shrink=0.85)
    cb.set_label(cbar_label)
    _fig_legend(fig, _legend_handles(result) + list(extra_handles))
    fig.suptitle(title)
    return fig


def plot_deflection_contours(result: Result, two_sided: Result | None = None, units=None, *,
                             levels: int = 20) -> Figure:
    """Contour maps of the nodal w, one-sided and two-sided side by side on the same levels."""
    fields = [result.w_nodes()] + ([two_sided.w_nodes()] if two_sided is not None else [])

    def subtitle(r, sub):
        wm, xm, ym = r.w_max()
        return f"{sub}\nmax |w| = {abs(wm):.4g} at ({xm:g}, {ym:g})"

    return _contour_pair(result, two_sided, units, fields, levels,
                         f"{result.scene.name}: contour lines of w" + (" (right: every support made two-sided)"
                                                                      if two_sided is not None else ""),
                         _w_label(units), subtitle=subtitle, labels=True)


# -- principal stress fields ------------------------------------------------------------------
def plot_principal_stress(result: Result, two_sided: Result | None = None, units=None, *,
                          quantity: str = "s1", levels: int = 14) -> Figure:
    """Principal stress σ1 (bottom face) of the one-sided and two-sided results side by side.

    Nodal values smoothed by :meth:`~plateqp.results.Result.nodal`; same colour scale in
    both panels; the largest σ1 of each is marked.
    """
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
                         _lab(f"{name}, bottom face", unit), extra_handles=extra, mark=mark)


# -- one-sided minus two-sided ----------------------------------------------------------------
def plot_difference(result: Result, two_sided: Result, units=None, *, zones: np.ndarray | None = None,
                    levels: int = 20) -> Figure:
    """w(one-sided) − w(two-sided) at the nodes as a contour map, with the contact / lift-off zones marked.

    ``zones``: optional, one value per node of the plate (``mesh.nodes`` order): +1 (contact
    zone), −1 (lift-off zone), 0 (neither), as :func:`plateqp.demo.zones` returns.
    """
    from matplotlib.lines import Line2D

    L = _units(units)[0]
    fig = _figure((7.6, 7.4))
    ax = fig.add_subplot()
    dW = result.w_nodes() - two_sided.w_nodes()
    lev = _levels([dW], levels)
    norm, cmap = _symmetric_or_not(lev[0], lev[-1])
    cf = _contours(ax, _triangulation(result), dW, lev, cmap, norm, result, 0.35)
    handles = []
    if zones is not None:
        zones = np.asarray(zones)
        nodes = result.model.grid.nodes
        if zones.shape != (len(nodes),):
            from ..errors import PlateQPError

            raise PlateQPError(f"zones: one value per node of the plate, shape ({len(nodes)},); got {zones.shape}")
        for val, col, lab in ((1, "tab:green", "contact zone"), (-1, "tab:orange", "lift-off zone")):
            sel = zones == val
            if sel.any():
                ax.scatter(nodes[sel, 0], nodes[sel, 1], s=9, c=col, marker="s", alpha=0.8, zorder=4, linewidths=0)
                handles.append(Line2D([], [], ls="none", marker="s", color=col, ms=5, label=f"node in the {lab}"))
    _draw_supports(ax, result, size=40)
    handles += _legend_handles(result)
    cb = fig.colorbar(cf, ax=ax, shrink=0.85)
    cb.set_label(_lab("w one-sided − w two-sided", L) + ", positive down")
    _plan_axes(ax, result, units, f"{result.scene.name}: one-sided minus two-sided deflection\n"
                                  f"(max |Δw| = {np.nanmax(np.abs(dW)):.3g})")
    _fig_legend(fig, handles)
    return fig
