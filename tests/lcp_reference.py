"""Independent references for LCP tests: brute-force enumeration and scipy's BVLS.

Shared by tests/test_lemke.py and tests/test_lcp_solvers.py (imported by module name:
pytest puts tests/ on sys.path).
"""

from __future__ import annotations

import itertools

import numpy as np
import scipy.linalg as sla
from scipy.optimize import lsq_linear


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
