"""Tests of Lemke's method (plateqp.backends.lemke) against external references.

References used (never the code's own earlier output):

* small LCPs solved by hand (derivations in the comments);
* brute-force enumeration of all 2ⁿ complementary bases (n ≤ 8);
* the bound-constrained QP  min ½ zᵀMz + qᵀz, z ≥ 0  solved independently by
  ``scipy.optimize.lsq_linear`` (BVLS) through a Cholesky factor M = L Lᵀ:
  ½ zᵀMz + qᵀz = ½ ‖Lᵀz + L⁻¹q‖² − const;
* problems built from a known solution (z*, w*) or with a hand-proved
  certificate of infeasibility (the certificate Lemke's method returns is
  checked here by its definition, y ≥ 0, Mᵀy ≤ 0, qᵀy < 0);
* a naive Lemke (smallest-ratio, ties to the last row) written here, which
  is shown to cycle on a degenerate problem.
"""

from __future__ import annotations


import numpy as np
import pytest
from lcp_reference import (INFEASIBLE_PSD, M2, assert_certificate, brute_force, bvls_reference, check_lcp,
                           net_uplift, random_spd, rounding_zero_lcp)
import scipy.sparse as sp

from plateqp.backends import get_backend
from plateqp.backends import lemke as L
from plateqp.backends.base import LCP, QP, Status
from plateqp.errors import ProblemError

#: The registered backend (``solve(problem, accuracy, options)``).
B = get_backend("lemke")


# ----------------------------------------------------------------------------- helpers


def naive_lemke(M, q, max_iter=100):
    """Textbook Lemke with a plain minimum-ratio test, ties → last row, no lexicographic rule.

    Returns "solved", "ray" or "cycle" (a (basis, leaving) pair seen twice).
    """
    n = len(q)
    T = np.hstack([np.eye(n), -M, -np.ones((n, 1)), q[:, None]]).astype(float)
    basis, Z0 = list(range(n)), 2 * n

    def pivot(r, j):
        T[r] /= T[r, j]
        for i in range(n):
            if i != r:
                T[i] -= T[i, j] * T[r]

    ratios = q.copy()
    r = max(i for i in range(n) if ratios[i] <= ratios.min() + 1e-12)
    pivot(r, Z0)
    leaving, basis[r] = basis[r], Z0
    seen = set()
    for _ in range(max_iter):
        if leaving == Z0:
            return "solved"
        j = leaving + n if leaving < n else leaving - n
        rows = [i for i in range(n) if T[i, j] > 1e-12]
        if not rows:
            return "ray"
        rat = {i: T[i, -1] / T[i, j] for i in rows}
        m = min(rat.values())
        ties = [i for i in rows if rat[i] <= m + 1e-12]
        r = basis.index(Z0) if basis.index(Z0) in ties else ties[-1]
        pivot(r, j)
        leaving, basis[r] = basis[r], j
        key = (frozenset(basis), leaving)
        if key in seen:
            return "cycle"
        seen.add(key)
    return "max_iter"


# ----------------------------------------------------------------------------- hand-solved


@pytest.mark.parametrize(
    "q, z_exact, w_exact",
    [
        # both supports active: 2z1+z2 = 5, z1+2z2 = 6 → z = (4/3, 7/3), w = 0
        ([-5.0, -6.0], [4 / 3, 7 / 3], [0.0, 0.0]),
        # only the first: 2z1 = 1 → z1 = 1/2, w2 = 1/2 + 2 = 5/2 ≥ 0
        ([-1.0, 2.0], [0.5, 0.0], [0.0, 2.5]),
        # only the second: 2z2 = 4 → z2 = 2, w1 = 2 + 1 = 3 ≥ 0
        ([1.0, -4.0], [0.0, 2.0], [3.0, 0.0]),
        # q ≥ 0: z = 0, w = q
        ([1.0, 0.0], [0.0, 0.0], [1.0, 0.0]),
    ],
)
def test_hand_solved_2x2(q, z_exact, w_exact):
    sol = L.lemke(M2, np.array(q))
    assert sol.status is Status.OPTIMAL
    np.testing.assert_allclose(sol.x, z_exact, rtol=0, atol=1e-14)
    np.testing.assert_allclose(sol.w, w_exact, rtol=0, atol=1e-14)
    z = np.array(z_exact)
    assert sol.obj == pytest.approx(0.5 * z @ M2 @ z + np.array(q) @ z, abs=1e-14)


