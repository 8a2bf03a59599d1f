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
from ...linalg.products import times
from ..base import Status
from .options import (
    INNER_EXACT,
    LH_ANCHORED_PROBE,
    LH_BUDGET,
    LH_OVERHEAD,
    LH_PROBE,
    PIVOT_TOL,
)
from .reduced import (ROUNDING_STOP, Exchange, Outcome, ReducedQP, gaps_at_rounding, infeasible,
                      stationary_at_rounding)

__all__ = ["DenseDual", "NotApplicable", "anchored_set", "first_set", "run_dense"]


class NotApplicable(Exception):
    """The dense method does not apply (too many contact dofs, K singular, no CHOLMOD);
    ``singular``: because K is singular (a floating plate)."""

    def __init__(self, message: str, singular: bool = False) -> None:
        super().__init__(message)
        self.singular = singular


class DenseDual:
    """The dual LCP ``(M, d)`` of a reduced QP, from the trailing block of one factorisation of
    ``K`` with the rows' dofs last, and the exact solve of an active set with that factor.

    ``anchor > 0``: the LCP of the plate with each of the rows' dofs held by a spring of
    ``anchor·K_jj`` (``K + anchor·diag(K)`` on those dofs: definite for a floating plate whose
    rows, held, hold it), for :func:`anchored_set`; no exact steps (:meth:`exact` refuses);
    ``prox``: with ``prox·diag(K)`` on every dof too (the sparse method's ``σ``), so that its
    factor serves the exact steps after (:class:`.factor.TrailingFactor`)."""

    def __init__(self, pb: ReducedQP, max_dense: int, anchor: float = 0.0, prox: float = 0.0) -> None:
        libs = bindings()
        if not libs:
            raise NotApplicable("no CHOLMOD binding (scikit-sparse or cvxopt) is in use here")
        B = pb.B
        c = np.unique(B.indices)
        if c.size == B.shape[0] and np.all(np.diff(B.indptr) == 1):
            # one dof a row, each its own: the dofs ordered last in the rows' order, so that M is
            # the trailing block's inverse as it stands (no m × m gather to reorder it)
            c = B.indices.astype(np.int64)
        if c.size > max_dense:
            raise NotApplicable(f"the rows touch {c.size} dofs (max_dense = {max_dense})")
        try:
            self.fac = SchurFactor(pb.K, c, shift=anchor, pivot_tol=PIVOT_TOL, method=libs[0], diagonal=pb.Kd,
                                   prox=prox if anchor > 0 else 0.0)
        except SingularMatrixError as exn:
            raise NotApplicable(f"K is singular ({exn})", singular=True) from exn
        t0 = time.perf_counter()
        M = self.fac.flexibility(B, shifted=anchor > 0)
        M[np.diag_indices(pb.m)] += pb.rho
        self.M = M
        self.pb = pb
        self._dense_s = time.perf_counter() - t0
        self.Bc = B[:, c].tocsr()  # the rows on the trailing unknowns, in the factor's order of them
        if anchor > 0:
            try:
                self.d = pb.g - B @ self.fac.solve_shifted(pb.f)  # g − B K̂⁻¹ f: one solve
            except ValueError as exn:  # cvxopt's factor spent by reading it
                raise NotApplicable(str(exn)) from exn
            self.yf = None
        else:
            self.yf = self._forward(pb.f)
            self.d = pb.g - self.Bc @ self._tail(self.yf)  # g − B K⁻¹ f: half a solve
        self._chol = None
        self.first: dict = {}  # how run_dense found its first set (extras)

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
                "factorisations": st["factorisations"], "contact_dofs": st["last"], "cholmod": st["method"],
                **self.first}

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
        """``(u, λ)`` of active set ``A`` on the exact sparse equations: ``basic``'s ``λ``, refined
        on the trailing unknowns (:meth:`_refine_tail`) before ``u``'s backward half, then
        iterative refinement with ``K⁻¹`` and the Cholesky factor of ``M_AA`` while the
        residuals are above rounding (:func:`.reduced.at_rounding`) and still halve: for
        residuals ``r_u``, ``r_A``, ``v = K⁻¹ r_u``, ``M_AA δλ = r_A + B_A v``, ``δu = v − K⁻¹ B_Aᵀ δλ``
        (``v = 0`` where ``r_u`` is at rounding already: :func:`.reduced.stationary_at_rounding`)."""
        if self.yf is None:
            raise ValueError("an anchored LCP has no exact steps (its K is not the plate's)")
        pb = self.pb
        idx = np.flatnonzero(A)
        BA, BcA = pb.B[idx], self.Bc[idx]
        lam = lam.copy()
        y, settled = self._refine_tail(idx, BcA, lam, self._sub_rows(self.yf, BcA, lam[idx]))
        u = self._backward(y)  # K⁻¹ (f − B_Aᵀ λ_A): half a solve
        best = np.inf
        tiny = np.finfo(float).tiny
        for k in range(INNER_EXACT):
            BtL = BA.T @ lam[idx]
            r_u = pb.f - times(pb.K, u) - BtL
            r_A = BA @ u - pb.g[idx] - pb.rho[idx] * lam[idx]
            delta = max(np.abs(pb.B @ u).max(initial=0.0), np.abs(pb.g).max(initial=0.0), tiny)
            res = max(np.abs(r_u).max() / max(np.abs(pb.f).max(), np.abs(BtL).max(initial=0.0), tiny),
                      np.abs(r_A).max(initial=0.0) / delta)
            if res == 0.0 or (k >= 1 and res > 0.5 * best):
                break
            still = stationary_at_rounding(pb, u, BA, lam[idx], r_u)  # the two halves of at_rounding
            # λ_A settled on the trailing unknowns the dense half gave: B_A u differs from there
            # only by the rounding of the sparse backward half (both solve L_ccᵀ x_c = y_c), which
            # a correction's own backward half would make again (measured: 2–4 ε either way)
            if still and ((k == 0 and settled) or gaps_at_rounding(pb, u, idx, BA, lam[idx], r_A)):
                break
            best = min(best, res)
            # v = K⁻¹ (r_u − B_Aᵀ δλ): one solve in two halves; where r_u is rounding already (the
            # step of a kept factor: only λ is off), v = 0 and the step corrects λ alone (half a solve)
            lone = still and self.fac.can_split and idx.size > 0
            y = np.zeros(self.fac.n) if lone else self._forward(r_u)
            if idx.size:
                rhs = r_A if lone else r_A + BcA @ self._tail(y)
                dlam = (sla.cho_solve(self._chol, rhs, check_finite=False) if self._chol is not None
                        else np.linalg.lstsq(self.M[np.ix_(idx, idx)], rhs, rcond=None)[0])
                y = self._sub_rows(y, BcA, dlam)
                lam[idx] += dlam
            u += self._backward(y)
        return u, lam

    def _refine_tail(self, idx: np.ndarray, BcA, lam: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, bool]:
        """``λ_A`` (in place) refined on the trailing unknowns alone, and its ``y``: ``B_A u``
        needs only them (a dense triangular solve of the trailing block, no sparse half), so the
        gap residual ``r_A`` is driven to rounding (:func:`.reduced.gaps_at_rounding`'s test)
        before the one backward half that gives ``u``; a step that does not halve it stops.
        Also whether ``r_A`` settled at rounding: that test met, or the steps stopped halving
        within twice the error of evaluating ``r_A`` itself (``γ_{L+2}`` of its terms, a row of
        ``L`` entries, ``g`` and ``ρλ``: Higham's bound for a sum of products), where a further
        step corrects noise (LAPACK's refinement stops there too)."""
        if not (self.fac.can_split and idx.size and self._chol is not None and self._chol[0].shape[0] == idx.size):
            return y, False
        pb, eps = self.pb, ROUNDING_STOP * np.finfo(float).eps
        noise = 2.0 * (np.diff(BcA.indptr).max() + 2) * np.finfo(float).eps
        best = np.inf
        for _ in range(INNER_EXACT):
            uc = self._tail(y)
            r_A = BcA @ uc - pb.g[idx] - pb.rho[idx] * lam[idx]
            size = np.abs(r_A).max()
            scale = (abs(BcA) @ np.abs(uc) + np.abs(pb.g[idx]) + pb.rho[idx] * np.abs(lam[idx])).max()
            if size <= eps * scale:
                return y, True
            if size > 0.5 * best:
                return y, size <= noise * scale
            best = size
            dlam = sla.cho_solve(self._chol, r_A, check_finite=False)
            y = self._sub_rows(y, BcA, dlam)
            lam[idx] += dlam
        return y, False


