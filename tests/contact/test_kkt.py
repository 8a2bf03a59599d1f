"""The KKT check of a contact answer (plateqp.contact.kkt), against exact references.

* the local stiffness of the natural residual bounds the exact condensed stiffness
  ``(M⁻¹)_ii``, ``M = B K⁻¹ Bᵀ + diag(ρ)`` (K⁻¹ by SciPy's SuperLU), on every mesh;
* an exact answer (Lemke on the condensed LCP, statics-checked elsewhere) passes a tight
  tolerance, and the same answer with one reaction moved by 1e-6 of the largest fails it
  (stationarity), and so does a reaction of that size at an open gap with the deflections kept
  in equilibrium (natural residual).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from plateqp.model.assembly import build_model
from plateqp.backends import get_backend
from plateqp.contact import Scaled
from plateqp.contact.formulations import ContactSolution, formulate
from plateqp.contact.kkt import kkt_report
from plateqp.scenes.families import family


@pytest.mark.parametrize("k", [3, 7])
def test_local_stiffness_bounds_the_exact_one_at_every_mesh(k):
    """The natural residual's stiffness k_i against the exact one, (M⁻¹)_ii with M = B K⁻¹ Bᵀ + ρ
    (support i pushed, every other contact point held): an upper bound on every mesh (the
    residual stays conservative) by a factor that does not grow as the mesh is refined (Σ B² diag K
    alone grows 4× per halving)."""
    import scipy.sparse.linalg as spla

    from plateqp.model.assembly import build_model
    from plateqp.scenes.families import family
    from plateqp.contact import Scaled
    from plateqp.contact.kkt import local_stiffness

    worst = {}
    for n in (16, 32, 64):
        d = Scaled.from_model(build_model(family("grid_rigid", n, k)))
        X = spla.splu(d.K.tocsc()).solve(d.B.T.toarray())
        exact = np.diag(np.linalg.inv(d.B @ X + np.diag(d.rho)))
        ratio = local_stiffness(d) / exact
        assert ratio.min() >= 1.0
        worst[n] = ratio.max()
    assert worst[64] <= 10.0 and worst[64] <= 1.5 * worst[16]


@pytest.mark.parametrize("family_name", ["grid_rigid", "grid_elastic"])
def test_exact_answer_passes_and_a_moved_reaction_fails(family_name):
    d = Scaled.from_model(build_model(family(family_name, 16, 5)))
    # the condensed LCP, not the dual: the dual's flexibility carries its factor's rounding, and
    # its answer before the pipeline's correction re-solve had a natural residual of 1.02e-10 on
    # grid_rigid on an AMD EPYC machine (Lemke and BPP alike); the condensed one's was 5e-15
    form = formulate(d, "condensed")
    c = form.recover(get_backend("lemke").solve(form.problem(frozenset({"lcp"})), accuracy="high"))
    exact = kkt_report(d, c, 1e-10)
    assert exact.worst <= 1e-10
    on = np.flatnonzero(c.R > 0)
    assert 0 < on.size < d.m  # a real contact problem
    i = on[np.argmax(c.R[on])]
    for sign in (1.0, -1.0):
        R = c.R.copy()
        R[i] += sign * 1e-6 * c.R.max()
        moved = kkt_report(d, ContactSolution(c.u, R, d.rho * R), 1e-10)
        assert moved.stationarity > 1e-8, moved
    # a reaction at an open gap, the deflections kept in equilibrium with it (K⁻¹ by SuperLU):
    # only the complementarity conditions can see it, in force units (natural residual)
    j = np.flatnonzero(c.R == 0)[0]
    R = c.R.copy()
    R[j] = 1e-6 * c.R.max()
    u = c.u - spla.splu(d.K.tocsc()).solve(d.B[[j]].T.toarray().ravel() * R[j])
    pushed = kkt_report(d, ContactSolution(u, R, d.rho * R), 1e-10)
    assert pushed.stationarity <= 1e-10 and pushed.natural > 1e-8, pushed


def _open_scene():
    """A simply supported square over two posts whose gaps are 1.5 × the plate's deflection there:
    nothing touches (the two-sided plate's deflection, Navier's, stays above them)."""
    import plateqp as pq

    plate = pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3)
    w_mid = 0.00406235 / plate.D  # Navier, q = 1
    return pq.Scene(name="open", plate=plate, mesh=pq.MeshSpec(8, 8), edges={"all": "simple"},
                    loads=[pq.UniformLoad(1.0)],
                    supports=[pq.Support(0.5, 0.5, gap=1.5 * w_mid), pq.Support(0.25, 0.25, gap=1.5 * w_mid)])


@pytest.mark.parametrize("backend", ["clarabel", "qpsolvers:piqp", "osqp", "pdas"])
@pytest.mark.parametrize("accuracy", ["default", "high"])
def test_nothing_touches_is_not_inaccurate(backend, accuracy):
    """Interior-point solvers leave ~1e-13 of the load at open supports; judged against the
    largest reaction (itself that noise) every such scene came back INACCURATE."""
    import plateqp as pq
    from plateqp.backends import registry

    if backend not in registry() or not registry()[backend].available():
        pytest.skip(f"{backend} not installed")
    res = pq.solve(_open_scene(), backend=backend, formulation="primal", accuracy=accuracy)
    assert res.status.value == "optimal" and res.kkt.ok, res.kkt
    assert not res.active.any()
    np.testing.assert_allclose(res.reactions, 0.0, atol=1e-9 * 1.0)  # the load is q a b = 1


def test_nothing_touches_still_sees_wrong_answers():
    """Where nothing touches the reactions are judged against the load, and still: a reaction of
    10 × tol of the load at an open support, or an open support left penetrated, fails."""
    d = Scaled.from_model(build_model(_open_scene()))
    form = formulate(d, "dual")
    c = form.recover(get_backend("lemke").solve(form.problem(frozenset({"lcp"})), accuracy="high"))
    assert not (c.R > 0).any() and kkt_report(d, c, 1e-9).worst <= 1e-9
    load = np.abs(d.f).sum()
    R = c.R.copy()
    R[0] = 10 * 1e-9 * load
    u = c.u - spla.splu(d.K.tocsc()).solve(d.B[[0]].T.toarray().ravel() * R[0])  # kept in equilibrium
    assert kkt_report(d, ContactSolution(u, R, d.rho * R), 1e-9).natural > 1e-9
    # a plate pushed through the support at 0 (its gap closed and passed), reactions zero
    g = d.B[[0]] @ c.u
    u = c.u * (1.0 + 2.0 * (d.g0[0] - g[0]) / g[0])  # the deflection scaled past the gap
    assert kkt_report(d, ContactSolution(u, c.R, d.rho * c.R), 1e-9).worst > 1e-6


def test_small_reactions_are_judged_against_themselves():
    """A post that carries 1e-3 of the load: an error of 1e-6 of its reaction at the other post
    (kept in equilibrium) is a 1e-6 error of the reactions, though only 1e-9 of the load."""
    sc = _open_scene()
    w_mid = sc.supports[0].gap / 1.5
    sc.supports[0].gap = 0.999 * w_mid  # the centre post just touches
    d = Scaled.from_model(build_model(sc))
    form = formulate(d, "dual")
    c = form.recover(get_backend("lemke").solve(form.problem(frozenset({"lcp"})), accuracy="high"))
    load = np.abs(d.f).sum()
    assert c.R[0] > 0 and c.R[1] == 0 and c.R[0] < 1e-2 * load  # a small share of the load
    R = c.R.copy()
    R[1] = 1e-6 * c.R[0]
    u = c.u - spla.splu(d.K.tocsc()).solve(d.B[[1]].T.toarray().ravel() * R[1])
    assert kkt_report(d, ContactSolution(u, R, d.rho * R), 1e-9).natural > 1e-7


def test_an_accuracy_below_the_rounding_floor_is_said_to_be_so():
    """Asked 1e-14 on a 32² plate (below what a double-precision answer can show there), pdas's exact answer is
    INACCURATE with its stationarity at or below the floor ε‖|K||u| + |f| + |Bᵀ||R|‖ (the
    Oettli–Prager bound), and the warning says so and what to ask instead; an answer moved
    off the exact one by 1e-8 is above its floor and no such thing is said."""
    import warnings

    import plateqp as pq

    sc = family("grid_rigid", 32, 3)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        res = pq.solve(sc, backend="pdas", accuracy=1e-14)
    assert res.status == pq.Status.INACCURATE
    rep = res.kkt
    assert 1e-14 < rep.floor < 1e-12 and rep.stationarity <= rep.floor and rep.at_floor
    said = " ".join(str(w.message) for w in seen)
    assert "rounding floor" in said and "ask 1e-" in said
    d = Scaled.from_model(res.model)
    exact = pq.solve(sc, backend="pdas", accuracy=1e-10)
    form = formulate(d, "primal")
    raw = get_backend("pdas").solve(form.problem(frozenset({"qp"})), accuracy="high")
    c = form.recover(raw)
    moved = kkt_report(d, ContactSolution(c.u * (1 + 1e-8), c.R, c.s), 1e-14)
    assert exact.status == pq.Status.OPTIMAL and not moved.at_floor and moved.stationarity > 10 * moved.floor


@pytest.mark.parametrize("n, held", [(16, False), (64, True)])
def test_a_load_on_a_post_is_not_inaccurate_and_a_pressed_post_still_fails(n, held):
    """A point load exactly on one of four posts: by statics that post carries all of it and the
    plate does not bend (its deflection is rounding: 1e-18 to 1e-25 m). The gap residuals were
    judged against that deflection, and pdas's exact answer (reactions (P, 0, 0, 0) to the
    digit) came back INACCURATE at 1e-6 (primal residual 2e-4 to 0.34: a gap error of 1e-22 m).
    A gap error below what the stationarity's rounding floor can move the plate by (floor ×
    the load's deflection scale), divided by the accuracy asked, is not resolvable: the
    deflection scale is at least that. Now OPTIMAL at 1e-6 and 1e-10, and the same answer with
    the plate pressed 1e-12 of the load's deflection scale into the idle posts still fails."""
    import plateqp as pq

    P = 10.0
    sc = pq.Scene(name="on a post", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n),
                  loads=[pq.PointLoad(P, 0.5, 0.5)], edges={"left": pq.Edge("simple")} if held else {},
                  supports=[pq.Support(0.5, 0.5), pq.Support(0.25, 0.25), pq.Support(0.75, 0.25),
                            pq.Support(0.5, 0.8)])
    for accuracy in ("default", 1e-10):
        res = pq.solve(sc, backend="pdas", accuracy=accuracy)
        assert res.status == pq.Status.OPTIMAL and res.kkt.ok, res.kkt
        np.testing.assert_allclose(res.reactions, [P, 0, 0, 0], rtol=0, atol=1e-9 * P)
    d = Scaled.from_model(build_model(sc))
    form = formulate(d, "primal")
    c = form.recover(get_backend("pdas").solve(form.problem(frozenset({"qp"})), accuracy=1e-10))
    assert kkt_report(d, c, 1e-10).ok
    worst = 0.0
    for sign in (1.0, -1.0):  # the plate moved by 1e-12 w_load at every node, one way: into the idle posts
        u = c.u + sign * 1e-12 * d.w_load * d.is_w
        worst = max(worst, kkt_report(d, ContactSolution(u, c.R, c.s), 1e-6).primal)
    assert worst > 1e-6


