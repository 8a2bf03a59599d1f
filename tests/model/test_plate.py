"""Two-sided Kirchhoff plates against external references.

References (never the code's own earlier output):

* Timoshenko & Woinowsky-Krieger, *Theory of Plates and Shells* (2nd ed.), tables for square
  and rectangular plates with ν = 0.3: simply supported (Navier/Lévy, §§28–30, 35) and clamped
  (§§44, 47) plates under uniform and central point loads;
* the exact Kirchhoff solutions of the simply supported rectangle, summed here: Lévy's single
  series for w under a uniform load, Navier's double series for w and its second derivatives
  (moments), and the single series of the centrally loaded plate (Navier summed over n in
  closed form), whose 1/m³ tail is summed exactly with ζ(3);
* exact statics: the reactions at the prescribed dofs balance the load resultant and its first
  moments, to round-off, because rigid motions lie in every element's space;
* beam theory for a ν = 0 plate strip in cylindrical bending, and rigid motions.

Sign conventions (plateqp.model.elements.base): w > 0 downward, M = −D_b κ (Mx > 0 sags),
Mxy = −D(1 − ν) w,xy. Reactions at prescribed dofs: r = f − K u (> 0 pushes the plate up).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import zeta

import plateqp as pq

# one plate for the physics tests: not unit sizes, so a scaling slip shows
A, H, E, NU = 2.0, 0.05, 3.0e4, 0.3
D = E * H**3 / (12.0 * (1.0 - NU**2))
Q, P = 5.0, 7.0
PLATE = dict(a=A, b=A, h=H, E=E, nu=NU)


# --------------------------------------------------------------------------------------------
# exact series solutions of the simply supported rectangle [0, a] × [0, b] (q = 1 or P = 1, D = 1)
# --------------------------------------------------------------------------------------------
def levy_w(x, y, a=1.0, b=1.0, m_max=401):
    """Uniform load: Lévy's single series (Timoshenko & Woinowsky-Krieger §30, eq. 137),
    written with y measured from the plate's mid-line and overflow-free hyperbolic ratios."""
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    m = np.arange(1, m_max + 1, 2, dtype=float)[:, None]
    al = m * np.pi * b / (2.0 * a)
    t = 2.0 * al * (y.ravel()[None, :] - 0.5 * b) / b  # |t| <= al
    e = np.exp(-2.0 * al)
    ch = (np.exp(np.abs(t) - al) + np.exp(-np.abs(t) - al)) / (1.0 + e)  # cosh t / cosh al
    sh = np.sign(t) * (np.exp(np.abs(t) - al) - np.exp(-np.abs(t) - al)) / (1.0 + e)  # sinh t / cosh al
    term = 1.0 - 0.5 * (al * np.tanh(al) + 2.0) * ch + 0.5 * t * sh
    w = 4.0 * a**4 / np.pi**5 * np.sum(term / m**5 * np.sin(m * np.pi * x.ravel()[None, :] / a), axis=0)
    return w.reshape(x.shape)


def navier_fields(x, y, a=1.0, b=1.0, nu=NU, n_max=2001):
    """Uniform load: Navier's double series for (w, Mx, My, Mxy) at one point (§28).

    w = Σ W_mn sin(α_m x) sin(β_n y), W_mn = 16 / (π² m n (α_m² + β_n²)²), m, n odd;
    moments by term-wise differentiation; truncation error of the moments ~1e-9 relative.
    """
    m = np.arange(1, n_max + 1, 2, dtype=float)
    M, N = np.meshgrid(m, m, indexing="ij")
    am, bn = M * np.pi / a, N * np.pi / b
    W = 16.0 / (np.pi**2 * M * N * (am**2 + bn**2) ** 2)
    ss = np.sin(am * x) * np.sin(bn * y)
    w = np.sum(W * ss)
    wxx = -np.sum(W * am**2 * ss)
    wyy = -np.sum(W * bn**2 * ss)
    wxy = np.sum(W * am * bn * np.cos(am * x) * np.cos(bn * y))
    return w, -(wxx + nu * wyy), -(wyy + nu * wxx), -(1.0 - nu) * wxy


