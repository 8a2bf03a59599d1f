"""The source paper's figures 5 and 6 as demo studies, and its comparison stated precisely.

References: statics (a floating plate: the reactions carry the whole load), the rigid limit
(springs much stiffer than the plate: the reactions of rigid supports), the soft limit (springs
much softer than the plate: the plate moves as a rigid body, R = c · (w_plane − g0), the plane
from force and moment balance), direct solves on either side of each breakpoint, hand-computed
uniformity measures. Small meshes; no timings.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp import demo, scenes
from plateqp.demo import paper
from plateqp.model.paths import set_param
from plateqp.studies.design import most_uniform_stiffness, uniformity

MESH = 8


def total_load(sc: pq.Scene) -> tuple[float, float, float]:
    """(force, moment about y = 0 ... as Σ F x, Σ F y) of the point and uniform loads."""
    F = Mx = My = 0.0
    for ld in sc.loads:
        if ld.type == "point":
            F, Mx, My = F + ld.P, Mx + ld.P * ld.x, My + ld.P * ld.y
        elif ld.type == "uniform":
            P = ld.q * sc.plate.a * sc.plate.b
            F, Mx, My = F + P, Mx + P * sc.plate.a / 2, My + P * sc.plate.b / 2
        else:
            raise AssertionError("only point and uniform loads here")
    return F, Mx, My


def rigid_body_reactions(sc: pq.Scene, c: float) -> np.ndarray:
    """Every support in contact, a rigid plate: w = α + βx + γy, R_i = c (w_i − g0_i), balance."""
    xy = np.array([[s.x, s.y] for s in sc.supports])
    g0 = np.array([s.gap for s in sc.supports])
    A = np.column_stack([np.ones(len(xy)), xy])  # w_i = A θ
    F, Mx, My = total_load(sc)
    # Σ R [1, x, y] = [F, Σ F x, Σ F y] with R = c (A θ − g0)
    theta = np.linalg.solve(c * A.T @ A, np.array([F, Mx, My]) + c * A.T @ g0)
    return c * (A @ theta - g0)


@pytest.fixture(scope="module")
def path():
    return paper.stiffness_path(mesh=MESH)


@pytest.fixture(scope="module")
def contour():
    return paper.contour_pressure(mesh=MESH, kappas=(1.0, 1e-3), scan=7)


# -- the uniformity measures ---------------------------------------------------------------------
def test_uniformity_measures_by_hand():
    R = np.array([1.0, 2.0, 3.0, 6.0])  # mean 3, population std sqrt(3.5)
    assert uniformity(R) == pytest.approx(math.sqrt(3.5) / 3, rel=1e-14)  # default: std/mean
    assert uniformity(R, "std/mean") == pytest.approx(0.6236095644623235, rel=1e-14)
    assert uniformity(R, "peak/mean") == pytest.approx(2.0, rel=1e-14)
    assert uniformity(R, "range/mean") == pytest.approx(5.0 / 3.0, rel=1e-14)
    assert uniformity(np.full(5, 7.0), "peak/mean") == pytest.approx(1.0)
    assert uniformity(np.full(5, 7.0), "range/mean") == 0.0
    assert uniformity(np.zeros(3), "std/mean") == math.inf
    with pytest.raises(pq.ProblemError, match="measure must be one of"):
        uniformity(R, "max/min")


def test_most_uniform_stiffness_measure_option(contour):
    """Each measure's optimum is no worse than any scanned stiffness, and its value is that
    measure of the reactions it returns; cv stays std/mean (backwards compatible)."""
    for m, u in contour.optima.items():
        assert u.measure == m
        assert u.value == pytest.approx(uniformity(u.reactions, m), rel=1e-12)
        assert u.cv == pytest.approx(uniformity(u.reactions, "std/mean"), rel=1e-12)
        assert u.value <= contour.measures[m].min() * (1 + 1e-9)
    # std/mean has no interior optimum (it falls towards the rigid-plate limit); peak/mean has one
    assert contour.optima["std/mean"].at_bound and contour.optima["std/mean"].c == pytest.approx(
        contour.grid[0] * contour.unit, rel=0.5)
    assert not contour.optima["peak/mean"].at_bound
    with pytest.raises(pq.ProblemError, match="measure"):
        most_uniform_stiffness(contour.scene, (1.0, 10.0), measure="nonsense")


# -- figure 6: the contour ------------------------------------------------------------------------
def test_contour_curves_statics_and_soft_limit(contour):
    sc = contour.scene
    F = total_load(sc)[0]
    for k, res in contour.curves:
        assert res.reactions.sum() == pytest.approx(F, rel=1e-8)
    # the soft limit: a rigid plate on springs, approached linearly in κ
    err = {}
    for k in (1e-4, 1e-5):
        c = k * contour.unit
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pq.PlateQPWarning)  # tiny c: the KKT scale is at its edge
            res = pq.solve(set_param(sc, "supports.*.stiffness", c), accuracy="high")
        assert res.active.all()
        err[k] = np.abs(res.reactions / rigid_body_reactions(sc, c) - 1).max()
    assert err[1e-5] < 2e-3 and err[1e-5] < 0.2 * err[1e-4]


# -- figure 5: the stiffness path -----------------------------------------------------------------
def test_path_schemes_statics_and_their_own_contact_sets(path):
    F = total_load(path.scene)[0]
    assert len(path.schemes) == len(path.breakpoints) + 1 >= 6  # the paper: 6 schemes
    for s in path.schemes:
        assert s.result.reactions.sum() == pytest.approx(F, rel=1e-8)
        assert tuple(bool(a) for a in s.result.active) == s.active
        assert s.in_contact == [i + 1 for i in np.flatnonzero(s.result.active)]  # 1-based
    # successive schemes differ, and they join up at the breakpoints
    for a, b, bp in zip(path.schemes, path.schemes[1:], path.breakpoints):
        assert a.active != b.active
        assert bp["before"] == a.in_contact and bp["after"] == b.in_contact


def test_path_rigid_limit(path):
    """Very stiff springs give the rigid supports' answer; the path starts from it."""
    sc = path.scene
    rigid = pq.solve(set_param(sc, "supports.*.stiffness", "rigid"), accuracy="high")
    assert path.schemes[0].active == tuple(bool(a) for a in rigid.active)
    np.testing.assert_allclose(path.schemes[0].result.reactions, rigid.reactions, rtol=1e-9,
                               atol=1e-9 * np.abs(rigid.reactions).max())  # the first panel is drawn rigid
    stiff = pq.solve(set_param(sc, "supports.*.stiffness", 1e8 * path.unit), accuracy="high")
    assert tuple(stiff.active) == tuple(rigid.active)
    np.testing.assert_allclose(stiff.reactions, rigid.reactions, rtol=1e-4, atol=1e-4 * np.abs(rigid.reactions).max())