_TRTRS = sla.get_lapack_funcs("trtrs", dtype=np.float64)


def _lower_solve(L: np.ndarray, b: np.ndarray, trans: bool = False) -> np.ndarray:
    """``L⁻¹ b`` (``L⁻ᵀ b`` with ``trans``) for a lower triangular block ``L`` of a row-major
    buffer: LAPACK's TRTRS on ``Lᵀ`` as ``scipy.linalg.solve_triangular`` calls it for such a
    block (the same arithmetic), without its checks and wrappers (Lawson–Hanson calls it a few
    hundred times a solve, where they took 0.015 s at 64²)."""
    if L.shape[0] == 0:  # an empty set: nothing to solve (SciPy 1.15's TRTRS refuses its LDA = 0)
        return np.array(b, dtype=float)
    x, info = _TRTRS(L.T, b, lower=0, trans=0 if trans else 1)
    if info != 0:  # a zero pivot (cannot happen for a Cholesky factor); as solve_triangular says it
        raise np.linalg.LinAlgError(f"singular matrix: resolution failed at diagonal {info - 1}")
    return x


def first_set(M, d: np.ndarray, c: np.ndarray, feas_tol: float, floor: float, budget: float,
              out: dict | None = None, probe: int = LH_PROBE) -> tuple[np.ndarray | None, int]:
    r"""A first active set for the dual LCP ``gap = d + Mλ ≥ 0, λ ≥ 0, λ·gap = 0`` (``M``
    symmetric positive definite): Lawson–Hanson's active-set method on ``min ½λᵀMλ + dᵀλ,
    λ ≥ 0`` (their NNLS algorithm with ``M`` for ``AᵀA``; Lawson & Hanson, *Solving Least
    Squares Problems*, 1974, ch. 23).

    From ``λ = 0`` it frees, one at a time, the row of most negative force ``c_j gap_j``, solves
    the free rows' equations ``M_FF λ_F = −d_F`` with a Cholesky factor grown by one row per row
    freed (k² flops, not k³/3), and where that would make a reaction negative steps back to the
    first row that reaches zero and fixes it again. It stops when no fixed row has
    ``c_j gap_j < −feas_tol · max(‖λ‖∞, floor)`` (the block steps' own test,
    :func:`.reduced.infeasible`). Each set's ``λ`` stays feasible, so where few of many rows end
    in contact it takes about as many cheap steps as there are contacts, where the block steps
    from ``d < 0`` take many dense Cholesky factorisations of large sets.

    ``M`` is the matrix, or a function ``M(j, force)`` that gives its row ``j`` as it is
    needed (``force``: every row's ``c_i gap_i`` at that moment, ``inf`` where free or barred,
    for the function to choose which other rows to compute with it) or None once its own
    budget is spent (:func:`.sparse.lawson_hanson`: only the rows freed are ever needed).

    Returns ``(A, steps)``: the free rows (the active set; the caller checks it) and the sets
    solved, and in ``out`` (a dict, if given) ``"lam"``, the set's reactions (also where the
    function gave None: those of the set reached, a warm start). ``A`` is None
    when the work (3k² + 2mk + LH_OVERHEAD flops for a set of k rows) would pass ``budget``, or
    when, after ``probe`` rows (LH_PROBE), the rows freed plus the rows still pressed (about the
    final size) would need more than it (a matrix ``M``), or when the function gave None. A row whose pivot
    vanishes (its row of ``M`` dependent on the free ones: two supports at one point) is never
    freed; the caller's block steps see to it.
    """
    m = d.size
    lazy = callable(M)
    gap = d.astype(float, copy=True)
    lam = np.zeros(m)
    free = np.zeros(m, dtype=bool)
    barred = np.zeros(m, dtype=bool)
    F = np.zeros(0, dtype=np.int64)  # the free rows, in the order of the factor
    cap = 16
    L = np.zeros((cap, cap))  # Cholesky factor of M_FF in L[:k, :k]
    R = np.zeros((cap, m))  # the rows M_F·, so gap = d + λ_Fᵀ M_F· is one matrix-vector product
    y = np.zeros(cap)  # L⁻¹ (−d_F), grown by one entry per row freed
    work, steps = 0.0, 0
    tiny = np.finfo(float).tiny
    sizes = np.arange(m + 1, dtype=float)
    kmax = int(np.searchsorted(np.cumsum(3.0 * sizes**2 + 2.0 * m * sizes + LH_OVERHEAD), budget))
    while True:
        force = np.where(free | barred, np.inf, c * gap)
        bad = force < -feas_tol * max(np.abs(lam).max(initial=0.0), floor, tiny)
        if not bad.any():
            if out is not None:
                out["lam"] = lam
            return free, steps
        j = int(np.argmin(force))
        k = F.size
        work += 3.0 * k * k + 2.0 * m * k + LH_OVERHEAD
        # past the probe, k + (rows still pressed) foretells the final size: each row freed
        # then relieves about one other (measured on post grids and beds; not on a post at
        # every node, where each relieves many: the function's own budget rules there)
        if not lazy and (work > budget or (k >= probe and k + int(bad.sum()) > kmax)):
            return None, steps
        if k == cap:  # grow the buffers
            cap *= 2
            L2, R2, y2 = np.zeros((cap, cap)), np.zeros((cap, m)), np.zeros(cap)
            L2[:k, :k], R2[:k], y2[:k] = L[:k, :k], R[:k], y[:k]
            L, R, y = L2, R2, y2
        row = M(j, force) if lazy else M[j]
        if row is None:
            if out is not None:
                out["lam"] = lam  # feasible, and the minimum of the dual QP on its face
            return None, steps
        ell = _lower_solve(L[:k, :k], row[F]) if k else np.zeros(0)
        pivot = row[j] - ell @ ell
        if not pivot > 1e-12 * row[j]:
            barred[j] = True
            continue
        L[k, :k], L[k, k], R[k] = ell, np.sqrt(pivot), row
        y[k] = (-d[j] - ell @ y[:k]) / L[k, k]  # the forward solve's new last entry
        F = np.append(F, j)
        free[j] = True
        while True:  # the free rows' reactions; step back while one of them would be negative
            steps += 1
            k = F.size
            z = _lower_solve(L[:k, :k], y[:k], trans=True)
            if np.all(z > 0):
                lam[F] = z
                break
            old = lam[F]
            neg = np.flatnonzero(z <= 0)
            t = old[neg] / (old[neg] - z[neg])
            new = old + t.min() * (z - old)
            new[neg[np.argmin(t)]] = 0.0
            keep = new > 0
            if not keep[-1] and old[-1] == 0.0:  # the row just freed cannot carry (rounding)
                barred[F[-1]] = True
            lam[F] = np.where(keep, new, 0.0)
            free[F[~keep]] = False
            # the rows kept past the new end fill the holes (the order of F is free: L is made
            # anew below); moving the kept rows down copied R whole (0.25 s at 128², every node)
            k = int(keep.sum())
            holes, fill = np.flatnonzero(~keep[:k]), k + np.flatnonzero(keep[k:])
            R[holes], F[holes] = R[fill], F[fill]
            F = F[:k].copy()
            work += k ** 3 / 3.0
            if k:
                try:
                    L[:k, :k] = np.linalg.cholesky(R[:k][:, F])  # M_FF: the rows kept
                except np.linalg.LinAlgError:  # M_FF singular to rounding: leave it to the block steps
                    return None, steps
                y[:k] = _lower_solve(L[:k, :k], -d[F])
        gap = d + lam[F] @ R[:F.size] if F.size else d.astype(float, copy=True)


