"""What every mesh shows of itself to figures and tables, and what its generator answers for the
scene's checks, so that no code downstream asks which kind of mesh it holds: the outline, the
default section lines, the position along the contour, the layout of a dataset, the cover of the
point checks, the scene-language rules."""

from __future__ import annotations

import math

import numpy as np
import pytest

import plateqp as pq
from plateqp.errors import SceneError
from plateqp.model.assembly import build_model
from plateqp.model.generators import GENERATORS, mesh_generator
from plateqp.model.grid import Grid
from plateqp.model.trimesh import TriMesh

A, B = 1.0, 0.8
OPENING = (0.5, 0.75, 0.3, 0.6)  # on cell lines of the 8 x 8 grid
HOLE = (0.3, 0.2, 0.2)  # a circle in the disc of radius 1


def grid_scene(supports=None) -> pq.Scene:
    return pq.Scene(plate=pq.Plate(a=A, b=B, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(8, 8),
                    openings=[pq.Opening(*OPENING)], loads=[pq.PointLoad(P=2.0, x=0.33, y=0.41)],
                    supports=supports if supports is not None else [pq.Support(1.0, 0.2), pq.Support(0.25, 0.7),
                                                                    pq.Support(0.0, 0.0)])


def tri_scene() -> pq.Scene:
    return pq.Scene(plate=pq.Plate(shape={"circle": [0, 0, 1.0]}, h=0.02, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=0.3), holes=[{"circle": list(HOLE)}],
                    edges={"outer": pq.Edge("simple")}, loads=[pq.PointLoad(P=2.0, x=-0.33, y=0.41)],
                    supports=[pq.Support(0.5, -0.5), pq.Support(-0.5, -0.5)])


@pytest.fixture(scope="module", params=["grid", "triangles"])
def model(request):
    sc = grid_scene() if request.param == "grid" else tri_scene()
    sc.validate()
    return build_model(sc)


def _shoelace(pts: np.ndarray) -> float:
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


# -- the generator: scene-language rules and the cover of the point checks --------------------
def test_the_generator_is_the_class_of_the_mesh_it_makes(model):
    assert type(model.grid) is mesh_generator(model.scene)
    assert set(GENERATORS.values()) == {Grid, TriMesh}


def test_an_unknown_element_is_a_scene_error_naming_it():
    sc = grid_scene()
    sc.mesh.element = "nope"
    with pytest.raises(SceneError, match=r"^mesh\.element: unknown element 'nope'"):
        mesh_generator(sc)


def test_the_cover_answers_as_the_plate_is(model):
    """A point is covered exactly where the plate is: on the grid where its kept cells are, on
    triangles inside the disc and outside the hole (the true circles, not their chords)."""
    cover = mesh_generator(model.scene).cover(model.scene)
    x0, x1, y0, y1 = model.grid.bbox
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(x0, x1, 400), rng.uniform(y0, y1, 400)])
    if isinstance(model.grid, Grid):
        on = model.grid.locate(pts[:, 0], pts[:, 1])[0] >= 0
    else:
        on = (np.hypot(*pts.T) <= 1.0) & (np.hypot(pts[:, 0] - HOLE[0], pts[:, 1] - HOLE[1]) >= HOLE[2])
    assert [cover.covers(x, y) for x, y in pts] == list(on)
    assert on.any() and not on.all()


def test_a_shape_or_a_size_needs_the_triangle_generator():
    sc = grid_scene()
    sc.mesh.size = 0.1
    with pytest.raises(SceneError, match=r"mesh\.size: needs a triangle mesh"):
        Grid.check_scene_fields(sc)
    TriMesh.check_scene_fields(tri_scene())  # nothing to refuse


