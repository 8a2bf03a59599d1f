"""Shaped plates in the scene (plateqp.model.geometry): the keys, their round trip, and bad geometry as a
SceneError naming the field and the file. No meshing here (gmsh is not needed to load a scene)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.geometry import Circle, Domain, Polygon

L_SHAPE = "[[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]"

BASE = f"""
name = "shaped"

[plate]
shape = {{ polygon = {L_SHAPE} }}
h = 0.01
E = 1.0e7
nu = 0.3

[mesh]
element = "dkt"
size = 0.25

[edges]
all = "simple"

[[holes]]
circle = [0.5, 0.5, 0.2]

[[loads]]
type = "uniform"
q = 1.0

[[supports]]
x = 1.5
y = 0.5
gap = -0.001
"""


def write(tmp_path, text, name="scene.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_shaped_scene_loads_and_round_trips(tmp_path):
    sc = pq.Scene.from_toml(write(tmp_path, BASE))
    assert sc.triangles and sc.plate.shape == {"polygon": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}
    assert (sc.plate.a, sc.plate.b) == (2.0, 2.0)  # the bounding box's sides: the length scales
    assert sc.holes == [{"circle": [0.5, 0.5, 0.2]}] and sc.mesh.size == 0.25 and sc.edges["all"].kind == "simple"
    back = pq.Scene.from_toml(write(tmp_path, sc.to_toml(), "back.toml"))
    assert back.to_dict() == sc.to_dict()
    assert "a" not in sc.to_dict()["plate"] and "shape" not in pq.Scene().to_dict()["plate"]
    assert "size" not in pq.Scene().to_dict()["mesh"] and "holes" not in pq.Scene().to_dict()


def sub(old, new):
    def edit(text):
        assert old in text
        return text.replace(old, new, 1)
    return edit


BOWTIE = "[[0, 0], [1, 1], [1, 0], [0, 1]]"
BAD = [
    ("self-intersecting", sub(L_SHAPE, BOWTIE), "plate.shape.polygon", "self-intersecting"),
    ("clockwise", sub(L_SHAPE, "[[0, 2], [1, 2], [1, 1], [2, 1], [2, 0], [0, 0]]"), "plate.shape.polygon",
     "clockwise"),
    ("two-vertices", sub(L_SHAPE, "[[0, 0], [2, 0]]"), "plate.shape.polygon", "at least 3 vertices"),
    ("repeated-vertex", sub(L_SHAPE, "[[0, 0], [2, 0], [2, 0], [2, 2]]"), "plate.shape.polygon.1", "repeats"),
    ("collinear", sub(L_SHAPE, "[[0, 0], [1, 0], [2, 0]]"), "plate.shape.polygon", "fold back"),
    ("zero-radius", sub(f"polygon = {L_SHAPE}", "circle = [0, 0, 0.0]"), "plate.shape.circle", "radius must be > 0"),
    ("negative-radius", sub(f"polygon = {L_SHAPE}", "circle = [0, 0, -1.0]"), "plate.shape.circle", "> 0"),
    ("not-a-shape", sub(f"polygon = {L_SHAPE}", "square = 1.0"), "plate.shape", "polygon"),
    ("nan-vertex", sub("[2, 1], [1, 1]", "[2, nan], [1, 1]"), "plate.shape.polygon.2.1", "finite"),
    ("hole-outside", sub("circle = [0.5, 0.5, 0.2]", "circle = [1.5, 1.5, 0.2]"), "holes.0", "not inside"),
    ("hole-crossing", sub("circle = [0.5, 0.5, 0.2]", "circle = [0.5, 0.1, 0.2]"), "holes.0", "crosses"),
    ("hole-touching", sub("circle = [0.5, 0.5, 0.2]", "circle = [0.5, 0.2, 0.2]"), "holes.0", "touches"),
    ("hole-polygon-crossing", sub("circle = [0.5, 0.5, 0.2]", "polygon = [[0.5, 0.5], [1.5, 0.5], [1.5, 1.5]]"),
     "holes.0", "not inside"),
    ("holes-overlap", lambda t: t + "\n[[holes]]\ncircle = [0.7, 0.5, 0.15]\n", "holes.1", "overlaps"),
    ("holes-nested", lambda t: t + "\n[[holes]]\npolygon = [[0.45, 0.45], [0.55, 0.45], [0.5, 0.55]]\n", "holes.1",
     "overlaps"),
    ("hole-circle-polygon", lambda t: t + "\n[[holes]]\npolygon = [[0.6, 0.4], [1.2, 0.4], [1.2, 0.8]]\n", "holes.1",
     "overlaps"),
    ("shape-on-acm", sub('element = "dkt"', 'element = "acm"'), "plate.shape", "dkt"),
    ("named-edge-on-shape", sub('all = "simple"', 'left = "simple"'), "edges.left", "unknown edge"),
    ("edge-no-such-hole", sub('all = "simple"', 'hole1 = "simple"'), "edges.hole1", "no hole 1"),
    ("edge-circle-segment", sub('all = "simple"', 'hole0_0 = "simple"'), "edges.hole0_0", "no segments"),
    ("edge-segment-range", sub('all = "simple"', 'outer_4-6 = "simple"'), "edges.outer_4-6", "segments 0 to 5"),
    ("edge-reversed-range", sub('all = "simple"', 'outer_3-1 = "simple"'), "edges.outer_3-1", "not segments"),
    ("edge-named-twice", sub('all = "simple"', 'outer_0-2 = "simple"\nouter_2 = "clamped"'), "edges.outer_2",
     "holds segment 2"),
    ("no-size", sub("size = 0.25", ""), "mesh.size", "size = h"),
    ("bad-size", sub("size = 0.25", "size = -1.0"), "mesh.size", "> 0"),
    ("support-in-hole", sub("x = 1.5\ny = 0.5", "x = 0.5\ny = 0.5"), "supports.1", "in a hole"),
    ("support-in-notch", sub("x = 1.5\ny = 0.5", "x = 1.5\ny = 1.5"), "supports.1", "outside its shape"),
    ("bed-off-the-plate", lambda t: t + "\n[foundation]\nk = 100.0\nregion = [1.2, 1.8, 1.2, 1.8]\n",
     "foundation.region", "holds the centre of no cell"),
    ("patch-off-the-shape", lambda t: t + '\n[[loads]]\ntype = "patch"\nq = 1.0\nx0 = 1.2\nx1 = 1.8\ny0 = 1.2\n'
     'y1 = 1.8\n', "loads.1", "no plate there"),
    ("opening-over-the-edge", lambda t: t + '\n[[openings]]\nx0 = 1.5\nx1 = 2.5\ny0 = 0.2\ny1 = 0.4\n',
     "openings.0", "not inside the plate"),
]


@pytest.mark.parametrize("edit, field, words", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_geometry_names_field_and_file(tmp_path, edit, field, words):
    path = write(tmp_path, edit(BASE), "bad-shape.toml")
    with pytest.raises(pq.SceneError) as info:
        pq.Scene.from_toml(path)
    msg = str(info.value)
    assert msg.startswith(f"{path}: {field}:"), msg
    assert words in msg and "\n" not in msg


def test_rectangle_with_triangles_keeps_named_edges(tmp_path):
    """A rectangle meshed with DKT takes the rectangle's edge names (or all), and holes."""
    sc = pq.Scene(plate=pq.Plate(a=2.0, b=1.0), mesh=pq.MeshSpec(8, 4, "dkt"),
                  edges={"left": pq.Edge("clamped")}, holes=[{"circle": [1.0, 0.5, 0.2]}])
    assert sc.triangles and sc.plate.a == 2.0
    pq.Scene(mesh=pq.MeshSpec(8, 8, "acm"), edges={"all": pq.Edge("simple")})  # every side (test_scene)


