"""Results where users work: VTK through meshio, xarray datasets and pandas tables, on the
rectangle grid and on triangles.

External references: Timoshenko & Woinowsky-Krieger's table for the simply supported square
under uniform load (centre w = 0.0040624 q a⁴/D, Mx = 0.0479 q a², ν = 0.3); the clamped circular
plate of radius R under uniform q (ibid. § 62: centre w = q R⁴ / 64 D, M = (1 + ν) q R² / 16);
statics (a free square plate on four corner supports under uniform load: each reaction q a²/4; a
floating plate on a bed: the bed's reactions sum to the load). The files are read back with
meshio, not with plateqp, and the nodal values compared with :meth:`Result.deflection` at the
same points.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import plateqp as pq
from plateqp.errors import ExportError
from plateqp.io import fields as fields_mod
from plateqp.io import vtk

meshio = pytest.importorskip("meshio")
xr = pytest.importorskip("xarray")
pd = pytest.importorskip("pandas")

E, NU, H, Q = 2.1e11, 0.3, 0.01, 1000.0
D = E * H**3 / (12 * (1 - NU**2))


def _scene(**extra):
    data = {"name": "out", "plate": {"a": 1.0, "b": 1.0, "h": H, "E": E, "nu": NU},
            "mesh": {"nx": 16, "ny": 16, "element": "bfs"}, "loads": [{"type": "uniform", "q": Q}]}
    data.update(extra)
    return pq.Scene.from_dict(data)


@pytest.fixture(scope="module")
def simple():
    return pq.solve(_scene(edges={k: "simple" for k in ("left", "right", "bottom", "top")}))


R = 1.0  # the disc on triangles: q = 1, E = 1e7, h = 0.01, ν = NU


def _disc(size=R / 16, **kw):
    return pq.Scene(name="disc", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.01, E=1.0e7, nu=NU),
                    mesh=pq.MeshSpec(element="dkt", size=size), edges={"all": pq.Edge("clamped")},
                    loads=[pq.UniformLoad(1.0)], **kw)


# a plate with a closed form on each mesh: its centre, the centre's w and Mx and their tolerances
PLATES = {
    "grid": {"centre": (0.5, 0.5), "w": 0.0040624 * Q / D, "w_rel": 2e-3, "Mx": 0.0479 * Q, "Mx_rel": 0.03},
    "triangles": {"centre": (0.0, 0.0), "w": R**4 / (64 * _disc().plate.D), "w_rel": 0.01,
                  "Mx": (1 + NU) * R**2 / 16, "Mx_rel": 0.02},
}


@pytest.fixture(scope="module", params=sorted(PLATES))
def plate(request, simple):
    """(mesh, its solved plate, its closed form): the simply supported square on the grid (BFS
    16²), the clamped disc on DKT triangles of size R/16."""
    if request.param == "grid":
        return request.param, simple, PLATES["grid"]
    pytest.importorskip("gmsh")
    return request.param, pq.solve(_disc()), PLATES["triangles"]


@pytest.fixture(scope="module")
def corners():
    sup = [{"x": x, "y": y} for x, y in ((0, 0), (1, 0), (1, 1), (0, 1))]
    return pq.solve(_scene(supports=sup), backend="lemke", accuracy="high")


def test_vtu_plate_fields_match_the_closed_form_and_the_result(plate, tmp_path):
    mesh_kind, res, ref = plate
    paths = vtk.write_vtu(res, tmp_path, "slab")
    assert [p.name for p in paths] == ["slab.vtu"]  # no discrete supports: no supports file
    mesh = meshio.read(paths[0])
    if mesh_kind == "grid":
        assert mesh.cells[0].type == "quad" and len(mesh.cells[0].data) == 16 * 16
    else:
        tri = res.model.grid.triangles
        assert mesh.cells[0].type == "triangle" and len(mesh.cells[0].data) == len(tri)
        np.testing.assert_array_equal(mesh.cells[0].data, tri)
    xy = mesh.points[:, :2]
    k = int(np.argmin(np.hypot(xy[:, 0] - ref["centre"][0], xy[:, 1] - ref["centre"][1])))
    w = mesh.point_data["w"]
    assert w[k] == pytest.approx(ref["w"], rel=ref["w_rel"])
    assert mesh.point_data["Mx"][k] == pytest.approx(ref["Mx"], rel=ref["Mx_rel"])
    # every node's w is the result's own deflection there (BFS and DKT: w is nodal)
    np.testing.assert_allclose(w, res.deflection(xy[:, 0], xy[:, 1]), rtol=0, atol=1e-12 * abs(w).max())
    np.testing.assert_allclose(mesh.point_data["displacement"][:, 2], -w)
    s1 = mesh.point_data["s1"]
    assert np.all(s1 >= mesh.point_data["s2"])


def test_vtu_supports_carry_the_statics(corners, tmp_path):
    paths = vtk.write_vtu(corners, tmp_path, "corners")
    assert [p.name for p in paths] == ["corners.vtu", "corners-supports.vtu"]
    sup = meshio.read(paths[1])
    assert sup.cells[0].type == "vertex"
    np.testing.assert_array_equal(sup.point_data["number"], [1, 2, 3, 4])
    np.testing.assert_allclose(sup.point_data["reaction"], Q / 4, rtol=1e-9)
    np.testing.assert_array_equal(sup.point_data["contact"], 1.0)
    np.testing.assert_allclose(sup.points[:, :2], [[0, 0], [1, 0], [1, 1], [0, 1]])
    assert np.all(np.isinf(sup.point_data["stiffness"]))


def test_vtu_refuses_to_overwrite_and_checks_every_target_first(corners, tmp_path):
    (tmp_path / "corners-supports.vtu").write_text("mine")
    with pytest.raises(ExportError, match="corners-supports.vtu: exists"):
        vtk.write_vtu(corners, tmp_path, "corners")
    assert not (tmp_path / "corners.vtu").exists()  # checked before the first was written
    assert (tmp_path / "corners-supports.vtu").read_text() == "mine"
    vtk.write_vtu(corners, tmp_path, "corners", force=True)
    assert meshio.read(tmp_path / "corners-supports.vtu").points.shape == (4, 3)


def test_vtu_supports_on_triangles(tmp_path):
    """The supports' file of a triangle scene: numbered from 1, the result's reactions."""
    pytest.importorskip("gmsh")
    sc = _disc(size=R / 4, supports=[pq.Support(0.5, 0.0, gap=0.0), pq.Support(-0.5, 0.0, gap=-1e-3)])
    sc.edges = {"all": pq.Edge("simple")}
    res = pq.solve(sc)
    paths = res.write_vtu(tmp_path, "posts")
    sup = meshio.read(paths[1])
    np.testing.assert_allclose(sup.point_data["number"], [1, 2])
    np.testing.assert_allclose(sup.point_data["reaction"], res.reactions)


def test_bed_reactions_at_nodes_sum_to_the_load(tmp_path):
    res = pq.solve(_scene(mesh={"nx": 8, "ny": 8, "element": "bfs"}, foundation={"k": 1e7}))
    mesh = meshio.read(vtk.write_vtu(res, tmp_path, "bed")[0])
    r = mesh.point_data["reaction"]
    assert np.isfinite(r).all()  # a bed under the whole plate reaches every node
    assert r.sum() == pytest.approx(Q * 1.0 * 1.0, rel=1e-9)
    assert set(np.unique(mesh.point_data["contact"])) <= {0.0, 1.0}


def test_xarray_dataset_on_node_coordinates(plate):
    """The grid's dataset on (y, x), the triangles' on their nodes (with the triangles): w is the
    result's deflection at the coordinates, the centre's values the closed form's."""
    mesh_kind, res, ref = plate
    ds = fields_mod.to_xarray(res)
    if mesh_kind == "grid":
        assert ds["w"].dims == ("y", "x") and ds.sizes == {"y": 17, "x": 17}
        assert float(ds["w"].sel(x=0.5, y=0.5)) == pytest.approx(ref["w"], rel=ref["w_rel"])
        assert float(ds["Mx"].sel(x=0.5, y=0.5)) == pytest.approx(ref["Mx"], rel=ref["Mx_rel"])
        xs, ys = np.meshgrid(ds["x"].values, ds["y"].values)
    else:
        mesh = res.model.grid
        assert ds["w"].dims == ("node",) and ds.sizes["node"] == mesh.n_nodes
        np.testing.assert_allclose(ds["x"].values, mesh.nodes[:, 0])
        np.testing.assert_allclose(ds["y"].values, mesh.nodes[:, 1])
        np.testing.assert_array_equal(ds["triangles"].values, mesh.triangles)
        k = int(np.argmin(np.hypot(ds["x"].values, ds["y"].values)))
        assert float(ds["w"][k]) == pytest.approx(ref["w"], rel=ref["w_rel"])
        assert float(ds["Mx"][k]) == pytest.approx(ref["Mx"], rel=ref["Mx_rel"])
        xs, ys = ds["x"].values, ds["y"].values
    w = ds["w"].values
    np.testing.assert_allclose(w, res.deflection(xs, ys), atol=1e-12 * abs(w).max())
    assert ds["w"].attrs["units"] == "L" and ds.attrs["status"] == "optimal"


