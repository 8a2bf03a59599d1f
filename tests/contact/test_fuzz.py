"""Hostile input, hunted with hypothesis: raw bytes, corrupted TOML and structured-but-wrong scenes
through ``Scene.from_toml`` and ``plateqp solve``.

The promises (README, "Command line"): whatever the file holds, the command ends with an exit code
in {0, 2, 3, 4, 5} (never 1, an internal error, and never a traceback), a failure is one line on
stderr that starts with "plateqp:", and with ``--json`` standard output parses as JSON whenever
a result was computed. ``Scene.from_toml`` raises SceneError and nothing else.

The Python API has the same promise: hostile values on a scene's parts (before or after its
construction) and in a Result's methods' arguments give a scene and a solve, or a PlateQPError.

The budget is bounded (``FUZZ_EXAMPLES`` examples per strategy, about a minute in all on two cores);
``PLATEQP_FUZZ_EXAMPLES=2000 pytest tests/contact/test_fuzz.py`` hunts longer.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import tempfile
import warnings
from pathlib import Path

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import plateqp as pq  # noqa: E402
from plateqp.cli import main  # noqa: E402

FUZZ_EXAMPLES = int(os.environ.get("PLATEQP_FUZZ_EXAMPLES", "400"))
# the default run is the same every time (CI); a longer hunt (the variable set) draws new examples
FUZZ = settings(max_examples=FUZZ_EXAMPLES, deadline=None, derandomize="PLATEQP_FUZZ_EXAMPLES" not in os.environ,
                database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

BASE = """\
name = "fuzz"

[plate]
a = 2.0
b = 1.0
h = 0.02
E = 1.0e7
nu = 0.3

[mesh]
nx = 6
ny = 4
element = "acm"

[edges]
left = "simple"

[[openings]]
x0 = 1.5
x1 = 2.0
y0 = 0.75
y1 = 1.0

[[pins]]
x = 0.0
y = 0.0

[[loads]]
type = "uniform"
q = 1.0

[[loads]]
type = "point"
P = 3.0
x = 1.2
y = 0.4

[[supports]]
x = 2.0
y = 0.0
gap = -0.001

[[supports]]
x = 1.0
y = 1.0
gap = 0.0
stiffness = 500.0

[foundation]
k = 50.0
region = [0.0, 1.0, 0.0, 1.0]
gap = { profile = "trough", x = 0.5, y = 0.5, radius = 0.3, depth = 0.001 }
"""

#: Values a hostile user puts where a number, string or table belongs.
HOSTILE = ["nan", "inf", "-inf", "0", "-0.0", "1e308", "-1e308", "1e-320", "5e-324", "1e120", "1e-120",
           "100000000000000000000000", "-3", "[]", "[1, 2]", "{}", "{ a = 1 }", '"x"', '""', "true",
           "2000", "1.5", '"rigid"', '"clamped"', "[[1]]", '"\\u0000"', "0.49999999", "-0.99999"]


def run(path: Path, *extra: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["solve", str(path), "--json", *extra])
    return code, out.getvalue(), err.getvalue()


def check(code: int, out: str, err: str) -> None:
    assert code in (0, 2, 3, 4, 5), (code, err)
    assert "Traceback" not in err, err
    if code in (2, 3, 4):
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("plateqp: "), err
    if code in (0, 5):
        d = json.loads(out)  # JSON alone on stdout
        assert d["status"] in {s.value for s in pq.Status}


def solve_text(data: bytes | str, *extra: str) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.toml"
        if isinstance(data, str):
            path.write_text(data, encoding="utf-8")
        else:
            path.write_bytes(data)
        try:
            pq.Scene.from_toml(path)
        except pq.SceneError as exn:
            assert "\n" not in str(exn).strip()
        check(*run(path, *extra))


def test_base_scene_solves():
    """The fuzzed scene itself is valid and solves (the mutations start from a working scene)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.toml"
        path.write_text(BASE)
        code, out, err = run(path)
    assert code == 0, err
    assert json.loads(out)["status"] == "optimal"


