"""Plates of any shape, end to end (DKT on gmsh meshes), against closed forms and statics.

References (Timoshenko & Woinowsky-Krieger, Theory of plates and shells, §§ 62-63, 30):
circular plate of radius R under uniform q, clamped w0 = q R⁴ / 64 D; simply supported
w0 = (5 + ν) q R⁴ / (64 (1 + ν) D); clamped under a central point load w0 = P R² / (16 π D);
simply supported square under uniform q (Navier series) w0 = 0.00406 q a⁴ / D.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.assembly import build_model
pytest.importorskip("gmsh")

R, NU = 1.0, 0.3


def disc(edge="clamped", size=R / 16, loads=None, **kw) -> pq.Scene:
    return pq.Scene(name="disc", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.01, E=1.0e7, nu=NU),
                    mesh=pq.MeshSpec(element="dkt", size=size),
                    edges=kw.pop("edges", {"all": pq.Edge(edge)} if edge else {}),
                    loads=loads if loads is not None else [pq.UniformLoad(1.0)], **kw)


def w0(res) -> float:
    return res.deflection(0.0, 0.0)


D = disc().plate.D
CLAMPED = R**4 / (64 * D)
SIMPLE = (5 + NU) * R**4 / (64 * (1 + NU) * D)
POINT = R**2 / (16 * math.pi * D)


@pytest.mark.parametrize("edge, ref", [("clamped", CLAMPED), ("simple", SIMPLE)])
def test_circular_plate_uniform_load(edge, ref):
    assert w0(pq.solve(disc(edge))) == pytest.approx(ref, rel=0.01)


def test_circular_plate_central_point_load():
    res = pq.solve(disc("clamped", loads=[pq.PointLoad(1.0, 0.0, 0.0)]))
    assert w0(res) == pytest.approx(POINT, rel=0.02)


def test_simple_support_converges_to_simple_not_clamped():
    """Babuška's paradox avoided: w = 0 only on the curved edge, with the observed order of
    convergence (DKT: h²) fitted on three meshes."""
    sizes = np.array([R / 4, R / 8, R / 16])
    err = np.array([abs(w0(pq.solve(disc("simple", size=h))) / SIMPLE - 1) for h in sizes])
    order = np.polyfit(np.log(sizes), np.log(err), 1)[0]
    assert 1.5 < order < 3.0, (err, order)
    assert err[-1] < 0.01


def square(edges, element="dkt", n=16, shape=True, a=1.0):
    plate = pq.Plate(a=a, shape={"polygon": [[0, 0], [a, 0], [a, 1], [0, 1]]} if shape else None, nu=NU)
    return pq.Scene(plate=plate, mesh=pq.MeshSpec(round(n * a), n, element, size=1.0 / n if element == "dkt" else None),
                    edges=edges, loads=[pq.UniformLoad(1.0)])


def w0_sq(res):
    return res.deflection(0.5 * res.scene.plate.a, 0.5)


def test_square_polygon_against_navier():
    res = pq.solve(square({"all": pq.Edge("simple")}))
    assert w0_sq(res) == pytest.approx(0.00406 / res.scene.plate.D, rel=0.01)


def test_square_with_named_edges_against_timoshenko():
    """The rectangle's edge names on triangles: left/right clamped, bottom/top simple; Timoshenko
    table 29 (b/a = 1): w0 = 0.00192 q a⁴ / D."""
    edges = {"left": pq.Edge("clamped"), "right": pq.Edge("clamped"), "bottom": pq.Edge("simple"),
             "top": pq.Edge("simple")}
    res = pq.solve(square(edges, shape=False))
    assert w0_sq(res) == pytest.approx(0.00192 / res.scene.plate.D, rel=0.01)


def test_rectangle_on_triangles_against_acm():
    """Unequal named edges on a 1.5 × 1 rectangle (left clamped, right and bottom simple, top free):
    DKT on triangles against ACM's grid, which converges from the other side: within 2 %."""
    edges = {"left": pq.Edge("clamped"), "right": pq.Edge("simple"), "bottom": pq.Edge("simple")}
    dkt = pq.solve(square(edges, shape=False, a=1.5))
    acm = pq.solve(square(edges, "acm", 32, shape=False, a=1.5))
    for x, y in [(0.75, 0.5), (0.4, 0.8), (1.2, 0.9)]:
        assert dkt.deflection(x, y) == pytest.approx(acm.deflection(x, y), rel=0.02)


