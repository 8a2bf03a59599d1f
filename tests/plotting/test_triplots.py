"""Figures on triangle meshes: the true outline with its hole, supports by contact state and
numbered from 1, contour levels spanning w, the surface over the triangles (Agg, no images)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import plateqp as pq

pytest.importorskip("gmsh")
pytest.importorskip("matplotlib")

from matplotlib.collections import PathCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from plateqp import plotting as pl  # noqa: E402

R, HOLE = 1.0, 0.2


@pytest.fixture(scope="module")
def pair():
    gaps = [-2e-3, 1e-4, 0.0, 1e-4, 0.0, 5e-5]
    sup = [pq.Support(0.6 * math.cos(t), 0.6 * math.sin(t), gap=g) for t, g in zip(np.arange(6) * math.pi / 3, gaps)]
    sc = pq.Scene(name="ring", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.05, E=1.0e7, nu=0.3),
                  holes=[{"circle": [0.0, 0.0, HOLE]}], mesh=pq.MeshSpec(element="dkt", size=R / 8),
                  edges={"outer": pq.Edge("simple")}, loads=[pq.UniformLoad(1.0)], supports=sup)
    one = pq.solve(sc, accuracy="high")
    two = pq.solve_bilateral(sc)
    assert 0 < one.active.sum() < one.active.size
    return one, two


def patches(fig, gid):
    return [p for ax in fig.axes for p in ax.patches if p.get_gid() == gid]


def test_plan_view_has_the_true_outline_and_hole(pair):
    one, _ = pair
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


def test_contours_span_w(pair):
    one, two = pair
    fig = pl.plot_deflection_contours(one, two)
    w = np.concatenate([one.w_nodes(), two.w_nodes()])
    cs = [c for c in fig.axes[0].collections if hasattr(c, "levels") and c.filled]
    lev = cs[0].levels
    assert lev[0] <= w.min() and lev[-1] >= w.max()
    assert lev[-1] - lev[0] < 2 * (w.max() - w.min())
    assert len(patches(fig, "outline")) == 2  # both panels on the true outline


def test_principal_stress_marks_the_largest_nodal_s1(pair):
    one, two = pair
    fig = pl.plot_principal_stress(one, two)
    s1 = one.nodal("s1")
    k = int(np.argmax(s1))
    ax = fig.axes[0]
    (mark,) = [ln for ln in ax.lines if ln.get_marker() == "+"]
    np.testing.assert_allclose(np.ravel(mark.get_data()), one.model.grid.nodes[k])
    lev = [c for c in ax.collections if hasattr(c, "levels") and c.filled][0].levels
    assert lev[0] <= min(s1.min(), two.nodal("s1").min()) and lev[-1] >= s1.max()


def test_surface_difference_sections_reactions(pair):
    one, two = pair
    fig = pl.plot_deflection_surface(one, two)
    ax = fig.axes[0]
    surf = ax.collections[0]
    pl.png_bytes(fig)  # drawn: the 3-d faces are projected
    assert len(surf.get_paths()) == len(one.model.grid.triangles)  # one face per triangle
    zlo, zhi = ax.get_zlim()
    assert zlo > zhi and zlo >= one.w_nodes().max()  # inverted: w positive down
    dif = pl.plot_difference(one, two)
    lev = [c for c in dif.axes[0].collections if hasattr(c, "levels") and c.filled][0].levels
    dw = one.w_nodes() - two.w_nodes()
    assert lev[0] <= dw.min() and lev[-1] >= dw.max()
    secs = pl.default_sections(one)
    for _lab, p0, p1 in secs:  # every section lies on the plate
        t = np.linspace(0, 1, 50)
        assert np.all(one.model.grid.locate(p0[0] + t * (p1[0] - p0[0]), p0[1] + t * (p1[1] - p0[1]))[0] >= 0)
    fig = pl.plot_sections(one, two, secs)
    assert len(fig.axes) == len(secs)
    (line,) = fig.axes[0].lines[:1]
    s, w = line.get_data()
    _lab, p0, p1 = secs[0]
    np.testing.assert_allclose(w[-1], one.deflection(*p1), rtol=1e-9)
    fig = pl.plot_reactions(one, two)
    assert fig.axes[0].get_xlabel() == "support number"
    bars = fig.axes[0].patches
    np.testing.assert_allclose([b.get_height() for b in bars], one.reactions)
    assert pl.png_bytes(fig)[:4] == b"\x89PNG"