def test_hand_trace_2x2():
    """Pivot sequence for M2, q = (−5, −6), d = 1, derived by hand.

    1. z0 enters; min q_i/d_i = −6 (row 2): w2 leaves, z0 = 6.
    2. z2 enters: w2 = 0 gives z0 = 6 − 2 z2, and w1 = −5 + z2 + z0 = 1 − z2,
       so w1 blocks at z2 = 1 (z0 would at 3): w1 leaves, z0 = 4.
    3. z1 enters: w1 = w2 = 0 give z2 = 1 + z1, z0 = 4 − 3 z1, so z0 leaves at
       z1 = 4/3 (z2 = 7/3 grows): done.
    """
    sol = L.lemke(M2, np.array([-5.0, -6.0]), trace=True)
    tr = sol.extras["trace"]
    assert [(s["step"], s["entering"], s["leaving"]) for s in tr] == [
        (1, ("z0", None), ("w", 1)),
        (2, ("z", 1), ("w", 0)),
        (3, ("z", 0), ("z0", None)),
    ]
    np.testing.assert_allclose([s["z0"] for s in tr], [6.0, 4.0, 0.0], atol=1e-14)
    assert sol.iterations == 3


def test_hand_solved_3x3_fully_degenerate():
    """M z = 1 for z = (1/3, 1/3, 1/3) (each row of M sums to 3), so w = 0.

    M is positive semidefinite (xᵀMx = (x1+x2+x3)²) and with q = −1, d = 1 all
    three ratios of the first step tie; every later step is degenerate too.
    """
    M = np.array([[1.0, 2.0, 0.0], [0.0, 1.0, 2.0], [2.0, 0.0, 1.0]])
    q = -np.ones(3)
    sol = L.lemke(M, q)
    assert sol.status is Status.OPTIMAL
    check_lcp(M, q, sol.x, sol.w)
    assert any(np.allclose(sol.x, s, atol=1e-12) for s in brute_force(M, q))
    np.testing.assert_allclose(sol.x, [1 / 3] * 3, atol=1e-14)


def test_q_nonnegative_returns_zero_at_once():
    q = np.array([0.0, 3.0, 1.0])
    sol = L.lemke(-np.eye(3), q, trace=True)  # M irrelevant when q ≥ 0
    assert sol.status is Status.OPTIMAL and sol.iterations == 0
    np.testing.assert_array_equal(sol.x, 0.0)
    np.testing.assert_array_equal(sol.w, q)
    assert sol.extras["trace"] == []


# ----------------------------------------------------------------------------- random SPD


@pytest.mark.parametrize("n, seed", [(5, 0), (5, 1), (8, 2), (8, 3), (20, 4), (35, 5), (60, 6), (60, 7)])
def test_random_spd_against_bvls(n, seed):
    rng = np.random.default_rng(seed)
    M = random_spd(n, rng)
    q = rng.standard_normal(n)
    sol = B.solve(LCP(M, q))
    assert sol.status is Status.OPTIMAL
    check_lcp(M, q, sol.x, sol.w)
    z_ref = bvls_reference(M, q)
    np.testing.assert_allclose(sol.x, z_ref, rtol=0, atol=1e-9 * max(1.0, np.abs(z_ref).max()))
    assert sol.obj == pytest.approx(0.5 * z_ref @ M @ z_ref + q @ z_ref, rel=1e-10, abs=1e-12)


@pytest.mark.parametrize("seed", range(6))
def test_random_spd_against_brute_force(seed):
    rng = np.random.default_rng(100 + seed)
    n = 4 + seed % 5  # 4 … 8
    M = random_spd(n, rng)
    q = rng.standard_normal(n) - 0.3
    sols = brute_force(M, q)
    assert len(sols) == 1  # P-matrix: unique solution
    sol = L.lemke(M, q)
    np.testing.assert_allclose(sol.x, sols[0], rtol=0, atol=1e-12)
    check_lcp(M, q, sol.x, sol.w)