def test_l_shape_by_segments_against_acm():
    """An L-shaped polygon with its outer segments clamped by name (outer_0-1, outer_4-5) and the
    re-entrant ones free, against ACM's grid of the same L (a square less a cut-out, whose
    cut-out edges are free): within 1 % at points in all three arms and by the re-entrant corner."""
    L = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
    dkt = pq.solve(pq.Scene(plate=pq.Plate(shape={"polygon": L}), mesh=pq.MeshSpec(element="dkt", size=1 / 16),
                            edges={"outer_0-1": pq.Edge("clamped"), "outer_4-5": pq.Edge("clamped")},
                            loads=[pq.UniformLoad(1.0)]))
    acm = pq.solve(pq.Scene(plate=pq.Plate(a=2.0, b=2.0), mesh=pq.MeshSpec(32, 32, "acm"),
                            openings=[pq.Opening(1.0, 2.0, 1.0, 2.0)], loads=[pq.UniformLoad(1.0)],
                            edges={k: pq.Edge("clamped") for k in ("left", "right", "bottom", "top")}))
    for x, y in [(0.5, 0.5), (1.5, 0.5), (0.5, 1.5), (1.5, 0.9), (0.9, 0.9)]:
        assert dkt.deflection(x, y) == pytest.approx(acm.deflection(x, y), rel=0.01)


def posts(gaps, r=0.6):
    return [pq.Support(r * math.cos(t), r * math.sin(t), gap=g)
            for t, g in zip(np.arange(len(gaps)) * 2 * math.pi / len(gaps), gaps)]


def total_load(model) -> float:
    return float(model.f_full[0::3].sum())


def test_floating_disc_on_three_posts_statics():
    """A free disc on three rigid one-sided posts at 120°: each carries a third of the load,
    exactly (statics), in the primal and the condensed formulation; the dual refuses a floating plate."""
    sc = disc(edge=None, size=R / 16, supports=posts([0.0, 0.0, 0.0], r=0.7))
    model = build_model(sc)
    F = total_load(model)
    assert F == pytest.approx(math.pi * R**2, rel=1e-3)  # the meshed disc's area: chords of the circle
    for form in ("primal", "condensed"):
        res = pq.solve(sc, formulation=form, accuracy="high", model=model)
        assert res.ok and res.kkt.ok
        assert np.allclose(res.reactions, F / 3, rtol=1e-6)
    with pytest.raises(pq.ProblemError, match="floats"):
        pq.solve(sc, formulation="dual", model=model)


def test_disc_on_posts_with_heave_three_formulations_agree():
    """A simply supported disc on six one-sided rigid posts, one heaved: primal, condensed and dual
    agree, the KKT check passes, and the reactions of the posts and of the edge carry the whole
    load; the two-sided comparison (solve_bilateral) balances it too."""
    sc = disc("simple", size=R / 8, supports=posts([-2e-3, 1e-4, 0.0, 1e-4, 0.0, 5e-5], r=0.5))
    sc.plate.h = 0.05
    model = build_model(sc)
    F = total_load(model)
    got = {}
    for form in ("primal", "condensed", "dual"):
        res = pq.solve(sc, formulation=form, accuracy="high", model=model)
        assert res.ok and res.kkt.ok, form
        assert np.all(res.reactions >= -1e-9 * F) and np.all(res.gaps >= -1e-9)
        edge = -(model.K_full @ res.u - model.f_full)[model.fixed]  # two-sided reactions, w dofs only
        assert np.all(model.fixed % 3 == 0)  # simple support: w = 0 only
        assert res.reactions.sum() + edge.sum() == pytest.approx(F, rel=1e-8)
        got[form] = res.reactions
    assert got["primal"][0] > 0 and got["primal"][1] < 1e-6 * got["primal"][0]  # the heaved post lifts its neighbours
    for form in ("condensed", "dual"):
        assert np.allclose(got[form], got["primal"], rtol=1e-5, atol=1e-7 * F)
    two = pq.solve_bilateral(sc, model=model)
    edge = -(model.K_full @ two.u - model.f_full)[model.fixed]
    assert two.reactions.sum() + edge.sum() == pytest.approx(F, rel=1e-8)
    assert np.any(two.reactions < 0)  # two-sided posts pull where one-sided ones would lift off


