"""Sweeps that change the loads on a triangle mesh re-use the model: the load vector
is re-assembled on the same mesh. Checked against fresh builds, the closed form of a simply
supported disc on a central one-sided support, and a moved point load (a new mesh)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.model.paths import set_param
from plateqp.studies import sweep
from plateqp.studies.reuse import adapt_model

pytest.importorskip("gmsh")

R, NU = 1.0, 0.3


def disc(**kw) -> pq.Scene:
    return pq.Scene(name="disc", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.01, E=1.0e7, nu=NU),
                    mesh=pq.MeshSpec(element="dkt", size=R / 8), edges={"all": pq.Edge("simple")}, **kw)


D = disc().plate.D
W_PER_Q = (5 + NU) * R**4 / (64 * (1 + NU) * D)  # centre deflection per unit q, simply supported
ALPHA = (3 + NU) * R**2 / (16 * math.pi * (1 + NU) * D)  # centre deflection per unit central force
G0 = 1e-3


def test_load_sweep_on_a_disc_matches_fresh_builds_and_the_closed_form():
    sc = disc(loads=[pq.UniformLoad(1.0)], supports=[pq.Support(0.0, 0.0, gap=G0)])
    q_star = G0 / W_PER_Q  # the load at which the plate reaches the support
    values = [0.5 * q_star, 2.0 * q_star, 4.0 * q_star]
    res = sweep(sc, "loads.0.q", values, progress=False, executor="serial", rtol=1e-6)
    for q, row in zip(values, res.rows):
        assert row["error"] is None and row["status"] == "optimal"
        fresh = pq.solve(set_param(sc, "loads.0.q", q), accuracy="high")  # a new mesh and assembly
        np.testing.assert_allclose(row["reactions"], fresh.reactions, rtol=1e-8, atol=1e-10 * q)
        exact = max(0.0, (W_PER_Q * q - G0) / ALPHA)  # superposition (Timoshenko §§ 16-19)
        assert row["reactions"][0] == pytest.approx(exact, rel=0.02, abs=1e-9 * q)
    (bp,) = res.breakpoints
    assert bp["at"] == pytest.approx(q_star, rel=0.01)  # the discretisation error of w_q at R/8


def test_a_moved_point_load_gets_a_new_mesh():
    sc = disc(loads=[pq.PointLoad(1.0, 0.2, 0.1)], supports=[pq.Support(0.0, 0.0, gap=0.0)])
    base = build_model(sc)
    assert adapt_model(base, set_param(sc, "loads.0.P", 2.0)) is not None  # same nodes: re-used
    assert adapt_model(base, set_param(sc, "loads.0.x", 0.3)) is None  # the load's node moves
    res = sweep(sc, "loads.0.x", [0.2, 0.3], progress=False, executor="serial", refine_breakpoints=False)
    for x, row in zip([0.2, 0.3], res.rows):
        fresh = pq.solve(set_param(sc, "loads.0.x", x))
        np.testing.assert_allclose(row["reactions"], fresh.reactions, rtol=1e-9)
