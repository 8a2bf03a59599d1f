r"""A primal–dual active set method with preconditioned conjugate gradients inside, matrix-free,
for the convex QP with bounds and a few equalities

.. math::
    \min_x \tfrac12 x^T M x + q^T x \quad\text{s.t.}\quad x \ge 0,\quad G^T x = b ,

``M`` symmetric positive semidefinite (positive definite on the null space of ``Gᵀ``), known
through ``matvec``; ``G`` dense m × k, k small (``None``: no equality).

Contract:

- **Method.** The active set A = {i : x_i − c g_i > 0} (g = M x + q − G α the gradient, c > 0
  a scale of M's inverse; the semismooth Newton step of the complementarity function
  min(x, g): Hintermüller, Ito & Kunisch, SIAM J. Optim. 13, 2003); on A the equality-constrained
  problem with x = 0 off A is solved by conjugate gradients projected onto the null space of
  G_Aᵀ and preconditioned by the restriction of ``precond`` (any symmetric positive definite
  approximation of M⁻¹), started from the last iterate. While A changes, the inner solves stop
  at ``INNER_RTOL``. Once it settles, the solution is refined: the residual from ``precise``
  (a dearer, more accurate product, where given: one per round), a correction by CG on the
  plain product (each round at most ``REFINE_RTOL`` of the residual, no tighter than the asked
  tolerance needs), A checked again with the accurate gradient, until the tolerance is met
  (``"stalled"`` where a round no longer halves the residual). The plain product's own error
  (a sparse solve's cond·ε) thus never limits the answer, and the dear one is spent on a few
  residuals only, not on every CG step.
- **Answer.** x ≥ 0 (the components left negative by an inexact inner solve are never
  returned: a set that does not settle ends ``"cycled"``), ``alpha`` the equalities'
  multipliers (least squares on A), ``g``.
- **Status.** ``"optimal"`` when A no longer changes and, with g from a fresh (accurate) product,
  ‖min(x, g)‖ ≤ tol · max(‖q‖, ‖M x‖, ‖G α‖) and ‖Gᵀx − b‖ ≤ tol · max(‖b‖, ‖G‖‖x‖) (the
  scales of :mod:`plateqp.backends.mprgp`'s rule); ``"cycled"`` when A repeats or ``max_outer``
  sets were tried (the method has no convergence guarantee for a matrix that is not an
  M-matrix: a flexibility is not one), ``"max_iter"`` when the products run out, ``"singular"``
  when G_A loses rank (the set does not hold the plate). The caller falls back to MPRGP,
  which converges for every such problem, on any of these.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

#: the inner solves' relative tolerance while the active set still changes
INNER_RTOL = 1e-6
#: active sets tried at most
MAX_OUTER = 40
#: the settled set's refinement: each round's CG asks at least this relative reduction (a plain
#: product's error, about cond(K)·ε, bounds what one round can gain)
REFINE_RTOL = 1e-3
#: each round aims at this fraction of the asked tolerance (a margin: the caller's check reads
#: the worst row, the tolerance a 2-norm)
REFINE_AIM = 0.01
#: refinement rounds on one settled set at most
MAX_ROUNDS = 12


@dataclass(frozen=True)
class ActiveSetResult:
    """What :func:`active_set_pcg` found (the module's contract)."""

    x: np.ndarray
    alpha: np.ndarray
    g: np.ndarray
    iterations: int  # conjugate gradient steps, all sets
    matvecs: int
    sets: int
    status: str
    message: str


def _pcg(apply, idx, rhs, x, precond, project, rtol, budget, Ax=None):
    """Projected preconditioned CG on the equations apply(x)[idx] = rhs (on the current set),
    from x (feasible for the projection's equalities; ``Ax`` its product if known): x, steps and
    the product of x on every row (``apply`` gives them all: carried along the steps, so the
    gradient off the set costs no product). Stops when the residual's preconditioned norm is
    ``rtol`` of the right-hand side's (estimated by the start's residual and rhs's plain norms:
    no product spent on it)."""
    Ax = apply(x) if Ax is None else Ax.copy()
    r = project(rhs - Ax[idx])
    z = project(precond(r))
    p = z.copy()
    rz = r @ z
    nr = np.linalg.norm(r)
    stop = rtol * max(np.sqrt(abs(rz)) * np.linalg.norm(project(rhs)) / max(nr, 1e-300), 1e-300)
    steps = 0
    while np.sqrt(abs(rz)) > stop and steps < budget:
        Ap = apply(p)
        pAp = p @ Ap[idx]
        if pAp <= 0:
            break
        a = rz / pAp
        x = x + a * p
        Ax += a * Ap
        r = r - a * project(Ap[idx])
        z = project(precond(r))
        rz, rz_old = r @ z, rz
        p = z + (rz / rz_old) * p
        steps += 1
    return x, steps, Ax


def active_set_pcg(matvec: Callable, q, *, precond: Callable | None = None, G=None, b=None, x0=None,
                   active=None, c: float = 1.0, tol: float = 1e-8, maxiter: int = 20000,
                   max_outer: int = MAX_OUTER, precise: Callable | None = None) -> ActiveSetResult:
    """Solve the module's QP; ``active`` (bool, m) or ``x0`` start the set (default: where the
    gradient at x0, or at 0, is negative); ``precise``: a more accurate (dearer) product for the
    residuals of the last solves, once the set has settled. See the module's contract."""
    q = np.asarray(q, dtype=float)
    m = q.size
    k = 0 if G is None else G.shape[1]
    Gm = np.zeros((m, 0)) if G is None else np.asarray(G, dtype=float)
    b = np.zeros(0) if G is None else np.asarray(b, dtype=float)
    count = [0]

    def M(v, dear=False):
        count[0] += 1
        return (precise if dear and precise is not None else matvec)(v)

    P = precond or (lambda v: v)
    x = np.zeros(m) if x0 is None else np.maximum(np.asarray(x0, dtype=float), 0.0)
    alpha = np.zeros(k)
    Mx = M(x)
    g = Mx + q
    if k:  # the equalities' multipliers that fit the start best where it presses (everywhere at 0)
        on = x > 0 if np.any(x > 0) else np.ones(m, dtype=bool)
        alpha = np.linalg.lstsq(Gm[on], g[on], rcond=None)[0]
        g = g - Gm @ alpha
    A = np.asarray(active, dtype=bool).copy() if active is not None else (x - c * g) > 0
    seen, steps, status, message = set(), 0, "cycled", f"{max_outer} active sets tried"
    # final: the set has settled once; Mx is then the accurate product of x (dear), fresh: of x as it is
    final, fresh, rounds, best = False, True, 0, np.inf
    sets = 1
    while True:
        idx = np.flatnonzero(A)
        GA = Gm[idx]
        if k and (idx.size < k or np.linalg.matrix_rank(GA) < k):
            status, message = "singular", f"the {idx.size} rows in the set do not hold the equalities"
            break
        GtG = GA.T @ GA if k else None

        def project(v):
            return v - GA @ np.linalg.solve(GtG, GA.T @ v) if k else v

        def apply(v):
            z = np.zeros(m)
            z[idx] = v
            return M(z)

        def pre(v):
            z = np.zeros(m)
            z[idx] = v
            return P(z)[idx]

        xa = x[idx]
        if k:  # onto G_Aᵀ x = b
            xa = xa + GA @ np.linalg.solve(GtG, b - GA.T @ xa)
        # the last product is still this start's where x is zero off A and no equality moved it
        known = fresh and not np.any(x[~A]) and (not k or np.array_equal(xa, x[idx]))
        if not final:
            xa, n, Mx = _pcg(apply, idx, -q[idx], xa, pre, project, INNER_RTOL, maxiter - count[0],
                             Mx if known else None)
        else:  # refinement: the accurate product's residual, corrected by CG on the plain one
            if not known:
                x = np.zeros(m)
                x[idx] = xa
                Mx = M(x, dear=True)
            r = -(Mx + q)[idx]
            scale = max(np.linalg.norm(q), np.linalg.norm(Mx), 1e-300)
            rtol = min(max(REFINE_AIM * tol * scale / max(np.linalg.norm(project(r)), 1e-300), REFINE_RTOL), 0.5)
            d, n, _ = _pcg(apply, idx, r, np.zeros(idx.size), pre, project, rtol, maxiter - count[0], np.zeros(m))
            xa = xa + d
            rounds += 1
        steps += n
        x = np.zeros(m)
        x[idx] = xa
        if final:  # the correction's product is the plain one's: the residual anew, accurate
            Mx = M(x, dear=True)
        alpha = np.linalg.lstsq(GA, (Mx + q)[idx], rcond=None)[0] if k else alpha
        g = Mx + q - Gm @ alpha
        fresh = True
        if count[0] >= maxiter:
            status, message = "max_iter", f"{count[0]} products"
            break
        new = (x - c * g) > 0
        if np.array_equal(new, A) and not final:  # settled: refine it on the accurate product, if given
            final = True
            if precise is not None:
                Mx = M(x, dear=True)
                alpha = np.linalg.lstsq(GA, (Mx + q)[idx], rcond=None)[0] if k else alpha
                g = Mx + q - Gm @ alpha
                new = (x - c * g) > 0
        if np.array_equal(new, A):
            scale = max(np.linalg.norm(q), np.linalg.norm(Mx), np.linalg.norm(Gm @ alpha), 1e-300)
            natural = np.linalg.norm(np.minimum(x, g)) / scale
            eq = np.linalg.norm(Gm.T @ x - b) / max(np.linalg.norm(b), np.linalg.norm(Gm, 2) * np.linalg.norm(x), 1e-300) if k else 0.0
            if natural <= tol and eq <= tol:
                status, message = "optimal", f"set settled after {sets} sets, natural residual {natural:.1e}"
                break
            if natural > 0.5 * best or rounds >= MAX_ROUNDS:
                status, message = "stalled", f"the settled set's natural residual {natural:.1e} stays above {tol:.0e}"
                break
            best = natural
            continue
        key = new.tobytes()
        if key in seen:
            status, message = "cycled", f"an active set came back after {sets} sets"
            break
        if sets >= max_outer:
            break
        seen.add(key)
        A, sets, best = new, sets + 1, np.inf
    return ActiveSetResult(np.maximum(x, 0.0), alpha, g, steps, count[0], sets, status, message)
