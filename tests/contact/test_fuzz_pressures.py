"""The matrix-free half-space route hunted with hypothesis: plates held or floating, beds over the
whole plate or part of it, heave and settlement, posts beside the soil. The promises: an answer
or one of plateqp's own errors, never a traceback; and never a wrong OPTIMAL: an answer called
optimal has the reactions of the soil-unknowns route (the dense H_F⁻¹ in K, solved by the default
route) to the accuracy asked."""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import plateqp as pq  # noqa: E402
from plateqp.model.assembly import build_model  # noqa: E402

EXAMPLES = int(os.environ.get("PLATEQP_FUZZ_EXAMPLES", "40"))
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize="PLATEQP_FUZZ_EXAMPLES" not in os.environ,
                database=None, suppress_health_check=[HealthCheck.too_slow])

EDGES = [{}, {"left": "simple"}, {"left": "clamped", "right": "simple"}, {"all": "simple"}]
REGIONS = [None, [0.0, 1.4, 0.0, 1.0], {"circle": [1.0, 0.5, 0.45]}, {"polygon": [[0, 0], [2, 0], [0, 1]]}]
GAPS = [0.0, -2e-4, 3e-4, {"profile": "linear", "g0": -1e-4, "gx": 2e-4, "gy": 0.0}]


@FUZZ
@given(st.integers(3, 9), st.sampled_from(range(len(EDGES))), st.sampled_from(range(len(REGIONS))),
       st.sampled_from(range(len(GAPS))), st.floats(0.05, 1.95), st.floats(0.05, 0.95),
       st.sampled_from([1e5, 1e7, 1e9]), st.sampled_from([0.0, 0.3, 0.5]),
       st.lists(st.tuples(st.floats(0, 2), st.floats(0, 1), st.sampled_from(["rigid", 1e5]), st.floats(-1e-4, 1e-4)),
                max_size=2))
def test_the_matrix_free_route_answers_as_the_soil_unknowns_route(n, edges, region, gap, x, y, E, nu, posts):
    fnd = dict(model="halfspace", E=E, nu=nu, gap=GAPS[gap])
    if REGIONS[region] is not None:
        fnd["region"] = REGIONS[region]
    try:
        scene = pq.Scene(plate=pq.Plate(a=2.0, b=1.0, h=0.05, E=3e10, nu=0.2), mesh=pq.MeshSpec(nx=2 * n, ny=n),
                         edges=EDGES[edges], loads=[pq.PointLoad(P=1e4, x=x, y=y), pq.UniformLoad(1e3)],
                         supports=[pq.Support(px, py, gap=g, stiffness=k) for px, py, k, g in posts],
                         foundation=pq.Foundation(**fnd))
    except pq.SceneError as exn:
        assert "\n" not in str(exn).strip()
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            res = pq.solve(scene, model=build_model(scene, soil_operator=True), accuracy=1e-8)
        except pq.PlateQPError as exn:
            assert str(exn) and "\n" not in str(exn).strip()
            return
        assert res.model.soil_flexibility is not None
        if res.status != pq.Status.OPTIMAL:
            return
        # (1e-9: a plate on the soil moves as a body, and the condensed route's reactions carry
        # K u's rounding along that motion, up to 2e-10 of the load here)
        ref = pq.solve(scene, model=build_model(scene, soil_operator=False), accuracy=1e-9)
    if ref.status != pq.Status.OPTIMAL:
        return
    scale = max(np.abs(ref.reactions).max(), 1e-12)
    assert np.abs(res.reactions - ref.reactions).max() <= 1e-5 * scale
    assert res.kkt.ok
