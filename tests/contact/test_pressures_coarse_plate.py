"""The matrix-free half-space's preconditioner with a coarser plate (plateqp.contact.pressures):
on the fine mesh itself it is the fine Woodbury form, on a coarser one it stays symmetric
positive definite and the route's answer is the dense route's, and where the scene's plate
matters only at long waves the fine plate is solved once per product, not twice per step."""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.contact import pressures
from plateqp.contact.scaling import Scaled
from plateqp.linalg import factor
from plateqp.model import soil
from plateqp.model.assembly import build_model


def slab(n=10, edges=None, supports=(), region=None) -> pq.Scene:
    fnd = dict(model="halfspace", E=3e7, nu=0.3, gap=0.0)
    if region is not None:
        fnd["region"] = region
    return pq.Scene(plate=pq.Plate(a=3.0, b=3.0, h=0.2, E=3e10, nu=0.2), mesh=pq.MeshSpec(nx=n, ny=n),
                    loads=[pq.PointLoad(P=2e5, x=0.5, y=0.6)], edges=edges or {}, supports=list(supports),
                    foundation=pq.Foundation(**fnd))


SCENES = {
    "floating slab": slab(),
    "clamped left edge, a post beside a bed over part of the plate": slab(
        edges={"left": "clamped"}, supports=[pq.Support(2.5, 2.5, gap=0.0, stiffness=5e7)],
        region=[0.0, 2.0, 0.0, 3.0]),
}


@pytest.fixture
def matrix_free(monkeypatch):
    monkeypatch.setattr(soil, "HALFSPACE_OPERATOR_FROM", 0)


def parts(scene):
    model = build_model(scene, soil_operator=True)
    data = Scaled.from_model(model, operator=True)
    return model, data, pressures.soil_fit(model, data)


@pytest.mark.parametrize("name", list(SCENES))
def test_the_coarse_form_on_the_fine_mesh_is_the_fine_woodbury_form(name, matrix_free):
    """Π from the element's interpolation at the rows' points and K̃ from the user's K, both
    scaled here, against the contact data's own B̃ and K̃: the same operator to rounding."""
    model, data, S = parts(SCENES[name])
    same = pressures.two_level(model, data, (10, 10), S)
    fine = pressures._woodbury(S, data.B.tocsr(), data.K)
    V = np.random.default_rng(1).standard_normal((data.m, 3))
    for v in V.T:
        a, b = same(v), fine(v)
        assert np.linalg.norm(a - b) <= 1e-9 * np.linalg.norm(b)


@pytest.mark.parametrize("name", list(SCENES))
def test_the_coarse_form_is_symmetric_positive_definite(name, matrix_free):
    model, data, S = parts(SCENES[name])
    Q = pressures.two_level(model, data, (5, 5), S)
    M = np.column_stack([Q(e) for e in np.eye(data.m)])
    assert np.abs(M - M.T).max() <= 1e-10 * np.abs(M).max()
    assert np.linalg.eigvalsh(0.5 * (M + M.T)).min() > 0


@pytest.mark.parametrize("name", list(SCENES))
def test_the_route_preconditioned_by_a_coarse_plate_answers_as_the_dense_route(name, monkeypatch):
    """Every mesh coarsened (5 × 5 cells under 10 × 10): the same reactions as block principal
    pivoting on the soil's unknowns, and the coarse plate was the one in the preconditioner."""
    scene = SCENES[name]
    ref = pq.solve(scene, backend="bpp", formulation="condensed", accuracy=1e-11)
    monkeypatch.setattr(soil, "HALFSPACE_OPERATOR_FROM", 0)
    monkeypatch.setattr(pressures, "COARSE_MIN", 5)
    monkeypatch.setattr(pressures, "COARSE_WAVES", 1e-6)
    built = []
    real = pressures.two_level
    monkeypatch.setattr(pressures, "two_level", lambda *a: built.append(a[2]) or real(*a))
    res = pq.solve(scene, accuracy=1e-9)
    assert built and built[0] == (5, 5)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok and res.backend == "pdas-pcg", res.extras["route"]
    scale = np.abs(ref.reactions).max()
    assert np.abs(res.reactions - ref.reactions).max() <= 1e-6 * scale


def test_a_plate_that_matters_at_long_waves_only_is_solved_once_a_step(monkeypatch):
    """A thin plate on a soft half-space (the plate is the more compliant below about 9 waves
    per metre, far under what 64² resolves): the solves with the fine plate's size are the
    products' and a few more (the linear term, the recovery), not also one per
    preconditioning."""
    scene = pq.Scene(plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(64, 64, "acm"),
                     edges={"left": "simple", "right": "simple"},
                     loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                     foundation=pq.Foundation(model="halfspace", E=1.0e4, nu=0.3,
                                              gap={"profile": "linear", "g0": 0.0, "gx": 0.004, "gy": 0.0}))
    model = build_model(scene)
    assert model.soil_flexibility is not None
    n = Scaled.from_model(model, operator=True).n
    sizes = []
    raw = factor.Factor._raw
    monkeypatch.setattr(factor.Factor, "_raw", lambda self, b: sizes.append(self.K.shape[0]) or raw(self, b))
    res = pressures.solve_pressures(model, accuracy=1e-8, options={"x0": np.zeros(model.contacts.m)})
    assert res.status == pq.Status.OPTIMAL
    fine = sum(s == n for s in sizes)
    assert res.extras["matvecs"] <= fine <= res.extras["matvecs"] + 12, (fine, res.extras["matvecs"])
