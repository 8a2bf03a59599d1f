"""plateqp.linalg against independent references: SciPy's ``spsolve`` and dense NumPy.

Each factorisation route runs with every CHOLMOD binding installed here (scikit-sparse,
cvxopt's wheels) and with SuperLU, on small sparse symmetric positive definite matrices whose
unknowns differ by orders of magnitude in scale (as a plate's deflections and rotations do),
and on singular ones. The trailing block of a contacts-last factorisation is checked against
the dense Schur complement ``K_ll − K_lo K_oo⁻¹ K_ol`` and ``B K⁻¹ Bᵀ`` against dense inverses;
the saddle solve against a dense solve of the bordered matrix; the row stiffness against its
closed forms and the exact condensed stiffness it bounds.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from plateqp import linalg
from plateqp.errors import MechanismError, SingularMatrixError
from plateqp.linalg import Factor, SchurFactor, row_stiffness, solve_saddle
from plateqp.linalg.cholmod import Cholesky, lower

LIBS = [lib for lib, have in (("sksparse", linalg.HAVE_CHOLMOD), ("cvxopt", linalg.HAVE_CVXOPT)) if have]
FACTOR_METHODS = ["superlu", "superlu-default"] + [{"sksparse": "cholmod", "cvxopt": "cvxopt"}[x] for x in LIBS]
SCHUR_METHODS = ["blocks"] + LIBS


def laplacian(k: int, shift: float = 0.0) -> sp.csc_matrix:
    """5-point Laplacian on a k × k grid with free (Neumann) edges: singular (constants) unless
    ``shift`` > 0 is added to its diagonal."""
    T = sp.diags([-np.ones(k - 1), np.r_[1.0, 2 * np.ones(k - 2), 1.0], -np.ones(k - 1)], [-1, 0, 1])
    Id = sp.identity(k)
    return sp.csc_matrix(sp.kron(T, Id) + sp.kron(Id, T) + shift * sp.identity(k * k))


def spd(k: int = 7, seed: int = 0, shift: float = 0.05) -> sp.csc_matrix:
    """A sparse SPD matrix D (L + shift I) D with D spanning six orders of magnitude."""
    d = 10.0 ** np.random.default_rng(seed).uniform(-3, 3, k * k)
    return sp.csc_matrix(sp.diags(d) @ laplacian(k, shift) @ sp.diags(d))


def dense_schur(K, last):
    Kd = K.toarray()
    o = np.setdiff1d(np.arange(K.shape[0]), last)
    return Kd[np.ix_(last, last)] - Kd[np.ix_(last, o)] @ np.linalg.solve(Kd[np.ix_(o, o)], Kd[np.ix_(o, last)])


def rel(a, b) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())


# --------------------------------------------------------------------------- Factor


@pytest.mark.parametrize("method", FACTOR_METHODS)
def test_factor_solves_like_spsolve(method):
    K = spd()
    rng = np.random.default_rng(1)
    b = rng.standard_normal(K.shape[0])
    Bm = rng.standard_normal((K.shape[0], 3))
    fac = Factor(K, method=method)
    assert rel(fac.solve(b), spla.spsolve(K, b)) < 1e-10
    assert rel(fac.solve(Bm), np.linalg.solve(K.toarray(), Bm)) < 1e-10
    # a given order (reversed) gives the same answer
    order = np.arange(K.shape[0])[::-1].copy()
    assert rel(Factor(K, method=method, order=order).solve(b), spla.spsolve(K, b)) < 1e-10


@pytest.mark.parametrize("method", FACTOR_METHODS)
def test_refactor_takes_new_values_of_the_pattern(method):
    K = spd()
    fac = Factor(K, method=method)
    K2 = spd(seed=5, shift=0.5)  # same pattern, other values (also once equilibrated)
    fac.refactor(K2)
    b = np.ones(K.shape[0])
    assert rel(fac.solve(b, refine=0), spla.spsolve(K2, b)) < 1e-10  # the new factor itself, unrefined


@pytest.mark.parametrize("method", FACTOR_METHODS)
def test_factor_refuses_singular_matrices(method):
    if method in ("cholmod", "cvxopt"):  # CHOLMOD sees the null space of constants
        with pytest.raises(SingularMatrixError):
            Factor(laplacian(6), method=method)
    # SuperLU's pivots there are rounding, not zero (so callers look for rigid modes first);
    # an exactly dependent pair it does see
    P = sp.lil_matrix(laplacian(6, 1.0))
    P[7, 7] = P[8, 8] = P[7, 8] = P[8, 7] = 1.0
    P[7, [1, 6, 13]] = P[[1, 6, 13], 7] = 0.0
    P[8, [2, 9, 14]] = P[[2, 9, 14], 8] = 0.0
    with pytest.raises(SingularMatrixError):
        Factor(P.tocsc(), method=method)
    Z = laplacian(6, 1.0).tolil()
    Z[3, 3] = 0.0
    with pytest.raises(SingularMatrixError, match="row 3"):
        Factor(Z.tocsc(), method=method)
    assert issubclass(SingularMatrixError, MechanismError)  # callers that know the matrix catch it as one


def test_lower_is_the_scaled_lower_triangle():
    """lower(K, s) (no order: K's own column order kept) and with an order, against dense numpy."""
    K = spd(5)
    s = 1.0 / np.sqrt(K.diagonal())
    Kd = (s[:, None] * K.toarray()) * s[None, :]
    assert rel(lower(K, s).toarray(), np.tril(Kd)) < 1e-15
    p = np.random.default_rng(4).permutation(K.shape[0])
    assert rel(lower(K, s, p).toarray(), np.tril(Kd[np.ix_(p, p)])) < 1e-15


@pytest.mark.parametrize("method", ["cvxopt", "superlu"] if linalg.HAVE_CVXOPT else ["superlu"])
def test_refinement_stops_once_a_step_no_longer_changes_the_answer(method):
    """A moderately conditioned matrix (cond ~1e7): one refinement step takes the answer from
    ~1e-10 to rounding and the next is predicted not to change it, so it is not taken (two raw
    solves in all); an ill-conditioned one: refinement still gains digits."""
    K = laplacian(8, 1e-6)
    b = np.random.default_rng(5).standard_normal(K.shape[0])
    fac = Factor(K, method=method)
    calls = []
    raw = fac._raw
    fac._raw = lambda r: calls.append(1) or raw(r)
    x = fac.solve(b)
    assert len(calls) == 2
    assert rel(x, dense_refined(K, b)) < 1e-13
    # ill-conditioned even once equilibrated (cond ~1e10): the reference is a dense LU solve
    # refined with long-double residuals (scipy, not plateqp); refinement gains two digits or more, to ~1e-12
    d = 10.0 ** np.linspace(-6, 6, 64)
    K2 = sp.csc_matrix(sp.diags(d) @ laplacian(8, 1e-8) @ sp.diags(d))
    b2 = np.random.default_rng(6).standard_normal(64) * d
    x_ref = dense_refined(K2, b2)
    fac2 = Factor(K2, method=method)
    assert rel(fac2.solve(b2), x_ref) < 1e-2 * rel(fac2.solve(b2, refine=0), x_ref)
    assert rel(fac2.solve(b2), x_ref) < 1e-11


def dense_refined(K, b, steps: int = 8) -> np.ndarray:
    """A dense LU solve (SciPy) with ``steps`` refinement steps on long-double residuals."""
    import scipy.linalg as sla

    Kd = K.toarray()
    lu = sla.lu_factor(Kd)
    x = sla.lu_solve(lu, b)
    KL = Kd.astype(np.longdouble)
    for _ in range(steps):
        x = x + sla.lu_solve(lu, (b.astype(np.longdouble) - KL @ x.astype(np.longdouble)).astype(float))
    return x


# --------------------------------------------------------------------------- CHOLMOD's trailing block


@pytest.mark.parametrize("lib", LIBS)
def test_trailing_block_is_the_dense_factors(lib):
    """In the natural order, L[no:, no:] of CHOLMOD's factor is that of numpy's Cholesky, and
    the factor still solves after it was read (cvxopt: not spent)."""
    K = spd(6)
    n, no = K.shape[0], 24
    A = lower(K, 1.0 / np.sqrt(K.diagonal()))
    chol = Cholesky(lib)
    chol.analyse(A, natural=True)
    chol.factor(A)
    T = chol.trailing(no)
    Ad = A.toarray() + np.tril(A.toarray(), -1).T
    assert rel(T, np.linalg.cholesky(Ad)[no:, no:]) < 1e-12
    assert not chol.spent
    b = np.arange(1.0, n + 1)
    assert rel(chol.solve(b), np.linalg.solve(Ad, b)) < 1e-10


def test_factor_flops_of_a_dense_matrix():
    """Cholesky.flops on a dense SPD matrix (one supernode, natural order): n(n+1)(2n+1)/6
    multiply-adds, the textbook count Σ_k (n − k)²."""
    if not getattr(linalg, "HAVE_CVXOPT", False):
        pytest.skip("the direct seam needs cvxopt's CHOLMOD")
    n = 40
    G = np.random.default_rng(0).standard_normal((n, n))
    K = sp.csc_matrix(G @ G.T + n * np.eye(n))
    chol = Cholesky("cvxopt")
    if chol.direct is None:
        pytest.skip("the direct seam does not load here")
    A = lower(K, 1.0 / np.sqrt(K.diagonal()), upper=chol.upper)
    chol.analyse(A, natural=True)
    chol.factor(A)
    assert chol.flops() == n * (n + 1) * (2 * n + 1) / 6


# --------------------------------------------------------------------------- SchurFactor


@pytest.mark.parametrize("method", SCHUR_METHODS)
def test_schur_complement_is_the_dense_one(method):
    K = spd()
    n = K.shape[0]
    last = np.random.default_rng(2).permutation(n)[:9]  # any order: schur() rows follow it
    fac = SchurFactor(K, last, method=method)
    assert rel(fac.schur(), dense_schur(K, last)) < 1e-10
    rng = np.random.default_rng(3)
    b = rng.standard_normal(n)
    assert rel(fac.solve(b, refine=2), spla.spsolve(K, b)) < 1e-10
    o = fac.others
    bo = rng.standard_normal(o.size)
    assert rel(fac.solve_others(bo), np.linalg.solve(K.toarray()[np.ix_(o, o)], bo)) < 1e-10


@pytest.mark.parametrize("lib", LIBS)
def test_solve_in_halves(lib):
    """SchurFactor's forward/backward halves: backward(forward(b)) = K⁻¹ b; the trailing part of
    K⁻¹ b from the forward half alone; forward of a vector on the last unknowns is zero on the
    others and its trailing part is trailing_forward's (all against dense numpy)."""
    K = spd()
    n = K.shape[0]
    last = np.random.default_rng(7).permutation(n)[:11]
    fac = SchurFactor(K, last, method=lib)
    assert fac.can_split
    b = np.random.default_rng(8).standard_normal(n)
    x = np.linalg.solve(K.toarray(), b)
    y = fac.forward(b)
    assert rel(fac.backward(y), x) < 1e-9
    assert rel(fac.trailing_backward(y[fac.no:]), x[last]) < 1e-9
    bl = np.random.default_rng(9).standard_normal(last.size)
    full = np.zeros(n)
    full[last] = bl
    yl = fac.forward(full)
    assert np.all(yl[:fac.no] == 0)
    assert rel(yl[fac.no:], fac.trailing_forward(bl)) < 1e-12
    assert rel(fac.backward(yl), np.linalg.solve(K.toarray(), full)) < 1e-9
    with pytest.raises(ValueError):
        SchurFactor(K, last, shift=1.0, method=lib).forward(b)


@pytest.mark.parametrize("method", SCHUR_METHODS)
def test_flexibility_is_B_Kinv_Bt(method):
    K = spd()
    n = K.shape[0]
    last = np.array([3, 10, 11, 17, 30, 40])
    Kinv = np.linalg.inv(K.toarray())
    fac = SchurFactor(K, last, method=method)
    # rows on one unknown each (POTRI route), and rows mixing several (triangular solve route)
    E = sp.csr_matrix((np.array([2.0, -1.0, 0.5, 3.0, 1.0, 1.0]), (np.arange(6), last[::-1])), shape=(6, n))
    Bmix = sp.csr_matrix(np.array([[0.3, 0.7, 0, 0, 0, 0], [0, 0.5, 0.25, 0.25, 0, 0],
                                   [0, 0, 0, 0, 1.0, -1.0]]) @ sp.csr_matrix(
        (np.ones(6), (np.arange(6), last)), shape=(6, n)).toarray())
    for B in (E, Bmix):
        ref = B.toarray() @ Kinv @ B.toarray().T
        assert rel(fac.flexibility(B), ref) < 1e-9
        assert rel(fac.flexibility(B, refine=2), ref) < 1e-10
    with pytest.raises(ValueError, match="not ordered last"):
        fac.flexibility(sp.csr_matrix(np.eye(n)[[0]]))


@pytest.mark.parametrize("method", SCHUR_METHODS)
def test_shifted_schur_of_a_semidefinite_matrix(method):
    """A singular K whose K_oo is definite (a floating plate's, contact points held): the shift
    makes the trailing block definite and schur() takes it off again."""
    K = laplacian(6)  # null space: constants
    last = np.array([0, 5, 30, 35])
    S = SchurFactor(K, last, shift=1.0, method=method).schur()
    assert rel(S, dense_schur(K, last)) < 1e-10
    assert abs(S.sum()) < 1e-10 * np.abs(S).max()  # constants still in its null space
    with pytest.raises(SingularMatrixError):
        SchurFactor(K, last, pivot_tol=1e-13, method=method)


@pytest.mark.parametrize("method", SCHUR_METHODS)
def test_smallest_eigenvalue_of_the_trailing_block(method):
    """SchurFactor.smallest_eigenvalue (two inverse iterations) against LAPACK's eigenvalues of
    the equilibrated Schur complement: an upper bound, within a factor 2 here; about ε·‖S‖
    for a singular K (a Laplacian: the constants), which pivot_tol then refuses."""
    K = spd()
    n = K.shape[0]
    last = np.random.default_rng(4).permutation(n)[:12]
    fac = SchurFactor(K, last, method=method)
    s = 1.0 / np.sqrt(K.diagonal())
    Ks = sp.diags(s) @ K @ sp.diags(s)
    low = np.linalg.eigvalsh(dense_schur(sp.csc_matrix(Ks), last))[0]
    est = fac.smallest_eigenvalue()
    assert low * (1 - 1e-12) <= est <= 2 * low
    # nearly singular: a Laplacian (null space: the constants) plus 1e-13 of its diagonal
    L = laplacian(6)
    L = sp.csc_matrix(L + 1e-13 * sp.diags(L.diagonal()))
    last = np.array([0, 5, 14, 30, 35])
    s = 1.0 / np.sqrt(L.diagonal())
    low = np.linalg.eigvalsh(dense_schur(sp.csc_matrix(sp.diags(s) @ L @ sp.diags(s)), last))[0]
    est = SchurFactor(L, last, method=method).smallest_eigenvalue()
    # nearly singular: below the pivot tolerance that refuses it (the eigenvalue is 1.0e-12 to
    # rounding, either side of 1e-12 by the BLAS kernel)
    assert low < 1e-11 and est <= 2 * low + 1e-15
    with pytest.raises(SingularMatrixError, match="singular"):
        SchurFactor(L, last, pivot_tol=1e-11, method=method)


# --------------------------------------------------------------------------- saddle, row stiffness


def test_solve_saddle_is_the_bordered_dense_solve():
    K = laplacian(5)  # singular: the rows must hold it
    n = K.shape[0]
    B = sp.csr_matrix((np.array([1.0, 0.5, 0.5, 1.0]), ([0, 1, 1, 2], [0, 12, 13, 24])), shape=(3, n))
    rho = np.array([0.0, 0.1, 0.0])
    rng = np.random.default_rng(4)
    f, g = rng.standard_normal(n), rng.standard_normal(3)
    A = np.block([[K.toarray(), B.toarray().T], [B.toarray(), -np.diag(rho)]])
    ref = np.linalg.solve(A, np.concatenate([f, g]))
    u, R = solve_saddle(K, B, rho, f, g)
    assert rel(np.concatenate([u, R]), ref) < 1e-10
    with pytest.raises(SingularMatrixError):
        solve_saddle(K, sp.csr_matrix((3, n)), np.zeros(3), f, g)


def test_row_stiffness_closed_forms_and_bound():
    K = spd()
    n = K.shape[0]
    B = sp.csr_matrix((np.array([1.0, 0.6, 0.4, 2.0]), ([0, 1, 1, 2], [4, 20, 21, 33])), shape=(3, n))
    Bd, Kd = B.toarray(), K.toarray()
    diag = (Bd**2) @ np.diag(Kd)
    ray = np.einsum("ij,jk,ik->i", Bd, Kd, Bd) / (Bd**2).sum(axis=1) ** 2
    assert np.allclose(row_stiffness(K, B, "diagonal"), diag, rtol=1e-14)
    assert np.allclose(row_stiffness(K, B), ray, rtol=1e-14)
    exact = 1.0 / np.diag(Bd @ np.linalg.inv(Kd) @ Bd.T)
    assert np.all(row_stiffness(K, B) >= exact * (1 - 1e-12))  # Rayleigh: an upper bound
    rho = np.array([0.0, 1e-3, 1.0])
    assert np.allclose(row_stiffness(K, B, rho=rho), ray / (1 + rho * ray), rtol=1e-14)
    with pytest.raises(ValueError):
        row_stiffness(K, B, "trace")


def test_row_stiffness_rows_on_one_unknown():
    """Rows that read one unknown each take the diagonal alone: the closed forms, worked out
    densely here, and to the bit what the general products give."""
    K = spd()
    n = K.shape[0]
    B = sp.csr_matrix((np.array([1.0, -0.6, 2.5]), ([0, 1, 2], [4, 20, 33])), shape=(3, n))
    Bd, Kd = B.toarray(), K.toarray()
    diag = (Bd**2) @ np.diag(Kd)
    ray = np.einsum("ij,jk,ik->i", Bd, Kd, Bd) / (Bd**2).sum(axis=1) ** 2
    np.testing.assert_allclose(row_stiffness(K, B, "diagonal"), diag, rtol=1e-15)
    np.testing.assert_allclose(row_stiffness(K, B), ray, rtol=1e-15)
    exact = 1.0 / np.diag(Bd @ np.linalg.inv(Kd) @ Bd.T)
    assert np.all(row_stiffness(K, B) >= exact * (1 - 1e-12))
    # the general products, forced by a second (zero) entry in one row
    wide = sp.csr_matrix((np.array([1.0, -0.6, 2.5, 0.0]), ([0, 1, 2, 0], [4, 20, 33, 5])), shape=(3, n))
    for kind in ("diagonal", "rayleigh"):
        assert np.array_equal(row_stiffness(K, B, kind), row_stiffness(K, wide, kind))
    assert np.array_equal(row_stiffness(sp.diags(K.diagonal()), B, "diagonal"), row_stiffness(K, B, "diagonal"))


def test_cvxopt_options_are_not_left_changed_by_two_threads():
    """cvxopt's CHOLMOD options are one global dict. Two threads in ``_cvx_options`` at once
    left it changed (nmethods=1: every later analysis without a given order failed in that
    process, as after a threaded Dask cluster). The lock makes the second wait for the first."""
    import threading

    from plateqp.linalg import cholmod as ch

    if not ch.HAVE_CVXOPT:
        pytest.skip("cvxopt is not installed")
    before = dict(ch._cvx_cholmod.options)
    a_in, a_out = threading.Event(), threading.Event()

    def first():
        with ch._cvx_options(nmethods=1, postorder=False):
            a_in.set()
            time.sleep(0.3)  # the second thread tries to enter meanwhile
        a_out.set()

    def second():
        a_in.wait(5)
        with ch._cvx_options(nmethods=1, postorder=False):
            a_out.wait(2)  # without the lock: inside while the first restores, then restores its copy

    threads = [threading.Thread(target=first), threading.Thread(target=second)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(10)
    assert dict(ch._cvx_cholmod.options) == before


# --------------------------------------------------------------------------- stored patterns


def _restore(K, full_pattern) -> sp.csc_matrix:
    """``K`` on ``full_pattern`` (its entries outside ``K``'s own stored as zeros)."""
    Z = sp.coo_matrix(full_pattern)
    return linalg.pattern.add(K, sp.coo_matrix((np.zeros(Z.nnz), (Z.row, Z.col)), shape=Z.shape))


def test_scaled_keeps_the_stored_pattern_and_scales_like_diag_products():
    K = _restore(sp.csc_matrix(sp.diags(np.arange(1.0, 50.0))), laplacian(7) != 0)  # off-diagonals stored zeros
    s = 10.0 ** np.random.default_rng(1).uniform(-3, 3, 49)
    for A in (K, K.tocsr()):
        out = linalg.pattern.scaled(A, s, 2.5)
        ref = 2.5 * (sp.diags(s) @ A @ sp.diags(s))  # SciPy's product: same values, zeros dropped
        assert ref.nnz == 49 and out.nnz == A.nnz == laplacian(7).nnz
        np.testing.assert_array_equal(out.indices, A.indices)
        assert abs(out - ref).max() <= 1e-15 * abs(ref).max()
    # a symmetric matrix stays exactly symmetric (each pair rounded alike), factor and all
    R = sp.random(60, 60, 0.1, random_state=2, format="csr")
    R = (R + R.T).tocsr()
    out = linalg.pattern.scaled(R, 10.0 ** np.random.default_rng(3).uniform(-3, 3, 60), 1 / 3.7)
    assert (out != out.T).nnz == 0


def test_add_keeps_entries_that_sum_to_zero():
    A = laplacian(5)
    out = linalg.pattern.add(A, -A, sp.identity(25))
    assert out.nnz == A.nnz  # A − A + I: SciPy's sum keeps only the diagonal
    np.testing.assert_array_equal(out.toarray(), np.eye(25))
    with pytest.raises(ValueError, match="shapes"):
        linalg.pattern.add(A, sp.identity(3))


def test_the_contact_pipeline_keeps_the_plates_stored_pattern():
    """The matrix pdas factorises is the model's K with every stored entry (the ordering reads
    the pattern; dropping the assembly's structural zeros cost 1.9× the factorisation time at
    128²): its stored entries are the model's, value for value up to the scaling."""
    import plateqp as pq
    from plateqp.model.assembly import build_model
    from plateqp.backends.pdas.reduced import ReducedQP
    from plateqp.contact.formulations import formulate
    from plateqp.contact.scaling import Scaled
    from plateqp.scenes.families import grid_rigid

    model = build_model(grid_rigid(8, 3))
    K = sp.csc_matrix(model.K)
    # the assembly stores zeros (ACM node blocks): exact, or rounding of a cancelling product
    # (5e-14 of 6e4 with OpenBLAS's SandyBridge kernels)
    assert np.count_nonzero(np.abs(K.data) <= 1e-15 * np.abs(K.data).max()) > 0
    data = Scaled.from_model(model)
    assert data.K.nnz == K.nnz
    pb = ReducedQP(formulate(data, "primal").problem(frozenset({"qp"})), max_rows=10**6)
    assert pb.K.nnz == K.nnz
    np.testing.assert_allclose(pb.K.toarray(), (sp.diags(data.dof_scale) @ K @ sp.diags(data.dof_scale)).toarray()
                               / (data.F0 * data.W), rtol=1e-13, atol=0)
    from plateqp.backends.pdas.sparse import SpringFactor

    assert SpringFactor(pb.K, pb.B, pb.Kd, pb.c, 1e-12, "auto").pattern_nnz == K.nnz  # the rows lie in K's pattern
    assert pq.solve(grid_rigid(8, 3), backend="pdas").kkt.ok


# --------------------------------------------------------------------------- CHOLMOD through ctypes


@pytest.fixture
def seam_off(monkeypatch):
    from plateqp.linalg import seam

    monkeypatch.setattr(seam, "SEAM", False)


@pytest.mark.skipif(not linalg.HAVE_CVXOPT, reason="cvxopt is not installed")
def test_the_seam_loads_here_and_solves_like_spsolve_and_the_binding(monkeypatch):
    """CHOLMOD's C API inside cvxopt's wheel, read in place through ctypes: the same solves and
    the same trailing block (a given order kept exactly) as cvxopt's own binding and SciPy."""
    from plateqp.linalg import seam as ch

    assert ch._seam() is not None  # the default install: the seam must load (else it is slower)
    K = spd(9, seed=3)
    b = np.random.default_rng(0).standard_normal((K.shape[0], 3))
    ref = spla.spsolve(K, b)
    last = np.array([5, 17, 40, 63, 70])
    out = {}
    for seam in (True, False):
        monkeypatch.setattr(ch, "SEAM", seam)
        f = Factor(K, method="cvxopt")
        assert (f.chol.direct is not None) == seam
        S = SchurFactor(K, last, method="cvxopt")
        out[seam] = (f.solve(b), S.schur(), S.forward(b[:, 0]))
        assert rel(out[seam][0], ref) < 1e-12
        assert rel(out[seam][1], dense_schur(K, last)) < 1e-9
    for a, c in zip(out[True], out[False]):
        np.testing.assert_array_equal(a, c)  # the same supernodal factor, to the bit


@pytest.mark.skipif(not linalg.HAVE_CVXOPT, reason="cvxopt is not installed")
def test_the_seam_refuses_singular_and_indefinite_matrices_silently(capfd):
    """Simplicial CHOLMOD would factor an indefinite matrix as L D Lᵀ without a word; the seam
    asks for L Lᵀ, so it refuses, and CHOLMOD prints nothing (stdout may carry --json)."""
    A = laplacian(6, 1.0).tolil()
    A[10, 10] = -1.0
    for M in (laplacian(6), A.tocsc()):  # singular (constants); indefinite
        with pytest.raises(SingularMatrixError):
            ch_ = Factor(M, method="cvxopt")
            assert ch_.chol.direct is not None
    assert capfd.readouterr().out == ""


@pytest.mark.skipif(not linalg.HAVE_CVXOPT, reason="cvxopt is not installed")
def test_a_different_cholmod_layout_falls_back_to_the_binding(monkeypatch):
    from plateqp.linalg import seam as ch

    monkeypatch.setattr(ch, "_SEAM", False)  # not tried yet
    monkeypatch.setattr(ch, "_LAYOUT", ch._LAYOUT + ((ch._OFF_PRINT, "i", 99),))  # not CHOLMOD 3's
    assert ch._seam() is None
    f = Factor(spd(5), method="cvxopt")
    assert f.chol.direct is None
    assert rel(f.solve(np.ones(25)), spla.spsolve(spd(5), np.ones(25))) < 1e-12


@pytest.mark.usefixtures("seam_off")
def test_pdas_through_cvxopts_binding_too():
    """The fallback route (cvxopt's own binding) still solves a contact scene exactly."""
    import plateqp as pq
    from plateqp.scenes.families import grid_rigid

    res = pq.solve(grid_rigid(8, 3), backend="pdas", accuracy=1e-10)
    assert res.kkt.ok and res.extras["cholmod"] == "cvxopt"


@pytest.mark.skipif(not linalg.HAVE_CVXOPT, reason="cvxopt is not installed")
def test_the_seam_takes_either_triangle_or_the_whole_matrix():
    """CHOLMOD is told which triangle it was handed (stype): the lower triangle, the upper one
    (what it reads fastest) and the whole symmetric matrix give the same solves."""
    from plateqp.linalg import seam

    K = spd(7, seed=5)
    s = 1.0 / np.sqrt(K.diagonal())
    b = np.random.default_rng(2).standard_normal(K.shape[0])
    ref = np.linalg.solve((sp.diags(s) @ K @ sp.diags(s)).toarray(), b)
    full = linalg.pattern.scaled(K, s)
    unsorted = full.copy()
    unsorted.indices = unsorted.indices.copy()
    for j in range(unsorted.shape[1]):  # each column's entries reversed: not sorted
        a, z = unsorted.indptr[j], unsorted.indptr[j + 1]
        unsorted.indices[a:z] = unsorted.indices[a:z][::-1]
        unsorted.data[a:z] = unsorted.data[a:z][::-1]
    unsorted.has_sorted_indices = False
    for A, stype in ((lower(K, s), -1), (lower(K, s, upper=True), 1), (full, 1), (unsorted, 1)):
        assert seam._stype(A) == stype
        chol = Cholesky("cvxopt")
        assert chol.direct is not None and chol.upper
        chol.analyse(A)
        chol.factor(A)
        assert rel(chol.solve(b), ref) < 1e-12


@pytest.mark.skipif(not linalg.HAVE_CVXOPT, reason="cvxopt is not installed")
def test_a_seam_that_loses_the_order_falls_back_with_the_triangle_it_was_handed(monkeypatch):
    """If CHOLMOD did not keep a given order (a layout not the one checked), the factor goes
    through cvxopt's binding instead, which reads a lower triangle: the upper one made for the
    seam is transposed for it, so the Schur complement is still right."""
    from plateqp.linalg import seam

    def lose(self, A, perm):
        raise OSError("CHOLMOD did not keep the given order")

    monkeypatch.setattr(seam._Direct, "analyse", lose)
    K = spd(8, seed=4)
    last = np.array([3, 20, 41, 60])
    S = SchurFactor(K, last, method="cvxopt")
    assert S.chol.direct is None
    assert rel(S.schur(), dense_schur(K, last)) < 1e-9
    b = np.ones(K.shape[0])
    assert rel(S.solve(b), spla.spsolve(K, b)) < 1e-10
