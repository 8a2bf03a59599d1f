"""Regions take the same shapes everywhere: a patch load, a bed region and a cut-out are each a
box [x0, x1, y0, y1], a polygon { polygon = [[x, y], ...] } or a circle { circle = [xc, yc, r] },
on the rectangle grid (ACM, BFS) and on triangles (DKT) alike.

External references: the area of a disc, πr², and of its quarter at a corner (statics: the
reactions of a two-sided plate sum to the load); Navier's double series for a simply supported
rectangle (Timoshenko & Woinowsky-Krieger, Theory of plates and shells, § 28), its load
coefficients over a disc in closed form, ∫∫_disc sin αx sin βy dA = sin αxc sin βyc · 2π r J1(ρr)/ρ,
ρ² = α² + β²; the simply supported circular plate of radius a under q over a central disc of
radius b (ibid. § 19): w0 = P/(16πD) [(3 + ν)/(1 + ν) a² − (7 + 3ν)/(4(1 + ν)) b² + b² ln(b/a)],
P = qπb².
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import j1

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.model.paths import get_param, set_param

pytest.importorskip("gmsh")

NU = 0.3
Q = 3.0


def rect(element="acm", n=16, loads=(), edges=None, **kw) -> pq.Scene:
    """The unit square, simply supported, on an n × n grid or on triangles of size 1/n."""
    mesh = pq.MeshSpec(n, n, element) if element != "dkt" else pq.MeshSpec(n, n, "dkt", size=1.0 / n)
    return pq.Scene(plate=pq.Plate(a=1.0, b=1.0, h=0.01, E=1.0e7, nu=NU), mesh=mesh,
                    edges={"all": "simple"} if edges is None else edges, loads=list(loads), **kw)


def reactions_total(res) -> float:
    """The sum of the two-sided supports' reactions (the w rows of K u − f: a rigid translation)."""
    m = res.model
    R = m.K_full @ res.u - m.f_full
    return -R[0::m.element.ndof_node].sum()


def load_resultant(model):
    """Total force and its centroid: the work of the loads in a rigid translation w = 1 and in
    the rigid rotations w = x, w = y (nodal slopes 1 where the element carries them)."""
    names = list(model.element.dof_names)
    f = model.f_full.reshape(-1, len(names))
    xy = model.grid.node_xy()
    F = f[:, 0].sum()
    mx = f[:, 0] @ xy[:, 0] + f[:, names.index("wx")].sum()
    my = f[:, 0] @ xy[:, 1] + f[:, names.index("wy")].sum()
    return F, np.array([mx, my]) / F


MESHES = [("acm", 16), ("bfs", 16), ("dkt", 16)]


@pytest.mark.parametrize("element, n", MESHES)
def test_circular_patch_total_force_is_q_pi_r2(element, n):
    """A circle inside the plate and one over its corner (a quarter on the plate): the total
    force is q π r² (q π r² / 4), to rounding, and the reactions of the two-sided plate carry it."""
    r = 0.23
    inside = rect(element, n, [pq.PatchLoad(Q, region={"circle": [0.41, 0.57, r]})])
    F, c = load_resultant(build_model(inside))
    assert F == pytest.approx(Q * math.pi * r**2, rel=1e-12)
    np.testing.assert_allclose(c, (0.41, 0.57), atol=1e-12)
    res = pq.solve(inside)
    assert reactions_total(res) == pytest.approx(Q * math.pi * r**2, rel=1e-9)
    corner = rect(element, n, [pq.PatchLoad(Q, region={"circle": [1.0, 0.0, r]})])
    F, c = load_resultant(build_model(corner))
    assert F == pytest.approx(Q * math.pi * r**2 / 4, rel=1e-12)
    np.testing.assert_allclose(c, (1.0 - 4 * r / (3 * math.pi), 4 * r / (3 * math.pi)), atol=1e-12)