@pytest.mark.parametrize("accuracy", ["low", "default", "high"])
def test_every_preset_is_exact(accuracy):
    rng = np.random.default_rng(11)
    n = 150
    M = random_spd(n, rng)
    q = rng.standard_normal(n)
    sol = B.solve(LCP(M, q), accuracy=accuracy, options={"refactor_every": 20})
    assert sol.status is Status.OPTIMAL
    check_lcp(M, q, sol.x, sol.w, rtol=1e-12)
    z_ref = bvls_reference(M, q)
    np.testing.assert_allclose(sol.x, z_ref, rtol=0, atol=1e-9)


def test_ill_conditioned_plate_like_matrix():
    """Discrete beam bending stiffness (second differences squared), cond ≈ 1e8."""
    n = 150
    D = np.diff(np.eye(n + 2), 2, axis=0)[:, 1:-1]
    M = D.T @ D
    assert np.linalg.cond(M) > 1e7
    q = np.random.default_rng(3).standard_normal(n)
    sol = L.lemke(M, q)
    assert sol.status is Status.OPTIMAL
    check_lcp(M, q, sol.x, sol.w, rtol=1e-10)
    # independent reference via the QP optimality: z solves the principal system on its support
    S = sol.x > 0
    z = np.zeros(n)
    z[S] = np.linalg.solve(M[np.ix_(S, S)], -q[S])
    np.testing.assert_allclose(sol.x, z, rtol=1e-6, atol=1e-12 * np.abs(z).max())


# ----------------------------------------------------------------------------- PSD


@pytest.mark.parametrize("seed", range(4))
def test_psd_rank_deficient_with_known_solution(seed):
    """M = AᵀA (rank 3, n = 9); q = w* − M z* for complementary z*, w* ≥ 0.

    For symmetric PSD M, w = Mz + q is the same at every solution, so w must
    equal w*, and the objective must equal that of z*.
    """
    rng = np.random.default_rng(200 + seed)
    n, k = 9, 3
    A = rng.standard_normal((k, n))
    M = A.T @ A
    S = rng.random(n) < 0.5
    z_star = np.where(S, rng.random(n) + 0.1, 0.0)
    w_star = np.where(S, 0.0, rng.random(n) + 0.1)
    q = w_star - M @ z_star
    sol = L.lemke(M, q)
    assert sol.status is Status.OPTIMAL
    check_lcp(M, q, sol.x, sol.w)
    np.testing.assert_allclose(sol.w, w_star, rtol=0, atol=1e-10)
    assert sol.obj == pytest.approx(0.5 * z_star @ M @ z_star + q @ z_star, rel=1e-10)


@pytest.mark.parametrize("M, q", INFEASIBLE_PSD)
def test_psd_without_solution_is_infeasible_with_a_certificate(M, q):
    sol = L.lemke(M, q)
    assert sol.status is Status.INFEASIBLE and sol.x is None
    assert "no solution" in sol.solver_status
    assert_certificate(M, q, sol.extras["certificate"])


def test_net_uplift_is_infeasible_with_a_certificate():
    """A positive null vector v of PSD M with vᵀq < 0 (lcp_reference.net_uplift): no solution."""
    M, q = net_uplift()
    sol = B.solve(LCP(M, q))
    assert sol.status is Status.INFEASIBLE and sol.x is None
    assert_certificate(M, q, sol.extras["certificate"])


def test_ray_without_a_certificate_proves_nothing():
    """M = [[1, 2], [2, 0]] is symmetric indefinite (not copositive-plus) and LCP(M, (−1, −1)) has
    solutions (z = (1, 0)); Lemke's method ends on a ray here, which proves nothing: the status
    is ERROR, never INFEASIBLE (the ray's direction fails the certificate check)."""
    M, q = np.array([[1.0, 2.0], [2.0, 0.0]]), np.array([-1.0, -1.0])
    assert any(np.allclose(z, [1.0, 0.0]) for z in brute_force(M, q))  # it has a solution
    sol = L.lemke(M, q)
    assert sol.status is Status.ERROR and sol.x is None
    assert "nothing is proved" in sol.solver_status and "certificate" not in sol.extras