def _start(pb: ReducedQP, cond: DenseDual, A, feas_tol, probe: int = LH_PROBE) -> tuple[np.ndarray, int]:
    """The dense method's first set (given; Lawson–Hanson's for stiff rows, ``probe`` for
    :func:`first_set`; else ``d < 0``) and Lawson–Hanson's steps; ``cond.first`` says which."""
    first = 0
    if A is not None:
        A = A.copy()
        cond.first = {"first_set": "given"}
    elif np.median(pb.rho * pb.k) < 1.0:  # stiff rows: Lawson–Hanson first (options.LH_BUDGET)
        A = cond.d < 0
        t0 = time.perf_counter()
        start, first = first_set(cond.M, cond.d, pb.c, feas_tol, 1e-12 * np.abs(pb.f).sum(),
                                 LH_BUDGET * int(A.sum()) ** 3 / 3.0, probe=probe)
        cond._dense_s += time.perf_counter() - t0
        cond.first = {"first_set": "d < 0 (lawson-hanson gave up)" if start is None else "lawson-hanson",
                      "first_set_steps": first}
        if start is not None:
            A = start
    else:
        A = cond.d < 0
        cond.first = {"first_set": "d < 0"}
    return A, first


def anchored_set(pb: ReducedQP, cond: DenseDual, feas_tol, max_iter, p, steps) -> tuple[np.ndarray, int]:
    """A first set for a floating plate (``K`` singular, no dual LCP): the contact set of the
    anchored plate (``cond`` made with ``anchor > 0``), by the dense method's first set and
    block steps on its LCP, without exact steps; the sparse method's exact steps then solve
    the plate itself from that set. Returns the set and the sets solved. Lawson–Hanson's probe
    waits for LH_ANCHORED_PROBE rows: the anchored plate starts sunk, every row pressed."""
    A, first = _start(pb, cond, None, feas_tol, probe=LH_ANCHORED_PROBE[0])
    ex = Exchange(p)
    for it in range(1, max_iter + 1):
        lam, gap = cond.basic(A)
        bad = infeasible(pb, A, lam, gap, feas_tol)
        if steps is not None:
            steps.append({"step": f"anchored {it}", "active": int(A.sum()), "infeasible": int(bad.sum()),
                          "solve": "dense"})
        if not bad.any() or A.tobytes() in ex.seen:
            return A, first + it
        A, mode = ex.next(A, bad)
        if steps is not None:
            steps[-1]["exchange"] = mode
    return A, first + max_iter


def run_dense(pb: ReducedQP, cond: DenseDual, A, feas_tol, max_iter, p, steps) -> Outcome:
    A, first = _start(pb, cond, A, feas_tol)
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
            return Outcome(Status.OPTIMAL, "no infeasible row", A, u, lam, first + it)
        A, mode = ex.next(A, bad)
        if steps is not None:
            steps[-1]["exchange"] = mode
    lam, _ = cond.basic(A)  # the last iterate: the set the last exchange gave, solved
    u, lam = cond.exact(A, lam)
    return Outcome(Status.MAX_ITER, f"iteration limit {max_iter} reached", A, u, lam, first + max_iter)
