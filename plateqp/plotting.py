"""Figures of a solved plate: matplotlib, imported lazily, no pyplot state.

Every function takes a :class:`~plateqp.results.Result` (and, where it compares, the
two-sided :class:`~plateqp.results.Result` of :func:`plateqp.solve_bilateral`) and returns a
:class:`matplotlib.figure.Figure`. The figures are built on ``matplotlib.figure.Figure``
directly, never through ``pyplot``: nothing global is touched (no backend switch, no figure
registry), and :func:`save` renders them with the Agg canvas, so they work headless.

Conventions in every figure: w is positive **downward** (the direction of the load), so
deflection axes are inverted (down is down) and say so in their label. One-sided results
are drawn solid / coloured, two-sided results dashed / as a wire frame, as in the source
paper. Supports: filled marker = in contact, hollow = lifted off; red ▲ = heaved (g0 < 0),
blue ▼ = settled (g0 > 0), black ● = level (g0 = 0); reactions in force units.

``units``: an optional pair (length, force), e.g. ``("cm", "kgf")``; the axis labels then
carry the units (stresses in force/length², reactions in force).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from .results import Result

ONE_SIDED = "one-sided supports"
TWO_SIDED = "two-sided supports"
HEAVE_COLOR = "tab:red"
SETTLE_COLOR = "tab:blue"
LEVEL_COLOR = "black"
LEVEL_BAR = "0.5"


# -- small helpers ----------------------------------------------------------------------------
def _figure(figsize):
    from matplotlib.figure import Figure

    return Figure(figsize=figsize, layout="constrained")


def _lab(name: str, unit: str | None) -> str:
    return f"{name} ({unit})" if unit else name


def _units(units) -> tuple[str | None, str | None]:
    if units is None:
        return None, None
    if len(units) != 2:
        raise ValueError(f"units must be a pair (length, force), e.g. ('cm', 'kgf'); got {units!r}")
    return units[0], units[1]


def _stress_unit(units) -> str | None:
    L, F = _units(units)
    return f"{F}/{L}²" if L and F else None


def _w_label(units) -> str:
    return _lab("w", _units(units)[0]) + ", positive down"


def _fmt(v: float) -> str:
    """A force or length for an annotation: 13,368 / 412 / 0.0523."""
    a = abs(v)
    if a >= 100:
        return f"{v:,.0f}"
    if a >= 1 or a == 0:
        return f"{v:.3g}"
    return f"{v:.2g}"


def _fig_legend(fig, handles, ncol: int = 4) -> None:
    """A legend below the panels (none when there is nothing to explain)."""
    if handles:
        fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), ncol), fontsize=8)


def save(fig: Figure, path: str | Path, dpi: int = 110) -> Path:
    """Write a figure as PNG (Agg); returns the path.

    The figures use constrained layout with everything inside their axes or legends, so only
    the 3D one and the mesh need a "tight" bounding box (a second full draw).
    """
    path = Path(path)
    fig.savefig(path, dpi=dpi, format="png", **_bbox(fig))
    return path


def png_bytes(fig: Figure, dpi: int = 110) -> bytes:
    """A figure as PNG bytes (for embedding)."""
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, **_bbox(fig))
    return buf.getvalue()


def _bbox(fig) -> dict:
    # 3D axes place their labels where constrained layout cannot see them (and see plot_mesh)
    return {"bbox_inches": "tight", "pad_inches": 0.15} if getattr(fig, "_plateqp_tight", False) else {}


@dataclass
class _Supports:
    """The discrete one-sided supports of a result, as arrays (scene order)."""

    xy: np.ndarray
    g0: np.ndarray
    active: np.ndarray
    R: np.ndarray
    s: np.ndarray  # spring compression (0 for rigid)
    rigid: np.ndarray
    stiffness: np.ndarray  # NaN for rigid

    @property
    def n(self) -> int:
        return self.xy.shape[0]


def _supports(result: Result) -> _Supports:
    sc = result.scene
    n = len(sc.supports)
    xy = np.array([[s.x, s.y] for s in sc.supports], dtype=float).reshape(n, 2)
    g0 = np.array([s.gap for s in sc.supports], dtype=float)
    rigid = np.array([s.rigid for s in sc.supports], dtype=bool)
    c = np.array([np.nan if s.rigid else float(s.stiffness) for s in sc.supports])
    if result.reactions.size >= n:
        active = np.asarray(result.active[:n], dtype=bool)
        R = np.asarray(result.reactions[:n], dtype=float)
        s = np.asarray(result.compressions[:n], dtype=float) if result.compressions.size >= n else np.zeros(n)
    else:
        active, R, s = np.ones(n, dtype=bool), np.zeros(n), np.zeros(n)
    return _Supports(xy, g0, active, R, s, rigid, c)


def _bed(result: Result):
    """(xy, active) of the tensionless bed's contact nodes, if any."""
    m = result.model.contacts
    if m is None or result.active.size == 0:
        return np.zeros((0, 2)), np.zeros(0, dtype=bool)
    bed = m.source == "bed"
    return m.xy[bed], np.asarray(result.active, dtype=bool)[bed]


