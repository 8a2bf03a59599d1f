"""The elastic half-space's surface flexibility (plateqp.model.halfspace): Boussinesq's point force
w = P (1 − ν²) / (π E r), integrated exactly over polygons, the dense matrix of cells, and the
FFT operator on a grid of equal rectangles.

External references: a uniform pressure q over a disc of radius a settles its centre by
2 q a (1 − ν²)/E and its edge by 4 q a (1 − ν²)/(π E) (Timoshenko & Goodier, Theory of Elasticity,
§ 138; Johnson, Contact Mechanics, § 3.2); over a rectangle a × b its corner settles by
q (1 − ν²)/(π E) [a ln((b + √(a² + b²))/a) + b ln((a + √(a² + b²))/b)] (Steinbrenner; Love 1929),
and the centre of a square of side B by 1.1222 q B (1 − ν²)/E (the published coefficient). Far
from a cell its pressure acts as a point force; the next term of the expansion of 1/|x − ξ| in
ξ/r (the cell's second moments) is exact for a rectangle hx × hy:
∬ dA/|x − ξ| = A/r [1 + (3 r̂x² hx² + 3 r̂y² hy² − hx² − hy²)/(24 r²) + O((h/r)⁴)].
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from plateqp.errors import ProblemError
from plateqp.model.halfspace import (GridFlexibility, flexibility, grid_kernel, polygon_potential,
                                     rectangle_potential)

E, NU, Q = 3.0e4, 0.3, 2.5
C = (1 - NU**2) / (math.pi * E)  # settlement per unit force at unit distance


def ngon(n: int, a: float = 1.0, centre=(0.0, 0.0), clockwise: bool = False) -> np.ndarray:
    """The regular n-gon inscribed in the circle of radius a (its vertices on the circle)."""
    t = 2 * np.pi * np.arange(n) / n
    xy = np.column_stack([centre[0] + a * np.cos(t), centre[1] + a * np.sin(t)])
    return xy[::-1] if clockwise else xy


def box(x0, x1, y0, y1) -> np.ndarray:
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float)


def corner(a: float, b: float) -> float:
    """Steinbrenner's corner integral of a rectangle a × b, as published (with logarithms)."""
    d = math.hypot(a, b)
    return a * math.log((b + d) / a) + b * math.log((a + d) / b)


def grid_cells(nx, ny, hx, hy, x0=0.0, y0=0.0):
    """The cells of an nx × ny grid as polygons and their centres, in the order j·nx + i."""
    i, j = (v.ravel() for v in np.meshgrid(np.arange(nx), np.arange(ny)))
    cells = np.stack([box(x0 + a * hx, x0 + (a + 1) * hx, y0 + b * hy, y0 + (b + 1) * hy) for a, b in zip(i, j)])
    centres = np.column_stack([x0 + (i + 0.5) * hx, y0 + (j + 0.5) * hy])
    return centres, cells


# -- the disc: convergence of inscribed polygons to the published settlements ----------------------------

def disc_errors(where: str, clockwise: bool, ns) -> np.ndarray:
    """Relative errors of the settlement under q over the inscribed n-gons of a disc of radius a,
    against the published centre 2 q a (1 − ν²)/E or edge 4 q a (1 − ν²)/(π E)."""
    a, centre = 1.7, (0.4, -0.2)
    exact = {"centre": 2 * Q * a * (1 - NU**2) / E, "edge": 4 * Q * a * (1 - NU**2) / (math.pi * E)}[where]
    err = []
    for n in ns:
        poly = ngon(n, a, centre=centre, clockwise=clockwise)
        point = np.array([centre]) if where == "centre" else poly[:1]  # a vertex lies on the circle
        err.append(abs(Q * flexibility(point, [poly], E, NU)[0, 0] - exact) / exact)
    return np.array(err)


NS = np.array([32, 64, 128, 256, 512])


@pytest.mark.parametrize("clockwise", [False, True], ids=["ccw", "cw"])
def test_a_disc_settles_its_centre_as_published_and_polygons_converge_as_one_over_n_squared(clockwise):
    """Timoshenko & Goodier § 138: 2 q a (1 − ν²)/E at the centre."""
    err = disc_errors("centre", clockwise, NS)
    slope = np.polyfit(np.log(NS), np.log(err), 1)[0]
    assert -2.05 < slope < -1.95, (slope, err)
    # n isosceles triangles: 2 n a cos(π/n) asinh(tan(π/n)) = 2πa (1 − π²/(3 n²) + O(n⁻⁴))
    assert err[-1] * NS[-1]**2 == pytest.approx(math.pi**2 / 3, rel=1e-4)


