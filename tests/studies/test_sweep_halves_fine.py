"""A spring-stiffness sweep at 128² (30 × 30 elastic posts) pays one triangular half of K's
factor per value after the first, as at 24² (test_sweep_halves.py): there the reactions settle
on the trailing unknowns at a gap residual of 2–4 ε of its terms, the error of evaluating it
(γ_{L+2}, Higham), and the one backward half that gives the deflection is the last. Each value
is the cold solve's, to rounding."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.paths import set_param
from plateqp.scenes.families import grid_elastic

from test_sweep_halves import ACC, halves, run  # noqa: F401  (halves: the counting fixture)

pytestmark = pytest.mark.skipif(not pq.linalg.bindings(), reason="no CHOLMOD binding")


def test_a_fine_stiffness_sweep_pays_one_half_per_value(halves):  # noqa: F811
    scene = grid_elastic(128, 30)
    path, values = "supports.*.stiffness", [1e6, 1.6e6, 2.5e6, 4e6]
    run(scene, path, values[:1])
    before = halves["n"]
    halves["n"] = 0
    res = run(scene, path, values)
    assert all(r["status"] == "optimal" for r in res.rows)
    per_value = (halves["n"] - before) / (len(values) - 1)
    assert per_value <= 1.0, f"{per_value} halves of K's factor per value after the first"
    for v, row in zip(values[1:], res.rows[1:]):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pq.PlateQPWarning)
            cold = pq.solve(set_param(scene, path, v), backend="pdas", accuracy=ACC)
        R, Rc = np.array(row["reactions"]), cold.reactions
        assert np.abs(R - Rc).max() <= 1e-10 * np.abs(Rc).max(), f"{path} = {v}: reactions off the cold solve's"
        assert row["active"] == [bool(a) for a in cold.active]
