"""Figures: every plotting function returns a Figure with labelled axes and renders to PNG, on
the rectangle grid and on triangles; contour levels span the field, the largest nodal σ1 is
marked, the surface, sections and reaction bars carry the result's values; on triangles the plan
view has the true outline with its hole, supports by contact state and numbered from 1 (Agg,
no images)."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import plateqp as pq

pytest.importorskip("matplotlib")

from matplotlib.collections import PathCollection  # noqa: E402
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


R, HOLE = 1.0, 0.2


@pytest.fixture(scope="module")
def ring():
    """A simply supported ring (a disc with a central hole) on DKT triangles, on six supports
    at r = 0.6: one heaved, some lifting off."""
    pytest.importorskip("gmsh")
    gaps = [-2e-3, 1e-4, 0.0, 1e-4, 0.0, 5e-5]
    sup = [pq.Support(0.6 * math.cos(t), 0.6 * math.sin(t), gap=g) for t, g in zip(np.arange(6) * math.pi / 3, gaps)]
    sc = pq.Scene(name="ring", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.05, E=1.0e7, nu=0.3),
                  holes=[{"circle": [0.0, 0.0, HOLE]}], mesh=pq.MeshSpec(element="dkt", size=R / 8),
                  edges={"outer": pq.Edge("simple")}, loads=[pq.UniformLoad(1.0)], supports=sup)
    one = pq.solve(sc, accuracy="high")
    two = pq.solve_bilateral(sc)
    assert 0 < one.active.sum() < one.active.size
    return one, two


@pytest.fixture(params=["grid", "triangles"])
def pairs(request):
    """(mesh, (one-sided result, two-sided result)) on the grid's small scene and on the ring."""
    return request.param, request.getfixturevalue("pair" if request.param == "grid" else "ring")


