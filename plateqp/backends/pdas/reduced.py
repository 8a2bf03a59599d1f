"""The QP read back as a contact problem, and what both methods share: the exchange rule,
the infeasible rows, the residuals of an answer (see the package docstring: "The problem",
"The method")."""

from __future__ import annotations

import copy

import numpy as np
import scipy.sparse as sp

from ...accuracy import NO_WORK
from ...errors import SolverError
from ...linalg import row_stiffness
from ...linalg.pattern import abs_matvec, leading
from ...linalg.products import remembered, times
from ..base import QP

#: The QP's null-space hint is taken where K annihilates it to this fraction of |K||N| (a plate's
#: rigid motions from its coordinates: about 1e-15 at 128²).
NULL_ROUNDING = 1e-10

__all__ = ["Exchange", "Outcome", "ReducedQP", "at_rounding", "force_scale", "gaps_at_rounding", "heave_force",
           "infeasible", "natural_residuals", "penalty_stiffness", "stationary_at_rounding"]

#: A rigid row's penalty spring puts at most PENALTY_SOFT · κ K_jj on each unknown j it reads
#: (:func:`penalty_stiffness`): ε κ PENALTY_SOFT lost on that unknown's pivot. Above 1 so that
#: a row whose weight sits on one unknown (a DKT row at a node: k and K_jj/B_ij² an ulp apart)
#: keeps its spring to the bit.
PENALTY_SOFT = 2.0

#: A step is exact when its residuals are within this many ε of the terms that make them
#: (:func:`at_rounding`).
ROUNDING_STOP = 2.0


def _leading_block(P: sp.csc_matrix, keep: np.ndarray) -> sp.csc_matrix:
    """``P[keep][:, keep]``. Where ``keep`` is ``0 … k−1`` and those columns hold no row past
    them (the primal formulation's ``block_diag(K, I)``), a view of P's leading columns: no
    copy of K (65 MB and 0.1 s at 256²)."""
    k = keep.size
    if k and keep[-1] == k - 1:  # keep is sorted and distinct: 0 … k−1
        K = leading(P, k)
        if K is not None:
            return K
    return P[keep][:, keep].tocsc()


def penalty_stiffness(B: sp.csr_matrix, Kd: np.ndarray, k: np.ndarray) -> np.ndarray:
    """The stiffness a rigid row's penalty spring is κ times (:func:`.driver.pdas`): the row's
    local stiffness ``k_i = Σ_j B_ij² K_jj``, but on a row that reads several unknowns at most
    ``PENALTY_SOFT · min_j K_jj / B_ij²`` (its softest unknown's stiffness in the row's units).

    The spring ``W B_iᵀB_i`` ties the row's unknowns together; where the factor eliminates one
    of them before another, the other's pivot becomes ``K_bb + W B_b² − (W B_a B_b)²/(K_aa +
    W B_a²)``, and the cancellation loses ``ε W B_b²`` on it: against ``K_bb``, ``ε κ`` (as on a
    row of one unknown, which cancels nothing) only while ``W B_b²`` is about ``κ K_bb`` at most.
    A bed row of a soil with unknowns of its own reads ``w − v``, the plate's stiff dof beside
    the soil's soft one (``K_ww / K_vv`` = 3e4 on a Pasternak soil at 16², 3e5 at 48²); with
    ``W = κ (K_ww + K_vv)`` the soil's pivots lost ``ε κ K_ww``: the refinement's steps then
    contracted only by 1/60 at 16² (by 1/3 with κ = 1e10: rounding, not the method) and at 24²
    (κ = 1e10) or 48² (κ = 1e8) the factor was not definite. Rows on one unknown, and the
    interpolated posts' rows of the ACM, BFS and DKT elements (weights at most 1 on unknowns
    of like stiffness), keep ``k_i``."""
    nnz = np.diff(B.indptr)
    soft = np.minimum.reduceat(Kd[B.indices] / B.data**2, B.indptr[:-1])  # every row has an entry
    return np.where(nnz > 1, np.minimum(k, PENALTY_SOFT * soft), k)


