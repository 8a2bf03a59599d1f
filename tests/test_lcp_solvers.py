"""Tests of the in-house LCP solvers: block principal pivoting (bpp) and projected Gauss–Seidel (pgs).

References used (never the code's own earlier output):

* small LCPs solved by hand (derivations in the comments);
* brute-force enumeration of all 2ⁿ complementary splits (n ≤ 10);
* the bound-constrained QP  min ½ zᵀMz + qᵀz, z ≥ 0  solved independently by
  ``scipy.optimize.lsq_linear`` (BVLS) through a Cholesky factor M = L Lᵀ:
  ½ zᵀMz + qᵀz = ½ ‖Lᵀz + L⁻¹q‖² − const;
* problems built from a known solution (z*, w*), degenerate ones included, and
  problems with a hand-proved certificate of infeasibility;
* a textbook block pivoting without Júdice–Pires' safeguard, written here, which
  is shown to cycle;
* on plates: statics (reactions balance the load in force and moment) and Lemke's
  method, an independent algorithm.
"""

from __future__ import annotations

import itertools
import warnings

import numpy as np
import pytest
from lcp_reference import brute_force, bvls_reference, random_spd
import scipy.sparse as sp

import plateqp as pq
from plateqp.backends import bpp as BPP
from plateqp.backends import get_backend, registry
from plateqp.backends import lemke as LEMKE
from plateqp.backends import pgs as PGS
from plateqp.backends.base import LCP, QP, Status
from plateqp.contact import formulations_for
from plateqp.errors import NoEquilibriumError, ProblemError, SolverError

# ----------------------------------------------------------------------------- the table

# (module, accuracy, options, relative tolerance on z against an exact reference)
SOLVERS = [
    pytest.param(BPP, "high", {}, 1e-12, id="bpp-high"),
    pytest.param(BPP, "default", {}, 1e-12, id="bpp-default"),  # a direct method: exact at every preset
    pytest.param(PGS, "high", {}, 1e-9, id="pgs-high"),
    pytest.param(PGS, "high", {"omega": 1.3}, 1e-9, id="psor-high"),
]


# ----------------------------------------------------------------------------- helpers


def check_lcp(M, q, z, w, rtol=1e-10):
    """The complementarity conditions, checked directly from M, q."""
    M, q = np.asarray(M, float), np.asarray(q, float)
    zs = max(np.abs(z).max(), 1.0)
    ws = max(np.abs(q).max(), np.abs(M).max() * np.abs(z).max(), 1e-300)
    np.testing.assert_allclose(w, M @ z + q, rtol=0, atol=1e-13 * ws)
    assert z.min() >= -rtol * zs
    assert w.min() >= -rtol * ws
    assert np.abs(z * w).max() <= rtol * zs * ws








def floating_psd(n, rng):
    """A floating plate's condensed stiffness in miniature: symmetric PSD whose null space is
    the rigid motions 1, x, y at n random support points."""
    xy = rng.random((n, 2))
    Q, _ = np.linalg.qr(np.column_stack([np.ones(n), xy]))
    P = np.eye(n) - Q @ Q.T
    A = rng.standard_normal((n, n))
    M = P @ (A @ A.T / n + 0.1 * np.eye(n)) @ P
    return 0.5 * (M + M.T), Q


def from_solution(M, rng, frac=0.5, degenerate=0.0):
    """q = w* − M z* for a complementary pair z*, w* ≥ 0 (a share ``degenerate`` of indices
    with z*_i = w*_i = 0)."""
    n = M.shape[0]
    S = rng.random(n) < frac
    z = np.where(S, rng.random(n) + 0.1, 0.0)
    w = np.where(S, 0.0, rng.random(n) + 0.1)
    D = rng.random(n) < degenerate
    z[D] = w[D] = 0.0
    return w - M @ z, z, w


def solve(mod, M, q, accuracy="high", **options):
    return mod.solve(LCP(M, q), accuracy=accuracy, options=options)


