"""Hostile soils, hunted with hypothesis: a Winkler, Pasternak or half-space bed whose model and
parameters are edited into anything, solved by ``plateqp solve`` and through the Python API.

The promises (as in tests/contact/test_fuzz.py): the command ends with an exit code in
{0, 2, 3, 4, 5}, never a traceback, a failure one line on stderr; ``Scene`` raises SceneError
and nothing else. And never a wrong OPTIMAL: an answer called optimal has the reactions of an
independent solve (BPP on the condensed problem, another method on another formulation) to the
accuracy asked.
"""

from __future__ import annotations

import json
import os
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import plateqp as pq  # noqa: E402

from test_fuzz import check, run  # noqa: E402  (the same promises, the same runner)

EXAMPLES = int(os.environ.get("PLATEQP_FUZZ_EXAMPLES", "120"))
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize="PLATEQP_FUZZ_EXAMPLES" not in os.environ,
                database=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

PLATE = dict(a=2.0, b=1.0, h=0.02, E=1.0e7, nu=0.3)
SOILS = {"winkler": {"k": 50.0}, "pasternak": {"k": 50.0, "shear": 5.0}, "halfspace": {"E": 200.0, "nu": 0.3}}
KEYS = ["model", "k", "shear", "E", "nu", "gap", "region"]
VALUES = st.one_of(
    st.sampled_from(["winkler", "pasternak", "halfspace", "Winkler", "", "kerr"]),
    st.floats(allow_nan=True, allow_infinity=True), st.integers(min_value=-10**6, max_value=10**6),
    st.sampled_from([0.5, 0.49999, -0.99, -1.0, 0.0, 1e-300, 1e300, 1e-3, 10.0, 1e4]),
    st.booleans(), st.lists(st.floats(-1, 3), max_size=4), st.text(max_size=5),
)


def scene_dict(soil: str, edits) -> dict:
    found = {"model": soil, **SOILS[soil], "gap": {"profile": "linear", "g0": -0.001, "gx": 0.002, "gy": 0.0}}
    for key, value in edits:
        found[key] = value
    return {"name": "soil-fuzz", "plate": dict(PLATE), "mesh": {"nx": 6, "ny": 4, "element": "acm"},
            "edges": {"left": "simple"}, "loads": [{"type": "uniform", "q": 1.0}, {"type": "point", "P": 2.0, "x": 1.5, "y": 0.5}],
            "foundation": found}


@FUZZ
@given(st.sampled_from(list(SOILS)), st.lists(st.tuples(st.sampled_from(KEYS), VALUES), max_size=3),
       st.sampled_from(["auto", "pdas", "bpp", "lemke", "clarabel"]), st.sampled_from(["auto", "primal", "condensed", "dual"]))
def test_a_hostile_soil_gives_an_answer_or_one_line(soil, edits, backend, formulation):
    import tomli_w

    try:
        text = tomli_w.dumps(scene_dict(soil, edits))
    except (TypeError, ValueError):
        return
    if backend not in ("auto", *pq.available_backends()):
        backend = "auto"
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.toml"
        path.write_text(text, encoding="utf-8")
        code, out, err = run(path, "--backend", backend, "--formulation", formulation)
    check(code, out, err)
    if code != 0 or json.loads(out)["status"] != "optimal":
        return
    # an optimal answer is the independent solve's
    import tomllib

    sc = pq.Scene.from_dict(tomllib.loads(text))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = pq.solve(sc, backend="bpp", formulation="condensed", accuracy=1e-10)
    R = np.asarray(json.loads(out)["reactions"], dtype=float)
    scale = max(np.abs(ref.reactions).max(), 1e-12)
    assert np.abs(R - ref.reactions).max() <= 1e-4 * scale, (soil, edits, backend, formulation)


@FUZZ
@given(st.sampled_from(list(SOILS)), st.lists(st.tuples(st.sampled_from(KEYS), VALUES), min_size=1, max_size=3))
def test_a_hostile_soil_in_python_is_a_scene_error_or_a_scene(soil, edits):
    d = scene_dict(soil, edits)
    try:
        sc = pq.Scene.from_dict(d)
    except pq.SceneError as exn:
        assert "\n" not in str(exn).strip()
        return
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            pq.solve(sc)
    except pq.PlateQPError as exn:
        assert str(exn)
