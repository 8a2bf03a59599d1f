"""Mesh refinement (plateqp.studies.refinement): the convergence table against Timoshenko, and
discretisation error against solver error: ``accuracy="auto"`` and ``solve_to_target``, on the
rectangle grid (ACM, BFS) and on triangles (DKT), where a mesh of n "cells a side" has element
size h = L / n (L: the bounding box's side).

External references: Navier's double series for a simply supported square plate, under a
uniform load and under a central point load; the simply supported and the clamped circular
plate of radius R (Timoshenko & Woinowsky-Krieger, Theory of plates and shells, §§ 15-19):
clamped w0 = q R⁴ / 64 D, simply supported w0 = (5 + ν) q R⁴ / (64 (1 + ν) D), under a central
point load P, w0 = (3 + ν) P R² / (16 π (1 + ν) D). By superposition the reaction of a rigid
one-sided support at the centre, set at a gap g0 below the plate, is
R = (w_q − g0) / α with w_q the centre deflection under the load and α that under a unit
point load (while w_q > g0).
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.errors import ProblemError
from plateqp.studies import auto_tolerance, convergence, solve_to_target
from study_scenes import fig5

SLAB_W = 0.0040624  # Timoshenko: SS square, uniform load, centre w × q a⁴/D
A, Q, NU = 1.0, 50.0, 0.3
PLATE = pq.Plate(a=A, b=A, h=0.02, E=1.0e7, nu=NU)
D = PLATE.D


def _odd(n):
    return np.arange(1, n + 1, 2, dtype=float)


def navier_uniform_centre(n=401):
    """w at the centre of a SS square plate under q: 16 q a⁴/(π⁶ D) Σ (−1)^… /(m n (m²+n²)²)."""
    m = _odd(n)[:, None]
    k = _odd(n)[None, :]
    sign = (-1.0) ** ((m - 1) / 2 + (k - 1) / 2)
    return 16 * Q * A**4 / (math.pi**6 * D) * float(np.sum(sign / (m * k * (m**2 + k**2) ** 2)))


def navier_point_centre(n=4001):
    """w at the centre under a unit central point load: 4 a²/(π⁴ D) Σ_{m,n odd} 1/(m²+n²)²."""
    m = _odd(n)[:, None]
    k = _odd(n)[None, :]
    return 4 * A**2 / (math.pi**4 * D) * float(np.sum(1.0 / (m**2 + k**2) ** 2))


W_Q = navier_uniform_centre()
ALPHA = navier_point_centre()
G0 = 0.5 * W_Q
R_EXACT = (W_Q - G0) / ALPHA


def centre_scene(n=8, element="acm", support=True):
    return pq.Scene(name="centre", plate=PLATE, mesh=pq.MeshSpec(n, n, element),
                    edges={k: "simple" for k in ("left", "right", "bottom", "top")},
                    loads=[pq.UniformLoad(Q)],
                    supports=[pq.Support(0.5, 0.5, gap=G0)] if support else [])


# the same central support on triangles: a simply supported disc (a shape the grid cannot mesh)
R, DISC_Q = 1.0, 1.0


def disc(edge="simple", size=R / 8, **kw) -> pq.Scene:
    return pq.Scene(name="disc", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.01, E=1.0e7, nu=NU),
                    mesh=pq.MeshSpec(element="dkt", size=size), edges={"all": pq.Edge(edge)},
                    loads=[pq.UniformLoad(DISC_Q)], **kw)


DISC_D = disc().plate.D
DISC_CLAMPED = DISC_Q * R**4 / (64 * DISC_D)
DISC_SIMPLE = (5 + NU) * DISC_Q * R**4 / (64 * (1 + NU) * DISC_D)
DISC_ALPHA = (3 + NU) * R**2 / (16 * math.pi * (1 + NU) * DISC_D)
DISC_G0 = 0.5 * DISC_SIMPLE
DISC_R_EXACT = (DISC_SIMPLE - DISC_G0) / DISC_ALPHA


def disc_centre_support(size=R / 8) -> pq.Scene:
    return disc("simple", size, supports=[pq.Support(0.0, 0.0, gap=DISC_G0)])


# the central support on each mesh: (scene, its reaction's closed form)
CENTRE = {"acm": (lambda: centre_scene(element="acm"), R_EXACT),
          "bfs": (lambda: centre_scene(element="bfs"), R_EXACT),
          "triangles": (disc_centre_support, DISC_R_EXACT)}


def centre_case(mesh):
    if mesh == "triangles":
        pytest.importorskip("gmsh")
    scene, exact = CENTRE[mesh]
    return scene(), exact


def test_references():
    """The series against Timoshenko's table: 0.00406 q a⁴/D and 0.01160 P a²/D."""
    assert W_Q * D / (Q * A**4) == pytest.approx(0.0040624, rel=2e-5)
    assert ALPHA * D / A**2 == pytest.approx(0.0116008, rel=2e-5)