def textbook_block_pivoting(M, q, max_iter=50):
    """Exchange every infeasible index at every step, no safeguard: "solved" or "cycle"."""
    n = len(q)
    F, seen = q < 0, set()
    for _ in range(max_iter):
        z = np.zeros(n)
        idx = np.flatnonzero(F)
        if idx.size:
            z[idx] = np.linalg.solve(M[np.ix_(idx, idx)], -q[idx])
        w = M @ z + q
        H = (F & (z < -1e-12)) | (~F & (w < -1e-12))
        if not H.any():
            return "solved"
        if F.tobytes() in seen:
            return "cycle"
        seen.add(F.tobytes())
        F = F ^ H
    return "max_iter"


# ----------------------------------------------------------------------------- hand-solved


M2 = np.array([[2.0, 1.0], [1.0, 2.0]])


@pytest.mark.parametrize("mod, accuracy, options, rtol", SOLVERS)
@pytest.mark.parametrize(
    "q, z_exact, w_exact",
    [
        ([-5.0, -6.0], [4 / 3, 7 / 3], [0.0, 0.0]),  # both free: 2z1+z2 = 5, z1+2z2 = 6
        ([-1.0, 2.0], [0.5, 0.0], [0.0, 2.5]),  # 2z1 = 1; w2 = 1/2 + 2
        ([1.0, -4.0], [0.0, 2.0], [3.0, 0.0]),  # 2z2 = 4; w1 = 2 + 1
        ([1.0, 0.0], [0.0, 0.0], [1.0, 0.0]),  # q ≥ 0: z = 0 (w2 = 0 too: degenerate)
    ],
)
def test_hand_solved_2x2(mod, accuracy, options, rtol, q, z_exact, w_exact):
    sol = solve(mod, M2, np.array(q), accuracy, **options)
    assert sol.status is Status.OPTIMAL
    np.testing.assert_allclose(sol.x, z_exact, rtol=0, atol=10 * rtol)
    np.testing.assert_allclose(sol.w, w_exact, rtol=0, atol=10 * rtol)


# ----------------------------------------------------------------------------- random SPD


@pytest.mark.parametrize("mod, accuracy, options, rtol", SOLVERS)
@pytest.mark.parametrize("n, seed", [(5, 0), (12, 1), (40, 2), (90, 3), (300, 4)])
def test_random_spd_against_bvls(mod, accuracy, options, rtol, n, seed):
    rng = np.random.default_rng(seed)
    M = random_spd(n, rng)
    q = rng.standard_normal(n)
    sol = solve(mod, M, q, accuracy, **options)
    assert sol.status is Status.OPTIMAL
    check_lcp(M, q, sol.x, sol.w, rtol=1e-8)
    z_ref = bvls_reference(M, q)
    np.testing.assert_allclose(sol.x, z_ref, rtol=0, atol=rtol * max(1.0, np.abs(z_ref).max()))
    assert sol.obj == pytest.approx(0.5 * z_ref @ M @ z_ref + q @ z_ref, rel=1e-9)


@pytest.mark.parametrize("mod, accuracy, options, rtol", SOLVERS)
@pytest.mark.parametrize("seed", range(6))
def test_random_spd_against_brute_force(mod, accuracy, options, rtol, seed):
    rng = np.random.default_rng(100 + seed)
    n = 5 + seed  # 5 … 10
    M = random_spd(n, rng)
    q = rng.standard_normal(n) - 0.3
    (z_ref,) = brute_force(M, q)  # P-matrix: exactly one solution
    sol = solve(mod, M, q, accuracy, **options)
    assert sol.status is Status.OPTIMAL
    np.testing.assert_allclose(sol.x, z_ref, rtol=0, atol=rtol * max(1.0, np.abs(z_ref).max()))


def test_nonsymmetric_p_matrix_against_brute_force():
    """Júdice–Pires is for P-matrices, symmetric or not (here: LU instead of Cholesky)."""
    rng = np.random.default_rng(7)
    for _ in range(10):
        n = 6
        S = rng.standard_normal((n, n))
        M = (S - S.T) + np.eye(n) * 0.5 + 0.1 * (S @ S.T)  # M + Mᵀ ≻ 0: a P-matrix
        q = rng.standard_normal(n)
        (z_ref,) = brute_force(M, q)
        sol = BPP.bpp(M, q, accuracy="high")
        assert sol.status is Status.OPTIMAL and sol.extras["factor"] in ("lu", "empty")
        np.testing.assert_allclose(sol.x, z_ref, atol=1e-12)