def _nodes(result: Result):
    g = result.model.grid
    x = np.linspace(0.0, g.a, g.nx + 1)
    y = np.linspace(0.0, g.b, g.ny + 1)
    return np.meshgrid(x, y)


def _name(result: Result) -> str:
    """What a result is called in titles and legends."""
    return ONE_SIDED if result.scene.one_sided else "two-sided supports only"


def _point_loads(scene):
    return [ld for ld in scene.loads if ld.type == "point"]


def _gap_style(g0: float):
    """(colour, marker, kind) of a support by the sign of its initial gap."""
    if g0 < 0:
        return HEAVE_COLOR, "^", "heaved"
    if g0 > 0:
        return SETTLE_COLOR, "v", "settled"
    return LEVEL_COLOR, "o", "level"


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


def _plan_axes(ax, result: Result, units, title: str | None = None):
    g = result.model.grid
    L = _units(units)[0]
    ax.set_aspect("equal")
    ax.set_xlim(0.0, g.a)
    ax.set_ylim(0.0, g.b)
    ax.set_xlabel(_lab("x", L))
    ax.set_ylabel(_lab("y", L))
    if title:
        ax.set_title(title)


def _symmetric_or_not(vmin: float, vmax: float):
    """A linear norm and colour map for a field: diverging and centred on 0 when it has both signs."""
    from matplotlib.colors import Normalize

    if vmin < 0.0 < vmax:
        m = max(-vmin, vmax)
        return Normalize(vmin=-m, vmax=m), "coolwarm"
    return Normalize(vmin=vmin, vmax=vmax), ("viridis" if vmin >= 0 else "viridis_r")


def _range(fields) -> tuple[float, float]:
    vals = np.concatenate([np.asarray(f, dtype=float)[np.isfinite(f)] for f in fields])
    lo, hi = (float(vals.min()), float(vals.max())) if vals.size else (0.0, 1.0)
    if hi <= lo:
        hi = lo + (abs(lo) if lo else 1.0) * 1e-6
    return lo, hi


def _levels(fields, n: int) -> np.ndarray:
    """About n round contour levels covering the fields (0 among them when the sign changes)."""
    from matplotlib.ticker import MaxNLocator

    lo, hi = _range(fields)
    return MaxNLocator(nbins=n, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)


def _w_at(result: Result, x, y) -> np.ndarray:
    """w at points (arrays), NaN where there is no plate (openings)."""
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    cell = result.model.grid.locate(x.ravel(), y.ravel())[0]
    out = np.full(x.size, np.nan)
    ok = cell >= 0
    if ok.any():
        out[ok] = np.atleast_1d(result.deflection(x.ravel()[ok], y.ravel()[ok]))
    return out.reshape(x.shape)


def _w_grid(result: Result, refine: int = 4):
    """(X, Y, W) on the mesh refined ``refine`` times per cell (the element's own interpolation)."""
    g = result.model.grid
    X, Y = np.meshgrid(np.linspace(0.0, g.a, refine * g.nx + 1), np.linspace(0.0, g.b, refine * g.ny + 1))
    return X, Y, _w_at(result, X, Y)


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


