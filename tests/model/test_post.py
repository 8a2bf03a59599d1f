"""Fields from the curvatures and nodal averages (plateqp.model.recovery).

References: the plate's constitutive law written out by hand (M = −D (κx + ν κy), …), the
invariants of the principal stresses, and, for the nodal average, each kept cell evaluated
point by point with ``Result.at`` just inside its corners and averaged by hand; a quadratic
deflection has constant curvatures, which every element reproduces exactly, so its moments
M = −D_b κ are exact at every node; on triangles, Timoshenko & Woinowsky-Krieger, Theory of
plates and shells, § 62 (clamped circular plate of radius R under uniform q:
M_r = q ((1 + ν) R² − (3 + ν) r²) / 16, so M = (1 + ν) q R² / 16 at the centre, w0 = q R⁴ / 64 D).
"""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.model import recovery as post
from plateqp.model.assembly import build_model
from plateqp.studies import adapt_model, set_param


def scene_with_an_opening() -> pq.Scene:
    return pq.Scene(plate=pq.Plate(a=1.0, b=0.8, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(8, 6),
                    edges={"left": pq.Edge("simple")}, openings=[pq.Opening(0.6, 1.0, 0.5, 0.8)],
                    loads=[pq.UniformLoad(q=5.0), pq.PointLoad(P=2.0, x=0.3, y=0.5)],
                    supports=[pq.Support(1.0, 0.2, gap=0.001), pq.Support(0.25, 0.8)],
                    foundation=pq.Foundation(k=3e4, region=[0.5, 1.0, 0.0, 0.4]))


@pytest.fixture(scope="module")
def result() -> pq.Result:
    return pq.solve(scene_with_an_opening(), backend="lemke")


def by_hand(res: pq.Result, quantity: str) -> np.ndarray:
    """Each kept cell at points 1e-9 of a cell inside its corners (Result.at), averaged per node."""
    g, cells = res.model.grid, res.model.cells
    acc, cnt = np.zeros(g.n_nodes), np.zeros(g.n_nodes)
    for c in cells:
        i, j = c % g.nx, c // g.nx
        for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
            x = (i + (1e-9 + (1 - 2e-9) * di)) * g.hx
            y = (j + (1e-9 + (1 - 2e-9) * dj)) * g.hy
            node = (j + dj) * (g.nx + 1) + (i + di)
            acc[node] += float(res.at(x, y, quantity))
            cnt[node] += 1
    out = np.full(g.n_nodes, np.nan)
    out[cnt > 0] = acc[cnt > 0] / cnt[cnt > 0]
    return out.reshape(g.ny + 1, g.nx + 1)


@pytest.mark.parametrize("quantity", post.QUANTITIES)
def test_nodal_average_equals_cells_evaluated_by_hand(result, quantity):
    ref = by_hand(result, quantity)
    got = result.model.grid.to_grid(result.nodal(quantity))  # the grid view, NaN off the plate
    assert got.shape == ref.shape
    np.testing.assert_array_equal(np.isnan(got), np.isnan(ref))  # the opening's nodes are NaN
    assert np.isnan(got).any()
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-12 * np.nanmax(np.abs(ref)))


def test_nodal_w_is_the_nodal_dof(result):
    """w is continuous at the nodes: every cell gives the node's own dof (up to the slope times
    the 1e-9 of a cell the points lie inside), so the average is w_nodes."""
    w = result.w_nodes()
    on = ~np.isnan(result.nodal("w"))
    np.testing.assert_allclose(result.nodal("w")[on], w[on], rtol=0, atol=1e-7 * np.nanmax(np.abs(w)))


def test_one_operator_serves_every_solution_on_its_mesh(result):
    """The operator of the base model gives Result.nodal of another solve on an adapted model."""
    sc = result.scene
    op = post.NodalOperator(build_model(sc))
    other = pq.solve(set_param(sc, "loads.0.q", 12.0), backend="lemke",
                     model=adapt_model(result.model, set_param(sc, "loads.0.q", 12.0)))
    for res in (result, other):
        for q in ("w", "s1", "Mxy"):
            np.testing.assert_array_equal(op(res.u, sc.plate, q), res.nodal(q))


