r"""A matrix-free solver for convex QPs with bounds and a few equalities: MPRGP inside SMALBE.

Solves

.. math::
    \min_x \tfrac12 x^T M x + q^T x \quad\text{s.t.}\quad x \ge \ell,\quad G^T x = b,

``M`` symmetric positive semidefinite and known only through ``matvec(v) = M v``, ``ℓ`` a scalar
or an array of finite values and ``−inf`` (no bound), ``G`` dense ``m × k`` with small ``k``
(``None``: no equality). ``M`` must be positive definite on the null space of ``Gᵀ`` for the
answer to be unique (a floating plate's condensed compliance, whose null space is spanned by
the columns of ``G``); otherwise one minimiser is returned.

Contract:

- **Method.** Dostál's MPRGP (conjugate gradients on the free set, expansion steps of fixed
  length ``ᾱ = ALPHA_FACTOR / ‖M‖``, proportioning steps on the chopped gradient) for the
  bounds; Dostál's SMALBE (augmented Lagrangian with a penalty ``ρ`` that grows when the
  Lagrangian does not increase enough) for the equalities. ``‖M‖`` is estimated by at most
  ``POWER_STEPS`` power iterations (one matvec each). ``diag`` (``M``'s diagonal) switches on
  Jacobi scaling: the same method on ``D^{-1/2} M D^{-1/2}``, which keeps bounds as bounds.
- **Answer.** ``x ≥ ℓ`` always; ``alpha`` the multipliers of the equalities and
  ``g = M x + q − G alpha`` (so ``g ≥ 0`` where ``x`` is at its bound, ``g = 0`` where free).
- **Status.** ``"optimal"`` only if, with ``g`` from a fresh matvec,
  ``‖gᴾ‖ ≤ tol · max(‖q‖, ‖Mx‖, ‖G alpha‖)`` (``gᴾ`` the projected gradient) and
  ``‖Gᵀx − b‖ ≤ tol · max(‖b‖, ‖G‖₂ ‖x‖)``: both scales move with ``q`` and ``M``, so that
  scaling the problem does not change the answer. ``"unbounded"``: a direction of zero
  curvature and descent that no bound stops was met (``x`` is the last iterate).
  ``"max_iter"``: ``maxiter`` steps taken. ``"stalled"``: the projected gradient made no
  progress in ``STALL_STEPS`` steps (rounding), or the equality residual in ``STALL_ROUNDS``
  rounds, or the penalty grew past ``RHO_LIMIT`` times its start (equalities that the bounds
  make infeasible). ``message`` says why, in one line.
- **Cost.** ``matvecs`` counts every call of ``matvec``: the power iterations, one per CG or
  proportioning step, two per expansion step, one per fresh gradient. ``iterations`` counts
  the MPRGP steps of every SMALBE round. No ``m × m`` array is formed; no input is changed.

The method, its stopping rule and references: docs/design/mprgp.md.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import ProblemError

__all__ = ["BoundQPResult", "backends", "mprgp_lcp", "solve_bound_qp"]

#: ``ᾱ = ALPHA_FACTOR / ‖A‖``: inside MPRGP's range ``(0, 2/‖A‖]`` with room for the estimate of ``‖A‖``
#: being low (power iterations approach ``‖A‖`` from below); halved whenever an expansion step
#: raises the cost.
ALPHA_FACTOR = 1.8
#: Proportioning parameter Γ: a proportioning step when ``‖β‖² > Γ² φ̃ᵀφ``.
GAMMA = 1.0
#: Power iterations for ``‖M‖``: at most this many, fewer once the estimate changes by < 1 %.
POWER_STEPS = 12
#: SMALBE: the start ``ρ₀ = RHO_START · ‖M‖ / ‖G‖₂²``, the growth factor, and the limit ``ρ / ρ₀``.
RHO_START, RHO_GROWTH, RHO_LIMIT = 1.0, 10.0, 1e10
#: SMALBE's inner tolerance: ``‖gᴾ‖ / scale_g ≤ min(ETA, INNER_M · ‖Gᵀx − b‖ / scale_e)``.
ETA, INNER_M = 1e-1, 1.0
#: Steps without a new best projected gradient (by 0.1 %) after which the solve is stalled.
STALL_STEPS = 500
#: SMALBE rounds without a new best equality residual (by 0.1 %) after which the solve is stalled.
STALL_ROUNDS = 50
#: A curvature ``pᵀAp ≤ CURVATURE_FLOOR · ‖A‖ ‖p‖²`` counts as zero.
CURVATURE_FLOOR = 1e-13


@dataclass(frozen=True)
class BoundQPResult:
    """The answer of :func:`solve_bound_qp` (see the module's contract for each field)."""

    x: np.ndarray
    alpha: np.ndarray
    g: np.ndarray
    iterations: int
    matvecs: int
    status: str
    message: str
    projected_gradient: float  # ‖gᴾ‖
    gradient_scale: float  # max(‖q‖, ‖Mx‖, ‖G alpha‖)
    equality_residual: float  # ‖Gᵀx − b‖
    equality_scale: float  # max(‖b‖, ‖G‖₂ ‖x‖)
    norm_estimate: float  # the estimate of ‖M‖ (of the scaled M with diag)
    rho: float  # the final penalty (0 without equalities)
    outer_iterations: int  # SMALBE rounds


@dataclass
class _Problem:
    """The validated problem in scaled variables ``y = w x`` (``w = √diag`` or ones)."""

    matvec: Callable
    q: np.ndarray
    lb: np.ndarray
    G: np.ndarray
    b: np.ndarray
    w: np.ndarray
    norm_G: float  # ‖G‖₂ of the unscaled G
    calls: int = 0

    def M(self, y: np.ndarray) -> np.ndarray:
        self.calls += 1
        out = np.asarray(self.matvec(y / self.w), dtype=float)
        if out.shape != y.shape or not np.all(np.isfinite(out)):
            raise ProblemError(f"matvec returned {'non-finite values' if out.shape == y.shape else f'shape {out.shape}'}"
                               f" for a finite vector of shape {y.shape}")
        return out / self.w

    def unscaled_norm(self, v: np.ndarray) -> float:
        """‖·‖ of a gradient-like vector back in the caller's variables (``g = w ⊙ g̃``)."""
        return float(np.linalg.norm(self.w * v))


def _array(name: str, value, shape: tuple[int, ...], allow_neg_inf: bool = False) -> np.ndarray:
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError) as exn:
        raise ProblemError(f"{name}: not an array of numbers") from exn
    if a.shape != shape:
        raise ProblemError(f"{name}: shape {a.shape}, expected {shape}")
    bad = np.isnan(a) | (a == np.inf) | ((a == -np.inf) & (not allow_neg_inf))
    if bad.any():
        raise ProblemError(f"{name}: {'NaN or infinite' if not allow_neg_inf else 'NaN or +inf'} at index "
                           f"{np.flatnonzero(bad.ravel())[0]}")
    return a


