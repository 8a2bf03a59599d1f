r"""Block principal pivoting (Júdice & Pires 1994) for LCP(M, q), in NumPy/SciPy.

Finds ``z ≥ 0`` with ``w = M z + q ≥ 0`` and ``zᵀ w = 0`` for ``M`` symmetric positive
(semi)definite or any P-matrix (a plate's condensed stiffness or flexibility). The unknowns are
split into ``F`` (``z_F`` free, ``w_F = 0``) and ``T`` (``z_T = 0``); each split is one solve
``M_FF z_F = −q_F``; all infeasible indices are exchanged at once, and where the count of
infeasibilities has not fallen for ``p`` steps (default 6) Murty's least-index rule exchanges
one at a time until it does (finite for every P-matrix).

Contract:

- **Start and warm start.** Default ``F = {i : q_i < −feas_tol ‖q‖∞}``. Option ``active``: a
  boolean array, ``True`` where ``z_i = 0`` is held (the set ``T``); the final split comes back
  in ``extras["active"]`` in the same form. On a plate's condensed form (z = gaps) that is "in
  contact", on its dual (z = reactions) "not in contact".
- **Singular blocks** (PSD ``M``, a floating plate): detected by a small pivot of the
  equilibrated block, then solved through its eigendecomposition: a consistent block takes the
  minimum-norm solution (made nonnegative by a small LP where it can), an inconsistent one
  either yields a Farkas certificate ``y ≥ 0``, ``M y = 0``, ``qᵀy < 0`` (status ``INFEASIBLE``,
  ``y`` in ``extras["certificate"]``, checked on the full ``M``) or sends the indices the steepest
  descent drives to zero into ``T``. A split seen twice ends the pivoting; then the whole LCP is
  tested for solvability and proximal-point steps (``PROX_EPS``) finish it.
- **Answer and status.** One clean solve on the final split (with one step of refinement),
  negatives down to ``feas_tol`` of its scale set to zero, ``w = M z + q`` from the full ``M``;
  ``OPTIMAL`` only if the relative natural residual (:func:`plateqp.backends.lcp.natural_residual`)
  is at most ``accept_tol``, else ``INACCURATE``: a wrong ``OPTIMAL`` cannot come out of the
  pivoting. ``ERROR`` (no ``x``) or ``MAX_ITER`` (the best split's ``x``) otherwise.
- **Accuracy.** A direct method, exact to about ``cond(M_FF) · ε``; the presets of
  :data:`ACCURACY` set ``feas_tol`` and ``accept_tol`` only.

The method, its singular cases and their measurements in detail: docs/design/bpp.md.

Examples
--------
>>> import numpy as np
>>> from plateqp.backends.bpp import bpp
>>> sol = bpp(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0]))
>>> np.round(sol.x * 3, 12), sol.iterations       # z = (4/3, 7/3)
(array([4., 7.]), 1)
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from ..errors import ProblemError
from .base import LCP, RawSolution, Status
from .lcp import (LCPBackend, answer, check_flag, check_int, infeasible, is_certificate, natural_residual,
                  settings)

__all__ = ["ACCURACY", "OPTIONS", "BACKEND", "bpp", "backends"]

#: Tolerances of each accuracy preset (a direct method: exact up to rounding at every preset).
#:
#: ``feas_tol``
#:     ``z_i`` (``w_i``) counts as infeasible only below ``−feas_tol`` times the
#:     scale of ``z`` (of ``w``: ``max(‖q‖∞, max|M| ‖z‖∞)``); smaller negatives are
#:     rounding, and are clipped to zero in the final ``z``.
#: ``accept_tol``
#:     relative natural residual of the final answer above which the status is
#:     ``INACCURATE`` instead of ``OPTIMAL`` (100 × ``feas_tol``: clipping a
#:     ``z_i`` of size ``feas_tol`` moves ``w`` by about that much).
ACCURACY: dict[str, dict[str, float]] = {
    "low": {"feas_tol": 1e-8, "accept_tol": 1e-6},
    "default": {"feas_tol": 1e-10, "accept_tol": 1e-8},
    "high": {"feas_tol": 1e-12, "accept_tol": 1e-10},
}

#: A squared Cholesky pivot of the equilibrated block (unit diagonal) below ``SING_TRIGGER ·
#: sing_tol`` sends the block to the eigen-decomposition, which decides whether it is singular.
SING_TRIGGER = 1e3

#: Proximal-point fallback (used only when the pivoting fails, i.e. for singular M): at most
#: ``PROX_STEPS`` steps z ← solution of LCP(M + ε D, q − ε D z), ε = ``PROX_EPS``, D = diag(M).
PROX_EPS = 1e-2
PROX_STEPS = 50

class _Block:
    """A factorised principal block ``M_FF``: Cholesky, LU, or (singular) eigen-decomposition."""

    def __init__(self, A: np.ndarray, symmetric: bool, sing_tol: float) -> None:
        self.kind = "empty"
        self.A = A
        self.null = None  # (|F|, k) orthonormal basis of the null space, eigen path only
        self.negative = 0.0  # most negative eigenvalue / λ_max, eigen path only
        if A.shape[0] == 0:
            return
        diag = np.diagonal(A)
        if symmetric:
            # Cholesky of the equilibrated block D A D (D = diag(A)^-½), judged by its pivots:
            # a block whose diagonal spans 1e-2 … 1e8 (a plate's dual: rigid supports next to
            # soft springs) is not near-singular, but a pivot test against max diag(A) said so
            # and sent it to the eigen path, which lost 1e-8 relative in the small rows' z.
            d = np.where(diag > 0, 1.0 / np.sqrt(np.where(diag > 0, diag, 1.0)), 1.0)
            try:
                c = sla.cho_factor(d[:, None] * A * d[None, :], lower=True, check_finite=False)
                if np.diagonal(c[0]).min() ** 2 > SING_TRIGGER * sing_tol and np.all(diag > 0):
                    self.kind, self._fac, self._d = "cholesky", c, d
                    return
            except np.linalg.LinAlgError:
                pass
            lam, V = sla.eigh(A, check_finite=False)
            lmax = max(np.abs(lam).max(), 0.0)
            keep = lam > sing_tol * lmax
            self.kind = "eigh"
            self._V, self._lam = V[:, keep], lam[keep]
            self.null = V[:, ~keep]
            self.negative = float(lam.min() / lmax) if lmax > 0 else 0.0
        else:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # LinAlgWarning on an exactly singular block
                lu = sla.lu_factor(A, check_finite=False)
            u = np.abs(np.diagonal(lu[0]))
            if u.min() <= sing_tol * max(u.max(), np.finfo(float).tiny):
                self.kind = "singular"
                return
            self.kind, self._fac = "lu", lu

    @property
    def singular(self) -> bool:
        return self.kind in ("eigh", "singular") and (self.kind == "singular" or self.null.shape[1] > 0)

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Solution of ``M_FF x = b`` (minimum-norm least squares on the eigen path)."""
        if self.kind == "empty":
            return np.zeros(0)
        if self.kind == "cholesky":
            d = self._d if b.ndim == 1 else self._d[:, None]
            return d * sla.cho_solve(self._fac, d * b, check_finite=False)
        if self.kind == "lu":
            return sla.lu_solve(self._fac, b, check_finite=False)
        return self._V @ ((self._V.T @ b) / self._lam)

    def null_part(self, b: np.ndarray) -> np.ndarray:
        """``P b``, the component of ``b`` in the null space of ``M_FF`` (zero if nonsingular)."""
        if self.null is None or self.null.shape[1] == 0:
            return np.zeros_like(b)
        return self.null @ (self.null.T @ b)