def test_constitutive_law_by_hand():
    plate = pq.Plate(a=1.0, b=1.0, h=0.05, E=2.0e11, nu=0.25)
    D, nu, h = plate.D, plate.nu, plate.h
    kxx, kyy, kxy = np.array([1e-3, -2e-3]), np.array([4e-4, 5e-4]), np.array([-3e-4, 7e-4])
    Mx, My, Mxy = post.moments(plate, kxx, kyy, kxy)
    np.testing.assert_allclose(Mx, -D * (kxx + nu * kyy), rtol=1e-14)
    np.testing.assert_allclose(My, -D * (kyy + nu * kxx), rtol=1e-14)
    np.testing.assert_allclose(Mxy, -D * (1 - nu) * kxy, rtol=1e-14)
    sx, sy, txy = post.stresses(plate, kxx, kyy, kxy)
    np.testing.assert_allclose(sx, 6 * Mx / h**2, rtol=1e-14)
    s1, s2, theta = post.principal(sx, sy, txy)
    assert np.all(s1 >= s2)
    np.testing.assert_allclose(s1 + s2, sx + sy, rtol=1e-12)  # the invariants
    np.testing.assert_allclose(s1 * s2, sx * sy - txy**2, rtol=1e-12)
    # σ1 acts along θ1: the normal stress on that direction is σ1
    c, s = np.cos(theta), np.sin(theta)
    np.testing.assert_allclose(sx * c**2 + sy * s**2 + 2 * txy * s * c, s1, rtol=1e-12)
    for q, v in (("Mx", Mx), ("sy", sy), ("s2", s2)):
        np.testing.assert_array_equal(post.from_curvatures(plate, q, kxx, kyy, kxy), v)


def test_unknown_quantity(result):
    with pytest.raises(ValueError, match="unknown quantity 'sigma'"):
        result.nodal("sigma")
    with pytest.raises(ValueError, match="unknown quantity"):
        post.from_curvatures(result.scene.plate, "w2", 0.0, 0.0, 0.0)


R, NU, Q = 1.0, 0.3, 1.0  # the plates below: radius (disc), Poisson's ratio, load


@pytest.mark.parametrize("element", ["acm", "bfs", "dkt"])
def test_constant_curvature_patch_gives_exact_nodal_moments(element):
    """w = ½(A x² + B y²) + C x y on a free plate (an L of any triangles; a grid with an
    opening): κ constant, so every node's averaged moments are −D_b κ exactly."""
    if element == "dkt":
        pytest.importorskip("gmsh")
        sc = pq.Scene(plate=pq.Plate(shape={"polygon": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}, nu=NU),
                      mesh=pq.MeshSpec(element="dkt", size=0.3), loads=[pq.UniformLoad(1.0)])
    else:
        sc = pq.Scene(plate=pq.Plate(a=2.0, b=2.0, nu=NU), mesh=pq.MeshSpec(8, 8, element),
                      openings=[pq.Opening(1.0, 2.0, 1.0, 2.0)], loads=[pq.UniformLoad(1.0)])
    model = build_model(sc)
    A, B, C = 0.3, -0.7, 0.2
    x, y = model.grid.node_xy().T
    dofs = {"w": 0.5 * (A * x**2 + B * y**2) + C * x * y, "wx": A * x + C * y, "wy": B * y + C * x,
            "wxy": np.full_like(x, C)}
    names = model.element.dof_names
    u = np.zeros(model.n_full)
    for k, name in enumerate(names):
        u[k::len(names)] = dofs[name]
    op = post.NodalOperator(model)
    on = np.isfinite(op(u, sc.plate, "Mx"))  # the grid's nodes inside the opening have no value
    assert on.all() if element == "dkt" else on.sum() > 0.5 * len(on)
    for q, want in zip(("Mx", "My", "Mxy"), post.moments(sc.plate, A, B, C)):
        np.testing.assert_allclose(op(u, sc.plate, q)[on], want, rtol=1e-9, atol=1e-12)


# -- nodal fields on triangles: the clamped disc ------------------------------------------------


@pytest.fixture(scope="module")
def clamped() -> pq.Result:
    """The clamped disc of radius R under uniform q, on DKT triangles of size R/16."""
    pytest.importorskip("gmsh")
    return pq.solve(pq.Scene(name="disc", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.01, E=1.0e7, nu=NU),
                             mesh=pq.MeshSpec(element="dkt", size=R / 16), edges={"all": pq.Edge("clamped")},
                             loads=[pq.UniformLoad(Q)]))


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