def _check(matvec, q, lb, G, b, x0, tol, maxiter, diag, callback) -> tuple[_Problem, np.ndarray]:
    if not callable(matvec):
        raise ProblemError("matvec: not callable")
    if callback is not None and not callable(callback):
        raise ProblemError("callback: not callable")
    if not (isinstance(tol, (int, float, np.floating)) and np.isfinite(tol) and tol > 0):
        raise ProblemError(f"tol: must be a positive number, got {tol!r}")
    if not (isinstance(maxiter, (int, np.integer)) and maxiter >= 1):
        raise ProblemError(f"maxiter: must be a positive integer, got {maxiter!r}")
    q = np.array(q, dtype=float)
    if q.ndim != 1 or q.size == 0:
        raise ProblemError(f"q: must be a nonempty 1-D array, got shape {q.shape}")
    m = q.size
    q = _array("q", q, (m,))
    lb = _array("lb", np.broadcast_to(lb, (m,)) if np.ndim(lb) == 0 else lb, (m,), allow_neg_inf=True)
    if G is None:
        if b is not None:
            raise ProblemError("b: given without G")
        G, b = np.zeros((m, 0)), np.zeros(0)
    else:
        G = np.array(G, dtype=float)
        G = _array("G", G, (m, G.shape[1] if G.ndim == 2 else -1))
        b = _array("b", np.zeros(G.shape[1]) if b is None else b, (G.shape[1],))
    w = np.ones(m)
    if diag is not None:
        d = _array("diag", diag, (m,))
        if np.any(d <= 0):
            raise ProblemError("diag: must be positive (M's diagonal)")
        w = np.sqrt(d)
    x0 = np.maximum(lb, 0.0) if x0 is None else np.maximum(_array("x0", x0, (m,)), lb)
    x0 = np.where(np.isfinite(x0), x0, 0.0)  # lb = −inf and no x0: start at 0
    norm_G = float(np.sqrt(np.linalg.eigvalsh(G.T @ G)[-1])) if G.shape[1] else 0.0
    prob = _Problem(matvec, q / w, lb * w, G / w[:, None], b, w, norm_G)
    return prob, x0 * w