def point_centre_w(a=1.0, b=1.0, m_max=201):
    """Central point load: centre deflection (§35, eq. 204):
    w = P a² / (2π³ D) Σ_{m odd} (tanh α_m − α_m / cosh² α_m) / m³, α_m = mπb / (2a).
    Written as (7/8) ζ(3) + Σ (tanh α_m − 1 − α_m / cosh² α_m) / m³: the correction decays
    like exp(−2α_m), so the sum is exact to round-off."""
    m = np.arange(1, m_max + 1, 2, dtype=float)
    al = m * np.pi * b / (2.0 * a)
    e = np.exp(-2.0 * al)
    corr = (np.tanh(al) - 1.0 - 4.0 * al * e / (1.0 + e) ** 2) / m**3
    return a**2 / (2.0 * np.pi**3) * (7.0 / 8.0 * zeta(3.0) + np.sum(corr))


def point_centre_w_double(a=1.0, b=1.0, n_max=3001):
    """Central point load, Navier's double series (§34): 4/(π⁴ a b) Σ 1/((m/a)² + (n/b)²)²."""
    m = np.arange(1, n_max + 1, 2, dtype=float)
    M, N = np.meshgrid(m, m, indexing="ij")
    return 4.0 / (np.pi**4 * a * b) * np.sum(1.0 / ((M / a) ** 2 + (N / b) ** 2) ** 2)


W_SS = float(levy_w(0.5, 0.5)[()])  # exact centre coefficient, q a⁴ / D
W_SS_POINT = point_centre_w()  # exact centre coefficient, P a² / D


def test_reference_series_agree():
    """The series references agree with each other and with the printed tables."""
    for x, y in [(0.5, 0.5), (0.3, 0.2), (0.9, 0.55)]:
        assert navier_fields(x, y)[0] == pytest.approx(float(levy_w(x, y)[()]), rel=1e-11)
    assert levy_w(0.5, 1.0, b=2.0)[()] == pytest.approx(levy_w(0.5, 1.0, b=2.0, m_max=2001)[()], rel=1e-14)
    assert point_centre_w_double() == pytest.approx(W_SS_POINT, rel=1e-5)
    assert W_SS == pytest.approx(0.0040624, abs=1e-7)  # Timoshenko's printed digits
    assert W_SS_POINT == pytest.approx(0.0116007, abs=2e-7)
    assert navier_fields(0.5, 0.5)[1] == pytest.approx(0.0479, abs=1e-4)
    assert levy_w(0.5, 1.0, b=2.0)[()] == pytest.approx(0.01013, abs=1e-5)


# --------------------------------------------------------------------------------------------
# 1. Timoshenko's tables, one row per (case, element, quantity)
# --------------------------------------------------------------------------------------------
CASES = {
    # name: (edge kind, load, b/a, nx, ny)
    "ss-uniform": ("simple", pq.UniformLoad(Q), 1, 32, 32),
    "clamped-uniform": ("clamped", pq.UniformLoad(Q), 1, 32, 32),
    "ss-point": ("simple", pq.PointLoad(P, A / 2, A / 2), 1, 32, 32),
    "clamped-point": ("clamped", pq.PointLoad(P, A / 2, A / 2), 1, 32, 32),
    "ss-rect-b2a": ("simple", pq.UniformLoad(Q), 2, 16, 32),
}

# (case, element, quantity, (x/a, y/a), coefficient, relative tolerance)
#   w of a uniform load in units of q a⁴/D, of a point load in P a²/D; moments in q a²
TABLE = [
    ("ss-uniform", "acm", "w", (0.5, 0.5), 0.0040624, 0.01),
    ("ss-uniform", "bfs", "w", (0.5, 0.5), 0.0040624, 0.002),
    ("ss-uniform", "acm", "Mx", (0.5, 0.5), 0.0479, 0.03),
    ("ss-uniform", "bfs", "Mx", (0.5, 0.5), 0.0479, 0.03),
    ("clamped-uniform", "acm", "w", (0.5, 0.5), 0.0012653, 0.01),
    ("clamped-uniform", "bfs", "w", (0.5, 0.5), 0.0012653, 0.002),
    ("clamped-uniform", "acm", "Mx", (0.0, 0.5), -0.0513, 0.03),  # left edge, moment normal to it
    ("clamped-uniform", "bfs", "Mx", (0.0, 0.5), -0.0513, 0.03),
    ("clamped-uniform", "acm", "My", (0.5, 0.0), -0.0513, 0.03),  # bottom edge
    ("clamped-uniform", "bfs", "My", (0.5, 1.0), -0.0513, 0.03),  # top edge
    ("ss-point", "acm", "w", (0.5, 0.5), 0.0116007, 0.01),
    ("ss-point", "bfs", "w", (0.5, 0.5), 0.0116007, 0.01),
    ("clamped-point", "acm", "w", (0.5, 0.5), 0.005612, 0.01),
    ("clamped-point", "bfs", "w", (0.5, 0.5), 0.005612, 0.01),
    ("ss-rect-b2a", "acm", "w", (0.5, 1.0), 0.01013, 0.01),
    ("ss-rect-b2a", "bfs", "w", (0.5, 1.0), 0.01013, 0.002),
]