def test_the_grid_speaks_the_same_language():
    """Holes and the triangle mesh's edge names on the rectangle grid: a hole removes the cells
    whose centre lies in it, ``outer`` is the rectangle, ``hole0`` the hole's staircase edge (one
    edge per side a kept cell shares with a removed one)."""
    from plateqp.model.grid import Grid

    sc = pq.Scene(mesh=pq.MeshSpec(8, 8, "acm"), holes=[{"circle": [0.5, 0.5, 0.2]}],
                  edges={"outer": pq.Edge("simple"), "hole0": pq.Edge("clamped")})
    g = Grid.from_scene(sc)
    removed = {(i, j) for i in range(8) for j in range(8) if math.hypot((i + 0.5) / 8 - 0.5, (j + 0.5) / 8 - 0.5) <= 0.2}
    assert sorted(np.flatnonzero(~g.cell_mask).tolist()) == sorted(8 * j + i for i, j in removed)
    shared = sum((i + di, j + dj) in removed for i in range(8) for j in range(8) if (i, j) not in removed
                 for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)))
    _, _, boundary, _ = g.boundary_edges()
    assert len(removed) == 12 and (boundary == 1).sum() == shared == 16 and (boundary == 0).sum() == 32
    with pytest.raises(pq.SceneError, match="holes.0.polygon: the vertices run clockwise"):
        pq.Scene(mesh=pq.MeshSpec(8, 8, "acm"), holes=[{"polygon": [[0.4, 0.4], [0.4, 0.6], [0.6, 0.6]]}])