@pytest.mark.parametrize("clockwise", [False, True], ids=["ccw", "cw"])
def test_a_disc_settles_its_edge_as_published_and_polygons_converge_as_log_n_over_n_squared(clockwise):
    """Timoshenko & Goodier § 138: 4 q a (1 − ν²)/(π E) on the edge. At a vertex the polygon's
    missing slivers near the point weigh 1/r: Σ (1/n³)/(k/n) over k gives ln n / n², so err · n² is
    linear in ln n, with a positive slope."""
    err = disc_errors("edge", clockwise, NS)
    B, A = np.polyfit(np.log(NS), err * NS**2, 1)
    assert B > 0
    assert np.abs(A + B * np.log(NS) - err * NS**2).max() < 0.01 * (err * NS**2).min()
    assert err[-1] < 1e-4


# -- the rectangle: Steinbrenner's corner, superposition, the square's coefficient ----------------------

@pytest.mark.parametrize("a, b", [(1.0, 1.0), (2.0, 0.5), (0.01, 3.0), (7.0, 7.5)])
def test_a_rectangle_settles_its_corners_as_steinbrenner(a, b):
    rect = box(10.0, 10.0 + a, -3.0, -3.0 + b)
    got = polygon_potential(rect[:, 0], rect[:, 1], rect)  # each vertex
    assert np.allclose(got, corner(a, b), rtol=1e-13, atol=0)
    assert np.allclose(rectangle_potential(rect[:, 0], rect[:, 1], 10.0, 10.0 + a, -3.0, -3.0 + b),
                       corner(a, b), rtol=1e-13, atol=0)


@pytest.mark.parametrize("a, b", [(1.0, 1.0), (2.0, 0.5), (0.3, 5.0)])
def test_a_rectangle_settles_its_centre_by_four_corners_of_its_quarter(a, b):
    H = flexibility([[a / 2, b / 2]], [box(0, a, 0, b)], E, NU)
    assert H[0, 0] == pytest.approx(4 * C * corner(a / 2, b / 2), rel=1e-13)


def test_a_square_settles_its_centre_by_the_published_coefficient():
    B = 2.3
    w = Q * flexibility([[B / 2, B / 2]], [box(0, B, 0, B)], E, NU)[0, 0]
    assert w / (Q * B * (1 - NU**2) / E) == pytest.approx(1.1222, abs=5e-5)


def test_points_on_an_edge_and_outside_settle_by_superposed_corners():
    a, b, x, y = 3.0, 2.0, 1.2, 0.7
    rect = box(0, a, 0, b)
    on_edge = corner(x, b) + corner(a - x, b)  # (x, 0): two rectangles meeting there
    beside = corner(a + 1.0, y) + corner(a + 1.0, b - y) - corner(1.0, y) - corner(1.0, b - y)  # (-1, y)
    diagonal = corner(a + 0.5, b + 0.25) - corner(0.5, b + 0.25) - corner(a + 0.5, 0.25) + corner(0.5, 0.25)
    got = polygon_potential(np.array([x, -1.0, -0.5]), np.array([0.0, y, -0.25]), rect)
    assert got == pytest.approx([on_edge, beside, diagonal], rel=1e-12)


def test_the_polygon_integral_is_additive_over_a_split_polygon():
    """An L-shape is two rectangles: the integral over it is the sum, at points inside, on the
    re-entrant corner, on the shared line, and outside (an independent route: Love's rectangles)."""
    L = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    x = np.array([0.5, 1.0, 1.0, 1.5, 3.0, -0.7, 1.0])
    y = np.array([1.5, 1.0, 0.5, 0.5, 3.0, 0.3, 2.0])
    parts = rectangle_potential(x, y, 0, 2, 0, 1) + rectangle_potential(x, y, 0, 1, 1, 2)
    assert polygon_potential(x, y, L) == pytest.approx(parts, rel=1e-12)
    assert polygon_potential(x, y, L[::-1]) == pytest.approx(parts, rel=1e-12)


