"""Regions take the same shapes everywhere: a patch load, a bed region and a cut-out are each a
box [x0, x1, y0, y1], a polygon { polygon = [[x, y], ...] } or a circle { circle = [xc, yc, r] },
on the rectangle grid (ACM, BFS) and on triangles (DKT) alike. On triangles a bed region's
outline inside the plate is a line of the gmsh mesh, so the region is a union of whole triangles
and the springs' tributary areas sum to the region's area exactly, and an opening is the box cut
out exactly (a rectangular hole).

External references: the area of a disc, πr², and of its quarter at a corner, of a box and of a
circular segment by elementary geometry; Winkler's bed under a load that covers exactly the
bedded part: a rigid translation w = q / k of the whole plate (no bending); statics (the
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

from test_loads_every_mesh import load_resultant  # noqa: E402  (one definition of the loads' resultant)

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


L_REGION = [[-0.2, -0.2], [0.7, -0.2], [0.7, 0.3], [0.35, 0.3], [0.35, 0.8], [-0.2, 0.8]]  # over a corner
SQ = [[0, 0], [1, 0], [1, 1], [0, 1]]


def bedded_square(region, size=1 / 8, shape=None, holes=(), loads=None, k=1e4, supports=()):
    """A free plate (the unit square given as a polygon, or ``shape``) on DKT triangles of
    ``size``, on a bed over ``region``."""
    return pq.Scene(plate=pq.Plate(shape=shape or {"polygon": SQ}, h=0.01, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=size), holes=list(holes),
                    loads=loads or [pq.UniformLoad(1.0)], supports=list(supports),
                    foundation=pq.Foundation(k=k, region=region))


@pytest.mark.parametrize("mesh", ["grid", "triangles"])
def test_polygon_bed_over_a_corner(mesh):
    """An L-shaped region over the square's corner, its sides on no cell line: the areas sum to
    its part on the plate (0.7 × 0.3 + 0.35 × 0.5) exactly, the region comes back from the
    scene's dict, and statics holds; on triangles no triangle is cut by it: the triangles whose
    centroid lies in it (matplotlib's point-in-polygon) have that area too."""
    from matplotlib.path import Path

    region = {"polygon": L_REGION}
    if mesh == "grid":
        sc = bedded("acm", 16, region, supports=[pq.Support(0.9, 0.9)])
    else:
        sc = bedded_square(region, supports=[pq.Support(0.9, 0.9)])
    m = build_model(sc)
    area = 0.7 * 0.3 + 0.35 * 0.5
    assert m.bed_areas().sum() == pytest.approx(area, rel=1e-12)
    if mesh == "triangles":
        g = m.grid
        inside = Path(np.array(L_REGION)).contains_points(g.nodes[g.triangles].mean(axis=1))
        assert g.areas()[inside].sum() == pytest.approx(area, rel=1e-12)
    back = pq.Scene.from_dict(sc.to_dict())
    assert back.foundation.region == region
    res = pq.solve(sc)
    assert res.kkt.ok and res.reactions.sum() == pytest.approx(1.0, rel=1e-8)  # statics


def straddles(model, region) -> int:
    """How many triangles have vertices strictly on both sides of one of the region's lines."""
    x0, x1, y0, y1 = region
    p = model.grid.nodes[model.grid.triangles]
    tol = 1e-9
    n = 0
    for axis, v in ((0, x0), (0, x1), (1, y0), (1, y1)):
        c = p[:, :, axis]
        o = p[:, :, 1 - axis].mean(axis=1)  # within the line's extent along the other axis
        lo, hi = (y0, y1) if axis == 0 else (x0, x1)
        inside_span = (o > lo) & (o < hi)
        n += int(np.sum(inside_span & (c.min(axis=1) < v - tol) & (c.max(axis=1) > v + tol)))
    return n


@pytest.mark.parametrize("region, area, holes", [
    ([0.0, 0.5, 0.0, 1.0], 0.5, []),  # half the plate: two sides on the boundary
    ([0.23, 0.71, 0.37, 1.4], 0.48 * 0.63, []),  # crossing the top edge
    ([0.1, 0.9, 0.1, 0.9], 0.64 - 0.04, [{"polygon": [[0.4, 0.4], [0.6, 0.4], [0.6, 0.6], [0.4, 0.6]]}]),
    ([0.2, 0.65, 0.3, 0.7], 0.45 * 0.4 - 0.15 * 0.2, [{"polygon": [[0.5, 0.4], [0.8, 0.4], [0.8, 0.6], [0.5, 0.6]]}]),
])
def test_bed_areas_on_triangles_sum_to_the_box_exactly(region, area, holes):
    """Triangles only: the box's outline is a line of the mesh (a box bed on the grid keeps its
    cell rule: every cell centred in the box)."""
    m = build_model(bedded_square(region, holes=holes, supports=[pq.Support(0.23, 0.5)]))
    assert m.bed_areas().sum() == pytest.approx(area, rel=1e-12)
    assert straddles(m, region) == 0  # the outline runs along element edges
    bed = m.contacts.xy[m.contacts.source == "bed"]
    x0, x1, y0, y1 = region
    assert np.all((bed[:, 0] >= x0 - 1e-12) & (bed[:, 0] <= x1 + 1e-12) & (bed[:, 1] >= y0 - 1e-12)
                  & (bed[:, 1] <= y1 + 1e-12))  # no spring outside the region


def test_load_on_the_bedded_part_translates_the_plate_on_triangles():
    """A free square, bed on its left half, the same pressure on that half only: on triangles the
    bed takes each node's load where it acts, and the whole plate sinks by q / k without bending
    (triangles only: on the grid the consistent load's nodal couples bend the plate)."""
    q, k, region = 3.0, 1e3, [0.0, 0.5, 0.0, 1.0]
    sc = bedded_square(region, loads=[pq.PatchLoad(q, *region)], k=k)
    res = pq.solve(sc, accuracy="high")
    assert res.kkt.ok and res.reactions.sum() == pytest.approx(q * 0.5, rel=1e-10)
    pts = np.array([[0.1, 0.2], [0.45, 0.9], [0.9, 0.5], [0.7, 0.05]])
    np.testing.assert_allclose(res.deflection(*pts.T), q / k, rtol=1e-7)


def test_bed_region_on_a_circular_plate():
    """A strip of a disc (triangles): the areas sum to the strip's part of the meshed disc (the
    polygon of its boundary nodes) exactly, and to the true circular segment within the chords'
    error."""
    region = [-2.0, 2.0, -0.5, 0.3]
    m = build_model(bedded_square(region, shape={"circle": [0.5, 0.5, 0.5]}, size=1 / 16,
                                  supports=[pq.Support(0.5, 0.5)]))
    d, r = 0.2, 0.5  # the segment below y = 0.3 of the circle of centre (0.5, 0.5)
    seg = r * r * math.acos(d / r) - d * math.sqrt(r * r - d * d)
    assert m.bed_areas().sum() == pytest.approx(seg, rel=5e-3)
    assert straddles(m, region) == 0


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
    ({"circle": [2.5, 2.5, 0.2]}, "does not overlap the plate"),
    ({"polygon": [[0, 0], [1, 1], [1, 0], [0, 1]]}, "self-intersecting"),
]