def test_pins_on_a_shape_are_nodes():
    """Three two-sided pins at 120° hold a free disc: each carries a third of the load."""
    sc = disc(edge=None, size=R / 8, pins=[pq.Pin(0.5 * math.cos(t), 0.5 * math.sin(t)) for t in (0, 2.0944, 4.1888)])
    res = pq.solve(sc)
    model = res.model
    r = -(model.K_full @ res.u - model.f_full)[model.fixed]
    assert np.allclose(r, total_load(model) / 3, rtol=1e-3)
    assert abs(res.deflection(0.5, 0.0)) < 1e-12 < abs(res.deflection(0.0, 0.0))


def test_moments_and_slopes_of_the_clamped_circular_plate():
    """DKT's own moments M = −D_b κ and slopes β through Result, against Timoshenko § 62:
    M_r = q (R²(1 + ν) − r²(3 + ν))/16, M_t = q (R²(1 + ν) − r²(1 + 3ν))/16, w,r = −q r (R² − r²)/16D."""
    res = pq.solve(disc("clamped"))
    mx, my, mxy = res.moments(np.array([0.0, 0.999 * R, 0.5 * R]), np.zeros(3))
    Mr = (1 + NU) * R**2 / 16 - np.array([0.0, 0.999, 0.5]) ** 2 * R**2 * (3 + NU) / 16
    Mt = (1 + NU) * R**2 / 16 - 0.25 * R**2 * (1 + 3 * NU) / 16
    assert mx[0] == pytest.approx(Mr[0], rel=0.01) and my[0] == pytest.approx(Mr[0], rel=0.01)
    assert mx[1] == pytest.approx(Mr[1], rel=0.02) and mx[2] == pytest.approx(Mr[2], rel=0.02)
    assert my[2] == pytest.approx(Mt, rel=0.02) and abs(mxy[2]) < 0.02 * abs(Mt)
    s1, s2, _ = res.principal_stresses(0.0, 0.0)  # equal bending both ways at the centre: 6 M / h²
    assert s1 == pytest.approx(6 * Mr[0] / 0.01**2, rel=0.01) and s2 == pytest.approx(s1, rel=0.01)
    c = 0.5 * R / math.sqrt(2)  # off the axes: M_xy = (M_r − M_t) sin θ cos θ, within 2 % of the largest M
    assert abs(res.moments(c, c)[2] + 0.25 * R**2 * (2 - 2 * NU) / 32) < 0.02 * Mr[0]
    slope = lambda x, y: -(R**2 - x * x - y * y) / (16 * res.scene.plate.D) * np.array([x, y])  # noqa: E731
    wx, wy = res.slopes(0.5 * R, 0.0)
    assert wx == pytest.approx(slope(0.5 * R, 0.0)[0], rel=0.005) and abs(wy) < 0.005 * abs(wx)
    node = res.model.grid.nodes[np.argmin(np.hypot(*(res.model.grid.nodes - [0.4, 0.3]).T))]
    assert np.allclose(res.slopes(*node), slope(*node), rtol=0.01)  # at a node: its own slope dofs


def annulus_w(r, a, b, q, Dp, nu, kind):
    """Deflection of an annular plate (radii b < a) under uniform q with both edges clamped or both
    simply supported: the general axisymmetric solution w = A + B r² + C ln r + E r² ln r + q r⁴/64D
    (Timoshenko & Woinowsky-Krieger § 62) with its four edge conditions."""
    def rows(rr):
        w = [1.0, rr**2, math.log(rr), rr**2 * math.log(rr)]
        w1 = [0.0, 2 * rr, 1 / rr, 2 * rr * math.log(rr) + rr]
        w2 = [0.0, 2.0, -1 / rr**2, 2 * math.log(rr) + 3]
        p = q / (64 * Dp)
        if kind == "clamped":
            return [w, w1], [-p * rr**4, -4 * p * rr**3]
        return [w, [w2[k] + nu * w1[k] / rr for k in range(4)]], [-p * rr**4, -(12 + 4 * nu) * p * rr**2]
    (ra, fa), (rb, fb) = rows(a), rows(b)
    c = np.linalg.solve(np.array(ra + rb), np.array(fa + fb))
    return c @ [1.0, r**2, math.log(r), r**2 * math.log(r)] + q * r**4 / (64 * Dp)