@pytest.mark.parametrize("mesh, target", [("acm", 1e-2), ("acm", 1e-3), ("bfs", 1e-2), ("bfs", 1e-3),
                                          ("triangles", 1e-2)])
def test_target_is_met(mesh, target):
    """The reaction of the central support within the target of its closed form; on triangles
    the mesh is chosen by halving the element size h."""
    sc, exact = centre_case(mesh)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        out = solve_to_target(sc, target)
    assert out.reached and out.result.ok
    assert abs(out.result.reactions[0] / exact - 1) <= target
    assert out.tolerance == pytest.approx(target / 10)
    assert out.result.accuracy == pytest.approx(target / 10)
    if mesh == "triangles":
        sizes = [r["mesh"][0] for r in out.rows]
        assert sizes == [4 * 2**k for k in range(len(sizes))]
        assert out.result.scene.mesh.size == pytest.approx(2 * R / sizes[-1])
        assert "element size" in str(out)


@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_estimates_err_on_the_safe_side(element):
    """From 16 cells a side on, each mesh's estimated reaction error is at least the true one."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        out = solve_to_target(centre_scene(element=element), 1e-4, max_cells=64)
    rows = [r for r in out.rows if r["estimate"] is not None and r["mesh"][0] >= 16]
    assert len(rows) == 3
    for r in rows:
        sc = centre_scene(r["mesh"][0], element)
        true = abs(pq.solve(sc, backend="lemke", accuracy="high").reactions[0] / R_EXACT - 1)
        assert r["estimate"]["reactions"] >= true, (r, true)


def test_target_on_a_two_sided_plate():
    """No contact: max |w| of the SS plate within the target of Navier's centre deflection."""
    out = solve_to_target(centre_scene(support=False), 1e-3)
    assert out.reached
    assert abs(out.result.w_max()[0] / W_Q - 1) <= 1e-3


@pytest.mark.parametrize("bad", [0.0, 1.0, 2.0, float("nan"), -1e-3])
def test_bad_target(bad):
    with pytest.raises(ProblemError):
        solve_to_target(centre_scene(), bad)


def test_auto_accuracy_lets_the_mesh_dominate():
    """accuracy="auto" on a 16² mesh: a tolerance looser than the default preset's, yet the
    answer as close to Navier as the exact (Lemke) answer on the same mesh."""
    backend = next((b for b in ("clarabel", "osqp") if b in pq.available_backends()), None)
    if backend is None:
        pytest.skip("no iterative QP backend installed")
    sc = centre_scene(16)
    tol, est = auto_tolerance(sc)
    assert est is not None and tol == pytest.approx(0.1 * est.worst)
    assert tol > 1e-6
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        res = pq.solve(sc, backend=backend, formulation="primal", accuracy="auto")
    exact = pq.solve(sc, backend="lemke", accuracy="high")
    assert res.accuracy == pytest.approx(tol) and res.extras["accuracy"] == "auto"
    assert res.extras["discretisation_error"]["worst"] == pytest.approx(est.worst)
    mesh_err = abs(exact.reactions[0] / R_EXACT - 1)
    assert abs(res.reactions[0] / R_EXACT - 1) <= 1.1 * mesh_err


