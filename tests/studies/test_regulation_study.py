"""The demo's gap-regulation study (the paper's "regulate the interaction forces by changing
the gaps"), checked by an independent solver and by geometry."""

from __future__ import annotations

import json

import numpy as np
import pytest

import plateqp as pq
from plateqp import demo, scenes
from plateqp.demo import regulation as rg
from plateqp.model.paths import set_param

MESH = 8  # supports at 200 cm stay on nodes of 100 cm cells


@pytest.fixture(scope="module")
def study():
    return rg.regulation(set_param(set_param(scenes.load("heave"), "mesh.nx", MESH), "mesh.ny", MESH))


def test_equalise_checked_by_lemke(study):
    eq = study.runs[0]
    assert eq.name == "equalise" and list(eq.supports) == list(rg.FOOT)
    # an independent route: the regulated scene on the condensed LCP by Lemke
    sc = set_param(study.scene, "supports.*.gap", eq.gaps)
    ref = pq.solve(sc, backend="lemke", formulation="condensed")
    R = ref.reactions[list(rg.FOOT)]
    mean = study.before.reactions[list(rg.FOOT)].mean()
    np.testing.assert_allclose(R, mean, rtol=1e-9)
    assert np.ptp(study.before.reactions[list(rg.FOOT)]) > 0.05 * mean  # there was something to equalise
    # statics: the supports carry the whole load (uniform q a b plus the point load)
    p = sc.plate
    load = sum(ld.q * p.a * p.b if isinstance(ld, pq.UniformLoad) else ld.P for ld in sc.loads)
    assert ref.reactions.sum() == pytest.approx(load, rel=1e-10)
    # the unregulated supports kept their gaps
    others = np.setdiff1d(np.arange(len(sc.supports)), rg.FOOT)
    np.testing.assert_array_equal(eq.gaps[others], eq.gaps_before[others])


def test_relevel_is_raising_by_the_heave(study):
    lv = study.runs[1]
    heave = np.array([s.gap for s in study.scene.supports])
    assert set(np.flatnonzero(heave != 0)) == {0, 1, 5} and lv.supports.size == 22
    touching = lv.supports[study.level.reactions[lv.supports] > 1e-9 * study.level.reactions.max()]
    # geometry: every support touching on level ground goes up by exactly the heave (2 mm)
    np.testing.assert_allclose(lv.gaps[touching], heave.min(), rtol=0, atol=1e-9)
    np.testing.assert_allclose(lv.check.reactions, study.level.reactions, rtol=0,
                               atol=1e-9 * study.level.reactions.max())
    assert lv.error <= 1e-9


def test_demo_writes_the_regulation_study(tmp_path, capsys):
    assert demo.run(["regulate"], tmp_path, study_mesh=MESH) == 0
    out = capsys.readouterr().out
    assert "equalise: new gaps under 12, 13, 17, 18" in out  # 1-based support numbers
    written = {p.name for p in tmp_path.iterdir()}
    assert written <= set(demo.output_files(["regulate"])) and "regulate.json" in written
    rep = json.loads((tmp_path / "regulate.json").read_text())
    assert [r["name"] for r in rep["regulations"]] == ["equalise", "re-level"]
    assert rep["regulations"][0]["supports"] == [12, 13, 17, 18]


def test_shim_tolerance_by_finite_differences(study):
    """The study's dR/dg0 among the four regulated supports against re-solving the regulated
    scene with one shim thinner (a finite difference, the contact set found again)."""
    eq = study.runs[0]
    foot = list(rg.FOOT)
    h = 1e-5  # cm: small against the shims (1e-3 … 0.04 cm), far above rounding
    base = pq.solve(set_param(study.scene, "supports.*.gap", eq.gaps), accuracy="high")
    for j, k in enumerate(foot):
        g = eq.gaps.copy()
        g[k] += h
        res = pq.solve(set_param(study.scene, "supports.*.gap", g), accuracy="high")
        fd = (res.reactions[foot] - base.reactions[foot]) / h
        np.testing.assert_allclose(eq.shim[:, j], fd, rtol=1e-6, atol=1e-6 * np.abs(eq.shim).max())
    assert np.all(np.diag(eq.shim) < 0)  # a thinner shim unloads its own support
