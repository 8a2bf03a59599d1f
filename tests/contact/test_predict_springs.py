"""A coarse mesh whose contact rows are all springs (a tensionless bed, elastic posts) is solved
for the prediction by Newton's method on its contact set (plateqp.contact.predict.spring_deflections),
not by the pdas backend: checked against Clarabel's answer to the primal QP of the same coarse
model (an independent formulation and solver), and against the set the pdas route predicts."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.contact import predict as P
from plateqp.estimate import with_mesh
from plateqp.model.assembly import build_model
from plateqp.scenes import families as F

pytest.importorskip("cvxopt")


def tilted_bed(n: int) -> pq.Scene:
    return pq.Scene(name="tilted", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                    edges={}, loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                    foundation=pq.Foundation(2.0e4, gap={"profile": "linear", "g0": 0.0, "gx": 0.004, "gy": 0.002}))


SCENES = {"column bed": lambda n: F.bed(n), "tilted bed": tilted_bed, "elastic posts": lambda n: F.grid_elastic(n, 6)}


@pytest.mark.parametrize("name", SCENES)
def test_newton_on_springs_is_clarabels_answer(name):
    pytest.importorskip("clarabel")
    model = build_model(SCENES[name](16))
    u = P.spring_deflections(model)
    assert u is not None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        ref = pq.solve(model.scene, backend="clarabel", formulation="primal", accuracy=1e-9, model=model)
    nd = model.element.ndof_node
    w, w_ref = model.expand(u)[::nd], ref.u[::nd]
    assert np.max(np.abs(w - w_ref)) <= 1e-6 * np.max(np.abs(w_ref))
    c = model.contacts
    pressed = c.B @ u - c.g0  # a spring's compression where positive
    clear = np.abs(pressed) > 1e-6 * np.abs(pressed).max()  # rows not at the edge of contact
    pressed_ref = c.B @ ref.u[model.free] - c.g0
    assert np.array_equal((pressed > 0)[clear], (pressed_ref > 0)[clear])
    assert 0 < (pressed > 0).sum() < c.m


@pytest.mark.parametrize("name", ["tilted bed", "elastic posts"])
def test_the_prediction_on_springs_asks_no_backend(name, monkeypatch):
    """The fine model's prediction on springs solves its coarse mesh without the pdas backend
    and predicts the set the pdas route predicts."""
    model = build_model(SCENES[name](64))

    def refused(*a, **k):
        raise AssertionError("the coarse prediction asked a backend")

    monkeypatch.setattr(P, "get_backend", refused)
    A, info = P.predicted_set(model)
    assert A is not None and info["rows"] == int(A.sum())
    monkeypatch.undo()
    monkeypatch.setattr(P, "spring_deflections", lambda coarse, start=None: None)  # the pdas route instead
    A_pdas, _ = P.predicted_set(model)
    assert np.array_equal(A, A_pdas)


def test_rigid_rows_are_left_to_pdas():
    """A rigid post is no spring: no Newton step; the pdas route answers."""
    assert P.spring_deflections(build_model(F.grid_rigid(16, 3))) is None


def test_a_coarse_mesh_large_enough_is_solved_by_newton_from_its_own_set(monkeypatch):
    """Where the coarse mesh is large enough for a prediction of its own, Newton's steps solve it
    from that set (a warm start: one factorisation, the few rows it gets wrong by Woodbury), the
    coarsest mesh from every row pressed, and no backend is asked; the set is the one the pdas
    route predicts from the same start (an independent solver of the coarse problem)."""
    monkeypatch.setattr(P, "ROWS_MIN", 100)
    monkeypatch.setattr(P, "COARSE_MIN", 4)
    model = build_model(SCENES["tilted bed"](64))  # coarse 16² (289 rows), its own coarse 4²
    solved = []
    real = P.spring_deflections

    def spy(coarse, start=None):
        solved.append((coarse.scene.mesh.nx, start is None))
        return real(coarse, start)

    def refused(*a, **k):
        raise AssertionError("the coarse prediction asked a backend")

    monkeypatch.setattr(P, "spring_deflections", spy)
    monkeypatch.setattr(P, "get_backend", refused)
    A, info = P.predicted_set(model)
    assert A is not None and info["mesh"] == [16, 16]
    assert solved == [(4, True), (16, False)]
    monkeypatch.undo()
    monkeypatch.setattr(P, "ROWS_MIN", 100)
    monkeypatch.setattr(P, "COARSE_MIN", 4)
    monkeypatch.setattr(P, "spring_deflections", lambda coarse, start=None: real(coarse) if coarse.scene.mesh.nx == 4
                        else None)  # 16² by pdas, from the 4² mesh's set
    A_pdas, _ = P.predicted_set(model)
    assert np.array_equal(A, A_pdas)


def test_newton_from_a_start_factorises_once_and_ends_where_the_cold_start_ends(monkeypatch):
    """Started from the coarser mesh's set, Newton's steps on springs factorise fewer times than
    from every row pressed (a few rows the start gets wrong go by Woodbury) and end at the cold
    start's answer."""
    from plateqp.backends.pdas.factor import SpringFactor

    monkeypatch.setattr(P, "ROWS_MIN", 100)
    monkeypatch.setattr(P, "COARSE_MIN", 4)
    coarse = build_model(SCENES["tilted bed"](16))
    start, _ = P.predicted_set(coarse)  # the 4² mesh's set
    count = {"n": 0}
    real = SpringFactor.refactor

    def counted(self, w):
        count["n"] += 1
        return real(self, w)

    monkeypatch.setattr(SpringFactor, "refactor", counted)
    warm = P.spring_deflections(coarse, start)
    once, count["n"] = count["n"], 0
    cold = P.spring_deflections(coarse)
    assert once < count["n"], (once, count["n"])
    assert np.max(np.abs(warm - cold)) <= 1e-10 * np.max(np.abs(cold))
