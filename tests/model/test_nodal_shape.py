"""One result shape on every mesh: a nodal field is one value per node of the plate, in the
order of ``mesh.nodes``, on the structured grid (ACM, BFS, with an opening) and on a triangle
mesh (DKT); the grid view is explicit (``Grid.to_grid``, ``to_xarray`` on x, y).

References: w at a node is the deflection the element interpolates there (``Result.deflection``
at the node's coordinates); a node off the plate has no value; the VTK file read back with
meshio, not with plateqp; figures drawn on the Agg canvas and written as PNG files.
"""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.model import recovery as post
def grid_scene(element: str, opening: bool) -> pq.Scene:
    return pq.Scene(name=f"grid-{element}", plate=pq.Plate(a=1.0, b=0.8, h=0.02, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(8, 6, element=element), edges={"left": pq.Edge("simple")},
                    openings=[pq.Opening(0.5, 1.0, 0.5, 0.8)] if opening else [],
                    loads=[pq.UniformLoad(q=5.0)], supports=[pq.Support(1.0, 0.0), pq.Support(0.25, 0.8, gap=1e-4)])


def tri_scene() -> pq.Scene:
    return pq.Scene(name="disc", plate=pq.Plate(shape={"circle": [0.0, 0.0, 1.0]}, h=0.02, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=0.25), edges={"all": pq.Edge("simple")},
                    loads=[pq.UniformLoad(1.0)], supports=[pq.Support(0.0, 0.0, gap=1e-4)])


CASES = {"acm": lambda: grid_scene("acm", False), "bfs-opening": lambda: grid_scene("bfs", True),
         "dkt": tri_scene}


@pytest.fixture(scope="module", params=sorted(CASES))
def result(request):
    if request.param == "dkt":
        pytest.importorskip("gmsh")
    return pq.solve(CASES[request.param](), backend="lemke")


@pytest.mark.parametrize("quantity", post.QUANTITIES)
def test_every_nodal_field_is_one_value_per_mesh_node(result, quantity):
    mesh = result.model.grid
    v = result.nodal(quantity)
    assert v.shape == (len(mesh.nodes),)
    assert np.all(np.isfinite(v))  # every node of the plate has a value, none off it


def test_w_at_the_nodes_is_the_deflection_there(result):
    mesh = result.model.grid
    w = result.w_nodes()
    assert w.shape == (len(mesh.nodes),)
    want = result.deflection(mesh.nodes[:, 0], mesh.nodes[:, 1])
    np.testing.assert_allclose(w, want, rtol=0, atol=1e-12 * np.abs(want).max())
    np.testing.assert_allclose(result.nodal("w"), want, rtol=0, atol=1e-7 * np.abs(want).max())
    wm, x, y = result.w_max()
    k = int(np.argmax(np.abs(want)))
    assert (wm, x, y) == (pytest.approx(want[k]), pytest.approx(mesh.nodes[k, 0]), pytest.approx(mesh.nodes[k, 1]))


def test_the_grid_view_puts_each_node_at_its_coordinates(result):
    mesh = result.model.grid
    if mesh.grid_shape is None:
        pytest.skip("a triangle mesh has no grid view")
    W = mesh.to_grid(result.nodal("s1"))
    assert W.shape == mesh.grid_shape
    on = mesh.node_mask().reshape(mesh.grid_shape)
    assert np.array_equal(np.isfinite(W), on)
    j, i = np.divmod(mesh.plate_node_ids, mesh.nx + 1)
    np.testing.assert_allclose(i * mesh.hx, mesh.nodes[:, 0])
    np.testing.assert_allclose(j * mesh.hy, mesh.nodes[:, 1])
    np.testing.assert_array_equal(W[j, i], result.nodal("s1"))


# -- consumers: one path ------------------------------------------------------------------
def test_to_xarray_grid_view_and_node_view(result):
    pytest.importorskip("xarray")
    mesh = result.model.grid
    dn = result.to_xarray(nodes=True)
    assert dn["s1"].dims == ("node",) and dn.sizes["node"] == len(mesh.nodes)
    np.testing.assert_array_equal(dn["s1"].values, result.nodal("s1"))
    np.testing.assert_array_equal(dn["x"].values, mesh.nodes[:, 0])
    np.testing.assert_array_equal(dn[f"{mesh.cell_type}s"].values, mesh.cells)
    ds = result.to_xarray()
    if mesh.grid_shape is None:
        assert ds["w"].dims == ("node",)
        return
    assert ds["w"].dims == ("y", "x")
    for q in ("w", "Mx", "s1"):
        want = mesh.to_grid(result.w_nodes() if q == "w" else result.nodal(q))
        np.testing.assert_array_equal(ds[q].values, want)
    xs, ys = np.meshgrid(ds["x"].values, ds["y"].values)
    on = np.isfinite(ds["w"].values)
    np.testing.assert_allclose(ds["w"].values[on], result.deflection(xs[on], ys[on]),
                               atol=1e-12 * float(abs(ds["w"]).max()))


def test_vtu_cells_are_the_mesh_cells_on_its_nodes(result, tmp_path):
    meshio = pytest.importorskip("meshio")
    mesh = result.model.grid
    got = meshio.read(result.write_vtu(tmp_path, "plate")[0])
    assert [c.type for c in got.cells] == [mesh.cell_type]
    np.testing.assert_array_equal(got.cells[0].data, mesh.cells)
    np.testing.assert_allclose(got.points[:, :2], mesh.nodes)
    w = got.point_data["w"]
    np.testing.assert_allclose(w, result.deflection(got.points[:, 0], got.points[:, 1]), atol=1e-12 * abs(w).max())
    np.testing.assert_array_equal(got.point_data["s1"], result.nodal("s1"))


def test_the_field_figures_draw_every_mesh_and_write_files(result, tmp_path):
    pytest.importorskip("matplotlib")
    from plateqp import plotting as pl

    two = pq.solve_bilateral(result.scene)
    figs = {"surface": pl.plot_deflection_surface(result, two), "contours": pl.plot_deflection_contours(result, two),
            "s1": pl.plot_principal_stress(result, two), "difference": pl.plot_difference(result, two)}
    for name, fig in figs.items():
        # the filled contours (or the surface) cover the plate's nodes: the triangulation of the mesh
        filled = [c for c in fig.axes[0].collections if getattr(c, "filled", False) or name == "surface"]
        assert filled, name
        path = tmp_path / f"{name}.png"
        pl.save(fig, path)
        assert path.stat().st_size > 10_000, name
    from matplotlib.tri import TriContourSet

    for name in ("contours", "s1", "difference"):  # the nodal values on the mesh's triangulation, every mesh
        assert all(isinstance(c, TriContourSet) for c in figs[name].axes[0].collections
                   if hasattr(c, "levels")), name
    cs = [c for c in figs["contours"].axes[0].collections if getattr(c, "filled", False)][0]
    w = np.concatenate([result.w_nodes(), two.w_nodes()])
    assert cs.levels[0] <= w.min() and cs.levels[-1] >= w.max()


def test_zones_of_the_grid_view_shape_are_refused_by_name(result):
    pytest.importorskip("matplotlib")
    from plateqp import plotting as pl
    from plateqp.errors import PlateQPError

    two = pq.solve_bilateral(result.scene)
    with pytest.raises(PlateQPError, match="^zones: one value per node of the plate"):
        pl.plot_difference(result, two, zones=np.zeros((3, len(result.model.grid.nodes))))