def solve_case(solved, case, element):
    edge, load, ratio, nx, ny = CASES[case]
    return solved(element=element, nx=nx, ny=ny, edges=edge, loads=(load,), **{**PLATE, "b": A * ratio})


@pytest.mark.parametrize("case, element, quantity, pt, coef, tol", TABLE,
                         ids=[f"{r[0]}-{r[1]}-{r[2]}@{r[3][0]},{r[3][1]}" for r in TABLE])
def test_timoshenko_table(solved, case, element, quantity, pt, coef, tol):
    r = solve_case(solved, case, element)
    x, y = pt[0] * A, pt[1] * A
    point_load = isinstance(CASES[case][1], pq.PointLoad)
    if quantity == "w":
        unit = P * A**2 / D if point_load else Q * A**4 / D
        got = r.deflection(x, y)
    else:
        unit = Q * A**2
        got = dict(zip(("Mx", "My", "Mxy"), r.moments(x, y)))[quantity]
    assert got / unit == pytest.approx(coef, rel=tol)


def test_point_load_centre_is_a_node(solved):
    """The 32 × 32 mesh has a node under the central load: w there is a nodal dof."""
    r = solve_case(solved, "clamped-point", "bfs")
    w, x, y = r.w_max()
    assert (x, y) == pytest.approx((A / 2, A / 2)) and w == pytest.approx(r.deflection(A / 2, A / 2), rel=1e-12)


# --------------------------------------------------------------------------------------------
# 2. observed convergence order of the centre deflection (simply supported square)
# --------------------------------------------------------------------------------------------
MESHES = (4, 8, 16, 32)
# (element, load, slope band): uniform load: h² (ACM), h⁴ (BFS); point load: h² log h
ORDERS = [
    ("acm", "uniform", (1.7, 2.3)),
    ("bfs", "uniform", (3.5, 4.5)),
    ("acm", "point", (1.5, 2.3)),
    ("bfs", "point", (1.5, 2.3)),
]


def centre_errors(solved, element, load):
    if load == "uniform":
        ld, exact = pq.UniformLoad(Q), W_SS * Q * A**4 / D
    else:
        ld, exact = pq.PointLoad(P, A / 2, A / 2), W_SS_POINT * P * A**2 / D
    w = np.array([solved(element=element, nx=n, edges="simple", loads=(ld,), **PLATE).deflection(A / 2, A / 2)
                  for n in MESHES])
    return w, exact


@pytest.mark.parametrize("element, load, band", ORDERS, ids=[f"{e}-{ld}" for e, ld, _ in ORDERS])
def test_convergence_order(solved, element, load, band):
    w, exact = centre_errors(solved, element, load)
    err = np.abs(w - exact) / exact
    slope = np.polyfit(np.log(A / np.array(MESHES)), np.log(err), 1)[0]
    assert band[0] <= slope <= band[1], f"observed order {slope:.3f}, errors {err}"
    assert np.all(np.diff(err) < 0)


def test_acm_converges_from_above(solved):
    """ACM overestimates the centre deflection of the uniformly loaded simply supported plate."""
    w, exact = centre_errors(solved, "acm", "uniform")
    assert np.all(w > exact)


def test_bfs_point_load_converges_from_below(solved):
    """BFS is conforming, so P w_h(x_P) = a(u_h, u_h) ≤ a(u, u) = P w(x_P): a strict lower bound."""
    w, exact = centre_errors(solved, "bfs", "point")
    assert np.all(w < exact) and np.all(np.diff(w) > 0)