@pytest.mark.parametrize("kind", ["clamped", "simple"])
def test_annular_plate_held_on_both_edges(kind):
    """A disc with a concentric round hole, edges.all (the outer circle) and edges.hole0 held the
    same way, against the closed form (R/16: simple within 0.04 %, clamped 0.9 %, the narrower
    clamped ring being the coarser one)."""
    sc = disc(kind, holes=[{"circle": [0.0, 0.0, 0.3]}])
    sc.edges["hole0"] = pq.Edge(kind)
    sc.validate()
    res = pq.solve(sc)
    for r in (0.5, 0.65, 0.8):
        ref = annulus_w(r, R, 0.3, 1.0, sc.plate.D, NU, kind)
        assert res.deflection(r * math.cos(0.4), r * math.sin(0.4)) == pytest.approx(ref, rel=0.015)


def test_free_disc_on_a_bed_sinks_by_q_over_k():
    """A free disc on a tensionless bed (no gap) under uniform q: a rigid translation w = q / k,
    exactly (lumped load and lumped bed springs share the tributary areas); the bed carries it all."""
    sc = disc(edge=None, size=R / 8, loads=[pq.UniformLoad(2.0)], foundation=pq.Foundation(k=100.0))
    res = pq.solve(sc, accuracy="high")
    assert res.kkt.ok and np.all(res.active)
    assert res.deflection(np.array([0.0, 0.5, -0.3]), np.array([0.0, 0.7, 0.9])) == pytest.approx(0.02, rel=1e-7)
    assert res.reactions.sum() == pytest.approx(total_load(res.model), rel=1e-10)
    assert res.model.bed_areas().sum() == pytest.approx(res.model.grid.areas().sum(), rel=1e-12)


def test_point_load_on_a_bed_against_hertz():
    """A disc on an elastic bed (two-sided, solve_bilateral) under a central point load, radius
    6.7 times the characteristic length ℓ = (D/k)^¼: Hertz's infinite plate, w0 = P / (8 √(k D))."""
    ell = 0.15
    k = D / ell**4
    sc = disc(edge=None, loads=[pq.PointLoad(1.0, 0.0, 0.0)], foundation=pq.Foundation(k=k))
    res = pq.solve_bilateral(sc)
    assert w0(res) == pytest.approx(1.0 / (8 * math.sqrt(k * D)), rel=0.01)
    assert res.reactions.sum() == pytest.approx(1.0, rel=1e-10)
    one = pq.solve(sc, model=res.model)  # tensionless: the rim lifts off, the centre sinks deeper
    assert one.kkt.ok and w0(one) > w0(res) and not np.all(one.active)


def test_bed_region_on_a_polygon():
    """A bed over part of a free square (its left half): the right half cantilevers, so its far
    edge deflects more than the bedded left one; the bed carries the whole load."""
    sq = [[0, 0], [1, 0], [1, 1], [0, 1]]
    sc = pq.Scene(plate=pq.Plate(shape={"polygon": sq}), mesh=pq.MeshSpec(element="dkt", size=1 / 8),
                  loads=[pq.UniformLoad(1.0)], foundation=pq.Foundation(k=1e4, region=[0.0, 0.5, 0.0, 1.0]))
    res = pq.solve(sc)
    assert res.kkt.ok and res.reactions.sum() == pytest.approx(1.0, rel=1e-8)
    # the region's outline is a mesh line: the springs' areas sum to the half's area exactly
    assert res.model.bed_areas().sum() == pytest.approx(0.5, rel=1e-12)
    assert res.deflection(1.0, 0.5) > res.deflection(0.0, 0.5)