def test_auto_on_a_coarse_mesh_is_low():
    tol, est = auto_tolerance(centre_scene(2))
    assert est is None and tol == 1e-3


def test_cli_target_and_accuracy(tmp_path, capsys):
    """``plateqp solve --target`` reports the mesh it chose and the estimate; numbers and "auto"
    are accepted by --accuracy; bad values are exit code 2 with a message."""
    from plateqp.cli import main

    path = tmp_path / "centre.toml"
    centre_scene(8, "bfs").to_toml(path)
    assert main(["solve", str(path), "--target", "1e-3", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["target"]["reached"] and d["target"]["tolerance"] == pytest.approx(1e-4)
    assert abs(d["reactions"][0] / R_EXACT - 1) <= 1e-3
    assert d["target"]["mesh"] == [r["mesh"] for r in d["target"]["meshes"]][-1]
    assert main(["solve", str(path), "--accuracy", "1e-7", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["accuracy"] == 1e-7
    assert main(["solve", str(path), "--accuracy", "auto", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["discretisation_error"]["mesh"] == [8, 8]
    for bad in (["--accuracy", "1e-20"], ["--accuracy", "best"], ["--target", "0"], ["--target", "x"]):
        with pytest.raises(SystemExit) as exc:
            main(["solve", str(path), *bad])
        assert exc.value.code == 2
    assert main(["solve", str(path), "--target", "1e-3", "--accuracy", "high"]) == 2
    assert "drop --accuracy" in capsys.readouterr().err


@pytest.mark.parametrize("mesh", ["bfs", "triangles"])
def test_cli_target_in_every_formulation(tmp_path, capsys, mesh):
    """``plateqp solve SCENE.toml --target`` from the command line, every formulation: the
    reaction within the target of its closed form (the square's on the grid, the disc's on
    triangles), the mesh it reports the last one it tried."""
    from plateqp.cli import main

    sc, exact = centre_case(mesh)
    path = tmp_path / "centre.toml"
    sc.to_toml(path)
    for form in ("primal", "condensed", "dual"):
        assert main(["solve", str(path), "--target", "1e-2", "--formulation", form, "--json"]) == 0
        d = json.loads(capsys.readouterr().out)
        assert d["target"]["reached"] and abs(d["reactions"][0] / exact - 1) <= 1e-2
        assert d["target"]["mesh"] == d["target"]["meshes"][-1]["mesh"]


def test_auto_accuracy_on_a_disc_errs_on_the_safe_side():
    """``accuracy="auto"`` on triangles: the error estimated from the meshes 4h and 2h is at least
    the true error of the reaction on h (against the closed form), and the solver's tolerance
    is a tenth of it."""
    pytest.importorskip("gmsh")
    sc = disc_centre_support(R / 16)
    tol, est = auto_tolerance(sc)
    assert est is not None and est.mesh == (32, 32) and est.from_meshes == ((8, 8), (16, 16))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        res = pq.solve(sc, accuracy="auto")
    assert res.accuracy == pytest.approx(tol) == pytest.approx(0.1 * est.worst)
    true_err = abs(res.reactions[0] / DISC_R_EXACT - 1)
    assert true_err <= res.extras["discretisation_error"]["reactions"]
    assert res.extras["discretisation_error"]["trusted"] is True


# -- convergence by mesh halving ----------------------------------------------------------------

def test_convergence_slab_against_timoshenko():
    sc = pq.Scene(name="slab", plate=pq.Plate(a=1.0, b=1.0, h=0.01, E=2.1e11, nu=0.3), mesh=pq.MeshSpec(8, 8),
                  edges={k: pq.Edge("simple") for k in ("left", "right", "bottom", "top")},
                  loads=[pq.UniformLoad(q=1000.0)])
    tab = convergence(sc, meshes=(2, 4, 8, 16, 32), quantities=("w_max", "w:0.5,0.5"), target=0.01)
    ref = SLAB_W * 1000.0 / sc.plate.D
    w = tab.values["w:0.5,0.5"]
    assert w[-1] == pytest.approx(ref, rel=0.01)  # the finest mesh within 1 %
    np.testing.assert_allclose(tab.values["w_max"], w)  # the maximum is at the centre
    d = tab.diff["w_max"]
    assert np.all(np.diff(d[:-1]) < 0) and np.isnan(d[-1])  # the changes shrink on halving
    assert d[:-1] == pytest.approx(np.abs(np.diff(w)) / np.abs(w[1:]))
    err = np.abs(w - ref)
    assert np.all(np.diff(err) < 0)
    # the paper's finding for deflections: halving 8x8 still changes w by 1.2 %, halving 16x16 by 0.3 %
    assert tab.converged_at["w_max"] == (16, 16)
    assert [r["nx"] for r in tab.rows] == [2, 4, 8, 16, 32] and "w_max diff" in tab.rows[0]
    assert "converged at" in str(tab)


def test_convergence_reactions_on_a_contact_scene():
    sc = fig5()
    sc.loads[0] = pq.PointLoad(P=20000.0, x=200.0, y=200.0)
    tab = convergence(sc, meshes=(4, 8, 16), quantities=("w_max", "reactions.12", "reactions.0"), target=0.01)
    assert all(e is None for e in tab.errors)
    # the paper's finding: reactions converge already on the coarsest meshes
    assert tab.converged_at["reactions.12"] == (4, 4)
    # a lifted support's reaction is zero up to rounding: compared with the largest reaction, not with noise
    assert tab.converged_at["reactions.0"] == (4, 4)


@pytest.mark.parametrize("edge, ref, meshes", [("clamped", DISC_CLAMPED, (16, 32, 64)),
                                               ("simple", DISC_SIMPLE, (8, 16, 32, 64))])
def test_convergence_on_a_disc_is_second_order(edge, ref, meshes):
    """Triangles: the convergence table on meshes of h = 2R/n against the closed forms: w at the
    centre within 0.1 % on the finest mesh, the error's fitted order in h ≈ 2 (DKT), the changes
    shrinking (clamped: from 16 on; at h = R/4 the clamped error passes through a sign change)."""
    pytest.importorskip("gmsh")
    tab = convergence(disc(edge), meshes=meshes, quantities=("w:0,0",), target=0.01)
    assert [m for m in tab.meshes] == [(n, n) for n in meshes] and all(e is None for e in tab.errors)
    w = tab.values["w:0,0"]
    err = np.abs(w / ref - 1)
    assert err[-1] < 1e-3
    h = 2 * R / np.array(meshes)
    order = np.polyfit(np.log(h), np.log(err), 1)[0]
    assert 1.7 < order < 2.3, (err, order)
    assert np.all(np.diff(tab.diff["w:0,0"][:-1]) < 0)


def _mean_edge(res) -> float:
    g = res.model.grid
    p = g.nodes[g.triangles]
    return float(np.mean(np.hypot(*(p - np.roll(p, 1, axis=1)).transpose(2, 0, 1))))


def test_triangle_meshes_halve_the_element_size():
    """A mesh of n cells a side is the gmsh mesh of size h = L / n: its mean edge is h (within 15 %: gmsh makes the coarsest a little finer)."""
    pytest.importorskip("gmsh")
    tab = convergence(disc(), meshes=(8, 16, 32), quantities=(("edge", _mean_edge),))
    assert tab.values["edge"] == pytest.approx(2 * R / np.array([8, 16, 32]), rel=0.15)