def test_loves_rectangle_and_the_polygon_integral_agree():
    rng = np.random.default_rng(7)
    x, y = rng.uniform(-2, 4, 400), rng.uniform(-3, 3, 400)
    x[:40], y[:40] = rng.uniform(0.5, 2.0, 40), -1.0  # on the bottom edge
    got = polygon_potential(x, y, box(0.5, 2.0, -1.0, 0.25))
    assert got == pytest.approx(rectangle_potential(x, y, 0.5, 2.0, -1.0, 0.25), rel=1e-12)


# -- the far field: a point force, and the cell's second moments ----------------------------------------

@pytest.mark.parametrize("hx, hy, direction", [(1.0, 1.0, (1, 0)), (1.0, 1.0, (0.6, 0.8)),
                                               (2.0, 0.5, (1, 0)), (2.0, 0.5, (0, 1)), (0.3, 1.1, (0.8, -0.6))])
def test_far_from_a_cell_its_pressure_acts_as_a_point_force(hx, hy, direction):
    rx, ry = direction
    r = np.array([10.0, 30.0, 100.0, 300.0, 1000.0]) * max(hx, hy)
    cell = box(5.0 - hx / 2, 5.0 + hx / 2, -2.0 - hy / 2, -2.0 + hy / 2)
    points = np.column_stack([5.0 + r * rx, -2.0 + r * ry])
    cells = np.concatenate([cell[None], np.repeat(box(-1, 0, -1, 0)[None], len(r) - 1, 0)])
    H = flexibility(points, cells, E, NU)[:, 0]
    A = hx * hy
    point_force = C * A / r
    assert H == pytest.approx(point_force, rel=(max(hx, hy) / r[0])**2)
    second = (3 * rx**2 * hx**2 + 3 * ry**2 * hy**2 - hx**2 - hy**2) / (24 * r**2)
    assert np.all(np.abs(H / point_force - 1 - second) < 2 * (max(hx, hy) / r)**4 + 1e-12)


# -- reciprocity and definiteness -------------------------------------------------------------------------

def test_on_equal_cells_the_matrix_is_symmetric_and_positive_definite():
    pts, cells = grid_cells(9, 6, 0.4, 0.7, x0=-1.0, y0=2.0)
    H = flexibility(pts, cells, E, NU)
    assert np.abs(H - H.T).max() <= 1e-14 * H.max()
    assert np.linalg.eigvalsh(H).min() > 0


def test_reciprocity_in_forces_holds_to_the_cells_second_moments():
    """Unequal squares L1, L2 at distance r: force flexibilities 1/r (1 + L²/(24 r²)) with the
    loaded cell's L, so their asymmetry is (L2² − L1²)/(24 r³) to O(L⁴/r⁵)."""
    L1, L2, r = 0.5, 2.0, 40.0
    pts = np.array([[0.0, 0.0], [r, 0.0]])
    cells = [box(-L1 / 2, L1 / 2, -L1 / 2, L1 / 2), box(r - L2 / 2, r + L2 / 2, -L2 / 2, L2 / 2)]
    F = flexibility(pts, cells, E, NU, per="force")
    Hp = flexibility(pts, cells, E, NU)
    assert F == pytest.approx(Hp / np.array([L1**2, L2**2]), rel=1e-15)
    asym = (F[0, 1] - F[1, 0]) / C
    assert asym == pytest.approx((L2**2 - L1**2) / (24 * r**3), rel=(L2 / r)**2)


def test_cells_may_have_different_numbers_of_vertices():
    pts = np.array([[0.0, 0.0], [3.0, 0.5], [-2.0, 4.0]])
    cells = [box(-0.5, 0.5, -0.5, 0.5), np.array([[2.5, 0], [3.5, 0], [3.0, 1.0]]), ngon(7, 0.6, (-2.0, 4.0))]
    H = flexibility(pts, cells, E, NU)
    want = np.array([[C * polygon_potential(p[0], p[1], c) for c in cells] for p in pts])
    assert H == pytest.approx(want, rel=1e-14)


# -- the grid: kernel and FFT operator against the dense matrix of polygons -------------------------------

NX, NY, HX, HY = 7, 5, 0.3, 0.2


@pytest.fixture(scope="module")
def dense():
    pts, cells = grid_cells(NX, NY, HX, HY)
    return flexibility(pts, cells, E, NU)


