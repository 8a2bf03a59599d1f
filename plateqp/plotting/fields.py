"""Fields over the plate: the deflection surface (axonometric), contour maps of w, principal
stresses, and the one-sided minus two-sided difference map.

w is positive **downward**, so the surface's z axis is inverted and every colour bar says
so; one-sided results are coloured, two-sided ones a wire frame or the right-hand panel, on
the same levels and colour scale.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .data import _nodes, _w_grid
from .marks import _supports_on_surface
from .plan import _draw_supports, _legend_handles, _plan_axes
from .style import (ONE_SIDED, TWO_SIDED, _fig_legend, _figure, _fmt, _lab, _levels, _name, _range,
                    _stress_unit, _symmetric_or_not, _units, _w_label)

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..results import Result


# -- axonometric deflection surface -----------------------------------------------------------
def plot_deflection_surface(result: Result, two_sided: Result | None = None, units=None, *,
                            elev: float = 32.0, azim: float | None = None) -> Figure:
    """Axonometric view of w: one-sided as a coloured surface, two-sided as a wire frame.

    The z axis is inverted (w positive down is drawn downward). ``azim`` (degrees, matplotlib's
    convention): by default the view puts the largest one-sided |w|, when it lies off the
    centre, in front if it is a dip (w > 0) and at the back if it is a rise (w < 0), so that
    the rest of the plate hides neither.
    """
    import mpl_toolkits.mplot3d  # noqa: F401  (registers the 3d projection)

    from .tri import on_triangles, plot_surface_tri

    if on_triangles(result):
        return plot_surface_tri(result, two_sided, units, elev=elev, azim=azim)
    L = _units(units)[0]
    fig = _figure((8.4, 6.4))
    fig._plateqp_tight = True
    # computed_zorder off: the wire frame and the supports are drawn over the surface
    ax = fig.add_subplot(projection="3d", computed_zorder=False)
    X, Y = _nodes(result)
    W = result.w_nodes()
    fields = [W] + ([two_sided.w_nodes()] if two_sided is not None else [])
    lo, hi = _range(fields)
    norm, cmap = _symmetric_or_not(lo, hi)
    surf = ax.plot_surface(X, Y, W, cmap=cmap, norm=norm, rstride=1, cstride=1, linewidth=0.2,
                           edgecolor="0.3", alpha=0.92, antialiased=True, zorder=1)
    handles = []
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    what = (ONE_SIDED + " (surface)") if result.scene.one_sided else "deflection w (surface)"
    handles.append(Patch(facecolor=surf.get_cmap()(0.7), edgecolor="0.3", label=what))
    if two_sided is not None:
        ax.plot_wireframe(X, Y, two_sided.w_nodes(), color="k", linewidth=0.6, linestyles="--", zorder=3)
        handles.append(Line2D([], [], color="k", lw=0.8, ls="--", label=TWO_SIDED + " (wire frame)"))
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
    ax.set_box_aspect((1.0, result.model.grid.b / result.model.grid.a, 0.55))
    cb = fig.colorbar(surf, ax=ax, shrink=0.6, pad=0.16)  # room for a z label on the right
    cb.set_label(_w_label(units))
    ax.legend(handles=handles, loc="upper left", fontsize=8, framealpha=0.9)
    ax.set_title(f"{result.scene.name}: deflection w"
                 + (" (one-sided coloured, two-sided wire frame)" if two_sided is not None else ""))
    return fig


def _auto_azim(result: Result) -> float:
    """A view direction that shows the largest deflection (see :func:`plot_deflection_surface`)."""
    g = result.model.grid
    w, x, y = result.w_max()
    dx, dy = x - 0.5 * g.a, y - 0.5 * g.b
    if np.hypot(dx / g.a, dy / g.b) < 0.2:
        return -60.0  # matplotlib's default: the corner (a, 0) in front
    if w < 0:
        dx, dy = -dx, -dy
    # the viewer sits at azimuth atan2 of the direction it looks from; 15° off the diagonal
    corner = np.degrees(np.arctan2(np.sign(dy) or 1.0, np.sign(dx) or 1.0))
    return float(corner - 15.0)


# -- contour maps of w ------------------------------------------------------------------------
def plot_deflection_contours(result: Result, two_sided: Result | None = None, units=None, *,
                             levels: int = 20) -> Figure:
    """Contour maps of w, one-sided and two-sided side by side on the same levels (on a triangle
    mesh: ``tricontourf`` of the nodal w, :func:`.tri.plot_contours_tri`)."""
    from .tri import on_triangles, plot_contours_tri

    if on_triangles(result):
        return plot_contours_tri(result, two_sided, units, levels=levels)
    pairs = [(result, _name(result))] + ([(two_sided, TWO_SIDED)] if two_sided is not None else [])
    fig = _figure((6.0 * len(pairs) + 1.2, 6.2))
    axs = fig.subplots(1, len(pairs), squeeze=False)[0]
    grids = [_w_grid(r) for r, _ in pairs]
    X, Y = grids[0][0], grids[0][1]
    fields = [gr[2] for gr in grids]
    lev = _levels(fields, levels)
    norm, cmap = _symmetric_or_not(lev[0], lev[-1])
    cf = None
    for ax, (r, title), W in zip(axs, pairs, fields):
        cf = ax.contourf(X, Y, W, levels=lev, cmap=cmap, norm=norm)
        cs = ax.contour(X, Y, W, levels=lev, colors="k", linewidths=0.5)
        ax.clabel(cs, cs.levels[::2], fontsize=7, fmt=lambda v: f"{v:.3g}")
        _draw_supports(ax, result if r is result else r, all_active=(r is not result), size=34)
        wm, xm, ym = r.w_max()
        _plan_axes(ax, r, units, f"{title}\nmax |w| = {abs(wm):.4g} at ({xm:g}, {ym:g})")
    cb = fig.colorbar(cf, ax=list(axs), shrink=0.85)
    cb.set_label(_w_label(units))
    hs = _legend_handles(result)
    _fig_legend(fig, hs)
    fig.suptitle(f"{result.scene.name}: contour lines of w" + (" (right: every support made two-sided)"
                                                                if two_sided is not None else ""))
    return fig


# -- principal stress fields ------------------------------------------------------------------
def plot_principal_stress(result: Result, two_sided: Result | None = None, units=None, *,
                          quantity: str = "s1", levels: int = 14) -> Figure:
    """Principal stress σ1 (bottom face) of the one-sided and two-sided results side by side.

    Nodal values smoothed by :meth:`~plateqp.results.Result.nodal`; same colour scale in
    both panels; the largest σ1 of each is marked. On a triangle mesh: :func:`.tri.plot_principal_tri`.
    """
    from .tri import on_triangles, plot_principal_tri

    if on_triangles(result):
        return plot_principal_tri(result, two_sided, units, quantity=quantity, levels=levels)
    name = {"s1": "σ1", "s2": "σ2", "sx": "σx", "sy": "σy", "txy": "τxy"}.get(quantity, quantity)
    pairs = [(result, _name(result))] + ([(two_sided, TWO_SIDED)] if two_sided is not None else [])
    fig = _figure((6.0 * len(pairs) + 1.2, 6.2))
    axs = fig.subplots(1, len(pairs), squeeze=False)[0]
    X, Y = _nodes(result)
    fields = [r.nodal(quantity) for r, _ in pairs]
    lev = _levels(fields, levels)
    norm, cmap = _symmetric_or_not(lev[0], lev[-1])
    unit = _stress_unit(units)
    cf = None
    for ax, (r, title), S in zip(axs, pairs, fields):
        cf = ax.contourf(X, Y, S, levels=lev, cmap=cmap, norm=norm)
        ax.contour(X, Y, S, levels=lev, colors="k", linewidths=0.35)
        _draw_supports(ax, result if r is result else r, all_active=(r is not result), size=30)
        k = int(np.nanargmax(np.where(np.isfinite(S), S, -np.inf)))
        ym, xm = np.unravel_index(k, S.shape)
        xs, ys = X[ym, xm], Y[ym, xm]
        ax.plot(xs, ys, marker="+", color="k", ms=12, mew=1.5, zorder=7)
        ax.annotate(f"max {name} = {_fmt(S[ym, xm])}" + (f" {unit}" if unit else ""), (xs, ys), xytext=(8, 8),
                    textcoords="offset points", fontsize=8, zorder=8,
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "0.5", "alpha": 0.85})
        _plan_axes(ax, r, units, title)
    cb = fig.colorbar(cf, ax=list(axs), shrink=0.85)
    cb.set_label(_lab(f"{name}, bottom face", unit))
    from matplotlib.lines import Line2D

    hs = _legend_handles(result) + [Line2D([], [], ls="none", marker="+", color="k", ms=10, mew=1.5,
                                           label=f"largest {name}")]
    _fig_legend(fig, hs)
    fig.suptitle(f"{result.scene.name}: principal stress {name} (bottom face; tension > 0)")
    return fig


# -- one-sided minus two-sided ----------------------------------------------------------------
def plot_difference(result: Result, two_sided: Result, units=None, *, zones: np.ndarray | None = None,
                    levels: int = 20) -> Figure:
    """w(one-sided) − w(two-sided) as a contour map, with the contact / lift-off zones marked.

    ``zones``: optional (ny+1, nx+1) array of +1 (contact zone), −1 (lift-off zone), 0 (neither)
    per node, as :func:`plateqp.demo.zones` returns. On a triangle mesh (:func:`.tri.plot_difference_tri`)
    ``zones`` is not drawn.
    """
    from .tri import on_triangles, plot_difference_tri

    if on_triangles(result):
        return plot_difference_tri(result, two_sided, units, levels=levels)
    from matplotlib.lines import Line2D

    L = _units(units)[0]
    fig = _figure((7.6, 7.4))
    ax = fig.add_subplot()
    X, Y, W1 = _w_grid(result)
    dW = W1 - _w_grid(two_sided)[2]
    lev = _levels([dW], levels)
    norm, cmap = _symmetric_or_not(lev[0], lev[-1])
    cf = ax.contourf(X, Y, dW, levels=lev, cmap=cmap, norm=norm)
    ax.contour(X, Y, dW, levels=lev, colors="k", linewidths=0.35)
    handles = []
    if zones is not None:
        zones = np.asarray(zones)
        Xn, Yn = _nodes(result)
        for val, col, lab in ((1, "tab:green", "contact zone"), (-1, "tab:orange", "lift-off zone")):
            sel = zones == val
            if sel.any():
                ax.scatter(Xn[sel], Yn[sel], s=9, c=col, marker="s", alpha=0.8, zorder=4, linewidths=0)
                handles.append(Line2D([], [], ls="none", marker="s", color=col, ms=5, label=f"node in the {lab}"))
    _draw_supports(ax, result, size=40)
    handles += _legend_handles(result)
    cb = fig.colorbar(cf, ax=ax, shrink=0.85)
    cb.set_label(_lab("w one-sided − w two-sided", L) + ", positive down")
    _plan_axes(ax, result, units, f"{result.scene.name}: one-sided minus two-sided deflection\n"
                                  f"(max |Δw| = {np.nanmax(np.abs(dW)):.3g})")
    _fig_legend(fig, handles)
    return fig