# ----------------------------------------------------------------------------- degenerate


@pytest.mark.parametrize("mod, accuracy, options, rtol", SOLVERS)
@pytest.mark.parametrize("seed", range(3))
def test_degenerate_integer_data_with_ties(mod, accuracy, options, rtol, seed):
    """SPD M with integer entries, q ∈ {0, −1}: zeros in q and ties everywhere."""
    rng = np.random.default_rng(300 + seed)
    n = 30
    B = rng.integers(-1, 2, (n, n)).astype(float)
    M = B @ B.T + np.eye(n)
    q = -rng.integers(0, 2, n).astype(float)
    sol = solve(mod, M, q, accuracy, **options)
    assert sol.status is Status.OPTIMAL
    check_lcp(M, q, sol.x, sol.w, rtol=1e-8)
    np.testing.assert_allclose(sol.x, bvls_reference(M, q), atol=max(rtol, 1e-12) * 10)


@pytest.mark.parametrize("mod, accuracy, options, rtol", SOLVERS)
def test_degenerate_known_solution(mod, accuracy, options, rtol):
    """z*_i = w*_i = 0 on a fifth of the indices: both splits of those are solutions."""
    rng = np.random.default_rng(12)
    M = random_spd(60, rng)
    q, z_star, w_star = from_solution(M, rng, degenerate=0.2)
    sol = solve(mod, M, q, accuracy, **options)
    assert sol.status is Status.OPTIMAL
    np.testing.assert_allclose(sol.x, z_star, rtol=0, atol=rtol * 10)
    np.testing.assert_allclose(sol.w, w_star, rtol=0, atol=rtol * 10 * np.abs(M).max())


# ----------------------------------------------------------------------------- PSD singular


@pytest.mark.parametrize("seed", range(5))
def test_floating_psd_with_solution(seed):
    """Rigid motions in the null space (a floating plate): every solution has w = w*."""
    rng = np.random.default_rng(400 + seed)
    M, _ = floating_psd(40, rng)
    q, z_star, w_star = from_solution(M, rng, frac=0.6)
    obj_star = 0.5 * z_star @ M @ z_star + q @ z_star
    # cold; and warm from a single support in contact, so the plate is a mechanism at first
    for active in (None, np.arange(40) == seed):
        sol = BPP.bpp(M, q, active=active, accuracy="high")
        assert sol.status is Status.OPTIMAL
        check_lcp(M, q, sol.x, sol.w)
        np.testing.assert_allclose(sol.w, w_star, rtol=0, atol=1e-10 * np.abs(w_star).max())
        assert sol.obj == pytest.approx(obj_star, rel=1e-10)
    assert sol.extras["singular_blocks"] >= 1  # the warm start did go through a singular block
    p = PGS.pgs(M, q, accuracy="high")
    assert p.status is Status.OPTIMAL
    np.testing.assert_allclose(p.w, w_star, rtol=0, atol=1e-7 * np.abs(w_star).max())


@pytest.mark.parametrize("seed", range(4))
def test_low_rank_psd_with_solution(seed):
    """M = AᵀA of rank 3, n = 9: many singular blocks, pivoting alone may cycle; the
    answer must still be right (via the proximal fallback) or not claimed at all."""
    rng = np.random.default_rng(200 + seed)
    A = rng.standard_normal((3, 9))
    M = A.T @ A
    q, z_star, w_star = from_solution(M, rng)
    sol = BPP.bpp(M, q, accuracy="high")
    assert sol.status is Status.OPTIMAL
    check_lcp(M, q, sol.x, sol.w)
    np.testing.assert_allclose(sol.w, w_star, rtol=0, atol=1e-10)
    assert sol.obj == pytest.approx(0.5 * z_star @ M @ z_star + q @ z_star, rel=1e-10)