class _Step:
    """One complementary split: its factor, basic solution and infeasibilities."""

    def __init__(self, M, q, F, symmetric, sing_tol, feas_tol, Mmax) -> None:
        self.F = F.copy()
        idx = np.flatnonzero(F)
        self.idx = idx
        self.block = _Block(M[np.ix_(idx, idx)], symmetric, sing_tol)
        self.drift = None  # descent direction along a null space (inconsistent singular block)
        self.certificate = None  # y ≥ 0, M y = 0, qᵀy < 0, if this split exposed one
        n = q.shape[0]
        z = np.zeros(n)
        self.z = self.w = z
        self.infeasible = np.zeros(n, bool)
        self.violation = np.inf
        if self.block.kind == "singular":  # non-symmetric M: nothing sensible to do
            return
        b = -q[idx]
        z[idx] = self.block.solve(b)
        zscale = max(np.abs(z).max(initial=0.0), np.finfo(float).tiny)
        wscale = max(np.abs(q).max(initial=0.0), Mmax * zscale, np.finfo(float).tiny)
        H = np.zeros(n, bool)
        Pb = self.block.null_part(b)
        if np.abs(Pb).max(initial=0.0) > feas_tol * wscale:
            # inconsistent: the objective falls without bound along the null space of M_FF, and
            # the z_i that reach zero first are the infeasible ones of F
            y = _null_certificate(self.block.null, q[idx], feas_tol)
            if y is not None:
                self.certificate = np.zeros(n)
                self.certificate[idx] = y
            self.drift = Pb  # steepest descent of ½zᵀMz + qᵀz in the null space
            H[idx] = Pb < -feas_tol * np.abs(Pb).max()
        elif self.block.singular and z[idx].min() < -feas_tol * zscale:
            # consistent: z_F + N c solves the block for every c; look for one that is ≥ 0
            z[idx] = _nonnegative_completion(z[idx], self.block.null, feas_tol * zscale)
            zscale = max(np.abs(z).max(initial=0.0), np.finfo(float).tiny)
            wscale = max(np.abs(q).max(initial=0.0), Mmax * zscale, np.finfo(float).tiny)
        w = M @ z + q
        H[idx] |= z[idx] < -feas_tol * zscale
        H |= ~F & (w < -feas_tol * wscale)
        viol = max(max(0.0, -z[idx].min(initial=0.0)) / zscale,
                   max(0.0, -w[~F].min(initial=0.0)) / wscale)
        self.z, self.w, self.infeasible = z, w, H
        self.violation = np.inf if self.drift is not None else viol


