"""Patch loads and openings on triangle meshes.

A patch load [x0, x1] × [y0, y1] is integrated exactly over the parts of the triangles it covers
(each triangle clipped by the box): its total is q × the patch's area on the plate, exactly, and
its moment that of the pressure. An opening on a triangle mesh is the box cut out exactly (a
rectangular hole). External references: the patch's area and centroid by elementary geometry;
Navier's double series for a simply supported rectangle under a rectangular patch (Timoshenko &
Woinowsky-Krieger, Theory of plates and shells, § 30, eq. 137), and statics.
"""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.assembly import build_model
pytest.importorskip("gmsh")

SQ = [[0, 0], [1, 0], [1, 1], [0, 1]]
Q = 2.0


def square(size=1 / 16, loads=(), **kw) -> pq.Scene:
    return pq.Scene(name="sq", plate=pq.Plate(shape={"polygon": SQ}, h=0.01, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=size), loads=list(loads), **kw)


def load_resultant(model):
    """Total force and its centroid from the assembled loads (the w rows of f)."""
    f = model.f_full[0::3]
    return f.sum(), (f[:, None] * model.grid.nodes).sum(axis=0) / f.sum()


@pytest.mark.parametrize("box, area, centroid, holes", [
    ((0.3, 0.55, 0.2, 0.45), 0.0625, (0.425, 0.325), []),  # inside, its outline cutting triangles
    ((0.8, 1.4, -0.2, 0.3), 0.2 * 0.3, (0.9, 0.15), []),  # over a corner: the part on the plate
    ((0.2, 0.8, 0.2, 0.8), 0.36 - 0.04, (0.5 - 0.04 * 0.1 / 0.32, 0.5), [[[0.5, 0.4], [0.7, 0.4], [0.7, 0.6], [0.5, 0.6]]]),
])
def test_patch_total_is_q_times_its_area_exactly(box, area, centroid, holes):
    sc = square(loads=[pq.PatchLoad(Q, *box)], holes=[{"polygon": h} for h in holes])
    F, c = load_resultant(build_model(sc))
    assert F == pytest.approx(Q * area, rel=1e-12)
    np.testing.assert_allclose(c, centroid, atol=1e-12)


def navier_patch(x, y, box, D, q=Q, a=1.0, b=1.0, n=301):
    """SS rectangle under q on the patch of centre (ξ, η) and sides u × v (Timoshenko § 30):
    q_mn = 16 q / (π² m n) sin(mπξ/a) sin(mπu/2a) sin(nπη/b) sin(nπv/2b),
    w = Σ q_mn sin(mπx/a) sin(nπy/b) / (π⁴ D (m²/a² + n²/b²)²)."""
    x0, x1, y0, y1 = box
    xi, eta, u, v = (x0 + x1) / 2, (y0 + y1) / 2, x1 - x0, y1 - y0
    m = np.arange(1, n + 1)[:, None]
    k = np.arange(1, n + 1)[None, :]
    qmn = 16 * q / (np.pi**2 * m * k) * np.sin(m * np.pi * xi / a) * np.sin(m * np.pi * u / (2 * a)) \
        * np.sin(k * np.pi * eta / b) * np.sin(k * np.pi * v / (2 * b))
    return float(np.sum(qmn * np.sin(m * np.pi * x / a) * np.sin(k * np.pi * y / b)
                        / (np.pi**4 * D * (m**2 / a**2 + k**2 / b**2) ** 2)))


def test_patch_on_a_simply_supported_square_against_navier():
    """An off-centre patch: w within 0.7 % of Navier's series at four points on h = 1/16, and the
    error converging with order ≈ 2 in h (DKT)."""
    box = (0.3, 0.55, 0.2, 0.45)
    pts = [(0.5, 0.5), (0.425, 0.325), (0.2, 0.7), (0.8, 0.3)]
    errs = []
    for h in (1 / 8, 1 / 16, 1 / 32):
        res = pq.solve(square(h, [pq.PatchLoad(Q, *box)], edges={"all": "simple"}))
        ref = np.array([navier_patch(x, y, box, res.scene.plate.D) for x, y in pts])
        errs.append(np.abs(res.deflection(*np.array(pts).T) / ref - 1).max())
    assert errs[1] < 0.007 and errs[2] < 0.002
    order = np.polyfit(np.log([1 / 8, 1 / 16, 1 / 32]), np.log(errs), 1)[0]
    assert 1.6 < order < 2.6, (errs, order)


