"""A half-space held matrix-free (plateqp.contact.pressures): the contact problem in the contact
forces with the soil as an operator, against an independent formulation of the same model (the
soil's settlements as unknowns of K, its dense stiffness H_F⁻¹, solved by block principal
pivoting on the condensed LCP), against Boussinesq's rigid punch at a size the dense route does
not take by default, and its refusals."""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.contact.pipeline import solve_bilateral
from plateqp.errors import ProblemError
from plateqp.model import soil
from plateqp.model.assembly import build_model

E_SOIL, NU_SOIL = 3e7, 0.3


def slab(n=10, P=2e5, gap=0.0, edges=None, supports=(), region=None, load_at=(0.5, 0.6)) -> pq.Scene:
    fnd = dict(model="halfspace", E=E_SOIL, nu=NU_SOIL, gap=gap)
    if region is not None:
        fnd["region"] = region
    return pq.Scene(plate=pq.Plate(a=3.0, b=3.0, h=0.2, E=3e10, nu=0.2), mesh=pq.MeshSpec(nx=n, ny=n),
                    loads=[pq.PointLoad(P=P, x=load_at[0], y=load_at[1])], edges=edges or {},
                    supports=list(supports), foundation=pq.Foundation(**fnd))


@pytest.fixture
def matrix_free(monkeypatch):
    """Every half-space bed on the grid held matrix-free, however small."""
    monkeypatch.setattr(soil, "HALFSPACE_OPERATOR_FROM", 0)


def dense(scene: pq.Scene) -> pq.Result:
    return pq.solve(scene, backend="bpp", formulation="condensed", accuracy=1e-11)


CASES = {
    "floating slab, corner load: the far side lifts off": slab(),
    "heave under the middle (negative gap), clamped left edge": slab(
        gap=-1e-4, edges={"left": "clamped"}),
    "an elastic post beside a bed over part of the plate": slab(
        supports=[pq.Support(2.5, 2.5, gap=0.0, stiffness=5e7)], region=[0.0, 2.0, 0.0, 3.0],
        load_at=(2.2, 1.5)),
}


@pytest.mark.parametrize("name", list(CASES))
def test_the_forces_route_is_the_soil_unknowns_route(name, monkeypatch):
    """The same model two ways: reactions, deflections, the soil's settlements and the gaps agree
    to 1e-8 of their scales, and the matrix-free answer passes its own KKT check."""
    scene = CASES[name]
    ref = dense(scene)
    assert ref.status == pq.Status.OPTIMAL
    monkeypatch.setattr(soil, "HALFSPACE_OPERATOR_FROM", 0)
    res = pq.solve(scene, accuracy=1e-9)
    assert res.model.soil_flexibility is not None and res.model.n_soil == 0
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok and res.backend == "pdas-pcg", res.extras["route"]
    scale_R, scale_w = np.abs(ref.reactions).max(), np.abs(ref.compressions).max()
    np.testing.assert_allclose(res.reactions, ref.reactions, atol=1e-8 * scale_R)
    np.testing.assert_allclose(res.compressions, ref.compressions, atol=1e-8 * scale_w)
    np.testing.assert_allclose(res.gaps, ref.gaps, atol=1e-8 * scale_w)
    np.testing.assert_allclose(res.w_nodes(), ref.w_nodes(), atol=1e-8 * np.abs(ref.w_nodes()).max())
    assert (~res.active).any() or name.startswith("heave")  # lift-off is part of each case but the heave


def test_statics_of_a_floating_slab_on_the_operator(matrix_free):
    """Σ R = P and the moment of R about the origin is the load's (the slab floats: only the soil
    holds it), R ≥ 0, and R·gap = 0 row by row."""
    P = 2e5
    res = pq.solve(slab(n=12, P=P), accuracy=1e-9)
    R, gap, xy = res.reactions, res.gaps, res.model.contacts.xy
    assert R.sum() == pytest.approx(P, rel=1e-9)
    np.testing.assert_allclose(R @ xy, [P * 0.5, P * 0.6], rtol=1e-8)
    assert R.min() >= 0 and gap.min() >= -1e-9 * np.abs(res.compressions).max()
    assert np.abs(R * gap).max() <= 1e-9 * R.max() * np.abs(res.compressions).max()


def test_the_bonded_comparison_is_the_same_system(monkeypatch):
    """The two-sided soil (solve_bilateral) on the operator equals the saddle-point solve on the
    soil's unknowns, and pulls somewhere (the one-sided slab lifts off there)."""
    scene = slab(n=10)
    ref = solve_bilateral(build_model(scene))
    monkeypatch.setattr(soil, "HALFSPACE_OPERATOR_FROM", 0)
    res = solve_bilateral(build_model(scene))
    np.testing.assert_allclose(res.reactions, ref.reactions, atol=1e-8 * np.abs(ref.reactions).max())
    assert res.reactions.min() < 0


@pytest.mark.parametrize("backend, formulation, words", [
    ("bpp", "auto", "backend 'bpp'"), ("clarabel", "primal", "backend 'clarabel'"),
    ("auto", "dual", "formulation 'dual'")])
def test_other_backends_and_formulations_are_refused_in_one_line(matrix_free, backend, formulation, words):
    with pytest.raises(ProblemError, match=words) as exn:
        pq.solve(slab(n=6), backend=backend, formulation=formulation)
    assert "\n" not in str(exn.value)


def test_what_needs_the_soil_as_unknowns_is_refused_not_answered_as_a_rigid_bed(matrix_free):
    """A sensitivity and a QP export read the soil as a matrix: refused, naming the route, never
    a rigid bed's answer (the bed's rows alone carry no soil)."""
    res = pq.solve(slab(n=6), accuracy=1e-8)
    with pytest.raises(ProblemError, match="matrix-free"):
        pq.sensitivity(res, "gaps")
    from plateqp.io.export import contact_qp

    with pytest.raises(ProblemError, match="matrix-free"):
        contact_qp(res.model)


def test_a_rigid_punch_held_matrix_free_settles_as_boussinesq_says():
    """A square plate 1e3 times stiffer than its soil resting on a circular bed of radius a (the
    grid's cells centred in the circle), under a central P, floating: held matrix-free by size
    (more than HALFSPACE_OPERATOR_FROM bed nodes), it settles P (1 − ν²)/(2 a E) (Boussinesq's
    rigid circular punch; Johnson, Contact Mechanics, § 3.2) within 3 %, closer on the finer
    mesh, with Σ R = P."""
    P, a, E_s, nu_s = 1e5, 1.0, 3e7, 0.3
    h = 0.5
    ref = P * (1 - nu_s**2) / (2 * a * E_s)
    errs = []
    for n in (48, 64):
        sc = pq.Scene(plate=pq.Plate(a=2.4, b=2.4, h=h, E=1e3 * E_s * a**3 / h**3, nu=0.2),
                      mesh=pq.MeshSpec(nx=n, ny=n), loads=[pq.PointLoad(P=P, x=1.2, y=1.2)],
                      foundation=pq.Foundation(model="halfspace", E=E_s, nu=nu_s, region={"circle": [1.2, 1.2, a]}))
        res = pq.solve(sc, accuracy=1e-8)
        assert res.model.soil_flexibility is not None and res.model.contacts.m > soil.HALFSPACE_OPERATOR_FROM
        assert res.status == pq.Status.OPTIMAL and res.kkt.ok
        assert res.reactions.sum() == pytest.approx(P, rel=1e-8)
        errs.append(abs(res.deflection(1.2, 1.2) / ref - 1))
    assert errs[1] < 0.03 and errs[1] < errs[0], errs
