"""Tensionless beds over part of a triangle-meshed plate, and scene paths with the
triangle meshes' edge names.

The bed region's outline inside the plate is a line of the gmsh mesh, so the region is a union
of whole triangles and the springs' tributary areas sum to the region's area exactly.
External references: the region's area by elementary geometry; Winkler's bed under a load that
covers exactly the bedded part: a rigid translation w = q / k of the whole plate (no bending);
the clamped circular plate's w0 = q R⁴ / 64 D (Timoshenko & Woinowsky-Krieger § 62).
"""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.model.paths import get_param, set_param

pytest.importorskip("gmsh")

SQ = [[0, 0], [1, 0], [1, 1], [0, 1]]


def bedded(region, size=1 / 8, shape=None, holes=(), loads=None, k=1e4, supports=()):
    return pq.Scene(plate=pq.Plate(shape=shape or {"polygon": SQ}, h=0.01, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=size), holes=list(holes),
                    loads=loads or [pq.UniformLoad(1.0)], supports=list(supports),
                    foundation=pq.Foundation(k=k, region=region))


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
def test_bed_areas_sum_to_the_region_exactly(region, area, holes):
    m = build_model(bedded(region, holes=holes, supports=[pq.Support(0.23, 0.5)]))
    assert m.bed_areas().sum() == pytest.approx(area, rel=1e-12)
    assert straddles(m, region) == 0  # the outline runs along element edges
    bed = m.contacts.xy[m.contacts.source == "bed"]
    x0, x1, y0, y1 = region
    assert np.all((bed[:, 0] >= x0 - 1e-12) & (bed[:, 0] <= x1 + 1e-12) & (bed[:, 1] >= y0 - 1e-12)
                  & (bed[:, 1] <= y1 + 1e-12))  # no spring outside the region


def test_load_on_the_bedded_part_translates_the_plate():
    """A free square, bed on its left half, the same pressure on that half only: the bed takes
    each node's load where it acts, and the whole plate sinks by q / k without bending."""
    q, k, region = 3.0, 1e3, [0.0, 0.5, 0.0, 1.0]
    sc = bedded(region, loads=[pq.PatchLoad(q, *region)], k=k)
    res = pq.solve(sc, accuracy="high")
    assert res.kkt.ok and res.reactions.sum() == pytest.approx(q * 0.5, rel=1e-10)
    pts = np.array([[0.1, 0.2], [0.45, 0.9], [0.9, 0.5], [0.7, 0.05]])
    np.testing.assert_allclose(res.deflection(*pts.T), q / k, rtol=1e-7)


def test_bed_region_on_a_circle():
    """A strip of a disc: the areas sum to the strip's part of the meshed disc (the polygon of
    its boundary nodes) exactly, and to the true circular segment within the chords' error."""
    import math

    region = [-2.0, 2.0, -0.5, 0.3]
    m = build_model(bedded(region, shape={"circle": [0.5, 0.5, 0.5]}, size=1 / 16,
                           supports=[pq.Support(0.5, 0.5)]))
    d, r = 0.2, 0.5  # the segment below y = 0.3 of the circle of centre (0.5, 0.5)
    seg = r * r * math.acos(d / r) - d * math.sqrt(r * r - d * d)
    assert m.bed_areas().sum() == pytest.approx(seg, rel=5e-3)
    assert straddles(m, region) == 0


# -- scene paths with the triangle meshes' edge names ----------------------------------------------

def disc(**edges):
    return pq.Scene(plate=pq.Plate(shape={"circle": [0.0, 0.0, 1.0]}, h=0.01, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=1 / 8), edges=edges, loads=[pq.UniformLoad(1.0)])


def test_paths_take_the_triangle_edge_names():
    sc = disc(all="simple")
    assert get_param(sc, "edges.all") == "simple"
    clamped = set_param(sc, "edges.all", "clamped")
    D = sc.plate.D
    assert pq.solve(clamped).deflection(0.0, 0.0) == pytest.approx(1.0 / (64 * D), rel=0.01)
    L = pq.Scene(plate=pq.Plate(shape={"polygon": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}),
                 mesh=pq.MeshSpec(element="dkt", size=0.25), loads=[pq.UniformLoad(1.0)])
    L2 = set_param(set_param(L, "edges.outer_0-1", "clamped"), "edges.outer_4-5.kind", "simple")
    assert L2.edges["outer_0-1"].kind == "clamped" and L2.edges["outer_4-5"].kind == "simple"
    holed = set_param(pq.Scene(plate=L.plate, mesh=L.mesh, holes=[{"circle": [0.5, 0.5, 0.2]}]), "edges.hole0", "clamped")
    assert holed.edges["hole0"].kind == "clamped"


@pytest.mark.parametrize("path, words", [("edges.outr", "unknown edge"), ("edges.hole3", "no hole 3"),
                                         ("edges.outer_2-9", "segments")])
def test_paths_refuse_bad_edge_names(path, words):
    L = pq.Scene(plate=pq.Plate(shape={"polygon": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}),
                 mesh=pq.MeshSpec(element="dkt", size=0.25), loads=[pq.UniformLoad(1.0)])
    with pytest.raises(pq.SceneError, match=words):
        set_param(L, path, "simple")


# -- a bed under a polygon region ------------------------------------------------------------------

L_REGION = [[-0.2, -0.2], [0.7, -0.2], [0.7, 0.3], [0.35, 0.3], [0.35, 0.8], [-0.2, 0.8]]  # over a corner


def test_polygon_region_areas_and_outline():
    """An L-shaped region over the square's corner: the areas sum to its part on the plate
    (0.7 × 0.3 + 0.35 × 0.5) exactly, and no triangle is cut by it: the triangles whose centroid
    lies in it (matplotlib's point-in-polygon) have that area too."""
    from matplotlib.path import Path

    region = {"polygon": L_REGION}
    sc = bedded(region, supports=[pq.Support(0.9, 0.9)])
    m = build_model(sc)
    area = 0.7 * 0.3 + 0.35 * 0.5
    assert m.bed_areas().sum() == pytest.approx(area, rel=1e-12)
    g = m.grid
    inside = Path(np.array(L_REGION)).contains_points(g.nodes[g.triangles].mean(axis=1))
    assert g.areas()[inside].sum() == pytest.approx(area, rel=1e-12)
    back = pq.Scene.from_dict(sc.to_dict())
    assert back.foundation.region == region
    res = pq.solve(sc)
    assert res.kkt.ok and res.reactions.sum() == pytest.approx(1.0, rel=1e-8)  # statics


@pytest.mark.parametrize("region, words", [
    ({"polygon": [[2, 2], [3, 2], [3, 3]]}, "does not overlap the plate"),
    ({"circle": [2.5, 2.5, 0.2]}, "does not overlap the plate"),
    ({"polygon": [[0, 0], [1, 1], [1, 0], [0, 1]]}, "self-intersecting"),
])
def test_bad_polygon_regions(region, words):
    with pytest.raises(pq.SceneError, match=f"foundation.region.*{words}"):
        bedded(region)


def test_a_region_of_no_known_form_is_named():
    with pytest.raises(pq.SceneError, match=r"foundation.region: must be \[x0, x1, y0, y1\], \{ polygon"):
        pq.Scene(mesh=pq.MeshSpec(8, 8), loads=[pq.UniformLoad(1.0)],
                 foundation=pq.Foundation(k=1e3, region={"square": L_REGION}))