@pytest.mark.parametrize("element", ["acm", "dkt", "dkt-polygon"])
def test_bad_regions_name_their_field(element):
    """The same mistakes give the same message naming the field, for a patch and for a bed, on
    both meshes (on triangles also on the square given as a polygon)."""
    for region, words in BAD:
        if element == "dkt-polygon":
            with pytest.raises(pq.SceneError, match=rf"foundation\.region[.\w]*: .*{words}"):
                bedded_square(region)
            continue
        with pytest.raises(pq.SceneError, match=rf"loads\.0\.region[.\w]*: .*{words}"):
            rect(element, 8, [pq.PatchLoad(1.0, region=region)])
        with pytest.raises(pq.SceneError, match=rf"foundation\.region[.\w]*: .*{words}"):
            bedded(element, 8, region)


def test_a_region_of_no_known_form_is_named():
    with pytest.raises(pq.SceneError, match=r"foundation.region: must be \[x0, x1, y0, y1\], \{ polygon"):
        pq.Scene(mesh=pq.MeshSpec(8, 8), loads=[pq.UniformLoad(1.0)],
                 foundation=pq.Foundation(k=1e3, region={"square": L_REGION}))


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


def square_with_an_opening(opening, loads, **kw) -> pq.Scene:
    """The unit square given as a polygon, on DKT triangles of size 1/8, with an opening."""
    return pq.Scene(name="sq", plate=pq.Plate(shape={"polygon": SQ}, h=0.01, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=1 / 8), loads=loads, openings=[pq.Opening(*opening)], **kw)


