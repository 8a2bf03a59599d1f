r"""The sparse method's exact steps (:func:`run_sparse`): from the first phase's set
(:mod:`.sparse`), each active set solved (loosely, then to rounding), the rows a free rigid motion
presses let in, a floating plate's hold on its final set checked, and the infeasible rows
exchanged until none is left."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..base import Status
from .factor import SpringFactor
from .motions import exact_motion, free_mode, free_motion, rows_hold
from .options import FREE_FLOOR, FREE_MOTIONS, FREE_WORK, NEWTON_SETTLED, RAY_MESSAGE
from .reduced import Exchange, Outcome, ReducedQP, infeasible
from .sparse import anchored_plate, dual_newton, held_plate, lawson_hanson, newton_pcg, solve_active

__all__ = ["run_sparse"]


@dataclass
class _Start:
    """Where the exact steps start: the first phase's deflection, reactions and set (None: every
    row), whether its set is solved exactly at once, its steps, and whether it found the plate
    floating."""

    u: np.ndarray
    lam: np.ndarray
    A: np.ndarray | None
    exact: bool = False
    newton: int = 0
    floating: bool = False


def _first_phase(pb: ReducedQP, fac, W, sigma, A, feas_tol, steps, kfac, info: dict, lh: bool, dual: bool,
                 anchor: bool) -> _Start:
    """The first phase of :func:`run_sparse` (see there), and its account in ``info``."""
    u, lam = np.zeros(pb.K.shape[0]), np.zeros(pb.m)
    if np.all(pb.rho * pb.k >= 1.0):  # soft rows only: phase 1, from the warm start's set if any
        u, A, newton = newton_pcg(pb, fac, W, sigma, steps, A)
        info.update(first_phase="newton", first_phase_steps=newton)
        return _Start(u, np.where(A, W * (pb.B @ u - pb.g), 0.0), A, True, newton)
    if A is not None or kfac is None:
        return _Start(u, lam, A, exact=A is not None)  # a warm start is meant to be (nearly) right: exact at once
    # stiff rows, cold start: a first phase on the dual
    uf = held_plate(pb, kfac, sigma)  # None: a floating plate
    floating = uf is None
    anchored = False
    if uf is None and lh and anchor:  # Lawson–Hanson on the anchored plate's flexibility
        uf = anchored_plate(pb, kfac, sigma)
        anchored = uf is not None
    first = lam0 = None
    spent = 0  # the sets Lawson–Hanson solved before it gave up (iterations count them)
    if uf is not None and lh:
        first = lawson_hanson(pb, kfac, uf, feas_tol, steps, info, anchored)
        phase = "anchored lawson-hanson" if anchored else "lawson-hanson"
        if first.u is None:  # gave up: its reactions start the projected Newton phase
            first, lam0, spent = None, first.lam, first.steps
    if first is None and uf is not None and dual and not anchored:  # (its ψ is the held plate's)
        first = dual_newton(pb, fac, kfac, W, sigma, feas_tol, steps, uf, lam0)
        phase = "dual"
    if first is not None:
        info.update(first_phase=phase, first_phase_steps=first.steps)
        return _Start(first.u, first.lam, first.A, True, spent + first.steps, floating)
    if anchored and lam0 is not None and np.any(lam0 > 0):
        # Lawson–Hanson gave up on the anchored plate: the exact steps start from the rows it
        # holds and the rows still pressed at its reactions (not from every row)
        ua = kfac.solve(pb.f - pb.B.T @ lam0)
        A = (lam0 > 0) | (pb.g + pb.rho * lam0 - pb.B @ ua <= 0)
        info.update(first_phase="anchored lawson-hanson (gave up)")
    return _Start(u, lam, A, False, spent, floating)


def _judge_motion(pb: ReducedQP, fac, A, null: list, d, left_exact: set):
    """A free rigid motion ``d`` of the active set ``A``, judged by the load's work along it:
    ("error", d) where it is no rigid motion of the plate; ("unbounded", the ray) where the load
    does work along it and no row stops it; (rows, d) where the load pushes along −d into rows
    not in ``A`` that make a set not already left on its exact step (they enter); (None, d):
    no work to rounding (or a push at rounding), so ``d`` is kept out as a free motion."""
    d = free_motion(pb, fac, null, d)  # sharpened: its work and K d judged on rounding
    exact_d = exact_motion(pb, A, null, d)  # the exact rigid motion, where the QP names them
    d = d if exact_d is None else exact_d
    Bd = pb.B @ d
    scale = np.abs(Bd).max(initial=0.0)
    Kd_rel = np.abs(pb.K @ d).max() / (pb.Kd.max() * np.abs(d).max())
    if Kd_rel > 1e-6 or len(null) >= FREE_MOTIONS:
        return "error", d
    work = float(pb.f @ d)
    # rounding: the sum's own (FREE_WORK Σ|f_j d_j|), and d's, which for a load on the axis of d
    # is all of Σ|f_j d_j| (FREE_FLOOR of the whole load moved by d's largest motion)
    no_work = (FREE_WORK * float(np.abs(pb.f) @ np.abs(d))
               + FREE_FLOOR * float(np.abs(pb.f).sum()) * float(np.abs(d).max()))
    if work > no_work and np.all(Bd <= 1e-9 * scale):
        return "unbounded", d
    if work < -no_work:  # the load pushes along −d
        hit = ~A & (Bd < -1e-9 * scale)
        if not hit.any():
            return "unbounded", -d
        if (A | hit).tobytes() not in left_exact:
            return hit, d
        # those rows, in, made a set already solved and left on its exact step: the push is at
        # rounding (a load 1e-10 inside the hull of four posts at 128² cycled {4} → {3} → {2} →
        # {4}); d is kept out as a free motion, and the answer's stationarity residual shows the
        # work left along it
    return None, d


@dataclass
class _Held:
    """What a set's step left (:func:`_step_held`): the solved ``step`` (None where the set changed
    or the method ends), the set ``A``, whether it is to be solved exactly, and an ``outcome`` that
    ends the method (the plate cannot be held)."""

    step: object | None
    A: np.ndarray
    exact: bool
    outcome: Outcome | None = None


def _step_held(pb: ReducedQP, fac: SpringFactor, W, sigma, A, u, lam, exact: bool, null: list, pending,
               left_exact: set, steps, it: int, newton: int) -> _Held:
    """Solve the active set ``A`` (after the free rigid motion ``pending``, if one is to be judged).
    While its rows leave the plate free to move along a rigid motion d: the rows d presses enter
    (the set changes), a motion along which the load does no work is kept out of the steps
    (appended to ``null``), and a plate the load pushes off every row, or a null direction of K
    that is no rigid motion, ends the method."""
    while True:
        if pending is not None:
            d, pending, solves = pending, None, 2  # free_mode's two solves
        else:
            step = solve_active(pb, fac, W, A, u, lam, sigma, exact, null)
            if step.ray is not None and not fac.clean:  # judge a free rigid motion on a clean factor
                fac.refactor(np.where(A, W, 0.0))
                step = solve_active(pb, fac, W, A, u, lam, sigma, exact, null)
            if step.ray is None:
                return _Held(step, A, exact)
            d, solves = step.ray, step.solves
        # the active rows do not hold the plate: it can move along d
        Bd = pb.B @ d
        scale = np.abs(Bd).max(initial=0.0)
        hit = ~A & (Bd > 1e-9 * scale)
        if steps is not None:
            steps.append({"step": it, "active": int(A.sum()), "infeasible": None, "solve": "singular",
                          "solves": solves, "entering": int(hit.sum())})
        if hit.any():
            return _Held(None, A | hit, False)
        verdict, d = _judge_motion(pb, fac, A, null, d, left_exact)
        if isinstance(verdict, str):  # "error" or "unbounded": the plate cannot be held
            if verdict == "error":
                return _Held(None, A, exact, Outcome(Status.ERROR, "the active rows leave a null direction of K "
                                                     "that is not a rigid motion of the plate: cannot go on",
                                                     A, it=newton + it))
            ray = np.zeros(pb.n)
            ray[pb.keep] = d  # (d, 0): P (d, 0) = 0, G (d, 0) = B d ≤ 0, qᵀ(d, 0) = −fᵀd < 0
            return _Held(None, A, exact, Outcome(Status.UNBOUNDED, RAY_MESSAGE, A, it=newton + it, ray=ray))
        if verdict is not None:  # the rows it presses enter
            return _Held(None, A | verdict, False)
        # the load does no work along d (to rounding): every u + t d is as good; keep d out of the steps
        null.append(d)


def _hold_check(pb: ReducedQP, fac: SpringFactor, W, A, null: list, sigma, info: dict):
    """A floating plate whose set looks optimal: do the active rows hold it? A rigid motion the
    load barely works along can escape the first correction's test (the elastic part of that
    correction outweighs it): the plate's rigid motions, held, need no solve; else two inverse
    iterations with H_A find a free one, on the factor in hand (a Woodbury correction or a
    downdate loses at most DOWNDATE_LOSS: a free motion still outgrows every held mode by λ/σ).
    The free mode to judge, or None."""
    if not null and rows_hold(pb, W, A, sigma):
        info["hold_check"] = "rigid motions"
        return None
    info["hold_check"] = "inverse iteration"
    return free_mode(pb, fac, W, A, null, sigma)


def run_sparse(pb: ReducedQP, fac: SpringFactor, W, sigma, A, feas_tol, max_iter, p, steps,
               kfac: SpringFactor | None = None, info: dict | None = None, lh: bool = True,
               dual: bool = True, floating: bool = False, anchor: bool = True) -> Outcome:
    """The sparse method: a first phase where it applies (soft rows: :func:`newton_pcg`; stiff
    rows on a held plate with ``kfac``, a factor for ``K`` alone: :func:`lawson_hanson` if
    ``lh``, then, where it gave up, :func:`dual_newton` if ``dual``), then exact steps. ``info``
    (a dict) receives ``first_phase`` ("newton", "lawson-hanson", "dual" or "none"),
    ``first_phase_steps`` and, where Lawson–Hanson ran, ``lh_sets``, ``lh_columns`` and ``lh_s``.
    ``floating``: ``K`` is known to be singular (as where :func:`held_plate` finds it so): the
    final set is checked to hold the plate (:func:`free_mode`) before it is called optimal.
    ``anchor``: on such a plate, Lawson–Hanson (if ``lh``) runs on the anchored plate's
    flexibility (:func:`anchored_plate`); where it gives up, the exact steps start from the
    rows it holds and those still pressed at its reactions (the projected Newton phase needs
    the plate's own ``K⁻¹``)."""
    info = {} if info is None else info
    info.update(first_phase="none", first_phase_steps=0)
    ex = Exchange(p)
    left_exact: set = set()  # sets left on their exact step's verdict
    start = _first_phase(pb, fac, W, sigma, A, feas_tol, steps, kfac, info, lh, dual, anchor)
    u, lam, A, exact, newton = start.u, start.lam, start.A, start.exact, start.newton
    floating = floating or start.floating
    A = np.ones(pb.m, dtype=bool) if A is None else A.copy()
    null: list = []  # free rigid motions of A along which the load does no work
    held = True  # the final set's hold on a floating plate checked (or not needed)
    pending = None  # a free rigid motion found by that check, to be judged
    prev = None
    for it in range(1, max_iter + 1):
        fac.set(np.where(A, W, 0.0))
        if prev is None or not np.array_equal(prev, A):
            null, held = [], not floating
            # a set met again is classified on its exact step: a loose step's reactions can call a
            # row that carries almost nothing infeasible every time (a load 1e-10 inside the hull
            # of four posts at 128²: {4} → {3} → {2}, which leaves the turn that brings {4} back)
            exact = exact or A.tobytes() in ex.seen
        prev = A.copy()
        done = _step_held(pb, fac, W, sigma, A, u, lam, exact, null, pending, left_exact, steps, it, newton)
        pending = None
        if done.outcome is not None:
            return done.outcome
        if done.step is None:  # rows entered: the next set
            A, exact = done.A, done.exact
            continue
        step = done.step
        u, lam = step.u, step.lam
        gap = pb.g + pb.rho * lam - pb.B @ u
        bad = infeasible(pb, A, lam, gap, feas_tol)
        if steps is not None:
            steps.append({"step": it, "active": int(A.sum()), "infeasible": int(bad.sum()),
                          "solve": "exact" if exact else "loose", "solves": step.solves})
        if not bad.any():
            if exact and not held:  # a floating plate: do the active rows hold it?
                held = True
                pending = _hold_check(pb, fac, W, A, null, sigma, info)
                if pending is not None:
                    continue
            if exact:
                return Outcome(Status.OPTIMAL, "no infeasible row", A, u, lam, newton + it)
            exact = True  # the set looks right: solve it to rounding and look again
            continue
        if exact:
            left_exact.add(A.tobytes())
        exact = exact and int(bad.sum()) <= NEWTON_SETTLED  # a few rows at the end: stay exact
        A, mode = ex.next(A, bad)
        if steps is not None:
            steps[-1]["exchange"] = mode
    return Outcome(Status.MAX_ITER, f"iteration limit {max_iter} reached", A, u, lam, newton + max_iter)
