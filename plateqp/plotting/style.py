"""The look shared by every figure: figure creation, labels and units, colours, saving.

Figures are built on ``matplotlib.figure.Figure`` directly, never through ``pyplot``: nothing
global is touched (no backend switch, no figure registry), and :func:`save` /
:func:`png_bytes` render them with the Agg canvas, so they work headless. matplotlib is
imported inside the functions that need it (importing plateqp never imports it).

``units``: an optional pair (length, force), e.g. ``("cm", "kgf")``; the axis labels then
carry the units (stresses in force/length², reactions in force).

Colours: red ▲ = heaved support (g0 < 0), blue ▼ = settled (g0 > 0), black ● = level
(g0 = 0); fields with both signs get a diverging colour map centred on 0.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..results import Result

ONE_SIDED = "one-sided supports"
TWO_SIDED = "two-sided supports"
HEAVE_COLOR = "tab:red"
SETTLE_COLOR = "tab:blue"
LEVEL_COLOR = "black"
LEVEL_BAR = "0.5"


def _figure(figsize):
    from matplotlib.figure import Figure

    return Figure(figsize=figsize, layout="constrained")


def _frame(ax, xlim, ylim, units, title: str | None = None) -> None:
    """A plan view's axes: equal aspect, the limits, x and y labelled in length units, a title."""
    L = _units(units)[0]
    ax.set_aspect("equal")
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_xlabel(_lab("x", L))
    ax.set_ylabel(_lab("y", L))
    if title:
        ax.set_title(title)


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
    from ..io.safe import write

    path = Path(path)  # replacing a file there, and a symbolic link itself rather than its target
    write(path, lambda tmp: fig.savefig(tmp, dpi=dpi, format="png", **_bbox(fig)), force=True, label=str(path))
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


def _name(result: Result) -> str:
    """What a result is called in titles and legends."""
    return ONE_SIDED if result.scene.one_sided else "two-sided supports only"


def _gap_style(g0: float):
    """(colour, marker, kind) of a support by the sign of its initial gap."""
    if g0 < 0:
        return HEAVE_COLOR, "^", "heaved"
    if g0 > 0:
        return SETTLE_COLOR, "v", "settled"
    return LEVEL_COLOR, "o", "level"


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
