"""The sparse method's factor builds each ``H(w)`` on the triangle it keeps: no second array of
the triangle's values beside it while CHOLMOD factorises, and the kept triangle unchanged after."""

import tracemalloc

import numpy as np
import pytest
import scipy.sparse as sp

from plateqp.backends.pdas.factor import SpringFactor
from plateqp.backends.pdas.reduced import ReducedQP
from plateqp.contact.formulations import Primal
from plateqp.contact.scaling import Scaled
from plateqp.linalg import bindings
from plateqp.model.assembly import build_model
from plateqp.scenes import families


def _bed(n: int) -> ReducedQP:
    model = build_model(families.bed(n))
    return ReducedQP(Primal(Scaled.from_model(model)).qp, None)


def _factor(pb: ReducedQP, sigma: float = 1e-12) -> SpringFactor:
    if "cvxopt" not in bindings():
        pytest.skip("cvxopt's CHOLMOD is not installed")
    fac = SpringFactor(pb.K, pb.B, pb.Kd, pb.c, sigma, "cvxopt")
    if fac.chol.direct is None:
        pytest.skip("CHOLMOD's C API is not reachable here")
    return fac


def test_a_refactorisation_allocates_no_copy_of_the_triangle():
    pb = _bed(32)
    fac = _factor(pb)
    w = np.where(np.arange(pb.m) % 3 == 0, 1.0 / pb.rho, 0.0)
    fac.set(w)  # the analysis (its own allocations) once
    w2 = np.where(np.arange(pb.m) % 2 == 0, 1.0 / pb.rho, 0.0)
    tracemalloc.start()
    fac.refactor(w2)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    # H(w)'s values were base + a bincount over the whole triangle: two arrays of its size
    assert peak < 0.5 * fac.base.nbytes


def test_the_kept_triangle_is_unchanged_and_each_factor_is_that_of_its_own_w():
    pb = _bed(16)
    sigma = 1e-6
    fac = _factor(pb, sigma)
    base = fac.base.copy()
    rng = np.random.default_rng(1)
    b = rng.standard_normal(pb.K.shape[0])
    for pattern in (3, 2, 5):
        w = np.where(np.arange(pb.m) % pattern == 0, 1.0 / pb.rho, 0.0)
        fac.refactor(w)
        assert np.array_equal(fac.base, base)
        H = sp.csc_matrix(pb.K + sp.diags(sigma * pb.Kd) + pb.B.T @ sp.diags(w) @ pb.B)
        x = fac.solve(b)
        assert np.linalg.norm(H @ x - b) <= 1e-9 * np.linalg.norm(b)


def test_the_woodbury_columns_cost_two_blocks_of_memory():
    """A few rows changed on cvxopt's CHOLMOD: their columns ``L⁻¹ P D Uᵀ`` (n × k) come from one
    block of the rows, scaled in place and read by CHOLMOD as it is, and the block solved."""
    pb = _bed(32)
    fac = _factor(pb)
    w = np.where(np.arange(pb.m) % 3 == 0, 1.0 / pb.rho, 0.0)
    fac.set(w)
    fac.t_solve = 0.0  # the columns priced as free: the low-rank correction is taken
    changed = np.flatnonzero(w == 0)[:8]
    w2 = w.copy()
    w2[changed] = 1.0 / pb.rho[changed]
    block = pb.K.shape[0] * changed.size * 8
    tracemalloc.start()
    fac.set(w2)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert fac.lr is not None and fac.stats["lowrank"] == 1
    assert peak < 2.5 * block  # the block and its solve; a scaled copy and a Fortran copy made four


def test_the_woodbury_columns_are_held_once():
    """Rows changed in two steps: the second correction's columns gathered into one array, and
    the blocks they were solved in let go (each column held once, in that array)."""
    pb = _bed(32)
    fac = _factor(pb)
    w = np.where(np.arange(pb.m) % 3 == 0, 1.0 / pb.rho, 0.0)
    fac.set(w)
    fac.t_solve = 0.0  # the columns priced as free: the low-rank corrections are taken
    off = np.flatnonzero(w == 0)
    w1 = w.copy()
    w1[off[:6]] = 1.0 / pb.rho[off[:6]]
    fac.set(w1)
    w2 = w1.copy()
    w2[off[6:10]] = 1.0 / pb.rho[off[6:10]]
    fac.set(w2)
    assert fac.stats["lowrank"] == 2
    Z = fac.lr[1]
    assert Z.shape[1] == 10
    assert all(np.shares_memory(col, Z) for col in fac._zcols.values())
    # and the correction is right: the factor solves H(w2)
    H = sp.csc_matrix(pb.K + sp.diags(1e-12 * pb.Kd) + pb.B.T @ sp.diags(w2) @ pb.B)
    b = np.random.default_rng(2).standard_normal(pb.K.shape[0])
    x = fac.solve(b)
    assert np.linalg.norm(H @ x - b) <= 1e-8 * np.linalg.norm(b)


def _posts_off_nodes(n: int) -> ReducedQP:
    """Elastic piles moved off the nodes: each row reads the element's unknowns around its point."""
    scene = families.grid_elastic(n)
    for s in scene.supports:
        s.x, s.y = 0.97 * s.x + 0.013, 0.96 * s.y + 0.021
    scene.validate()
    return ReducedQP(Primal(Scaled.from_model(build_model(scene))).qp, None)


@pytest.mark.parametrize("make", [_bed, _posts_off_nodes], ids=["bed", "posts off the nodes"])
def test_the_kept_triangle_is_that_of_the_equilibrated_matrix(make):
    """The triangle CHOLMOD factorises (kept in its order) against the matrix assembled by SciPy:
    ``D (K + σ diag K + Bᵀ diag(w) B) D``, ``D = diag(K)^(-1/2)``, its lower triangle in the
    factor's order, for rows on one unknown and rows read by interpolation."""
    pb = make(8)
    sigma = 1e-6
    fac = _factor(pb, sigma)
    w = np.where(np.arange(pb.m) % 3 == 0, 1.0 / pb.rho, 0.0)
    H = (pb.K + sp.diags(sigma * pb.Kd) + pb.B.T @ sp.diags(w) @ pb.B).toarray()
    d = 1.0 / np.sqrt(pb.Kd)
    ref = d[:, None] * H * d[None, :]
    order = np.arange(ref.shape[0]) if fac.order is None else fac.order
    ref = ref[np.ix_(order, order)]
    got = fac._matrix(w).toarray()
    want = np.tril(ref) if np.count_nonzero(np.triu(got, 1)) == 0 else np.triu(ref)
    assert np.count_nonzero(got) == np.count_nonzero(want)
    assert np.abs(got - want).max() <= 1e-14 * np.abs(want).max()