# --------------------------------------------------------------------------------------------
# 3. moments, stresses and sections against Navier's series
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_centre_moment_navier(solved, element):
    r = solve_case(solved, "ss-uniform", element)
    _, mx, my, _ = navier_fields(0.5, 0.5)
    Mx, My, Mxy = r.moments(A / 2, A / 2)
    assert Mx == pytest.approx(mx * Q * A**2, rel=5e-3)
    assert My == pytest.approx(my * Q * A**2, rel=5e-3)
    # exact Mxy = 0 at the centre; ACM's twist is discontinuous between cells and the value at a
    # node comes from one cell, so it is zero only to discretisation error; the average over the
    # four cells around the node (Result.nodal) cancels by symmetry
    assert abs(Mxy) < 5e-3 * Mx
    centre = np.flatnonzero(np.all(np.isclose(r.model.grid.nodes, [A / 2, A / 2]), axis=1))
    assert centre.size == 1  # the centre is a node of the 32 × 32 mesh
    assert abs(r.nodal("Mxy")[centre[0]]) < 1e-9 * Mx


@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_principal_stresses_centre(solved, element):
    """At the centre of the square the stress state is isotropic: σ1 = σ2 = 6M/h²."""
    r = solve_case(solved, "ss-uniform", element)
    sigma = 6.0 * navier_fields(0.5, 0.5)[1] * Q * A**2 / H**2
    s1, s2, _ = r.principal_stresses(A / 2, A / 2)
    assert s1 == pytest.approx(sigma, rel=5e-3)
    assert s2 == pytest.approx(sigma, rel=5e-3)
    assert s1 - s2 < 5e-3 * sigma  # exactly 0; see test_centre_moment_navier for ACM's twist at a node


@pytest.mark.parametrize("element", ["acm", "bfs"])
@pytest.mark.parametrize("pt", [(0.3, 0.2), (0.81, 0.37), (0.15, 0.9)])
def test_principal_stresses_off_centre(solved, element, pt):
    """σ1, σ2 and the angle of σ1 from Navier's Mx, My, Mxy at non-symmetric points."""
    r = solve_case(solved, "ss-uniform", element)
    _, mx, my, mxy = (Q * A**2 * v for v in navier_fields(*pt))
    sx, sy, txy = (6.0 * m / H**2 for m in (mx, my, mxy))
    c, rad = 0.5 * (sx + sy), np.hypot(0.5 * (sx - sy), txy)
    theta = 0.5 * np.arctan2(2.0 * txy, sx - sy)
    s1, s2, th = r.principal_stresses(pt[0] * A, pt[1] * A)
    scale = max(abs(c) + rad, 1e-300)
    assert s1 == pytest.approx(c + rad, abs=0.01 * scale)
    assert s2 == pytest.approx(c - rad, abs=0.01 * scale)
    assert th == pytest.approx(theta, abs=0.02)  # radians
    # the twisting moment's sign: compare Mxy itself
    assert r.moments(pt[0] * A, pt[1] * A)[2] == pytest.approx(mxy, abs=0.01 * np.max(np.abs([mx, my, mxy])))


@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_section_navier(solved, element):
    r = solve_case(solved, "ss-uniform", element)
    s, w = r.section((0.0, A / 2), (A, A / 2), n=41)
    assert s[0] == 0.0 and s[-1] == pytest.approx(A)
    ref = levy_w(s / A, 0.5) * Q * A**4 / D
    assert w[0] == pytest.approx(0.0, abs=1e-12) and w[-1] == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(w[1:-1], ref[1:-1], rtol=0.01)
    # a diagonal section too
    s, w = r.section((0.1 * A, 0.2 * A), (0.7 * A, 0.95 * A), n=17)
    t = np.linspace(0, 1, 17)
    ref = levy_w(0.1 + 0.6 * t, 0.2 + 0.75 * t) * Q * A**4 / D
    np.testing.assert_allclose(w, ref, rtol=0.01)


