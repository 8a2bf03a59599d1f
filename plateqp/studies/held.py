r"""The held systems of an exact path on one kept factorisation.

Along :func:`plateqp.studies.exact_path` every piece solves the KKT system of the plate held at
its contact set H (:func:`plateqp.sensitivity.held_solve`),

.. math::

    K u + B_H^T R_H = f, \qquad B_H u - \rho_H R_H = g,

and the sets of two pieces in a row differ by the one or few points of the event between
them. :class:`HeldFactor` solves them on one symbolic analysis of ``K + BᵀB``
(:class:`plateqp.backends.pdas.factor.SpringFactor`), in one of two modes:

- springs (a floating plate, or rows no stiffer than the plate under them): the factor of
  ``K + B_Hᵀ diag(W_H) B_H``, a few changed rows by a Woodbury correction on the factor in hand,
  else a numeric refactorisation; ``W`` a row's own spring ``1/ρ`` where it is softer than the
  plate under it (then one solve is the answer), else a penalty spring in series with it;
- condensed (a plate its two-sided supports hold, with a row stiffer than it, at most
  CONDENSED_MAX rows): ``K`` alone, factorised once; ``(B_H K⁻¹ B_Hᵀ + ρ_H) R_H = B_H K⁻¹ F − G``
  on the rows' flexibility, whose column a row gets the first time it is held (one solve) and
  keeps; no penalty and no refactorisation, two solves a correction (one where the first
  equation already holds to rounding, or where the load is a combination of loads solved
  before, as a path's f + t df is).

Either is refined on the held system itself until each residual is rounding of the norms of the
terms that make it (a normwise backward error at rounding). A sparse LU of the whole
saddle-point system a piece (what :func:`plateqp.linalg.solve_saddle` does) cost 16 times
a factorise-and-solve of K a piece (grid, 128²); here a piece costs a correction or a
factorisation and a few solves.

Where the factor fails (the held points do not hold the plate: a singular matrix) or the
refinement does not reach rounding, :meth:`HeldFactor.__call__` raises
:class:`~plateqp.linalg.SingularMatrixError` and the caller solves the saddle-point system
instead (its answer, or its own error, stands).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..errors import SolverError
from ..linalg import SingularMatrixError, row_stiffness
from ..linalg.pattern import abs_matvec

#: Refinement steps at most a held system takes.
MAX_STEPS = 10
#: A residual within this many ε of the terms that make it is rounding (pdas's ROUNDING_STOP).
ROUNDING = 2.0
#: The penalty spring of a stiff row: this many times its local stiffness (pdas's default κ).
PENALTY = 1e8
#: A refinement that stops short of rounding is accepted at most this backward error (else the
#: caller solves the saddle-point system).
ACCEPT = 1e-13

#: The condensed mode (a held plate, some row stiffer than the plate under it) keeps the rows'
#: flexibility B K⁻¹ Bᵀ dense (m × m): at most this many rows.
CONDENSED_MAX = 2000

__all__ = ["HeldFactor"]


class HeldFactor:
    """Solves the held systems of one scaled problem (``data``: :class:`plateqp.contact.scaling.Scaled`)
    for any held set, keeping one factorisation current between the calls."""

    def __init__(self, data) -> None:
        from ..backends.pdas.factor import SpringFactor  # the factor of K + Bᵀ diag(w) B, kept current

        self.K = sp.csc_matrix(data.K)
        self.B = sp.csr_matrix(data.B)
        self.rho = np.asarray(data.rho, dtype=float)
        Kd = self.K.diagonal()
        if not np.all(Kd > 0):
            raise SingularMatrixError("the plate's stiffness has a zero on its diagonal")
        k = row_stiffness(sp.diags(Kd), self.B, "diagonal")
        soft = self.rho * k >= 1.0
        with np.errstate(divide="ignore"):
            self.W = np.where(soft, 1.0 / np.where(soft, self.rho, 1.0), 1.0 / (self.rho + 1.0 / (PENALTY * k)))
        self.K_norm = float(abs_matvec(self.K, np.ones(self.K.shape[0])).max(initial=0.0))  # ‖K‖∞
        self.row_sums = np.asarray(abs(self.B).sum(axis=1)).ravel()
        self.fac = SpringFactor(self.K, self.B, Kd, k / (1.0 + self.rho * k), 0.0, "auto")
        self.steps = 0  # refinement steps taken over every call (a count for the benchmarks)
        self.calls = 0
        # a plate its two-sided supports hold, with a row stiffer than the plate under it: K
        # itself factorised once, the held rows condensed onto it (no penalty, no refactorisation)
        self.condensed = (not data.floating and not np.all(soft) and self.rho.size <= CONDENSED_MAX)
        if self.condensed:
            self.M = np.zeros((self.rho.size, self.rho.size))  # B K⁻¹ Bᵀ, its columns filled as rows are held
            self.filled = np.zeros(self.rho.size, dtype=bool)

    @staticmethod
    def col_sums(BH) -> float:
        """‖B_Hᵀ‖∞: the largest column sum of |B_H|."""
        return float(np.bincount(BH.indices, weights=np.abs(BH.data), minlength=BH.shape[1]).max(initial=0.0))

    def __call__(self, H: np.ndarray, F: np.ndarray, G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(u, R_H)`` of the plate held at the rows ``H`` for the columns of ``F`` (n × p) and
        ``G`` (|H| × p), each exact to rounding; SingularMatrixError where this factor cannot give
        them (see the module docstring)."""
        self.calls += 1
        BH = self.B[H]
        correct = self._condensed(H, BH) if self.condensed else self._springs(H, BH)
        BH_norm = max(self.row_sums[H].max(initial=0.0), self.col_sums(BH))
        rhoH = self.rho[H][:, None]
        u = np.zeros_like(F)
        R = np.zeros_like(G)
        r_u, r_H = F, -G
        settled = False  # the first equation's residual at rounding (the last step's check)
        best = np.inf
        eps = ROUNDING * np.finfo(float).eps
        for step in range(MAX_STEPS + 1):
            if step:
                r_u = F - self.K @ u - BH.T @ R
                r_H = BH @ u - G - rhoH * R
                # normwise (Rigal–Gaches): each residual against the norms of the terms that make it
                size_u = self.K_norm * np.abs(u).max(axis=0) + BH_norm * np.abs(R).max(axis=0, initial=0.0) \
                    + np.abs(F).max(axis=0)
                size_H = BH_norm * np.abs(u).max(axis=0) + np.abs(G).max(axis=0, initial=0.0) \
                    + (rhoH * np.abs(R)).max(axis=0, initial=0.0)
                err_u = np.abs(r_u).max(axis=0)
                err_H = np.abs(r_H).max(axis=0, initial=0.0)
                settled = bool(np.all(err_u <= eps * size_u))
                if settled and np.all(err_H <= eps * size_H):
                    return u, R
                omega = float(max((err_u / np.maximum(size_u, 1e-300)).max(initial=0.0),
                                  (err_H / np.maximum(size_H, 1e-300)).max(initial=0.0)))
                if not np.isfinite(omega):
                    break
                if step >= 2 and omega > 0.5 * best:  # stalled: another step would not change it
                    if omega <= ACCEPT:
                        return u, R
                    break
                best = min(best, omega)
            du, dR = correct(r_u, -r_H, settled)
            if not (np.all(np.isfinite(du)) and np.all(np.isfinite(dR))):
                break
            u, R = u + du, R + dR
            self.steps += 1
        raise SingularMatrixError("the refinement of the held system did not reach rounding")

    def _springs(self, H: np.ndarray, BH):
        """The correction of the springs' mode: ``(du, dR)`` with ``(K + B_Hᵀ W_H B_H) du =
        F + B_Hᵀ W_H G`` and ``dR = W_H (B_H du − G)`` (exact for a row's own spring, W = 1/ρ;
        a penalty's share is left to the next step)."""
        w = np.zeros(self.rho.size)
        w[H] = self.W[H]
        try:
            self.fac.set(w)
        except (SolverError, SingularMatrixError) as exn:
            raise SingularMatrixError(f"the held set's matrix could not be factorised ({exn})") from exn
        WH = self.W[H][:, None]

        def correct(F, G, settled):
            du = self.fac.solve(F + BH.T @ (WH * G))
            return du, WH * (BH @ du - G)
        return correct

    def _k_solve(self, F: np.ndarray) -> np.ndarray:
        """``K⁻¹F`` (condensed mode), a column at a time on K's factor, recycling the loads solved
        before (:meth:`plateqp.backends.pdas.factor.SpringFactor.solve_in_span`: a path's load at
        t is f + t df, its two directions solved once; a zero column, a unit gap's, no solve)."""
        return np.column_stack([self.fac.solve_in_span(F[:, j]) for j in range(F.shape[1])])

    def _condensed(self, H: np.ndarray, BH):
        """The correction of the condensed mode, exact: ``X = K⁻¹F``, ``(B_H K⁻¹ B_Hᵀ + ρ_H) dR =
        B_H X − G``, ``du = K⁻¹(F − B_Hᵀ dR)`` (two solves with K's factor; a row held for the
        first time costs one more, its column of B K⁻¹ Bᵀ, kept). Where ``F`` is rounding
        (``settled``: the first equation holds), ``X`` is left out: one solve."""
        if self.fac.w is None:  # K's factorisation, on the first call
            try:
                self.fac.set(np.zeros(self.rho.size))
            except (SolverError, SingularMatrixError) as exn:
                raise SingularMatrixError(f"the plate's stiffness could not be factorised ({exn})") from exn
        new = H[~self.filled[H]]
        if new.size:
            Z = self.fac.solve(self.B[new].T.toarray())
            cols = np.asarray(self.B @ Z)
            self.M[:, new] = cols
            self.M[new, :] = cols.T
            self.filled[new] = True
        C = self.M[np.ix_(H, H)]
        C[np.diag_indices(H.size)] += self.rho[H]
        try:
            cho = sla.cho_factor(C, lower=True, check_finite=False)
        except np.linalg.LinAlgError as exn:  # rows that do not bind independently (ρ = 0)
            raise SingularMatrixError(f"the held rows' flexibility is singular ({exn})") from exn

        def correct(F, G, settled):
            if settled:  # F is rounding: only the rows' residual is left to correct (one solve)
                dR = sla.cho_solve(cho, -G, check_finite=False)
                return -self.fac.solve(BH.T @ dR), dR
            X = self._k_solve(F)
            dR = sla.cho_solve(cho, BH @ X - G, check_finite=False)
            # K du = F − B_Hᵀ dR solved as it stands (not X − K⁻¹B_Hᵀ dR, which cancels where
            # the supports carry most of the load): the first equation then holds to rounding
            return self.fac.solve(F - BH.T @ dR), dR
        return correct
