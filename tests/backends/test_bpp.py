"""Tests of block principal pivoting (plateqp.backends.bpp): what is its own beyond the shared
LCP contract of tests/backends/test_lcp.py.

References used (never the code's own earlier output):

* brute-force enumeration of all 2ⁿ complementary splits and scipy's BVLS (tests/lcp_reference.py);
* problems built from a known solution (z*, w*), rank-deficient ones included, and problems with
  a hand-proved certificate of infeasibility (the certificate returned is checked by its
  definition);
* a textbook block pivoting without Júdice–Pires' safeguard, written here, which is shown to
  cycle, and the pivoting rules replayed step by step;
* Lemke's method, an independent algorithm (on a cond ≈ 1e8 matrix and on plates).
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from lcp_reference import (assert_certificate, brute_force, bvls_reference, check_lcp, floating_psd,
                           from_solution, ill_conditioned, net_uplift, random_spd)

import plateqp as pq
from plateqp.backends import bpp as BPP
from plateqp.backends import get_backend
from plateqp.backends import lemke as LEMKE
from plateqp.backends.base import LCP, Status


def solve(M, q, accuracy="high", **options):
    return get_backend("bpp").solve(LCP(M, q), accuracy=accuracy, options=options)


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



# ----------------------------------------------------------------------------- P-matrices


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


def test_net_uplift_is_infeasible_with_a_certificate():
    """A positive null vector v of PSD M with vᵀq < 0 (lcp_reference.net_uplift): no solution."""
    M, q = net_uplift()
    sol = BPP.bpp(M, q)
    assert sol.status is Status.INFEASIBLE and sol.x is None
    assert "block principal pivoting" in sol.solver_status
    assert_certificate(M, q, sol.extras["certificate"])


def test_tipping_is_infeasible_like_lemke():
    """Random floating problems that Lemke's method proves unsolvable (secondary ray, with its
    certificate): the load tips the plate off its supports. BPP must find its own certificate."""
    found = 0
    for seed in range(30):
        rng = np.random.default_rng(seed)
        M, _ = floating_psd(15, rng)
        q = rng.standard_normal(15) + 0.3
        if LEMKE.lemke(M, q).status is not Status.INFEASIBLE:
            continue
        found += 1
        sol = BPP.bpp(M, q)
        assert sol.status is Status.INFEASIBLE
        assert_certificate(M, q, sol.extras["certificate"])
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
    # the true active set, from an independent solver: BVLS leaves ±1e-18 at a bound with some
    # BLAS kernels, so zero is judged to 1e-12 of the largest z, far from the smallest positive
    zero = np.abs(z_ref) <= 1e-12 * np.abs(z_ref).max()
    assert z_ref[~zero].min() > 1e-6 * np.abs(z_ref).max()  # well apart: no degenerate index
    warm = solve(M, q, active=zero)
    assert warm.status is Status.OPTIMAL and warm.iterations == 1
    np.testing.assert_allclose(warm.x, z_ref, atol=1e-12)
    again = solve(M, q, active=cold.extras["active"])
    assert again.iterations == 1
    np.testing.assert_array_equal(again.extras["active"], cold.extras["active"])


# ----------------------------------------------------------------------------- limits and failures


def test_bpp_ill_conditioned_against_lemke():
    """cond ≈ 1e8, the beam of :func:`ill_conditioned`; exact to rounding like Lemke's method.

    (With the default p = 6 (or 3) this one needs hundreds of Murty single pivots; a longer
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
    sol = solve(M, q, max_iter=1)
    assert sol.status is Status.MAX_ITER and sol.iterations == 1 and sol.x is not None


def test_not_psd_is_an_error_not_an_answer():
    """Symmetric indefinite M: outside the method's reach, said so (even though this LCP
    happens to have the solution z = (1/3, 1/3))."""
    M = np.array([[1.0, 2.0], [2.0, 1.0]])
    sol = BPP.bpp(M, np.array([-1.0, -1.0]))
    assert sol.status is Status.ERROR and sol.x is None
    assert "not positive semidefinite" in sol.solver_status


# ----------------------------------------------------------------------------- plates


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