# --------------------------------------------------------------------------------------------
# 4. exact statics: reactions at the prescribed dofs balance the load
# --------------------------------------------------------------------------------------------
def rigid_dofs(model):
    """(3, n_full): the dof vectors of w = 1, w = x, w = y (slopes 1 where they apply, twist 0)."""
    nd = model.element.ndof_node
    xy = model.grid.node_xy()
    out = np.zeros((3, model.n_full))
    out[0, 0::nd] = 1.0
    out[1, 0::nd], out[1, 1::nd] = xy[:, 0], 1.0
    out[2, 0::nd], out[2, 2::nd] = xy[:, 1], 1.0
    return out


def reactions(result):
    """r = f − K u on the prescribed dofs (zero elsewhere): the support forces, upward positive."""
    m = result.model
    r = np.zeros(m.n_full)
    r[m.fixed] = (m.f_full - m.K_full @ result.u)[m.fixed]
    return r


def load_resultant(scene):
    """(F, ∫ q x, ∫ q y) of the scene's loads, computed from the geometry alone."""
    out = np.zeros(3)
    a, b = scene.plate.a, scene.plate.b
    holes = [(o.x0, o.x1, o.y0, o.y1) for o in scene.openings]  # tests align openings with cells

    def box(q, x0, x1, y0, y1):
        x0, x1, y0, y1 = max(x0, 0), min(x1, a), max(y0, 0), min(y1, b)
        if x1 <= x0 or y1 <= y0:
            return np.zeros(3)
        ar = (x1 - x0) * (y1 - y0)
        return q * ar * np.array([1.0, 0.5 * (x0 + x1), 0.5 * (y0 + y1)])

    for ld in scene.loads:
        if isinstance(ld, pq.PointLoad):
            out += ld.P * np.array([1.0, ld.x, ld.y])
            continue
        rect = (0, a, 0, b) if isinstance(ld, pq.UniformLoad) else (ld.x0, ld.x1, ld.y0, ld.y1)
        out += box(ld.q, *rect)
        for hx0, hx1, hy0, hy1 in holes:  # subtract the part over each (disjoint) opening
            out -= box(ld.q, max(rect[0], hx0), min(rect[1], hx1), max(rect[2], hy0), min(rect[3], hy1))
    return out


STATICS = {
    "ss-uniform": lambda el: dict(element=el, nx=8, edges="simple", loads=(pq.UniformLoad(Q),)),
    "clamped-point-off-node": lambda el: dict(element=el, nx=8, edges="clamped",
                                              loads=(pq.PointLoad(P, 0.37 * A, 0.61 * A),)),
    "mixed-edges-patch-pin": lambda el: dict(
        element=el, nx=10, ny=6, edges={"left": "simple", "top": "clamped"},
        pins=[pq.Pin(A, 0.0)], loads=(pq.PatchLoad(Q, 0.23 * A, 0.71 * A, 0.1 * A, 0.45 * A),
                                      pq.PointLoad(-P, 0.9 * A, 0.2 * A))),
    "L-clamped-uniform": lambda el: dict(element=el, nx=8, edges="clamped", openings=[pq.Opening(A / 2, A, A / 2, A)],
                                         loads=(pq.UniformLoad(Q), pq.PointLoad(P, 0.3 * A, 0.8 * A))),
    "prescribed-w-and-slope": lambda el: dict(
        element=el, nx=8, edges={"left": pq.Edge("clamped", w=0.01, slope=0.02), "right": pq.Edge("simple", w=-0.03)},
        loads=(pq.UniformLoad(Q), pq.PatchLoad(2 * Q, 0.1 * A, 0.3 * A, 0.55 * A, 0.95 * A))),
    "three-pins": lambda el: dict(element=el, nx=6, edges={}, pins=[pq.Pin(0, 0), pq.Pin(A, 0), pq.Pin(0, A)],
                                  loads=(pq.UniformLoad(Q),)),
}


@pytest.mark.parametrize("element", ["acm", "bfs"])
@pytest.mark.parametrize("case", sorted(STATICS))
def test_statics(make_scene, case, element):
    kw = STATICS[case](element)
    kw = {**PLATE, **kw}
    scene = make_scene(**kw)
    result = pq.solve(scene)
    r = reactions(result)
    got = rigid_dofs(result.model) @ r
    want = load_resultant(scene)
    # scale: the load's absolute magnitude (forces), times the plate size for the moments
    mag = sum(abs(load_resultant(make_scene(**{**kw, "loads": [ld]}))[0]) for ld in scene.loads)
    units = mag * np.array([1.0, A, A])
    np.testing.assert_allclose(got / units, want / units, rtol=0, atol=1e-9)