def _nonnegative_completion(z0: np.ndarray, N: np.ndarray, tol: float) -> np.ndarray:
    """``z0 + N c`` with the least total negativity (zero if some ``c`` makes it ≥ 0); an LP."""
    from scipy.optimize import linprog

    m, k = N.shape
    scale = max(np.abs(z0).max(), np.finfo(float).tiny)
    # variables (c, s): minimise Σ s  subject to  z0 + N c + s ≥ 0,  s ≥ 0
    cost = np.concatenate([np.zeros(k), np.ones(m)])
    A = np.hstack([-N, -np.eye(m)])
    res = linprog(cost, A_ub=A, b_ub=z0 / scale, bounds=[(None, None)] * k + [(0, None)] * m,
                  method="highs")
    if res.status != 0:
        return z0
    z = z0 + N @ (res.x[:k] * scale)
    z[(z < 0) & (z >= -tol)] = 0.0
    return z


def _null_certificate(N: np.ndarray, q: np.ndarray, tol: float) -> np.ndarray | None:
    """``y = N c ≥ 0`` with ``qᵀy < 0`` (``Σ y = 1``), if one exists; an LP in ``c``."""
    from scipy.optimize import linprog

    if N is None or N.shape[1] == 0:
        return None
    k = N.shape[1]
    qs = q / max(np.abs(q).max(), np.finfo(float).tiny)
    res = linprog(N.T @ qs, A_ub=-N, b_ub=np.zeros(N.shape[0]), A_eq=N.sum(axis=0)[None, :],
                  b_eq=[1.0], bounds=[(None, None)] * k, method="highs")
    if res.status != 0 or res.fun >= -max(tol, 1e-12):
        return None
    return np.maximum(N @ res.x, 0.0)


def _full_null_space(M: np.ndarray, sing_tol: float) -> np.ndarray:
    """Orthonormal basis of the (numerical) null space of symmetric ``M``."""
    lam, V = sla.eigh(M, check_finite=False)
    lmax = max(np.abs(lam).max(initial=0.0), 0.0)
    return V[:, lam <= sing_tol * lmax]


# --------------------------------------------------------------------------- the method


class _Failure(Exception):
    """A split the method cannot go on from (M neither PSD nor a P-matrix)."""


@dataclass
class _Run:
    """What one pivoting run ends with."""

    ending: str  # "solved" | "infeasible" | "cycle" | "max_iter"
    best: _Step
    splits: int = 0
    block: int = 0
    single: int = 0
    singular: int = 0
    certificate: np.ndarray | None = None  # y ≥ 0, Mᵀy ≤ 0, qᵀy < 0 (ending "infeasible")

    def infeasible(self, step: _Step, y: np.ndarray) -> _Run:
        self.ending, self.best, self.certificate = "infeasible", step, y
        return self