def test_low_rank_psd_needs_the_fallback_and_never_lies():
    """Over many rank-deficient problems: the statuses claimed are always true, and the
    proximal fallback is what rescues the ones where Murty's rule cycles."""
    rescued = 0
    for seed in range(40):
        rng = np.random.default_rng(1000 + seed)
        n = int(rng.integers(4, 25))
        A = rng.standard_normal((int(rng.integers(1, n)), n))
        M = A.T @ A
        q, _, w_star = from_solution(M, rng)
        sol = BPP.bpp(M, q, accuracy="high")
        if sol.status.solved:
            np.testing.assert_allclose(sol.w, w_star, rtol=0, atol=1e-9 * max(1, np.abs(w_star).max()))
        assert sol.status is Status.OPTIMAL
        rescued += sol.extras["proximal_steps"] > 0
    assert rescued > 0


@pytest.mark.parametrize(
    "M, q",
    [
        # w1 + w2 = (z1 − z2 − 1) + (−z1 + z2 − 1) = −2 for every z: w ≥ 0 impossible
        (np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0])),
        # w = −1 whatever z
        (np.array([[0.0]]), np.array([-1.0])),
    ],
)
def test_infeasible_psd_bpp_raises(M, q):
    with pytest.raises(NoEquilibriumError, match="cannot carry this load"):
        BPP.bpp(M, q)


def test_infeasible_psd_pgs_never_optimal():
    M, q = np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0])
    for acc in ("low", "default", "high"):
        sol = solve(PGS, M, q, acc, max_iter=3000)
        assert sol.status is Status.MAX_ITER and not sol.status.solved
        assert sol.x is not None and sol.extras["natural_residual"] > 0.5  # z runs away, w = (−1, −1)
    sol = PGS.pgs(np.array([[0.0]]), np.array([-1.0]), max_iter=10)  # w = −1 whatever z
    assert sol.status is Status.MAX_ITER and "held" in sol.solver_status


def test_net_uplift_bpp_raises():
    """A positive null vector v (lift-off) with vᵀq < 0: vᵀw = vᵀq < 0, so no w ≥ 0."""
    rng = np.random.default_rng(7)
    n = 20
    v = rng.random(n) + 0.5
    P = np.eye(n) - np.outer(v, v) / (v @ v)
    A = rng.standard_normal((n, n))
    M = P @ A @ A.T @ P
    q = rng.standard_normal(n)
    q = -q if v @ q > 0 else q
    with pytest.raises(NoEquilibriumError, match="certificate"):
        BPP.bpp(M, q)


def test_tipping_bpp_raises():
    """Random floating problems that Lemke's method proves unsolvable (secondary ray): the
    load tips the plate off its supports. BPP must find its own certificate."""
    found = 0
    for seed in range(30):
        rng = np.random.default_rng(seed)
        M, _ = floating_psd(15, rng)
        q = rng.standard_normal(15) + 0.3
        try:
            LEMKE.lemke(M, q)
            continue
        except NoEquilibriumError:
            found += 1
        with pytest.raises(NoEquilibriumError):
            BPP.bpp(M, q)
    assert found >= 3


# ----------------------------------------------------------------------------- pivoting rules


CYCLING_M = np.array([[0.1, -0.829, -0.117], [0.829, 0.1, 3.001], [0.117, -3.001, 0.1]])
CYCLING_Q = np.array([-0.354, 0.348, -0.136])


def test_block_pivoting_cycles_without_the_backup_rule():
    """A 3×3 P-matrix (M + Mᵀ = 0.2 I) on which plain block pivoting cycles; with
    Júdice–Pires' counter and Murty's rule it terminates at the unique solution."""
    assert np.allclose(CYCLING_M + CYCLING_M.T, 0.2 * np.eye(3))
    assert textbook_block_pivoting(CYCLING_M, CYCLING_Q) == "cycle"
    (z_ref,) = brute_force(CYCLING_M, CYCLING_Q)
    for p in (0, 1, 3):
        sol = BPP.bpp(CYCLING_M, CYCLING_Q, p=p, trace=True)
        assert sol.status is Status.OPTIMAL
        np.testing.assert_allclose(sol.x, z_ref, atol=1e-14)
        assert sol.extras["single_pivots"] >= 1
        assert [s["pivot"] for s in sol.extras["trace"]].count("single") == sol.extras["single_pivots"]
    np.testing.assert_allclose(z_ref, [3.54, 0.0, 0.0], atol=1e-12)  # 0.1 z1 = 0.354


