"""pdas on plates K does not hold: floating on posts, or free to turn about one held edge.

The condensed method needs ``K⁻¹``; for such a plate pdas (method "auto") first finds the contact
set of the *anchored* plate (each post's dof held by a spring of ``ANCHOR·K_jj``, definite) by
the condensed method's dense steps, then the sparse method's exact steps solve the plate itself
from that set (``extras["first_phase"] == "anchored"``). Before, plain PDAS from every row
active took one factorisation a set (29 at 128² with the plate held on one edge).

References, none of them pdas's own earlier output: Lemke's method on the condensed LCP (an
independent algorithm on another formulation); statics by hand (the total load and its moments
against the posts' reactions plus the held edge's); SciPy's sparse LU for the shifted factor.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from test_pdas_sparse import (
    wall_reactions,  # the held edge's upward forces, from the full stiffness
)

import plateqp as pq
from plateqp.scenes import families as F
from plateqp.model.assembly import build_model
from plateqp.backends.base import QP
from plateqp.backends.pdas import options as pdas_options
from plateqp.backends.pdas.driver import pdas
from plateqp.contact.formulations import Primal
from plateqp.contact.scaling import Scaled
from plateqp.linalg import SchurFactor, bindings

TOTAL = F.Q * F.A * F.A + F.P  # kN: 10 kN/m² on 8 m × 8 m plus the 300 kN column
MOMENT_X = F.Q * F.A**3 / 2 + F.P * F.PX  # Σ load · x
MOMENT_Y = F.Q * F.A**3 / 2 + F.P * F.PY

needs_cholmod = pytest.mark.skipif(not bindings(), reason="the condensed method needs a CHOLMOD binding")


def solve(scene, backend="pdas", formulation="primal", accuracy=1e-10, options=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene, backend=backend, formulation=formulation, accuracy=accuracy, options=options)


def one_edge(n: int, k: int) -> pq.Scene:
    """grid_rigid's slab simply supported on its left edge only: free to turn about it."""
    sc = F.grid_rigid(n, k)
    return pq.Scene(name=f"one-edge-{n}-{k}", plate=sc.plate, mesh=sc.mesh, edges={"left": pq.Edge("simple")},
                    loads=sc.loads, supports=sc.supports)


SCENES = {"floating": lambda: F.floating(16, 9), "one edge": lambda: one_edge(16, 12)}


@pytest.fixture(scope="module", params=sorted(SCENES))
def solved(request):
    sc = SCENES[request.param]()
    return (request.param, sc, solve(sc), solve(sc, options={"anchor_start": False}),
            solve(sc, "lemke", "condensed", "high"))


@needs_cholmod
def test_anchored_first_set_then_exact_steps_agree_with_lemke(solved):
    _, _, res, plain, ref = solved
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert res.extras["method"] == "sparse" and res.extras["first_phase"] == "anchored"
    assert "singular" in res.extras["condensed_skipped"]
    scale = np.abs(ref.reactions).max()
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-8 * scale)
    np.testing.assert_array_equal(res.reactions > 1e-9 * scale, ref.reactions > 1e-9 * scale)
    # plain PDAS (no first set) reaches the same answer, by more factorisations
    assert plain.status == pq.Status.OPTIMAL and plain.extras["first_phase"] == "none"
    np.testing.assert_allclose(plain.reactions, ref.reactions, rtol=0, atol=1e-8 * scale)
    assert res.extras["factorisations"] <= 3 < plain.extras["factorisations"]


