"""Output on triangle meshes: nodal fields, VTK and xarray, against closed forms and exact patches.

References: Timoshenko & Woinowsky-Krieger, Theory of plates and shells, § 62 (clamped circular
plate of radius R under uniform q: M_r = q ((1 + ν) R² − (3 + ν) r²) / 16, so M = (1 + ν) q R² / 16
at the centre, w0 = q R⁴ / 64 D); a quadratic deflection has constant curvatures, which DKT
reproduces exactly, so its moments M = −D_b κ are exact at every node.
"""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.model.recovery import NodalOperator, moments

pytest.importorskip("gmsh")

R, NU, Q = 1.0, 0.3, 1.0


def disc(size=R / 16, **kw) -> pq.Scene:
    return pq.Scene(name="disc", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.01, E=1.0e7, nu=NU),
                    mesh=pq.MeshSpec(element="dkt", size=size), edges={"all": pq.Edge("clamped")},
                    loads=[pq.UniformLoad(Q)], **kw)


@pytest.fixture(scope="module")
def clamped():
    return pq.solve(disc())


def radial(res, quantity_xy):
    """M_r at the nodes from the nodal (Mx, My, Mxy): M_r = Mx c² + My s² + 2 Mxy s c."""
    xy = res.model.grid.nodes
    r = np.hypot(*xy.T)
    c, s = xy[:, 0] / np.where(r > 0, r, 1), xy[:, 1] / np.where(r > 0, r, 1)
    Mx, My, Mxy = (res.nodal(q) for q in quantity_xy)
    return r, Mx * c * c + My * s * s + 2 * Mxy * s * c


def test_nodal_moment_of_the_clamped_disc_against_the_closed_form(clamped):
    r, Mr = radial(clamped, ("Mx", "My", "Mxy"))
    k = int(np.argmin(r))  # the node nearest the centre (r ≈ 0.03 R at R/16)
    exact = Q * ((1 + NU) * R**2 - (3 + NU) * r**2) / 16
    assert Mr[k] == pytest.approx((1 + NU) * Q * R**2 / 16, rel=0.02)
    assert Mr[k] == pytest.approx(exact[k], rel=0.01)
    inner = r < 0.9 * R  # away from the clamped edge, within 2 % of the largest moment
    assert np.abs(Mr - exact)[inner].max() < 0.02 * (1 + NU) * Q * R**2 / 16
    assert clamped.nodal("Mx").shape == (clamped.model.grid.n_nodes,)


def test_nodal_principal_stresses_are_ordered_and_w_max_is_the_centre(clamped):
    s1, s2 = clamped.nodal("s1"), clamped.nodal("s2")
    assert np.all(np.isfinite(s1)) and np.all(s1 >= s2)
    assert np.any(s1 > s2 * (1 + 1e-3))  # not trivially equal
    np.testing.assert_array_equal(clamped.nodal("w"), clamped.w_nodes())
    w, x, y = clamped.w_max()
    assert w == pytest.approx(Q * R**4 / (64 * clamped.scene.plate.D), rel=0.01)
    assert np.hypot(x, y) < R / 16


def test_constant_curvature_patch_gives_exact_nodal_moments():
    """w = ½(A x² + B y²) + C x y on an L-shaped free plate (any triangles): κ constant, so every
    node's averaged moments are −D_b κ exactly."""
    sc = pq.Scene(plate=pq.Plate(shape={"polygon": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}, nu=NU),
                  mesh=pq.MeshSpec(element="dkt", size=0.3), loads=[pq.UniformLoad(1.0)])
    model = build_model(sc)
    A, B, C = 0.3, -0.7, 0.2
    x, y = model.grid.nodes.T
    u = np.zeros(model.n_full)
    u[0::3] = 0.5 * (A * x**2 + B * y**2) + C * x * y
    u[1::3] = A * x + C * y
    u[2::3] = B * y + C * x
    op = NodalOperator(model)
    for q, want in zip(("Mx", "My", "Mxy"), moments(sc.plate, A, B, C)):
        np.testing.assert_allclose(op(u, sc.plate, q), want, rtol=1e-9, atol=1e-12)


# -- results out ---------------------------------------------------------------------------
meshio = pytest.importorskip("meshio")
xr = pytest.importorskip("xarray")


def test_vtu_on_triangles_read_back(clamped, tmp_path):
    paths = clamped.write_vtu(tmp_path, "disc")
    mesh = meshio.read(paths[0])
    tri = clamped.model.grid.triangles
    assert mesh.cells[0].type == "triangle" and len(mesh.cells[0].data) == len(tri)
    np.testing.assert_array_equal(mesh.cells[0].data, tri)
    xy = mesh.points[:, :2]
    w = mesh.point_data["w"]
    np.testing.assert_allclose(w, clamped.deflection(xy[:, 0], xy[:, 1]), rtol=0, atol=1e-12 * abs(w).max())
    np.testing.assert_allclose(mesh.point_data["displacement"][:, 2], -w)
    k = int(np.argmin(np.hypot(*xy.T)))
    assert mesh.point_data["Mx"][k] == pytest.approx((1 + NU) * Q * R**2 / 16, rel=0.02)


def test_vtu_on_triangles_with_supports(tmp_path):
    sc = disc(size=R / 4, supports=[pq.Support(0.5, 0.0, gap=0.0), pq.Support(-0.5, 0.0, gap=-1e-3)])
    sc.edges = {"all": pq.Edge("simple")}
    res = pq.solve(sc)
    paths = res.write_vtu(tmp_path, "posts")
    sup = meshio.read(paths[1])
    np.testing.assert_allclose(sup.point_data["number"], [1, 2])
    np.testing.assert_allclose(sup.point_data["reaction"], res.reactions)


def test_xarray_on_triangles(clamped):
    ds = clamped.to_xarray()
    mesh = clamped.model.grid
    assert ds["w"].dims == ("node",) and ds.sizes["node"] == mesh.n_nodes
    np.testing.assert_allclose(ds["x"].values, mesh.nodes[:, 0])
    np.testing.assert_allclose(ds["y"].values, mesh.nodes[:, 1])
    np.testing.assert_array_equal(ds["triangles"].values, mesh.triangles)
    w = ds["w"].values
    np.testing.assert_allclose(w, clamped.deflection(ds["x"].values, ds["y"].values), atol=1e-12 * abs(w).max())
    k = int(np.argmin(np.hypot(ds["x"].values, ds["y"].values)))
    assert float(ds["Mx"][k]) == pytest.approx((1 + NU) * Q * R**2 / 16, rel=0.02)
