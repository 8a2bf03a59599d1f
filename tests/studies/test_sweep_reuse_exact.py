"""A sweep that re-uses the plate's factorisation, its scaled data and its QP's reading gives,
value for value, what a cold pq.solve of that value's scene gives (an independent solve: its
own model, scaling, formulation and factorisation), with the KKT check passed on every value;
and it does that work once per sweep, not once per value."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.backends.pdas import driver
from plateqp.contact import scaling
from plateqp.model.paths import set_param
from plateqp.scenes.families import grid_elastic, grid_rigid
from plateqp.studies.sweep import sweep

ACC = 1e-10
REL = 1e-10


def bed_scene(n: int = 12, element: str = "acm") -> pq.Scene:
    """A free plate on a tensionless bed falling away towards (1, 1): part of it lifts off."""
    return pq.Scene(name=f"bed{n}", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, element),
                    edges={}, loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                    foundation=pq.Foundation(2.0e4, gap={"profile": "linear", "g0": 0.0, "gx": 0.004, "gy": 0.002}))


def patched(element: str = "acm") -> pq.Scene:
    """grid_elastic with a circular patch load beside its uniform and point loads."""
    sc = grid_elastic(8, 2, element)
    sc.loads.append(pq.PatchLoad(q=15.0, region={"circle": [2.5, 5.0, 1.2]}))
    sc.validate()
    return sc


CASES = {
    "grid gap": (lambda: grid_rigid(12, 3), "supports.1.gap", [-1e-3, 0.0, 5e-4, 2e-3]),
    "grid load": (lambda: grid_rigid(12, 3), "loads.0.q", [5.0, 10.0, 20.0, 40.0]),
    "grid stiffness": (lambda: grid_elastic(12, 3), "supports.*.stiffness", [1e4, 1e5, 1e6, "rigid"]),
    "bed gap": (bed_scene, "foundation.gap.gx", [0.003, 0.004, 0.005, 0.006]),
    "bed load": (bed_scene, "loads.1.P", [100.0, 200.0, 300.0, 400.0]),
    "bed stiffness": (bed_scene, "foundation.k", [1e4, 2e4, 4e4, 8e4]),
    "patch load": (patched, "loads.2.q", [0.0, 15.0, 60.0]),
    "triangles gap": (lambda: grid_elastic(8, 2, "dkt"), "supports.1.gap", [-1e-3, 0.0, 1e-3]),
    "triangles load": (lambda: patched("dkt"), "loads.1.P", [100.0, 300.0, 600.0]),
    "triangles stiffness": (lambda: grid_elastic(8, 2, "dkt"), "supports.*.stiffness", [1e4, 1e5, 1e6]),
}


def run(scene, path, values, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return sweep(scene, path, values, accuracy=ACC, executor="serial", progress=False, refine_breakpoints=False,
                     **kw)


@pytest.mark.parametrize("case", list(CASES))
def test_each_value_of_a_sweep_is_the_cold_solve_of_its_scene(case):
    make, path, values = CASES[case]
    scene = make()
    r = run(scene, path, values)
    for v, row in zip(values, r.rows):
        assert row["error"] is None and row["status"] == "optimal" and row["kkt"]["ok"], (v, row["error"])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pq.PlateQPWarning)
            cold = pq.solve(set_param(scene, path, v), accuracy=ACC)
        assert cold.kkt.ok
        R = np.asarray(row["reactions"])
        scale = max(np.abs(cold.reactions).max(), 1e-300)
        assert np.abs(R - cold.reactions).max() <= REL * scale, (v, np.abs(R - cold.reactions).max() / scale)
        assert abs(row["w_max"] - cold.to_dict()["w_max"]) <= REL * abs(cold.to_dict()["w_max"]), v
        assert row["active"] == [bool(a) for a in cold.active], v


class _Counted:
    def __init__(self):
        self.n = 0


@pytest.mark.parametrize("case", ["grid gap", "bed gap", "bed load", "grid stiffness"])
def test_a_sweep_scales_its_data_reads_its_qp_and_validates_its_scene_once_not_once_per_value(case, monkeypatch):
    make, path, values = CASES[case]
    scene = make()
    scaled, read, checked = _Counted(), _Counted(), _Counted()
    real_spacing = scaling.contact_spacing  # read by the scaled data's first build alone

    def counting_spacing(*a, **k):
        scaled.n += 1
        return real_spacing(*a, **k)

    class CountingReduced(driver.ReducedQP):
        def __init__(self, *a, **k):
            read.n += 1
            super().__init__(*a, **k)

    real_validate = pq.Scene.validate

    def counting_validate(self):
        checked.n += 1
        return real_validate(self)

    monkeypatch.setattr(scaling, "contact_spacing", counting_spacing)
    monkeypatch.setattr(driver, "ReducedQP", CountingReduced)
    monkeypatch.setattr(pq.Scene, "validate", counting_validate)
    r = run(scene, path, values, backend="pdas")
    assert all(row["status"] == "optimal" for row in r.rows)
    assert scaled.n == 1, f"the scaled data built {scaled.n} times for {len(values)} values"
    # the springs' rows change with a stiffness that goes rigid: the QP is read again there
    assert read.n <= (2 if "stiffness" in case else 1), f"the QP read {read.n} times for {len(values)} values"
    assert checked.n <= 1, f"the scene validated whole {checked.n} times for {len(values)} values"


@pytest.mark.parametrize("case", ["grid load", "bed load", "patch load"])
def test_a_load_sweep_assembles_each_load_once_not_once_per_value(case, monkeypatch):
    from plateqp.model.assembly import Model

    make, path, values = CASES[case]
    scene = make()
    assembled = _Counted()
    real = Model.load_vector

    def counting(self, sc):
        assembled.n += len(sc.loads)
        return real(self, sc)

    monkeypatch.setattr(Model, "load_vector", counting)
    r = run(scene, path, values)
    assert all(row["status"] == "optimal" for row in r.rows)
    assert assembled.n <= len(scene.loads), f"{assembled.n} loads assembled for {len(values)} values"