@needs_cholmod
def test_exact_steps_on_the_anchored_factorisation_or_their_own(solved):
    """The floating slab's 81 posts cost little as a dense block: its exact steps run on the
    anchored factorisation, trailing block replaced (one sparse factorisation in all); the
    one-edge slab's 144 posts at 16² do not (TRAILING_SHARE): a sparse factorisation of their
    own. Both answers are Lemke's (above); here, each route is taken where it should be, and
    the floating slab's exact steps on a factorisation of their own give the same reactions."""
    name, sc, res, _, ref = solved
    trailing = name == "floating"
    assert (res.extras["factor"] == "trailing") is trailing
    assert res.extras["factorisations"] == (1 if trailing else 2)
    if trailing:  # a sparse factorisation of their own, forced by naming the binding
        binding = {"sksparse": "cholmod", "cvxopt": "cvxopt"}[bindings()[0]]
        other = solve(sc, options={"factor": binding})
        assert other.status == pq.Status.OPTIMAL and other.extras["factor"] == binding
        scale = np.abs(ref.reactions).max()
        np.testing.assert_allclose(other.reactions, res.reactions, rtol=0, atol=1e-9 * scale)


@needs_cholmod
def test_anchored_answer_carries_the_load_by_statics(solved):
    name, _, res, _, _ = solved
    xy = res.model.contacts.xy
    R = res.reactions
    if name == "floating":  # the posts carry everything
        np.testing.assert_allclose(R.sum(), TOTAL, rtol=1e-9)
        np.testing.assert_allclose(R @ xy[:, 0], MOMENT_X, rtol=1e-9)
        np.testing.assert_allclose(R @ xy[:, 1], MOMENT_Y, rtol=1e-9)
    else:  # the left edge (x = 0) carries the rest, up or down: moments about it are the posts' alone
        # (about the x axis the edge's prescribed slopes ∂w/∂y carry moments too: not checked)
        np.testing.assert_allclose(R @ xy[:, 0], MOMENT_X, rtol=1e-9)
        wall, wxy = wall_reactions(res)
        assert np.all(wxy[:, 0] == 0.0)
        np.testing.assert_allclose(R.sum() + wall.sum(), TOTAL, rtol=1e-9)
    assert R.min() >= -1e-10 * R.max()


def _four_posts(n, x):
    """A 1 m slab (n × n) on four corner posts of [0.25, 0.75]², a 10 kN point load at (x, 0.5):
    x = 0.75 puts it on the line of the two posts there."""
    return pq.Scene(name="posts", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(n, n),
                    loads=[pq.PointLoad(10.0, x, 0.5)],
                    supports=[pq.Support(x0, y0) for x0, y0 in [(0.25, 0.25), (0.75, 0.25), (0.75, 0.75), (0.25, 0.75)]])


def _primal_qp(scene, singular, null=False):
    """The primal QP of ``scene`` with the hint ``singular``, and its rigid motions if ``null``."""
    qp = Primal(Scaled.from_model(build_model(scene))).qp
    return QP(P=qp.P, q=qp.q, G=qp.G, h=qp.h, singular=singular, null=qp.null if null else None)


@needs_cholmod
def test_the_singular_hint_only_skips_a_factorisation():
    """Without the hint the condensed factorisation is tried and fails (CHOLMOD stops), and the
    anchored route follows; with a wrong hint on a held plate the anchored route still ends at
    the held plate's answer (the exact steps decide, not the hint)."""
    floating = F.floating(16, 9)
    hinted = pdas(_primal_qp(floating, True), accuracy=1e-10)
    unknown = pdas(_primal_qp(floating, None), accuracy=1e-10)
    for raw in (hinted, unknown):
        assert raw.status == pq.Status.OPTIMAL and raw.extras["first_phase"] == "anchored"
    assert "the QP says so" in hinted.extras["condensed_skipped"]
    assert "the QP says so" not in unknown.extras["condensed_skipped"]
    np.testing.assert_allclose(unknown.z, hinted.z, rtol=0, atol=1e-9 * np.abs(hinted.z).max())

    held = F.grid_rigid(16, 9)
    right = pdas(_primal_qp(held, None), accuracy=1e-10)
    wrong = pdas(_primal_qp(held, True), accuracy=1e-10)
    assert right.extras["method"] == "condensed"
    assert wrong.status == pq.Status.OPTIMAL and wrong.extras["first_phase"] == "anchored"
    np.testing.assert_allclose(wrong.z, right.z, rtol=0, atol=1e-9 * np.abs(right.z).max())


