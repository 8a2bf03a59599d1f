"""The standard forms of the contact problem (plateqp.contact.formulations) against dense
references built here from the same scaled data: the condensed stiffness on the contact
deflections is the inverse of the flexibility, ``S = (B K⁻¹ Bᵀ)⁻¹``, its load ``r = S B K⁻¹ f``;
the dual's matrix is ``B K⁻¹ Bᵀ + diag(ρ)`` and its vector ``g0 − B K⁻¹ f`` (K⁻¹ by SciPy's
SuperLU, an independent factorisation); the condensation cache gives a fresh build's answer.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.contact import Scaled
from plateqp.contact.formulations import formulate
from plateqp.scenes.families import family


def dense_reference(d: Scaled):
    """(G = B K⁻¹ Bᵀ, B K⁻¹ f) by SuperLU with dense right-hand sides."""
    lu = spla.splu(d.K.tocsc())
    return d.B @ lu.solve(d.B.T.toarray()), d.B @ lu.solve(d.f)


@pytest.fixture(scope="module")
def held():
    """A slab on four walls with a 5 × 5 grid of rigid posts (ρ = 0): K definite."""
    return Scaled.from_model(build_model(family("grid_rigid", 16, 5)))


def test_condensed_is_the_inverse_flexibility(held):
    d = held
    assert np.all(d.rho == 0)  # rigid: the condensed LCP is (S, r − S g0) itself
    G, wf = dense_reference(d)
    S = np.linalg.inv(G)
    lcp = formulate(d, "condensed").lcp
    np.testing.assert_allclose(lcp.M, S, rtol=0, atol=1e-9 * np.abs(S).max())
    q = S @ (wf - d.g0)
    np.testing.assert_allclose(lcp.q, q, rtol=0, atol=1e-9 * np.abs(q).max())


def test_dual_is_the_flexibility():
    d = Scaled.from_model(build_model(family("grid_elastic", 16, 5)))  # piles: ρ > 0
    assert np.all(d.rho > 0)
    G, wf = dense_reference(d)
    lcp = formulate(d, "dual").lcp
    np.testing.assert_allclose(lcp.M, G + np.diag(d.rho), rtol=0, atol=1e-12 * np.abs(G).max())
    np.testing.assert_allclose(lcp.q, d.g0 - wf, rtol=0, atol=1e-12 * np.abs(d.g0 - wf).max())


def test_condensation_is_reused_across_gap_changes():
    """Same K and B, other gaps: the cached condensation gives the answer of a fresh build."""
    from test_contact import symmetric_scene

    from plateqp.studies import adapt_model, set_param

    sc = symmetric_scene()
    base = build_model(sc)
    first = pq.solve(sc, backend="lemke", formulation="condensed", model=base)
    sc2 = set_param(sc, "supports.5.gap", -2e-3)
    reused = pq.solve(sc2, backend="lemke", formulation="condensed", model=adapt_model(base, sc2))
    fresh = pq.solve(sc2, backend="lemke", formulation="condensed")
    assert not np.allclose(first.reactions, fresh.reactions)
    np.testing.assert_allclose(reused.reactions, fresh.reactions, rtol=1e-10, atol=1e-12)


# -- the dual's flexibility from the trailing block, corrected ------------------------------------

@pytest.fixture(scope="module")
def fine_dual():
    """grid_rigid(32, 15): 225 posts on a 32² slab, where G from the trailing block alone
    (accurate to about cond(K)·ε) is not enough at 1e-10 (measured: KKT 8e-10 with BPP)."""
    sc = family("grid_rigid", 32, 15)
    ref = pq.solve(sc, backend="pdas", formulation="primal", accuracy=1e-10)  # independent formulation
    assert ref.status == pq.Status.OPTIMAL
    return sc, ref


def test_dual_is_corrected_where_its_flexibility_is_not_enough(fine_dual):
    from plateqp.backends import get_backend
    from plateqp.contact.kkt import kkt_report

    sc, ref = fine_dual
    d = Scaled.from_model(build_model(sc))
    form = formulate(d, "dual")
    raw = get_backend("bpp").solve(form.lcp, accuracy=1e-10)
    assert not kkt_report(d, form.recover(raw), 1e-10).ok  # the uncorrected answer fails the check
    res = pq.solve(sc, backend="bpp", formulation="dual", accuracy=1e-10)
    assert res.status == pq.Status.OPTIMAL and res.kkt.worst <= 1e-10
    assert 1 <= res.extras["corrections"] <= 3
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())


def test_export_hands_the_exact_flexibility(fine_dual):
    """The exported dual is all another solver sees: its exact solution passes at 1e-10 with no
    correction (from the trailing block's G it fails: the test above)."""
    from plateqp.backends import get_backend
    from plateqp.backends.base import LCP
    from plateqp.io import contact_qp

    sc, ref = fine_dual
    exp = contact_qp(sc, "dual")
    raw = get_backend("bpp").solve(LCP(exp.qp.P, exp.qp.q), accuracy=1e-10)
    res = exp.result(raw.x, accuracy=1e-10, solver="bpp")
    assert res.status == pq.Status.OPTIMAL
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())