def test_xarray_is_nan_off_the_plate():
    scene = _scene(edges={"left": "clamped"}, openings=[{"x0": 0.5, "x1": 1.0, "y0": 0.5, "y1": 1.0}])
    ds = fields_mod.to_xarray(pq.solve(scene))
    assert np.isnan(float(ds["w"].sel(x=1.0, y=1.0)))  # the corner of the cut-out
    assert np.isfinite(float(ds["w"].sel(x=0.5, y=0.5)))  # the re-entrant corner is on the plate


def test_supports_frame_one_row_per_support(corners):
    df = fields_mod.supports_frame(corners)
    assert list(df.columns) == list(fields_mod.SUPPORT_COLUMNS)
    assert list(df["number"]) == [1, 2, 3, 4] and set(df["source"]) == {"support"}
    assert df["reaction"].sum() == pytest.approx(Q, rel=1e-9)  # statics, at the asked accuracy
    np.testing.assert_allclose(df["reaction"], Q / 4, rtol=1e-9)
    assert df["active"].all()


def test_supports_frame_of_a_two_sided_scene_is_empty(simple):
    df = fields_mod.supports_frame(simple)
    assert len(df) == 0 and list(df.columns) == list(fields_mod.SUPPORT_COLUMNS)


def test_solve_out_writes_the_vtu_and_its_w_is_the_json_w_max(tmp_path, capsys):
    from plateqp.cli import main

    rc = main(["solve", "heave", "--json", "--out", str(tmp_path)])
    d = json.loads(capsys.readouterr().out)
    assert rc == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["heave-supports.vtu", "heave-w.npy", "heave.json", "heave.vtu"]
    mesh = meshio.read(tmp_path / "heave.vtu")
    w = mesh.point_data["w"]
    k = int(np.nanargmax(np.abs(w)))
    assert w[k] == pytest.approx(d["w_max"], rel=1e-12)
    assert mesh.points[k, 0] == pytest.approx(d["w_max_x"]) and mesh.points[k, 1] == pytest.approx(d["w_max_y"])
    sup = meshio.read(tmp_path / "heave-supports.vtu")
    np.testing.assert_allclose(sup.point_data["reaction"], d["reactions"], rtol=1e-12)
    # a second run refuses before any work: the .vtu is among the files checked
    (tmp_path / "heave.json").unlink()
    (tmp_path / "heave-w.npy").unlink()
    assert main(["solve", "heave", "--out", str(tmp_path)]) == 2
    assert "heave" in capsys.readouterr().err and not (tmp_path / "heave.json").exists()
