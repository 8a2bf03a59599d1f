r"""Primal–dual active set (semismooth Newton) for the sparse primal contact QP.

The problem
-----------
The primal formulation's QP (:class:`plateqp.contact.formulations.Primal`)

.. math::

    \min_x\ \tfrac12 x^T P x + q^T x \quad\text{s.t.}\quad G x \le h,

with ``P`` sparse, few rows ``m ≪ n`` in ``G``, no equalities and no bounds. The backend
refuses any other shape with a :class:`~plateqp.errors.SolverError`, so that it is offered
only where it makes sense.

Variables ``x_j`` that are *separable* (the column of ``P`` holds only ``P_jj > 0``, the column
of ``G`` one entry ``γ`` in row ``i``) are eliminated exactly: stationarity gives
``x_j = −(q_j + γ λ_i) / P_jj``. On the primal formulation those are the spring variables
``t`` (``P_tt = 1``, ``G_it = −√ρ_i``), so what remains is the contact problem in the plate's
own terms, with ``K = P_uu``, ``f = −q_u``, ``B = G_u`` and, per row, a flexibility
``ρ_i = Σ γ²/P_jj`` (0: rigid) and gap ``g_i = h_i + Σ γ q_j / P_jj``:

.. math::

    K u - f + B^T\lambda = 0,\qquad
    \lambda \ge 0,\quad \mathrm{gap} = g + \rho\lambda - B u \ge 0,\quad
    \lambda_i\,\mathrm{gap}_i = 0 .

The method
----------
Semismooth Newton on ``min(λ, c ⊙ gap) = 0`` (``c_i = k_i / (1 + ρ_i k_i)``, the local
stiffness ``k_i = Σ_j B_ij² K_jj`` of row ``i`` in series with its spring), i.e. the
primal–dual active set method: with the active set ``A = {i : λ_i − c_i gap_i > 0}`` each
step solves the equality-constrained problem

.. math::

    K u + B_A^T \lambda_A = f,\qquad B_A u - \rho_A \lambda_A = g_A,\qquad \lambda_I = 0 .

With exact steps (``gap_A = 0``, ``λ_I = 0``) the rule reads: a row leaves ``A`` when its
reaction is negative and enters when its gap is, all at once; this is block principal
pivoting (Júdice & Pires 1994) on the dual LCP, and the choice of ``c`` only scales the
tolerances. **Globalisation**: block exchanges can cycle (the plate's condensed stiffness is
not an M-matrix, so the monotone convergence of PDAS is not guaranteed), so the number of
infeasible rows is watched; when it has not fallen below its best value for ``p`` steps, or
an active set comes back, one row only is exchanged, the infeasible row of largest index
(Murty's rule), until the count falls again. Murty's rule terminates for a P-matrix, which
the dual LCP's matrix ``B K⁻¹ Bᵀ + diag(ρ)`` is whenever ``K`` is definite and ``B`` has full
row rank; ``max_iter`` bounds the work for the rest (``Status.MAX_ITER``).

Two ways to solve a step
------------------------
``method="condensed"`` (the default where CHOLMOD is at hand, through scikit-sparse or the copy
in cvxopt's wheels, ``K`` is definite and the rows touch at most ``max_dense`` dofs: discrete
supports on a held plate). The dofs the rows act on go *last* in the elimination order
(AMD order on the rest); one sparse Cholesky ``K = L Lᵀ`` then holds, in its trailing dense
block ``L_cc``, the static condensation of every other dof: ``L_cc L_ccᵀ`` is the condensed
stiffness. With ``Z = L_cc⁻¹ B_cᵀ`` (a dense triangular solve) the dual LCP

.. math::

    \mathrm{gap} = d + M\lambda,\qquad M = Z^T Z + \mathrm{diag}(\rho) = B K^{-1} B^T + \mathrm{diag}(\rho),
    \qquad d = g - B K^{-1} f,

costs no column solves at all (where each row is one dof, ``M`` is the inverse of
``L_cc L_ccᵀ``, LAPACK's POTRI, rows and columns scaled). Measured on a 128 × 128 plate with a
30 × 30 grid of supports: the contacts-last factor costs about 1.5–2 plain factorisations,
plus a third of one to read ``L_cc``, where the columns ``K⁻¹ B_iᵀ`` (each about 1/50 of a
factorisation, even solved in blocks) would cost 18 for the 900 rows. Each active set is
then a dense Cholesky of ``M_AA`` (|A|³/3 flops). The final set is solved on the exact sparse
equations by iterative refinement with ``K⁻¹`` and ``M_AA`` (two sparse solves per step), so
rounding in ``d`` (``g − B K⁻¹ f`` cancels) does not reach the answer. (cvxopt's factor is
spent once ``L_cc`` is read from it: there the solves use a second, plain factorisation,
:class:`plateqp.linalg.Factor`.)

``method="sparse"`` (beds: every node a contact point; floating plates; no CHOLMOD). One
sparse Cholesky of

.. math::

    H_A = K + \sigma\,\mathrm{diag}(K) + B_A^T W_A B_A,\qquad
    W_i = \frac{1}{\rho_i + 1/\beta_i},\quad \beta_i = \kappa\, k_i,

a spring on each active row (the row's own spring for an elastic support; a stiff penalty
spring, ``κ = 10⁸``, for a rigid one; in series for a stiff elastic one); ``σ = 10⁻¹²`` keeps
``H_A`` definite for a floating plate whose active rows do not hold it. The exact step is
reached by iterative refinement on the exact equations (proximal augmented Lagrangian):
with ``r_u = f − K u − B_Aᵀλ_A`` and ``r_A = B_A u − g_A − ρ_A λ_A``,

.. math::

    H_A\,\delta u = r_u - B_A^T W_A r_A,\qquad
    \lambda_A \leftarrow \lambda_A + W_A (r_A + B_A \delta u),\qquad u \leftarrow u + \delta u,

exact in one step for springs, contracting a rigid row's error by about
``1/(1 + κ k λ_min(flexibility))`` per step. While the active set still changes one or two
solves classify the rows; the final set is solved to rounding. The factor follows the active
set: the symbolic analysis (of the pattern of ``K + BᵀB``, which contains every ``H_A``) is
done once and every change is a numeric refactorisation with it; with scikit-sparse, rows
that enter or leave are instead added or removed by CHOLMOD's rank-k update/downdate when
that is cheaper (the costs are measured as the solve goes: about 0.4 ms a row against 0.15 s
a factorisation on a 128 × 128 plate). A downdate of a stiff penalty loses about ``ε κ``
relative; that only slows the refinement, and the factor is rebuilt when the accumulated
loss says so. Without CHOLMOD every change refactorises with :class:`plateqp.linalg.Factor`
(SuperLU: its analysis cannot be re-used).

A bed's first steps change thousands of rows each (plain PDAS from the two-sided start:
16 641 → 11 501 → 9 352 → 8 727 → 8 658 rows in contact on a 128 × 128 bed, a
refactorisation each). So when every row is a soft spring (``ρ_i k_i ≥ 1``: no stiffer than
the plate under it) and there is no warm start, a first phase finds the contact without
refactorising: semismooth Newton on the energy ``½uᵀKu − fᵀu + Σ ½ W_i max(0, B_i u − g_i)²``
(the tensionless bed's own energy), each Newton system solved roughly (PCG to
``PCG_TOL``) with the factor of the two-sided matrix as preconditioner, then an exact line
search (the energy is piecewise quadratic along a line). Removing soft springs changes
``H`` only in its few smooth, spring-dominated modes, so PCG needs a handful of iterations.
When a Newton step changes few rows (``NEWTON_SETTLED``), the factor is rebuilt once for that
active set and exact steps finish as above. On the 128 × 128 bed: three Newton steps, 13 PCG
iterations, then one exact step and two updated rows.

Singular steps and no equilibrium (sparse method)
-------------------------------------------------
If the active rows do not hold a floating plate, the refinement's first correction is
dominated by a rigid motion ``d`` (``K d ≈ 0``, ``B_A d ≈ 0``), recognised by its Rayleigh
quotient ``δuᵀ(H_A − σD)δu / (σ δuᵀDδu) < 1`` (a held plate gives ``λ_min/σ ≳ 10⁴``). Rows that
``d`` would press into (``B_i d > 0``) enter the active set; if there are none and the load
does work along ``d`` (``fᵀd > 0``), then ``K d = 0``, ``G d ≤ 0``, ``qᵀd < 0``: a certificate
that the QP is unbounded below, the plate cannot be held (``Status.UNBOUNDED``,
``extras["ray"]``; the contact driver turns it into :class:`~plateqp.errors.NoEquilibriumError`
after its own statics check). The condensed method needs a definite ``K`` and leaves
floating plates to the sparse one.

Warm start and output
---------------------
Option ``active`` (bool array over the rows of ``G``) gives the first active set (default:
the rows the unsupported plate would press into, ``d < 0``, for the condensed method; every
row, the two-sided problem, for the sparse one); ``extras["active"]`` holds the final set,
so a sweep can warm start each solve from the previous one. ``x`` (``u`` with the eliminated
variables restored), ``z = λ ≥ 0`` (one per row of ``G``, the qpsolvers sign convention),
``iterations`` (active sets solved, Newton steps of the first phase included),
``solve_time``; ``extras`` has the method and the counts and times of the linear algebra
(``extras["trace"]`` each step, with option ``trace``).

Accuracy
--------
A direct method: at every preset the final active set is solved to rounding. The presets of
:data:`ACCURACY` set only the tolerance under which a negative reaction or gap counts as zero
(``feas_tol``) and the residual above which the answer is flagged ``INACCURATE``
(``accept_tol``), checked on the answer itself: the relative natural residual
``max |min(λ_i, c_i gap_i)| / max(‖λ‖∞, 10⁻¹² ‖f‖₁)`` (as :mod:`plateqp.contact.kkt`) and the relative
stationarity residual ``‖K u − f + Bᵀλ‖ / max(‖f‖, ‖Bᵀλ‖)``.
"""

