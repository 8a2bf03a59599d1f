"""Exact working-scheme paths (plateqp.studies.exact_path) against external references.

- Closed form: a free square plate on four rigid corner supports under a uniform load q; as
  corner C settles by δ the plate twists (w = δ x y / a², exact for both elements), the corner
  forces change by 2 D (1 − ν) δ / a², and C (with A, on the same diagonal) is unloaded at
  δ* = q a⁴ / (8 D (1 − ν)): the lift-off must come out to 1e-9.
- Pointwise solves: on small random scenes the path's reactions, gaps and support deflections
  match independent exact solves (Lemke on the condensed LCP) at many parameter values.
- Bisection: every breakpoint the bisection of plateqp.studies.sweep brackets is an exact
  breakpoint inside its bracket, with the same contact sets on each side.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.studies import exact_path, exact_sweep, set_param, sweep
from test_sensitivity import A, NU, corners, random_scene


def solve(scene):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene, backend="lemke", accuracy="high")


@pytest.mark.parametrize("element, nx, q", [("acm", 4, 1.0), ("acm", 8, 3.0), ("bfs", 4, 1.0), ("acm", 6, 0.5)])
def test_corner_settlement_lift_off(element, nx, q):
    scene = corners(nx, element, q=q)
    D = scene.plate.D
    dstar = q * A**4 / (8 * D * (1 - NU))
    path = exact_path(scene, "supports.3.gap", 0.0, 3 * dstar)
    assert len(path.breakpoints) == 1
    b = path.breakpoints[0]
    np.testing.assert_allclose(b["at"], dstar, rtol=1e-9)
    assert b["before"] == [0, 1, 2, 3] and b["lifts_off"] == [2] and b["comes_into_contact"] == []
    # on the first piece the twist: R_C = q a²/4 − 2 D (1 − ν) δ / a²
    k = 2 * D * (1 - NU) / A**2
    np.testing.assert_allclose(path.reactions(0.5 * dstar), q * A * A / 4 + k * 0.5 * dstar * np.array([-1, 1, -1, 1]),
                               rtol=1e-10)
    # beyond: the plate rests on B–D (R = q a²/2 each), C's gap opens one for one
    np.testing.assert_allclose(path.reactions(2 * dstar), [0, q * A * A / 2, 0, q * A * A / 2], atol=1e-10 * q)
    np.testing.assert_allclose(path.gaps(2 * dstar)[2], dstar, rtol=1e-9)
    assert not path.pieces[-1]["unique"]  # it may rock about B–D: the reactions are unique, w is not


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("param", ["supports.4.gap", "loads.1.P", "supports.*.gap"])
def test_path_matches_pointwise_solves(seed, param):
    scene = random_scene(seed)
    W = 0.01 / scene.plate.D
    lo, hi = {"supports.4.gap": (-W, W), "loads.1.P": (0.0, 20.0), "supports.*.gap": (-0.5 * W, 0.5 * W)}[param]
    path = exact_path(scene, param, lo, hi)
    ts = np.linspace(lo, hi, 13)
    ts = np.concatenate([ts, [b["at"] for b in path.breakpoints]])
    for t in ts:
        r = solve(set_param(scene, param, float(t)))
        Rs = np.abs(r.reactions).max()
        np.testing.assert_allclose(path.reactions(t), r.reactions, atol=1e-8 * Rs)
        np.testing.assert_allclose(path.gaps(t), r.gaps, atol=1e-8 * W)
        np.testing.assert_allclose(path.deflections(t), r.model.contacts.B @ r.u[r.model.free] + r.model.contacts.shift,
                                   atol=1e-8 * W)


@pytest.mark.parametrize("seed, param", [(1, "supports.4.gap"), (3, "supports.4.gap"), (3, "loads.1.P"),
                                         (5, "loads.1.P"), (3, "supports.*.gap")])
def test_path_matches_bisection(seed, param):
    scene = random_scene(seed)
    W = 0.01 / scene.plate.D
    lo, hi = {"supports.4.gap": (-W, W), "loads.1.P": (0.0, 20.0), "supports.*.gap": (-0.5 * W, 0.5 * W)}[param]
    values = list(np.linspace(lo, hi, 7))
    rtol = 1e-7
    bis = sweep(scene, param, values, backend="lemke", accuracy="high", executor="serial", progress=False, rtol=rtol)
    path = exact_path(scene, param, lo, hi)
    assert bis.breakpoints, "the scene was chosen for its breakpoints"
    assert len(path.breakpoints) == len(bis.breakpoints)
    for b, e in zip(bis.breakpoints, path.breakpoints):
        x1, x2 = sorted(b["bracket"])
        slack = 2 * rtol * max(abs(x1), abs(x2), 1e-3 * max(abs(lo), abs(hi)))
        assert x1 - slack <= e["at"] <= x2 + slack
        assert (b["before"], b["after"]) == (e["before"], e["after"])


def test_prescribed_displacement_is_linear():
    scene = random_scene(1)  # held by a simple left edge
    n = scene.mesh.nx
    scene.supports.append(pq.Support(0.5 / n, 0.37, gap=0.0))  # off the nodes, next to the moving edge
    scene.validate()
    path = exact_path(scene, "edges.left.w", 0.0, 1e-4)
    for t in (2e-5, 5e-5, 1e-4):
        r = solve(set_param(scene, "edges.left.w", t))
        np.testing.assert_allclose(path.reactions(t), r.reactions, atol=1e-8 * np.abs(r.reactions).max())
        w = np.array([r.deflection(s.x, s.y) for s in scene.supports])  # through the element, edge included
        np.testing.assert_allclose(path.deflections(t), w, atol=1e-8 * np.abs(w).max())


@pytest.mark.parametrize("param, values, what", [
    ("supports.1.stiffness", (1e3, 1e4), "flexibility 1/c"),
    ("foundation.k", (1e3, 1e4), "flexibility 1/c"),
    ("plate.h", (0.01, 0.02), "stiffness matrix"),
    ("mesh.nx", (4, 8), "mesh"),
    ("loads.1.x", (0.3, 0.7), "affine"),  # a point load moving: K stays, f is not affine in x
])
def test_refuses_parameters_that_are_not_linear(param, values, what):
    scene = random_scene(1)
    if param.startswith("foundation"):
        scene.foundation = pq.Foundation(k=1e3, region=[0.5, 1.0, 0.0, 1.0])
        scene.validate()
    with pytest.raises(pq.ProblemError, match=f"not enter the problem linearly.*{what}"):
        exact_path(scene, param, *values)


def test_exact_sweep_needs_monotone_values():
    with pytest.raises(pq.ProblemError, match="increasing or decreasing"):
        exact_sweep(corners(), "supports.3.gap", [0.0, 0.02, 0.01], executor="serial", progress=False)


def test_cli_sweep_exact(tmp_path, capsys):
    from plateqp.cli import main

    scene = corners(4)
    path = tmp_path / "corners.toml"
    scene.to_toml(path)
    dstar = A**4 / (8 * scene.plate.D * (1 - NU))
    argv = ["sweep", str(path), "--param", "supports.3.gap", "--values", f"0,{dstar / 2},{1.5 * dstar},{2 * dstar}",
            "--workers", "1", "--json"]
    assert main(argv + ["--exact"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["method"] == "exact" and len(d["breakpoints"]) == 1
    np.testing.assert_allclose(d["breakpoints"][0]["at"], dstar, rtol=1e-9)
    assert d["breakpoints"][0]["between"] == [dstar / 2, 1.5 * dstar]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["method"] == "bisection"
    assert main(["sweep", str(path), "--param", "supports.3.stiffness", "--values", "1e3,1e4", "--exact"]) == 2
    err = capsys.readouterr().err
    assert "linearly" in err and len(err.strip().splitlines()) == 1


def test_step_limit_is_an_error():
    with pytest.raises(pq.ProblemError, match="more than 1 pieces"):
        exact_path(corners(4), "supports.3.gap", 0.0, 0.05, max_pieces=1)
