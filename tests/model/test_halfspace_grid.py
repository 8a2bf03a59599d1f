"""The half-space bed's force flexibility on a grid, matrix-free (plateqp.model.halfspace_grid).

References, each independent of the FFT route:
- the dense flexibility the model builds (:func:`plateqp.model.soil.halfspace_flexibility`:
  Boussinesq's integral exact over every quarter polygon, point by point, then ½(H + Hᵀ));
- the settlement of the surface under a uniform pressure p over a rectangle, by superposing four
  rectangles that meet at the point, each settling its corner by Love's (1929) closed form
  (Timoshenko & Goodier, Theory of Elasticity, 3rd ed., 1970, § 138, the corner of a uniformly
  loaded rectangle a × b):
  w = p (1 − ν²)/(π E) · [a ln((b + √(a² + b²))/a) + b ln((a + √(a² + b²))/b)];
- symmetry and positive definiteness of a flexibility (reciprocity; the half-space's strain
  energy is positive).
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import plateqp as pq
from plateqp.errors import ProblemError
from plateqp.model.assembly import build_model
from plateqp.model.grid import Grid
from plateqp.model.halfspace import flexibility
from plateqp.model.soil import halfspace_areas, halfspace_flexibility, pressure_cells

E_SOIL, NU_SOIL = 3e7, 0.3


def scene(a=2.0, b=1.0, nx=8, ny=5, region=None, **kw) -> pq.Scene:
    return pq.Scene(plate=pq.Plate(a=a, b=b, h=0.1, E=3e10, nu=0.2), mesh=pq.MeshSpec(nx=nx, ny=ny),
                    loads=[pq.UniformLoad(1e3)],
                    foundation=pq.Foundation(model="halfspace", E=E_SOIL, nu=NU_SOIL, region=region), **kw)


#: (name, scene): cells square and not, the bed over the whole plate, a sub-box, a circle and a
#: polygon, a clamped edge and a pin (prescribed nodes press no soil), a hole and an opening
CASES = [
    ("square-cells-whole-plate", lambda: scene(a=1.0, b=1.0, nx=6, ny=6)),
    ("flat-cells-whole-plate", lambda: scene(a=2.0, b=0.6, nx=7, ny=5)),
    ("tall-cells-sub-box", lambda: scene(a=1.0, b=3.0, nx=9, ny=6, region=[0.2, 0.8, 0.4, 2.2])),
    ("circle-bed", lambda: scene(a=2.0, b=1.5, nx=10, ny=8, region={"circle": [0.9, 0.8, 0.6]})),
    ("polygon-bed", lambda: scene(nx=10, ny=6, region={"polygon": [[0.1, 0.1], [1.9, 0.3], [1.0, 0.95]]})),
    ("clamped-edge-and-pin", lambda: scene(nx=8, ny=5, edges={"left": pq.Edge("clamped")},
                                            pins=[pq.Pin(1.0, 0.6)])),
    ("hole-and-opening", lambda: scene(a=2.0, b=1.0, nx=10, ny=6, holes=[{"circle": [1.0, 0.5, 0.25]}],
                                       openings=[pq.Opening(1.6, 2.0, 0.7, 1.0)],
                                       edges={"bottom": pq.Edge("simple")}, region=[0.0, 1.7, 0.0, 1.0])),
]


def collocated(model, nodes):
    """H before symmetrising, as the dense route builds it (soil.halfspace_flexibility's steps)."""
    fnd, mesh = model.scene.foundation, model.grid
    pos = np.full(mesh.n_nodes, -1)
    pos[nodes] = np.arange(nodes.size)
    owner, polys = pressure_cells(mesh, fnd.region)
    keep = pos[owner] >= 0
    return flexibility(mesh.node_xy()[nodes], polys[keep], fnd.E, fnd.nu, per="force", owner=pos[owner][keep])


def operator_of(model):
    fnd = model.scene.foundation
    return model.grid.halfspace_flexibility_operator(fnd.region, fnd.E, fnd.nu, model.soil_nodes)


@pytest.mark.parametrize("make", [c[1] for c in CASES], ids=[c[0] for c in CASES])
def test_the_operator_is_the_dense_flexibility_the_model_builds(make):
    model = build_model(make())
    nodes = model.soil_nodes
    H = halfspace_flexibility(model, nodes)
    op = operator_of(model)
    m = nodes.size
    assert op.shape == (m, m) and op.dtype == np.float64
    X = np.random.default_rng(1).standard_normal((m, 3))
    for Y, ref in ((op @ X[:, 0], H @ X[:, 0]), (op.rmatvec(X[:, 1]), H.T @ X[:, 1]), (op @ X, H @ X),
                   (op.H @ X, H.T @ X)):
        assert np.linalg.norm(Y - ref) <= 1e-10 * np.linalg.norm(ref)
    full = op @ np.eye(m)
    assert np.abs(full - H).max() <= 1e-10 * np.abs(H).max()
    np.testing.assert_allclose(op.diagonal(), np.diag(H), rtol=1e-10, atol=0)
    Hc = collocated(model, nodes)
    assert np.linalg.norm(op.settlements(X) - Hc @ X) <= 1e-10 * np.linalg.norm(Hc @ X)
    assert np.linalg.norm(op.settlements(X[:, 2]) - Hc @ X[:, 2]) <= 1e-10 * np.linalg.norm(Hc @ X[:, 2])


def corner(a, b):
    """Love's corner integral of 1/r over an a × b rectangle at its corner (0 for a side of 0)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    d = np.sqrt(a * a + b * b)
    with np.errstate(divide="ignore", invalid="ignore"):
        return (np.where(a > 0, a * np.log((b + d) / np.where(a > 0, a, 1.0)), 0.0)
                + np.where(b > 0, b * np.log((a + d) / np.where(b > 0, b, 1.0)), 0.0))


@pytest.mark.parametrize("a, b, nx, ny, box", [(1.0, 1.0, 8, 8, None), (3.0, 1.0, 9, 4, None),
                                               (2.0, 2.0, 10, 7, (0.4, 1.6, 2 / 7, 10 / 7))])
def test_a_uniform_pressure_settles_every_node_as_loves_rectangle(a, b, nx, ny, box):
    """Forces x_j = p A_j press the bed's rectangle uniformly (the quarters tile it): every node
    settles (H x) p (1 − ν²)/(π E) Σ corner(…) of the four rectangles meeting at it, to rounding;
    the symmetrised operator keeps H's quadratic form, xᵀ ½(H + Hᵀ) x = xᵀ H x."""
    region = None if box is None else list(box)
    mesh = Grid.from_scene(scene(a=a, b=b, nx=nx, ny=ny, region=region))
    area = halfspace_areas(mesh, region)
    nodes = np.flatnonzero(area > 0)
    p = 2.5e4
    x = p * area[nodes]
    op = mesh.halfspace_flexibility_operator(region, E_SOIL, NU_SOIL, nodes)
    x0, x1, y0, y1 = (0.0, a, 0.0, b) if box is None else box
    px, py = mesh.node_xy()[nodes].T
    I = corner(px - x0, py - y0) + corner(x1 - px, py - y0) + corner(px - x0, y1 - py) + corner(x1 - px, y1 - py)
    w = p * (1 - NU_SOIL**2) / (np.pi * E_SOIL) * I
    np.testing.assert_allclose(op.settlements(x), w, rtol=1e-11, atol=0)
    assert x @ (op @ x) == pytest.approx(x @ w, rel=1e-11)


def test_the_operator_is_symmetric_and_positive_definite():
    rng = np.random.default_rng(7)
    nx, ny = (int(v) for v in rng.integers(4, 9, size=2))
    a, b = (float(v) for v in rng.uniform(0.5, 3.0, size=2))
    x0, y0 = rng.uniform(0.0, 0.3) * a, rng.uniform(0.0, 0.3) * b
    model = build_model(scene(a=a, b=b, nx=nx, ny=ny, region=[x0, x0 + 0.6 * a, y0, y0 + 0.6 * b],
                              edges={"bottom": pq.Edge("simple")}))
    op = operator_of(model)
    m = op.shape[0]
    x, y = rng.standard_normal((2, m))
    scale = np.linalg.norm(x) * np.linalg.norm(y) * np.abs(op.diagonal()).max()
    assert abs(x @ (op @ y) - y @ (op @ x)) <= 1e-13 * scale
    D = op @ np.eye(m)
    assert np.abs(D - D.T).max() <= 1e-13 * np.abs(D).max()
    assert np.linalg.eigvalsh(0.5 * (D + D.T)).min() > 0


def test_a_512_squared_bed_applies_without_a_dense_matrix():
    """513² = 263 169 bed nodes: a dense H would take 554 GB; the operator builds and applies in
    well under 1 GB (its padded FFT arrays), and its answer is Love's at the centre node."""
    n, a = 512, 4.0
    tracemalloc.start()
    try:
        mesh = Grid.from_scene(scene(a=a, b=a, nx=n, ny=n))
        nodes = mesh.plate_node_ids
        op = mesh.halfspace_flexibility_operator(None, E_SOIL, NU_SOIL, nodes)
        area = np.full((n + 1, n + 1), (a / n) ** 2)
        area[0] /= 2
        area[-1] /= 2
        area[:, 0] /= 2
        area[:, -1] /= 2
        w = op.settlements(area.ravel())
        op @ area.ravel()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2**30
    centre = (n // 2) * (n + 1) + n // 2
    assert w[centre] == pytest.approx((1 - NU_SOIL**2) / (np.pi * E_SOIL) * 4 * corner(a / 2, a / 2), rel=1e-11)


def test_a_node_that_presses_no_bed_cell_is_refused():
    mesh = Grid.from_scene(scene(nx=6, ny=4, region=[0.0, 1.0, 0.0, 1.0]))
    far = 4 * 7 + 6  # node (6, 4): the corner (2, 1), beyond the box
    with pytest.raises(ProblemError, match=r"^nodes: node 34 .*no bed cell"):
        mesh.halfspace_flexibility_operator([0.0, 1.0, 0.0, 1.0], E_SOIL, NU_SOIL, np.array([0, 1, far]))


@pytest.mark.parametrize("E, nu, field", [(-1.0, 0.3, "E"), (3e7, 0.7, "nu")])
def test_bad_soil_parameters_are_refused_by_name(E, nu, field):
    mesh = Grid.from_scene(scene(nx=4, ny=3))
    with pytest.raises(ProblemError, match=rf"^{field}: "):
        mesh.halfspace_flexibility_operator(None, E, nu, mesh.plate_node_ids)


def test_a_triangle_mesh_has_no_matrix_free_route():
    sc = pq.Scene(plate=pq.Plate(shape={"circle": [0.0, 0.0, 1.0]}, h=0.1, E=3e10, nu=0.2),
                  mesh=pq.MeshSpec(element="dkt", size=0.5), loads=[pq.UniformLoad(1.0)],
                  foundation=pq.Foundation(model="halfspace", E=E_SOIL, nu=NU_SOIL))
    mesh = build_model(sc).grid
    assert mesh.halfspace_flexibility_operator(None, E_SOIL, NU_SOIL, np.arange(mesh.n_nodes)) is None