@FUZZ
@given(st.binary(max_size=3000))
def test_raw_bytes(data):
    solve_text(data)


@FUZZ
@given(st.data())
def test_corrupted_toml(data):
    lines = BASE.splitlines()
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(lines) - 1))
        kind = data.draw(st.sampled_from(["value", "delete", "duplicate", "chars", "swap"]))
        if kind == "value" and "=" in lines[i]:
            key = lines[i].split("=")[0]
            lines[i] = f"{key}= {data.draw(st.sampled_from(HOSTILE))}"
        elif kind == "delete":
            del lines[i]
        elif kind == "duplicate":
            lines.insert(i, lines[i])
        elif kind == "chars":
            pos = data.draw(st.integers(0, len(lines[i])))
            lines[i] = lines[i][:pos] + data.draw(st.text(max_size=8)) + lines[i][pos:]
        elif kind == "swap":
            j = data.draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        if not lines:
            break
    solve_text("\n".join(lines) + "\n")


#: Dotted paths into the scene's dict, and where a hostile value goes.
PATHS = ["name", "plate.a", "plate.b", "plate.h", "plate.E", "plate.nu", "mesh.nx", "mesh.ny", "mesh.element",
         "edges.left", "edges.right", "edges.top", "openings.0.x0", "openings.0.y1", "pins.0.x", "pins.0.w",
         "loads.0.q", "loads.0.type", "loads.1.P", "loads.1.x", "loads.1.y", "supports.1.x", "supports.1.gap",
         "supports.2.stiffness", "supports.2.y", "foundation.k", "foundation.region", "foundation.gap",
         "foundation.gap.radius", "foundation.gap.depth", "loads", "supports", "plate", "mesh"]

VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(min_value=-10**30, max_value=10**30),
    st.text(max_size=10), st.booleans(), st.lists(st.floats(-2, 2), max_size=5),
    st.dictionaries(st.sampled_from(["kind", "w", "slope", "profile", "x", "a"]), st.floats(-1, 1), max_size=3),
    st.sampled_from(["rigid", "simple", "clamped", "free", "uniform", "point", "patch", "bfs", "trough"]),
)


def set_path(d: dict, path: str, value) -> None:
    keys = path.split(".")
    cur = d
    for k in keys[:-1]:
        cur = cur[int(k)] if isinstance(cur, list) else cur.setdefault(k, {})
        if not isinstance(cur, (dict, list)):
            return
    last = keys[-1]
    if isinstance(cur, list):
        cur[int(last)] = value
    else:
        cur[last] = value


@FUZZ
@given(st.lists(st.tuples(st.sampled_from(PATHS), VALUES), min_size=1, max_size=3),
       st.sampled_from(["auto", "lemke", "bpp", "pdas", "clarabel", "osqp"]),
       st.sampled_from(["auto", "primal", "condensed", "dual"]))
def test_structured_but_wrong(edits, backend, formulation):
    import tomllib

    import tomli_w

    d = tomllib.loads(BASE)
    for path, value in edits:
        try:
            set_path(d, path, value)
        except (IndexError, ValueError, TypeError, KeyError):
            continue
    try:
        text = tomli_w.dumps(d)
    except (TypeError, ValueError):  # nan/inf/None TOML cannot hold here: write repr-like text
        return
    if backend not in ("auto", *pq.available_backends()):
        backend = "auto"
    solve_text(text, "--backend", backend, "--formulation", formulation)


# -- the Python API: anything where a number, a part or an argument belongs ---------------------------
#: Values a Python caller may put anywhere: numbers (NumPy's too), wrong types, containers.
import numpy as np  # noqa: E402

