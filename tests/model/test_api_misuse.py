"""The Python API misused: every wrong argument is one of plateqp's own errors whose one-line
message names the argument (or the scene field), never an AttributeError, TypeError or
ValueError from inside plateqp; NumPy numbers and arrays are taken wherever numbers are; and a
scene changed after construction is checked again when it is solved, with the message its
construction would have given.

The table below is the contract: (id, call, error class, words the message must hold). Each call
is made on a fresh valid scene (``sc``) and, for the Result rows, on one solved result (``res``).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import plateqp as pq
from plateqp.errors import ArgumentError, ProblemError, SceneError, SolverError


def make_scene() -> pq.Scene:
    return pq.Scene(name="misuse", plate=pq.Plate(a=1.0, b=1.0, h=0.01, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(nx=4, ny=4), loads=[pq.UniformLoad(1.0)],
                    supports=[pq.Support(0.0, 0.0), pq.Support(1.0, 0.0), pq.Support(0.0, 1.0),
                              pq.Support(1.0, 1.0, gap=0.0, stiffness=500.0)])


@pytest.fixture(scope="module")
def res():
    return pq.solve(make_scene(), backend="lemke")


S = pq.Scene
P = pq.Plate
M = pq.MeshSpec
UL = pq.UniformLoad
SUP = pq.Support
DKT = {"mesh": M(element="dkt", size=0.25)}

#: (id, call taking (sc, res), error class, words in the message)
SCENE_ROWS = [
    # solve's scene argument
    ("solve-None", lambda sc, r: pq.solve(None), SceneError, "scene"),
    ("solve-dict", lambda sc, r: pq.solve(sc.to_dict()), SceneError, "Scene.from_dict"),
    ("solve-path", lambda sc, r: pq.solve("scene.toml"), SceneError, "Scene.from_toml"),
    ("solve-int", lambda sc, r: pq.solve(42), SceneError, "scene"),
    ("solve-list", lambda sc, r: pq.solve([sc]), SceneError, "scene"),
    ("solve-plate", lambda sc, r: pq.solve(sc.plate), SceneError, "scene"),
    ("bilateral-None", lambda sc, r: pq.solve_bilateral(None), SceneError, "scene"),
    ("bilateral-dict", lambda sc, r: pq.solve_bilateral({}), SceneError, "scene"),
    # solve's other arguments
    ("backend-int", lambda sc, r: pq.solve(sc, backend=123), SolverError, "backend"),
    ("backend-None", lambda sc, r: pq.solve(sc, backend=None), SolverError, "backend"),
    ("backend-list", lambda sc, r: pq.solve(sc, backend=["lemke"]), SolverError, "backend"),
    ("backend-bytes", lambda sc, r: pq.solve(sc, backend=b"lemke"), SolverError, "backend"),
    ("backend-empty", lambda sc, r: pq.solve(sc, backend=""), SolverError, "backend"),
    ("backend-unknown", lambda sc, r: pq.solve(sc, backend="nope"), SolverError, "backend"),
    ("formulation-int", lambda sc, r: pq.solve(sc, formulation=1), ProblemError, "formulation"),
    ("formulation-None", lambda sc, r: pq.solve(sc, formulation=None), ProblemError, "formulation"),
    ("formulation-unknown", lambda sc, r: pq.solve(sc, formulation="qp"), ProblemError, "formulation"),
    ("accuracy-None", lambda sc, r: pq.solve(sc, accuracy=None), ProblemError, "accuracy"),
    ("accuracy-list", lambda sc, r: pq.solve(sc, accuracy=[1e-6]), ProblemError, "accuracy"),
    ("accuracy-bool", lambda sc, r: pq.solve(sc, accuracy=True), ProblemError, "accuracy"),
    ("accuracy-word", lambda sc, r: pq.solve(sc, accuracy="x"), ProblemError, "accuracy"),
    ("accuracy-nan", lambda sc, r: pq.solve(sc, accuracy=math.nan), ProblemError, "accuracy"),
    ("accuracy-array", lambda sc, r: pq.solve(sc, accuracy=np.array([1e-6, 1e-3])), ProblemError, "accuracy"),
    ("options-str", lambda sc, r: pq.solve(sc, options="x"), ArgumentError, "options"),
    ("options-list", lambda sc, r: pq.solve(sc, options=[1]), ArgumentError, "options"),
    ("options-int", lambda sc, r: pq.solve(sc, options=1), ArgumentError, "options"),
    ("options-keys", lambda sc, r: pq.solve(sc, options={1: 2}), ArgumentError, "options"),
    ("model-str", lambda sc, r: pq.solve(sc, model="x"), ArgumentError, "model"),
    ("model-int", lambda sc, r: pq.solve(sc, model=123), ArgumentError, "model"),
    ("model-dict", lambda sc, r: pq.solve(sc, model={}), ArgumentError, "model"),
    ("check-statics-str", lambda sc, r: pq.solve(sc, check_statics="yes"), ArgumentError, "check_statics"),
    ("check-statics-None", lambda sc, r: pq.solve(sc, check_statics=None), ArgumentError, "check_statics"),
    ("bilateral-model", lambda sc, r: pq.solve_bilateral(sc, model="x"), ArgumentError, "model"),
    # the Scene constructor
    ("supports-ints", lambda sc, r: S(supports=[1, 2]), SceneError, "supports.1"),
    ("supports-one", lambda sc, r: S(supports=SUP(0, 0)), SceneError, "supports"),
    ("supports-None", lambda sc, r: S(supports=None), SceneError, "supports"),
    ("supports-str", lambda sc, r: S(supports="abc"), SceneError, "supports"),
    ("supports-dict-item", lambda sc, r: S(supports=[{"x": 0, "y": 0}]), SceneError, "supports.1"),
    ("supports-second", lambda sc, r: S(supports=[SUP(0, 0), (1, 1)]), SceneError, "supports.2"),
    ("edges-list", lambda sc, r: S(edges=["simple"]), SceneError, "edges"),
    ("edges-str", lambda sc, r: S(edges="simple"), SceneError, "edges"),
    ("edges-None", lambda sc, r: S(edges=None), SceneError, "edges"),
    ("edges-value-int", lambda sc, r: S(edges={"left": 1}), SceneError, "edges.left"),
    ("edges-key-int", lambda sc, r: S(edges={1: "simple"}), SceneError, "edges"),
    ("edge-kind-int", lambda sc, r: S(edges={"left": pq.Edge(kind=1)}), SceneError, "edges.left"),
    ("edge-kind-None", lambda sc, r: S(edges={"left": pq.Edge(kind=None)}), SceneError, "edges.left"),
    ("edge-w-str", lambda sc, r: S(edges={"left": pq.Edge("simple", w="0")}), SceneError, "edges.left.w"),
    ("edge-dict-w-str", lambda sc, r: S(edges={"left": {"kind": "simple", "w": "0"}}), SceneError, "edges.left.w"),
    ("plate-None", lambda sc, r: S(plate=None), SceneError, "plate"),
    ("plate-dict", lambda sc, r: S(plate={"a": 1.0}), SceneError, "plate"),
    ("plate-str", lambda sc, r: S(plate="steel"), SceneError, "plate"),
    ("plate-a-str", lambda sc, r: S(plate=P(a="1")), SceneError, "plate.a"),
    ("plate-a-None", lambda sc, r: S(plate=P(a=None)), SceneError, "plate.a"),
    ("plate-a-list", lambda sc, r: S(plate=P(a=[1.0])), SceneError, "plate.a"),
    ("plate-a-complex", lambda sc, r: S(plate=P(a=1 + 1j)), SceneError, "plate.a"),
    ("plate-h-array", lambda sc, r: S(plate=P(h=np.array([0.01, 0.02]))), SceneError, "plate.h"),
    ("plate-nu-nan", lambda sc, r: S(plate=P(nu=math.nan)), SceneError, "plate.nu"),
    ("plate-nu-None", lambda sc, r: S(plate=P(nu=None)), SceneError, "plate.nu"),
    ("plate-E-bool", lambda sc, r: S(plate=P(E=True)), SceneError, "plate.E"),
    ("plate-shape-str", lambda sc, r: S(plate=P(shape="square"), **DKT), SceneError, "plate.shape"),
    ("mesh-None", lambda sc, r: S(mesh=None), SceneError, "mesh"),
    ("mesh-dict", lambda sc, r: S(mesh={"nx": 4}), SceneError, "mesh"),
    ("mesh-nx-float", lambda sc, r: S(mesh=M(nx=4.0)), SceneError, "mesh.nx"),
    ("mesh-nx-str", lambda sc, r: S(mesh=M(nx="4")), SceneError, "mesh.nx"),
    ("mesh-nx-None", lambda sc, r: S(mesh=M(nx=None)), SceneError, "mesh.nx"),
    ("mesh-nx-float32", lambda sc, r: S(mesh=M(nx=np.float32(4))), SceneError, "mesh.nx"),
    ("mesh-element-None", lambda sc, r: S(mesh=M(element=None)), SceneError, "mesh.element"),
    ("mesh-element-int", lambda sc, r: S(mesh=M(element=3)), SceneError, "mesh.element"),
    ("mesh-element-list", lambda sc, r: S(mesh=M(element=["acm"])), SceneError, "mesh.element"),
    ("mesh-size-str", lambda sc, r: S(mesh=M(element="dkt", size="0.1")), SceneError, "mesh.size"),
    ("loads-int", lambda sc, r: S(loads=[1]), SceneError, "loads.0"),
    ("loads-dict-item", lambda sc, r: S(loads=[{"type": "uniform", "q": 1.0}]), SceneError, "loads.0"),
    ("loads-one", lambda sc, r: S(loads=UL(1.0)), SceneError, "loads"),
    ("loads-None", lambda sc, r: S(loads=None), SceneError, "loads"),
    ("load-q-None", lambda sc, r: S(loads=[UL(None)]), SceneError, "loads.0.q"),
    ("load-q-str", lambda sc, r: S(loads=[UL("1")]), SceneError, "loads.0.q"),
    ("load-P-str", lambda sc, r: S(loads=[pq.PointLoad("1", 0.5, 0.5)]), SceneError, "loads.0.P"),
    ("load-x-None", lambda sc, r: S(loads=[pq.PointLoad(1.0, None, 0.5)]), SceneError, "loads.0.x"),
    ("patch-x0-str", lambda sc, r: S(loads=[pq.PatchLoad(1.0, "0", 1, 0, 1)]), SceneError, "loads.0.x0"),
    ("pins-tuple-item", lambda sc, r: S(pins=[(0, 0)]), SceneError, "pins.0"),
    ("pins-None", lambda sc, r: S(pins=None), SceneError, "pins"),
    ("pin-x-None", lambda sc, r: S(pins=[pq.Pin(None, 0.0)]), SceneError, "pins.0.x"),
    ("openings-list-item", lambda sc, r: S(openings=[[0, 1, 0, 1]]), SceneError, "openings.0"),
    ("openings-None", lambda sc, r: S(openings=None), SceneError, "openings"),
    ("opening-x0-str", lambda sc, r: S(openings=[pq.Opening("0", 1, 0, 1)]), SceneError, "openings.0.x0"),
    ("support-x-str", lambda sc, r: S(supports=[SUP("0", 0)]), SceneError, "supports.1.x"),
    ("support-y-None", lambda sc, r: S(supports=[SUP(0, None)]), SceneError, "supports.1.y"),
    ("support-gap-None", lambda sc, r: S(supports=[SUP(0, 0, gap=None)]), SceneError, "supports.1.gap"),
    ("support-gap-list", lambda sc, r: S(supports=[SUP(0, 0, gap=[0.0])]), SceneError, "supports.1.gap"),
    ("support-stiffness-None", lambda sc, r: S(supports=[SUP(0, 0, stiffness=None)]), SceneError,
     "supports.1.stiffness"),
    ("support-stiffness-list", lambda sc, r: S(supports=[SUP(0, 0, stiffness=[1.0])]), SceneError,
     "supports.1.stiffness"),
    ("support-stiffness-word", lambda sc, r: S(supports=[SUP(0, 0, stiffness="soft")]), SceneError,
     "supports.1.stiffness"),
    ("foundation-int", lambda sc, r: S(foundation=5), SceneError, "foundation"),
    ("foundation-dict", lambda sc, r: S(foundation={"k": 1.0}), SceneError, "foundation"),
    ("foundation-k-None", lambda sc, r: S(foundation=pq.Foundation(None)), SceneError, "foundation.k"),
    ("foundation-region-str", lambda sc, r: S(foundation=pq.Foundation(1.0, region="all")), SceneError,
     "foundation.region"),
    ("foundation-region-short", lambda sc, r: S(foundation=pq.Foundation(1.0, region=[0, 1])), SceneError,
     "foundation.region"),
    ("foundation-gap-str", lambda sc, r: S(foundation=pq.Foundation(1.0, gap="x")), SceneError, "foundation.gap"),
    ("foundation-gap-profile", lambda sc, r: S(foundation=pq.Foundation(1.0, gap={"profile": 1})), SceneError,
     "foundation.gap.profile"),
    ("foundation-gap-keys", lambda sc, r: S(foundation=pq.Foundation(1.0, gap={1: 2})), SceneError,
     "foundation.gap"),
    ("name-None", lambda sc, r: S(name=None), SceneError, "name"),
    ("name-int", lambda sc, r: S(name=3), SceneError, "name"),
    ("holes-str", lambda sc, r: S(holes="x", **DKT), SceneError, "holes"),
    ("holes-int-item", lambda sc, r: S(holes=[1], **DKT), SceneError, "holes.0"),
    ("holes-None", lambda sc, r: S(holes=None, **DKT), SceneError, "holes"),
    ("polygon-str-vertex", lambda sc, r: S(plate=P(shape={"polygon": [[0, 0], [1, 0], "ab"]}), **DKT), SceneError,
     "plate.shape.polygon.2"),
    ("source-int", lambda sc, r: S(source=1), SceneError, "source"),
    # Scene.from_dict and Scene.from_toml
    ("from-dict-None", lambda sc, r: S.from_dict(None), SceneError, "scene"),
    ("from-dict-list", lambda sc, r: S.from_dict([]), SceneError, "scene"),
    ("from-dict-str", lambda sc, r: S.from_dict("scene.toml"), SceneError, "scene"),
    ("from-dict-int-key", lambda sc, r: S.from_dict({1: 2}), SceneError, "1"),
    ("from-dict-mixed-keys", lambda sc, r: S.from_dict({1: 2, "x": 3}), SceneError, "unknown key"),
    ("from-dict-plate-None", lambda sc, r: S.from_dict({"plate": None}), SceneError, "plate"),
    ("from-dict-plate-list", lambda sc, r: S.from_dict({"plate": []}), SceneError, "plate"),
    ("from-dict-plate-int-key", lambda sc, r: S.from_dict({"plate": {1: 2}}), SceneError, "plate"),
    ("from-dict-mesh-int", lambda sc, r: S.from_dict({"mesh": 1}), SceneError, "mesh"),
    ("from-dict-edges-list", lambda sc, r: S.from_dict({"edges": ["simple"]}), SceneError, "edges"),
    ("from-dict-edges-int", lambda sc, r: S.from_dict({"edges": {"left": 1}}), SceneError, "edges.left"),
    ("from-dict-edge-kind-int", lambda sc, r: S.from_dict({"edges": {"left": {"kind": 1}}}), SceneError,
     "edges.left"),
    ("from-dict-edge-int-key", lambda sc, r: S.from_dict({"edges": {"left": {1: 2}}}), SceneError, "edges.left"),
    ("from-dict-supports-table", lambda sc, r: S.from_dict({"supports": {}}), SceneError, "supports"),
    ("from-dict-supports-int", lambda sc, r: S.from_dict({"supports": [1]}), SceneError, "supports.1"),
    ("from-dict-support-missing", lambda sc, r: S.from_dict({"supports": [{"x": 0}]}), SceneError, "supports.1"),
    ("from-dict-loads-int", lambda sc, r: S.from_dict({"loads": [1]}), SceneError, "loads.0"),
    ("from-dict-loads-type-None", lambda sc, r: S.from_dict({"loads": [{"type": None}]}), SceneError,
     "loads.0.type"),
    ("from-dict-loads-table", lambda sc, r: S.from_dict({"loads": {"type": "uniform"}}), SceneError, "loads"),
    ("from-dict-foundation-list", lambda sc, r: S.from_dict({"foundation": []}), SceneError, "foundation"),
    ("from-dict-holes-table", lambda sc, r: S.from_dict({"holes": {}}), SceneError, "holes"),
    ("from-dict-name-None", lambda sc, r: S.from_dict({"name": None}), SceneError, "name"),
    ("from-dict-source-int", lambda sc, r: S.from_dict({}, source=1), SceneError, "source"),
    ("from-toml-None", lambda sc, r: S.from_toml(None), SceneError, "path"),
    ("from-toml-int", lambda sc, r: S.from_toml(123), SceneError, "path"),
    ("from-toml-list", lambda sc, r: S.from_toml(["a.toml"]), SceneError, "path"),
    # a Result's methods
    ("deflection-str", lambda sc, r: r.deflection("a", 0.5), ArgumentError, "x"),
    ("deflection-y-str", lambda sc, r: r.deflection(0.5, "b"), ArgumentError, "y"),
    ("deflection-None", lambda sc, r: r.deflection(None, 0.5), ArgumentError, "x"),
    ("deflection-mixed", lambda sc, r: r.deflection([0.1, "a"], 0.5), ArgumentError, "x"),
    ("deflection-complex", lambda sc, r: r.deflection(0.5j, 0.5), ArgumentError, "x"),
    ("deflection-dict", lambda sc, r: r.deflection({}, 0.5), ArgumentError, "x"),
    ("deflection-shapes", lambda sc, r: r.deflection([0.1, 0.2], [0.1, 0.2, 0.3]), ArgumentError, "x and y"),
    ("deflection-nan", lambda sc, r: r.deflection(math.nan, 0.5), SceneError, "not on the plate"),
    ("slopes-str", lambda sc, r: r.slopes("a", 0.5), ArgumentError, "x"),
    ("curvatures-str", lambda sc, r: r.curvatures(0.5, "a"), ArgumentError, "y"),
    ("moments-str", lambda sc, r: r.moments("a", 0.5), ArgumentError, "x"),
    ("stresses-None", lambda sc, r: r.stresses(0.5, None), ArgumentError, "y"),
    ("principal-str", lambda sc, r: r.principal_stresses("a", 0.5), ArgumentError, "x"),
    ("section-p0-str", lambda sc, r: r.section("a", (1, 1)), ArgumentError, "p0"),
    ("section-p1-short", lambda sc, r: r.section((0, 0), (1,)), ArgumentError, "p1"),
    ("section-p0-None", lambda sc, r: r.section(None, (1, 1)), ArgumentError, "p0"),
    ("section-n-str", lambda sc, r: r.section((0, 0), (1, 1), n="x"), ArgumentError, "n"),
    ("section-n-zero", lambda sc, r: r.section((0, 0), (1, 1), n=0), ArgumentError, "n"),
    ("section-n-float", lambda sc, r: r.section((0, 0), (1, 1), n=2.5), ArgumentError, "n"),
    ("section-quantity", lambda sc, r: r.section((0, 0), (1, 1), quantity="M"), ArgumentError, "quantity"),
    ("at-quantity", lambda sc, r: r.at(0.5, 0.5, "bad"), ArgumentError, "quantity"),
    ("at-quantity-int", lambda sc, r: r.at(0.5, 0.5, 1), ArgumentError, "quantity"),
    ("at-quantity-list", lambda sc, r: r.at(0.5, 0.5, ["w"]), ArgumentError, "quantity"),
    ("nodal-quantity", lambda sc, r: r.nodal("bad"), ArgumentError, "quantity"),
    ("nodal-quantity-None", lambda sc, r: r.nodal(None), ArgumentError, "quantity"),
    ("to-dict-probes-int", lambda sc, r: r.to_dict(probes=1), ArgumentError, "probes"),
    ("to-dict-probes-short", lambda sc, r: r.to_dict(probes=[(1,)]), ArgumentError, "probes.0"),
    ("to-dict-probes-str", lambda sc, r: r.to_dict(probes=["ab"]), ArgumentError, "probes.0"),
]


@pytest.mark.parametrize("call, error, words", [row[1:] for row in SCENE_ROWS], ids=[row[0] for row in SCENE_ROWS])
def test_misuse_is_a_plateqp_error_naming_the_argument(res, call, error, words):
    with pytest.raises(pq.PlateQPError) as info:
        call(make_scene(), res)
    assert isinstance(info.value, error), (type(info.value).__name__, str(info.value))
    msg = str(info.value)
    assert words in msg and "\n" not in msg.strip() and len(msg) < 1000, msg


def test_the_misuse_table_is_large():
    assert len(SCENE_ROWS) >= 150
    assert len({row[0] for row in SCENE_ROWS}) == len(SCENE_ROWS)


# -- a scene changed after construction: checked again at solve ---------------------------------
def _set(path, value):
    def change(sc):
        *head, last = path.split(".")
        obj = sc
        for k in head:
            obj = obj[int(k)] if isinstance(obj, list) else getattr(obj, k)
        if isinstance(obj, list):
            obj[int(last)] = value
        else:
            setattr(obj, last, value)
    return change


MUTATIONS = [
    ("nu-half", _set("plate.nu", 0.5), "plate.nu"),
    ("h-negative", _set("plate.h", -1.0), "plate.h"),
    ("E-nan", _set("plate.E", math.nan), "plate.E"),
    ("nx-zero", _set("mesh.nx", 0), "mesh.nx"),
    ("element-unknown", _set("mesh.element", "quad9"), "mesh.element"),
    ("support-off-plate", _set("supports.0.x", 5.0), "supports.1"),
    ("support-gap-str", _set("supports.1.gap", "0"), "supports.2.gap"),
    ("support-stiffness-negative", _set("supports.3.stiffness", -5.0), "supports.4.stiffness"),
    ("support-replaced", _set("supports.2", 7), "supports.3"),
    ("supports-replaced", _set("supports", "none"), "supports"),
    ("load-q-inf", _set("loads.0.q", math.inf), "loads.0.q"),
    ("edges-replaced", _set("edges", ["simple"]), "edges"),
    ("plate-replaced", _set("plate", None), "plate"),
]


@pytest.mark.parametrize("change, field", [m[1:] for m in MUTATIONS], ids=[m[0] for m in MUTATIONS])
@pytest.mark.parametrize("entry", ["solve", "solve_bilateral"])
def test_a_scene_changed_after_construction_is_checked_at_solve(change, field, entry):
    sc = make_scene()
    change(sc)
    with pytest.raises(SceneError) as at_solve:
        getattr(pq, entry)(sc)
    assert field in str(at_solve.value)
    # the same message construction gives, for the changes a constructor can be handed
    with pytest.raises(SceneError) as at_build:
        sc.validate()
    assert str(at_solve.value) == str(at_build.value)


def test_a_scene_changed_after_construction_gives_the_constructors_message():
    sc = make_scene()
    sc.plate.nu = 0.5
    with pytest.raises(SceneError) as at_solve:
        pq.solve(sc)
    with pytest.raises(SceneError) as at_build:
        pq.Scene(plate=pq.Plate(nu=0.5), mesh=pq.MeshSpec(nx=4, ny=4), loads=[pq.UniformLoad(1.0)])
    assert str(at_solve.value) == str(at_build.value)


def test_a_model_built_before_is_taken(res):
    from plateqp.model.assembly import build_model
    sc = make_scene()
    own = build_model(sc)
    assert np.allclose(pq.solve(sc, model=own, backend="lemke").reactions, res.reactions, rtol=1e-9, atol=0)


def test_sweeps_copy_scenes_with_replace_and_may_change_the_copies():
    sc = make_scene()
    copy = dataclasses.replace(sc, plate=dataclasses.replace(sc.plate, h=0.02))
    copy.supports = [dataclasses.replace(s) for s in copy.supports]
    copy.supports[0].gap = 0.001
    r = pq.solve(copy, backend="lemke")
    assert r.status.solved and sc.supports[0].gap == 0.0 and sc.plate.h == 0.01


# -- NumPy numbers wherever numbers are -----------------------------------------------------------
def numpy_scene() -> pq.Scene:
    f32, f64, i64 = np.float32, np.float64, np.int64
    return pq.Scene(name="misuse", plate=pq.Plate(a=f64(1.0), b=np.array(1.0), h=f32(0.01), E=i64(10_000_000),
                                                  nu=f32(0.3)),
                    mesh=pq.MeshSpec(nx=i64(4), ny=np.int32(4)), loads=[pq.UniformLoad(f32(1.0))],
                    supports=[pq.Support(f64(0.0), i64(0)), pq.Support(np.array(1.0), f32(0.0)),
                              pq.Support(0.0, np.int8(1)),
                              pq.Support(1.0, 1.0, gap=np.array(0.0), stiffness=f32(500.0))])


def test_numpy_numbers_are_taken_and_give_the_same_answer(res, tmp_path):
    sc = numpy_scene()
    py = make_scene()
    # stored as the Python numbers they stand for: the scene compares equal and saves to TOML
    assert type(sc.plate.h) is float and type(sc.mesh.nx) is int and sc.plate.h == float(np.float32(0.01))
    sc.plate.h, sc.plate.nu, sc.loads[0].q = 0.01, 0.3, 1.0  # float32's rounding undone: the scene itself
    assert sc == py
    assert pq.Scene.from_toml(sc.to_toml(tmp_path / "np.toml") and tmp_path / "np.toml") == sc
    r = pq.solve(numpy_scene(), backend="lemke", accuracy=np.float64(1e-6))
    assert np.allclose(r.reactions, res.reactions, rtol=1e-5, atol=0)
    assert math.isclose(r.deflection(np.float32(0.5), np.float32(0.5)), res.deflection(0.5, 0.5), rel_tol=1e-5)


def test_numpy_arguments_to_result_methods(res):
    w = res.deflection(np.float64(0.25), np.array(0.75))
    assert isinstance(w, float) and w == res.deflection(0.25, 0.75)
    s, v = res.section(np.array([0.0, 0.0]), np.array([1.0, 1.0]), n=np.int64(5))
    assert len(s) == 5 and np.allclose(v, res.section((0, 0), (1, 1), n=5)[1])
    d = res.to_dict(probes=np.array([[0.5, 0.5]]))
    assert d["probes"][0]["w"] == res.deflection(0.5, 0.5)
    assert np.allclose(res.at(np.array([0.5]), [0.5], np.str_("Mx")), res.at(0.5, 0.5, "Mx"))


def test_numpy_polygons_holes_and_regions_are_taken(tmp_path):
    poly = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
    kw = dict(mesh=pq.MeshSpec(element="dkt", size=np.float32(0.25)), loads=[pq.UniformLoad(1.0)])
    plain = pq.Scene(plate=pq.Plate(shape={"polygon": poly}), holes=[{"circle": [0.5, 0.5, 0.2]}],
                     foundation=pq.Foundation(10.0, region={"polygon": [[0, 0], [1, 0], [1, 1], [0, 1]]}), **kw)
    arr = pq.Scene(plate=pq.Plate(shape={"polygon": np.array(poly, dtype=np.int64)}),
                   holes=[{"circle": np.array([0.5, 0.5, 0.2])}],
                   foundation=pq.Foundation(np.float32(10.0), region={"polygon": np.array([[0, 0], [1, 0], [1, 1],
                                                                                          [0, 1]], float)}), **kw)
    assert arr.to_dict() == plain.to_dict()
    assert pq.Scene.from_toml(arr.to_toml(tmp_path / "a.toml") and tmp_path / "a.toml").to_dict() == plain.to_dict()
    box = pq.Scene(foundation=pq.Foundation(10.0, region=np.array([0.0, 0.5, 0.0, 0.5])), loads=[pq.UniformLoad(1.0)])
    assert box.foundation.region == [0.0, 0.5, 0.0, 0.5] and isinstance(box.foundation.region[0], float)


def test_no_points_give_no_values(res):
    assert res.deflection(0.0, ()).shape == (0,) and res.moments([], [])[0].shape == (0,)


@pytest.mark.parametrize("element", ["acm", "dkt"])
@pytest.mark.parametrize("point", [(8.98846567431158e307, 0.0), (1.7e308, 1.7e308), (math.inf, 0.0),
                                   (math.nan, 0.5), (-1e308, 0.3)],
                         ids=["huge-x", "huge-both", "inf", "nan", "huge-negative"])
def test_a_point_at_the_edge_of_double_precision_is_off_the_plate(element, point):
    """Coordinates near the largest double (x / h overflows), infinite or NaN: a SceneError that
    the point is not on the plate, on either mesh, and no RuntimeWarning (the suite makes
    plateqp's RuntimeWarnings errors)."""
    pytest.importorskip("gmsh")
    mesh = pq.MeshSpec(4, 2, element) if element != "dkt" else pq.MeshSpec(element="dkt", size=0.5)
    res = pq.solve(pq.Scene(plate=pq.Plate(a=2.0, b=1.0), mesh=mesh, loads=[pq.UniformLoad(1.0)],
                            supports=[pq.Support(0.5, 0.5), pq.Support(1.5, 0.5), pq.Support(1.0, 0.2)]))
    with pytest.raises(SceneError, match="is not on the plate"):
        res.deflection(*point)


def test_a_scene_unchanged_since_its_validation_is_not_checked_again(monkeypatch):
    """solve() checks a scene again only where something changed since its last validation:
    counted on the checks themselves; a change to any part, nested dicts included, is seen."""
    import plateqp.model.scene as scene_module

    sc = make_scene()
    calls = []
    real = scene_module.check_scene
    monkeypatch.setattr(scene_module, "check_scene", lambda s: (calls.append(1), real(s)))
    pq.solve(sc)
    pq.solve(sc)
    assert calls == []
    for change in (lambda s: setattr(s.supports[0], "gap", 1e-4), lambda s: setattr(s.plate, "h", 0.03),
                   lambda s: s.edges.update(left=pq.Edge("free")), lambda s: s.loads.append(pq.UniformLoad(1.0))):
        before = len(calls)
        change(sc)
        pq.solve(sc)
        assert len(calls) == before + 1
