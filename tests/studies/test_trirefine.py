"""Refinement on triangle meshes: convergence studies, ``solve_to_target``
(``plateqp solve --target``) and ``accuracy="auto"`` on a circular plate, where a mesh of n
"cells a side" has element size h = L / n (L = 2R: the bounding box).

External references (Timoshenko & Woinowsky-Krieger, Theory of plates and shells, §§ 15-19):
circular plate of radius R, uniform q, clamped w0 = q R⁴ / 64 D, simply supported
w0 = (5 + ν) q R⁴ / (64 (1 + ν) D); simply supported under a central point load P,
w0 = (3 + ν) P R² / (16 π (1 + ν) D). By superposition a rigid one-sided support at the centre,
a gap g0 below the plate, carries R = (w_q − g0) / α (α: w0 under P = 1) while w_q > g0.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.studies import auto_tolerance, convergence, solve_to_target

pytest.importorskip("gmsh")

R, NU, Q = 1.0, 0.3, 1.0


def disc(edge="simple", size=R / 8, **kw) -> pq.Scene:
    return pq.Scene(name="disc", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.01, E=1.0e7, nu=NU),
                    mesh=pq.MeshSpec(element="dkt", size=size), edges={"all": pq.Edge(edge)},
                    loads=[pq.UniformLoad(Q)], **kw)


D = disc().plate.D
CLAMPED = Q * R**4 / (64 * D)
SIMPLE = (5 + NU) * Q * R**4 / (64 * (1 + NU) * D)
ALPHA = (3 + NU) * R**2 / (16 * math.pi * (1 + NU) * D)
G0 = 0.5 * SIMPLE
R_EXACT = (SIMPLE - G0) / ALPHA


def centre_support(size=R / 8) -> pq.Scene:
    return disc("simple", size, supports=[pq.Support(0.0, 0.0, gap=G0)])


@pytest.mark.parametrize("edge, ref, meshes", [("clamped", CLAMPED, (16, 32, 64)), ("simple", SIMPLE, (8, 16, 32, 64))])
def test_convergence_on_a_disc_is_second_order(edge, ref, meshes):
    """The convergence table on meshes of h = 2R/n against the closed forms: w at the centre
    within 0.1 % on the finest mesh, the error's fitted order in h ≈ 2 (DKT), the changes
    shrinking (clamped: from 16 on; at h = R/4 the clamped error passes through a sign change)."""
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
    tab = convergence(disc(), meshes=(8, 16, 32), quantities=(("edge", _mean_edge),))
    assert tab.values["edge"] == pytest.approx(2 * R / np.array([8, 16, 32]), rel=0.15)


def test_target_on_a_disc_with_a_central_support():
    """``solve_to_target`` on triangles: the reaction of a one-sided support at the centre of a
    simply supported disc within the target of its closed form, the mesh chosen by halving h."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        out = solve_to_target(centre_support(), 1e-2)
    assert out.reached and out.result.ok
    assert abs(out.result.reactions[0] / R_EXACT - 1) <= 1e-2
    sizes = [r["mesh"][0] for r in out.rows]
    assert sizes == [4 * 2**k for k in range(len(sizes))]
    assert out.result.scene.mesh.size == pytest.approx(2 * R / sizes[-1])
    assert "element size" in str(out)


def test_auto_accuracy_on_a_disc_errs_on_the_safe_side():
    """``accuracy="auto"`` on triangles: the error estimated from the meshes 4h and 2h is at least
    the true error of the reaction on h (against the closed form), and the solver's tolerance
    is a tenth of it."""
    sc = centre_support(R / 16)
    tol, est = auto_tolerance(sc)
    assert est is not None and est.mesh == (32, 32) and est.from_meshes == ((8, 8), (16, 16))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        res = pq.solve(sc, accuracy="auto")
    assert res.accuracy == pytest.approx(tol) == pytest.approx(0.1 * est.worst)
    true_err = abs(res.reactions[0] / R_EXACT - 1)
    assert true_err <= res.extras["discretisation_error"]["reactions"]
    assert res.extras["discretisation_error"]["trusted"] is True


def test_cli_target_on_a_circle(tmp_path, capsys):
    """``plateqp solve CIRCLE.toml --target`` from the command line, every formulation."""
    from plateqp.cli import main

    path = tmp_path / "disc.toml"
    centre_support().to_toml(path)
    for form in ("primal", "condensed", "dual"):
        assert main(["solve", str(path), "--target", "1e-2", "--formulation", form, "--json"]) == 0
        d = json.loads(capsys.readouterr().out)
        assert d["target"]["reached"] and abs(d["reactions"][0] / R_EXACT - 1) <= 1e-2
        assert d["target"]["mesh"] == d["target"]["meshes"][-1]["mesh"]
