"""The sparse method's factor recycles its solves on one matrix (``SpringFactor.solve_in_span``):
a right-hand side in the span of those solved before on the same ``H(w)`` is their combination,
with no solve, and is as accurate as a solve; anything else is solved. Checked against SciPy's
SuperLU on the assembled ``H(w)`` (an independent factorisation), and by the normwise backward
error of each answer."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from plateqp.backends.pdas.factor import SpringFactor
from plateqp.backends.pdas.options import SPAN_KEEP
from plateqp.backends.pdas.reduced import ReducedQP
from plateqp.contact.formulations import Primal
from plateqp.contact.scaling import Scaled
from plateqp.linalg import bindings
from plateqp.model.assembly import build_model
from plateqp.scenes import families


@pytest.fixture(scope="module")
def pb() -> ReducedQP:
    return ReducedQP(Primal(Scaled.from_model(build_model(families.bed(16)))).qp, None)


def factor(pb: ReducedQP, w: np.ndarray) -> SpringFactor:
    if not bindings():
        pytest.skip("no CHOLMOD binding")
    fac = SpringFactor(pb.K, pb.B, pb.Kd, pb.c, 0.0, "auto")
    fac.set(w)
    return fac


def H(pb: ReducedQP, w: np.ndarray) -> sp.csc_matrix:
    return sp.csc_matrix(pb.K + pb.B.T @ sp.diags(w) @ pb.B)


def check(pb, w, x, b):
    """x is H(w)⁻¹b: against SuperLU's, and by its backward error (a solve's: a few ε)."""
    A = H(pb, w)
    ref = spla.spsolve(A, b)
    assert np.linalg.norm(x - ref) <= 1e-9 * np.linalg.norm(ref)
    back = np.abs(A @ x - b).max() / (abs(A) @ np.abs(x) + np.abs(b)).max()
    assert back <= 1e-14, back


def rows(pb, every):
    return np.where(np.arange(pb.m) % every == 0, 1.0 / pb.rho, 0.0)


def test_a_right_hand_side_in_the_span_of_those_solved_is_their_combination_and_no_solve(pb):
    w = rows(pb, 1)
    fac = factor(pb, w)
    rng = np.random.default_rng(3)
    g, dg = rng.uniform(-1e-3, 1e-3, pb.m), rng.uniform(-1e-3, 1e-3, pb.m)
    b = lambda t: pb.f + pb.B.T @ (w * (g + t * dg))  # a gap sweep's values: f + Bᵀ W (g + t dg)
    for t in (0.0, 1.0):
        check(pb, w, fac.solve_in_span(b(t)), b(t))
    solves = fac.stats["solves"]
    for t in (0.5, 2.0, -3.0, 40.0, 1e4):  # far outside the two solved too: no cancellation
        check(pb, w, fac.solve_in_span(b(t)), b(t))
    assert fac.stats["solves"] == solves
    assert fac.stats["span_solves"] == 5


def test_a_right_hand_side_outside_the_span_is_solved_and_joins_it(pb):
    w = rows(pb, 1)
    fac = factor(pb, w)
    rng = np.random.default_rng(4)
    B = rng.standard_normal((pb.K.shape[0], SPAN_KEEP + 2))
    for j in range(B.shape[1]):  # more directions than the basis keeps: it starts again, still right
        before = fac.stats["solves"]
        check(pb, w, fac.solve_in_span(B[:, j]), B[:, j])
        assert fac.stats["solves"] == before + 1
    inside = B[:, -2] - 2.0 * B[:, -1]  # the basis since it started again holds these two
    before = fac.stats["solves"]
    check(pb, w, fac.solve_in_span(inside), inside)
    assert fac.stats["solves"] == before
    off = inside + 1e-9 * np.linalg.norm(inside) * B[:, 0] / np.linalg.norm(B[:, 0])  # just off it
    check(pb, w, fac.solve_in_span(off), off)
    assert fac.stats["solves"] == before + 1


@pytest.mark.parametrize("change", ["woodbury", "refactor"])
def test_the_span_is_dropped_when_the_matrix_changes(pb, change):
    w = rows(pb, 1)
    fac = factor(pb, w)
    rng = np.random.default_rng(5)
    b1, b2 = rng.standard_normal((2, pb.K.shape[0]))
    fac.solve_in_span(b1)
    fac.solve_in_span(b2)
    w2 = w.copy()
    if change == "woodbury":
        w2[:3] = 0.0  # three rows let go: a low-rank correction on the factor in hand
        fac.t_solve = 0.0  # its columns priced as free: the correction is taken
    else:
        w2[::2] = 0.0
    fac.set(w2)
    assert (fac.lr is not None) == (change == "woodbury")
    before = fac.stats["solves"]
    x = fac.solve_in_span(b1 + b2)  # in the old span, not an answer of the new matrix
    assert fac.stats["solves"] == before + 1
    check(pb, w2, x, b1 + b2)
