"""Independent references and test problems for the LCP tests: brute-force enumeration, scipy's
BVLS, the complementarity conditions and Farkas' certificate checked by their definitions, and
generators of problems with known answers.

Shared by tests/backends/test_lemke.py, test_lcp.py, test_bpp.py and test_pgs.py (imported by module
name: pytest puts tests/ on sys.path).
"""

from __future__ import annotations

import itertools

import numpy as np
import scipy.linalg as sla
from scipy.optimize import lsq_linear

#: A 2×2 SPD matrix whose LCPs are solved by hand in the tests.
M2 = np.array([[2.0, 1.0], [1.0, 2.0]])

#: Symmetric PSD LCPs with no solution, each with its hand proof.
INFEASIBLE_PSD = [
    # w1 + w2 = (z1 − z2 − 1) + (−z1 + z2 − 1) = −2 for every z: w ≥ 0 impossible
    (np.array([[1.0, -1.0], [-1.0, 1.0]]), np.array([-1.0, -1.0])),
    # w = −1 whatever z
    (np.array([[0.0]]), np.array([-1.0])),
]


def brute_force(M, q, tol=1e-10):
    """All solutions of LCP(M, q) on complementary bases (2ⁿ principal systems)."""
    n = len(q)
    sols = []
    for mask in itertools.product([False, True], repeat=n):
        S = np.array(mask)
        z = np.zeros(n)
        if S.any():
            MSS = M[np.ix_(S, S)]
            if abs(np.linalg.det(MSS)) < 1e-12:
                continue
            z[S] = np.linalg.solve(MSS, -q[S])
        w = M @ z + q
        if z.min() >= -tol and w.min() >= -tol:
            sols.append(np.maximum(z, 0.0))
    return sols


def bvls_reference(M, q):
    """min ½ zᵀMz + qᵀz, z ≥ 0 for SPD M, by scipy's BVLS on the Cholesky factor."""
    Lc = np.linalg.cholesky(M)  # M = Lc Lcᵀ
    b = -sla.solve_triangular(Lc, q, lower=True)
    res = lsq_linear(Lc.T, b, bounds=(0.0, np.inf), method="bvls", tol=1e-14,
                     lsmr_tol=None, max_iter=10_000)
    assert res.success
    return res.x


def random_spd(n, rng):
    A = rng.standard_normal((n, n))
    return A @ A.T / n + 0.5 * np.eye(n)


def check_lcp(M, q, z, w, rtol=1e-10):
    """The complementarity conditions, checked directly from M, q."""
    M, q = np.asarray(M, float), np.asarray(q, float)
    zs = max(np.abs(z).max(), 1.0)
    ws = max(np.abs(q).max(), np.abs(M).max() * np.abs(z).max(), 1e-300)
    np.testing.assert_allclose(w, M @ z + q, rtol=0, atol=1e-13 * ws)
    assert z.min() >= -rtol * zs
    assert w.min() >= -rtol * ws
    assert abs(z @ w) <= rtol * zs * ws * len(q)
    assert np.abs(z * w).max() <= rtol * zs * ws


def assert_certificate(M, q, y):
    """Farkas: y ≥ 0, Mᵀy ≤ 0, qᵀy < 0 means no z ≥ 0 has w = M z + q ≥ 0
    (0 ≤ yᵀw = (Mᵀy)ᵀz + qᵀy < 0)."""
    assert y.min() >= 0 and y.max() > 0
    assert (M.T @ y).max() <= 1e-12 * max(np.abs(M).max(), 1.0) * y.max()
    assert q @ y < -1e-12 * np.abs(q).max() * y.max()


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


def ill_conditioned(n=200):
    """Discrete beam bending stiffness (second differences squared), cond ≈ 1e8 (n = 150)."""
    D = np.diff(np.eye(n + 2), 2, axis=0)[:, 1:-1]
    return D.T @ D, np.random.default_rng(3).standard_normal(n)


def net_uplift(seed=7, n=20):
    """Symmetric PSD M with a positive null vector v (a rigid lift-off mode) and vᵀq < 0.

    Then vᵀw = vᵀMz + vᵀq = vᵀq < 0 for every z, while v > 0 and w ≥ 0 would give vᵀw ≥ 0:
    no solution (net uplift)."""
    rng = np.random.default_rng(seed)
    v = rng.random(n) + 0.5
    P = np.eye(n) - np.outer(v, v) / (v @ v)
    A = rng.standard_normal((n, n))
    M = P @ A @ A.T @ P
    q = rng.standard_normal(n)
    return M, (-q if v @ q > 0 else q)


def rounding_zero_lcp():
    """M zero up to rounding (indefinite noise of 1e-17) and q = (14, −1e-16, 14): q ≥ 0 up to
    rounding, so z = 0 (w = q) is the answer. On a plate: floating on three supports with the
    load's resultant exactly on the line between two of them, so the third carries nothing
    (found by a hunt over random scenes: Lemke claimed no equilibrium, BPP said M is not PSD)."""
    rng = np.random.default_rng(3)
    A = rng.standard_normal((3, 3))
    M = 1e-17 * (A + A.T)
    assert np.linalg.eigvalsh(M).min() < 0  # the noise is indefinite: no certificate can be checked
    return M, np.array([14.0, -1e-16, 14.0])