RAFT = """
name = "raft"

[plate]
shape = { circle = [0.0, 0.0, 1.0] }
h = 0.05
E = 1.0e7
nu = 0.3

[mesh]
element = "dkt"
size = 0.125

[edges]
all = "simple"

[[holes]]
polygon = [[0.3, -0.1], [0.5, -0.1], [0.5, 0.1], [0.3, 0.1]]

[[loads]]
type = "uniform"
q = 1.0

[[supports]]
x = -0.5
y = 0.0
gap = -0.001

[[supports]]
x = 0.0
y = 0.5
gap = 0.0
"""


@pytest.mark.parametrize("form", ["primal", "condensed", "dual"])
def test_command_line_solve_on_a_shape(tmp_path, capsys, form):
    """`plateqp solve` on a TOML circle with a hole, each formulation: the same reactions, and
    statics: the reactions and the edge carry the load (checked through the Python API)."""
    import json

    from plateqp.cli import main

    path = tmp_path / "raft.toml"
    path.write_text(RAFT)
    assert main(["solve", str(path), "--formulation", form, "--accuracy", "high", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "optimal" and out["formulation"] == form and out["kkt"]["ok"]
    ref = pq.solve(pq.Scene.from_toml(path), formulation="primal", accuracy="high")
    assert np.allclose(out["reactions"], ref.reactions, rtol=1e-6, atol=1e-9)
    m = ref.model
    edge = -(m.K_full @ ref.u - m.f_full)[m.fixed]
    assert ref.reactions.sum() + edge.sum() == pytest.approx(total_load(m), rel=1e-8)
    assert out["w_max"] == pytest.approx(float(np.abs(ref.u[0::3]).max() * np.sign(ref.u[0::3][np.abs(ref.u[0::3]).argmax()])))


def test_prescribed_edge_w_and_slope_on_a_circle():
    """The source paper's w = f1, ∂w/∂n = f2 on a curved edge, against the axisymmetric closed
    forms: a clamped edge raised by δ moves the unloaded disc rigidly; a clamped edge at slope s
    bends it to w = s (r² − R²)/2R; a simple edge at δ adds δ to the simply supported plate."""
    delta, s = 1e-3, 2e-3
    res = pq.solve(disc(edge=None, loads=[], edges={"all": pq.Edge("clamped", w=delta)}))
    assert res.deflection(np.array([0.0, 0.4, -0.7]), np.array([0.0, 0.3, 0.2])) == pytest.approx(delta, rel=1e-9)
    res = pq.solve(disc(edge=None, loads=[], edges={"all": pq.Edge("clamped", slope=s)}))
    for r in (0.0, 0.5):
        assert res.deflection(r, 0.0) == pytest.approx(s * (r * r - R * R) / (2 * R), rel=0.01)
    res = pq.solve(disc(edge=None, edges={"all": pq.Edge("simple", w=delta)}))
    assert w0(res) == pytest.approx(delta + SIMPLE, rel=0.01)
    # a straight clamped edge at slope s, the rest free, no load: the rigid rotation w = −s x, exactly
    sq = pq.Scene(plate=pq.Plate(shape={"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]]}),
                  mesh=pq.MeshSpec(element="dkt", size=0.25), edges={"outer_3": pq.Edge("clamped", slope=s)})
    res = pq.solve(sq)
    assert res.deflection(np.array([1.0, 0.3]), np.array([0.5, 0.9])) == pytest.approx([-s, -0.3 * s], rel=1e-9)
    with pytest.raises(pq.SceneError, match="edges.outer_0 and edges.outer_3 prescribe different slopes"):
        pq.solve(pq.Scene(plate=sq.plate, mesh=sq.mesh, edges={"outer_0": pq.Edge("clamped", slope=s),
                                                                 "outer_3": pq.Edge("clamped", slope=s)}))
    with pytest.raises(pq.SceneError, match="different values of w"):
        pq.solve(pq.Scene(plate=pq.Plate(shape={"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]]}),
                          mesh=pq.MeshSpec(element="dkt", size=0.25), loads=[pq.UniformLoad(1.0)],
                          edges={"outer_0": pq.Edge("simple", w=delta), "outer_1": pq.Edge("simple")}))