def test_patch_on_a_triangle_meshed_rectangle():
    """The same patch on a rectangle (a, b; no shape) meshed with triangles: the same answer as
    Navier (the rectangle's edge names)."""
    box = (0.3, 0.55, 0.2, 0.45)
    sc = pq.Scene(plate=pq.Plate(a=1.0, b=1.0, h=0.01, E=1e7, nu=0.3), mesh=pq.MeshSpec(element="dkt", size=1 / 16),
                  edges={k: "simple" for k in ("left", "right", "bottom", "top")}, loads=[pq.PatchLoad(Q, *box)])
    res = pq.solve(sc)
    assert res.deflection(0.5, 0.5) == pytest.approx(navier_patch(0.5, 0.5, box, sc.plate.D), rel=0.007)


def test_opening_on_triangles_is_cut_out_exactly():
    """A free square with an opening, on a tensionless bed under uniform q: the plate sinks by
    q / k everywhere (a rigid translation), and the bed carries q × (1 − the opening's area),
    exactly; no node lies strictly inside the opening."""
    k = 100.0
    sc = square(1 / 8, [pq.UniformLoad(Q)], openings=[pq.Opening(0.3, 0.55, 0.35, 0.6)],
                foundation=pq.Foundation(k=k))
    res = pq.solve(sc, accuracy="high")
    assert res.kkt.ok and res.reactions.sum() == pytest.approx(Q * (1 - 0.25 * 0.25), rel=1e-10)
    assert res.deflection(0.1, 0.9) == pytest.approx(Q / k, rel=1e-7)
    n = res.model.grid.nodes
    assert not np.any((n[:, 0] > 0.3 + 1e-9) & (n[:, 0] < 0.55 - 1e-9) & (n[:, 1] > 0.35 + 1e-9) & (n[:, 1] < 0.6 - 1e-9))
    with pytest.raises(pq.SceneError, match="no plate there|off the plate"):
        square(1 / 8, [pq.PointLoad(1.0, 0.4, 0.5)], openings=[pq.Opening(0.3, 0.55, 0.35, 0.6)])


@pytest.mark.parametrize("opening, words", [
    ((0.8, 1.2, 0.3, 0.5), "openings.0: the hole is not inside the plate"),
    ((0.1, 0.3, 0.1, 0.3), "openings.0: overlaps or touches holes.0"),
])
def test_bad_openings_on_triangles(opening, words):
    with pytest.raises(pq.SceneError, match=words):
        square(1 / 8, [pq.UniformLoad(Q)], openings=[pq.Opening(*opening)], holes=[{"circle": [0.25, 0.25, 0.1]}])


def test_patch_anywhere_on_a_disc():
    """A disc centred at the origin: a patch at negative x (left of the bounding box's corner)
    is on the plate; its total is q × its area exactly."""
    sc = pq.Scene(plate=pq.Plate(shape={"circle": [0.0, 0.0, 1.0]}, h=0.01, E=1e7, nu=0.3),
                  mesh=pq.MeshSpec(element="dkt", size=1 / 8), edges={"all": "clamped"},
                  loads=[pq.PatchLoad(Q, -0.9, -0.5, -0.2, 0.2)])
    F, c = load_resultant(build_model(sc))
    assert F == pytest.approx(Q * 0.4 * 0.4, rel=1e-12)
    np.testing.assert_allclose(c, (-0.7, 0.0), atol=1e-12)


def test_bed_scale_is_checked_at_the_element_size():
    """The bed's node spring is about k h² with h the triangle mesh's size (not the grid's nx):
    a bed flexible enough against a 1e-181 plate at h = 1e-3 passes, at h = 0.5 it is named."""
    def bed(size):
        return pq.Scene(plate=pq.Plate(shape={"polygon": SQ}, h=1e-30, E=1e-90, nu=0.3),
                        mesh=pq.MeshSpec(element="dkt", size=size), loads=[pq.UniformLoad(1e-30)],
                        foundation=pq.Foundation(k=1e22))
    bed(1e-3)
    with pytest.raises(pq.SceneError, match="foundation.k"):
        bed(0.5)
