"""Figures of the source paper's stiffness studies (figures 5 and 6): the working schemes of a
stiffness path (one plan panel per scheme), w along section lines for each scheme, the
contact pressure along an elastic contour for several stiffnesses, and uniformity measures
against the dimensionless stiffness κ = c s²/D.

Support numbers in every figure are 1-based (scene order), as in the paper's figures.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..model.views import contour_position as _contour_position
from .data import _supports, _w_at
from .plan import _draw_supports, _legend_handles, _norm_sections
from .style import _fig_legend, _figure, _lab, _units

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..results import Result


def kappa_label(k: float) -> str:
    """κ for a title or legend: "rigid" for ∞, else three significant digits."""
    return "rigid" if math.isinf(k) else f"{k:.3g}"


def plot_schemes(results: Sequence[Result], titles: Sequence[str], units=None, *, ncol: int = 4) -> Figure:
    """One small plan panel per working scheme: supports filled in contact, hollow lifted off
    (red ▲ heaved), numbered 1-based; ``titles`` one line per panel (e.g. the κ interval)."""
    L = _units(units)[0]
    k = len(results)
    ncol = max(1, min(ncol, k))
    nrow = max(1, math.ceil(k / ncol))
    fig = _figure((2.6 * ncol + 0.4, 2.75 * nrow + 0.9))
    axs = fig.subplots(nrow, ncol, squeeze=False)
    for j, ax in enumerate(axs.flat):
        if j >= k:
            ax.set_axis_off()
            continue
        res = results[j]
        g = res.model.grid
        _draw_supports(ax, res, size=30)
        sup = _supports(res)
        span = max(g.a, g.b)
        for i in range(sup.n):
            ax.annotate(str(i + 1), sup.xy[i], xytext=(3, 3), textcoords="offset points", fontsize=5.5,
                        color="0.3", annotation_clip=False)
        ax.add_patch(_rect(g.a, g.b))
        ax.set_aspect("equal")
        m = 0.06 * span
        ax.set_xlim(-m, g.a + m)
        ax.set_ylim(-m, g.b + m)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(f"{j + 1}: {titles[j]}\n{int(sup.active.sum())} of {sup.n} in contact", fontsize=7.5)
    if results:
        _fig_legend(fig, _legend_handles(results[0]), ncol=4)
        fig.suptitle(f"working schemes (plan {results[0].model.grid.a:g} × {results[0].model.grid.b:g}"
                     + (f" {L}" if L else "") + ")", fontsize=10)
    return fig


def _rect(a: float, b: float):
    from matplotlib.patches import Rectangle

    return Rectangle((0, 0), a, b, fill=False, ec="k", lw=0.9, zorder=2)


def plot_scheme_sections(results: Sequence[Result], labels: Sequence[str], sections, units=None, *,
                         n: int = 161) -> Figure:
    """w along each section line (one panel per section), one curve per working scheme; the
    w axis points down (w positive down)."""
    import matplotlib as mpl

    L = _units(units)[0]
    secs = _norm_sections(sections, results[0]) if results else []
    fig = _figure((8.6, 1.2 + 2.6 * max(1, len(secs))))
    axs = fig.subplots(max(1, len(secs)), 1, squeeze=False)[:, 0]
    cmap = mpl.colormaps["viridis"]
    for j, (ax, (lab, p0, p1)) in enumerate(zip(axs, secs), 1):
        t = np.linspace(0.0, 1.0, n)
        px, py = p0[0] + t * (p1[0] - p0[0]), p0[1] + t * (p1[1] - p0[1])
        s = t * math.hypot(p1[0] - p0[0], p1[1] - p0[1])
        for k, (res, name) in enumerate(zip(results, labels)):
            col = cmap(k / max(1, len(results) - 1))
            ax.plot(s, _w_at(res, px, py), color=col, lw=1.4, label=name)
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.invert_yaxis()
        ax.set_ylabel(_lab("w", L) + "\n↓ positive down", fontsize=9)
        ax.set_xlabel(_lab("distance along the section", L), fontsize=9)
        ax.set_title(f"section {j}-{j}: {lab}   ({p0[0]:g}, {p0[1]:g}) → ({p1[0]:g}, {p1[1]:g})", fontsize=9,
                     loc="left")
        ax.grid(True, color="0.9")
    if secs:
        _fig_legend(fig, axs[0].get_legend_handles_labels()[0], ncol=4)
    return fig


def plot_contour_pressure(results: Sequence[Result], labels: Sequence[str], units=None) -> Figure:
    """Reactions of supports standing on the plate's edge against the position along the
    contour (anticlockwise from (0, 0)), one curve per stiffness; lifted-off supports at 0."""
    import matplotlib as mpl

    L, F = _units(units)
    fig = _figure((10.0, 4.8))
    ax = fig.add_subplot()
    cmap = mpl.colormaps["plasma"]
    for k, (res, name) in enumerate(zip(results, labels)):
        sup = _supports(res)
        a, b = res.scene.plate.a, res.scene.plate.b
        pos, along = _contour_position(sup.xy, a, b)
        if not along:
            raise ValueError("plot_contour_pressure: every support must stand on the plate's edge")
        o = np.argsort(pos)
        ax.plot(pos[o], sup.R[o], color=cmap(0.85 * k / max(1, len(results) - 1)), lw=1.4, marker=".", ms=4,
                label=name)
    if results:
        a, b = results[0].scene.plate.a, results[0].scene.plate.b
        for c in (0.0, a, a + b, 2 * a + b, 2 * (a + b)):
            ax.axvline(c, color="0.7", lw=0.8, ls=":")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel(_lab("position along the contour, anticlockwise from (0, 0); dotted: corners", L))
    ax.set_ylabel(_lab("reaction R per support", F))
    ax.grid(True, color="0.9")
    ax.legend(fontsize=8, loc="best")
    ax.set_title("contact pressure along the elastic contour")
    return fig


def plot_uniformity(kappas: Sequence[float], measures: Mapping[str, Sequence[float]],
                    optima: Mapping[str, float] | None = None, marks: Mapping[str, float] | None = None) -> Figure:
    """Uniformity measures against κ (log axis), their minima (``optima``: measure → κ) marked;
    ``marks``: other κ values to draw as labelled vertical lines (e.g. the paper's value)."""
    fig = _figure((7.6, 4.8))
    ax = fig.add_subplot()
    k = np.asarray(kappas, dtype=float)
    o = np.argsort(k)
    for j, (name, vals) in enumerate(measures.items()):
        v = np.asarray(vals, dtype=float)
        line, = ax.semilogx(k[o], v[o], marker="osD"[j % 3], ms=3.5, lw=1.3, label=name)
        if optima and name in optima and math.isfinite(optima[name]):
            ax.axvline(optima[name], color=line.get_color(), lw=0.9, ls="--")
    for name, kv in (marks or {}).items():
        ax.axvline(kv, color="0.3", lw=1.0, ls=":")
        ax.text(kv, 0.98, f" {name}", transform=ax.get_xaxis_transform(), fontsize=7.5, va="top", rotation=90)
    ax.set_xlabel("κ = c s² / D  (stiffer →)")
    ax.set_ylabel("measure (0 = uniform; peak/mean: 1)")
    ax.grid(True, which="both", color="0.92")
    ax.legend(fontsize=8, title="dashed: minimum", title_fontsize=8)
    ax.set_title("uniformity of the contact pressure against the support stiffness")
    return fig


def plot_regulation(before: Result, runs: Sequence, units=None) -> Figure:
    """The gap-regulation study: reactions per support before and after each regulation (left),
    the gap change each regulation asks (right); regulated supports hatched, numbered 1-based.
    ``runs``: objects with ``name``, ``supports`` (0-based), ``gaps_before``, ``gaps`` and
    ``check`` (the Result of solving the regulated scene)."""
    L, F = _units(units)
    fig = _figure((11.0, 4.6))
    axR, axG = fig.subplots(1, 2, gridspec_kw={"width_ratios": [3, 2]})
    m = before.reactions.size
    ids = np.arange(1, m + 1)
    width = 0.8 / (1 + len(runs))
    axR.bar(ids - 0.4 + width / 2, before.reactions, width, color="0.6", label="as it is")
    for j, r in enumerate(runs, 1):
        hatch = np.zeros(m, dtype=bool)
        hatch[np.asarray(r.supports)] = True
        bars = axR.bar(ids - 0.4 + width * (j + 0.5), r.check.reactions, width, label=f"{r.name} (checked)")
        for b, h in zip(bars, hatch):
            if h:
                b.set_hatch("///")
        axG.bar(ids - 0.4 + width * (j + 0.5), np.asarray(r.gaps) - np.asarray(r.gaps_before), width,
                color=bars[0].get_facecolor(), label=r.name)
    for ax in (axR, axG):
        ax.set_xticks(ids)
        ax.tick_params(axis="x", labelsize=7)
        ax.set_xlabel("support (hatched: regulated)")
        ax.grid(True, axis="y", color="0.9")
        ax.axhline(0.0, color="k", lw=0.6)
    axR.set_ylabel(_lab("reaction R", F))
    axR.set_title("reactions: as it is and after each regulation")
    axR.legend(fontsize=8)
    axG.set_ylabel(_lab("gap change (negative: shim up)", L))
    axG.set_title("the gap changes that do it")
    axG.legend(fontsize=8)
    return fig


__all__ = ["kappa_label", "plot_contour_pressure", "plot_regulation", "plot_scheme_sections", "plot_schemes", "plot_uniformity"]