PY_VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(min_value=-10**30, max_value=10**30),
    st.sampled_from([None, True, "", "x", "rigid", "simple", b"1", 1j, (), [], {}, [1, 2], {"a": 1}, object(),
                     np.float32(0.3), np.int64(3), np.float64(-1.0), np.array(0.5), np.array([1.0, 2.0]),
                     np.bool_(True), np.nan, pq.Plate(), pq.Support(0.0, 0.0), pq.UniformLoad(1.0)]),
)
#: (part, field) of the fuzzed scene that a value replaces; "" the scene's own field.
PY_FIELDS = [("plate", f) for f in ("a", "b", "h", "E", "nu")] + [("mesh", f) for f in ("nx", "ny", "element")] + [
    ("supports.0", f) for f in ("x", "y", "gap", "stiffness")] + [("loads.0", "q"), ("loads.1", "P"),
    ("loads.1", "x"), ("foundation", "k"), ("foundation", "region"), ("foundation", "gap"), ("pins.0", "x")] + [
    ("", f) for f in ("name", "plate", "mesh", "edges", "openings", "pins", "loads", "supports", "foundation")]


def py_scene(**kw) -> pq.Scene:
    return pq.Scene(name="fuzz", plate=pq.Plate(a=2.0, b=1.0, h=0.02), mesh=pq.MeshSpec(nx=4, ny=2),
                    edges={"left": pq.Edge("simple")}, pins=[pq.Pin(0.0, 0.0)],
                    loads=[pq.UniformLoad(1.0), pq.PointLoad(3.0, 1.2, 0.5)],
                    supports=[pq.Support(2.0, 0.0, gap=-0.001), pq.Support(1.0, 1.0, stiffness=500.0)],
                    foundation=pq.Foundation(50.0, region=[0.0, 1.0, 0.0, 1.0]), **kw)


def test_python_base_scene_solves():
    assert pq.solve(py_scene()).status.solved


@FUZZ
@given(st.lists(st.tuples(st.sampled_from(PY_FIELDS), PY_VALUES), min_size=1, max_size=3), st.booleans())
def test_python_api_misuse_is_a_plateqp_error(edits, after):
    """Values set on the scene's parts before construction (a new Scene from them) or after it
    (then solve checks again): a scene and a solve, or a PlateQPError and nothing else."""
    sc = py_scene()
    try:
        for (part, name), value in edits:
            obj = sc
            for k in part.split(".") if part else ():
                obj = obj[int(k)] if k.isdigit() else getattr(obj, k)
            setattr(obj, name, value)
    except (AttributeError, IndexError, KeyError, TypeError):  # a part replaced earlier by a bare value
        return
    try:
        if not after:
            sc = pq.Scene(**{f: getattr(sc, f) for f in ("name", "plate", "mesh", "edges", "openings", "pins",
                                                          "loads", "supports", "foundation")})
        sc.validate()  # what solve checks first
        if sc.mesh.nx * sc.mesh.ny > 64:  # a valid scene on a large mesh: its solve is not this test's
            return
        with warnings.catch_warnings():  # ill-conditioned scenes (a support 1e-160 from a pin) are
            warnings.simplefilter("ignore")  # solved and flagged: the status is asserted below
            res = pq.solve(sc)
    except pq.PlateQPError as exn:
        assert "\n" not in str(exn).strip()
        return
    assert res.status in set(pq.Status)


@FUZZ
@given(st.sampled_from(["deflection", "slopes", "curvatures", "moments", "stresses", "principal_stresses",
                        "section", "at", "nodal", "to_dict"]),
       st.lists(st.one_of(PY_VALUES, st.lists(st.floats(-1, 3), min_size=1, max_size=3)), max_size=3))
def test_python_result_methods_misuse_is_a_plateqp_error(method, args):
    res = _fuzz_result()
    try:
        getattr(res, method)(*args)
    except pq.PlateQPError as exn:
        assert "\n" not in str(exn).strip()
    except TypeError as exn:  # the wrong number of arguments: Python's own call check
        assert "positional argument" in str(exn), exn


_RESULT = []


def _fuzz_result():
    if not _RESULT:
        _RESULT.append(pq.solve(py_scene()))
    return _RESULT[0]