def test_zero_matrix_and_a_rounding_negative_q_is_solved():
    """lcp_reference.rounding_zero_lcp: z = 0 is the answer. Before the fix the pivot on the
    rounding-negative row met a ray and Lemke's method claimed that no solution exists."""
    M, q = rounding_zero_lcp()
    sol = L.lemke(M, q)
    assert sol.status is Status.OPTIMAL
    np.testing.assert_array_equal(sol.x, np.zeros(3))
    assert sol.w.min() >= -1e-15 * np.abs(q).max()


# ----------------------------------------------------------------------------- degeneracy


# Positive semidefinite (M + Mᵀ ⪰ 0), hence copositive-plus: Lemke must solve it.
M_CYCLE = np.array([[4.0, 2.0, 3.0, -3.0],
                    [0.0, 1.0, 1.0, 1.0],
                    [5.0, 1.0, 4.0, -1.0],
                    [-1.0, -3.0, -3.0, 2.0]])


def test_degenerate_problem_that_cycles_without_lexicographic_rule():
    q = -np.ones(4)
    assert np.linalg.eigvalsh(M_CYCLE + M_CYCLE.T).min() > -1e-12
    assert naive_lemke(M_CYCLE, q) == "cycle"  # plain min-ratio rule cycles here
    sol = L.lemke(M_CYCLE, q, trace=True)
    assert sol.status is Status.OPTIMAL
    check_lcp(M_CYCLE, q, sol.x, sol.w)
    assert any(np.allclose(sol.x, s, atol=1e-12) for s in brute_force(M_CYCLE, q))
    np.testing.assert_allclose(sol.x, [1.0, 0.0, 0.0, 1.0], atol=1e-14)
    # no basis is visited twice
    bases, basis = [], set(("w", i) for i in range(4))
    for s in sol.extras["trace"]:
        basis = (basis - {s["leaving"]}) | {s["entering"]}
        bases.append(frozenset(basis))
    assert len(bases) == len(set(bases))


