"""The plate elements (ACM, BFS) on their own: interpolation, rigid modes, patch tests.

References are mathematical facts, not earlier output: Hermite shape functions take the value 1
on their own dof and 0 on the others; an element reproduces every polynomial of its space; the
bending energy of a constant-curvature field is (hx·hy) κᵀ D_b κ; the stiffness vanishes exactly
on the three rigid motions w = 1, x, y; and a mesh with its boundary dofs set from a field of
constant curvature (ACM, BFS) or any biharmonic polynomial of the space (BFS, conforming) must
reproduce that field exactly at the interior dofs (the patch test).
"""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.model.elements import ACM, BFS, ELEMENTS, bending_matrix

HX, HY = 0.7, 0.4  # a non-square cell
X0, Y0 = 1.3, -0.6  # a cell away from the origin
CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])

ACM_SPACE = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2), (3, 0), (2, 1), (1, 2), (0, 3), (3, 1), (1, 3)]
BFS_SPACE = [(i, j) for i in range(4) for j in range(4)]
SPACE = {"acm": ACM_SPACE, "bfs": BFS_SPACE}


def dmono(i, j, dx, dy, x, y):
    """∂^{dx+dy}/∂x^dx ∂y^dy of x^i y^j."""
    if dx > i or dy > j:
        return np.zeros_like(np.asarray(x, float) * np.asarray(y, float))
    ci = np.prod(np.arange(i - dx + 1, i + 1)) if dx else 1.0
    cj = np.prod(np.arange(j - dy + 1, j + 1)) if dy else 1.0
    return ci * cj * np.asarray(x, float) ** (i - dx) * np.asarray(y, float) ** (j - dy)


def poly(coef, dx=0, dy=0):
    """The polynomial Σ c_ij x^i y^j (or a derivative) as a function of (x, y)."""
    return lambda x, y: sum(c * dmono(i, j, dx, dy, x, y) for (i, j), c in coef.items())


def element_dofs(el, coef, x0=X0, y0=Y0, hx=HX, hy=HY):
    """The element dof vector of a polynomial: its nodal derivatives at the four corners."""
    out = []
    for cx, cy in CORNERS:
        for dx, dy in el.node_dofs:
            out.append(poly(coef, dx, dy)(x0 + cx * hx, y0 + cy * hy))
    return np.array(out, dtype=float)


@pytest.fixture(params=["acm", "bfs"])
def el(request):
    return ELEMENTS[request.param]()


def test_registry():
    assert set(ELEMENTS) == {"acm", "bfs", "dkt"}
    assert ACM().ndof == 12 and ACM().ndof_node == 3 and ACM().dof_names == ("w", "wx", "wy")
    assert BFS().ndof == 16 and BFS().ndof_node == 4 and BFS().dof_names == ("w", "wx", "wy", "wxy")


def test_coefficients_worked_out_once_and_read_only():
    """Every instance of an element class shares one array of shape-function coefficients (built
    once a process), and nothing can write into it: a change would reach every model after it."""
    for cls in (ACM, BFS):
        a, b = cls(), cls()
        assert a._coef is b._coef and not a._coef.flags.writeable
        with pytest.raises(ValueError):
            a._coef[0, 0] = 1.0
    assert ACM()._coef is not BFS()._coef


def test_kronecker_property(el):
    """Dof k of shape function j is δ_kj (physical dofs, non-square cell)."""
    rows = [el.shape(cx, cy, HX, HY, dx, dy)[0] for cx, cy in CORNERS for dx, dy in el.node_dofs]
    np.testing.assert_allclose(np.array(rows), np.eye(el.ndof), atol=1e-12)


def test_partition_of_unity_and_linear_fields(el):
    rng = np.random.default_rng(1)
    xi, eta = rng.random(50), rng.random(50)
    for coef in ({(0, 0): 1.0}, {(1, 0): 1.0}, {(0, 1): 1.0}):
        N = el.shape(xi, eta, HX, HY)
        np.testing.assert_allclose(N @ element_dofs(el, coef), poly(coef)(X0 + xi * HX, Y0 + eta * HY),
                                   rtol=1e-12, atol=1e-12)


