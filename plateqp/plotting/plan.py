"""The plan view: the mesh with its two-sided edges and pins, the one-sided supports (filled in
contact, hollow lifted off, shaped and coloured by the sign of their gap), the bed's contact
nodes, point loads, reactions and the section lines drawn on the plate.

The axes, outline and markers every plan-view map shares are in :mod:`.marks`; here also the
choice of section lines (:func:`default_sections`, as the mesh chooses them). The mesh picks the
plan view that draws it (``mesh.plan_view``): a grid's here, a triangle mesh's in :mod:`.tri`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .data import _point_loads, _supports, support_spacing
from .marks import _draw_supports, _legend_handles, _norm_sections  # noqa: F401  (shared by the maps)
from .style import _figure, _fmt, _lab, _units

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..results import Result


# -- the mesh, the supports, their reactions --------------------------------------------------
def plot_mesh(result: Result, units=None, *, sections=None, annotate: bool = True,
              numbers: bool | None = None) -> Figure:
    """The mesh with the supports: filled in contact, hollow lifted off, heave/settlement marked.

    ``annotate``: write each in-contact support's reaction beside it (force units).
    ``numbers``: write the support numbers (1-based, scene order); default when ≤ 64 supports.
    ``sections``: section lines to draw and number (as for :func:`plot_sections`).
    """
    from .tri import plot_mesh_tri

    # the mesh picks its plan view: a grid's lines on the rectangle, or the cells on the true outline
    view = result.model.grid.plan_view(_plot_mesh_grid, plot_mesh_tri)
    return view(result, units, sections=sections, annotate=annotate, numbers=numbers)


def _plot_mesh_grid(result: Result, units=None, *, sections=None, annotate: bool = True,
                    numbers: bool | None = None) -> Figure:
    """The plan view of a grid (:func:`plot_mesh`): its lines, the removed cells hatched, the
    rectangle's named sides, the supports and reactions placed outward from its edges."""
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
    for name, e in sc.side_edges().items():
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
    dense = sup.n > 1 and support_spacing(sup.xy) < 0.1 * span
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


# -- section lines ----------------------------------------------------------------------------
def default_sections(result: Result) -> list[tuple[str, tuple[float, float], tuple[float, float]]]:
    """Section lines for a scene, as its mesh chooses them (``mesh.default_sections``): the rows
    of supports (up to six), else lines through the load.

    Rows: the distinct y of the supports when there are 2 to 6 of them with at least two
    supports each (the source paper's sections 1–5 through a grid of supports). Otherwise the
    horizontal and vertical lines through the largest point load (or the centre); on a grid also
    the bottom edge if supports stand on it, and the diagonal; on a triangle mesh each line is
    cut to its longest stretch on the plate (:mod:`plateqp.model.views`).
    """
    return result.model.grid.default_sections(result.scene)