# -- 1. axonometric deflection surface ----------------------------------------------------------
def plot_deflection_surface(result: Result, two_sided: Result | None = None, units=None, *,
                            elev: float = 32.0, azim: float | None = None) -> Figure:
    """Axonometric view of w: one-sided as a coloured surface, two-sided as a wire frame.

    The z axis is inverted (w positive down is drawn downward). ``azim`` (degrees, matplotlib's
    convention): by default the view puts the largest one-sided |w|, when it lies off the
    centre, in front if it is a dip (w > 0) and at the back if it is a rise (w < 0), so that
    the rest of the plate hides neither.
    """
    import mpl_toolkits.mplot3d  # noqa: F401  (registers the 3d projection)

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
    sup = _supports(result)
    if sup.n:
        wsup = np.atleast_1d(result.deflection(sup.xy[:, 0], sup.xy[:, 1]))
        on = sup.active
        ax.scatter(sup.xy[on, 0], sup.xy[on, 1], wsup[on], c="k", s=18, depthshade=False, zorder=4)
        ax.scatter(sup.xy[~on, 0], sup.xy[~on, 1], wsup[~on], facecolors="white", edgecolors="k", s=18,
                   depthshade=False, zorder=4)
        handles.append(Line2D([], [], ls="none", marker="o", mec="k", mfc="k", label="support in contact"))
        if not on.all():
            handles.append(Line2D([], [], ls="none", marker="o", mec="k", mfc="white", label="support lifted off"))
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


# -- 2. contour maps ------------------------------------------------------------------------
def plot_deflection_contours(result: Result, two_sided: Result | None = None, units=None, *,
                             levels: int = 20) -> Figure:
    """Contour maps of w, one-sided and two-sided side by side on the same levels."""
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