def test_artificial_variable_leaves_first_on_a_tie():
    """M = [[4, 2], [2, −2]], q = (−2, −1), d = 1, traced by hand.

    1. z0 enters; min q_i/d_i = −2 (row 1): w1 leaves, z0 = 2.
    2. z1 enters: w1 = 0 gives z0 = 2 − 4 z1, and w2 = −1 + 2 z1 + z0 = 1 − 2 z1: z0 and w2
       both block at z1 = 1/2, a tie. With z0 leaving, z = (1/2, 0), w = M z + q = (0, 0)
       solves the LCP (check: 4·½ − 2 = 0, 2·½ − 1 = 0). With w2 leaving instead, z2 enters
       and z1 falls back to 0 at z2 = 1/4; M is not copositive-plus (M_22 = −2), and that
       path ends on a ray that proves nothing.
    """
    M = np.array([[4.0, 2.0], [2.0, -2.0]])
    q = np.array([-2.0, -1.0])
    sol = L.lemke(M, q, trace=True)
    assert sol.status is Status.OPTIMAL
    np.testing.assert_allclose(sol.x, [0.5, 0.0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(sol.w, [0.0, 0.0], rtol=0, atol=1e-15)
    assert [(s["entering"], s["leaving"]) for s in sol.extras["trace"]] == [
        (("z0", None), ("w", 0)), (("z", 0), ("z0", None))]


@pytest.mark.parametrize("seed", range(4))
def test_degenerate_ties_spd(seed):
    """SPD M with q having many equal entries and zeros (ties in every ratio test)."""
    rng = np.random.default_rng(300 + seed)
    n = 30
    B = rng.integers(-1, 2, (n, n)).astype(float)
    M = B @ B.T + np.eye(n)
    q = -rng.integers(0, 2, n).astype(float)
    sol = L.lemke(M, q)
    assert sol.status is Status.OPTIMAL
    check_lcp(M, q, sol.x, sol.w)
    np.testing.assert_allclose(sol.x, bvls_reference(M, q), atol=1e-9)


# ----------------------------------------------------------------------------- covering


def test_covering_vector_does_not_change_unique_solution():
    rng = np.random.default_rng(42)
    n = 25
    M = random_spd(n, rng)
    q = rng.standard_normal(n)
    ref = L.lemke(M, q)
    for d in (rng.random(n) + 0.01, np.linspace(1.0, 100.0, n), 3.0):
        sol = B.solve(LCP(M, q), options={"covering": d})
        assert sol.status is Status.OPTIMAL
        np.testing.assert_allclose(sol.x, ref.x, rtol=0, atol=1e-11)
    np.testing.assert_allclose(ref.x, bvls_reference(M, q), atol=1e-9)


@pytest.mark.parametrize("d", [[1.0, 0.0], [1.0, -2.0], [1.0, np.nan], [1.0, 1.0, 1.0], -1.0])
def test_bad_covering_vector(d):
    with pytest.raises(ProblemError):
        L.lemke(M2, np.array([-1.0, -1.0]), covering=d)


# ----------------------------------------------------------------------------- trace, limits


def test_trace_one_entry_per_pivot_and_complementary_rule():
    rng = np.random.default_rng(5)
    n = 40
    M = random_spd(n, rng)
    q = rng.standard_normal(n)
    sol = L.lemke(M, q, trace=True)
    tr = sol.extras["trace"]
    assert len(tr) == sol.iterations > 0
    assert [s["step"] for s in tr] == list(range(1, sol.iterations + 1))
    assert tr[0]["entering"] == ("z0", None) and tr[0]["leaving"][0] == "w"
    assert tr[-1]["leaving"] == ("z0", None) and tr[-1]["z0"] == 0.0
    flip = {"w": "z", "z": "w"}
    for prev, cur in zip(tr, tr[1:]):  # the complement of the leaving variable enters
        kind, i = prev["leaving"]
        assert cur["entering"] == (flip[kind], i)
    assert all(s["z0"] >= -1e-12 for s in tr)
    assert "trace" not in L.lemke(M, q).extras


def test_max_iter_gives_status_not_exception():
    rng = np.random.default_rng(8)
    M = random_spd(10, rng)
    q = -np.abs(rng.standard_normal(10))
    sol = B.solve(LCP(M, q), options={"max_iter": 2})
    assert sol.status is Status.MAX_ITER and sol.iterations == 2
    assert sol.x is None and sol.extras["z0"] > 0


def test_solve_time_and_iterations_recorded():
    sol = B.solve(LCP(M2, np.array([-5.0, -6.0])))
    assert sol.iterations == 3 and sol.solve_time > 0.0


# ----------------------------------------------------------------------------- interface


def test_backend_interface():
    (backend,) = L.backends()
    assert backend.name == "lemke" and backend.accepts == frozenset({"lcp"})
    assert backend.available() is True
    assert isinstance(backend.version(), str) and "plateqp" in backend.version()
    assert set(L.ACCURACY) == {"low", "default", "high"}
    for preset in L.ACCURACY.values():
        assert {"pivot_tol", "zero_tol"} <= set(preset)
    sol = backend.solve(LCP(sp.csr_matrix(M2), np.array([-1.0, 2.0])))
    np.testing.assert_allclose(sol.x, [0.5, 0.0], atol=1e-15)


def test_rejects_qp_unknown_option_and_accuracy():
    with pytest.raises(ProblemError):
        B.solve(QP(P=M2, q=np.array([-1.0, -1.0]), lb=np.zeros(2)))
    with pytest.raises(ProblemError, match="covering"):
        B.solve(LCP(M2, np.array([-1.0, -1.0])), options={"tolerance": 1e-3})
    with pytest.raises(ProblemError):
        B.solve(LCP(M2, np.array([-1.0, -1.0])), accuracy="extreme")
    with pytest.raises(ProblemError):
        B.solve(LCP(M2, np.array([-1.0, -1.0])), options={"max_iter": 0})


def test_pivot_tol_option_accepted():
    sol = B.solve(LCP(M2, np.array([-5.0, -6.0])), options={"pivot_tol": 1e-14, "trace": True})
    np.testing.assert_allclose(sol.x, [4 / 3, 7 / 3], atol=1e-14)