def _norm_estimate(prob: _Problem) -> float:
    """Power iterations on the scaled M from a fixed pseudo-random start: a lower estimate of ‖M‖."""
    v = np.random.default_rng(0).standard_normal(prob.q.size)
    v /= np.linalg.norm(v)
    est = 0.0
    for _ in range(POWER_STEPS):
        Mv = prob.M(v)
        new = float(np.linalg.norm(Mv))
        if new == 0.0:
            return 0.0
        v = Mv / new
        if abs(new - est) <= 1e-2 * new:
            return new
        est = new
    return est


@dataclass
class _Round:
    """One SMALBE round's data: the penalty, multipliers and the augmented problem's pieces."""

    prob: _Problem
    rho: float
    alpha: np.ndarray
    normM: float  # the estimate of ‖M‖
    normA: float = 1.0  # of ‖A_ρ‖ = ‖M‖ + ρ‖G‖₂²

    @property
    def c(self) -> np.ndarray:  # linear term of L(·, α, ρ) = ½yᵀA_ρy + cᵀy + const
        return self.prob.q - self.prob.G @ (self.alpha + self.rho * self.prob.b)

    def A(self, y: np.ndarray) -> np.ndarray:  # A_ρ = M + ρ G Gᵀ
        return self.prob.M(y) + self.rho * (self.prob.G @ (self.prob.G.T @ y))

    def measures(self, y: np.ndarray, g: np.ndarray) -> tuple[float, float, float, float]:
        """(‖gᴾ‖, scale_g, ‖Gᵀx − b‖, scale_e) in the caller's variables, with the multipliers
        α − ρ r that make ``g`` the gradient of the Lagrangian."""
        p = self.prob
        r = p.G.T @ y - p.b
        Galpha = p.G @ (self.alpha - self.rho * r)
        free = y > p.lb
        gp = np.where(free, g, np.minimum(g, 0.0))
        scale_g = max(p.unscaled_norm(p.q), p.unscaled_norm(g - p.q + Galpha), p.unscaled_norm(Galpha))
        scale_e = max(float(np.linalg.norm(p.b)), p.norm_G * float(np.linalg.norm(y / p.w)))
        return p.unscaled_norm(gp), scale_g, float(np.linalg.norm(r)), scale_e


def _parts(y, g, lb, abar):
    """Free gradient φ, chopped gradient β and reduced free gradient φ̃ at y."""
    free = y > lb
    phi = np.where(free, g, 0.0)
    beta = np.where(free, 0.0, np.minimum(g, 0.0))
    with np.errstate(invalid="ignore"):  # (y − lb) = inf where lb = −inf: min(inf, g) = g
        phit = np.where(free, np.minimum((y - lb) / abar, g), 0.0)
    return phi, beta, phit


def _max_step(y, p, lb) -> tuple[float, int]:
    """The longest step a ≥ 0 with y − a p ≥ lb, and the index that blocks it (−1: none)."""
    idx = np.flatnonzero((p > 0) & np.isfinite(lb))
    if idx.size == 0:
        return np.inf, -1
    steps = (y[idx] - lb[idx]) / p[idx]
    j = int(np.argmin(steps))
    return max(float(steps[j]), 0.0), int(idx[j])


@dataclass
class _Inner:
    y: np.ndarray
    g: np.ndarray
    steps: int
    outcome: str  # "done", "unbounded", "max_iter", "stalled"


