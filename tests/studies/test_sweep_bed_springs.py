"""A sweep of a tensionless bed's modulus changes every spring under the plate: the factor kept
from the value before (of the springs before) preconditions the Newton steps that find the new
contact set, and the exact steps factorise once, for the set they settle on: one numeric
factorisation per value after the first, not one for the warm start's set and another for the
final one. Every value is the cold solve's, to rounding, and passes the KKT check."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.paths import set_param
from plateqp.studies.sweep import sweep

from test_sweep_factor_reuse import bed  # one bed scene; the counting fixture is conftest.py's

pytestmark = pytest.mark.skipif(not pq.linalg.bindings(), reason="no CHOLMOD binding")

ACC = 1e-10
VALUES = list(np.geomspace(1.0e4, 4.0e4, 6))


def run(scene, values):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return sweep(scene, "foundation.k", values, backend="pdas", accuracy=ACC, executor="serial", progress=False,
                     refine_breakpoints=False)


def test_one_factorisation_per_modulus(factorisations):
    scene = bed(24)
    run(scene, VALUES[:1])
    one = factorisations["n"]
    factorisations["n"] = 0
    res = run(scene, VALUES)
    assert all(r["status"] == "optimal" for r in res.rows)
    assert len({tuple(r["active"]) for r in res.rows}) > 1  # the contact set moves with the modulus
    per_value = (factorisations["n"] - one) / (len(VALUES) - 1)
    assert per_value <= 1.0, f"{per_value} factorisations per value after the first"


def test_each_modulus_is_the_cold_solve():
    scene = bed(24)
    hot = run(scene, VALUES)
    for v, row in zip(VALUES, hot.rows):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pq.PlateQPWarning)
            cold = pq.solve(set_param(scene, "foundation.k", v), backend="pdas", accuracy=ACC)
        assert row["status"] == "optimal" and row["kkt_worst"] <= ACC
        assert row["active"] == [bool(a) for a in cold.active]
        R, Rc = np.array(row["reactions"]), cold.reactions
        assert np.abs(R - Rc).max() <= 1e-10 * np.abs(Rc).max()
        assert row["w_max"] == pytest.approx(float(cold.to_dict()["w_max"]), rel=1e-10)
