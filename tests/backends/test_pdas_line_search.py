"""The sparse method's line search (``sparse.line_search``): the exact minimiser of the convex,
piecewise quadratic energy ``½uᵀKu − fᵀu + Σ ½ W_i max(0, B_i u − g_i)²`` along ``u + α du``.

Reference, independent of the method: SciPy's root finder (``brentq``) on the energy's slope,
evaluated term by term, and the energy itself compared on a fine grid of α around the answer."""

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import brentq

from plateqp.backends.pdas.options import ALPHA_MAX
from plateqp.backends.pdas.sparse import line_search


def _problem(rng, n=40, m=60, zero_rows=0, touching=0):
    A = rng.standard_normal((n, n))
    K = sp.csr_matrix(A @ A.T / n + 0.1 * np.eye(n))
    B = sp.csr_matrix(rng.standard_normal((m, n)) * (rng.random((m, n)) < 0.2))
    if zero_rows:  # rows the direction does not move (B_i du = 0 is arranged below)
        B = sp.csr_matrix(np.vstack([B.toarray(), np.zeros((zero_rows, n))]))
    g = rng.standard_normal(B.shape[0])
    f = rng.standard_normal(n)
    u = rng.standard_normal(n)
    if touching:  # rows exactly at their threshold at α = 0 (r_i = 0)
        g[:touching] = B[:touching] @ u
    W = 10.0 ** rng.uniform(-1, 3, B.shape[0])
    return SimpleNamespace(K=K, B=B, g=g, f=f), W, u


def _energy(pb, W, u):
    r = pb.B @ u - pb.g
    return 0.5 * u @ (pb.K @ u) - pb.f @ u + 0.5 * np.sum(W * np.maximum(0.0, r) ** 2)


def _slope(pb, W, u, du, a):
    v = u + a * du
    return float(du @ (pb.K @ v - pb.f) + np.sum(W * (pb.B @ du) * np.maximum(0.0, pb.B @ v - pb.g)))


def _descent(pb, W, u):
    """Minus the energy's gradient at u: a descent direction, as a Newton step is."""
    r = pb.B @ u - pb.g
    return -(pb.K @ u - pb.f + pb.B.T @ (W * np.maximum(0.0, r)))


@pytest.mark.parametrize("seed", range(12))
def test_minimiser_against_brentq(seed):
    rng = np.random.default_rng(seed)
    pb, W, u = _problem(rng, zero_rows=3, touching=4)
    du = _descent(pb, W, u)
    alpha = line_search(pb, W, u, du)
    assert np.isfinite(alpha) and alpha > 0
    hi = 1.0
    while _slope(pb, W, u, du, hi) < 0:
        hi *= 2
    ref = brentq(lambda a: _slope(pb, W, u, du, a), 0.0, hi, xtol=1e-15, rtol=1e-14)
    assert alpha == pytest.approx(ref, rel=1e-10)
    # no α near it gives a lower energy
    e = _energy(pb, W, u + alpha * du)
    grid = alpha * (1.0 + np.linspace(-0.2, 0.2, 401))
    assert min(_energy(pb, W, u + a * du) for a in grid) >= e - 1e-12 * abs(e)


def test_breakpoint_minimiser():
    """One row, no plate stiffness along du: the minimiser is where the row's spring balances
    the load, past the point where it starts to act (a breakpoint crossed)."""
    pb = SimpleNamespace(K=sp.csr_matrix((1, 1)), B=sp.csr_matrix([[1.0]]), g=np.array([1.0]),
                         f=np.array([2.0]))
    # energy along u = α: −2α + ½·4·max(0, α − 1)²: slope −2 + 4(α − 1) on α > 1, zero at 1.5
    assert line_search(pb, np.array([4.0]), np.zeros(1), np.ones(1)) == pytest.approx(1.5, rel=1e-14)


def test_unbounded_direction_is_infinite():
    """The springs along du all let go (s_i < 0) and the plate is not stiff along it: the energy
    falls without bound, the step is infinite (left to the exact steps)."""
    pb = SimpleNamespace(K=sp.csr_matrix((2, 2)), B=sp.csr_matrix([[1.0, 0.0], [0.0, 1.0]]),
                         g=np.array([-1.0, -2.0]), f=np.array([-1.0, -1.0]))
    W = np.array([1.0, 3.0])
    assert line_search(pb, W, np.zeros(2), -np.ones(2)) == np.inf


def test_minimiser_beyond_alpha_max_is_infinite():
    pb = SimpleNamespace(K=sp.csr_matrix([[1e-6]]), B=sp.csr_matrix((0, 1)), g=np.zeros(0), f=np.array([1.0]))
    # energy ½·1e-6 α² − α: minimiser 1e6 > ALPHA_MAX
    assert 1e6 > ALPHA_MAX
    assert line_search(pb, np.zeros(0), np.zeros(1), np.ones(1)) == np.inf