def test_three_pins_statically_determinate(make_scene):
    """Pins at (0,0), (a,0), (0,a) under q: moments about the axes give R = (0, qa²/2, qa²/2)."""
    for el in ("acm", "bfs"):
        scene = make_scene(**{**PLATE, **STATICS["three-pins"](el)})
        result = pq.solve(scene)
        m = result.model
        r = reactions(result)
        wdofs = [m.grid.node_at(x, y) * m.element.ndof_node for x, y in [(0, 0), (A, 0), (0, A)]]
        np.testing.assert_allclose(r[wdofs], [0.0, Q * A**2 / 2, Q * A**2 / 2], atol=1e-9 * Q * A**2)


@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_four_corner_pins_symmetric(make_scene, element):
    """Four corner pins (statically indeterminate) under q: by symmetry each carries q a² / 4."""
    corners = [(0, 0), (A, 0), (A, A), (0, A)]
    scene = make_scene(element, 6, edges={}, pins=[pq.Pin(x, y) for x, y in corners], loads=[pq.UniformLoad(Q)],
                       **PLATE)
    result = pq.solve(scene)
    m = result.model
    r = reactions(result)
    wdofs = [m.grid.node_at(x, y) * m.element.ndof_node for x, y in corners]
    np.testing.assert_allclose(r[wdofs], Q * A**2 / 4, rtol=1e-9)


# --------------------------------------------------------------------------------------------
# 5. loads
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_patch_over_whole_plate_equals_uniform(make_scene, element):
    from plateqp.model.assembly import build_model
    u = build_model(make_scene(element, 6, 4, loads=[pq.UniformLoad(Q)], **PLATE))
    p = build_model(make_scene(element, 6, 4, loads=[pq.PatchLoad(Q, 0, A, 0, A)], **PLATE))
    big = build_model(make_scene(element, 6, 4, loads=[pq.PatchLoad(Q, -1, 2 * A, -3, 5 * A)], **PLATE))
    np.testing.assert_allclose(p.f_full, u.f_full, rtol=1e-13, atol=1e-15 * Q * A**2)
    np.testing.assert_allclose(big.f_full, u.f_full, rtol=1e-13, atol=1e-15 * Q * A**2)


@pytest.mark.parametrize("element", ["acm", "bfs"])
@pytest.mark.parametrize("box", [
    (0.25, 0.375, 0.5, 0.75),  # half a cell in x, one cell in y
    (0.1, 0.63, 0.33, 0.4),  # arbitrary, cutting cells
    (0.9, 1.5, -0.2, 0.1),  # sticking out of the plate
], ids=["half-cell", "arbitrary", "outside-part"])
def test_patch_load_integrates_exactly(make_scene, element, box):
    """Σ f·d(p) = ∫ q p dA for p = 1, x, y, x², xy, y² (all in both element spaces)."""
    from plateqp.model.assembly import build_model
    x0, x1, y0, y1 = (A * v for v in box)
    model = build_model(make_scene(element, 8, 4, loads=[pq.PatchLoad(Q, x0, x1, y0, y1)], **PLATE))
    x0, x1, y0, y1 = max(x0, 0), min(x1, A), max(y0, 0), min(y1, A)
    X = lambda k: (x1 ** (k + 1) - x0 ** (k + 1)) / (k + 1)  # noqa: E731  ∫ x^k dx
    Y = lambda k: (y1 ** (k + 1) - y0 ** (k + 1)) / (k + 1)  # noqa: E731
    for (i, j), d in poly_dofs(model).items():
        assert model.f_full @ d == pytest.approx(Q * X(i) * Y(j), rel=1e-12)


