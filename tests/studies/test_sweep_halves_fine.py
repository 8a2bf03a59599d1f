"""A spring-stiffness sweep at 128² (30 × 30 elastic posts) pays one triangular half of K's
factor per value after the first, as at 24² (test_sweep_halves.py): there the reactions settle
on the trailing unknowns at a gap residual of 2–4 ε of its terms, the error of evaluating it
(γ_{L+2}, Higham), and the one backward half that gives the deflection is the last. Each value
is the cold solve's, to rounding."""

from __future__ import annotations

import pytest

import plateqp as pq
from plateqp.scenes.families import grid_elastic

from test_sweep_halves import assert_cold, halves, halves_per_value  # noqa: F401  (halves: the counting fixture)

pytestmark = pytest.mark.skipif(not pq.linalg.bindings(), reason="no CHOLMOD binding")


def test_a_fine_stiffness_sweep_pays_one_half_per_value(halves):  # noqa: F811
    scene = grid_elastic(128, 30)
    path, values = "supports.*.stiffness", [1e6, 1.6e6, 2.5e6, 4e6]
    res, per_value = halves_per_value(scene, path, values, 1, halves)
    assert per_value <= 1.0, f"{per_value} halves of K's factor per value after the first"
    assert_cold(scene, path, values[1:], res.rows[1:], 1e-10)
