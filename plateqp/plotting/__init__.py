"""Figures of a solved plate: matplotlib, imported lazily, no pyplot state.

Every function takes a :class:`~plateqp.results.Result` (and, where it compares, the
two-sided :class:`~plateqp.results.Result` of :func:`plateqp.solve_bilateral`) and returns a
:class:`matplotlib.figure.Figure`. The figures are built on ``matplotlib.figure.Figure``
directly, never through ``pyplot``: nothing global is touched (no backend switch, no figure
registry), and :func:`save` renders them with the Agg canvas, so they work headless.
Importing this package does not import matplotlib; drawing a figure does.

Conventions in every figure: w is positive **downward** (the direction of the load), so
deflection axes are inverted (down is down) and say so in their label. One-sided results
are drawn solid / coloured, two-sided results dashed / as a wire frame, as in the source
paper. Supports: filled marker = in contact, hollow = lifted off; red ▲ = heaved (g0 < 0),
blue ▼ = settled (g0 > 0), black ● = level (g0 = 0); reactions in force units.

``units``: an optional pair (length, force), e.g. ``("cm", "kgf")``; the axis labels then
carry the units (stresses in force/length², reactions in force).

Modules, by job: :mod:`.style` (figure creation, labels and units, colours, :func:`save`,
:func:`png_bytes`), :mod:`.data` (what a figure reads from a result), :mod:`.marks` (the
support markers, legend entries, axes and outline every plan-view map shares), :mod:`.plan` (the plan
view: mesh, supports, contact state, section lines), :mod:`.fields` (deflection surface,
contours, principal stresses, difference map), :mod:`.charts` (sections, reactions,
convergence as line and bar charts), :mod:`.studies` (the source paper's figures 5 and 6:
working schemes, w along sections per scheme, contact pressure along a contour, uniformity
against κ), :mod:`.tri` (the plan view of a triangle mesh: the true outline and holes;
:func:`plot_mesh` draws with it where the mesh picks it, and :func:`default_sections` are the
mesh's own). The field maps are one path for every mesh: the nodal values (one per node of
the plate) on a matplotlib ``Triangulation`` of ``mesh.nodes`` and ``mesh.triangulation()``
(a grid's quads split in two for drawing only).
"""

from __future__ import annotations

from .charts import plot_convergence, plot_reactions, plot_sections
from .data import support_spacing
from .fields import plot_deflection_contours, plot_deflection_surface, plot_difference, plot_principal_stress
from .plan import default_sections, plot_mesh
from .studies import plot_contour_pressure, plot_scheme_sections, plot_schemes, plot_uniformity
from .style import (HEAVE_COLOR, LEVEL_BAR, LEVEL_COLOR, ONE_SIDED, SETTLE_COLOR, TWO_SIDED, png_bytes,
                    save)

__all__ = [
    "HEAVE_COLOR", "LEVEL_BAR", "LEVEL_COLOR", "ONE_SIDED", "SETTLE_COLOR", "TWO_SIDED",
    "default_sections", "plot_contour_pressure", "plot_convergence", "plot_deflection_contours",
    "plot_deflection_surface", "plot_difference", "plot_mesh", "plot_principal_stress", "plot_reactions",
    "plot_scheme_sections", "plot_schemes", "plot_sections", "plot_uniformity",
    "png_bytes", "save", "support_spacing",
]
