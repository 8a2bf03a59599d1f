"""Figures: every plotting function returns a Figure with labelled axes and renders to PNG."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import plateqp as pq

pytest.importorskip("matplotlib")

from matplotlib.figure import Figure  # noqa: E402

from plateqp import plotting as pl  # noqa: E402

UNITS = ("cm", "kgf")


def small_scene(**kw) -> pq.Scene:
    """A 1 x 1 floating plate, 6 x 6 mesh, on a 3 x 3 grid of supports: one heaved, one settled."""
    gaps = {0: -0.002, 8: 0.001}
    sups = [pq.Support(0.5 * i, 0.5 * j, gap=gaps.get(3 * j + i, 0.0)) for j in range(3) for i in range(3)]
    base = dict(name="small", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1.0e7, nu=0.3),
                mesh=pq.MeshSpec(6, 6, "acm"), loads=[pq.PointLoad(P=100.0, x=2 / 3, y=2 / 3), pq.UniformLoad(q=5.0)],
                supports=sups)
    base.update(kw)
    return pq.Scene(**base)


@pytest.fixture(scope="module")
def pair():
    sc = small_scene()
    one = pq.solve(sc, accuracy="high")
    two = pq.solve_bilateral(sc)
    assert 0 < one.active.sum() < one.active.size  # a real contact problem: the figures show both kinds
    return one, two


def labelled(fig: Figure) -> None:
    """Every plot axes has x and y labels (3D: z too); every colour bar has a label."""
    assert isinstance(fig, Figure)
    assert fig.axes
    for ax in fig.axes:
        if ax.get_label() == "<colorbar>":
            assert ax.get_ylabel() or ax.get_xlabel(), "colour bar without a label"
            continue
        assert ax.get_xlabel(), f"axes {ax.get_title()!r} has no x label"
        assert ax.get_ylabel(), f"axes {ax.get_title()!r} has no y label"
        if hasattr(ax, "get_zlabel"):
            assert ax.get_zlabel()
        assert ax.get_title() or fig._suptitle is not None


FIGURES = {
    "surface": lambda one, two, u: pl.plot_deflection_surface(one, two, u),
    "contours": lambda one, two, u: pl.plot_deflection_contours(one, two, u),
    "mesh": lambda one, two, u: pl.plot_mesh(one, u, sections=pl.default_sections(one)),
    "sections": lambda one, two, u: pl.plot_sections(one, two, [((0, 0.5), (1, 0.5)), ("diag", (0, 0), (1, 1))], u),
    "sigma1": lambda one, two, u: pl.plot_principal_stress(one, two, u),
    "difference": lambda one, two, u: pl.plot_difference(one, two, u, zones=np.zeros(len(one.model.grid.nodes), dtype=int)),
    "reactions": lambda one, two, u: pl.plot_reactions(one, two, u),
}


@pytest.mark.parametrize("kind", sorted(FIGURES))
def test_figure_labelled_with_units(pair, kind):
    one, two = pair
    fig = FIGURES[kind](one, two, UNITS)
    labelled(fig)
    plan = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert any("cm" in ax.get_xlabel() or "kgf" in ax.get_ylabel() for ax in plan)  # labels carry units
    assert pl.png_bytes(fig, dpi=40)[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("kind", sorted(FIGURES))
def test_figure_without_units(pair, kind):
    one, two = pair
    labelled(FIGURES[kind](one, two, None))


def test_one_sided_only_and_two_sided_scene(make_scene):
    """Figures work without a comparison, on a two-sided scene, and with an opening (NaN off the plate)."""
    sc = make_scene(nx=6, loads=[pq.UniformLoad(q=1.0)], openings=[pq.Opening(0.6, 1.0, 0.6, 1.0)])
    res = pq.solve(sc)
    for fig in (pl.plot_deflection_surface(res), pl.plot_deflection_contours(res), pl.plot_mesh(res),
                pl.plot_sections(res), pl.plot_principal_stress(res)):
        labelled(fig)
        pl.png_bytes(fig, dpi=30)


def test_units_must_be_a_pair(pair):
    with pytest.raises(ValueError, match="pair"):
        pl.plot_mesh(pair[0], ("cm",))


def test_convergence_plot_takes_plain_lists():
    meshes = [2, 4, 8, 16]
    fig = pl.plot_convergence(meshes, {"max w": [0.2, 0.05, 0.01], "R at 5": [np.nan, 0.1, 0.0, 1e-4]}, target=0.02)
    labelled(fig)
    ax = fig.axes[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["max w", "R at 5", "target 0.02"]
    # the zero and the NaN are left out, not drawn at the bottom of the axis
    assert len(ax.get_lines()[1].get_xdata()) == 2
    labelled(pl.plot_convergence(meshes, [0.3, 0.1, 0.03]))
    with pytest.raises(ValueError, match="one per mesh"):
        pl.plot_convergence(meshes, {"bad": [0.1]})


def test_sections_default_to_support_rows(pair):
    secs = pl.default_sections(pair[0])
    assert [s[1][1] for s in secs] == [0.0, 0.5, 1.0]  # the three rows of supports


def test_save_writes_png(pair, tmp_path):
    path = pl.save(pl.plot_reactions(*pair), tmp_path / "r.png", dpi=30)
    assert path.read_bytes()[:4] == b"\x89PNG"


def test_matplotlib_is_imported_lazily():
    """Importing plateqp, its plots, the demo and the report does not import matplotlib; a figure does."""
    code = ("import sys, plateqp, plateqp.plotting, plateqp.demo, plateqp.demo.report, plateqp.cli\n"
            "assert 'matplotlib' not in sys.modules, sorted(m for m in sys.modules if 'matplotlib' in m)[:3]\n"
            "import plateqp.plotting.style as st\n"
            "st._figure((1, 1))\n"
            "assert 'matplotlib' in sys.modules\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr


def test_public_names_of_the_package():
    """The names plateqp.plotting had as one module are all there, each from its module by job."""
    for name in ("save", "png_bytes", "default_sections", "plot_mesh", "plot_deflection_surface",
                 "plot_deflection_contours", "plot_sections", "plot_principal_stress", "plot_difference",
                 "plot_reactions", "plot_convergence", "ONE_SIDED", "TWO_SIDED", "HEAVE_COLOR", "SETTLE_COLOR",
                 "LEVEL_COLOR", "LEVEL_BAR"):
        assert hasattr(pl, name), name
    assert set(pl.__all__) <= set(dir(pl))