class ReducedQP:
    """The QP read back as a contact problem ``(K, f, B, ρ, g)``: separable variables eliminated
    (see the package docstring, "The problem")."""

    def __init__(self, qp: QP, max_rows: int | None) -> None:
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
        limit = n if max_rows is None else min(n, max_rows)
        if m > limit:
            cap = "n" if max_rows is None else f"min(n, {max_rows}) (option max_rows)"
            raise SolverError(f"the pdas backend takes at most {cap} constraint rows, got m = {m}, n = {n}")
        P = sp.csc_matrix(qp.P, dtype=float)  # stored zeros kept: the ordering reads them (linalg.pattern)
        G = sp.csc_matrix(qp.G, dtype=float)
        G.eliminate_zeros()
        vw = np.random.default_rng(0).standard_normal((n, 2))
        Pvw = P @ vw  # both products in one pass over P
        v, w, Pv, Pw = vw[:, 0], vw[:, 1], Pvw[:, 0], Pvw[:, 1]
        if abs(v @ Pw - w @ Pv) > 1e-10 * np.sqrt((Pv @ Pv) * (w @ w)) + 1e-300:
            raise SolverError("the pdas backend needs a symmetric P")  # a randomised check, O(nnz)
        d = P.diagonal()
        # separable: a positive diagonal, one row of G, no other non-zero in its column; the
        # non-zeros counted in the columns of the first two kinds only (O(their entries), not
        # O(nnz P): 12 ms at 128²)
        sep = (d > 0) & (np.diff(G.indptr) == 1)
        cand = np.flatnonzero(sep)
        lo, length = P.indptr[cand], np.diff(P.indptr)[cand]
        # a column whose first two stored entries hold a non-zero off its diagonal is coupled: only
        # the others are counted (a bed's plate dofs under its springs, 66 049 columns at 256²,
        # are decided by two entries each, not by all of theirs)
        two = length >= 2
        i0, i1 = lo[two], lo[two] + 1
        coupled_at = (((P.indices[i0] != cand[two]) & (P.data[i0] != 0))
                      | ((P.indices[i1] != cand[two]) & (P.data[i1] != 0)))
        sep[cand[two][coupled_at]] = False
        rest = np.ones(cand.size, dtype=bool)
        rest[np.flatnonzero(two)[coupled_at]] = False
        cand, lo, length = cand[rest], lo[rest], length[rest]
        at = np.arange(length.sum()) + np.repeat(lo - (np.cumsum(length) - length), length)
        nz = np.bincount(np.repeat(np.arange(cand.size), length), weights=P.data[at] != 0, minlength=cand.size)
        sep[cand] = nz == 1
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
        self.K = _leading_block(P, self.keep) if self.sep.size else P
        self.f = -qp.q[self.keep]
        self.B = (G[:, self.keep] if self.sep.size else G).tocsr()
        self.rho = np.bincount(self.sep_row, weights=self.sep_gamma**2 / self.sep_p, minlength=m)
        self.g = qp.h + np.bincount(self.sep_row, weights=self.sep_gamma * self.sep_q / self.sep_p, minlength=m)
        Kd = d[self.keep] if self.sep.size else d  # K's diagonal (one pass over P, not three)
        if np.any(Kd <= 0):
            raise SolverError("the pdas backend needs P with a positive diagonal on the coupled variables "
                              "(a coupled variable with no curvature makes the QP unbounded or degenerate)")
        empty = np.flatnonzero(np.diff(self.B.indptr) == 0)
        if empty.size:
            raise SolverError(f"row {empty[0]} of G acts on no coupled variable: not a contact row")
        self.Kd = Kd
        # local stiffness of each row, Σ_j B_ij² K_jj: that kind reads the diagonal alone
        self.k = row_stiffness(sp.diags(Kd), self.B, "diagonal")
        self.c = self.k / (1.0 + self.rho * self.k)  # in series with the row's spring
        self.k_penalty = penalty_stiffness(self.B, Kd, self.k)
        self.P, self.q = P, qp.q
        self._null, self._null_checked, self._lift = qp.null, False, None  # (:meth:`rigid`, :meth:`lift`)
        self._src = (qp.P, qp.G, G, max_rows, qp.null)  # what :meth:`again` compares
        self._abs_K = None  # |K|, kept where the problem is read again (:meth:`abs_K_times`)

    def abs_K_times(self, x: np.ndarray) -> np.ndarray:
        """``|K| x``: by blocks of K (:func:`plateqp.linalg.pattern.abs_matvec`, no copy of K),
        or where this problem was read again for another solve (:meth:`again`: a sweep) with
        ``|K|`` kept (its values only; K's index arrays shared)."""
        kept = self._abs_K
        return remembered(self.K, x, "abs", lambda: abs_matvec(self.K, x) if kept is None else kept @ x)

    def again(self, qp: QP, max_rows: int | None) -> ReducedQP | None:
        """This problem for ``qp`` where only its loads and gaps (``q``, ``h``) and the values of
        the separable columns of ``G`` (the springs) differ from the QP it was read from, P being
        the same object (a sweep's next value, its Hessian kept: :mod:`plateqp.linalg.keep`): a
        copy with those read anew, the rest (the split, K's block, B, the checks on P, the rigid
        motions checked) shared. None where anything else differs."""
        P0, G0, Gc0, rows0, null0 = self._src
        if qp.P is not P0 or max_rows != rows0 or qp.A is not None or qp.lb is not None or qp.ub is not None:
            return None
        if (qp.null is None) != (null0 is None) or (qp.null is not None and not np.array_equal(qp.null, null0)):
            return None
        new = copy.copy(self)
        if new._abs_K is None:
            K = self.K
            new._abs_K = sp.csc_matrix((np.abs(K.data[:K.indptr[-1]]), K.indices[:K.indptr[-1]], K.indptr),
                                       shape=K.shape, copy=False)
        if qp.G is not G0:
            G = sp.csc_matrix(qp.G, dtype=float)
            G.eliminate_zeros()
            if (G.shape != Gc0.shape or not np.array_equal(G.indptr, Gc0.indptr)
                    or not np.array_equal(G.indices, Gc0.indices)):
                return None
            at = Gc0.indptr[self.sep]  # each separable column's one entry
            coupled = np.ones(Gc0.data.size, dtype=bool)
            coupled[at] = False
            if not np.array_equal(G.data[coupled], Gc0.data[coupled]):
                return None
            gamma = np.empty(self.sep.size)
            gamma[:] = G.data[at]
            if not np.array_equal(gamma, self.sep_gamma):
                new.sep_gamma = gamma
                new.rho = np.bincount(self.sep_row, weights=gamma**2 / self.sep_p, minlength=self.m)
                new.c = self.k / (1.0 + new.rho * self.k)
            new._src = (P0, qp.G, G, rows0, null0)
        new.q = qp.q
        new.sep_q = qp.q[self.sep]
        new.f = -qp.q[self.keep]
        new.g = qp.h + np.bincount(self.sep_row, weights=new.sep_gamma * new.sep_q / self.sep_p, minlength=self.m)
        return new

    def rigid(self) -> np.ndarray | None:
        """The QP's hint ``null`` (:attr:`QP.null`) on the coupled variables, once checked (on
        first use): zero on the separable ones, and ``K`` annihilates it to rounding
        (``|K N r| ≤ NULL_ROUNDING · |K||N||r|`` for a fixed random ``r``: every column at
        once); None where there is none or it fails (then nothing trusts it)."""
        if not self._null_checked:
            self._null_checked = True
            N = self._null
            if N is not None:
                Nk = N[self.keep]
                scale = np.abs(Nk).max(initial=0.0)
                ok = scale > 0 and np.abs(N[self.sep]).max(initial=0.0) <= NULL_ROUNDING * scale
                if ok and Nk.shape[1]:
                    # the columns in one fixed random combination v = N r, against the bound
                    # |K| |N| |r| ≥ Σ_j |r_j| |K| |N_j| (every column at rounding passes: |K v| ≤
                    # Σ_j |r_j| |K N_j|); a column that K does not annihilate shows in K v unless
                    # the others cancel it exactly. One product with K and one with |K| of a
                    # single vector each, not of every column (45 → 16 ms at 256²)
                    k = Nk.shape[1]
                    r = np.random.default_rng(0).uniform(0.5, 1.5, k) * np.where(np.arange(k) % 2, -1.0, 1.0)
                    bound = abs_matvec(self.K, np.abs(Nk) @ np.abs(r)).max(initial=0.0)
                    ok = bool(np.abs(self.K @ (Nk @ r)).max(initial=0.0) <= NULL_ROUNDING * bound)
                N = Nk if ok else None
            self._null = N
        return self._null

    def lift(self) -> np.ndarray | None:
        """``V(VᵀV)⁻¹`` for the rigid motions ``V`` of :meth:`rigid` (``VᵀV(VᵀV)⁻¹ = I``: it
        carries a part along V back onto the dofs), made once and shared with the copies of
        :meth:`again`; None where :meth:`rigid` is."""
        V = self.rigid()
        if V is None or V.shape[1] == 0:
            return None
        if self._lift is None:
            self._lift = V @ np.linalg.inv(V.T @ V)
        return self._lift

    def rigid_rows(self) -> np.ndarray | None:
        """``B N`` (m × k) for the rigid motions ``N`` of :meth:`rigid`, made once (the hold
        checks read its active rows, ``(B N)[A] = B_A N``, each time: no row slice of ``B``); None
        where :meth:`rigid` is."""
        N = self.rigid()
        if N is None:
            return None
        if getattr(self, "_rigid_rows", None) is None:  # (made on first use, shared by :meth:`again`'s copies)
            self._rigid_rows = np.asarray(self.B @ N)
        return self._rigid_rows

    def rigid_mass(self) -> np.ndarray | None:
        """``Nᵀ diag(K) N`` (k × k) for the rigid motions of :meth:`rigid`, made once; None where
        :meth:`rigid` is."""
        N = self.rigid()
        if N is None:
            return None
        if getattr(self, "_rigid_mass", None) is None:
            self._rigid_mass = N.T @ (self.Kd[:, None] * N)
        return self._rigid_mass

    def x(self, u: np.ndarray, lam: np.ndarray) -> np.ndarray:
        x = np.empty(self.n)
        x[self.keep] = u
        x[self.sep] = -(self.sep_q + self.sep_gamma * lam[self.sep_row]) / self.sep_p
        return x