@needs_cholmod
def test_no_anchored_route_where_the_posts_cannot_hold_the_plate():
    """Three collinear posts under a free slab: even held, they leave it free to turn about their
    line, so the anchored plate is singular too (K_oo); pdas says there is no equilibrium."""
    sc = F.floating(16, 9)
    xy = np.array([[2.0, 4.0], [4.0, 4.0], [6.0, 4.0]])
    sc = pq.Scene(name="three-in-a-row", plate=sc.plate, mesh=sc.mesh, loads=sc.loads,
                  supports=[pq.Support(x, y, gap=0.0) for x, y in xy])
    with pytest.raises(pq.NoEquilibriumError):
        solve(sc)


@needs_cholmod
def test_a_shifted_factor_gives_the_anchored_flexibility_and_solve():
    """SchurFactor(shift=a): ``B K̂⁻¹ Bᵀ`` and ``K̂⁻¹ b`` for ``K̂ = K + a·diag(K)`` on the dofs
    ordered last, against SciPy's LU of ``K̂`` (a floating slab: K itself is singular)."""
    m = build_model(F.floating(8, 5))
    K, B = m.K.tocsc(), m.contacts.B.tocsr()
    last = np.unique(B.indices)
    a = 1e-3
    Kd = K.diagonal()
    shift = np.zeros(K.shape[0])
    shift[last] = a * Kd[last]
    Khat = sp.csc_matrix(K + sp.diags(shift))
    fac = SchurFactor(K, last, shift=a)
    ref = B @ spla.spsolve(Khat, B.T.toarray())
    M = fac.flexibility(B, shifted=True)
    np.testing.assert_allclose(M, ref, rtol=0, atol=1e-9 * np.abs(ref).max())
    b = np.random.default_rng(1).standard_normal(K.shape[0])
    x = spla.spsolve(Khat, b)
    np.testing.assert_allclose(fac.solve_shifted(b), x, rtol=0, atol=1e-9 * np.abs(x).max())
    with pytest.raises(ValueError):
        fac.flexibility(B)  # unshifted asked of a shifted factor
    with pytest.raises(ValueError):
        fac.solve(b)


def test_anchor_start_is_an_option():
    assert pdas_options.SETTINGS["anchor_start"] is True
    with pytest.raises(pq.ProblemError):
        solve(F.floating(8, 5), options={"anchor_start": "yes"})


@needs_cholmod
def test_the_final_set_must_hold_a_floating_plate():
    """Four corner posts of [0.25, 0.75]², a point load 1e-10 outside their hull: the anchored
    set (the two posts under the load) leaves the plate free to tip about their line, and the
    load works along that motion, but too little for the first correction of the exact step to
    show it. The final set's check (two inverse iterations with H_A) finds it: unbounded, with
    a ray, as Lemke and BPP say (tests/contact/test_statics.py: exit code 3). Without that check the
    anchored route answered OPTIMAL."""
    sc = _four_posts(8, 0.75 + 1e-10)
    raw = pdas(_primal_qp(sc, True), accuracy="default", trace=True)
    steps = [s["solve"] for s in raw.extras["trace"]]
    assert raw.status == pq.Status.UNBOUNDED and "ray" in raw.extras
    assert steps[0] == "dense" and "singular" in steps  # anchored first, then the motion found
    with pytest.raises(pq.NoEquilibriumError):
        solve(sc, accuracy="default")


@pytest.fixture(scope="module")
def one_edge_every_node():
    """A post on every interior node of a 16² slab held on one edge only, by the sparse method
    (as above ``max_dense`` rows): Lawson–Hanson on the anchored plate's flexibility, and
    plain PDAS, and Lemke."""
    from plateqp.backends.pdas import sparse as pdas_sparse

    sc = one_edge(16, "all")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(pdas_sparse, "LH_ANCHORED", 1e9)  # a loaded machine must not change the path checked
        res = solve(sc, options={"method": "sparse"})
    plain = solve(sc, options={"method": "sparse", "anchor_start": False})
    return res, plain, solve(sc, "lemke", "condensed", "high")