def _pivoting(M, q, F, max_iter, p, symmetric, sing_tol, feas_tol, steps=None) -> _Run:
    """The block principal pivoting loop from split ``F`` (Júdice & Pires, with Murty's backup).

    Ends "infeasible" on a checked certificate that LCP(M, q) has no solution; raises _Failure
    on a block it cannot handle.
    """
    n = q.shape[0]
    Mmax = np.abs(M).max(initial=0.0)
    ninf, pbar = n + 1, p
    visited: set[bytes] = set()
    run = _Run("max_iter", None)
    while run.splits < max_iter:
        run.splits += 1
        step = _Step(M, q, F, symmetric, sing_tol, feas_tol, Mmax)
        run.singular += step.block.singular
        if step.block.kind == "singular":
            raise _Failure(f"singular principal block (|F| = {step.idx.size}) of a non-symmetric M")
        if step.block.negative < -SING_TRIGGER * sing_tol:
            raise _Failure(f"M is not positive semidefinite (a principal block has eigenvalue "
                           f"{step.block.negative:.1e} λ_max)")
        if step.certificate is not None and is_certificate(M, q, step.certificate, SING_TRIGGER * sing_tol):
            return run.infeasible(step, step.certificate)
        if run.best is None or step.violation < run.best.violation:
            run.best = step
        H = step.infeasible
        nV = int(H.sum())
        if nV == 0:
            if step.drift is not None:  # the descent meets no bound: y = P b ≥ 0
                y = np.zeros(n)
                y[step.idx] = np.maximum(step.drift, 0.0)
                if is_certificate(M, q, y, SING_TRIGGER * sing_tol):
                    return run.infeasible(step, y)
                raise _Failure("singular principal block with no certificate of infeasibility")
            run.best, run.ending = step, "solved"
            _record(steps, run.splits, step, nV, None)
            return run
        if nV < ninf:
            ninf, pbar, rule = nV, p, "block"
            visited.clear()
        elif pbar >= 1:
            pbar, rule = pbar - 1, "block"
        else:
            rule = "single"
            key = F.tobytes()
            if key in visited:  # Murty's rule never revisits a split in exact arithmetic
                run.ending = "cycle"
                _record(steps, run.splits, step, nV, None)
                return run
            visited.add(key)
            r = int(np.flatnonzero(H)[0])  # least index
            H = np.zeros(n, bool)
            H[r] = True
        _record(steps, run.splits, step, nV, rule, H)
        run.block += rule == "block"
        run.single += rule == "single"
        F = F ^ H
    return run


def _finish(M, q, step: _Step, feas_tol: float) -> tuple[np.ndarray, np.ndarray, float]:
    """One clean solve on a split (its factor, one refinement step): z, w = M z + q, residual."""
    idx = step.idx
    z = np.zeros(q.shape[0])
    if idx.size:
        zF = step.z[idx]
        zF = zF - step.block.solve(step.block.A @ zF + q[idx])  # (Λ⁺ ignores a null part)
        zscale = max(np.abs(zF).max(), np.finfo(float).tiny)
        zF[(zF < 0) & (zF >= -feas_tol * zscale)] = 0.0
        z[idx] = zF
    w = M @ z + q
    return z, w, natural_residual(M, q, z, w)