def poly_dofs(model):
    """{(i, j): dof vector of w = x^i y^j} for the monomials of degree ≤ 2."""
    nd = model.element.ndof_node
    orders = list(model.element.node_dofs)
    x, y = model.grid.node_xy().T
    out = {}
    for i, j in [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]:
        d = np.zeros(model.n_full)
        for k, (dx, dy) in enumerate(orders):
            if dx > i or dy > j:
                continue
            ci = np.prod(np.arange(i - dx + 1, i + 1)) if dx else 1.0
            cj = np.prod(np.arange(j - dy + 1, j + 1)) if dy else 1.0
            d[k::nd] = ci * cj * x ** (i - dx) * y ** (j - dy)
        out[(i, j)] = d
    return out


@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_point_load_at_node(make_scene, element):
    from plateqp.model.assembly import build_model
    model = build_model(make_scene(element, 8, loads=[pq.PointLoad(P, 0.375 * A, 0.5 * A)], **PLATE))
    f = np.zeros(model.n_full)
    f[model.grid.node_at(0.375 * A, 0.5 * A) * model.element.ndof_node] = P
    np.testing.assert_allclose(model.f_full, f, atol=1e-13 * P)


@pytest.mark.parametrize("element", ["acm", "bfs"])
@pytest.mark.parametrize("pt", [(0.41, 0.27), (0.375, 0.6), (1.0, 0.93)], ids=["inside", "on-edge", "plate-edge"])
def test_point_load_off_node(make_scene, element, pt):
    """Consistent loads f_k = P N_k(x_P): Σ f·d(p) = P p(x_P) for every polynomial p of the space."""
    from plateqp.model.assembly import build_model
    xp, yp = pt[0] * A, pt[1] * A
    model = build_model(make_scene(element, 8, loads=[pq.PointLoad(P, xp, yp)], **PLATE))
    for (i, j), d in poly_dofs(model).items():
        assert model.f_full @ d == pytest.approx(P * xp**i * yp**j, rel=1e-12, abs=1e-13 * P)


def test_point_load_off_node_deflection_symmetry(solved):
    """Maxwell–Betti: w at B due to P at A equals w at A due to P at B (points off the nodes)."""
    for el in ("acm", "bfs"):
        pa, pb = (0.31 * A, 0.47 * A), (0.66 * A, 0.22 * A)
        ra = solved(element=el, nx=8, edges="clamped", loads=(pq.PointLoad(P, *pa),), **PLATE)
        rb = solved(element=el, nx=8, edges="clamped", loads=(pq.PointLoad(P, *pb),), **PLATE)
        assert ra.deflection(*pb) == pytest.approx(rb.deflection(*pa), rel=1e-10)


# --------------------------------------------------------------------------------------------
# 7. mechanisms
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("pins, edges, n_modes", [
    ([pq.Pin(0, 0), pq.Pin(A, A)], {}, "one"),
    ([], {}, "three"),
    ([], {"left": "free", "top": "free"}, "three"),
    ([pq.Pin(0, 0), pq.Pin(A / 2, A / 2), pq.Pin(A, A)], {}, "one"),  # collinear pins
    ([pq.Pin(A, 0)], {"left": "simple"}, None),  # fine: a line and a point off it
], ids=["two-pins", "free", "free-edges-named", "collinear-pins", "simple-edge-and-pin"])
@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_mechanisms(make_scene, pins, edges, n_modes, element):
    scene = make_scene(element, 4, edges=edges, pins=pins, loads=[pq.UniformLoad(Q)], **PLATE)
    if n_modes is None:
        assert np.isfinite(pq.solve(scene).u).all()
        return
    with pytest.raises(pq.MechanismError, match="rigid motion") as info:
        pq.solve(scene)
    assert n_modes in str(info.value)


# --------------------------------------------------------------------------------------------
# 8. openings
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_l_shaped_plate(make_scene, element):
    scene = make_scene(element, 8, edges="clamped", openings=[pq.Opening(A / 2, A, A / 2, A)],
                       loads=[pq.UniformLoad(Q)], **PLATE)
    result = pq.solve(scene)
    g = result.model.grid
    assert np.isnan(g.to_grid(result.w_nodes())[-1, -1])  # the removed quadrant's corner is off the plate
    assert not np.any(np.all(np.isclose(g.nodes, [A, A]), axis=1))  # and not among the plate's nodes
    assert pq.solve(scene).deflection(0.25 * A, 0.25 * A) > 0
    m = result.model
    r = reactions(result)
    assert r[m.fixed[m.fixed % m.element.ndof_node == 0]].sum() == pytest.approx(Q * 0.75 * A**2, rel=1e-12)
    # symmetry about the diagonal y = x
    assert result.deflection(0.2 * A, 0.7 * A) == pytest.approx(result.deflection(0.7 * A, 0.2 * A), rel=1e-10)