def test_sparse_method_lawson_hanson_on_the_anchored_plate(one_edge_every_node):
    res, plain, ref = one_edge_every_node
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert res.extras["first_phase"] == "anchored lawson-hanson" and "lh_gave_up" not in res.extras
    scale = np.abs(ref.reactions).max()
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-8 * scale)
    assert plain.status == pq.Status.OPTIMAL and plain.extras["first_phase"] == "none"
    np.testing.assert_allclose(plain.reactions, ref.reactions, rtol=0, atol=1e-8 * scale)
    assert res.extras["factorisations"] < plain.extras["factorisations"]
    xy = res.model.contacts.xy
    np.testing.assert_allclose(res.reactions @ xy[:, 0], MOMENT_X, rtol=1e-9)  # about the held edge


def test_anchored_lawson_hanson_giving_up_starts_the_exact_steps_from_its_set(one_edge_every_node, monkeypatch):
    """Lawson–Hanson on the anchored plate out of memory (LH_MEMORY made tiny): the exact steps
    start from the rows it holds and those still pressed, and end at Lemke's answer."""
    from plateqp.backends.pdas import sparse as pdas_sparse

    _, _, ref = one_edge_every_node
    monkeypatch.setattr(pdas_sparse, "LH_MEMORY", 200)
    monkeypatch.setattr(pdas_sparse, "LH_ANCHORED", 1e9)  # a loaded machine must not change the path checked
    monkeypatch.setattr(pdas_sparse, "LH_TIME", 1e9)
    res = solve(one_edge(16, "all"), options={"method": "sparse"})
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert res.extras["first_phase"] == "anchored lawson-hanson (gave up)" and res.extras["lh_gave_up"] == "memory"
    scale = np.abs(ref.reactions).max()
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-8 * scale)


def test_anchored_lawson_hanson_stops_on_a_broad_contact(monkeypatch):
    """A floating slab with a post on every interior node (24²): about 44 % of the rows end in
    contact, one row a Lawson–Hanson step would take hundreds of steps; with 96 rows freed
    more than 30 % are still pressed (LH_ANCHORED_PROBE), so it stops there and the exact
    steps start from its set, ending at Lemke's answer. (Its time budget lifted: on a busy
    machine the wall clock stopped it first, "time".)"""
    from plateqp.backends.pdas import sparse as pdas_sparse

    monkeypatch.setattr(pdas_sparse, "LH_ANCHORED", 1e9)
    monkeypatch.setattr(pdas_sparse, "LH_TIME", 1e9)
    sc = F.grid_rigid(24, "all")
    sc = pq.Scene(name="free-every-node", plate=sc.plate, mesh=sc.mesh, loads=sc.loads, supports=sc.supports)
    res = solve(sc, options={"method": "sparse"})
    ref = solve(sc, "lemke", "condensed", "high")
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert res.extras["first_phase"] == "anchored lawson-hanson (gave up)" and res.extras["lh_gave_up"] == "pressed"
    assert res.extras["lh_sets"] < 200
    scale = np.abs(ref.reactions).max()
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(res.reactions.sum(), TOTAL, rtol=1e-9)


@needs_cholmod
def test_anchored_dense_first_set_by_lawson_hanson():
    """900 posts under a slab held on one edge (32²): every row of the anchored plate starts
    pressed, so Lawson–Hanson's probe waits for LH_ANCHORED_PROBE rows (at LH_PROBE it gave
    up, and dense block steps from ``d < 0`` followed); its set then needs no exchange beyond
    one. Against BPP on the condensed LCP (exact, another algorithm)."""
    sc = one_edge(32, 20)
    res = solve(sc)
    ref = solve(sc, "bpp", "condensed", 1e-10)
    assert res.status == pq.Status.OPTIMAL and res.extras["first_phase"] == "anchored"
    assert res.extras["anchored_first_set"] == "lawson-hanson"
    assert res.extras["factorisations"] == 2
    scale = np.abs(ref.reactions).max()
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * scale)