@pytest.mark.parametrize("p", [0, 1, 3])
def test_pivoting_rules_replayed(p):
    """Replay the trace with splits solved here: a block pivot exchanges every infeasible
    index, a single pivot only the least one, and single pivots come exactly when the
    count has not dropped below its best for p steps (Júdice & Pires' counter)."""
    M, q = CYCLING_M, CYCLING_Q
    sol = BPP.bpp(M, q, p=p, trace=True)
    F = q < 0
    best, patience = 4, p
    for s in sol.extras["trace"]:
        z = np.zeros(3)
        idx = np.flatnonzero(F)
        if idx.size:
            z[idx] = np.linalg.solve(M[np.ix_(idx, idx)], -q[idx])
        w = M @ z + q
        H = np.flatnonzero((F & (z < -1e-12)) | (~F & (w < -1e-12))).tolist()
        assert s["free"] == idx.size and s["infeasible"] == len(H)
        if not H:
            assert s["pivot"] is None
            break
        if len(H) < best:
            best, patience, rule = len(H), p, "block"
        elif patience >= 1:
            patience, rule = patience - 1, "block"
        else:
            rule = "single"
        assert s["pivot"] == rule
        assert s["exchanged"] == (H if rule == "block" else [min(H)])
        F = F.copy()
        F[s["exchanged"]] = ~F[s["exchanged"]]
    np.testing.assert_allclose(z, sol.x, atol=1e-14)


# ----------------------------------------------------------------------------- warm start


def test_warm_start_from_the_solution_takes_one_split():
    rng = np.random.default_rng(21)
    M = random_spd(200, rng)
    q = rng.standard_normal(200)
    cold = BPP.bpp(M, q, accuracy="high")
    z_ref = bvls_reference(M, q)
    assert cold.iterations > 1
    warm = solve(BPP, M, q, active=z_ref == 0)  # the true active set, from an independent solver
    assert warm.status is Status.OPTIMAL and warm.iterations == 1
    np.testing.assert_allclose(warm.x, z_ref, atol=1e-12)
    again = solve(BPP, M, q, active=cold.extras["active"])
    assert again.iterations == 1
    np.testing.assert_array_equal(again.extras["active"], cold.extras["active"])


def test_pgs_warm_start():
    rng = np.random.default_rng(22)
    M = random_spd(50, rng)
    q = rng.standard_normal(50)
    z_ref = bvls_reference(M, q)
    sol = solve(PGS, M, q, "default", z0=z_ref)
    assert sol.status is Status.OPTIMAL and sol.iterations <= 1
    cold = solve(PGS, M, q, "default")
    assert cold.iterations > 5


# ----------------------------------------------------------------------------- PGS limits


@pytest.mark.parametrize("accuracy", ["low", "default", "high"])
def test_pgs_reaches_each_preset(accuracy):
    rng = np.random.default_rng(31)
    M = random_spd(80, rng)
    q = rng.standard_normal(80)
    sol = solve(PGS, M, q, accuracy)
    tol = PGS.ACCURACY[accuracy]["tol"]
    assert sol.status is Status.OPTIMAL
    assert sol.extras["natural_residual"] <= tol
    # the same measure, computed here from the definition
    w = M @ sol.x + q
    r = np.abs(np.minimum(np.diag(M) * sol.x, w)).max() / max(np.abs(w).max(), np.abs(q).max())
    assert r <= tol * 1.001


def ill_conditioned(n=200):
    """Discrete beam bending stiffness (second differences squared), cond ≈ 1e8 (n = 150)."""
    D = np.diff(np.eye(n + 2), 2, axis=0)[:, 1:-1]
    return D.T @ D, np.random.default_rng(3).standard_normal(n)