def patches(fig, gid):
    return [p for ax in fig.axes for p in ax.patches if p.get_gid() == gid]


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
def test_figure_labelled_with_units(pairs, kind):
    _, (one, two) = pairs
    fig = FIGURES[kind](one, two, UNITS)
    labelled(fig)
    plan = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert any("cm" in ax.get_xlabel() or "kgf" in ax.get_ylabel() for ax in plan)  # labels carry units
    assert pl.png_bytes(fig, dpi=40)[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("kind", sorted(FIGURES))
def test_figure_without_units(pairs, kind):
    _, (one, two) = pairs
    labelled(FIGURES[kind](one, two, None))


def test_one_sided_only_and_two_sided_scene(make_scene):
    """Figures work without a comparison, on a two-sided scene, and with an opening (NaN off the plate)."""
    sc = make_scene(nx=6, loads=[pq.UniformLoad(q=1.0)], openings=[pq.Opening(0.6, 1.0, 0.6, 1.0)])
    res = pq.solve(sc)
    for fig in (pl.plot_deflection_surface(res), pl.plot_deflection_contours(res), pl.plot_mesh(res),
                pl.plot_sections(res), pl.plot_principal_stress(res)):
        labelled(fig)
        pl.png_bytes(fig, dpi=30)


def test_plan_view_has_the_true_outline_and_hole(ring):
    one, _ = ring
    fig = pl.plot_mesh(one, ("cm", "kgf"), sections=pl.default_sections(one))
    assert isinstance(fig, Figure)
    (outer,), (hole,) = patches(fig, "outline"), patches(fig, "hole")
    r_out = np.hypot(*outer.get_xy().T)
    r_hole = np.hypot(*hole.get_xy().T)
    np.testing.assert_allclose(r_out, R, rtol=1e-9)  # the circle's own points, not a staircase
    np.testing.assert_allclose(r_hole, HOLE, rtol=1e-9)
    mesh = one.model.grid
    assert len(outer.get_xy()) >= np.sum(mesh.boundary == 0)  # every boundary node of the outer circle
    edges = [c for c in fig.axes[0].collections if c.get_gid() == "edge-simple"]
    assert len(edges) == 1 and len(edges[0].get_segments()) == np.sum(mesh.boundary == 0)  # the hole is free
    numbers = sorted(int(t.get_text()) for t in fig.axes[0].texts if t.get_gid() == "support-number")
    assert numbers == list(range(1, 7))
    reactions = [t for t in fig.axes[0].texts if t.get_gid() == "reaction"]
    assert len(reactions) == int(one.active.sum())
    # filled markers for supports in contact, white for lifted ones
    marks = [c for c in fig.axes[0].collections if isinstance(c, PathCollection)]
    white = sum(len(c.get_offsets()) for c in marks if np.allclose(c.get_facecolors()[0, :3], 1.0))
    filled = sum(len(c.get_offsets()) for c in marks if not np.allclose(c.get_facecolors()[0, :3], 1.0))
    assert (white, filled) == (int((~one.active).sum()), int(one.active.sum()))


def test_contours_span_w(pairs):
    mesh, (one, two) = pairs
    fig = pl.plot_deflection_contours(one, two)
    w = np.concatenate([one.w_nodes(), two.w_nodes()])
    cs = [c for c in fig.axes[0].collections if hasattr(c, "levels") and c.filled]
    lev = cs[0].levels
    assert lev[0] <= w.min() and lev[-1] >= w.max()
    assert lev[-1] - lev[0] < 2 * (w.max() - w.min())
    if mesh == "triangles":
        assert len(patches(fig, "outline")) == 2  # both panels on the true outline


def test_principal_stress_marks_the_largest_nodal_s1(pairs):
    _, (one, two) = pairs
    fig = pl.plot_principal_stress(one, two)
    s1 = one.nodal("s1")
    k = int(np.argmax(s1))
    ax = fig.axes[0]
    (mark,) = [ln for ln in ax.lines if ln.get_marker() == "+"]
    np.testing.assert_allclose(np.ravel(mark.get_data()), one.model.grid.nodes[k])
    lev = next(c for c in ax.collections if hasattr(c, "levels") and c.filled).levels
    assert lev[0] <= min(s1.min(), two.nodal("s1").min()) and lev[-1] >= s1.max()


def test_surface_difference_sections_reactions(pairs):
    mesh, (one, two) = pairs
    fig = pl.plot_deflection_surface(one, two)
    ax = fig.axes[0]
    surf = ax.collections[0]
    pl.png_bytes(fig)  # drawn: the 3-d faces are projected
    if mesh == "triangles":
        assert len(surf.get_paths()) == len(one.model.grid.triangles)  # one face per triangle
    zlo, zhi = ax.get_zlim()
    assert zlo > zhi and zlo >= one.w_nodes().max()  # inverted: w positive down
    dif = pl.plot_difference(one, two)
    lev = next(c for c in dif.axes[0].collections if hasattr(c, "levels") and c.filled).levels
    dw = one.w_nodes() - two.w_nodes()
    assert lev[0] <= dw.min() and lev[-1] >= dw.max()
    secs = pl.default_sections(one)
    for _lab, p0, p1 in secs:  # every section lies on the plate
        t = np.linspace(0, 1, 50)
        assert np.all(one.model.grid.locate(p0[0] + t * (p1[0] - p0[0]), p0[1] + t * (p1[1] - p0[1]))[0] >= 0)
    fig = pl.plot_sections(one, two, secs)
    assert len(fig.axes) == len(secs)
    (line,) = fig.axes[0].lines[:1]
    _s, w = line.get_data()
    _lab, p0, p1 = secs[0]
    np.testing.assert_allclose(w[-1], one.deflection(*p1), rtol=1e-9)
    fig = pl.plot_reactions(one, two)
    assert fig.axes[0].get_xlabel() == "support number"
    bars = fig.axes[0].patches
    np.testing.assert_allclose([b.get_height() for b in bars], one.reactions)
    assert pl.png_bytes(fig)[:4] == b"\x89PNG"


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
