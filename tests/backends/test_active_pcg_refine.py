"""The active-set PCG's last solves: an inexact product (a solve accurate to about cond·ε, as the
matrix-free half-space's) with an accurate one given for the residuals. The answer must meet the
asked tolerance on the exact matrix, and the dear product is spent on residuals only (a few per
set), never on every conjugate gradient step."""

from __future__ import annotations

import numpy as np
import pytest

from plateqp.backends.active_pcg import active_set_pcg
from plateqp.backends.bpp import bpp


def problem(m, seed):
    """A flexibility (positive entries, not an M-matrix) and a load that lifts part of it off."""
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(0, 1, m))
    M = np.exp(-np.abs(x[:, None] - x[None, :]) / 0.1) + 0.01 * np.eye(m)
    q = np.sin(6 * x + seed) - 0.2
    return M, q


def noisy(M, rel, seed):
    """v ↦ M v with a relative error ``rel`` that changes at every call (a rounding-level solve)."""
    rng = np.random.default_rng(seed)

    def product(v):
        w = M @ v
        return w + rel * np.linalg.norm(w) * rng.standard_normal(w.size) / np.sqrt(w.size)
    return product


@pytest.mark.parametrize("seed", range(4))
def test_the_accurate_product_is_spent_on_residuals_only(seed):
    M, q = problem(120, seed)
    calls = [0]

    def exact(v):
        calls[0] += 1
        return M @ v

    tol = 1e-12
    out = active_set_pcg(noisy(M, 1e-7, seed), q, tol=tol, precise=exact, precond=lambda v: v / np.diag(M))
    assert out.status == "optimal", out.message
    ref = bpp(M, q, accuracy="high").x
    assert np.array_equal(out.x > 0, ref > 0)
    g = M @ out.x + q
    assert out.x.min() >= 0
    assert np.linalg.norm(np.minimum(out.x, g)) <= tol * max(np.linalg.norm(q), np.linalg.norm(M @ out.x))
    # a handful of residuals against the conjugate gradient steps of the last solves
    assert calls[0] <= 8, (calls[0], out.iterations)
    assert calls[0] < out.iterations


def test_without_an_accurate_product_the_plain_one_refines():
    """No ``precise``: the last solves are refined on the product given (exact here)."""
    M, q = problem(100, 7)
    out = active_set_pcg(lambda v: M @ v, q, tol=1e-13)
    assert out.status == "optimal", out.message
    g = M @ out.x + q
    assert np.linalg.norm(np.minimum(out.x, g)) <= 1e-13 * max(np.linalg.norm(q), np.linalg.norm(M @ out.x))