class Exchange:
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


def at_rounding(pb: ReducedQP, u: np.ndarray, idx: np.ndarray, BA, lamA: np.ndarray, r_u: np.ndarray,
                r_A: np.ndarray) -> bool:
    """The step ``(u, λ_A)`` of the active rows ``idx`` is exact to rounding: each residual is
    within ``ROUNDING_STOP·ε`` of the terms that make it (Oettli–Prager's backward error in
    the max norm, the test LAPACK's iterative refinement stops at): ``|r_u| ≤ c ε (|K||u| +
    |B_A|ᵀ|λ_A| + |f|)`` and ``|r_A| ≤ c ε (|B_A||u| + |g_A| + ρ_A|λ_A|)``. Another
    refinement step would not change the answer."""
    return stationary_at_rounding(pb, u, BA, lamA, r_u) and gaps_at_rounding(pb, u, idx, BA, lamA, r_A)


def stationary_at_rounding(pb: ReducedQP, u: np.ndarray, BA, lamA: np.ndarray, r_u: np.ndarray) -> bool:
    """The first half of :func:`at_rounding`: ``|r_u| ≤ c ε (|K||u| + |B_A|ᵀ|λ_A| + |f|)``."""
    eps = ROUNDING_STOP * np.finfo(float).eps
    su = (pb.abs_K_times(np.abs(u)) + abs(BA.T) @ np.abs(lamA) + np.abs(pb.f)).max(initial=0.0)
    return bool(np.abs(r_u).max(initial=0.0) <= eps * su)


