"""Line and bar charts: w along section lines, the support reactions, and relative changes
under mesh refinement (log–log)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from .data import _bbox, _supports, _w_at, support_spacing
from .plan import _norm_sections, default_sections
from .style import (HEAVE_COLOR, LEVEL_BAR, ONE_SIDED, SETTLE_COLOR, TWO_SIDED, _fig_legend, _figure,
                    _gap_style, _lab, _name, _units)

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..results import Result


# -- w along section lines --------------------------------------------------------------------
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
    x0, x1, y0, y1 = _bbox(result)
    span = max(x1 - x0, y1 - y0)
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


# -- reactions --------------------------------------------------------------------------------
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
    pos, along = result.model.grid.contour_position(sup.xy)  # a shaped plate: (…, False), by number
    if along:
        order = np.argsort(pos)
        x = pos[order]
        width = 0.8 * support_spacing(sup.xy) if sup.n > 1 else 1.0
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


# -- convergence ------------------------------------------------------------------------------
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
