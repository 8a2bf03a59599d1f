"""A QP solver that needs a positive definite Hessian (quadprog; ecos through qpsolvers' Cholesky
of P) on a plate its two-sided supports do not hold: its Hessian is only semidefinite in the
primal and condensed formulations and there is no dual one, and the error says so and which
backends take it, before any solve; where the plate is held, every formulation suits it."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.backends import get_backend

DEFINITE_ONLY = [b for b in ("qpsolvers:quadprog", "qpsolvers:ecos") if b in pq.available_backends()]
pytestmark = pytest.mark.skipif(not DEFINITE_ONLY, reason="neither quadprog nor ecos is installed")

PLATE = pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3)


def floating() -> pq.Scene:
    return pq.Scene(name="floating", plate=PLATE, mesh=pq.MeshSpec(8, 8), loads=[pq.UniformLoad(10.0)],
                    supports=[pq.Support(x, y) for x in (0.0, 0.5, 1.0) for y in (0.0, 0.5, 1.0)])


def hinged() -> pq.Scene:
    return pq.Scene(name="hinged", plate=PLATE, mesh=pq.MeshSpec(8, 8), loads=[pq.UniformLoad(10.0)],
                    edges={"left": pq.Edge("simple")},
                    supports=[pq.Support(x, y) for x in (0.5, 1.0) for y in (0.0, 0.5, 1.0)])


@pytest.mark.parametrize("backend", DEFINITE_ONLY)
@pytest.mark.parametrize("make", [floating, hinged])
@pytest.mark.parametrize("formulation", ["primal", "condensed", "auto"])
def test_a_definite_only_solver_on_a_plate_that_is_not_held_says_what_to_use(backend, make, formulation):
    assert get_backend(backend).definite
    with pytest.raises(pq.SolverError) as info:
        pq.solve(make(), backend=backend, formulation=formulation)
    msg = str(info.value)
    assert "\n" not in msg and "positive definite" in msg and "semidefinite" in msg
    assert "formulation='dual'" in msg and "two-sided supports" in msg  # what would make it definite
    assert "pdas" in msg and "lemke" in msg  # and what takes it as it is


@pytest.mark.parametrize("backend", DEFINITE_ONLY)
def test_on_a_held_plate_every_formulation_suits_it(backend):
    scene = pq.Scene(name="held", plate=PLATE, mesh=pq.MeshSpec(8, 8), loads=[pq.UniformLoad(10.0)],
                     edges={e: pq.Edge("simple") for e in ("left", "right", "bottom", "top")},
                     supports=[pq.Support(x, y) for x in (0.25, 0.75) for y in (0.25, 0.75)])
    ref = pq.solve(scene, backend="lemke", formulation="condensed", accuracy="high").reactions
    for formulation in ("primal", "condensed", "dual"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = pq.solve(scene, backend=backend, formulation=formulation)
        if res.status == pq.Status.OPTIMAL:
            np.testing.assert_allclose(res.reactions, ref, rtol=0, atol=1e-5 * np.abs(ref).max())
        else:
            assert not res.kkt.ok