@pytest.mark.parametrize("element, n", MESHES)
def test_polygon_patch_total_and_moment(element, n):
    """A triangle (not aligned with the mesh) and a box written as a region: q × area, centroid."""
    tri = [[0.13, 0.21], [0.87, 0.33], [0.42, 0.79]]
    sc = rect(element, n, [pq.PatchLoad(Q, region={"polygon": tri})])
    F, c = load_resultant(build_model(sc))
    area = 0.5 * abs((0.87 - 0.13) * (0.79 - 0.21) - (0.42 - 0.13) * (0.33 - 0.21))
    assert F == pytest.approx(Q * area, rel=1e-12)
    np.testing.assert_allclose(c, np.mean(tri, axis=0), atol=1e-12)
    box = build_model(rect(element, n, [pq.PatchLoad(Q, region=[0.1, 0.45, 0.3, 0.62])]))
    old = build_model(rect(element, n, [pq.PatchLoad(Q, 0.1, 0.45, 0.3, 0.62)]))
    np.testing.assert_allclose(box.f_full, old.f_full, rtol=0, atol=1e-15)


def navier_disc(x, y, xc, yc, r, D, q=Q, terms=121):
    """w of the simply supported unit square under q on the disc (xc, yc, r): Navier's series."""
    m = np.arange(1, terms + 1)
    al = m * math.pi
    A, B = np.meshgrid(al, al, indexing="ij")
    rho = np.hypot(A, B)
    qmn = 4 * q * np.sin(A * xc) * np.sin(B * yc) * 2 * math.pi * r * j1(rho * r) / rho
    return float(np.sum(qmn / (D * (A**2 + B**2) ** 2) * np.sin(A * x) * np.sin(B * y)))


@pytest.mark.parametrize("element", ["acm", "dkt"])
def test_circular_patch_on_a_simply_supported_square_against_navier(element):
    """A circle off the centre: w at two points within 2 % of Navier's series at n = 8 and the
    error falling at n = 16."""
    xc, yc, r = 0.45, 0.55, 0.2
    errs = []
    for n in (8, 16):
        res = pq.solve(rect(element, n, [pq.PatchLoad(Q, region={"circle": [xc, yc, r]})]))
        D = res.scene.plate.D
        pts = [(0.5, 0.5), (0.3, 0.6)]
        ref = np.array([navier_disc(x, y, xc, yc, r, D) for x, y in pts])
        got = np.array([res.deflection(x, y) for x, y in pts])
        errs.append(np.max(np.abs(got - ref) / ref))
    assert errs[0] < 0.02 and errs[1] < errs[0] / 2


def test_circular_patch_on_a_simply_supported_disc_against_timoshenko():
    """The simply supported circular plate (a = 1) under q on the central disc b = 0.3: the
    centre deflection within 1 % at h = a/8, the error falling at a/16."""
    a, b = 1.0, 0.3
    errs = []
    for size in (a / 8, a / 16):
        sc = pq.Scene(plate=pq.Plate(shape={"circle": [0.0, 0.0, a]}, h=0.01, E=1.0e7, nu=NU),
                      mesh=pq.MeshSpec(element="dkt", size=size), edges={"all": "simple"},
                      loads=[pq.PatchLoad(Q, region={"circle": [0.0, 0.0, b]})])
        D = sc.plate.D
        P = Q * math.pi * b**2
        ref = P / (16 * math.pi * D) * ((3 + NU) / (1 + NU) * a**2 - (7 + 3 * NU) / (4 * (1 + NU)) * b**2
                                        + b**2 * math.log(b / a))
        errs.append(abs(pq.solve(sc).deflection(0.0, 0.0) / ref - 1))
    assert errs[0] < 0.01 and errs[1] < errs[0] / 2


def bedded(element, n, region, loads=None, supports=()):
    return rect(element, n, loads or [pq.UniformLoad(1.0)], edges={}, supports=list(supports),
                foundation=pq.Foundation(k=1.0e4, region=region))