@needs_cholmod
def test_auto_solves_a_floating_plate_by_pdas_to_a_tight_tolerance():
    """backend="auto", one solve of a floating 128² slab on 5 × 5 posts at accuracy 1e-10: pdas
    on the primal (the condensed LCP that auto took before ended INACCURATE here, KKT 1.7e-10:
    the condensation of a singular K costs digits), OPTIMAL, and the posts carry the load."""
    res = solve(F.floating(128, 5), backend="auto", formulation="auto", accuracy=1e-10)
    assert (res.backend, res.formulation) == ("pdas", "primal")
    assert res.status == pq.Status.OPTIMAL and res.kkt.worst <= 1e-10
    assert res.extras["first_phase"] == "anchored"
    np.testing.assert_allclose(res.reactions.sum(), TOTAL, rtol=1e-9)


def test_the_hold_check_finds_a_free_motion_on_a_woodbury_corrected_factor(monkeypatch):
    """The final set's hold check (``_free_mode``) runs on the factor in hand, also where that is
    a Woodbury correction of another set's factor. Four elastic posts (soft: a stiff row leaving
    is refactorised, its downdate would lose too many digits), three in a line and one off it,
    hold a free slab; the factor of that set corrected by one row (the off-line post leaves) is
    the factor of three collinear posts, which leave the slab free to turn about their line.
    The check must find that motion (statics: w vanishes on the line, K d = 0, B_A d = 0) and
    find none where the four posts hold."""
    from plateqp.backends.pdas import factor as pdas_factor
    from plateqp.backends.pdas.reduced import ReducedQP
    from plateqp.backends.pdas.motions import free_mode as _free_mode

    base = F.floating(16, 9)
    xy = np.array([[2.0, 4.0], [4.0, 4.0], [6.0, 4.0], [4.0, 6.0]])
    sc = pq.Scene(name="three-in-a-row-and-one", plate=base.plate, mesh=base.mesh, loads=base.loads,
                  supports=[pq.Support(x, y, gap=0.0) for x, y in xy])
    pb = ReducedQP(Primal(Scaled.from_model(build_model(sc))).qp, 10**6)
    sigma = 1e-12
    W = 1e-2 * pb.k  # springs a hundred times softer than the plate under them
    monkeypatch.setattr(pdas_factor, "LOWRANK_COST", 1e9)  # a small plate's solve costs as much as its factor
    fac = pdas_factor.SpringFactor(pb.K, pb.B, pb.Kd, pb.c, sigma, "auto")
    four = np.ones(4, dtype=bool)
    fac.set(np.where(four, W, 0.0))
    assert _free_mode(pb, fac, W, four, [], sigma) is None
    three = np.array([True, True, True, False])
    fac.set(np.where(three, W, 0.0))
    assert fac.stats["factorisations"] == 1 and fac.stats["lowrank"] == 1 and not fac.clean
    d = _free_mode(pb, fac, W, three, [], sigma)
    assert d is not None
    scale = np.abs(d).max()
    assert np.abs(pb.B[:3] @ d).max() <= 1e-6 * scale  # w = 0 at the three posts on the line
    assert abs(pb.B[3] @ d) >= 0.1 * scale  # the fourth post's point moves
    assert np.abs(pb.K @ d).max() <= 1e-6 * np.abs(pb.K).max() * scale  # a rigid motion