def test_opening_on_triangles_is_cut_out_exactly():
    """A free square with an opening, on a tensionless bed under uniform q: the plate sinks by
    q / k everywhere (a rigid translation), and the bed carries q × (1 − the opening's area),
    exactly; no node lies strictly inside the opening (triangles only: on the grid the consistent
    load's nodal couples bend the plate)."""
    q, k = 2.0, 100.0
    sc = square_with_an_opening((0.3, 0.55, 0.35, 0.6), [pq.UniformLoad(q)], foundation=pq.Foundation(k=k))
    res = pq.solve(sc, accuracy="high")
    assert res.kkt.ok and res.reactions.sum() == pytest.approx(q * (1 - 0.25 * 0.25), rel=1e-10)
    assert res.deflection(0.1, 0.9) == pytest.approx(q / k, rel=1e-7)
    n = res.model.grid.nodes
    assert not np.any((n[:, 0] > 0.3 + 1e-9) & (n[:, 0] < 0.55 - 1e-9) & (n[:, 1] > 0.35 + 1e-9) & (n[:, 1] < 0.6 - 1e-9))


@pytest.mark.parametrize("mesh", ["grid", "triangles"])
def test_a_point_load_in_an_opening_is_refused(mesh):
    load, opening = pq.PointLoad(1.0, 0.4, 0.5), (0.3, 0.55, 0.35, 0.6)
    with pytest.raises(pq.SceneError, match="no plate there|off the plate"):
        if mesh == "grid":
            rect("acm", 8, [load], openings=[pq.Opening(*opening)])
        else:
            square_with_an_opening(opening, [load])


@pytest.mark.parametrize("opening, words", [
    ((0.8, 1.2, 0.3, 0.5), "openings.0: the hole is not inside the plate"),
    ((0.1, 0.3, 0.1, 0.3), "openings.0: overlaps or touches holes.0"),
])
def test_bad_openings_on_triangles(opening, words):
    with pytest.raises(pq.SceneError, match=words):
        square_with_an_opening(opening, [pq.UniformLoad(2.0)], holes=[{"circle": [0.25, 0.25, 0.1]}])


@pytest.mark.parametrize("mesh, fine, coarse", [("grid", pq.MeshSpec(1000, 1000, "acm"), pq.MeshSpec(2, 2, "acm")),
                                                ("triangles", pq.MeshSpec(element="dkt", size=1e-3),
                                                 pq.MeshSpec(element="dkt", size=0.5))], ids=["grid", "triangles"])
def test_bed_scale_is_checked_at_the_element_size(mesh, fine, coarse):
    """The bed's node spring is about k h² with h the element size (the grid's cell, the triangle
    mesh's size): a bed flexible enough against a 1e-181 plate at h = 1e-3 passes, at h = 0.5 it
    is named."""
    plate = pq.Plate(a=1.0, b=1.0, h=1e-30, E=1e-90, nu=0.3) if mesh == "grid" else \
        pq.Plate(shape={"polygon": SQ}, h=1e-30, E=1e-90, nu=0.3)

    def bed(spec):
        return pq.Scene(plate=plate, mesh=spec, loads=[pq.UniformLoad(1e-30)], foundation=pq.Foundation(k=1e22))
    bed(fine)
    with pytest.raises(pq.SceneError, match="foundation.k"):
        bed(coarse)


def test_shapes_given_in_python_keep_their_scene_form():
    """A Polygon or a Circle object given in Python is kept as its TOML form and saves."""
    from plateqp.model.geometry import Circle, Polygon

    sc = rect("acm", 8, [pq.PatchLoad(Q, region=Circle(0.4, 0.5, 0.2))],
              foundation=pq.Foundation(k=1.0e3, region=Polygon(((0.1, 0.1), (0.9, 0.1), (0.5, 0.8)))))
    assert sc.loads[0].region == {"circle": [0.4, 0.5, 0.2]}
    assert sc.foundation.region == {"polygon": [[0.1, 0.1], [0.9, 0.1], [0.5, 0.8]]}
    back = pq.Scene.from_dict(sc.to_dict())
    assert back.loads == sc.loads and back.foundation.region == sc.foundation.region