def test_the_total_reaction_of_a_floating_bed_is_the_load_and_the_check_sees_it():
    """A free slab on a tensionless bed at 128², asked 1e-10: the reactions sum to the load
    (statics, exact for the element). The slab sinks into the bed as a body, and K u's rounding
    along that motion (ε Vᵀ|K||u|, 3e-9 of the load) had passed into pdas's reactions: they were
    1.3e-9 short of the load while the stationarity norm over every dof said 1.3e-11, and the
    answer was OPTIMAL. Now pdas's exact steps leave K u's part along the rigid motions out of
    their residual, and the KKT check holds the statics: the same shortfall spread over the
    springs (δ each, m δ = 1e-9 of the load) fails it, though the norm moves by only √m δ."""
    import plateqp as pq
    from plateqp.scenes.families import bed, total_load

    sc = bed(128)
    load = total_load(sc)
    res = pq.solve(sc, accuracy=1e-10)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert abs(res.reactions.sum() - load) <= 1e-12 * load
    d = Scaled.from_model(res.model)
    u = res.u[res.model.free] / d.dof_scale
    R = res.reactions / d.F0
    s = res.compressions / d.W
    short = 1e-9 * R.sum() / R.size
    fine, off = (kkt_report(d, ContactSolution(u, R - x, s), 1e-10) for x in (0.0, short))
    assert fine.ok
    assert off.stationarity >= 0.9e-9 and not off.ok
    norm = np.linalg.norm(d.K @ u - d.f + d.B.T @ (R - short)) / max(np.linalg.norm(d.f), np.linalg.norm(d.B.T @ R))
    assert norm <= 1e-10  # what the norm alone would have said