def test_the_rigid_motions_hold_check_agrees_with_the_inverse_iterations():
    """Where the QP names the plate's rigid motions, the final set's hold check is the rank of
    ``B_A N`` (``rows_hold``, no solve): four posts, three in a line and one off it, hold a free
    slab (and the inverse iterations find no free motion); the three in a line do not (rank 2:
    it gives no verdict, and the inverse iterations find the turn about their line); nor do
    four posts on springs so soft that the least held rigid motion is below the inverse
    iterations' own threshold (they find it free too)."""
    from plateqp.backends.pdas import factor as pdas_factor
    from plateqp.backends.pdas.motions import free_mode, rows_hold
    from plateqp.backends.pdas.reduced import ReducedQP

    base = F.floating(16, 9)
    xy = np.array([[2.0, 4.0], [4.0, 4.0], [6.0, 4.0], [4.0, 6.0]])
    sc = pq.Scene(name="three-in-a-row-and-one", plate=base.plate, mesh=base.mesh, loads=base.loads,
                  supports=[pq.Support(x, y, gap=0.0) for x, y in xy])
    pb = ReducedQP(Primal(Scaled.from_model(build_model(sc))).qp, 10**6)
    assert pb.rigid() is not None and pb.rigid().shape[1] == 3
    sigma = 1e-12
    four, three = np.ones(4, dtype=bool), np.array([True, True, True, False])
    for W, holds in ((1e-2 * pb.k, True), (1e-20 * pb.k, False)):
        fac = pdas_factor.SpringFactor(pb.K, pb.B, pb.Kd, pb.c, sigma, "auto")
        fac.set(np.where(four, W, 0.0))
        assert rows_hold(pb, W, four, sigma) is holds
        assert (free_mode(pb, fac, W, four, [], sigma) is None) is holds
    W = 1e-2 * pb.k
    assert rows_hold(pb, W, three, sigma) is False
    fac = pdas_factor.SpringFactor(pb.K, pb.B, pb.Kd, pb.c, sigma, "auto")
    fac.set(np.where(three, W, 0.0))
    assert free_mode(pb, fac, W, three, [], sigma) is not None
    # a plate whose rigid motions the QP does not name: no verdict
    pb._null, pb._null_checked = None, True
    assert rows_hold(pb, W, four, sigma) is False


@needs_cholmod
def test_trailing_factor_solves_the_active_set_matrix_of_a_floating_plate():
    """The exact steps' factor on the anchored contacts-last factorisation of ``K + σ diag(K)``
    (its trailing block replaced by a dense Cholesky of ``S + B_cᵀ diag(w) B_c``) solves
    ``H(w) = K + σ diag(K) + Bᵀ diag(w) B``, the sparse method's matrix: checked against SciPy's sparse LU
    of that matrix, built from K and B directly, for a set that holds the plate and for one
    that leaves it free to turn (then H(w) is definite by σ alone, and both agree still)."""
    from plateqp.backends.pdas.factor import TrailingFactor
    from plateqp.backends.pdas.reduced import ReducedQP

    pb = ReducedQP(Primal(Scaled.from_model(build_model(F.floating(16, 5)))).qp, 10**6)
    c = np.unique(pb.B.indices)
    sigma = 1e-12
    schur = SchurFactor(pb.K, c, shift=pdas_options.ANCHOR, method=bindings()[0], diagonal=pb.Kd, prox=sigma)
    fac = TrailingFactor(schur, pb.B)
    rng = np.random.default_rng(3)
    b = rng.standard_normal(pb.K.shape[0])
    sig = sigma * pb.Kd
    free = np.zeros(pb.m, dtype=bool)
    free[[0, 1, 2, 3, 4]] = True  # one row of five posts: the plate turns about their line
    for name, A, tol in (("held", rng.random(pb.m) < 0.5, 1e-10), ("free", free, 1e-6)):
        A[0] = A[pb.m - 1] = A[4] = True if name == "held" else A[0]  # three corners: held
        w = np.where(A, 1e8 * pb.k, 0.0)
        fac.set(w)
        H = sp.csc_matrix(pb.K + pb.B.T @ sp.diags(w) @ pb.B + sp.diags(sig))
        ref = spla.spsolve(H, b)
        x = fac.solve(b)
        assert np.abs(x - ref).max() <= tol * np.abs(ref).max(), name
        assert np.abs(H @ x - b).max() <= 1e-13 * abs(H).max() * np.abs(x).max(), name  # backward stable
    assert fac.stats["trailing_factorisations"] == 2 and fac.stats["factorisations"] == 0