def _mprgp(rd: _Round, y, g, abar, stop, budget, on_step) -> _Inner:
    """MPRGP on min ½yᵀA_ρy + cᵀy, y ≥ lb, from y with gradient g, until ``stop(y, g)`` holds for a
    fresh gradient; at most ``budget`` steps."""
    lb, c = rd.prob.lb, rd.c
    p = _parts(y, g, lb, abar)[0]
    best, since, cost, fresh = np.inf, 0, 0.5 * y @ (g + c), True
    for step in range(budget + 1):
        if stop(y, g):
            if fresh:
                return _Inner(y, g, step, "done")
            g, fresh = rd.A(y) + c, True
            p = _parts(y, g, lb, abar)[0]
            if stop(y, g):
                return _Inner(y, g, step, "done")
        if step == budget:
            return _Inner(y, g, step, "max_iter")
        phi, beta, phit = _parts(y, g, lb, abar)
        norm = float(np.linalg.norm(phi + beta))
        best, since = (norm, 0) if norm < 0.999 * best else (best, since + 1)
        if since > STALL_STEPS:
            return _Inner(y, g, step, "stalled")
        fresh = False
        if beta @ beta <= GAMMA**2 * (phit @ phi):
            if g @ p <= 0:  # rounding spoilt the conjugate direction: restart
                p = phi
            Ap = rd.A(p)
            pAp = float(p @ Ap)
            acg = float(g @ p) / pAp if pAp > CURVATURE_FLOOR * rd.normA * (p @ p) else np.inf
            af, j = _max_step(y, p, lb)
            if acg <= af and acg < np.inf:  # conjugate gradient step
                y, g = y - acg * p, g - acg * Ap
                phi = _parts(y, g, lb, abar)[0]
                p = phi - (phi @ Ap) / pAp * p
            elif af == np.inf:
                return _Inner(y, g, step, "unbounded")
            else:  # expansion step: to the bound, then a fixed-step projected gradient step
                y, g = np.maximum(y - af * p, lb), g - af * Ap
                y[j] = lb[j]
                phi = _parts(y, g, lb, abar)[0]
                y = np.maximum(y - abar * phi, lb)
                g, fresh = rd.A(y) + c, True
                new_cost = 0.5 * y @ (g + c)
                if new_cost > cost + 1e-12 * abs(cost):  # ᾱ above 2/‖A‖: the estimate was low
                    abar /= 2
                p = _parts(y, g, lb, abar)[0]
        else:  # proportioning step along the chopped gradient
            Ab = rd.A(beta)
            bAb = float(beta @ Ab)
            if bAb <= CURVATURE_FLOOR * rd.normA * (beta @ beta):
                return _Inner(y, g, step, "unbounded")
            a = float(beta @ beta) / bAb
            y, g = y - a * beta, g - a * Ab
            p = _parts(y, g, lb, abar)[0]
        cost = 0.5 * y @ (g + c)
        on_step(y)
    raise AssertionError("unreachable")  # pragma: no cover


MESSAGES = {
    "unbounded": "unbounded: a direction of descent with zero curvature that no bound stops",
    "max_iter": "maxiter reached before the projected gradient and the equality residual met tol",
    "stalled": "stalled: the projected gradient stopped falling above tol (rounding; try a larger tol)",
}


def _smalbe(prob: _Problem, y, maxiter, tol, callback):
    """SMALBE's rounds around MPRGP; returns (round, y, g, steps, rounds, status, message)."""
    normM = _norm_estimate(prob)
    k = prob.G.shape[1]
    normG2 = float(np.linalg.norm(prob.G, 2) ** 2) if k else 0.0
    rho0 = RHO_START * normM / normG2 if k and normM > 0 else (1.0 / normG2 if k else 0.0)
    rd = _Round(prob, rho0, np.zeros(k), normM)
    steps, rounds, lagr_prev, best, since = 0, 0, -np.inf, np.inf, 0
    infeasible = ("stalled: the equality residual stopped falling above tol: the equalities may be "
                  "infeasible with the bounds")

    def on_step(yy):
        nonlocal steps
        steps += 1
        if callback is not None:
            callback(steps, yy / prob.w)

    def final(yy, gg):
        gp, sg, res, se = rd.measures(yy, gg)
        return gp <= tol * sg and res <= tol * se

    def inner_stop(yy, gg):
        gp, sg, res, se = rd.measures(yy, gg)
        return final(yy, gg) or (k > 0 and gp <= sg * min(ETA, INNER_M * res / se if se > 0 else np.inf))

    g = rd.A(y) + rd.c
    while True:
        rounds += 1
        rd.normA = max(normM + rd.rho * normG2, np.finfo(float).tiny)
        budget = maxiter - steps - (rounds - 1)  # a round costs at least one step of the budget
        if budget <= 0:
            return rd, y, g, steps, rounds, "max_iter", MESSAGES["max_iter"]
        inner = _mprgp(rd, y, g, ALPHA_FACTOR / rd.normA, inner_stop, budget, on_step)
        y, g = inner.y, inner.g
        if inner.outcome != "done":
            return rd, y, g, steps, rounds, inner.outcome, MESSAGES[inner.outcome]
        if final(y, g):
            return rd, y, g, steps, rounds, "optimal", "optimal: the KKT conditions hold to tol"
        r = prob.G.T @ y - prob.b
        lagr = 0.5 * y @ (g + rd.c) + rd.alpha @ prob.b + 0.5 * rd.rho * (prob.b @ prob.b)
        My = g - rd.c - rd.rho * (prob.G @ (prob.G.T @ y))
        rho = rd.rho * RHO_GROWTH if lagr < lagr_prev + 0.5 * rd.rho * (r @ r) else rd.rho
        best, since = (float(r @ r), 0) if r @ r < 0.998 * best else (best, since + 1)
        if rho > RHO_LIMIT * rho0 or since > STALL_ROUNDS:
            return rd, y, g, steps, rounds, "stalled", infeasible
        lagr_prev = lagr
        rd = _Round(prob, rho, rd.alpha - rd.rho * r, normM)
        g = My + rho * (prob.G @ (prob.G.T @ y)) + rd.c  # the new round's gradient, without a matvec