def test_pgs_time_limit_gives_max_iter_with_x():
    M, q = ill_conditioned()
    sol = solve(PGS, M, q, "high", time_limit=0.2)
    assert sol.status is Status.MAX_ITER and "time limit" in sol.solver_status
    assert sol.x is not None and sol.w is not None and sol.solve_time < 2.0
    assert sol.extras["natural_residual"] > 1e-11
    sol = solve(PGS, M, q, "high", max_iter=7)
    assert sol.status is Status.MAX_ITER and sol.iterations == 7 and "sweep limit" in sol.solver_status


def test_bpp_ill_conditioned_against_lemke():
    """cond ≈ 1e8, the beam of :func:`ill_conditioned`; exact to rounding like Lemke's method.

    (With the default p = 3 this one needs hundreds of Murty single pivots; a longer
    patience with block pivots, p = 30, gets there in under a hundred splits.)
    """
    M, q = ill_conditioned(150)
    ref = LEMKE.lemke(M, q, accuracy="high")
    sol = BPP.bpp(M, q, p=30, accuracy="high")
    assert sol.status is Status.OPTIMAL and sol.iterations < 150
    np.testing.assert_array_equal(sol.x > 0, ref.x > 0)
    np.testing.assert_allclose(sol.x, ref.x, rtol=0, atol=1e-8 * np.abs(ref.x).max())
    np.testing.assert_allclose(sol.w, ref.w, rtol=0, atol=1e-8 * np.abs(ref.w).max())


def test_bpp_max_iter_gives_status_not_exception():
    rng = np.random.default_rng(8)
    M = random_spd(60, rng)
    q = rng.standard_normal(60)
    sol = solve(BPP, M, q, max_iter=1)
    assert sol.status is Status.MAX_ITER and sol.iterations == 1 and sol.x is not None


# ----------------------------------------------------------------------------- interface


@pytest.mark.parametrize("mod", [BPP, PGS])
def test_backend_interface(mod):
    (backend,) = mod.backends()
    assert registry()[mod.name] is backend and get_backend(mod.name) is backend
    assert backend.accepts == frozenset({"lcp"}) and backend.available() is True
    assert "plateqp" in backend.version()
    assert formulations_for(backend.accepts) == ["condensed", "dual"]
    assert set(mod.ACCURACY) == {"low", "default", "high"}
    sol = backend.solve(LCP(sp.csr_matrix(M2), np.array([-1.0, 2.0])), accuracy="high")
    np.testing.assert_allclose(sol.x, [0.5, 0.0], atol=1e-10)
    assert sol.solve_time > 0 and sol.iterations >= 1


@pytest.mark.parametrize("mod, bad", [
    (BPP, {"tolerance": 1e-3}), (BPP, {"max_iter": 0}), (BPP, {"p": -1}), (BPP, {"active": [1, 0]}),
    (BPP, {"active": np.array([True])}), (BPP, {"feas_tol": -1.0}), (BPP, {"trace": "yes"}),
    (PGS, {"tolerance": 1e-3}), (PGS, {"omega": 2.0}), (PGS, {"omega": 0.0}), (PGS, {"max_iter": 0}),
    (PGS, {"time_limit": 0}), (PGS, {"z0": [1.0]}), (PGS, {"tol": 2.0}),
])
def test_bad_options(mod, bad):
    with pytest.raises(ProblemError):
        mod.solve(LCP(M2, np.array([-1.0, -1.0])), options=bad)


@pytest.mark.parametrize("mod", [BPP, PGS])
def test_rejects_qp_and_unknown_accuracy(mod):
    with pytest.raises(ProblemError):
        mod.solve(QP(P=M2, q=np.array([-1.0, -1.0]), lb=np.zeros(2)))
    with pytest.raises(ProblemError):
        mod.solve(LCP(M2, np.array([-1.0, -1.0])), accuracy="extreme")


def test_not_psd_is_an_error_not_an_answer():
    """Symmetric indefinite M: outside the method's reach, said so (even though this LCP
    happens to have the solution z = (1/3, 1/3))."""
    M = np.array([[1.0, 2.0], [2.0, 1.0]])
    sol = BPP.bpp(M, np.array([-1.0, -1.0]))
    assert sol.status is Status.ERROR and sol.x is None
    assert "not positive semidefinite" in sol.solver_status


# ----------------------------------------------------------------------------- plates


