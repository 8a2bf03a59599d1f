"""Tests of the matrix-free bound- and equality-constrained QP solver (plateqp.backends.mprgp).

References used (never the code's own earlier output):

* Clarabel, an interior-point solver called here on the same QP written out in its own cone form;
* block principal pivoting (plateqp.backends.bpp), a direct method, on the LCP of the QP with
  ``lb = 0`` and no equality;
* ``numpy.linalg.solve`` where no bound is active (the QP is then a linear system);
* the KKT conditions checked by their definitions: ``x ≥ lb``, ``g = Mx + q − Gα ≥ 0`` where
  ``x`` is at its bound, ``g = 0`` where it is free, ``Gᵀx = b``;
* problems with a hand-proved absence of solution (a ray of descent, infeasible equalities).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.sparse as sp

from plateqp.backends.base import Status
from plateqp.backends.bpp import bpp
from plateqp.backends.mprgp import BoundQPResult, solve_bound_qp
from plateqp.errors import ProblemError

clarabel = pytest.importorskip("clarabel")


# ----------------------------------------------------------------------------- references


def clarabel_reference(M, q, lb, G=None, b=None):
    """min ½xᵀMx + qᵀx, x ≥ lb (finite entries only), Gᵀx = b, by Clarabel at tight tolerances."""
    m = len(q)
    lb = np.broadcast_to(np.asarray(lb, float), (m,))
    bounded = np.flatnonzero(np.isfinite(lb))
    rows, rhs, cones = [], [], []
    if G is not None and G.shape[1]:
        rows.append(sp.csc_matrix(G.T))
        rhs.append(np.asarray(b, float))
        cones.append(clarabel.ZeroConeT(G.shape[1]))
    if bounded.size:
        rows.append(-sp.eye(m, format="csc")[bounded])  # −x + s = −lb, s ≥ 0
        rhs.append(-lb[bounded])
        cones.append(clarabel.NonnegativeConeT(bounded.size))
    A = sp.vstack(rows, format="csc") if rows else sp.csc_matrix((0, m))
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = 1e-10
    settings.max_iter = 500
    solver = clarabel.DefaultSolver(sp.triu(sp.csc_matrix(M), format="csc"), q, A,
                                    np.concatenate(rhs) if rhs else np.zeros(0), cones, settings)
    sol = solver.solve()
    # Clarabel 0.9 (the oldest the project allows) stops short of 1e-10 on some of these
    # ("InsufficientProgress") with an answer whose active set is right: refined() solves the KKT
    # system on that set exactly and checks it, so a wrong set cannot pass either way
    assert str(sol.status) in ("Solved", "AlmostSolved", "InsufficientProgress"), sol.status
    x, z = np.array(sol.x), np.array(sol.z)[len(rhs[0]) if G is not None and G.shape[1] else 0:]
    slack = np.full(m, np.inf)
    dual = np.zeros(m)
    slack[bounded], dual[bounded] = x[bounded] - lb[bounded], z
    return refined(M, q, lb, G, b, x, slack <= dual)


def refined(M, q, lb, G, b, x, A):
    """The interior point's answer made exact: its active set ``A`` (where the bound's multiplier
    exceeds the slack) and the KKT system on it solved directly, the answer then
    checked (feasible, multipliers of the bounds ≥ 0) so that a wrong active set cannot pass."""
    m = len(q)
    G = np.zeros((m, 0)) if G is None else G
    b = np.zeros(0) if b is None else np.asarray(b, float)
    scale = max(1.0, np.abs(x).max())
    F = ~A
    k = G.shape[1]
    xs = np.where(A, lb, 0.0)
    K = np.block([[M[np.ix_(F, F)], G[F]], [G[F].T, np.zeros((k, k))]])
    rhs = np.concatenate([-q[F] - M[np.ix_(F, A)] @ xs[A], b - G[A].T @ xs[A]])
    sol = np.linalg.lstsq(K, rhs, rcond=None)[0]
    xs[F] = sol[: F.sum()]
    alpha = -sol[F.sum():]
    g = M @ xs + q - G @ alpha
    tiny = 1e-9 * max(np.linalg.norm(q), np.linalg.norm(M @ xs))
    assert np.all(xs[F] >= lb[F] - 1e-9 * scale) and np.all(g[A] >= -tiny), "the reference's active set is wrong"
    return np.maximum(xs, lb)


def assert_kkt(M, q, lb, G, b, res: BoundQPResult, rtol=1e-7):
    """The KKT conditions of the QP, each by its definition, from M itself (not from res.g)."""
    m = len(q)
    lb = np.broadcast_to(np.asarray(lb, float), (m,))
    G = np.zeros((m, 0)) if G is None else G
    b = np.zeros(0) if b is None else np.asarray(b, float)
    x = res.x
    g = M @ x + q - G @ res.alpha
    scale = max(np.linalg.norm(q), np.linalg.norm(M @ x), np.linalg.norm(G @ res.alpha))
    assert res.alpha.shape == (G.shape[1],)
    assert np.allclose(res.g, g, atol=rtol * scale)
    assert np.all(x >= lb), "a bound violated"
    at = np.isfinite(lb) & (x == lb)
    assert np.all(g[at] >= -rtol * scale), "a multiplier of a bound negative"
    assert np.all(np.abs(g[~at]) <= rtol * scale), "stationarity at a free component"
    if G.shape[1]:
        assert np.linalg.norm(G.T @ x - b) <= rtol * max(np.linalg.norm(b), np.linalg.norm(G, 2) * np.linalg.norm(x))


def counted(M):
    """M as a matvec, with the number of calls kept."""
    calls = [0]

    def matvec(v):
        calls[0] += 1
        return M @ v

    return matvec, calls


def spd(m, rng, cond=None):
    Q, _ = np.linalg.qr(rng.standard_normal((m, m)))
    eig = rng.uniform(0.5, 2.0, m) if cond is None else np.geomspace(1.0, cond, m)
    return (Q * eig) @ Q.T


def psd_with_null(m, k, rng):
    """PSD M whose null space is range(G), G random (m × k): M is definite on null(Gᵀ) (a floating plate)."""
    G = rng.standard_normal((m, k))
    P = np.eye(m) - G @ np.linalg.pinv(G)
    M = P @ spd(m, rng) @ P
    return (M + M.T) / 2, G


def random_lb(m, rng, mixed):
    return np.where(rng.random(m) < 0.5, -np.inf, 0.0) if mixed else 0.0


# ----------------------------------------------------------------------------- 1. against references


CASES = [(m, k, mixed) for m in (5, 37, 200) for k in (0, 1, 3) for mixed in (False, True)]


@pytest.mark.parametrize("m, k, mixed", CASES)
def test_spd_problems_match_clarabel_and_satisfy_kkt(m, k, mixed):
    rng = np.random.default_rng(1000 * m + 10 * k + mixed)
    M = spd(m, rng)
    q = rng.standard_normal(m)
    lb = random_lb(m, rng, mixed)
    G = rng.standard_normal((m, k)) if k else None
    # b from a point that is feasible for the bounds, so that the QP has a solution
    b = G.T @ np.abs(rng.standard_normal(m)) if k else None
    res = solve_bound_qp(lambda v: M @ v, q, lb=lb, G=G, b=b, tol=1e-10)
    assert res.status == "optimal", res.message
    ref = clarabel_reference(M, q, lb, G, b)
    assert np.linalg.norm(res.x - ref) <= 1e-7 * max(np.linalg.norm(ref), 1.0)
    assert_kkt(M, q, lb, G, b, res)


@pytest.mark.parametrize("m, k, mixed", [(m, k, mixed) for m in (6, 40, 150) for k in (1, 2, 3) for mixed in (False, True)])
def test_floating_psd_problems_match_clarabel(m, k, mixed):
    """M singular, its null space the span of G's columns (a floating plate): the equality makes the
    solution unique."""
    rng = np.random.default_rng(7 + 100 * m + k + 1000 * mixed)
    M, G = psd_with_null(m, k, rng)
    q = rng.standard_normal(m)
    lb = random_lb(m, rng, mixed)
    b = G.T @ np.abs(rng.standard_normal(m))
    res = solve_bound_qp(lambda v: M @ v, q, lb=lb, G=G, b=b, tol=1e-10)
    assert res.status == "optimal", res.message
    ref = clarabel_reference(M, q, lb, G, b)
    assert np.linalg.norm(res.x - ref) <= 1e-7 * max(np.linalg.norm(ref), 1.0)
    assert_kkt(M, q, lb, G, b, res)


@pytest.mark.parametrize("m", [5, 60, 200])
def test_lcp_problems_match_block_principal_pivoting(m):
    rng = np.random.default_rng(m)
    M = spd(m, rng)
    q = rng.standard_normal(m)
    ref = bpp(M, q, accuracy="high")
    assert ref.status == Status.OPTIMAL
    res = solve_bound_qp(lambda v: M @ v, q, tol=1e-10)
    assert res.status == "optimal", res.message
    assert np.linalg.norm(res.x - ref.x) <= 1e-7 * np.linalg.norm(ref.x)
    assert_kkt(M, q, 0.0, None, None, res)


def test_psd_lcp_without_equality_reaches_the_optimal_value():
    """M singular, no equality: x is not unique, the optimal value is (Clarabel's)."""
    rng = np.random.default_rng(3)
    B = rng.standard_normal((40, 25))
    M = B @ B.T / 25
    q = rng.standard_normal(40) + M @ rng.standard_normal(40)
    q = np.abs(q) * np.where(rng.random(40) < 0.3, -1, 1)
    ref = clarabel_reference(M, q, 0.0)
    res = solve_bound_qp(lambda v: M @ v, q, tol=1e-10)
    assert res.status == "optimal", res.message

    def f(x):
        return 0.5 * x @ M @ x + q @ x

    assert abs(f(res.x) - f(ref)) <= 1e-8 * max(1.0, abs(f(ref)))
    assert_kkt(M, q, 0.0, None, None, res)


def test_matvec_count_is_reported_and_callback_sees_every_iteration():
    rng = np.random.default_rng(11)
    M = spd(50, rng)
    q = rng.standard_normal(50)
    matvec, calls = counted(M)
    seen = []
    res = solve_bound_qp(matvec, q, callback=lambda it, x: seen.append((it, x.copy())))
    assert res.status == "optimal"
    assert res.matvecs == calls[0]
    assert [it for it, _ in seen] == list(range(1, res.iterations + 1))
    assert all(np.all(x >= 0) for _, x in seen)


def test_warm_start_is_projected_and_the_solution_itself_needs_no_step():
    rng = np.random.default_rng(12)
    M = spd(80, rng)
    q = rng.standard_normal(80)
    cold = solve_bound_qp(lambda v: M @ v, q, tol=1e-10)
    warm = solve_bound_qp(lambda v: M @ v, q, tol=1e-8, x0=cold.x)
    assert warm.status == "optimal" and warm.iterations == 0
    x0 = cold.x + 0.01 * rng.standard_normal(80)  # some entries below the bound
    res = solve_bound_qp(lambda v: M @ v, q, tol=1e-10, x0=x0)
    assert res.status == "optimal"
    assert np.linalg.norm(res.x - cold.x) <= 1e-7 * np.linalg.norm(cold.x)
    assert np.any(x0 < 0)  # the start was infeasible


def test_the_answer_does_not_depend_on_the_scale_of_q_and_m():
    """The stopping rule's scales move with q and M: scaling both by 1e6 (or 1e-6) changes nothing."""
    rng = np.random.default_rng(13)
    M, G = psd_with_null(60, 2, rng)
    q = rng.standard_normal(60)
    b = G.T @ np.abs(rng.standard_normal(60))
    base = solve_bound_qp(lambda v: M @ v, q, G=G, b=b, tol=1e-9)
    for s in (1e-6, 1e6):
        res = solve_bound_qp(lambda v, s=s: s * (M @ v), s * q, G=G, b=b, tol=1e-9)
        assert res.status == "optimal"
        assert np.linalg.norm(res.x - base.x) <= 1e-7 * np.linalg.norm(base.x)
        assert np.allclose(res.alpha, s * base.alpha, rtol=1e-6)


def test_a_jacobi_diagonal_gives_the_same_answer():
    rng = np.random.default_rng(14)
    d = np.geomspace(1.0, 1e4, 70)
    S = spd(70, rng)
    M = np.sqrt(d)[:, None] * S * np.sqrt(d)[None, :]
    q = rng.standard_normal(70) * np.sqrt(d)
    plain = solve_bound_qp(lambda v: M @ v, q, tol=1e-10, maxiter=20_000)
    scaled = solve_bound_qp(lambda v: M @ v, q, tol=1e-10, diag=np.diag(M).copy())
    ref = bpp(M, q, accuracy="high").x
    for res in (plain, scaled):
        assert res.status == "optimal"
        assert np.linalg.norm(res.x - ref) <= 1e-7 * np.linalg.norm(ref)
    assert scaled.matvecs < plain.matvecs


# ----------------------------------------------------------------------------- 2. degenerate cases


def test_strict_complementarity_failing():
    """x_i = 0 and g_i = 0 at once: built from a known solution with degenerate indices."""
    rng = np.random.default_rng(21)
    m = 60
    M = spd(m, rng)
    x_star = np.where(rng.random(m) < 0.5, rng.uniform(0.5, 2.0, m), 0.0)
    mult = np.where(x_star > 0, 0.0, rng.uniform(0.5, 2.0, m))
    degenerate = rng.choice(np.flatnonzero(x_star == 0), 10, replace=False)
    mult[degenerate] = 0.0
    q = mult - M @ x_star
    res = solve_bound_qp(lambda v: M @ v, q, tol=1e-10)
    assert res.status == "optimal"
    assert np.linalg.norm(res.x - x_star) <= 1e-7 * np.linalg.norm(x_star)
    assert_kkt(M, q, 0.0, None, None, res)


def test_everything_at_the_bound():
    rng = np.random.default_rng(22)
    M = spd(30, rng)
    q = np.abs(rng.standard_normal(30))  # q ≥ 0: x = 0 is the minimiser
    res = solve_bound_qp(lambda v: M @ v, q, tol=1e-12)
    assert res.status == "optimal"
    assert np.all(res.x == 0.0)
    assert np.allclose(res.g, q)


@pytest.mark.parametrize("cond", [None, 1e4])
def test_no_bound_active_is_a_linear_system(cond):
    rng = np.random.default_rng(23)
    M = spd(120, rng, cond)
    q = rng.standard_normal(120)
    ref = np.linalg.solve(M, -q)
    for lb in (-np.inf, np.full(120, -np.inf)):
        res = solve_bound_qp(lambda v: M @ v, q, lb=lb, tol=1e-12, maxiter=5000)
        assert res.status == "optimal"
        assert np.linalg.norm(res.x - ref) <= 1e-7 * np.linalg.norm(ref)
    lb = ref - 1.0  # bounds that are never reached
    res = solve_bound_qp(lambda v: M @ v, q, lb=lb, tol=1e-12, maxiter=5000)
    assert np.linalg.norm(res.x - ref) <= 1e-7 * np.linalg.norm(ref)


def test_an_equality_that_pins_everything():
    """m = k equalities with G invertible: x = G⁻ᵀ b whatever M and q; α from stationarity."""
    rng = np.random.default_rng(24)
    M = spd(3, rng)
    q = rng.standard_normal(3)
    G = rng.standard_normal((3, 3))
    x_star = np.array([0.5, 1.0, 2.0])
    b = G.T @ x_star
    res = solve_bound_qp(lambda v: M @ v, q, G=G, b=b, tol=1e-10)
    assert res.status == "optimal", res.message
    assert np.allclose(res.x, x_star, rtol=1e-7)
    assert np.allclose(res.alpha, np.linalg.solve(G, M @ x_star + q), rtol=1e-6)


def test_an_equality_that_pins_a_component_to_its_bound():
    """x_1 = 0 forced by the equality: at the bound and in the equality both."""
    rng = np.random.default_rng(25)
    M = spd(20, rng)
    q = -np.abs(rng.standard_normal(20))
    G = np.zeros((20, 1))
    G[0, 0] = 1.0
    res = solve_bound_qp(lambda v: M @ v, q, G=G, b=np.zeros(1), tol=1e-10)
    assert res.status == "optimal", res.message
    ref = np.r_[0.0, bpp(M[1:, 1:], q[1:], accuracy="high").x]  # x_1 = 0 eliminated
    assert np.linalg.norm(res.x - ref) <= 1e-7 * np.linalg.norm(ref)
    assert_kkt(M, q, 0.0, G, np.zeros(1), res)


def test_zero_load_gives_zero():
    M = spd(10, np.random.default_rng(26))
    res = solve_bound_qp(lambda v: M @ v, np.zeros(10))
    assert res.status == "optimal" and np.all(res.x == 0.0)


# ----------------------------------------------------------------------------- 3. ill-conditioned


@pytest.mark.parametrize("k", [0, 2])
def test_ill_conditioned_problem_stays_right(k):
    rng = np.random.default_rng(31)
    m = 150
    M = spd(m, rng, cond=1e6)
    q = rng.standard_normal(m)
    G = rng.standard_normal((m, k)) if k else None
    b = G.T @ np.abs(rng.standard_normal(m)) if k else None
    res = solve_bound_qp(lambda v: M @ v, q, G=G, b=b, tol=1e-10, maxiter=50_000)
    assert res.status == "optimal", res.message
    if k:
        ref = clarabel_reference(M, q, 0.0, G, b)
        assert np.linalg.norm(res.x - ref) <= 1e-6 * np.linalg.norm(ref)  # Clarabel's own accuracy at cond 1e6
    else:
        ref = bpp(M, q, accuracy="high").x
        assert np.linalg.norm(res.x - ref) <= 1e-7 * np.linalg.norm(ref)
    assert_kkt(M, q, 0.0, G, b, res)


# ----------------------------------------------------------------------------- 4. no solution


def no_numpy_warnings(fn):
    with warnings.catch_warnings(), np.errstate(all="raise"):
        warnings.simplefilter("error")
        return fn()


def test_a_ray_of_descent_against_no_bound_is_reported_unbounded():
    """M = diag(1, …, 1, 0), x_last ≥ 0 and q_last < 0: f → −∞ as x_last → ∞."""
    M = np.diag(np.r_[np.ones(9), 0.0])
    q = np.r_[np.ones(9), -1.0]
    res = no_numpy_warnings(lambda: solve_bound_qp(lambda v: M @ v, q, maxiter=500))
    assert res.status == "unbounded"
    assert "unbounded" in res.message
    assert res.iterations <= 500


def test_a_ray_of_descent_along_a_free_component_is_not_optimal():
    """A free component (lb = −inf) on which M is 0 and q is not: no minimiser."""
    rng = np.random.default_rng(41)
    B = rng.standard_normal((30, 20))
    M = B @ B.T
    v = np.linalg.svd(B.T)[2][-1]  # M v = 0
    q = rng.standard_normal(30) + v
    lb = np.where(np.arange(30) < 10, 0.0, -np.inf)
    res = no_numpy_warnings(lambda: solve_bound_qp(lambda u: M @ u, q, lb=-np.inf, maxiter=300))
    assert res.status != "optimal" and res.message
    res = no_numpy_warnings(lambda: solve_bound_qp(lambda u: M @ u, q, lb=lb, maxiter=300))
    assert res.status != "optimal" and res.message
    assert res.iterations <= 300


def test_an_equality_infeasible_with_the_bounds_is_not_optimal():
    """Σx = −1 with x ≥ 0 has no feasible point."""
    rng = np.random.default_rng(42)
    M = spd(25, rng)
    q = rng.standard_normal(25)
    G = np.ones((25, 1))
    res = no_numpy_warnings(lambda: solve_bound_qp(lambda v: M @ v, q, G=G, b=np.array([-1.0]), maxiter=3000))
    assert res.status == "stalled"
    assert "equalities may be infeasible" in res.message
    assert res.iterations <= 3000


def test_an_unreachable_tolerance_ends_without_claiming_optimal():
    rng = np.random.default_rng(43)
    M = spd(40, rng, cond=1e8)
    q = rng.standard_normal(40)
    res = no_numpy_warnings(lambda: solve_bound_qp(lambda v: M @ v, q, tol=1e-18, maxiter=4000))
    assert res.status in ("stalled", "max_iter") and res.message
    assert res.projected_gradient > 1e-18 * res.gradient_scale


# ----------------------------------------------------------------------------- 5. bad input


def _M(v):
    return 2.0 * v


BAD = [
    ("q", {"q": np.array([1.0, np.nan, 0.0])}),
    ("q", {"q": np.ones((3, 1))}),
    ("q", {"q": np.zeros(0)}),
    ("tol", {"tol": -1e-8}),
    ("tol", {"tol": np.nan}),
    ("maxiter", {"maxiter": 0}),
    ("lb", {"lb": np.array([0.0, 0.0])}),
    ("lb", {"lb": np.array([0.0, np.nan, 0.0])}),
    ("lb", {"lb": np.inf}),
    ("G", {"G": np.ones((2, 1)), "b": np.zeros(1)}),
    ("G", {"G": np.array([[1.0], [np.inf], [0.0]]), "b": np.zeros(1)}),
    ("b", {"G": np.ones((3, 1)), "b": np.zeros(2)}),
    ("b", {"b": np.zeros(1)}),
    ("x0", {"x0": np.ones(4)}),
    ("x0", {"x0": np.array([0.0, np.nan, 1.0])}),
    ("diag", {"diag": np.array([1.0, 0.0, 1.0])}),
    ("diag", {"diag": np.ones(2)}),
    ("callback", {"callback": 3}),
    ("matvec", {"matvec": None}),
    ("matvec", {"matvec": lambda v: v[:2]}),
    ("matvec", {"matvec": lambda v: v * np.nan}),
]


@pytest.mark.parametrize("name, kwargs", BAD, ids=[f"{n}-{i}" for i, (n, _) in enumerate(BAD)])
def test_bad_input_raises_problem_error_naming_the_argument(name, kwargs):
    args = {"matvec": _M, "q": np.array([1.0, -1.0, 0.5])}
    args.update(kwargs)
    with pytest.raises(ProblemError, match=name):
        solve_bound_qp(args.pop("matvec"), args.pop("q"), **args)


def test_the_inputs_are_not_changed():
    rng = np.random.default_rng(51)
    M = spd(20, rng)
    q = rng.standard_normal(20)
    x0 = rng.standard_normal(20)
    G = rng.standard_normal((20, 1))
    b = np.array([1.0])
    copies = [a.copy() for a in (q, x0, G, b)]
    solve_bound_qp(lambda v: M @ v, q, x0=x0, G=G, b=b)
    for a, c in zip((q, x0, G, b), copies):
        assert np.array_equal(a, c)