# -- what figures and tables read ---------------------------------------------------------------
def test_the_outline_is_the_plates_boundary(model):
    """Grid: the boundary sides of the kept cells, as long as the rectangle's and the opening's
    perimeters together. Triangles: closed loops (outer, hole) whose enclosed area less the
    hole's is the triangles' area, each loop's points on its circle."""
    paths = model.grid.outline_paths()
    if isinstance(model.grid, Grid):
        (gid, segs, closed), = paths
        assert (gid, closed, segs.shape[1:]) == ("outline", False, (2, 2))
        x0, x1, y0, y1 = OPENING
        length = np.hypot(*(segs[:, 1] - segs[:, 0]).T).sum()
        assert length == pytest.approx(2 * (A + B) + 2 * (x1 - x0 + y1 - y0), rel=1e-12)
        return
    assert [(g, c) for g, _, c in paths] == [("outline", True), ("hole", True)]
    (_, outer, _), (_, hole, _) = paths
    assert _shoelace(outer) - _shoelace(hole) == pytest.approx(model.grid.areas().sum(), rel=1e-12)
    assert np.hypot(*outer.T) == pytest.approx(np.ones(len(outer)), abs=1e-9)
    assert np.hypot(hole[:, 0] - HOLE[0], hole[:, 1] - HOLE[1]) == pytest.approx(np.full(len(hole), HOLE[2]), abs=1e-9)


def test_default_sections_lie_where_the_mesh_says(model):
    """Triangles: every point of every section is on the plate. Grid: lines across the
    rectangle, through the point load and along its diagonal."""
    secs = model.grid.default_sections(model.scene)
    assert secs
    if isinstance(model.grid, Grid):
        assert [s[0] for s in secs] == ["y = 0.41", "x = 0.33", "y = 0 (edge)", "diagonal"]
        assert secs[-1][1:] == ((0.0, 0.0), (A, B))
        return
    for _, p0, p1 in secs:
        t = np.linspace(0, 1, 101)
        x, y = p0[0] + t * (p1[0] - p0[0]), p0[1] + t * (p1[1] - p0[1])
        assert (model.grid.locate(x, y)[0] >= 0).all()


def test_rows_of_supports_are_sections_across_the_rectangle():
    sc = grid_scene([pq.Support(x, y) for y in (0.2, 0.7) for x in (0.25, 0.875)])
    sc.validate()
    secs = build_model(sc).grid.default_sections(sc)
    assert secs == [("y = 0.2", (0.0, 0.2), (A, 0.2)), ("y = 0.7", (0.0, 0.7), (A, 0.7))]


def test_the_contour_position_is_the_arc_length_on_a_rectangle(model):
    xy = np.array([[0.0, 0.0], [A, 0.0], [A, B], [0.0, B], [0.5, 0.0]])
    pos, along = model.grid.contour_position(xy)
    if isinstance(model.grid, Grid):
        assert along and pos == pytest.approx([0.0, A, A + B, 2 * A + B, 0.5])
        assert not model.grid.contour_position(np.array([[0.0, 0.0], [A, 0.0], [0.5, 0.4]]))[1]
    else:  # a shaped plate's points go by number
        assert not along and pos.shape == (5,)


def test_the_field_layout_is_the_grid_view_or_one_value_per_node(model):
    mesh = model.grid
    values = {"w": np.arange(len(mesh.nodes), dtype=float)}
    dims, coords, fields = mesh.field_layout(values, nodes=True)
    assert dims == ("node",) and np.array_equal(fields["w"], values["w"])
    assert np.array_equal(np.column_stack([coords["x"][1], coords["y"][1]]), mesh.nodes)
    dims, coords, fields = mesh.field_layout(values)
    if isinstance(mesh, TriMesh):
        assert dims == ("node",)
        return
    assert dims == ("y", "x")
    xs, ys = coords["x"][1], coords["y"][1]
    for k, (x, y) in enumerate(mesh.nodes):  # node k at its row and column
        i, j = int(np.argmin(abs(xs - x))), int(np.argmin(abs(ys - y)))
        assert (xs[i], ys[j], fields["w"][j, i]) == (x, y, k)
    assert np.isnan(fields["w"]).sum() == (mesh.nx + 1) * (mesh.ny + 1) - len(mesh.nodes)


def test_the_caption_names_the_mesh(model):
    words = model.grid.caption("acm" if isinstance(model.grid, Grid) else "dkt")
    if isinstance(model.grid, Grid):
        assert words == "8 × 8 mesh"
    else:
        assert words == f"triangle mesh (size {model.grid.size:g}, DKT)" and not math.isnan(model.grid.size)