@pytest.mark.parametrize("n, d", [(64, 0.0), (64, 1e-10), (128, 0.0), (128, 1e-10)])
def test_a_load_on_the_line_of_two_posts_does_no_work_along_the_turn_about_it(n, d):
    """A point load on the line of two of four posts: the anchored set (those two) leaves the
    slab free to turn about their line. On the line the load does no work along that turn: an
    equilibrium, the lever rule's reactions (5 kN on each of the two). 1e-10 of the slab
    outside it, the load works along it: no equilibrium (unbounded, with a ray: an exact rigid
    motion, P d = 0 to rounding). The turn as the inverse iterations find it carries the
    plate's softest elastic modes at their rounding, which for a point load on its axis is
    all of fᵀd: before FREE_FLOOR the line said unbounded at 64² (4e-12 of Σ|f_j| max|d_j|
    there), and at 128² (2.7e-11) until the QP named the plate's rigid motions (QP.null) and
    the turn was taken as the exact one nearest it. On the line the exact steps' residual has
    no part along the turn to find it by (K u's part along the plate's rigid motions is left out
    of it: :func:`plateqp.backends.pdas.sparse.solve_active`), and none is needed."""
    sc = _four_posts(n, 0.75 + d)
    qp = _primal_qp(sc, True, null=True)
    raw = pdas(qp, accuracy="default", trace=True)
    if d > 0:
        assert "singular" in [s["solve"] for s in raw.extras["trace"]]  # the turn was found and judged
        assert raw.status == pq.Status.UNBOUNDED and "ray" in raw.extras
        ray = raw.extras["ray"]
        assert np.abs(qp.P @ ray).max() <= 1e-12 * abs(qp.P).max() * np.abs(ray).max()  # exact: K d = 0
        assert qp.q @ ray < 0 and np.all(qp.G @ ray <= 1e-12 * np.abs(qp.G @ ray).max())
    else:
        res = solve(sc, accuracy="default")
        assert res.status == pq.Status.OPTIMAL
        np.testing.assert_allclose(res.reactions, [0.0, 5.0, 5.0, 0.0], rtol=0, atol=1e-6 * 10.0)


def test_a_load_just_inside_two_posts_line_does_not_cycle():
    """A point load 1e-10 of the slab inside the line of two of four posts, at 128²: the four
    posts' exact step calls the far two infeasible (their reactions, 1e-9 kN by statics, are
    at the exact step's rounding there), the two left leave the slab free to turn, and the
    load's push along that turn (1e-10 of its work) brought the four back: before, a cycle
    {4} → {3} → {2} → {4} to MAX_ITER. A set left on its exact step is not re-entered by a
    push: the turn is kept out as a free motion, and the answer is the lever rule's."""
    sc = _four_posts(128, 0.75 - 1e-10)
    res = solve(sc, accuracy="default")
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    np.testing.assert_allclose(res.reactions, [0.0, 5.0, 5.0, 0.0], rtol=0, atol=1e-8 * 10.0)


