"""The coarse mesh's contact set (plateqp.contact.predict) comes from the coarse problem solved
directly: the backend's answer in the user's units, without the Result, its KKT report or the
fine solve's pipeline around it (the set only starts the fine solve; the exact steps and the fine
KKT check decide the answer). Checked against the whole pipeline's answer on the coarse mesh, an
independent route to the same deflections."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.contact import kkt, predict as P
from plateqp.contact import pipeline
from plateqp.contact.pipeline import solve_contact
from plateqp.estimate import with_mesh
from plateqp.model.assembly import build_model
from plateqp.scenes import families as F

pytest.importorskip("cvxopt")


def _reference_set(model):
    """The set the whole pipeline's coarse answer predicts (its Result's deflection at each
    contact point, against the point's gap)."""
    nx, ny = model.scene.mesh.nx, model.scene.mesh.ny
    coarse_scene = with_mesh(model.scene, round(nx / P.DIVISOR), round(ny / P.DIVISOR))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        res = solve_contact(build_model(coarse_scene), backend="pdas", formulation="primal", accuracy="default")
    c = model.contacts
    on = res.model.grid.locate(c.xy[:, 0], c.xy[:, 1])[0] >= 0
    w = np.full(c.m, -np.inf)
    w[on] = res.deflection(c.xy[on, 0], c.xy[on, 1])
    return w - c.scene_gaps > 0


@pytest.mark.parametrize("scene", [F.bed(32), pq.Scene(
    name="tilted", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(32, 32, "acm"), edges={},
    loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
    foundation=pq.Foundation(2.0e4, gap={"profile": "linear", "g0": 0.0, "gx": 0.004, "gy": 0.002}))],
    ids=["column", "tilted"])
def test_the_coarse_set_is_the_whole_pipelines(scene):
    model = build_model(scene)
    A, info = P.predicted_set(model)
    ref = _reference_set(model)
    assert 0 < ref.sum() <= ref.size
    assert np.array_equal(A, ref)
    assert info["rows"] == int(ref.sum())


def test_the_coarse_solve_makes_no_result_nor_kkt_report(monkeypatch):
    """Only what the start needs: no KKT report and no Result for the coarse answer (the fine
    solve makes its own, once)."""
    model = build_model(F.bed(32))

    def refused(*a, **k):
        raise AssertionError("the coarse prediction built a KKT report")

    monkeypatch.setattr(kkt, "kkt_report", refused)
    monkeypatch.setattr(pipeline, "kkt_report", refused)
    A, info = P.predicted_set(model)
    assert A is not None, info
    assert A.sum() == info["rows"] > 0
