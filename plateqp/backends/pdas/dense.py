r"""The dense method: the dual LCP of the reduced QP from one factorisation's trailing block.

The dofs the rows act on go *last* in the elimination order (AMD order on the rest); one
sparse Cholesky ``K = L Lᵀ`` (:class:`plateqp.linalg.SchurFactor`) then holds, in its trailing
dense block ``L_cc``, the static condensation of every other dof. With ``Z = L_cc⁻¹ B_cᵀ`` (a
dense triangular solve) the dual LCP

.. math::

    \mathrm{gap} = d + M\lambda,\qquad M = Z^T Z + \mathrm{diag}(\rho) = B K^{-1} B^T + \mathrm{diag}(\rho),
    \qquad d = g - B K^{-1} f,

costs no column solves at all. Each active set is then a dense Cholesky of ``M_AA``; the final
set is solved on the exact sparse equations by iterative refinement with ``K⁻¹`` (the same
factor) and ``M_AA``, so rounding in ``d`` does not reach the answer.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.linalg as sla

from ...errors import SingularMatrixError
from ...linalg import SchurFactor, bindings
from ..base import Status
from .options import INNER_EXACT, PIVOT_TOL
from .reduced import Exchange, Outcome, ReducedQP, at_rounding, infeasible

__all__ = ["DenseDual", "NotApplicable", "run_dense"]


class NotApplicable(Exception):
    """The dense method does not apply (too many contact dofs, K singular, no CHOLMOD)."""


class DenseDual:
    """The dual LCP ``(M, d)`` of a reduced QP, from the trailing block of one factorisation of
    ``K`` with the rows' dofs last, and the exact solve of an active set with that factor."""

    def __init__(self, pb: ReducedQP, max_dense: int) -> None:
        libs = bindings()
        if not libs:
            raise NotApplicable("no CHOLMOD binding (scikit-sparse or cvxopt) is in use here")
        B = pb.B
        c = np.unique(B.indices)
        if c.size > max_dense:
            raise NotApplicable(f"the rows touch {c.size} dofs (max_dense = {max_dense})")
        try:
            self.fac = SchurFactor(pb.K, c, pivot_tol=PIVOT_TOL, method=libs[0], diagonal=pb.Kd)
        except SingularMatrixError as exn:
            raise NotApplicable(f"K is singular ({exn})") from exn
        t0 = time.perf_counter()
        M = self.fac.flexibility(B)
        M[np.diag_indices(pb.m)] += pb.rho
        self.M = M
        self.pb = pb
        self._dense_s = time.perf_counter() - t0
        self.Bc = B[:, c].tocsr()  # the rows on the trailing unknowns, in the factor's order of them
        self.yf = self._forward(pb.f)
        self.d = pb.g - self.Bc @ self._tail(self.yf)  # g − B K⁻¹ f: half a solve
        self._chol = None

    # K⁻¹ in two halves where the factor allows (SchurFactor.forward / backward: the rows need
    # only the trailing part of the first half); else "y" is the whole solution x = K⁻¹ b

    def _forward(self, b: np.ndarray) -> np.ndarray:
        return self.fac.forward(b) if self.fac.can_split else self.solve_K(b)

    def _backward(self, y: np.ndarray) -> np.ndarray:
        return self.fac.backward(y) if self.fac.can_split else y

    def _tail(self, y: np.ndarray) -> np.ndarray:
        """``(K⁻¹ b)`` on the trailing unknowns, from ``y = _forward(b)``."""
        return self.fac.trailing_backward(y[self.fac.no:]) if self.fac.can_split else y[self.fac.last]

    def _sub_rows(self, y: np.ndarray, BA, lam_A: np.ndarray) -> np.ndarray:
        """``_forward(b − B_Aᵀ λ_A)`` from ``y = _forward(b)`` (``B_A`` on the trailing unknowns)."""
        y = y.copy()
        b_l = BA.T @ lam_A
        if self.fac.can_split:  # L⁻¹ of a vector on the trailing unknowns only: a dense solve
            y[self.fac.no:] -= self.fac.trailing_forward(b_l)
        else:
            full = np.zeros(self.fac.n)
            full[self.fac.last] = b_l
            y -= self.solve_K(full)
        return y

    @property
    def stats(self) -> dict:
        """Counts and times of the linear algebra (``extras`` of the answer)."""
        st = self.fac.stats
        return {"analyse_s": st["analyse_s"], "factor_s": st["factor_s"], "extract_s": st["extract_s"],
                "dense_s": self._dense_s, "solves": st["solves"], "solve_s": st["solve_s"],
                "factorisations": st["factorisations"], "contact_dofs": st["last"], "cholmod": st["method"]}

    def solve_K(self, b: np.ndarray) -> np.ndarray:
        """``K⁻¹ b``."""
        return self.fac.solve(b, refine=0)

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
        self._dense_s += time.perf_counter() - t0
        return lam, gap

    def exact(self, A: np.ndarray, lam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(u, λ)`` of active set ``A`` on the exact sparse equations: ``basic``'s ``λ``, then
        iterative refinement with ``K⁻¹`` and the Cholesky factor of ``M_AA`` while the
        residuals are above rounding (:func:`.reduced.at_rounding`) and still halve: for
        residuals ``r_u``, ``r_A``, ``v = K⁻¹ r_u``, ``M_AA δλ = r_A + B_A v``, ``δu = v − K⁻¹ B_Aᵀ δλ``."""
        pb = self.pb
        idx = np.flatnonzero(A)
        BA, BcA = pb.B[idx], self.Bc[idx]
        lam = lam.copy()
        u = self._backward(self._sub_rows(self.yf, BcA, lam[idx]))  # K⁻¹ (f − B_Aᵀ λ_A): half a solve
        best = np.inf
        tiny = np.finfo(float).tiny
        for k in range(INNER_EXACT):
            BtL = BA.T @ lam[idx]
            r_u = pb.f - pb.K @ u - BtL
            r_A = BA @ u - pb.g[idx] - pb.rho[idx] * lam[idx]
            delta = max(np.abs(pb.B @ u).max(initial=0.0), np.abs(pb.g).max(initial=0.0), tiny)
            res = max(np.abs(r_u).max() / max(np.abs(pb.f).max(), np.abs(BtL).max(initial=0.0), tiny),
                      np.abs(r_A).max(initial=0.0) / delta)
            if res == 0.0 or (k >= 1 and res > 0.5 * best) or at_rounding(pb, u, idx, BA, lam[idx], r_u, r_A):
                break
            best = min(best, res)
            y = self._forward(r_u)  # v = K⁻¹ (r_u − B_Aᵀ δλ): one solve in two halves
            if idx.size:
                rhs = r_A + BcA @ self._tail(y)
                dlam = (sla.cho_solve(self._chol, rhs, check_finite=False) if self._chol is not None
                        else np.linalg.lstsq(self.M[np.ix_(idx, idx)], rhs, rcond=None)[0])
                y = self._sub_rows(y, BcA, dlam)
                lam[idx] += dlam
            u += self._backward(y)
        return u, lam


def run_dense(pb: ReducedQP, cond: DenseDual, A, feas_tol, max_iter, p, steps) -> Outcome:
    A = (cond.d < 0) if A is None else A.copy()
    ex = Exchange(p)
    for it in range(1, max_iter + 1):
        lam, gap = cond.basic(A)
        bad = infeasible(pb, A, lam, gap, feas_tol)
        kind = "dense"
        # the set looks right, or it was met before: solve it on the exact equations and look
        # again. A set met again means the dense classification cycles: M (from the trailing
        # block) is accurate to about cond(K)·ε, and at a row whose gap and reaction are both
        # near zero it can call the row's gap negative without it and its reaction negative
        # with it (a bed of stiff springs at 14²: 45 ↔ 46 rows for 470 steps, MAX_ITER)
        if not bad.any() or A.tobytes() in ex.seen:
            u, lam = cond.exact(A, lam)
            gap = pb.g + pb.rho * lam - pb.B @ u
            bad = infeasible(pb, A, lam, gap, feas_tol)
            kind = "exact"
        if steps is not None:
            steps.append({"step": it, "active": int(A.sum()), "infeasible": int(bad.sum()), "solve": kind})
        if not bad.any():
            return Outcome(Status.OPTIMAL, "no infeasible row", A, u, lam, it)
        A, mode = ex.next(A, bad)
        if steps is not None:
            steps[-1]["exchange"] = mode
    lam, _ = cond.basic(A)  # the last iterate: the set the last exchange gave, solved
    u, lam = cond.exact(A, lam)
    return Outcome(Status.MAX_ITER, f"iteration limit {max_iter} reached", A, u, lam, max_iter)