class _Sloppy:
    """BPP with every reaction then scaled by 1 + 1e-7, claiming optimal: the backend's own error."""

    name = "test-sloppy"
    accepts = frozenset({"lcp"})
    warm_start = False

    def available(self):
        return True

    def version(self):
        return "0"

    def solve(self, problem, accuracy="default", options=None):
        from plateqp.backends import get_backend

        raw = get_backend("bpp").solve(problem, accuracy=accuracy)
        raw.x = raw.x * (1 + 1e-7)
        raw.w = problem.M @ raw.x + problem.q
        return raw


def test_dual_correction_leaves_a_backends_own_error_alone(fine_dual):
    """The correction removes G's error, not the backend's: the sloppy answer stays INACCURATE,
    and no re-solve is spent on it (the gaps' error explains too little of the residual)."""
    from plateqp.backends import registry

    sc, _ = fine_dual
    reg = registry()
    reg[_Sloppy.name] = _Sloppy()
    try:
        with pytest.warns(pq.PlateQPWarning, match="inaccurate"):
            res = pq.solve(sc, backend=_Sloppy.name, formulation="dual", accuracy=1e-10)
    finally:
        del reg[_Sloppy.name]
    assert res.status == pq.Status.INACCURATE and res.kkt.worst > 1e-8
    assert res.extras["corrections"] == 0


def test_dual_recovers_u_by_one_solve_where_the_posts_carry_the_load():
    """A simply supported 32² slab on 31 × 31 posts, heave in one corner: the posts carry nearly
    all the load, so u0 = K⁻¹f and K⁻¹BᵀR are both far larger than u. Recovered as their
    difference, the rounding of each left stationarity at 4e-10 (scaled by the load's own
    deflection over the plate's, as kkt_report does); from one solve with f − BᵀR it is at
    rounding. The reactions are PDAS's on the primal (an independent formulation)."""
    xs = np.round(np.linspace(1 / 32, 31 / 32, 31) * 32) / 32
    sc = pq.Scene(name="posts", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(32, 32, "acm"),
                  edges={k: "simple" for k in ("left", "right", "bottom", "top")},
                  loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.7, 0.6)],
                  supports=[pq.Support(float(x), float(y), gap=float(2e-4 * (x + y - 1))) for x in xs for y in xs])
    res = pq.solve(sc, backend="bpp", formulation="dual", accuracy=1e-10)
    ref = pq.solve(sc, backend="pdas", formulation="primal", accuracy=1e-10)
    assert res.status == ref.status == pq.Status.OPTIMAL
    assert res.kkt.stationarity <= 1e-13
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-10 * np.abs(ref.reactions).max())


class _Flaky:
    """BPP on the first call; then a solver that fails (``mode``): an error, no answer, NaNs."""

    name = "test-flaky"
    accepts = frozenset({"lcp"})
    warm_start = False

    def __init__(self, mode):
        self.mode, self.calls = mode, 0

    def available(self):
        return True

    def version(self):
        return "0"

    def solve(self, problem, accuracy="default", options=None):
        from plateqp.backends import get_backend
        from plateqp.backends.base import RawSolution, Status

        self.calls += 1
        if self.calls == 1:
            return get_backend("bpp").solve(problem, accuracy=accuracy)
        if self.mode == "raise":
            raise pq.SolverError("the flaky solver gave up")
        if self.mode == "none":
            return RawSolution(status=Status.ERROR, solver_status="gave up")
        return RawSolution(status=Status.OPTIMAL, x=np.full(problem.n, np.nan), solver_status="solved (NaN)")


@pytest.mark.parametrize("mode", ["raise", "none", "nan"])
def test_a_failed_correction_keeps_the_answer_in_hand(fine_dual, mode):
    """The first answer fails the check by G's error (see above); the re-solve fails: the first
    answer is returned, INACCURATE with its own residuals, and the failure is said."""
    from plateqp.backends import registry

    sc, ref = fine_dual
    reg = registry()
    reg[_Flaky.name] = flaky = _Flaky(mode)
    try:
        with pytest.warns(pq.PlateQPWarning, match="inaccurate"):
            res = pq.solve(sc, backend=_Flaky.name, formulation="dual", accuracy=1e-10)
    finally:
        del reg[_Flaky.name]
    assert flaky.calls == 2
    assert res.status == pq.Status.INACCURATE and np.isfinite(res.kkt.worst)
    assert res.extras["corrections"] == 0 and res.extras["correction_failed"]
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-8 * np.abs(ref.reactions).max())