def bpp(M, q, active=None, max_iter=None, p=6, trace=False, *, accuracy="default",
        feas_tol=None, accept_tol=None, sing_tol=None) -> RawSolution:
    """Solve LCP(M, q) by block principal pivoting (Júdice & Pires 1994).

    Find ``z ≥ 0`` with ``w = M z + q ≥ 0`` and ``zᵀ w = 0``.

    Parameters
    ----------
    M : array_like or sparse matrix, shape (n, n)
        Symmetric positive (semi)definite, or any P-matrix (densified).
    q : array_like, shape (n,)
    active : array_like of bool, shape (n,), optional
        Warm start: ``True`` where ``z_i = 0`` is held at the start (the set
        ``T``). Default: ``q ≥ 0`` up to rounding. Pass ``extras["active"]`` of an earlier
        solve of a neighbouring problem.
    max_iter : int, optional
        Maximum number of splits tried by the pivoting (default ``2 n + 50``;
        each costs one factorisation); the proximal fallback, if it runs, has a
        budget of its own of as many. Reaching it gives ``Status.MAX_ITER`` with
        the best split's ``x``.
    p : int, optional
        Number of block pivots allowed without a decrease of the number of
        infeasibilities before Murty's single-pivot rule takes over (default 6;
        Júdice & Pires used 3, which on the 128² slab on 30 × 30 posts let Murty's
        one-index steps run for about 30 splits: 58 against 29 splits on the
        condensed LCP, 60 against 31 on the dual; other scenes measured did not
        change). ``p = 0``: Murty's rule whenever the count does not decrease.
    trace : bool, optional
        Record every split of the main run in ``extras["trace"]`` as
        ``{"step": k, "free": |F|, "infeasible": |H1 ∪ H2|, "pivot": "block" |
        "single" | None, "exchanged": [indices], "singular": bool}``
        (``pivot`` and ``exchanged``: the exchange made *after* the step).
    accuracy : {"low", "default", "high"} or float, optional
        Preset of :data:`ACCURACY`; the keywords below override it.
    feas_tol, accept_tol : float, optional
        See :data:`ACCURACY`.
    sing_tol : float, optional
        Relative eigenvalue under which a principal block counts as singular
        (default ``max(1e-12, 10 n ε)``).

    Returns
    -------
    RawSolution
        ``status``: ``OPTIMAL`` when the natural residual of the cleaned-up
        answer is at most ``accept_tol``, whatever route led to it; else
        ``INFEASIBLE`` (no ``x``: a certificate ``y ≥ 0``, ``Mᵀy ≤ 0``,
        ``qᵀy < 0`` that no solution exists, in ``extras["certificate"]``),
        ``INACCURATE`` (a feasible split was found but rounding spoiled it),
        ``MAX_ITER`` (``x`` is the best split seen) or ``ERROR`` (no ``x``: the
        pivoting cycled or met a block it cannot handle; ``M`` is then neither
        a P-matrix nor symmetric PSD, or the problem is degenerate beyond the
        fallback; ``extras`` holds the best ``z`` and ``w``). ``x = z``,
        ``w = M z + q``, ``obj = ½ zᵀMz + qᵀz``, ``iterations`` (number of
        splits tried, every run included: a warm start from the solution's
        split takes 1), ``solve_time``. ``extras``: ``active`` (final ``T``, a
        bool array), ``block_pivots``, ``single_pivots``, ``singular_blocks``,
        ``proximal_steps``, ``natural_residual``, ``factor``, ``trace`` if asked.

    Raises
    ------
    ProblemError
        Malformed data or a bad option value.
    """
    t0 = time.perf_counter()
    prob = LCP(M, q)
    M, q, n = prob.M, prob.q, prob.n
    tol = settings(ACCURACY, accuracy, ("feas_tol", "accept_tol"), feas_tol=feas_tol, accept_tol=accept_tol,
                   sing_tol=max(1e-12, 10 * n * np.finfo(float).eps) if sing_tol is None else sing_tol)
    feas_tol, accept_tol, sing_tol = tol["feas_tol"], tol["accept_tol"], tol["sing_tol"]
    max_iter = check_int("max_iter", 2 * n + 50 if max_iter is None else max_iter, 1)
    p, trace = check_int("p", p, 0), check_flag("trace", trace)
    if active is None:  # z_i = 0 held where q_i ≥ 0 up to rounding (w's own infeasibility test)
        F = q < -feas_tol * np.abs(q).max(initial=0.0)
    else:
        a = np.asarray(active)
        if a.dtype != bool or a.shape != (n,):
            raise ProblemError(f"option active must be a boolean array of length {n}, "
                               f"got {a.dtype} array of shape {a.shape}")
        F = ~a

    Mmax = np.abs(M).max(initial=0.0)
    symmetric = bool(np.abs(M - M.T).max(initial=0.0) <= 1e-10 * max(Mmax, np.finfo(float).tiny))
    steps: list[dict] | None = [] if trace else None
    extras: dict = {"trace": steps} if trace else {}
    args = (p, symmetric, sing_tol, feas_tol)
    try:
        run = _pivoting(M, q, F, max_iter, *args, steps=steps)
    except _Failure as exn:
        return RawSolution(status=Status.ERROR, solve_time=time.perf_counter() - t0, extras=extras,
                           solver_status=f"{exn}: block principal pivoting needs a P-matrix or a "
                                         "symmetric positive semidefinite M")
    if run.ending == "infeasible":
        return infeasible(run.certificate, t0, run.splits, f"block principal pivoting, after {run.splits} splits",
                          extras)
    runs = [run]
    z, w, res = _finish(M, q, run.best, feas_tol)
    final, how = run, run.ending
    n_prox = 0
    if res > accept_tol and symmetric and (run.ending == "cycle" or
                                           (run.ending == "max_iter" and run.singular)):
        # The pivoting failed (possible for a singular M: the theorem is for P-matrices).
        # First, does the LCP have a solution at all? For symmetric PSD M it has none iff
        # some y ≥ 0 has M y = 0 and qᵀy < 0: a small LP on the null space of M.
        y = _null_certificate(_full_null_space(M, sing_tol), q, feas_tol)
        if is_certificate(M, q, y, SING_TRIGGER * sing_tol):
            return infeasible(y, t0, run.splits, f"the null space of M, after the pivoting had failed "
                                                 f"({run.splits} splits)", extras)
        # It has one: proximal-point steps z ← LCP(M + εD, q − εD z), each with a positive
        # definite matrix (finite pivoting), each split tried on the original problem.
        d = np.diagonal(M).copy()
        d[d <= 0] = max(d.max(initial=0.0), 1.0)
        Mp = M + PROX_EPS * np.diag(d)
        zk, act = np.maximum(z, 0.0), ~run.best.F
        try:
            for n_prox in range(1, PROX_STEPS + 1):
                budget = max_iter - sum(r.splits for r in runs[1:])  # its own budget
                if budget < 2:
                    break
                sub = _pivoting(Mp, q - PROX_EPS * d * zk, ~act, budget - 1, *args)
                zk = _finish(Mp, q - PROX_EPS * d * zk, sub.best, feas_tol)[0]
                act = zk <= 0
                test = _pivoting(M, q, ~act, 1, *args)
                if test.ending == "infeasible":
                    return infeasible(test.certificate, t0, run.splits, "a proximal step's split", extras)
                runs += [sub, test]
                zt, wt, rt = _finish(M, q, test.best, feas_tol)
                if rt <= accept_tol:
                    z, w, res, final, how = zt, wt, rt, test, "proximal"
                    break
        except _Failure:
            pass
    splits = sum(r.splits for r in runs)
    if res <= accept_tol:
        status = Status.OPTIMAL
    elif run.ending == "solved":
        status = Status.INACCURATE
    else:
        status = Status.ERROR if run.ending == "cycle" else Status.MAX_ITER
    message = {
        "solved": f"feasible split after {splits} splits",
        "proximal": (f"pivoting {run.ending} after {run.splits} splits; solved after {n_prox} "
                     f"proximal steps ({splits} splits in all)"),
        "cycle": (f"a split repeated under Murty's rule after {run.splits} splits (M is not a "
                  f"P-matrix) and {n_prox} proximal steps did not recover; best split: natural "
                  f"residual {res:.1e}"),
        "max_iter": (f"iteration limit {max_iter} reached, {n_prox} proximal steps; best split: "
                     f"natural residual {res:.1e}"),
    }[how]
    extras.update(active=~final.best.F, block_pivots=sum(r.block for r in runs),
                  single_pivots=sum(r.single for r in runs),
                  singular_blocks=sum(r.singular for r in runs), proximal_steps=n_prox,
                  natural_residual=res, factor=final.best.block.kind)
    out = answer(q, z, w, status, t0, splits, message, extras)
    if status is Status.ERROR:  # no answer: the best split's z and w stay in extras
        extras.update(z=z, w=w)
        out.x = out.w = None
    return out


def _record(steps: list | None, it: int, step: _Step, nV: int, rule: str | None,
            exchanged: np.ndarray | None = None) -> None:
    if steps is not None:
        steps.append({"step": it, "free": int(step.idx.size), "infeasible": nV, "pivot": rule,
                      "exchanged": [] if exchanged is None else np.flatnonzero(exchanged).tolist(),
                      "singular": bool(step.block.singular)})


#: Keys accepted in the ``options`` dict of the backend's ``solve``.
OPTIONS = ("active", "max_iter", "p", "sing_tol", "trace") + tuple(ACCURACY["default"])

#: The ``bpp`` backend: exact, warm-started by ``options["active"]``.
BACKEND = LCPBackend("bpp", bpp, OPTIONS, exact=True, warm_start=True)


def backends() -> list[LCPBackend]:
    """The backends this module provides: ``[BACKEND]``."""
    return [BACKEND]
