"""What a mesh and an element answer so that no code downstream asks which kind it holds: the
point loads as nodes, the mesh's summary and grid view, the cells' corner curvatures."""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.model.generators import GENERATORS
from plateqp.model.elements import ELEMENTS


def grid_scene() -> pq.Scene:
    return pq.Scene(plate=pq.Plate(a=1.0, b=0.8, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(8, 6),
                    edges={"left": pq.Edge("simple")}, loads=[pq.PointLoad(P=2.0, x=0.33, y=0.41)],
                    supports=[pq.Support(1.0, 0.2), pq.Support(0.25, 0.8)])


def tri_scene() -> pq.Scene:
    return pq.Scene(plate=pq.Plate(shape={"circle": [0, 0, 1.0]}, h=0.02, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=0.3), edges={"all": pq.Edge("simple")},
                    loads=[pq.PointLoad(P=2.0, x=0.33, y=0.41)])


@pytest.fixture(scope="module", params=["grid", "triangles"])
def model(request):
    sc = grid_scene() if request.param == "grid" else tri_scene()
    sc.validate()
    return build_model(sc)


def test_the_generator_says_whether_point_loads_are_nodes(model):
    """A point load off the grid's nodes is a node of the mesh exactly when the generator says so."""
    gen = GENERATORS[model.element.cell_type]
    ld = model.scene.loads[0]
    assert gen.points_are_nodes == (model.grid.node_at(ld.x, ld.y) is not None)


def test_the_summary_counts_the_mesh(model):
    mesh, spec = model.grid, model.scene.mesh
    s = mesh.summary(spec.element)
    assert s["element"] == spec.element
    if "nx" in s:  # the cells a side of a grid
        assert (s["nx"], s["ny"]) == (spec.nx, spec.ny) and len(mesh.cells) == spec.nx * spec.ny
    else:
        assert (s["nodes"], s["triangles"]) == (len(mesh.nodes), len(mesh.cells))
        assert s["size"] == pytest.approx(mesh.size)
    words = mesh.summary_text(spec.element, "m")
    assert spec.element.upper() in words and all(str(v) in words for k, v in s.items() if k != "element")


def test_the_grid_view_is_the_nodes_on_the_grid_or_none(model):
    """The view puts node k at its (row, column) of the grid, NaN elsewhere; a mesh without a
    grid has none."""
    mesh = model.grid
    values = np.arange(len(mesh.nodes), dtype=float)
    view = mesh.grid_view(values)
    if view is None:
        assert not hasattr(mesh, "nx")
        return
    ix = np.rint(mesh.nodes[:, 0] / mesh.hx).astype(int)
    iy = np.rint(mesh.nodes[:, 1] / mesh.hy).astype(int)
    np.testing.assert_array_equal(view[iy, ix], values)
    assert np.isnan(view).sum() == view.size - len(values)


@pytest.mark.parametrize("name", sorted(ELEMENTS))
def test_corner_curvatures_are_the_basis_at_the_corners(name):
    """(ncell, corners, 3, ndof): w,xx, w,yy, w,xy of each cell at each corner (a quad's just
    inside it), equal to the element's own basis evaluated there."""
    el = ELEMENTS[name]()
    if el.cell_type == "quad":
        xy = np.array([[[0, 0], [0.5, 0], [0.5, 0.25], [0, 0.25]], [[0.5, 0], [1, 0], [1, 0.25], [0.5, 0.25]]])
        c = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
        local = 1e-9 + (1 - 2e-9) * c
    else:
        xy = np.array([[[0, 0], [0.6, 0.1], [0.2, 0.5]], [[0.6, 0.1], [0.9, 0.7], [0.2, 0.5]]])
        local = np.eye(3)
    K = el.corner_curvatures(xy)
    n, k = xy.shape[:2]
    assert K.shape == (n, k, 3, el.ndof)
    for cell in range(n):
        for v in range(k):
            for q, (dx, dy) in enumerate(((2, 0), (0, 2), (1, 1))):
                ref = el.basis(xy[cell:cell + 1], local[v:v + 1], dx, dy)[0]
                np.testing.assert_allclose(K[cell, v, q], ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())
    W = el.corner_w(xy)  # None: a corner's w is its node's own dof, as the basis says there
    for cell in range(n):
        for v in range(k):
            ref = el.basis(xy[cell:cell + 1], local[v:v + 1])[0]
            if W is None:
                np.testing.assert_array_equal(ref, np.eye(el.ndof)[v * el.ndof_node])
            else:
                np.testing.assert_allclose(W[cell, v], ref, rtol=1e-12, atol=1e-12)


def test_the_bounding_box_is_the_nodes_span(model):
    """(x0, x1, y0, y1) of the plate, the box its nodes span."""
    x0, x1, y0, y1 = model.grid.bbox
    nodes = model.grid.nodes
    span = (nodes[:, 0].min(), nodes[:, 0].max(), nodes[:, 1].min(), nodes[:, 1].max())
    assert (x0, x1, y0, y1) == pytest.approx(span, rel=1e-9, abs=1e-12)