def solve_bound_qp(matvec: Callable[[np.ndarray], np.ndarray], q, *, lb=0.0, G=None, b=None, x0=None,
                   tol: float = 1e-8, maxiter: int = 10_000, diag=None,
                   callback: Callable[[int, np.ndarray], None] | None = None) -> BoundQPResult:
    """Minimise ½xᵀMx + qᵀx subject to x ≥ lb and Gᵀx = b, with M given by ``matvec``.

    ``lb``: scalar or ``(m,)`` array, ``−inf`` for no bound. ``G``: ``(m, k)`` or ``None``;
    ``b``: ``(k,)`` (zeros by default). ``x0``: a start, projected onto the bounds (default: the
    0 projected onto the bounds). ``tol``: the relative accuracy of the stopping rule.
    ``maxiter``: the most MPRGP steps in all. ``diag``: M's diagonal, for Jacobi scaling.
    ``callback(it, x)``: called after each step. Bad input raises
    :class:`~plateqp.errors.ProblemError` naming the argument.
    """
    prob, y = _check(matvec, q, lb, G, b, x0, tol, maxiter, diag, callback)
    rd, y, g, steps, rounds, status, message = _smalbe(prob, y, maxiter, tol, callback)
    r = prob.G.T @ y - prob.b
    alpha = rd.alpha - rd.rho * r
    gp, sg, res, se = rd.measures(y, g)
    return BoundQPResult(x=y / prob.w, alpha=alpha, g=g * prob.w, iterations=steps, matvecs=prob.calls,
                         status=status, message=message, projected_gradient=gp, gradient_scale=sg,
                         equality_residual=res, equality_scale=se,
                         norm_estimate=rd.normM,
                         rho=rd.rho, outer_iterations=rounds)


# -- as a backend: LCP(M, q) with M symmetric positive semidefinite (the condensed and dual forms) ---------

#: The stopping tolerance of each accuracy preset (the contract's rule on ‖gᴾ‖).
ACCURACY: dict[str, dict[str, float]] = {"low": {"tol": 1e-6}, "default": {"tol": 1e-9}, "high": {"tol": 1e-12}}
#: Keys accepted in the ``options`` dict of the backend's ``solve``.
OPTIONS = ("max_iter", "z0") + tuple(ACCURACY["default"])
#: The products at most, unless ``max_iter`` says otherwise.
MAX_ITER = 20_000


def mprgp_lcp(M, q, max_iter=None, z0=None, *, accuracy="default", tol=None):
    """LCP(M, q) (M symmetric positive semidefinite) as min ½ zᵀMz + qᵀz, z ≥ 0, by
    :func:`solve_bound_qp` on the products of M: the backend ``mprgp`` of the standard forms (a
    half-space held matrix-free is solved in :mod:`plateqp.contact.pressures` instead)."""
    import time

    import scipy.sparse as sp

    from .base import Status
    from .lcp import answer, check_int, settings

    t0 = time.perf_counter()
    s = settings(ACCURACY, accuracy, ("tol",), tol=tol)
    M = M.toarray() if sp.issparse(M) else np.asarray(M, dtype=float)
    q = np.asarray(q, dtype=float)
    limit = MAX_ITER if max_iter is None else check_int("max_iter", max_iter, 1)
    out = solve_bound_qp(lambda v: M @ v, q, lb=0.0, x0=z0, tol=s["tol"], maxiter=limit)
    status = {"optimal": Status.OPTIMAL, "max_iter": Status.MAX_ITER, "unbounded": Status.UNBOUNDED}.get(
        out.status, Status.INACCURATE)
    return answer(q, out.x, M @ out.x + q, status, t0, out.iterations, out.message,
                  {"matvecs": out.matvecs, "active": out.x == 0})


def backends() -> list:
    """The backend this module provides: ``mprgp``, iterative, warm-started by ``z0``."""
    from .lcp import LCPBackend

    return [LCPBackend("mprgp", mprgp_lcp, OPTIONS, exact=False)]