def test_edge_names_resolve_most_specific_first():
    from plateqp.model.constraints import edge_table
    from plateqp.model.geometry import scene_domain

    sc = pq.Scene(plate=pq.Plate(shape={"polygon": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}),
                  mesh=pq.MeshSpec(element="dkt", size=0.25), holes=[{"circle": [0.5, 0.5, 0.2]}],
                  edges={"all": pq.Edge("simple"), "outer": pq.Edge("free"), "outer_1-2": pq.Edge("clamped")})
    t = {k: name for k, (name, _) in edge_table(sc, scene_domain(sc)).items()}
    # edges.all holds the outer boundary only: the hole's edge is free unless named
    assert t == {(0, 0): "outer", (0, 1): "outer_1-2", (0, 2): "outer_1-2", (0, 3): "outer", (0, 4): "outer",
                 (0, 5): "outer"}
    sc.edges["hole0"] = pq.Edge("clamped")
    assert edge_table(sc, scene_domain(sc))[(1, 0)][0] == "hole0"


def test_shapes_given_in_python_save_as_toml(tmp_path):
    sc = pq.Scene(plate=pq.Plate(shape=Circle(0.0, 0.0, 2.0)), mesh=pq.MeshSpec(element="dkt", size=0.5),
                  holes=[Polygon(((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)))])
    back = pq.Scene.from_toml(write(tmp_path, sc.to_toml()))
    assert back.plate.shape == {"circle": [0.0, 0.0, 2.0]} and back.holes == [{"polygon": [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]}]
    assert (back.plate.a, back.plate.b) == (4.0, 4.0)


def test_domain_covers_is_the_plate():
    """Points of an L-shape with a round hole: in the plate, in the notch, in the hole, on edges."""
    d = Domain(Polygon(((0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2))), (Circle(0.5, 0.5, 0.2),))
    x = np.array([1.5, 1.5, 0.5, 0.5, 2.0, 1.0, 0.5 + 0.2 * math.cos(1.0)])
    y = np.array([0.5, 1.5, 0.5, 1.5, 0.5, 1.5, 0.5 + 0.2 * math.sin(1.0)])
    assert d.covers(x, y).tolist() == [True, False, False, True, True, True, True]
    assert d.area == pytest.approx(3.0 - math.pi * 0.04, rel=1e-14)


# -- large polygons: the checks in n log n, and a vertex limit -------------------------------------
def star(n: int, centre=(0.0, 0.0), radius: float = 1.0) -> list[list[float]]:
    """A simple counter-clockwise polygon of n vertices (a wavy circle: r = R (1 + 0.2 sin 7θ))."""
    t = 2 * np.pi * np.arange(n) / n
    r = radius * (1 + 0.2 * np.sin(7 * t))
    return np.column_stack([centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)]).tolist()


def shaped(outline, holes=(), **kw) -> pq.Scene:
    return pq.Scene(plate=pq.Plate(shape={"polygon": outline}), mesh=pq.MeshSpec(element="dkt", size=0.5),
                    holes=[{"polygon": h} for h in holes], **kw)


def test_polygon_checks_do_not_test_every_pair_of_segments(monkeypatch):
    """The crossing checks of a plate's outline and of a hole in it look at the segments near each
    other (a spatial index), not at all n² / 2 pairs: the pairwise test runs far fewer than n times."""
    pytest.importorskip("shapely")
    from plateqp.model import crossings
    calls = []
    pairwise = crossings._segments_cross
    monkeypatch.setattr(crossings, "_segments_cross", lambda s, t: calls.append(1) or pairwise(s, t))
    n = 400
    sc = shaped(star(n), holes=[star(n, radius=0.3)])
    assert len(sc.holes[0]["polygon"]) == n
    assert len(calls) < n


def brute_crossing(pts) -> tuple[int, int] | None:
    """The first pair (i, j), i < j, of non-adjacent segments that cross (points in general
    position: proper crossings only), by testing every pair."""
    n = len(pts)
    seg = [(pts[i], pts[(i + 1) % n]) for i in range(n)]

    def orient(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])

    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue
            (p1, p2), (p3, p4) = seg[i], seg[j]
            if (orient(p3, p4, p1) > 0) != (orient(p3, p4, p2) > 0) and \
                    (orient(p1, p2, p3) > 0) != (orient(p1, p2, p4) > 0):
                return i, j
    return None