def test_path_soft_limit(path):
    """Soft springs: every support in contact, R = c (w_plane − g0) of a rigid plate."""
    last = path.schemes[-1]
    assert all(last.active)
    c = 1e-4 * path.unit
    res = pq.solve(set_param(path.scene, "supports.*.stiffness", c), accuracy="high")
    ref = rigid_body_reactions(path.scene, c)
    np.testing.assert_allclose(res.reactions, ref, rtol=1e-3)
    np.testing.assert_allclose(res.compressions, ref / c, rtol=1e-3)  # the springs: s = R / c


def test_path_breakpoints_bracket_scheme_changes(path):
    """Two direct solves (fresh, no re-use) on either side of each breakpoint: the contact set
    changes there, by exactly the supports the study names (1-based)."""
    assert all(b["kappa"] is not None for b in path.breakpoints)
    for b in path.breakpoints:
        k = b["kappa"]
        above = pq.solve(set_param(path.scene, "supports.*.stiffness", k * 1.004 * path.unit), accuracy="high")
        below = pq.solve(set_param(path.scene, "supports.*.stiffness", k / 1.004 * path.unit), accuracy="high")
        on_above = set(int(i) + 1 for i in np.flatnonzero(above.active))
        on_below = set(int(i) + 1 for i in np.flatnonzero(below.active))
        assert on_above != on_below, k
        assert sorted(on_below - on_above) == b["on"] and sorted(on_above - on_below) == b["off"], k
        assert b["c"] == pytest.approx(k * path.unit)


def test_path_kappa_scaling():
    sc = scenes.load("stiffness")
    unit, s = paper.kappa_unit(sc)
    assert s == 200.0
    assert unit == pytest.approx(sc.plate.E * sc.plate.h**3 / (12 * (1 - sc.plate.nu**2)) / 200.0**2)