def test_the_grid_kernel_holds_the_dense_matrix_by_index_differences(dense):
    K = grid_kernel(NX, NY, HX, HY, E, NU)
    assert K.shape == (2 * NY - 1, 2 * NX - 1)
    i, j = (v.ravel() for v in np.meshgrid(np.arange(NX), np.arange(NY)))
    want = K[NY - 1 + j[:, None] - j[None, :], NX - 1 + i[:, None] - i[None, :]]
    assert np.abs(want - dense).max() <= 1e-13 * dense.max()
    dj, di = np.meshgrid(np.arange(-(NY - 1), NY), np.arange(-(NX - 1), NX), indexing="ij")
    love = C * rectangle_potential(di * HX, dj * HY, -HX / 2, HX / 2, -HY / 2, HY / 2)
    assert np.abs(K - love).max() <= 1e-12 * K.max()


@pytest.mark.parametrize("masked", [False, True], ids=["full", "mask"])
def test_the_fft_operator_equals_the_dense_matrix(dense, masked):
    rng = np.random.default_rng(3)
    mask = rng.random((NY, NX)) < 0.6 if masked else None
    keep = np.ones(NX * NY, bool) if mask is None else mask.ravel()
    op = GridFlexibility(NX, NY, HX, HY, E, NU, mask=mask)
    Hk = dense[np.ix_(keep, keep)]
    assert op.shape == Hk.shape
    p = rng.normal(size=keep.sum())
    scale = np.abs(Hk).sum(axis=1).max() * np.abs(p).max()
    assert np.abs(op.matvec(p) - Hk @ p).max() <= 1e-12 * scale
    assert np.abs(op @ p - Hk @ p).max() <= 1e-12 * scale
    P = rng.normal(size=(keep.sum(), 3))
    assert np.abs(op @ P - Hk @ P).max() <= 1e-12 * np.abs(Hk).sum(axis=1).max() * np.abs(P).max()
    assert np.abs(op @ np.eye(keep.sum()) - Hk).max() <= 1e-12 * Hk.max()
    assert op.diagonal() == pytest.approx(np.diag(Hk), rel=1e-14)


def test_the_fft_operator_in_forces_divides_by_the_cell_area(dense):
    op = GridFlexibility(NX, NY, HX, HY, E, NU, per="force")
    f = np.linspace(-1, 2, NX * NY)
    assert np.abs(op @ f - dense @ f / (HX * HY)).max() <= 1e-12 * np.abs(dense @ f).max() / (HX * HY)


def test_the_fft_operator_is_symmetric_as_the_dense_matrix():
    op = GridFlexibility(16, 11, 1.0, 0.6, E, NU, mask=np.add.outer(np.arange(11), np.arange(16)) % 3 > 0)
    rng = np.random.default_rng(5)
    u, v = rng.normal(size=(2, op.shape[0]))
    assert u @ (op @ v) == pytest.approx(v @ (op @ u), rel=1e-12)


def test_the_fft_operator_takes_a_flat_mask_and_column_vectors(dense):
    mask = np.arange(NX * NY) % 4 != 1
    op = GridFlexibility(NX, NY, HX, HY, E, NU, mask=mask)
    p = np.linspace(1, 2, mask.sum())[:, None]
    w = op @ p
    assert w.shape == p.shape
    assert np.abs(w - dense[np.ix_(mask, mask)] @ p).max() <= 1e-12 * np.abs(w).max()


def test_a_rigid_disc_pressed_through_the_fft_operator_carries_boussinesqs_force():
    """A rigid flat punch of radius a settled by δ carries P = 2 a δ E/(1 − ν²) (Boussinesq;
    Johnson, Contact Mechanics, § 3.2): the operator solved by conjugate gradients for a uniform
    settlement over the cells of a staircase disc (radius of equal area) converges to it as O(h)."""
    from scipy.sparse.linalg import cg

    err = []
    ns = np.array([16, 32, 64])
    for m in ns:
        h = 2.0 / m
        c = (np.arange(m) + 0.5) * h - 1.0
        X, Y = np.meshgrid(c, c)
        mask = X**2 + Y**2 < 1.0
        op = GridFlexibility(m, m, h, h, E, NU, mask=mask)
        p, info = cg(op, np.ones(op.shape[0]), rtol=1e-10, maxiter=1000)
        assert info == 0
        a = math.sqrt(mask.sum() * h * h / math.pi)
        err.append(abs(p.sum() * h * h / (2 * a * E / (1 - NU**2)) - 1))
    slope = np.polyfit(np.log(1.0 / ns), np.log(err), 1)[0]
    assert 0.85 < slope < 1.15, (slope, err)
    assert err[-1] < 0.005