def test_self_intersections_agree_with_every_pair_tested():
    """Random polygons (3 to 12 random vertices): a polygon is refused as self-intersecting exactly
    when testing every pair of segments finds a crossing, and the message names that first pair."""
    from plateqp.model.geometry import parse_shape

    rng = np.random.default_rng(7)
    seen = {True: 0, False: 0}
    for _ in range(300):
        pts = rng.random((int(rng.integers(3, 13)), 2)).tolist()
        expect = brute_crossing(pts)
        msgs = []
        try:
            parse_shape({"polygon": pts}, "plate.shape", lambda where, what: msgs.append(what) or 1 / 0)
        except ZeroDivisionError:
            pass
        crossing = bool(msgs) and "self-intersecting" in msgs[0]
        assert crossing == (expect is not None), (pts, msgs, expect)
        if expect is not None:
            i, j = expect
            assert f"segment {i} (vertices" in msgs[0] and f"crosses segment {j} (vertices" in msgs[0], msgs
        seen[crossing] += 1
    assert min(seen.values()) > 30  # both verdicts drawn many times


@pytest.mark.parametrize("where", ["outline", "hole"])
def test_a_crossing_far_along_a_large_polygon_is_found(where):
    """Two segments of a 5000-vertex outline (or hole) made to cross, far apart in the list."""
    outline, hole = star(5000), star(5000, radius=0.3)
    bad = outline if where == "outline" else hole
    bad[4000], bad[4001] = bad[4001], bad[4000]  # a bow tie between vertices 3999 and 4002
    with pytest.raises(pq.SceneError) as info:
        shaped(outline, holes=[hole])
    field = "plate.shape.polygon" if where == "outline" else "holes.0.polygon"
    assert str(info.value).startswith(f"{field}: self-intersecting: segment 3999") and "segment 4001" in str(info.value)


def test_vertex_limit_is_a_clear_error(monkeypatch):
    from plateqp.model import geometry
    monkeypatch.setattr(geometry, "MAX_VERTICES", 60)
    shaped(star(60))
    with pytest.raises(pq.SceneError, match=r"^plate\.shape\.polygon: 61 vertices, more than .* \(at most 60\)"):
        shaped(star(61))
    with pytest.raises(pq.SceneError, match=r"^holes\.1\.polygon: 61 vertices"):
        shaped(star(8), holes=[star(8, (0.5, 0.0), 0.1), star(61, (-0.5, 0.0), 0.1)])
    # all boundaries together, the holes' vertices counted with the outline's
    with pytest.raises(pq.SceneError, match=r"^holes: the plate's boundaries have 70 vertices in all, more than"):
        shaped(star(40), holes=[star(30, (0.4, 0.0), 0.2)])
    with pytest.raises(pq.SceneError, match=r"^foundation\.region\.polygon: 61 vertices"):
        shaped(star(8), foundation=pq.Foundation(1.0, region={"polygon": star(61, radius=0.3)}))


def test_the_vertex_limit_is_checked_before_the_vertices_are_read():
    """A polygon over the limit is refused at once by its length, whatever its vertices hold."""
    from plateqp.model import geometry
    with pytest.raises(pq.SceneError, match="vertices, more than"):
        shaped([[0, 0]] * (geometry.MAX_VERTICES + 1))


def test_without_shapely_small_polygons_are_checked_pair_by_pair(monkeypatch):
    """shapely missing (the shapes extra not installed): polygons up to PAIRWISE_VERTICES vertices are
    checked by testing every pair of segments, with the same verdicts; larger ones ask for shapely."""
    import sys

    from plateqp.model import crossings
    monkeypatch.setitem(sys.modules, "shapely", None)  # import shapely raises ImportError
    monkeypatch.setattr(crossings, "PAIRWISE_VERTICES", n := 80)
    outline = star(n)
    shaped(outline, holes=[star(n, radius=0.3)])
    outline[50], outline[51] = outline[51], outline[50]
    with pytest.raises(pq.SceneError, match=r"^plate\.shape\.polygon: self-intersecting: segment 49 "):
        shaped(outline)
    with pytest.raises(pq.SceneError, match=rf"^plate\.shape\.polygon: {n + 1} vertices: .* needs shapely"):
        shaped(star(n + 1))