def test_reproduces_its_polynomial_space(el):
    """Every polynomial of the element's space, and its derivatives up to order 2, exactly."""
    rng = np.random.default_rng(7)
    coef = {ij: rng.normal() for ij in SPACE[el.name]}
    xi, eta = rng.random(40), rng.random(40)
    x, y = X0 + xi * HX, Y0 + eta * HY
    d = element_dofs(el, coef)
    for dx, dy in [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]:
        exact = poly(coef, dx, dy)(x, y)
        got = el.shape(xi, eta, HX, HY, dx, dy) @ d
        np.testing.assert_allclose(got, exact, rtol=1e-9, atol=1e-9 * np.abs(exact).max())


def test_acm_does_not_contain_x2y2():
    """A check that the reproduction test can fail: x²y² is outside ACM's 12-term space."""
    el = ACM()
    coef = {(2, 2): 1.0}
    xi, eta = np.array([0.5]), np.array([0.5])
    got = el.shape(xi, eta, HX, HY) @ element_dofs(el, coef)
    assert abs(got[0] - poly(coef)(X0 + 0.5 * HX, Y0 + 0.5 * HY)) > 1e-4
    el = BFS()
    got = el.shape(xi, eta, HX, HY) @ element_dofs(el, coef)
    assert got[0] == pytest.approx(poly(coef)(X0 + 0.5 * HX, Y0 + 0.5 * HY), rel=1e-12)


@pytest.mark.parametrize("hx, hy, nu", [(0.7, 0.4, 0.3), (1.0, 1.0, 0.0), (0.05, 0.2, 0.45), (2.0, 0.5, -0.5)])
def test_stiffness_rigid_modes(el, hx, hy, nu):
    """Symmetric, positive semi-definite, with exactly three zero eigenvalues: w = 1, x, y."""
    D = 2.3
    K = el.stiffness(hx, hy, D, nu)
    np.testing.assert_allclose(K, K.T, rtol=0, atol=1e-14 * np.abs(K).max())
    # scale the dofs to the cell size so the eigenvalues are comparable
    s = np.tile([hx**dx * hy**dy for dx, dy in el.node_dofs], 4)
    Ks = K / s[:, None] / s[None, :]
    ev = np.linalg.eigvalsh(Ks)
    assert np.sum(np.abs(ev) < 1e-10 * ev.max()) == 3
    assert ev[3] > 1e-6 * ev.max()
    for coef in ({(0, 0): 1.0}, {(1, 0): 1.0}, {(0, 1): 1.0}):
        r = element_dofs(el, coef, 0.0, 0.0, hx, hy)
        assert np.abs(K @ r).max() < 1e-12 * np.abs(K).max() * np.abs(r).max()


@pytest.mark.parametrize("kx, ky, kxy", [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (0.3, -1.2, 0.7)])
def test_constant_curvature_energy(el, kx, ky, kxy):
    """w = kx x²/2 + ky y²/2 + kxy xy: uᵀ K u = hx hy κᵀ D_b κ with κ = (kx, ky, 2 kxy)."""
    D, nu = 1.7, 0.3
    coef = {(2, 0): kx / 2, (0, 2): ky / 2, (1, 1): kxy, (1, 0): 0.4, (0, 0): -0.2}
    u = element_dofs(el, coef)
    kappa = np.array([kx, ky, 2 * kxy])
    energy = HX * HY * kappa @ bending_matrix(D, nu) @ kappa
    assert u @ el.stiffness(HX, HY, D, nu) @ u == pytest.approx(energy, rel=1e-12)