# -- bad input -------------------------------------------------------------------------------------------

SQUARE = box(0, 1, 0, 1)
BAD = [
    ("nu-minus-one", lambda: flexibility([[0.5, 0.5]], [SQUARE], E, -1.0), "nu"),
    ("nu-above-half", lambda: flexibility([[0.5, 0.5]], [SQUARE], E, 0.5000001), "nu"),
    ("nu-nan", lambda: flexibility([[0.5, 0.5]], [SQUARE], E, float("nan")), "nu"),
    ("E-zero", lambda: flexibility([[0.5, 0.5]], [SQUARE], 0.0, NU), "E"),
    ("E-negative", lambda: grid_kernel(3, 3, 1.0, 1.0, -1.0, NU), "E"),
    ("E-inf", lambda: GridFlexibility(3, 3, 1.0, 1.0, float("inf"), NU), "E"),
    ("two-vertices", lambda: polygon_potential(0.0, 0.0, [[0, 0], [1, 0]]), "polygon"),
    ("collinear", lambda: polygon_potential(0.0, 0.0, [[0, 0], [1, 0], [2, 0]]), "polygon"),
    ("repeated-vertex", lambda: polygon_potential(0.0, 0.0, [[0, 0], [1, 0], [1, 0], [1, 1]]), "vertex"),
    ("bowtie", lambda: polygon_potential(0.0, 0.0, [[0, 0], [1, 1], [1, 0], [0, 1]]), "self-intersecting"),
    ("touching", lambda: polygon_potential(0.0, 0.0, [[0, 0], [2, 0], [2, 2], [1, 0.0], [0, 2]]),
     "self-intersecting"),
    ("folded", lambda: polygon_potential(0.0, 0.0, [[0, 0], [2, 0], [1, 0], [1, 1]]), "self-intersecting"),
    ("star-crossing", lambda: polygon_potential(0.0, 0.0, ngon(41, 1.0)[np.arange(41) * 2 % 41]), "self-intersecting"),
    ("nan-vertex", lambda: polygon_potential(0.0, 0.0, [[0, 0], [1, np.nan], [1, 1]]), "polygon"),
    ("bad-cell", lambda: flexibility([[0, 0], [3, 3]], [SQUARE, [[0, 0], [1, 1], [1, 0], [0, 1]]], E, NU),
     "cells[1]"),
    ("cells-count", lambda: flexibility([[0, 0], [3, 3]], [SQUARE], E, NU), "cells"),
    ("points-shape", lambda: flexibility([0, 0, 1], [SQUARE], E, NU), "points"),
    ("points-nan", lambda: flexibility([[np.nan, 0]], [SQUARE], E, NU), "points"),
    ("per", lambda: flexibility([[0, 0]], [SQUARE], E, NU, per="stress"), "per"),
    ("mask-shape", lambda: GridFlexibility(4, 3, 1.0, 1.0, E, NU, mask=np.ones((4, 3), bool)), "mask"),
    ("grid-size", lambda: grid_kernel(0, 3, 1.0, 1.0, E, NU), "nx"),
    ("grid-h", lambda: grid_kernel(3, 3, 1.0, 0.0, E, NU), "hy"),
    ("vector-length", lambda: GridFlexibility(4, 3, 1.0, 1.0, E, NU) @ np.ones(11), "12"),
]


@pytest.mark.parametrize("call, words", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_input_is_a_problem_error_naming_it(call, words):
    with pytest.raises(ProblemError, match=words.replace("[", r"\[").replace("]", r"\]")) as info:
        call()
    assert "\n" not in str(info.value)


def test_a_dense_matrix_above_the_limit_is_refused_before_it_is_built():
    pts, cells = grid_cells(40, 40, 1.0, 1.0)
    with pytest.raises(ProblemError, match=r"1600 .*20480000 bytes") as info:
        flexibility(pts, cells, E, NU, max_bytes=10**7)
    assert "\n" not in str(info.value)
    assert flexibility(pts[:10], cells[:10], E, NU, max_bytes=10**7).shape == (10, 10)