def floating_scene(**kw):
    sups = [pq.Support(x, y) for x in (0, 0.5, 1) for y in (0, 0.5, 1)]
    return pq.Scene(plate=pq.Plate(1, 1, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
                    loads=[pq.PointLoad(10, 0.3, 0.6)], supports=sups, **kw)


@pytest.fixture(scope="module")
def lemke_floating():
    return pq.solve(floating_scene(), backend="lemke", formulation="condensed", accuracy="high")


@pytest.mark.parametrize("backend, accuracy, atol", [("bpp", "high", 1e-10), ("pgs", "default", 1e-6)])
def test_floating_plate_statics_and_lemke(backend, accuracy, atol, lemke_floating):
    sc = floating_scene()
    res = pq.solve(sc, backend=backend, formulation="condensed", accuracy=accuracy)
    assert res.status is Status.OPTIMAL and res.kkt.ok
    R = res.reactions
    x = np.array([s.x for s in sc.supports])
    y = np.array([s.y for s in sc.supports])
    P, xp, yp = 10.0, 0.3, 0.6
    assert R.min() >= -atol * P
    assert R.sum() == pytest.approx(P, rel=atol)  # vertical equilibrium
    assert (R * x).sum() == pytest.approx(P * xp, rel=atol)  # moments about the axes
    assert (R * y).sum() == pytest.approx(P * yp, rel=atol)
    np.testing.assert_allclose(R, lemke_floating.reactions, rtol=0, atol=atol * P)
    # the contact set, from the reactions (Result.active counts R > 1e-9 max R as contact,
    # finer than PGS's "default" tolerance)
    np.testing.assert_array_equal(R > atol * P, lemke_floating.reactions > atol * P)
    if backend == "bpp":
        np.testing.assert_array_equal(res.active, lemke_floating.active)


def test_plate_sweep_warm_start_and_dual():
    """A held plate: the dual formulation too; a neighbouring load warm-started from the
    reported set."""
    sups = [pq.Support(x, y, gap=g) for (x, y), g in zip(
        itertools.product((0.25, 0.5, 0.75), repeat=2), np.linspace(-2e-4, 2e-4, 9))]
    edges = {k: pq.Edge("simple") for k in ("left", "right")}

    def scene(P):
        return pq.Scene(plate=pq.Plate(1, 1, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8), edges=edges,
                        loads=[pq.UniformLoad(5.0), pq.PointLoad(P, 0.4, 0.6)], supports=sups)

    ref = pq.solve(scene(50.0), backend="lemke", formulation="dual", accuracy="high")
    for form in ("condensed", "dual"):
        res = pq.solve(scene(50.0), backend="bpp", formulation=form, accuracy="high")
        assert res.status is Status.OPTIMAL
        np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0,
                                   atol=1e-10 * np.abs(ref.reactions).max())
    first = pq.solve(scene(50.0), backend="bpp", formulation="condensed", accuracy="high")
    again = pq.solve(scene(50.0), backend="bpp", formulation="condensed", accuracy="high",
                     options={"active": first.extras["active"]})
    assert again.iterations == 1
    near = pq.solve(scene(52.0), backend="bpp", formulation="condensed", accuracy="high",
                    options={"active": first.extras["active"]})
    ref2 = pq.solve(scene(52.0), backend="lemke", formulation="condensed", accuracy="high")
    np.testing.assert_allclose(near.reactions, ref2.reactions, rtol=0,
                               atol=1e-10 * np.abs(ref2.reactions).max())


def test_plate_no_equilibrium_is_never_optimal():
    """Every support far from a load at the plate's corner: the plate tips off."""
    sups = [pq.Support(x, y) for x in (0.6, 0.8) for y in (0.6, 0.8)]
    sc = pq.Scene(plate=pq.Plate(1, 1, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(6, 6),
                  loads=[pq.PointLoad(10, 0.1, 0.1)], supports=sups)
    for backend in ("bpp", "pgs"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                res = pq.solve(sc, backend=backend, formulation="condensed", check_statics=False,
                               options={"time_limit": 0.3} if backend == "pgs" else None)
            except (NoEquilibriumError, SolverError, pq.MechanismError):
                continue
        assert not res.status.solved
