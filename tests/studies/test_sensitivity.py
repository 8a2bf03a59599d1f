"""Exact sensitivities (plateqp.sensitivity) against external references.

- Closed form: a free square plate on four rigid corner supports under a uniform load stays in
  contact at all four; settling one corner by δ twists the plate, w = δ x y / a² (an exact
  state of the plate: Mxy = −D(1 − ν) δ / a² everywhere, and both elements hold x y exactly), so
  the corner forces change by 2 Mxy: dR_A/dg0_C = −2 D (1 − ν) / a², with the pattern (±) of
  the twist at all four corners (Timoshenko & Woinowsky-Krieger, Theory of plates and shells,
  §"pure bending" / corner forces 2 Mxy).
- Statics: the derivatives of the reactions carry no load: Σ_i dR_i/dp = 0 and no moment, for
  a floating plate (the load does not change with a gap).
- Finite differences on small random scenes (fixed seeds; lemke on the condensed problem and
  pdas on the primal, both exact), with the step small enough that the contact set does not
  change: gaps and loads enter linearly, so central differences are exact up to rounding.
"""

from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.paths import set_param

A = 1.0
NU = 0.3


def corners(nx=4, element="acm", gaps=(0.0, 0.0, 0.0, 0.0), q=1.0, stiffness="rigid", b=A):
    pts = [(0.0, 0.0), (A, 0.0), (A, b), (0.0, b)]
    return pq.Scene(name="corners", plate=pq.Plate(a=A, b=b, h=0.02, E=1.0e7, nu=NU),
                    mesh=pq.MeshSpec(nx, nx, element), loads=[pq.UniformLoad(q=q)],
                    supports=[pq.Support(x, y, gap=g, stiffness=stiffness) for (x, y), g in zip(pts, gaps)])


def solve(scene, backend="lemke", **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene, backend=backend, accuracy="high", **kw)


@pytest.mark.parametrize("element, nx", [("acm", 4), ("acm", 8), ("bfs", 4)])
def test_corner_twist_closed_form(element, nx):
    scene = corners(nx, element)
    r = solve(scene)
    S = pq.sensitivity(r, "gaps")
    D = scene.plate.D
    k = 2 * D * (1 - NU) / A**2
    # corners A(0,0) B(a,0) C(a,a) D(0,a): the twist loads the diagonal pair together
    pattern = np.array([[-1, 1, -1, 1], [1, -1, 1, -1], [-1, 1, -1, 1], [1, -1, 1, -1]], dtype=float)
    assert S.shape == (4, 4)
    np.testing.assert_allclose(S[0, 2], -k, rtol=1e-9)
    np.testing.assert_allclose(np.asarray(S), k * pattern, rtol=1e-9, atol=1e-9 * k)
    # deflections at the held supports follow their gaps exactly; w = δ x y / a² inside
    np.testing.assert_allclose(S.deflections, np.eye(4), atol=1e-12)
    np.testing.assert_allclose(S.deflection([0.5, 0.25], [0.5, 0.75])[:, 2], [0.25, 0.1875], rtol=1e-9)


def test_statics_of_gap_derivatives():
    scene = corners(8, gaps=(0.0, 0.0, 0.0, 0.0))
    scene.supports.append(pq.Support(0.5, 0.5, gap=-1e-4))
    scene.supports.append(pq.Support(0.25, 0.75, gap=1e-5, stiffness=1e4))
    scene.validate()
    r = solve(scene)
    S = np.asarray(pq.sensitivity(r, "gaps"))
    xy = r.model.contacts.xy
    scale = np.abs(S).max()
    np.testing.assert_allclose(S.sum(axis=0), 0.0, atol=1e-11 * scale)
    np.testing.assert_allclose(xy[:, 0] @ S, 0.0, atol=1e-11 * scale)
    np.testing.assert_allclose(xy[:, 1] @ S, 0.0, atol=1e-11 * scale)
    # an open support carries nothing and changes nothing (its column and row are zero)
    open_ = ~r.active
    assert np.all(S[open_] == 0.0) and np.all(S[:, open_] == 0.0)
    # and load factors: the derivative of the reactions carries the load
    L = pq.sensitivity(r, "loads")
    np.testing.assert_allclose(L.reactions.sum(axis=0), [scene.loads[0].q * A * A], rtol=1e-10)