# -- 3. mesh, supports, reactions ---------------------------------------------------------------
def plot_mesh(result: Result, units=None, *, sections=None, annotate: bool = True,
              numbers: bool | None = None) -> Figure:
    """The mesh with the supports: filled in contact, hollow lifted off, heave/settlement marked.

    ``annotate``: write each in-contact support's reaction beside it (force units).
    ``numbers``: write the support numbers (1-based, scene order); default when ≤ 64 supports.
    ``sections``: section lines to draw and number (as for :func:`plot_sections`).
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Rectangle

    L, F = _units(units)
    sc = result.scene
    g = result.model.grid
    fig = _figure((8.6, 7.0))
    fig._plateqp_tight = True  # constrained layout misjudges this equal-aspect axes beside an outside legend
    ax = fig.add_subplot()
    # mesh lines and removed cells
    from matplotlib.collections import LineCollection

    segs = [[(i * g.hx, 0.0), (i * g.hx, g.b)] for i in range(g.nx + 1)]
    segs += [[(0.0, j * g.hy), (g.a, j * g.hy)] for j in range(g.ny + 1)]
    ax.add_collection(LineCollection(segs, colors="0.8", linewidths=0.5, zorder=1))
    for c in np.flatnonzero(~g.cell_mask):
        ax.add_patch(Rectangle(((c % g.nx) * g.hx, (c // g.nx) * g.hy), g.hx, g.hy, facecolor="0.92",
                               hatch="///", edgecolor="0.7", lw=0.0, zorder=1))
    handles = [Line2D([], [], color="0.8", lw=0.8, label=f"mesh {g.nx} × {g.ny} ({sc.mesh.element.upper()})")]
    # two-sided edges and pins
    edge_lines = {"left": ([0, 0], [0, g.b]), "right": ([g.a, g.a], [0, g.b]),
                  "bottom": ([0, g.a], [0, 0]), "top": ([0, g.a], [g.b, g.b])}
    seen = set()
    for name, e in sc.edges.items():
        if e.kind == "free":
            continue
        style = {"simple": {"color": "tab:green", "lw": 4}, "clamped": {"color": "tab:purple", "lw": 6}}[e.kind]
        ax.plot(*edge_lines[name], solid_capstyle="butt", zorder=3, clip_on=False, **style)
        if e.kind not in seen:
            handles.append(Line2D([], [], label=f"{e.kind} edge (two-sided)", **style))
            seen.add(e.kind)
    if sc.pins:
        ax.scatter([p.x for p in sc.pins], [p.y for p in sc.pins], marker="s", s=50, c="tab:green",
                   edgecolors="k", zorder=5, clip_on=False)
        handles.append(Line2D([], [], ls="none", marker="s", mfc="tab:green", mec="k", label="pin (two-sided)"))
    # supports
    sup = _supports(result)
    _draw_supports(ax, result, size=60 if sup.n <= 40 else 34)
    handles += _legend_handles(result)
    if sup.n and not sup.rigid.all():
        cs = np.unique(sup.stiffness[~sup.rigid])
        what = f"c = {cs[0]:.4g}" if cs.size == 1 else f"c = {cs.min():.3g} … {cs.max():.3g}"
        unit = f" {F}/{L}" if L and F else ""
        label = ("elastic supports, " if sup.rigid.sum() == 0 else f"{(~sup.rigid).sum()} elastic, ") + what + unit
        handles.append(Line2D([], [], ls="none", label=label))
    if numbers is None:
        numbers = 0 < sup.n <= 64
    span = max(g.a, g.b)
    dense = sup.n > 1 and _spacing(sup.xy) < 0.1 * span
    if annotate or numbers:
        for i in range(sup.n):
            d = _outward(sup.xy[i], g.a, g.b)
            on_tb = d[1] != 0 and d[0] == 0  # on the bottom or top edge (not a corner)
            rot = 90 if (dense and on_tb) else 0
            if annotate and sup.active[i]:
                ax.annotate(_fmt(sup.R[i]), sup.xy[i], xytext=(8 * d[0], 8 * d[1]), textcoords="offset points",
                            fontsize=7 if dense else 8, color="tab:brown", rotation=rot, zorder=7,
                            ha=_ha(d[0]) if not rot else "center", va=_va(d[1]), annotation_clip=False)
            if numbers:
                ax.annotate(str(i + 1), sup.xy[i], xytext=(-7 * d[0] if d.any() else -6, -7 * d[1] if d.any() else -6),
                            textcoords="offset points", fontsize=6 if dense else 7, color="0.35",
                            ha=_ha(-d[0] if d.any() else -1), va=_va(-d[1] if d.any() else -1), zorder=7)
        if annotate and sup.active.any():
            handles.append(Line2D([], [], ls="none", marker="$R$", color="tab:brown",
                                  label="reaction R" + (f" ({F})" if F else "")))
        if numbers:
            handles.append(Line2D([], [], ls="none", marker="$7$", color="0.35", label="support number"))
    # point loads
    for ld in _point_loads(sc):
        ax.annotate(f"P = {_fmt(ld.P)}" + (f" {F}" if F else ""), (ld.x, ld.y), xytext=(9, -12),
                    textcoords="offset points", fontsize=8, color="tab:orange", fontweight="bold", zorder=7)
    # sections: numbered beyond the plate's edge (past the reactions), at the start of the line,
    # or at its end when another section's number is already there
    placed: list[np.ndarray] = []
    for k, (_label, p0, p1) in enumerate(_norm_sections(sections, result), 1):
        ax.plot([p0[0], p1[0]], [p0[1], p1[1]], color="tab:purple", lw=1.0, ls=(0, (6, 3)), zorder=2)
        for a0, a1 in ((p0, p1), (p1, p0)):
            at = np.array(a0) + 0.13 * span * _unit(np.array(a0) - np.array(a1))
            if all(np.hypot(*(at - q)) > 0.06 * span for q in placed):
                break
        placed.append(at)
        ax.plot([a0[0], at[0]], [a0[1], at[1]], color="tab:purple", lw=0.6, ls=":", zorder=2)
        ax.annotate(str(k), at, fontsize=8, color="tab:purple", ha="center", va="center", annotation_clip=False,
                    bbox={"boxstyle": "circle,pad=0.2", "fc": "white", "ec": "tab:purple", "lw": 0.8}, zorder=8)
    if sections is not None and len(sections):
        handles.append(Line2D([], [], color="tab:purple", lw=1.0, ls=(0, (6, 3)), label="section line (numbered)"))
    m = 0.17 * span
    ax.set_aspect("equal")
    ax.set_xlim(-m, g.a + m)
    ax.set_ylim(-m, g.b + m)
    ax.add_patch(Rectangle((0, 0), g.a, g.b, fill=False, ec="k", lw=1.2, zorder=2))
    ax.set_xlabel(_lab("x", L))
    ax.set_ylabel(_lab("y", L))
    n_on = int(sup.active.sum())
    title = f"{sc.name}: mesh and supports"
    if sup.n:
        title += f", {n_on} of {sup.n} in contact"
    ax.set_title(title)
    fig.legend(handles=handles, loc="outside right upper", fontsize=8)
    return fig


def _spacing(xy: np.ndarray) -> float:
    """Median distance from a support to its nearest neighbour."""
    if xy.shape[0] < 2:
        return float("inf")
    d = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
    np.fill_diagonal(d, np.inf)
    return float(np.median(d.min(axis=1)))


def _outward(p, a: float, b: float) -> np.ndarray:
    """Unit-ish direction away from the plate at a boundary point; (1, 1)/√2 inside."""
    tol = 1e-9 * max(a, b)
    dx = -1.0 if p[0] <= tol else (1.0 if p[0] >= a - tol else 0.0)
    dy = -1.0 if p[1] <= tol else (1.0 if p[1] >= b - tol else 0.0)
    if dx == 0 and dy == 0:
        dx = dy = 1.0
    d = np.array([dx, dy])
    return d / np.hypot(*d)


def _ha(dx: float) -> str:
    return "left" if dx > 1e-9 else ("right" if dx < -1e-9 else "center")


def _va(dy: float) -> str:
    return "bottom" if dy > 1e-9 else ("top" if dy < -1e-9 else "center")


def _unit(d: np.ndarray) -> np.ndarray:
    n = float(np.hypot(*d))
    return d / n if n > 0 else np.array([0.0, 1.0])


# -- 4. sections -------------------------------------------------------------------------------
def default_sections(result: Result) -> list[tuple[str, tuple[float, float], tuple[float, float]]]:
    """Section lines for a scene: the rows of supports (up to six), else lines through the load.

    Rows: the distinct y of the supports when there are 2 to 6 of them with at least two
    supports each (the source paper's sections 1–5 through a grid of supports). Otherwise the
    horizontal and vertical lines through the largest point load (or the centre), the bottom
    edge if supports stand on it, and the diagonal.
    """
    sc = result.scene
    a, b = sc.plate.a, sc.plate.b
    sup = _supports(result)
    if sup.n:
        ys, counts = np.unique(np.round(sup.xy[:, 1], 9), return_counts=True)
        if 2 <= ys.size <= 6 and np.all(counts >= 2):
            return [(f"y = {y:g}", (0.0, float(y)), (a, float(y))) for y in ys]
    pl = _point_loads(sc)
    xl, yl = ((max(pl, key=lambda ld: abs(ld.P)).x, max(pl, key=lambda ld: abs(ld.P)).y) if pl else (a / 2, b / 2))
    out = [(f"y = {yl:g}", (0.0, yl), (a, yl)), (f"x = {xl:g}", (xl, 0.0), (xl, b))]
    if sup.n and np.any(np.abs(sup.xy[:, 1]) <= 1e-9 * max(a, b)):
        out.append(("y = 0 (edge)", (0.0, 0.0), (a, 0.0)))
    out.append(("diagonal", (0.0, 0.0), (a, b)))
    return out


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


def plot_sections(result: Result, two_sided: Result | None = None, sections=None, units=None, *,
                  n: int = 161) -> Figure:
    """w along section lines: solid one-sided, dashed two-sided, one panel per section.

    ``sections``: a list of (p0, p1) or (label, p0, p1), points (x, y); default
    :func:`default_sections`. The supports on a line are drawn at the height of their top
    (g0, plus the spring's compression), filled where in contact; the w axis is inverted.
    """
    L = _units(units)[0]
    secs = _norm_sections(sections if sections is not None else default_sections(result), result)
    k = len(secs)
    fig = _figure((8.6, 1.0 + 2.15 * k))
    axs = fig.subplots(k, 1, squeeze=False)[:, 0]
    sup = _supports(result)
    span = max(result.scene.plate.a, result.scene.plate.b)
    for j, (ax, (lab, p0, p1)) in enumerate(zip(axs, secs), 1):
        t = np.linspace(0.0, 1.0, n)
        px, py = p0[0] + t * (p1[0] - p0[0]), p0[1] + t * (p1[1] - p0[1])
        s = t * np.hypot(p1[0] - p0[0], p1[1] - p0[1])
        w1 = _w_at(result, px, py)
        ax.plot(s, w1, color="tab:blue", lw=1.8, label=_name(result))
        if two_sided is not None:
            w2 = _w_at(two_sided, px, py)
            ax.plot(s, w2, color="k", lw=1.2, ls="--", label=TWO_SIDED)
        ax.axhline(0.0, color="0.6", lw=0.6)
        # supports on this line
        if sup.n:
            d = np.array(p1) - np.array(p0)
            length = np.hypot(*d)
            rel = sup.xy - np.array(p0)
            t = rel @ d / length**2
            off = np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0]) / length
            on_line = (off <= 1e-6 * span) & (t >= -1e-9) & (t <= 1 + 1e-9)
            for i in np.flatnonzero(on_line):
                col, mk, _ = _gap_style(sup.g0[i])
                top = sup.g0[i] + sup.s[i]
                ax.scatter(t[i] * length, top, marker=mk, s=40, edgecolors=col,
                           facecolors=col if sup.active[i] else "white", zorder=5, linewidths=1.2, clip_on=False)
                ax.annotate(str(i + 1), (t[i] * length, top), xytext=(0, -6), textcoords="offset points",
                            fontsize=6.5, color="0.35", ha="center", va="top")
        ax.invert_yaxis()
        ax.set_ylabel(_lab("w", L) + "\n↓ positive down", fontsize=9)
        ax.set_title(f"section {j}: {lab}   ({p0[0]:g}, {p0[1]:g}) → ({p1[0]:g}, {p1[1]:g})", fontsize=9, loc="left")
        ax.grid(True, color="0.9")
        ax.margins(x=0.02, y=0.12)
        ax.set_xlabel(_lab("distance along the section", L), fontsize=9)
    handles = axs[0].get_legend_handles_labels()[0]
    from matplotlib.lines import Line2D

    if sup.n:
        handles += [Line2D([], [], ls="none", marker="o", mec="k", mfc="k",
                           label="support top (one-sided), in contact"),
                    Line2D([], [], ls="none", marker="o", mec="k", mfc="white",
                           label="support top (one-sided), lifted off")]
        if (sup.g0 < 0).any():
            handles.append(Line2D([], [], ls="none", marker="^", mec=HEAVE_COLOR, mfc=HEAVE_COLOR, label="heaved"))
        if (sup.g0 > 0).any():
            handles.append(Line2D([], [], ls="none", marker="v", mec=SETTLE_COLOR, mfc=SETTLE_COLOR, label="settled"))
    _fig_legend(fig, handles)
    fig.suptitle(f"{result.scene.name}: deflection along sections")
    return fig


# -- 5. principal stress fields ----------------------------------------------------------------
def plot_principal_stress(result: Result, two_sided: Result | None = None, units=None, *,
                          quantity: str = "s1", levels: int = 14) -> Figure:
    """Principal stress σ1 (bottom face) of the one-sided and two-sided results side by side.

    Nodal values smoothed by :meth:`~plateqp.results.Result.nodal`; same colour scale in
    both panels; the largest σ1 of each is marked.
    """
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


# -- 6. one-sided minus two-sided --------------------------------------------------------------
def plot_difference(result: Result, two_sided: Result, units=None, *, zones: np.ndarray | None = None,
                    levels: int = 20) -> Figure:
    """w(one-sided) − w(two-sided) as a contour map, with the contact / lift-off zones marked.

    ``zones``: optional (ny+1, nx+1) array of +1 (contact zone), −1 (lift-off zone), 0 (neither)
    per node, as :func:`plateqp.demo.zones` returns.
    """
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


# -- 7. reactions --------------------------------------------------------------------------------
def plot_reactions(result: Result, two_sided: Result | None = None, units=None) -> Figure:
    """Reactions support by support, one-sided (bars) and two-sided (dashed line with dots).

    When every support stands on the plate's edge the horizontal axis is the position along
    the contour, anticlockwise from (0, 0) (the source paper's contact pressure along an
    elastic contour); otherwise it is the support number.
    """
    L, F = _units(units)
    sc = result.scene
    sup = _supports(result)
    fig = _figure((10.0, 4.6))
    ax = fig.add_subplot()
    pos, along = _contour_position(sup.xy, sc.plate.a, sc.plate.b)
    if along:
        order = np.argsort(pos)
        x = pos[order]
        width = 0.8 * _spacing(sup.xy) if sup.n > 1 else 1.0
        ax.set_xlabel(_lab("position along the contour, anticlockwise from (0, 0)", L))
        a, b = sc.plate.a, sc.plate.b
        for c, txt in ((0.0, "(0, 0)"), (a, f"({a:g}, 0)"), (a + b, f"({a:g}, {b:g})"), (2 * a + b, f"(0, {b:g})"),
                       (2 * (a + b), "(0, 0)")):
            ax.axvline(c, color="0.7", lw=0.8, ls=":")
            ax.text(c, 1.0, f"corner {txt}", transform=ax.get_xaxis_transform(), fontsize=7, ha="center",
                    va="bottom", color="0.4")
    else:
        order = np.arange(sup.n)
        x = order + 1.0
        width = 0.8
        ax.set_xlabel("support number")
        if sup.n <= 40:
            ax.set_xticks(x)
    R1 = sup.R[order]
    colors = [_gap_style(g)[0] if g != 0 else LEVEL_BAR for g in sup.g0[order]]
    ax.bar(x, R1, width=width, color=colors, alpha=0.75)
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [Patch(color=LEVEL_BAR, alpha=0.75, label=ONE_SIDED + " (bars)")]
    lifted = ~sup.active[order]
    if lifted.any():
        ax.scatter(x[lifted], np.zeros(lifted.sum()), marker="o", facecolors="white", edgecolors="k", s=16, zorder=4)
        handles.append(Line2D([], [], ls="none", marker="o", mfc="white", mec="k", label="lifted off (R = 0)"))
    if two_sided is not None:
        R2 = np.asarray(two_sided.reactions[: sup.n])[order]
        ax.plot(x, R2, color="k", ls="--", lw=1.0, marker=".", ms=5)
        handles.append(Line2D([], [], color="k", ls="--", lw=1.0, marker=".", ms=5, label=TWO_SIDED))
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_ylabel(_lab("reaction R", F) + ", compression > 0")
    ax.grid(True, axis="y", color="0.9")
    if (sup.g0 < 0).any():
        handles.append(Patch(color=HEAVE_COLOR, alpha=0.75, label="one-sided, heaved support"))
    if (sup.g0 > 0).any():
        handles.append(Patch(color=SETTLE_COLOR, alpha=0.75, label="one-sided, settled support"))
    ax.legend(handles=handles, fontsize=8, loc="best")
    ax.set_title(f"{sc.name}: support reactions ({int(sup.active.sum())} of {sup.n} in contact)", pad=14)
    return fig


def _contour_position(xy: np.ndarray, a: float, b: float) -> tuple[np.ndarray, bool]:
    """Arc length along the boundary, anticlockwise from (0, 0), and whether all points are on it."""
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


# -- 8. convergence ------------------------------------------------------------------------------
def plot_convergence(meshes: Sequence, differences: Mapping[str, Sequence[float]] | Sequence[float],
                     target: float | None = None, *, xlabel: str = "mesh (cells per side)",
                     ylabel: str = "relative change between successive meshes", title: str | None = None) -> Figure:
    """Relative changes under mesh refinement, on log–log axes, with a target line.

    ``meshes``: mesh sizes, coarse to fine: cells per side (2, 4, 8, ...) or (nx, ny) pairs.
    ``differences``: for each quantity name, its relative changes, either one per mesh
    (drawn at that mesh; NaN where there is none, e.g. the ``diff`` of
    :class:`plateqp.studies.ConvergenceTable`: the change on halving each mesh) or one per
    pair of successive meshes (drawn at the finer one). A plain sequence is one quantity.
    ``target``: the tolerance, drawn as a horizontal line. Non-positive and NaN values are left
    out (a log scale cannot show them).
    """
    pairs = [tuple(m) if isinstance(m, (tuple, list, np.ndarray)) else (m,) for m in meshes]
    x_all = np.array([float(m[0]) for m in pairs])
    names = [f"{m[0]:g}×{m[-1]:g}" for m in pairs]
    if not isinstance(differences, Mapping):
        differences = {"relative change": differences}
    fig = _figure((7.4, 5.0))
    ax = fig.add_subplot()
    markers = "osD^vP*X"
    for k, (name, vals) in enumerate(differences.items()):
        v = np.asarray(vals, dtype=float)
        if v.size == x_all.size - 1:
            x = x_all[1:]
        elif v.size == x_all.size:
            x = x_all
        else:
            raise ValueError(f"differences[{name!r}] has {v.size} values for {x_all.size} meshes; "
                             f"give one per mesh or one per pair of successive meshes")
        ok = np.isfinite(v) & (v > 0)
        ax.loglog(x[ok], v[ok], marker=markers[k % len(markers)], lw=1.4, label=name)
    if target is not None:
        ax.axhline(target, color="tab:red", ls="--", lw=1.2, label=f"target {target:.3g}")
    ax.set_xscale("log", base=2)
    ax.set_xticks(x_all)
    ax.set_xticklabels(names)
    from matplotlib.ticker import NullLocator

    ax.xaxis.set_minor_locator(NullLocator())
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="major", color="0.9")
    ax.legend(fontsize=8)
    ax.set_title(title or "convergence under mesh halving")
    return fig