def gaps_at_rounding(pb: ReducedQP, u: np.ndarray, idx: np.ndarray, BA, lamA: np.ndarray, r_A: np.ndarray) -> bool:
    """The second half of :func:`at_rounding`: ``|r_A| ≤ c ε (|B_A||u| + |g_A| + ρ_A|λ_A|)``."""
    eps = ROUNDING_STOP * np.finfo(float).eps
    sA = abs(BA) @ np.abs(u) + np.abs(pb.g[idx]) + pb.rho[idx] * np.abs(lamA)
    return bool(np.all(np.abs(r_A) <= eps * sA.max(initial=0.0)))


def heave_force(pb: ReducedQP) -> float:
    """The force that closes the largest negative gap at its row's own stiffness (the row's
    spring left out): max k_i · max(−g_i, 0)."""
    return float((pb.k * np.maximum(-pb.g, 0.0)).max(initial=0.0))


def force_scale(pb: ReducedQP, lam: np.ndarray, tol: float = 0.0) -> float:
    """The force scale of the reactions: the largest, at least 1e-12 of the load ‖f‖₁; where
    every reaction is at most ``tol`` of the load, the load itself; where the load and the
    reactions are below NO_WORK of :func:`heave_force`, that force takes the load's place (with
    no load, the reactions of a plate lifted as a body onto negative gaps are rounding of it,
    not of themselves: measured against themselves they never settled)."""
    load = np.abs(pb.f).sum()
    rmax = np.abs(lam).max(initial=0.0)
    heave = heave_force(pb)
    if max(load, rmax) <= NO_WORK * heave:
        load = heave
    if rmax <= tol * load:
        return max(load, np.finfo(float).tiny)
    return max(rmax, 1e-12 * load, np.finfo(float).tiny)