def test_a_wrong_null_space_hint_is_refused():
    """QP.null is a hint: pdas takes it only where K annihilates it to rounding and it is zero
    on the separable (spring) variables; a wrong one (a random vector; a rigid motion with an
    elastic support's variable set) is refused, and the answer is the one without the hint.
    A hint of the wrong shape is a ProblemError."""
    from plateqp.backends.pdas.reduced import ReducedQP
    from plateqp.errors import ProblemError

    sc = F.floating(8, 3)
    qp = Primal(Scaled.from_model(build_model(sc))).qp
    assert qp.null is not None and qp.null.shape[1] == 3
    assert ReducedQP(qp, 10**6).rigid() is not None  # the formulation's own: taken
    wrong = QP(P=qp.P, q=qp.q, G=qp.G, h=qp.h, singular=True,
               null=np.random.default_rng(0).standard_normal(qp.null.shape))
    assert ReducedQP(wrong, 10**6).rigid() is None
    for j in range(3):  # two rigid motions and one that is none: refused whichever column it is
        one_off = qp.null.copy()
        one_off[:, j] = np.random.default_rng(j).standard_normal(qp.null.shape[0])
        assert ReducedQP(QP(P=qp.P, q=qp.q, G=qp.G, h=qp.h, singular=True, null=one_off), 10**6).rigid() is None
    # a rigid motion off by more than rounding in one entry: refused too
    near = qp.null.copy()
    near[near.shape[0] // 2, 1] *= 1 + 1e-6
    assert ReducedQP(QP(P=qp.P, q=qp.q, G=qp.G, h=qp.h, singular=True, null=near), 10**6).rigid() is None
    ref = pdas(_primal_qp(sc, True), accuracy=1e-10)
    out = pdas(wrong, accuracy=1e-10)
    assert out.status == ref.status == pq.Status.OPTIMAL
    np.testing.assert_allclose(out.x, ref.x, rtol=0, atol=1e-9 * np.abs(ref.x).max())
    el = pq.Scene(name="elastic", plate=sc.plate, mesh=sc.mesh, loads=sc.loads,
                  supports=[pq.Support(s.x, s.y, gap=s.gap, stiffness=1e6) for s in sc.supports])
    qe = Primal(Scaled.from_model(build_model(el))).qp
    assert qe.null.shape[0] == qe.P.shape[0]  # P carries the springs' variables too: zero there
    assert np.all(qe.null[-len(sc.supports):] == 0)
    bad = qe.null.copy()
    bad[-1, 0] = 1.0  # a spring's variable moved by a "rigid motion"
    assert ReducedQP(QP(P=qe.P, q=qe.q, G=qe.G, h=qe.h, null=bad), 10**6).rigid() is None
    assert ReducedQP(qe, 10**6).rigid() is not None
    with pytest.raises(ProblemError, match="null"):
        QP(P=qp.P, q=qp.q, G=qp.G, h=qp.h, null=qp.null[:-1])


@pytest.mark.parametrize("n", [32, 64])
def test_the_free_turns_work_is_taken_off_before_the_solve(n):
    """Two posts on the line x = c of a floating slab carry a point load on that line (on an
    element edge), two more posts on one side of it carry nothing: the slab may turn about the
    line, and the exact steps keep that turn out. Statics: the lever rule along the line, the
    far posts idle. Each correction solves with ``K + σD + B_Aᵀ W B_A``, nearly singular along
    the turn; the residual's work along it (rounding of K u, 4e-12) came back from the solve
    multiplied by 1/σ and, projected off after it, left the rest polluted: the residual grew
    tenfold a correction and the answer ended 1.5e-7 off (INACCURATE at 1e-10). With that work
    taken off the right-hand side first the corrections converge."""
    c, y1, y2, y0, P = 41 / 64, 3 / 64, 51 / 64, 0.08083139542683387, 42.0
    sc = pq.Scene(name="line", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n),
                  loads=[pq.PointLoad(P, c, y0)],
                  supports=[pq.Support(c, y1), pq.Support(c, y2), pq.Support(51 / 64, 0.143), pq.Support(51 / 64, 0.407)])
    res = solve(sc, backend="pdas", accuracy=1e-10)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    lever = [P * (y2 - y0) / (y2 - y1), P * (y0 - y1) / (y2 - y1), 0.0, 0.0]
    np.testing.assert_allclose(res.reactions, lever, rtol=0, atol=1e-9 * P)