@pytest.mark.parametrize("element, n", [("acm", 16), ("dkt", 16)])
def test_circular_bed_statics(element, n):
    """A free plate on a circular bed (plus one post), under a uniform load: the bed's and the
    post's reactions carry the whole load; every spring lies in the circle (within a cell)."""
    circle = [0.5, 0.45, 0.3]
    res = pq.solve(bedded(element, n, {"circle": circle}, supports=[pq.Support(0.9, 0.9)]))
    assert res.kkt.ok
    assert res.reactions.sum() == pytest.approx(1.0, rel=1e-8)
    c = res.model.contacts
    bed = c.xy[c.source == "bed"]
    assert len(bed) > 0
    assert np.all(np.hypot(bed[:, 0] - 0.5, bed[:, 1] - 0.45) <= 0.3 + 1.5 / n)
    area = res.model.bed_areas().sum()
    assert area == pytest.approx(math.pi * 0.09, rel=1e-12)  # the hats over each cell's part: exact


def test_circular_bed_agrees_between_grid_and_triangles():
    """A simply supported square on a circular bed under a uniform load: the centre deflection
    on the grid (ACM n × n) and on triangles (DKT 1/n) differ by less than 1 % at n = 16 and
    by less than half that at n = 32 (measured 0.60 %, 0.21 %; 0.04 % at n = 64)."""
    diffs = []
    for n in (16, 32):
        w = [pq.solve(rect(el, n, [pq.UniformLoad(1.0)], foundation=pq.Foundation(k=2.0e3, region={
            "circle": [0.5, 0.5, 0.31]}))).deflection(0.5, 0.5) for el in ("acm", "dkt")]
        diffs.append(abs(w[0] / w[1] - 1))
    assert diffs[0] < 0.01 and diffs[1] < diffs[0] / 2


def test_polygon_bed_on_the_grid():
    """An L-shaped bed on the grid: its springs' areas are the L's area (its sides on cell lines),
    no spring outside it, and statics holds."""
    L = [[0, 0], [0.5, 0], [0.5, 0.25], [0.25, 0.25], [0.25, 0.75], [0, 0.75]]
    res = pq.solve(bedded("acm", 16, {"polygon": L}, supports=[pq.Support(0.9, 0.9), pq.Support(0.9, 0.1)]))
    m = res.model
    assert m.bed_areas().sum() == pytest.approx(0.5 * 0.25 + 0.25 * 0.5, rel=1e-12)
    bed = m.contacts.xy[m.contacts.source == "bed"]
    x, y = bed.T + 0.0
    eps = 1e-12
    in_l = ((x <= 0.5 + eps) & (y <= 0.25 + eps)) | ((x <= 0.25 + eps) & (y <= 0.75 + eps))
    assert len(bed) > 0 and in_l.all()
    assert res.kkt.ok and res.reactions.sum() == pytest.approx(1.0, rel=1e-8)


BAD = [
    ({"circle": [0.5, 0.5, -0.1]}, "radius must be > 0"),
    ({"circle": [3.0, 3.0, 0.2]}, "does not overlap the plate"),
    ({"polygon": [[2, 2], [3, 2], [3, 3]]}, "does not overlap the plate"),
    ({"polygon": [[0.1, 0.1], [0.6, 0.6], [0.6, 0.1], [0.1, 0.6]]}, "self-intersecting"),
    ({"square": [0.5, 0.5, 0.1]}, r"must be \[x0, x1, y0, y1\], \{ polygon"),
    ([0.6, 0.2, 0.1, 0.3], "needs x0 < x1"),
]


@pytest.mark.parametrize("element", ["acm", "dkt"])
def test_bad_regions_name_their_field(element):
    """The same mistakes give the same message naming the field, for a patch and for a bed, on
    both meshes."""
    for region, words in BAD:
        with pytest.raises(pq.SceneError, match=rf"loads\.0\.region[.\w]*: .*{words}"):
            rect(element, 8, [pq.PatchLoad(1.0, region=region)])
        with pytest.raises(pq.SceneError, match=rf"foundation\.region[.\w]*: .*{words}"):
            bedded(element, 8, region)