def infeasible(pb: ReducedQP, A: np.ndarray, lam: np.ndarray, gap: np.ndarray, feas_tol: float) -> np.ndarray:
    """Rows to exchange: active with a negative reaction, inactive with a negative gap."""
    F = feas_tol * force_scale(pb, lam, feas_tol)
    return (A & (lam < -F)) | (~A & (pb.c * gap < -F))


class Outcome:
    def __init__(self, status, message, A, u=None, lam=None, it=0, ray=None):
        self.status, self.message, self.A, self.u, self.lam, self.it, self.ray = status, message, A, u, lam, it, ray


def natural_residuals(pb: ReducedQP, u: np.ndarray, lam: np.ndarray, tol: float = 0.0) -> tuple[float, float]:
    """Relative natural residual and relative stationarity residual of ``(u, λ)``; where the
    load and the reactions are below NO_WORK of :func:`heave_force`, forces are measured
    against that."""
    gap = pb.g + pb.rho * lam - pb.B @ u
    nat = float(np.abs(np.minimum(lam, pb.c * gap)).max(initial=0.0) / force_scale(pb, lam, tol))
    BtL = pb.B.T @ lam
    force, heave = max(np.linalg.norm(pb.f), np.linalg.norm(BtL)), heave_force(pb)
    st = float(np.linalg.norm(times(pb.K, u) - pb.f + BtL) / max(heave if force <= NO_WORK * heave else force, 1e-300))
    return nat, st