@pytest.mark.parametrize("what", ["point", "patch", "support", "pin"])
def test_load_in_opening_is_rejected(make_scene, what):
    hole = [pq.Opening(A / 2, A, A / 2, A)]
    kw = {"point": dict(loads=[pq.PointLoad(P, 0.8 * A, 0.8 * A)]),
          "patch": dict(loads=[pq.PatchLoad(Q, 0.6 * A, 0.9 * A, 0.55 * A, A)]),
          "support": dict(supports=[pq.Support(0.8 * A, 0.7 * A)]),
          "pin": dict(pins=[pq.Pin(0.75 * A, 0.75 * A)])}[what]
    with pytest.raises(pq.SceneError, match="opening|not a mesh node"):
        make_scene("acm", 8, edges="clamped", openings=hole, **kw, **PLATE)


# --------------------------------------------------------------------------------------------
# 9. prescribed edge values (the paper's w = f1, ∂w/∂n = f2)
# --------------------------------------------------------------------------------------------
GRID_PTS = np.meshgrid(np.linspace(0, A, 9), np.linspace(0, A, 7))


@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_prescribed_translation(make_scene, element):
    scene = make_scene(element, 6, edges={k: pq.Edge("simple", w=0.01) for k in ("left", "right", "bottom", "top")},
                       **PLATE)
    r = pq.solve(scene)
    x, y = GRID_PTS
    np.testing.assert_allclose(r.deflection(x, y), 0.01, rtol=1e-12)
    for mom in r.moments(x, y):
        assert np.abs(mom).max() < 1e-9 * D * 0.01 / A**2


@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_prescribed_clamped_slope_rotates_rigidly(make_scene, element):
    """Clamped left edge with ∂w/∂n = s (n = −x outward), rest free, no load: w = −s x exactly."""
    s = 0.02
    scene = make_scene(element, 6, 4, edges={"left": pq.Edge("clamped", slope=s)}, **PLATE)
    r = pq.solve(scene)
    x, y = GRID_PTS
    np.testing.assert_allclose(r.deflection(x, y), -s * x, atol=1e-12 * s * A)
    np.testing.assert_allclose(r.slopes(x, y)[0], -s, rtol=1e-10)
    for mom in r.moments(x, y):
        assert np.abs(mom).max() < 1e-9 * D * s / A
    # the same rotation from the right edge: outward normal +x, so w = s (x − a)
    scene = make_scene(element, 6, 4, edges={"right": pq.Edge("clamped", slope=s)}, **PLATE)
    np.testing.assert_allclose(pq.solve(scene).deflection(x, y), s * (x - A), atol=1e-12 * s * A)


@pytest.mark.parametrize("element, tol", [("bfs", 1e-9), ("acm", 1e-4)])
def test_cantilever_strip_cylindrical_bending(make_scene, element, tol):
    """ν = 0 strip clamped at x = 0, free elsewhere, uniform q: the free long edges carry no My,
    so the exact plate solution is the beam w = q (x⁴ − 4Lx³ + 6L²x²) / (24 D), tip q L⁴ / (8D).
    BFS holds it at the nodes to round-off (Hermite beam elements are nodally exact); ACM,
    non-conforming, only approximately."""
    L, b = 2.0 * A, 0.5 * A
    scene = make_scene(element, 16, 2, edges={"left": "clamped"}, loads=[pq.UniformLoad(Q)],
                       a=L, b=b, h=H, E=E, nu=0.0)
    d = scene.plate.D
    r = pq.solve(scene)
    x = np.linspace(0, L, 17)
    beam = Q * (x**4 - 4 * L * x**3 + 6 * L**2 * x**2) / (24 * d)
    for y in (0.0, b / 2, b):
        np.testing.assert_allclose(r.deflection(x, np.full_like(x, y)), beam, atol=tol * beam[-1])
    assert r.deflection(L, b / 2) == pytest.approx(Q * L**4 / (8 * d), rel=tol)