# -- the demo ---------------------------------------------------------------------------------
def test_demo_runs_the_studies(tmp_path, capsys):
    assert demo.run(["fig5"], tmp_path, study_mesh=MESH) == 0
    out = capsys.readouterr().out
    assert "fig5: Figure 5" in out and "change 1 at kappa" in out and "scheme 1:" in out
    written = {p.name for p in tmp_path.iterdir()}
    assert written <= set(demo.output_files(["fig5"]))
    assert {"fig5.json", "report.html"} <= written
    rep = json.loads((tmp_path / "fig5.json").read_text())
    assert rep["breakpoints"] and rep["schemes"][0]["kappa_interval"][1] == "rigid"
    html = (tmp_path / "report.html").read_text()
    assert "Study “fig5”" in html
    if (tmp_path / "fig5-schemes.png").exists():
        assert (tmp_path / "fig5-schemes.png").read_bytes()[:4] == b"\x89PNG"


def test_demo_names_and_files():
    assert demo.names_all()[-3:] == ["fig5", "fig6", "regulate"]
    files = demo.output_files(["fig6"])
    assert files == ["report.html", "fig6.json", "fig6-pressure.png", "fig6-uniformity.png"]
    with pytest.raises(pq.SceneError, match="no built-in scene or study 'fig7'"):
        demo.output_files(["fig7"])


# -- the paper's comparison, stated precisely ---------------------------------------------------
def test_sections_2_and_4_normalisation():
    sc = set_param(set_param(scenes.load("heave"), "mesh.nx", MESH), "mesh.ny", MESH)
    one, two = pq.solve(sc, accuracy="high"), pq.solve_bilateral(sc)
    c = demo.compare(one, two)
    # sections 2 and 4 are the rows y = 200 and y = 600; recompute on those nodes by hand
    nodes = one.model.grid.nodes  # one row per node of the plate, as the nodal fields
    on = np.isin(np.round(nodes[:, 1], 9), [200.0, 600.0])
    sel = on & (demo.zones(one) == 1)
    w1, w2 = one.w_nodes(), two.w_nodes()
    dw = np.abs(w1 - w2)[sel].max()
    assert c.sections_nodes == sel.sum() > 0
    assert c.sections_dw == pytest.approx(dw, rel=1e-12)
    assert c.sections_rel == pytest.approx(dw / np.abs(w2[on]).max(), rel=1e-12)
    assert c.sections_rel_plate == pytest.approx(dw / c.w_ref, rel=1e-12)
    assert c.sections_dw <= c.dw_contact  # the sections' contact nodes are part of the contact zone


def test_sigma1_at_a_fixed_distance_converges_where_the_peak_does_not():
    """The peak σ1 at the point load grows as the mesh is halved; σ1 at a fixed distance does not."""
    vals = {}
    for n in (16, 32):
        sc = set_param(set_param(scenes.load("heave"), "mesh.nx", n), "mesh.ny", n)
        one, two = pq.solve(sc, accuracy="high"), pq.solve_bilateral(sc)
        c = demo.compare(one, two)
        # the four points (x ± r, y), (x, y ± r) are mesh nodes here: the mean of their nodal σ1
        g = one.model.grid
        S = g.to_grid(one.nodal("s1"))  # the grid view: S[j, i] at (i hx, j hy)
        r = c.s1_ring_radius
        pts = [(300 + r, 500), (300 - r, 500), (300, 500 + r), (300, 500 - r)]
        direct = np.mean([S[int(round(y / g.hy)), int(round(x / g.hx))] for x, y in pts])
        assert c.s1_ring_one == pytest.approx(direct, rel=1e-9)
        vals[n] = (c.s1_ring_one, float(np.nanmax(S)))
    assert abs(vals[32][0] / vals[16][0] - 1) < 0.02
    assert vals[32][1] / vals[16][1] - 1 > 0.15


def test_all_in_contact_sigma1_ring_and_sections_agree():
    """A 4 x 4 grid of supports under a uniform load, all in contact: one- and two-sided agree."""
    sup = [pq.Support(x, y) for y in (0.0, 1.0, 2.0, 3.0) for x in (0.0, 1.0, 2.0, 3.0)]
    sc = pq.Scene(name="grid", plate=pq.Plate(a=3.0, b=3.0, h=0.05, E=1.0e7, nu=0.3), mesh=pq.MeshSpec(6, 6, "acm"),
                  loads=[pq.UniformLoad(q=1.0), pq.PointLoad(P=1.0, x=1.5, y=1.5)], supports=sup)
    one, two = pq.solve(sc, accuracy="high"), pq.solve_bilateral(sc)
    assert one.active.all()
    c = demo.compare(one, two)
    assert c.sections_nodes > 0 and c.sections_dw <= 1e-9 * c.w_ref
    assert abs(c.s1_ring_rel) <= 1e-8 and c.s1_ring_radius == pytest.approx(0.5)