def random_scene(seed: int) -> pq.Scene:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 7))
    floating = seed % 2 == 0
    edges = {} if floating else {"left": "simple"}
    D = pq.Plate(h=0.02, E=1e7).D
    W = 0.01 / D  # deflection per unit load
    pts = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] if floating else []
    while len(pts) < 7:
        p = (int(rng.integers(0, n + 1)) / n, int(rng.integers(0, n + 1)) / n)
        if p not in pts and not (not floating and p[0] == 0.0):
            pts.append(p)
    sup = [pq.Support(x, y, gap=float(rng.uniform(-0.5, 0.5)) * W,
                      stiffness="rigid" if rng.random() < 0.6 else float(10 ** rng.uniform(3, 5)))
           for x, y in pts]
    loads = [pq.UniformLoad(float(rng.uniform(0.5, 2.0))),
             pq.PointLoad(float(rng.uniform(0.5, 2.0)), float(rng.uniform(0.3, 0.7)), float(rng.uniform(0.3, 0.7)))]
    return pq.Scene(name=f"sens-{seed}", plate=pq.Plate(h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(n, n),
                    edges=edges, loads=loads, supports=sup)


#: (seed, backend, formulation): held (odd seeds) and floating (even seeds) scenes on both.
ROUTES = [(s, "lemke", "condensed") for s in range(4)] + [(s, "pdas", "primal") for s in range(6)]


def _fd(scene, path, value, h, base_active, backend, formulation):
    out = []
    for s in (+1, -1):
        r = solve(set_param(scene, path, value + s * h), backend=backend, formulation=formulation)
        if not np.array_equal(r.active, base_active):
            return None
        out.append(r)
    return (out[0].reactions - out[1].reactions) / (2 * h), (out[0].gaps - out[1].gaps) / (2 * h)


@pytest.mark.parametrize("seed, backend, formulation", ROUTES)
def test_gaps_and_loads_against_finite_differences(seed, backend, formulation):
    scene = random_scene(seed)
    r = solve(scene, backend=backend, formulation=formulation)
    Sg = pq.sensitivity(r, "gaps")
    Sl = pq.sensitivity(r, "loads")
    W = 0.01 / scene.plate.D
    checked = 0
    for j, sup in enumerate(scene.supports):
        fd = _fd(scene, f"supports.{j + 1}.gap", sup.gap, 1e-4 * W, r.active, backend, formulation)
        if fd is None:
            continue
        scale = np.abs(Sg.reactions).max()
        np.testing.assert_allclose(Sg.reactions[:, j], fd[0], atol=1e-6 * scale)
        np.testing.assert_allclose(Sg.gaps[:, j], fd[1], atol=1e-6)
        checked += 1
    for j, ld in enumerate(scene.loads):
        key = "q" if isinstance(ld, pq.UniformLoad) else "P"
        v = getattr(ld, key)
        fd = _fd(scene, f"loads.{j}.{key}", v, 1e-4 * v, r.active, backend, formulation)
        assert fd is not None
        scale = np.abs(Sl.reactions).max()
        np.testing.assert_allclose(Sl.reactions[:, j] / v, fd[0], atol=1e-6 * scale / v)
        np.testing.assert_allclose(Sl.gaps[:, j] / v, fd[1], atol=1e-6 * W)
        checked += 1
    assert checked >= 4


@pytest.mark.parametrize("seed", range(4))
def test_stiffness_against_finite_differences(seed):
    scene = random_scene(seed)
    r = solve(scene)
    S = pq.sensitivity(r, "stiffness")
    elastic = [j for j, s in enumerate(scene.supports) if not s.rigid]
    assert S.labels == [f"supports.{j + 1}.stiffness" for j in elastic]
    for col, j in enumerate(elastic):
        c = scene.supports[j].stiffness
        fd = _fd(scene, f"supports.{j + 1}.stiffness", c, 1e-4 * c, r.active, "lemke", "condensed")
        assert fd is not None
        scale = np.abs(S.reactions).max() * c
        np.testing.assert_allclose(S.reactions[:, col] * c, fd[0] * c, atol=1e-6 * max(scale, 1e-300) + 1e-12)


def test_bed_stiffness_against_finite_differences():
    scene = corners(4)
    scene.foundation = pq.Foundation(k=2e3, region=[0.25, 0.5, 0.25, 0.75], gap=1e-5)
    scene.validate()
    r = solve(scene)
    S = pq.sensitivity(r, "stiffness")
    assert S.labels == ["foundation.k"]
    fd = _fd(scene, "foundation.k", 2e3, 0.2, r.active, "lemke", "condensed")
    assert fd is not None and np.any(r.reactions[4:] > 0)
    np.testing.assert_allclose(S.reactions[:, 0], fd[0], atol=1e-6 * np.abs(fd[0]).max())


def test_one_sided_derivatives_at_lift_off():
    """Corner C settled exactly to lift-off, δ* = q a⁴ / (8 D (1 − ν)): there the plate rests on
    the diagonal B–D, A and C touch without force (both degenerate). Below δ* all four carry
    load and the twist stiffness holds; above it C opens one for one and A stays touching with
    no force (the plate rests on A, B, D with the load's resultant on B–D)."""
    q = 1.0
    D = corners().plate.D
    dstar = q * A**4 / (8 * D * (1 - NU))
    r = solve(corners(4, gaps=(0.0, 0.0, dstar, 0.0), q=q))
    S = pq.sensitivity(r, "gaps", tol=1e-8)
    assert list(S.degenerate) == [0, 2]
    k = 2 * D * (1 - NU) / A**2
    np.testing.assert_allclose(S.decreasing.reactions[:, 2], k * np.array([-1, 1, -1, 1]), rtol=1e-8)
    np.testing.assert_allclose(S.increasing.reactions[:, 2], 0.0, atol=1e-9 * k)
    # settling C further the plate may rock about B–D between A and C: its deflection is not
    # unique on that side (NaN), its reactions are; below δ* everything is unique
    assert not S.increasing.unique[2] and np.all(np.isnan(S.increasing.gaps[:, 2]))
    np.testing.assert_allclose(S.decreasing.deflections[:, 2], [0, 0, 1, 0], atol=1e-12)
    # settling B loads A and C again (all four in contact, twist); raising B would lift A and C
    # and leave the plate rocking on B–D (not unique)
    np.testing.assert_allclose(S.increasing.reactions[:, 1], k * np.array([1, -1, 1, -1]), rtol=1e-8)
    assert list(S.decreasing.unique) == [True, False, True, False]
    assert S.kinked[2] and not S.smooth
    with pytest.raises(pq.ProblemError, match="lift-off"):
        np.asarray(S)
    d = S.to_dict()
    assert "increasing" in d and "decreasing" in d and d["degenerate"] == [1, 3]  # JSON: numbered from 1


def test_errors():
    two_sided = pq.Scene(name="t", edges={"left": "clamped"}, loads=[pq.UniformLoad(1.0)], mesh=pq.MeshSpec(4, 4))
    with pytest.raises(pq.ProblemError, match="no contact solution"):
        pq.sensitivity(pq.solve(two_sided), "gaps")
    r = solve(corners())
    with pytest.raises(pq.ProblemError, match="unknown wrt"):
        pq.sensitivity(r, "thickness")
    with pytest.raises(pq.ProblemError, match="two-sided comparison"):
        pq.sensitivity(pq.solve_bilateral(corners()), "gaps")
    # a floating plate resting on two supports with the load on their line, the other two open:
    # it may rock about that line (the deflection is not unique)
    line = pq.Scene(name="line", mesh=pq.MeshSpec(4, 4), loads=[pq.PointLoad(1.0, 0.5, 0.5)],
                    supports=[pq.Support(0.0, 0.5), pq.Support(1.0, 0.5), pq.Support(0.5, 0.0, gap=0.1),
                              pq.Support(0.5, 1.0, gap=0.1)])
    with pytest.raises(pq.MechanismError, match="not unique"):
        pq.sensitivity(solve(line), "gaps")
    # the same plate answered level on three collinear supports, the other two open: the contact
    # set leaves the rotation about their line free (the answer a solver may give; not unique)
    three = pq.Scene(name="three", mesh=pq.MeshSpec(4, 4), loads=[pq.PointLoad(1.0, 0.25, 0.5)],
                     supports=[pq.Support(0.0, 0.5), pq.Support(0.5, 0.5), pq.Support(1.0, 0.5),
                               pq.Support(0.5, 0.0, gap=0.1), pq.Support(0.5, 1.0, gap=0.1)])
    r = solve(three)
    level = dataclasses.replace(r, gaps=np.array([0.0, 0.0, 0.0, 0.1, 0.1]),
                                reactions=np.array([0.5, 0.5, 1e-3, 0.0, 0.0]))  # all three held
    with pytest.raises(pq.MechanismError, match="rigid motion"):
        pq.sensitivity(level, "gaps")


def test_cli_sensitivity(tmp_path, capsys):
    from plateqp.cli import main

    path = tmp_path / "corners.toml"
    corners().to_toml(path)
    assert main(["solve", str(path), "--backend", "lemke", "--json", "--sensitivity"]) == 0
    d = json.loads(capsys.readouterr().out)
    k = 2 * corners().plate.D * (1 - NU) / A**2
    np.testing.assert_allclose(d["sensitivity"]["reactions"][0][2], -k, rtol=1e-9)
    assert d["sensitivity"]["parameters"][2] == "supports.3.gap" and d["sensitivity"]["smooth"]
    two_sided = pq.Scene(name="t", edges={"left": "clamped"}, loads=[pq.UniformLoad(1.0)], mesh=pq.MeshSpec(4, 4))
    two_sided.to_toml(tmp_path / "t.toml")
    assert main(["solve", str(tmp_path / "t.toml"), "--sensitivity"]) == 2
    err = capsys.readouterr().err
    assert "--sensitivity" in err and len(err.strip().splitlines()) == 1