def test_a_patch_takes_a_box_or_a_region_not_both():
    with pytest.raises(pq.SceneError, match=r"loads\.0: .*either x0, x1, y0, y1 or region"):
        rect("acm", 8, [pq.PatchLoad(1.0, 0.1, 0.2, 0.1, 0.2, region={"circle": [0.5, 0.5, 0.1]})])
    with pytest.raises(pq.SceneError, match=r"loads\.0: .*x0, x1, y0, y1 or region"):
        rect("acm", 8, [pq.PatchLoad(1.0)])


@pytest.mark.parametrize("element", ["acm", "dkt"])
def test_regions_round_trip_through_toml(element, tmp_path):
    """Each shape comes back from TOML as it was written, and solves to the same answer."""
    sc = rect(element, 8, [pq.PatchLoad(Q, region={"circle": [0.4, 0.5, 0.2]}),
                           pq.PatchLoad(1.0, region={"polygon": [[0.6, 0.1], [0.9, 0.1], [0.8, 0.4]]}),
                           pq.PatchLoad(2.0, 0.1, 0.3, 0.6, 0.9)],
              foundation=pq.Foundation(k=1.0e3, region={"circle": [0.5, 0.5, 0.35]}))
    path = tmp_path / "s.toml"
    sc.to_toml(path)
    text = path.read_text()
    assert "circle" in text and "polygon" in text and "x0" in text
    back = pq.Scene.from_toml(path)
    assert back.loads == sc.loads and back.foundation.region == sc.foundation.region
    assert pq.solve(back).deflection(0.5, 0.5) == pytest.approx(pq.solve(sc).deflection(0.5, 0.5), rel=1e-12)


def test_scene_paths_reach_regions():
    sc = rect("acm", 8, [pq.PatchLoad(Q, region={"circle": [0.4, 0.5, 0.2]})],
              foundation=pq.Foundation(k=1.0e3, region={"circle": [0.5, 0.5, 0.35]}))
    assert get_param(sc, "loads.0.region") == {"circle": [0.4, 0.5, 0.2]}
    assert get_param(sc, "foundation.region.circle") == [0.5, 0.5, 0.35]
    new = set_param(sc, "loads.0.region", {"circle": [0.5, 0.5, 0.1]})
    F, _ = load_resultant(build_model(new))
    assert F == pytest.approx(Q * math.pi * 0.01, rel=1e-12)
    with pytest.raises(pq.SceneError, match=r"loads\.0\.region.*radius must be > 0"):
        set_param(sc, "loads.0.region", {"circle": [0.5, 0.5, 0.0]})


def test_openings_share_the_region_checks():
    """An opening is a box region: the same message as a patch's or a bed's box."""
    with pytest.raises(pq.SceneError, match=r"openings\.0: needs x0 < x1 and y0 < y1"):
        rect("acm", 8, [pq.UniformLoad(1.0)], openings=[pq.Opening(0.6, 0.2, 0.1, 0.3)])
    with pytest.raises(pq.SceneError, match=r"loads\.0\.region: needs x0 < x1 and y0 < y1"):
        rect("acm", 8, [pq.PatchLoad(1.0, region=[0.6, 0.2, 0.1, 0.3])])


def test_shapes_given_in_python_keep_their_scene_form():
    """A Polygon or a Circle object given in Python is kept as its TOML form and saves."""
    from plateqp.model.geometry import Circle, Polygon

    sc = rect("acm", 8, [pq.PatchLoad(Q, region=Circle(0.4, 0.5, 0.2))],
              foundation=pq.Foundation(k=1.0e3, region=Polygon(((0.1, 0.1), (0.9, 0.1), (0.5, 0.8)))))
    assert sc.loads[0].region == {"circle": [0.4, 0.5, 0.2]}
    assert sc.foundation.region == {"polygon": [[0.1, 0.1], [0.9, 0.1], [0.5, 0.8]]}
    back = pq.Scene.from_dict(sc.to_dict())
    assert back.loads == sc.loads and back.foundation.region == sc.foundation.region