from __future__ import annotations

import contextlib
import sys
import time
import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .. import linalg as _linalg
from ..errors import ProblemError, SolverError
from ..linalg import Factor
from .base import QP, RawSolution, Status, plateqp_version, preset


def _bindings() -> list[str]:
    """The CHOLMOD bindings :mod:`plateqp.linalg` found, best first ("sksparse": scikit-sparse,
    analysis re-use and rank-k updates; "cvxopt": the copy in cvxopt's wheels, analysis
    re-use). Read at every solve, so that a test can turn one off in plateqp.linalg."""
    out = []
    if getattr(_linalg, "HAVE_CHOLMOD", False):
        out.append("sksparse")
    if getattr(_linalg, "HAVE_CVXOPT", False):
        out.append("cvxopt")
    return out


class _NotDefinite(Exception):
    """CHOLMOD met a non-positive pivot."""


@contextlib.contextmanager
def _cvx_options(**kw):
    """cvxopt's CHOLMOD options are one global dict: set them for one call, then restore."""
    from cvxopt import cholmod

    old = dict(cholmod.options)
    cholmod.options.update(kw)
    try:
        yield cholmod
    finally:
        cholmod.options.clear()
        cholmod.options.update(old)


class _Chol:
    """One sparse Cholesky factor through a CHOLMOD binding, with the few calls pdas needs.

    Matrices are SciPy CSC holding the lower triangle (all CHOLMOD reads). ``analyse`` once,
    then ``factor`` any matrix of that pattern (or a sub-pattern), as often as needed.
    """

    def __init__(self, lib: str) -> None:
        self.lib = lib
        self.sym = None  # scikit-sparse: the analysis; cvxopt: the factor object itself
        self.F = None
        self._last = (None, None)  # cvxopt: the last matrix converted, and its conversion

    @property
    def can_update(self) -> bool:
        return self.lib == "sksparse" and self.F is not None

    def _cvx(self, A: sp.csc_matrix):
        if self._last[0] is A:
            return self._last[1]
        from cvxopt import matrix, spmatrix

        cols = np.repeat(np.arange(A.shape[0], dtype=np.int64), np.diff(A.indptr))
        out = spmatrix(matrix(A.data.astype(float)), matrix(A.indices.astype(np.int64)), matrix(cols), A.shape)
        self._last = (A, out)
        return out

    def order(self, A: sp.csc_matrix) -> np.ndarray:
        """A fill-reducing (AMD) order of ``A``'s pattern."""
        if self.lib == "sksparse":
            import sksparse.cholmod as ch

            return ch.analyze(A, mode="supernodal", ordering_method="amd").P()
        from cvxopt import amd

        return np.array(amd.order(self._cvx(A), uplo="L"), dtype=np.int64).ravel()

    def analyse(self, A: sp.csc_matrix, natural: bool = False) -> None:
        n = A.shape[0]
        if self.lib == "sksparse":
            import sksparse.cholmod as ch

            self.sym = ch.analyze(A, mode="supernodal", ordering_method="natural" if natural else "default")
            return
        from cvxopt import matrix

        opts = {"nmethods": 1, "postorder": False} if natural else {}  # else CHOLMOD reorders anyway
        with _cvx_options(**opts) as cholmod:
            p = matrix(np.arange(n, dtype=np.int64)) if natural else None
            self.sym = cholmod.symbolic(self._cvx(A), p=p) if natural else cholmod.symbolic(self._cvx(A))

    def factor(self, A: sp.csc_matrix) -> None:
        """Numeric factorisation with the analysis (raises _NotDefinite)."""
        if self.lib == "sksparse":
            import sksparse.cholmod as ch

            try:
                self.F = self.sym.cholesky(A)
            except ch.CholmodNotPositiveDefiniteError as exn:
                raise _NotDefinite(str(exn)) from exn
            return
        from cvxopt import cholmod

        try:
            cholmod.numeric(self._cvx(A), self.sym)
        except ArithmeticError as exn:
            raise _NotDefinite(f"non-positive pivot at column {exn}") from exn
        self.F = self.sym

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``A⁻¹ b`` (the factor's permutation applied inside)."""
        if self.lib == "sksparse":
            return self.F.solve_A(b)
        from cvxopt import cholmod, matrix

        B = matrix(np.asarray(b, dtype=float).copy())
        cholmod.solve(self.F, B)
        return np.array(B).ravel()

    def trailing(self, no: int) -> np.ndarray:
        """The trailing block ``L[no:, no:]`` of the factor, dense (natural order). cvxopt's
        factor is spent afterwards (no more solves)."""
        if self.lib == "sksparse":
            return self.F.L()[no:, no:].toarray()
        from cvxopt import cholmod

        G = cholmod.getfactor(self.F)
        self.F = self.sym = None
        colptr, rowind, vals = (np.asarray(memoryview(v)).ravel() for v in G.CCS)  # no copies
        n = G.size[0]
        start = int(colptr[no])
        cols = np.repeat(np.arange(n - no), np.diff(colptr[no:]))
        out = np.zeros((n - no, n - no))
        out[rowind[start:] - no, cols] = vals[start:]
        return out

    def update(self, C: sp.csc_matrix, subtract: bool) -> None:
        self.F.update_inplace(C, subtract=subtract)


__all__ = ["ACCURACY", "OPTIONS", "SETTINGS", "accepts", "available", "backends", "formulations", "name", "pdas",
           "solve", "version"]

name = "pdas"
accepts = frozenset({"qp"})
#: The QP of the primal formulation only (see :func:`plateqp.contact.formulations_for`).
formulations = ("primal",)

#: Tolerances of each accuracy preset (a direct method: exact up to rounding at every preset).
#:
#: ``feas_tol``
#:     a reaction ``λ_i`` (a gap, as the force ``c_i gap_i``) counts as negative only below
#:     ``−feas_tol`` times the force scale ``max(‖λ‖∞, 10⁻¹² ‖f‖₁)``; smaller negatives are
#:     rounding (and such reactions are clipped to zero in the answer).
#: ``accept_tol``
#:     relative natural and stationarity residuals of the answer above which the status is
#:     ``INACCURATE`` instead of ``OPTIMAL``.
ACCURACY: dict[str, dict[str, float]] = {
    "low": {"feas_tol": 1e-8, "accept_tol": 1e-6},
    "default": {"feas_tol": 1e-11, "accept_tol": 1e-8},
    "high": {"feas_tol": 1e-13, "accept_tol": 1e-10},
}

#: Method settings (not accuracy: the answer is exact at every value); options override them.
#:
#: ``method``     "auto" (condensed where it applies, else sparse), "condensed", "sparse".
#: ``max_dense``  the condensed method only if the rows touch at most this many dofs.
#: ``penalty``    κ (sparse): a rigid row's spring in ``H_A`` is κ times its local stiffness.
#: ``prox``       σ (sparse): ``H_A`` includes σ diag(K) (definite for a floating plate).
#: ``factor``     (sparse) "cholmod" (scikit-sparse: analysis re-used, rank-k updates),
#:                "cvxopt" (CHOLMOD in cvxopt's wheels: analysis re-used, a numeric
#:                refactorisation at every change), "linalg" (:class:`plateqp.linalg.Factor`'s
#:                own choice, a new factorisation at every change), "superlu" (Factor's SuperLU,
#:                likewise); "auto": the first of these that is installed.
#: ``p``          block exchanges allowed without progress before Murty's single exchange.
#: ``max_rows``   refuse a ``G`` with more rows than ``min(n, max_rows)``.
#: ``max_iter``   active sets solved before ``Status.MAX_ITER``; default 50 + 2 m.
SETTINGS: dict = {"method": "auto", "max_dense": 2000, "penalty": 1e8, "prox": 1e-12, "factor": "auto",
                  "p": 3, "max_rows": 100_000, "max_iter": None}

#: Keys accepted in the ``options`` dict of :func:`solve`.
OPTIONS = ("active", "trace") + tuple(SETTINGS) + tuple(ACCURACY["default"])

#: (sparse) A first correction with Rayleigh quotient δuᵀ(H − σD)δu / (σ δuᵀDδu) below this is
#: a rigid motion the active rows do not hold.
SINGULAR_QUOTIENT = 1.0
#: Refinement: at most this many solves per active set while it changes, and for the final set.
INNER_LOOSE, INNER_EXACT = 2, 12
#: (sparse) While the active set changes, refinement stops at this relative residual.
LOOSE_TOL = 1e-7
#: (sparse) Rebuild the factor rather than downdate when the digits lost to downdates
#: (Σ ε·ΔW_i/c_i) would pass this: a soft spring's downdate loses ~ε, a rigid row's penalty
#: ~ε·κ = 2e-8, which would hide the σ-sized modes of a plate the active rows do not hold.
DOWNDATE_LOSS = 1e-10
#: (sparse, soft rows) Phase 1: at most this many Newton steps, PCG to this relative tolerance
#: (at most PCG_MAX iterations each); it ends when a step changes at most
#: max(NEWTON_SETTLED, NEWTON_SETTLED_FRACTION · m) rows, or when its solves have cost
#: NEWTON_BUDGET factorisations.
NEWTON_STEPS, PCG_TOL, PCG_MAX = 8, 5e-2, 30
NEWTON_SETTLED, NEWTON_SETTLED_FRACTION, NEWTON_BUDGET = 10, 2e-3, 3.0
#: The line search looks for the minimum up to this step length.
ALPHA_MAX = 1e3
#: (condensed) A trailing pivot L_ii² below this (K equilibrated to a unit diagonal) means K is
#: singular to working precision (a floating plate): the sparse method takes over.
PIVOT_TOL = 1e-13

_RAY_MESSAGE = ("the active rows cannot hold the plate and no inactive row is pressed along the rigid motion "
                "d it falls along: K d = 0, G d ≤ 0, qᵀd < 0 (the QP is unbounded below; the one-sided "
                "supports cannot carry the load)")


def available() -> bool:
    """PDAS needs NumPy and SciPy only (CHOLMOD makes it faster): always available."""
    return True


version = plateqp_version  # the backend is part of plateqp


def backends() -> list:
    """The backends this module provides: ``[module]`` (it satisfies the ``Backend`` protocol)."""
    return [sys.modules[__name__]]


# --------------------------------------------------------------------------- the problem


class _Contact:
    """The QP as a contact problem: separable variables eliminated (see the module docstring)."""

    def __init__(self, qp: QP, max_rows: int) -> None:
        if not isinstance(qp, QP):
            raise SolverError(f"the pdas backend solves QPs only (the primal formulation), got {type(qp).__name__}")
        if qp.A is not None or qp.lb is not None or qp.ub is not None:
            raise SolverError("the pdas backend takes a QP with inequalities G x ≤ h only, no equality rows "
                              "and no bounds: use formulation='primal' (the condensed and dual formulations "
                              "are bound-constrained; give them to lemke or bpp)")
        if qp.G is None or qp.G.shape[0] == 0:
            raise SolverError("the pdas backend needs inequality rows G x ≤ h; this QP has none")
        if not (sp.issparse(qp.P) and sp.issparse(qp.G)):
            raise SolverError("the pdas backend takes sparse P and G (the primal formulation); for a dense "
                              "problem use the condensed formulation with lemke or bpp")
        m, n = qp.G.shape
        if m > min(n, max_rows):
            raise SolverError(f"the pdas backend takes few constraint rows (m ≤ min(n, {max_rows})), "
                              f"got m = {m}, n = {n}")
        P = sp.csc_matrix(qp.P, dtype=float)
        P.eliminate_zeros()
        G = sp.csc_matrix(qp.G, dtype=float)
        G.eliminate_zeros()
        v, w = np.random.default_rng(0).standard_normal((2, n))
        if abs(v @ (P @ w) - w @ (P @ v)) > 1e-10 * np.sqrt((P @ v) @ (P @ v) * (w @ w)) + 1e-300:
            raise SolverError("the pdas backend needs a symmetric P")  # a randomised check, O(nnz)
        d = P.diagonal()
        sep = (np.diff(P.indptr) == 1) & (d > 0) & (np.diff(G.indptr) == 1)
        # a row left with no coupled variable keeps its separable ones (as plain variables)
        coupled = np.bincount(G.indices, weights=~sep[np.repeat(np.arange(n), np.diff(G.indptr))], minlength=m)
        lone = coupled[G.indices] == 0
        sep[np.repeat(np.arange(n), np.diff(G.indptr))[lone]] = False
        keep = ~sep
        self.n, self.m = n, m
        self.sep, self.keep = np.flatnonzero(sep), np.flatnonzero(keep)
        Gs = G[:, self.sep].tocoo()  # one entry per column
        self.sep_row = np.empty(self.sep.size, dtype=int)
        self.sep_gamma = np.empty(self.sep.size)
        self.sep_row[Gs.col], self.sep_gamma[Gs.col] = Gs.row, Gs.data
        self.sep_p = d[self.sep]
        self.sep_q = qp.q[self.sep]
        self.K = P[self.keep][:, self.keep].tocsc() if self.sep.size else P
        self.f = -qp.q[self.keep]
        self.B = (G[:, self.keep] if self.sep.size else G).tocsr()
        self.rho = np.bincount(self.sep_row, weights=self.sep_gamma**2 / self.sep_p, minlength=m)
        self.g = qp.h + np.bincount(self.sep_row, weights=self.sep_gamma * self.sep_q / self.sep_p, minlength=m)
        Kd = self.K.diagonal()
        if np.any(Kd <= 0):
            raise SolverError("the pdas backend needs P with a positive diagonal on the coupled variables "
                              "(a variable with no stiffness is a mechanism of the plate)")
        empty = np.flatnonzero(np.diff(self.B.indptr) == 0)
        if empty.size:
            raise SolverError(f"row {empty[0]} of G acts on no coupled variable: not a contact row")
        self.Kd = Kd
        self.k = self.B.multiply(self.B) @ Kd  # local stiffness of each row
        self.c = self.k / (1.0 + self.rho * self.k)  # in series with the row's spring
        self.P, self.q = P, qp.q

    def x(self, u: np.ndarray, lam: np.ndarray) -> np.ndarray:
        x = np.empty(self.n)
        x[self.keep] = u
        x[self.sep] = -(self.sep_q + self.sep_gamma * lam[self.sep_row]) / self.sep_p
        return x


# --------------------------------------------------------------------------- the factor


class _SpringFactor:
    """Factor of ``H(w) = K + σ diag(K) + Bᵀ diag(w) B``, kept current as ``w`` changes.

    CHOLMOD: one symbolic analysis of the pattern of ``K + BᵀB`` (equilibrated by
    ``diag(K)^(-1/2)``); changes by numeric refactorisation with that analysis or, with
    scikit-sparse, by rank-k update/downdate, whichever the measured costs say is cheaper.
    Otherwise :class:`plateqp.linalg.Factor` on every change.
    """

    def __init__(self, K: sp.csc_matrix, B: sp.csr_matrix, Kd: np.ndarray, c: np.ndarray,
                 sigma: float, method: str) -> None:
        libs = _bindings()
        if method == "auto":
            method = ("cholmod" if "sksparse" in libs else "cvxopt" if "cvxopt" in libs else "linalg")
        if method not in ("cholmod", "cvxopt", "linalg", "superlu"):
            raise ProblemError("option factor must be 'auto', 'cholmod', 'cvxopt', 'linalg' or 'superlu', "
                               f"got {method!r}")
        lib = {"cholmod": "sksparse", "cvxopt": "cvxopt"}.get(method)
        if lib is not None and lib not in libs:
            raise SolverError(f"option factor={method!r}: that CHOLMOD binding is not in use here "
                              f"(plateqp.linalg found: {libs or 'none'})")
        self.method = method
        self.chol = _Chol(lib) if lib else None
        n, m = K.shape[0], B.shape[0]
        self.B, self.c = B, c
        self.s = 1.0 / np.sqrt(Kd)
        Babs = abs(B)
        pat = sp.csc_matrix(abs(K) + Babs.T @ Babs)
        pat.sort_indices()
        self.indptr, self.indices = pat.indptr, pat.indices
        cols = np.repeat(np.arange(n), np.diff(pat.indptr))
        keys = cols.astype(np.int64) * n + pat.indices
        nnz = keys.size

        def pos(r, cc):
            return np.searchsorted(keys, np.asarray(cc, np.int64) * n + r)

        Ks = sp.csc_matrix(K)
        Ks.sort_indices()
        if Ks.nnz == nnz:  # B's pattern lies in K's (rows within one element): same structure
            self.base = Ks.data.astype(float, copy=True)
        else:
            Kc = Ks.tocoo()
            self.base = np.bincount(pos(Kc.row, Kc.col), weights=Kc.data, minlength=nnz)
        self.base[pos(np.arange(n), np.arange(n))] += sigma * Kd
        # all products B_ia B_ib of each row, and where they go in the pattern
        L = np.diff(B.indptr)
        L2 = L * L
        pr = np.repeat(np.arange(m), L2)
        within = np.arange(L2.sum()) - np.repeat(np.cumsum(L2) - L2, L2)
        ia = B.indptr[pr] + within // L[pr]
        ib = B.indptr[pr] + within % L[pr]
        self.pair_row, self.pair_val = pr, B.data[ia] * B.data[ib]
        self.pair_pos = pos(B.indices[ia], B.indices[ib])
        self.scale = self.s[pat.indices] * self.s[cols]
        self.nnz = nnz
        # CHOLMOD reads the lower triangle only: hand it that (half the data)
        self.low = np.flatnonzero(pat.indices >= cols)
        self.low_indptr = np.concatenate([[0], np.cumsum(np.bincount(cols[self.low], minlength=n))])
        self.w = None
        self.fac = None  # a plateqp.linalg.Factor (linalg, superlu)
        self.loss = 0.0
        self.t_factor = None  # seconds per numeric factorisation (last measured)
        self.t_row = None  # seconds per updated row (last measured)
        self.stats = {"analyse_s": 0.0, "factorisations": 0, "factor_s": 0.0, "updates": 0, "updated_rows": 0,
                      "update_s": 0.0, "solves": 0, "solve_s": 0.0}

    def _matrix(self, w: np.ndarray, scaled: bool) -> sp.csc_matrix:
        data = self.base + np.bincount(self.pair_pos, weights=w[self.pair_row] * self.pair_val,
                                       minlength=self.nnz)
        n = self.s.size
        if scaled:  # the lower triangle, equilibrated, for CHOLMOD
            low = self.low
            return sp.csc_matrix((data[low] * self.scale[low], self.indices[low], self.low_indptr), shape=(n, n))
        return sp.csc_matrix((data, self.indices, self.indptr), shape=(n, n))

    def refactor(self, w: np.ndarray) -> None:
        t0 = time.perf_counter()
        if self.chol is not None:
            H = self._matrix(w, scaled=True)
            if self.chol.sym is None:
                self.chol.analyse(H)
                t1 = time.perf_counter()
                self.stats["analyse_s"] += t1 - t0
                t0 = t1
            try:
                self.chol.factor(H)
            except _NotDefinite as exn:
                raise SolverError(f"pdas: the active-set matrix is not positive definite ({exn}); is P "
                                  "positive semidefinite?") from exn
        else:  # plateqp.linalg.Factor: its own choice of library, or SuperLU; analysis not re-used
            try:
                self.fac = Factor(self._matrix(w, scaled=False), method="auto" if self.method == "linalg" else "superlu")
            except Exception as exn:
                raise SolverError(f"pdas: the active-set matrix could not be factorised ({exn})") from exn
        dt = time.perf_counter() - t0
        self.t_factor = dt
        self.stats["factorisations"] += 1
        self.stats["factor_s"] += dt
        self.w = w.copy()
        self.loss = 0.0

    def set(self, w: np.ndarray) -> None:
        """Make the factor that of ``H(w)``."""
        if self.w is None:
            self.refactor(w)
            return
        dw = w - self.w
        changed = np.flatnonzero(dw)
        if changed.size == 0:
            return
        down = changed[dw[changed] < 0]
        loss = self.loss + np.finfo(float).eps * np.sum(-dw[down] / self.c[down])
        t_row = self.t_row if self.t_row is not None else self.t_factor / 400.0
        if (self.chol is None or not self.chol.can_update or changed.size * t_row > 0.7 * self.t_factor
                or loss > DOWNDATE_LOSS):
            self.refactor(w)
            return
        t0 = time.perf_counter()
        up = changed[dw[changed] > 0]
        for rows, subtract in ((up, False), (down, True)):  # updates first: stays definite
            if rows.size:
                C = (self.B[rows].T.tocsc() @ sp.diags(np.sqrt(np.abs(dw[rows])))).tocsc()
                C = sp.diags(self.s) @ C
                self.chol.update(sp.csc_matrix(C), subtract)
        dt = time.perf_counter() - t0
        self.t_row = dt / changed.size
        self.stats["updates"] += 1
        self.stats["updated_rows"] += int(changed.size)
        self.stats["update_s"] += dt
        self.w = w.copy()
        self.loss = loss

    def solve(self, b: np.ndarray) -> np.ndarray:
        t0 = time.perf_counter()
        if self.chol is not None:
            x = self.s * self.chol.solve(self.s * b)
        else:
            x = self.fac.solve(b, refine=0)
        self.stats["solves"] += 1
        self.stats["solve_s"] += time.perf_counter() - t0
        return x


# --------------------------------------------------------------------------- condensed in the factor


class _NotApplicable(Exception):
    """The condensed method does not apply (too many contact dofs, K singular, no CHOLMOD)."""


def _lower_permuted(K: sp.csc_matrix, s: np.ndarray, perm: np.ndarray) -> sp.csc_matrix:
    """Lower triangle of ``(S K S)[perm][:, perm]``, ``S = diag(s)``, built in O(nnz) (CHOLMOD
    reads only the lower triangle)."""
    n = K.shape[0]
    inv = np.empty(n, dtype=np.int64)
    inv[perm] = np.arange(n)
    col = np.repeat(np.arange(n), np.diff(K.indptr))
    r, c = inv[K.indices], inv[col]
    keep = r >= c
    data = K.data[keep] * s[K.indices[keep]] * s[col[keep]]
    return sp.csc_matrix((data, (r[keep], c[keep])), shape=(n, n))


class _Condensed:
    """``K = L Lᵀ`` with the rows' dofs last; the dual LCP ``(M, d)`` from the trailing block.

    In the equilibrated, permuted variables ``ũ_p = (u / s)[perm]``, ``s = diag(K)^(-1/2)``,
    ``B̃_c`` is ``B`` on the trailing dofs and ``M = B̃_c (L_cc L_ccᵀ)⁻¹ B̃_cᵀ + diag(ρ)``;
    ``d = g − B K⁻¹ f``. Solves with ``K``: the same factor (scikit-sparse), or a plain
    :class:`plateqp.linalg.Factor` of ``K`` (cvxopt, whose factor is spent once ``L`` is read).
    """

    def __init__(self, pb: _Contact, max_dense: int) -> None:
        libs = _bindings()
        if not libs:
            raise _NotApplicable("no CHOLMOD binding (scikit-sparse or cvxopt) is in use here")
        B = pb.B
        c = np.unique(B.indices)
        if c.size > max_dense:
            raise _NotApplicable(f"the rows touch {c.size} dofs (max_dense = {max_dense})")
        n, nc, m = pb.K.shape[0], c.size, pb.m
        chol = _Chol(libs[0])
        self.stats = {"analyse_s": 0.0, "factor_s": 0.0, "extract_s": 0.0, "dense_s": 0.0, "solves": 0,
                      "solve_s": 0.0, "factorisations": 1, "contact_dofs": int(nc), "cholmod": chol.lib}
        t0 = time.perf_counter()
        s = 1.0 / np.sqrt(pb.Kd)
        # fill-reducing order of the whole matrix, the rows' dofs then moved to the end
        order = chol.order(_lower_permuted(pb.K, s, np.arange(n)))
        last = np.zeros(n, dtype=bool)
        last[c] = True
        perm = np.concatenate([order[~last[order]], c])
        Kp = _lower_permuted(pb.K, s, perm)
        chol.analyse(Kp, natural=True)
        t1 = time.perf_counter()
        try:
            chol.factor(Kp)
        except _NotDefinite as exn:
            raise _NotApplicable(f"K is not positive definite ({exn}): a floating plate") from exn
        t2 = time.perf_counter()
        no = n - nc
        Lcc = chol.trailing(no)
        t3 = time.perf_counter()
        if np.diagonal(Lcc).min(initial=1.0) ** 2 < PIVOT_TOL:
            raise _NotApplicable("K is singular to working precision: a floating plate")
        if chol.lib == "sksparse":  # the factor still solves (natural order: P = I)
            self._solve_p = chol.solve
        else:
            self._Kfac = Factor(pb.K)
            self.stats["factorisations"] += 1
        t4 = time.perf_counter()
        Bc = sp.csr_matrix(B[:, c] @ sp.diags(s[c]))  # columns in trailing order
        if m == nc and np.all(np.diff(Bc.indptr) == 1):  # one dof per row, one row per dof
            dof, b = Bc.indices, Bc.data
            Sinv = sla.lapack.dpotri(Lcc, lower=1)[0]  # (L Lᵀ)⁻¹, lower triangle
            Sinv = np.tril(Sinv) + np.tril(Sinv, -1).T
            M = Sinv[np.ix_(dof, dof)] * np.outer(b, b)
        else:
            Z = sla.solve_triangular(Lcc, Bc.T.toarray(), lower=True, check_finite=False)
            M = sla.blas.dsyrk(1.0, Z, trans=1, lower=1)
            M = np.tril(M) + np.tril(M, -1).T
        M[np.diag_indices(m)] += pb.rho
        self.M = M
        self.pb, self.perm, self.s = pb, perm, s
        t5 = time.perf_counter()
        self.d = pb.g - B @ self.solve_K(pb.f)
        self.stats.update(analyse_s=t1 - t0, factor_s=t2 - t1 + t4 - t3, extract_s=t3 - t2, dense_s=t5 - t4)
        self._chol = None

    def solve_K(self, b: np.ndarray) -> np.ndarray:
        """``K⁻¹ b``."""
        t0 = time.perf_counter()
        if hasattr(self, "_Kfac"):
            x = self._Kfac.solve(b, refine=0)
        else:
            x = np.empty_like(b)
            x[self.perm] = self.s[self.perm] * self._solve_p(self.s[self.perm] * b[self.perm])
        self.stats["solves"] += 1
        self.stats["solve_s"] += time.perf_counter() - t0
        return x

    def basic(self, A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``λ`` (``M_AA λ_A = −d_A``, zero off ``A``) and the gaps ``d + M λ``."""
        t0 = time.perf_counter()
        idx = np.flatnonzero(A)
        lam = np.zeros(self.d.size)
        self._chol = None
        if idx.size:
            MAA = self.M[np.ix_(idx, idx)]
            try:
                self._chol = sla.cho_factor(MAA, lower=True, check_finite=False)
                lam[idx] = sla.cho_solve(self._chol, -self.d[idx], check_finite=False)
            except np.linalg.LinAlgError:  # dependent rows (two supports at one point)
                lam[idx] = np.linalg.lstsq(MAA, -self.d[idx], rcond=None)[0]
        gap = self.d + self.M[:, idx] @ lam[idx]
        self.stats["dense_s"] += time.perf_counter() - t0
        return lam, gap

    def exact(self, A: np.ndarray, lam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(u, λ)`` of active set ``A`` on the exact sparse equations: ``basic``'s ``λ``, then
        iterative refinement with ``K⁻¹`` and the Cholesky factor of ``M_AA``: for residuals
        ``r_u``, ``r_A``, ``v = K⁻¹ r_u``, ``M_AA δλ = r_A + B_A v``, ``δu = v − K⁻¹ B_Aᵀ δλ``."""
        pb = self.pb
        idx = np.flatnonzero(A)
        BA = pb.B[idx]
        lam = lam.copy()
        u = self.solve_K(pb.f - BA.T @ lam[idx])
        best = np.inf
        tiny = np.finfo(float).tiny
        for k in range(INNER_EXACT):
            BtL = BA.T @ lam[idx]
            r_u = pb.f - pb.K @ u - BtL
            r_A = BA @ u - pb.g[idx] - pb.rho[idx] * lam[idx]
            delta = max(np.abs(pb.B @ u).max(initial=0.0), np.abs(pb.g).max(initial=0.0), tiny)
            res = max(np.abs(r_u).max() / max(np.abs(pb.f).max(), np.abs(BtL).max(initial=0.0), tiny),
                      np.abs(r_A).max(initial=0.0) / delta)
            if res == 0.0 or (k >= 1 and res > 0.5 * best):
                break
            best = min(best, res)
            v = self.solve_K(r_u)
            if idx.size:
                rhs = r_A + BA @ v
                dlam = (sla.cho_solve(self._chol, rhs, check_finite=False) if self._chol is not None
                        else np.linalg.lstsq(self.M[np.ix_(idx, idx)], rhs, rcond=None)[0])
                v -= self.solve_K(BA.T @ dlam)
                lam[idx] += dlam
            u += v
        return u, lam


# --------------------------------------------------------------------------- the exchange rule


class _Exchange:
    """Block exchange with Júdice–Pires' safeguard: Murty's single exchange when stuck or cycling."""

    def __init__(self, p: int) -> None:
        self.p, self.best, self.backups, self.seen = p, np.inf, p, set()

    def next(self, A: np.ndarray, bad: np.ndarray) -> tuple[np.ndarray, str]:
        count = int(bad.sum())
        key = A.tobytes()
        cycle = key in self.seen
        self.seen.add(key)
        if count < self.best:
            self.best, self.backups = count, self.p
            mode = "block"
        elif self.backups > 0 and not cycle:
            self.backups -= 1
            mode = "block"
        else:
            mode = "single"
        A = A.copy()
        if mode == "block":
            A ^= bad
        else:
            i = np.flatnonzero(bad)[-1]  # Murty: the infeasible row of largest index
            A[i] = not A[i]
        return A, mode


def _force_scale(pb: _Contact, lam: np.ndarray) -> float:
    return max(np.abs(lam).max(initial=0.0), 1e-12 * np.abs(pb.f).sum(), np.finfo(float).tiny)


def _infeasible(pb: _Contact, A: np.ndarray, lam: np.ndarray, gap: np.ndarray, feas_tol: float) -> np.ndarray:
    """Rows to exchange: active with a negative reaction, inactive with a negative gap."""
    F = feas_tol * _force_scale(pb, lam)
    return (A & (lam < -F)) | (~A & (pb.c * gap < -F))


# --------------------------------------------------------------------------- the two methods


class _Outcome:
    def __init__(self, status, message, A, u=None, lam=None, it=0, ray=None):
        self.status, self.message, self.A, self.u, self.lam, self.it, self.ray = status, message, A, u, lam, it, ray


def _run_condensed(pb: _Contact, cond: _Condensed, A, feas_tol, max_iter, p, steps) -> _Outcome:
    A = (cond.d < 0) if A is None else A.copy()
    ex = _Exchange(p)
    for it in range(1, max_iter + 1):
        lam, gap = cond.basic(A)
        bad = _infeasible(pb, A, lam, gap, feas_tol)
        kind = "dense"
        if not bad.any():  # the set looks right: solve it on the exact equations and look again
            u, lam = cond.exact(A, lam)
            gap = pb.g + pb.rho * lam - pb.B @ u
            bad = _infeasible(pb, A, lam, gap, feas_tol)
            kind = "exact"
        if steps is not None:
            steps.append({"step": it, "active": int(A.sum()), "infeasible": int(bad.sum()), "solve": kind})
        if not bad.any():
            return _Outcome(Status.OPTIMAL, "no infeasible row", A, u, lam, it)
        A, mode = ex.next(A, bad)
        if steps is not None:
            steps[-1]["exchange"] = mode
    lam, _ = cond.basic(A)  # the last iterate: the set the last exchange gave, solved
    u, lam = cond.exact(A, lam)
    return _Outcome(Status.MAX_ITER, f"iteration limit {max_iter} reached", A, u, lam, max_iter)


class _Step:
    """Outcome of one active set (sparse method): ``u``, ``λ`` (zero off the set), residual, ray."""

    def __init__(self, u, lam, residual, solves, ray=None):
        self.u, self.lam, self.residual, self.solves, self.ray = u, lam, residual, solves, ray


def _solve_active(pb: _Contact, fac: _SpringFactor, W: np.ndarray, A: np.ndarray, u: np.ndarray,
                  lam: np.ndarray, sigma: float, exact: bool) -> _Step:
    """Refine ``(u, λ_A)`` towards the exact step of active set ``A`` (see the module docstring)."""
    idx = np.flatnonzero(A)
    BA = pb.B[idx]
    WA, gA, rhoA = W[idx], pb.g[idx], pb.rho[idx]
    lamA = lam[idx].copy()
    u = u.copy()
    fnorm = max(np.abs(pb.f).max(initial=0.0), np.finfo(float).tiny)
    gnorm = np.abs(pb.g).max(initial=0.0)
    best = np.inf
    tol = 0.0 if exact else LOOSE_TOL
    n_max = INNER_EXACT if exact else INNER_LOOSE
    solves = 0
    res = np.inf
    for k in range(n_max + 1):
        BtL = BA.T @ lamA
        r_u = pb.f - pb.K @ u - BtL
        r_A = BA @ u - gA - rhoA * lamA
        delta = max(np.abs(pb.B @ u).max(initial=0.0), gnorm, np.finfo(float).tiny)
        res = max(np.abs(r_u).max() / max(fnorm, np.abs(BtL).max(initial=0.0)),
                  np.abs(r_A).max(initial=0.0) / delta)
        if res <= tol or k == n_max or (k >= 2 and res > 0.5 * best):
            break
        best = min(best, res)
        du = fac.solve(r_u - BA.T @ (WA * r_A))
        solves += 1
        if k == 0:
            Bdu = BA @ du
            Ddu = float(du @ (pb.Kd * du))
            energy = float(du @ (pb.K @ du)) + float(Bdu @ (WA * Bdu))
            if Ddu > 0 and energy < SINGULAR_QUOTIENT * sigma * Ddu:
                return _Step(u, lam, np.inf, solves, ray=du / np.abs(du).max())
        lamA += WA * (r_A + BA @ du)
        u += du
    out = np.zeros_like(lam)
    out[idx] = lamA
    return _Step(u, out, res, solves)


def _line_search(pb: _Contact, W: np.ndarray, u: np.ndarray, du: np.ndarray) -> float:
    """Exact minimiser ``α ∈ (0, ALPHA_MAX]`` of the (convex, piecewise quadratic) energy
    ``½uᵀKu − fᵀu + Σ ½ W_i max(0, B_i u − g_i)²`` along ``u + α du`` (bisection on its slope)."""
    r = pb.B @ u - pb.g
    s = pb.B @ du
    a2 = float(du @ (pb.K @ du))
    b = float(du @ (pb.K @ u - pb.f))

    def slope(al):
        return al * a2 + b + float(np.sum(W * s * np.maximum(0.0, r + al * s)))

    lo, hi = 0.0, 1.0
    while slope(hi) < 0:
        lo, hi = hi, 2 * hi
        if hi > ALPHA_MAX:
            return np.inf  # the energy falls without bound along du: left to the exact steps
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if slope(mid) < 0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _newton_pcg(pb: _Contact, fac: _SpringFactor, W: np.ndarray, sigma: float, steps) -> tuple:
    """Phase 1 of the sparse method, for soft rows (springs no stiffer than the plate under them).

    Semismooth Newton on the energy ``½uᵀKu − fᵀu + Σ ½ W_i max(0, B_i u − g_i)²`` (the exact
    energy of a tensionless bed), each Newton system ``(K + σD + B_Aᵀ W_A B_A) δu = −∇`` solved
    only roughly (PCG to ``PCG_TOL``) with the factor of the two-sided matrix (every row
    active) as preconditioner, then an exact line search: no refactorisation until the active
    set settles. Returns ``(u, A, solves)``.
    """
    B, K, f, g, D = pb.B, pb.K, pb.f, pb.g, pb.Kd
    fac.set(W.copy())
    u = fac.solve(f + B.T @ (W * g))  # the two-sided problem
    A = B @ u - g > 0
    for k in range(NEWTON_STEPS):
        WA = np.where(A, W, 0.0)
        grad = K @ u - f + B.T @ (WA * (B @ u - g))
        du = np.zeros_like(u)
        res = -grad
        z = fac.solve(res)
        d = z.copy()
        rz = rz0 = float(res @ z)
        for j in range(PCG_MAX):
            Hd = K @ d + sigma * D * d + B.T @ (WA * (B @ d))
            dHd = float(d @ Hd)
            if dHd <= 0:
                break
            a = rz / dHd
            du += a * d
            res -= a * Hd
            z = fac.solve(res)
            rz_new = float(res @ z)
            if rz_new <= PCG_TOL**2 * rz0:
                break
            d = z + (rz_new / rz) * d
            rz = rz_new
        alpha = _line_search(pb, W, u, du)
        if not np.isfinite(alpha):
            break
        u = u + alpha * du
        A_new = B @ u - g > 0
        changes = int((A_new ^ A).sum())
        if steps is not None:
            steps.append({"step": f"newton {k + 1}", "active": int(A.sum()), "infeasible": changes,
                          "solve": f"pcg {j + 1}", "alpha": round(alpha, 3)})
        A = A_new
        if changes <= max(NEWTON_SETTLED, NEWTON_SETTLED_FRACTION * pb.m):
            break
        if fac.t_factor is not None and fac.stats["solve_s"] > NEWTON_BUDGET * fac.t_factor:
            break
    return u, A, k + 1


def _run_sparse(pb: _Contact, fac: _SpringFactor, W, sigma, A, feas_tol, max_iter, p, steps) -> _Outcome:
    ex = _Exchange(p)
    u = np.zeros(pb.K.shape[0])
    lam = np.zeros(pb.m)
    exact = False
    newton = 0
    if A is None and np.all(pb.rho * pb.k >= 1.0):  # soft rows only, cold start: phase 1
        u, A, newton = _newton_pcg(pb, fac, W, sigma, steps)
        lam = np.where(A, W * (pb.B @ u - pb.g), 0.0)
        exact = True
    elif A is not None:
        exact = True  # a warm start is meant to be (nearly) right: solve it exactly at once
    A = np.ones(pb.m, dtype=bool) if A is None else A.copy()
    for it in range(1, max_iter + 1):
        fac.set(np.where(A, W, 0.0))
        step = _solve_active(pb, fac, W, A, u, lam, sigma, exact)
        if step.ray is not None and fac.loss > 0:  # judge a free rigid motion on a clean factor
            fac.refactor(np.where(A, W, 0.0))
            step = _solve_active(pb, fac, W, A, u, lam, sigma, exact)
        if step.ray is not None:  # the active rows do not hold the plate: it falls along d
            d = step.ray
            Bd = pb.B @ d
            scale = np.abs(Bd).max(initial=0.0)
            hit = ~A & (Bd > 1e-9 * scale)
            if steps is not None:
                steps.append({"step": it, "active": int(A.sum()), "infeasible": None, "solve": "singular",
                              "solves": step.solves, "entering": int(hit.sum())})
            if hit.any():
                A = A | hit
                exact = False
                continue
            Kd_rel = np.abs(pb.K @ d).max() / (pb.Kd.max() * np.abs(d).max())
            if pb.f @ d > 0 and Kd_rel <= 1e-6 and np.all(Bd <= 1e-9 * scale):
                ray = np.zeros(pb.n)
                ray[pb.keep] = d  # (d, 0): P (d, 0) = 0, G (d, 0) = B d ≤ 0, qᵀ(d, 0) = −fᵀd < 0
                return _Outcome(Status.UNBOUNDED, _RAY_MESSAGE, A, it=newton + it, ray=ray)
            return _Outcome(Status.ERROR, "the active rows do not hold the plate, no row stops its rigid motion, "
                            "yet the load does no work along it: cannot go on", A, it=newton + it)
        u, lam = step.u, step.lam
        gap = pb.g + pb.rho * lam - pb.B @ u
        bad = _infeasible(pb, A, lam, gap, feas_tol)
        if steps is not None:
            steps.append({"step": it, "active": int(A.sum()), "infeasible": int(bad.sum()),
                          "solve": "exact" if exact else "loose", "solves": step.solves})
        if not bad.any():
            if exact:
                return _Outcome(Status.OPTIMAL, "no infeasible row", A, u, lam, newton + it)
            exact = True  # the set looks right: solve it to rounding and look again
            continue
        exact = exact and int(bad.sum()) <= NEWTON_SETTLED  # a few rows at the end: stay exact
        A, mode = ex.next(A, bad)
        if steps is not None:
            steps[-1]["exchange"] = mode
    return _Outcome(Status.MAX_ITER, f"iteration limit {max_iter} reached", A, u, lam, newton + max_iter)


# --------------------------------------------------------------------------- the backend


def _natural(pb: _Contact, u: np.ndarray, lam: np.ndarray) -> tuple[float, float]:
    """Relative natural residual and relative stationarity residual of ``(u, λ)``."""
    gap = pb.g + pb.rho * lam - pb.B @ u
    nat = float(np.abs(np.minimum(lam, pb.c * gap)).max(initial=0.0) / _force_scale(pb, lam))
    BtL = pb.B.T @ lam
    st = float(np.linalg.norm(pb.K @ u - pb.f + BtL) / max(np.linalg.norm(pb.f), np.linalg.norm(BtL), 1e-300))
    return nat, st


def _option(settings: dict, key: str, ok, what: str):
    val = settings[key]
    if not ok(val):
        raise ProblemError(f"option {key} must be {what}, got {val!r}")
    return val


def _is_int(v, lo):
    return not isinstance(v, bool) and isinstance(v, (int, np.integer)) and v >= lo


def pdas(qp: QP, active=None, trace=False, *, accuracy="default", **options) -> RawSolution:
    """Solve the primal contact QP by the primal–dual active set method.

    Parameters
    ----------
    qp : QP
        ``min ½ xᵀPx + qᵀx  s.t.  G x ≤ h`` with sparse ``P``, ``G`` (few rows), nothing else.
    active : array_like of bool, optional
        First active set, one entry per row of ``G`` (defaults: see the module docstring).
    trace : bool
        Record each step in ``extras["trace"]``: ``{"step", "active", "infeasible", "solve", "exchange"}``.
    accuracy : {"low", "default", "high"} or float (a KKT tolerance; see base.preset)
        Preset of :data:`ACCURACY`; ``feas_tol`` and ``accept_tol`` override it.
    **options
        ``feas_tol``, ``accept_tol`` and the keys of :data:`SETTINGS`.

    Returns
    -------
    RawSolution
        ``x``, ``z`` (reactions ``λ ≥ 0``), ``status`` (``OPTIMAL``; ``INACCURATE`` if the
        residuals exceed ``accept_tol``; ``UNBOUNDED`` with ``extras["ray"]`` when the plate
        cannot be held; ``MAX_ITER`` with the last iterate), ``iterations``, ``solve_time``,
        ``extras["active"]``, ``extras["method"]`` and the counts of the linear algebra.

    Raises
    ------
    SolverError
        The QP is not of the primal formulation's shape; ``method="condensed"`` where it
        does not apply.
    ProblemError
        A bad option value.
    """
    t0 = time.perf_counter()
    tol = preset(ACCURACY, accuracy, scale=("feas_tol", "accept_tol"))
    settings = dict(SETTINGS)
    for key, val in options.items():
        if key in tol:
            tol[key] = val
        elif key in settings:
            settings[key] = val
        else:
            raise ProblemError(f"unknown option {key!r} for backend pdas; known: {list(OPTIONS)}")
    for key in ("feas_tol", "accept_tol"):
        if not (np.isscalar(tol[key]) and np.isfinite(tol[key]) and 0 <= tol[key] < 1):
            raise ProblemError(f"option {key} must be a number in [0, 1), got {tol[key]!r}")
    number = (lambda lo: lambda v: np.isscalar(v) and not isinstance(v, (bool, str)) and np.isfinite(v) and v > lo)
    method = _option(settings, "method", lambda v: v in ("auto", "condensed", "sparse"),
                     "'auto', 'condensed' or 'sparse'")
    kappa = _option(settings, "penalty", number(1.0), "a number > 1")
    sigma = _option(settings, "prox", number(0.0), "a number > 0")
    p = _option(settings, "p", lambda v: _is_int(v, 0), "an integer ≥ 0")
    max_dense = _option(settings, "max_dense", lambda v: _is_int(v, 0), "an integer ≥ 0")
    max_rows = _option(settings, "max_rows", lambda v: _is_int(v, 1), "a positive integer")
    if not isinstance(trace, (bool, np.bool_)):
        raise ProblemError(f"option trace must be True or False, got {trace!r}")

    pb = _Contact(qp, max_rows)
    m = pb.m
    max_iter = settings["max_iter"] if settings["max_iter"] is not None else 50 + 2 * m
    if not _is_int(max_iter, 1):
        raise ProblemError(f"option max_iter must be a positive integer, got {max_iter!r}")
    A = None
    if active is not None:
        A = np.asarray(active)
        if A.shape != (m,) or A.dtype != bool:
            raise ProblemError(f"option active must be a bool array with one entry per row of G ({m})")
    steps: list[dict] | None = [] if trace else None

    out = None
    extras: dict = {}
    if method in ("auto", "condensed"):
        try:
            cond = _Condensed(pb, max_dense)
        except _NotApplicable as why:
            if method == "condensed":
                raise SolverError(f"pdas: the condensed method does not apply here: {why}") from None
            extras["condensed_skipped"] = str(why)
        else:
            out = _run_condensed(pb, cond, A, tol["feas_tol"], max_iter, p, steps)
            extras.update(method="condensed", **cond.stats)
    if out is None:
        W = 1.0 / (pb.rho + 1.0 / (kappa * pb.k))
        fac = _SpringFactor(pb.K, pb.B, pb.Kd, pb.c, sigma, settings["factor"])
        out = _run_sparse(pb, fac, W, sigma, A, tol["feas_tol"], max_iter, p, steps)
        extras.update(method="sparse", factor=fac.method, **fac.stats)

    extras["active"] = out.A.copy()
    if steps is not None:
        extras["trace"] = steps
    if out.u is None:  # UNBOUNDED or ERROR: no answer
        if out.ray is not None:
            extras["ray"] = out.ray
        return RawSolution(status=out.status, iterations=out.it, solve_time=time.perf_counter() - t0,
                           solver_status=out.message, extras=extras)
    lam = out.lam.copy()
    lam[(lam < 0) & (lam >= -tol["feas_tol"] * _force_scale(pb, lam))] = 0.0
    nat, st = _natural(pb, out.u, lam)
    extras.update(natural_residual=nat, stationarity=st)
    status = out.status
    if status is Status.OPTIMAL and max(nat, st) > tol["accept_tol"]:
        status = Status.INACCURATE
    x = pb.x(out.u, lam)
    obj = float(0.5 * x @ (pb.P @ x) + pb.q @ x)
    return RawSolution(status=status, x=x, z=lam, obj=obj, iterations=out.it,
                       solve_time=time.perf_counter() - t0, solver_status=out.message, extras=extras)


def solve(problem, accuracy: str = "default", options: dict | None = None) -> RawSolution:
    """Solve the primal formulation's :class:`~plateqp.backends.base.QP` (Backend protocol).

    Parameters
    ----------
    problem : QP
        Sparse ``P``, ``G`` with ``m ≤ min(n, max_rows)`` rows, ``h``; nothing else.
    accuracy : {"low", "default", "high"} or float (a KKT tolerance; see base.preset)
        Preset of :data:`ACCURACY`.
    options : dict, optional
        Keys among :data:`OPTIONS` (see :func:`pdas`).

    Raises
    ------
    SolverError
        Not a QP of the primal formulation's shape (an LCP, equalities, bounds, dense or too
        many rows).
    ProblemError
        Unknown accuracy or option.
    """
    if not isinstance(problem, QP):
        raise SolverError(f"the pdas backend solves the primal formulation's QP only, got "
                          f"{type(problem).__name__}; use formulation='primal'")
    options = dict(options or {})
    unknown = sorted(set(options) - set(OPTIONS))
    if unknown:
        raise ProblemError(f"unknown option(s) {unknown} for backend pdas; known: {list(OPTIONS)}")
    with warnings.catch_warnings():
        if "sksparse" in _bindings():
            import sksparse.cholmod

            warnings.simplefilter("ignore", sksparse.cholmod.CholmodTypeConversionWarning)
        return pdas(problem, accuracy=accuracy, **options)