def test_consistent_load_moments(el):
    """Unit pressure on one cell: Σ f_k d_k(p) = ∫ p dA for p = 1, x, y, x², xy, y²."""
    f = el.load(HX, HY)
    for (i, j) in [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]:
        exact = ((X0 + HX) ** (i + 1) - X0 ** (i + 1)) / (i + 1) * ((Y0 + HY) ** (j + 1) - Y0 ** (j + 1)) / (j + 1)
        assert f @ element_dofs(el, {(i, j): 1.0}) == pytest.approx(exact, rel=1e-12, abs=1e-14)
    # a sub-box load is a share of the whole: two halves add up to the cell
    halves = el.load(HX, HY, [[0.0, 0.37, 0.0, 1.0], [0.37, 1.0, 0.0, 1.0]])
    np.testing.assert_allclose(halves.sum(axis=0), f, rtol=1e-12, atol=1e-15)


# --------------------------------------------------------------------------------------------
# patch tests on a 3 × 3 mesh: boundary dofs from a field, interior dofs must reproduce it
# --------------------------------------------------------------------------------------------
PATCH_FIELDS = {
    "constant-curvature": {(2, 0): 0.5, (0, 2): 0.5, (1, 1): 0.3, (1, 0): -0.2, (0, 1): 0.1, (0, 0): 0.05},
    "pure-twist": {(1, 1): 1.0},
    "cubic": {(3, 0): 0.4, (2, 1): -0.3, (1, 2): 0.2, (0, 3): 0.1, (2, 0): 0.5},
    "x3y-xy3": {(3, 1): 0.2, (1, 3): -0.35, (2, 0): 0.1},
}
# (element, field): ACM passes the constant-curvature patch test; BFS, conforming, reproduces
# any biharmonic polynomial of its space (∇⁴w = 0, so the consistent load of w is zero inside)
PATCH_CASES = [("acm", "constant-curvature"), ("acm", "pure-twist"),
               ("bfs", "constant-curvature"), ("bfs", "pure-twist"), ("bfs", "cubic"), ("bfs", "x3y-xy3")]


def patch_solve(element, coef):
    """Interior dofs of a 3 × 3 mesh, unloaded, with every boundary dof set from the field."""
    scene = pq.Scene(plate=pq.Plate(a=1.2, b=0.9, h=0.02, E=1.0e4, nu=0.3), mesh=pq.MeshSpec(3, 3, element))
    model = build_model(scene)
    el, g = model.element, model.grid
    nd = el.ndof_node
    x, y = g.node_xy().T
    u_exact = np.zeros(model.n_full)
    for k, (dx, dy) in enumerate(el.node_dofs):
        u_exact[k::nd] = poly(coef, dx, dy)(x, y)
    interior = np.flatnonzero((x > 1e-12) & (x < g.a - 1e-12) & (y > 1e-12) & (y < g.b - 1e-12))
    assert len(interior) == 4
    idof = (interior[:, None] * nd + np.arange(nd)).ravel()
    bdof = np.setdiff1d(np.arange(model.n_full), idof)
    K = model.K_full.toarray()
    u_i = np.linalg.solve(K[np.ix_(idof, idof)], -K[np.ix_(idof, bdof)] @ u_exact[bdof])
    return u_i, u_exact[idof], np.abs(u_exact).max()


@pytest.mark.parametrize("element, name", PATCH_CASES, ids=[f"{e}-{n}" for e, n in PATCH_CASES])
def test_patch_test(element, name):
    got, exact, scale = patch_solve(element, PATCH_FIELDS[name])
    np.testing.assert_allclose(got, exact, rtol=1e-10, atol=1e-10 * scale)


def test_patch_test_can_fail():
    """x²y² lies in the BFS space but ∇⁴(x²y²) = 8 ≠ 0: unloaded, the interior cannot follow it."""
    got, exact, scale = patch_solve("bfs", {(2, 2): 1.0})
    assert np.abs(got - exact).max() > 1e-4 * scale
