r"""Two teaching methods for LCP(M, q) that engineers meet in practice, honest about their failures.

``toggle``: "toggle the springs"
--------------------------------
What general finite-element codes do for tension-only supports (and PyNite's
``tension_only`` members): assume every support in contact, solve, switch off the supports in
tension, switch on those that are penetrated, solve again, until nothing changes. On LCP(M, q)
(find ``z ≥ 0``, ``w = M z + q ≥ 0``, ``zᵀw = 0``) with ``A`` the rows whose z is solved for::

    z_A = −M_AA⁻¹ q_A,  z = 0 elsewhere;   w = M z + q
    A ← {i ∈ A : z_i > 0} ∪ {i ∉ A : w_i < 0}

What ``A`` is depends on the LCP's unknowns (:attr:`plateqp.backends.base.LCP.unknown`). On
the dual form z are the reactions, so ``A`` is the set of supports in contact and the recipe
starts from every row. On the condensed form z are the gaps, so ``A`` is the set lifted off
and "every support in contact" is ``A`` empty: z = 0, w = q, the two-sided solution. That
start holds a floating plate wherever any set of its supports does (all of them hold it, or
the condensed problem could not be formed). A plain LCP ("z") starts from every row.

When ``A`` no longer changes, ``z`` solves the LCP exactly (status ``OPTIMAL`` once the
natural residual confirms it). It is a primal-dual active-set step without safeguards: every
sign change flips at once, and even for a symmetric positive definite ``M`` the sets can
**cycle** (a 4 × 4 example in tests/backends/test_toggle.py). A set seen before ends the iteration
with status ``MAX_ITER`` and "cycled" in ``solver_status`` (``extras["cycle"]`` its length);
so does ``max_iter``. A singular ``M_AA`` (a round's supports in contact leave a rigid motion
of a floating plate free) is status ``ERROR`` with no answer, and ``solver_status`` names the
round and that set of supports in contact (rows numbered from 1, the supports in scene
order); :func:`plateqp.solve` raises a SolverError with it. :mod:`~plateqp.backends.pdas` is
this method with the safeguards that make it finish.

``penalty``: stiff springs instead of one-sided constraints
-----------------------------------------------------------
The penalty method replaces each rigid support by a tension-free spring of stiffness ``k``:
in the LCP's terms a compliance ``1/k`` on the diagonal, LCP(M + ε I, q) with
``ε = ratio · max diag M``, solved exactly (by :mod:`~plateqp.backends.bpp`). Its answer
penetrates each support in contact by ``ε z_i`` (``w_i = −ε z_i``), an error that shrinks like
``ε`` while the conditioning of ``M + ε I`` worsens like ``1/ε``. The status is ``OPTIMAL``
only when that penetration is within the asked accuracy of the original LCP (the natural
residual), ``INACCURATE`` otherwise: the method says what the plate's KKT check would.
Elastic supports are the same thing with a physical ``k``.
"""

from __future__ import annotations

import time

import numpy as np

from ..accuracy import Accuracy
from ..errors import ProblemError
from .base import LCP, RawSolution, Status, check_options
from .bpp import bpp
from .lcp import LCPBackend, answer, check_fraction, check_int, natural_residual, settings

__all__ = ["ACCURACY", "toggle", "penalty", "backends"]

#: Acceptance tolerance of the natural residual for each preset (as bpp's).
ACCURACY: dict[str, dict[str, float]] = {
    "low": {"tol": 1e-6},
    "default": {"tol": 1e-9},
    "high": {"tol": 1e-12},
}

#: Default limit of toggle rounds.
MAX_ITER = 100

#: A contact block M_AA with a larger condition number is taken as singular (status ERROR).
COND_MAX = 1e12

#: On the condensed form (z the gaps) M is the plate's stiffness condensed onto the supports,
#: singular along a floating plate's rigid motions and computed to about cond(K)·ε only (1e-12
#: of its largest eigenvalue seen on a 10 × 10 mesh): M_AA is taken as singular, its supports in
#: contact leaving a rigid motion free, where its smallest eigenvalue is below this share of M's
#: largest.
NULL_SHARE = 1e-9

#: Default penalty compliance relative to max diag M.
RATIO = 1e-8


def toggle(M, q, max_iter=None, *, accuracy="default", tol=None, unknown="z") -> RawSolution:
    """Solve LCP(M, q) by toggling the contact set (module docstring); ``unknown``: what z
    stands for ("z", "reactions" or "gaps"), which sets the start and the words of a failure.

    Returns
    -------
    RawSolution
        ``OPTIMAL`` (the set settled and the natural residual is within ``tol``), ``MAX_ITER``
        (a set repeated: "cycled", ``extras["cycle"]`` its length; or ``max_iter`` rounds),
        ``ERROR`` (a singular ``M_AA``: no ``x``, ``solver_status`` says which round); ``x = z``, ``w``
        of the last round, ``extras``:
        ``sets`` (the contact sets tried, in order), ``natural_residual``.
    """
    t0 = time.perf_counter()
    prob = LCP(M, q, unknown=unknown)
    M, q, n = prob.M, prob.q, prob.n
    tol = settings(ACCURACY, accuracy, ("tol",), tol=tol)["tol"]
    max_iter = check_int("max_iter", MAX_ITER if max_iter is None else max_iter, 1)
    # every support in contact: every z solved for where z are reactions, none where they are gaps
    A = np.full(n, unknown != "gaps")
    sets: list[tuple[int, ...]] = []
    z, w = np.zeros(n), q.copy()
    floor = NULL_SHARE * float(np.abs(np.linalg.eigvalsh(0.5 * (M + M.T))).max(initial=0.0)) if unknown == "gaps" \
        else 0.0
    for it in range(1, max_iter + 1):
        key = tuple(np.flatnonzero(A).tolist())
        if key in sets:
            cycle = len(sets) - sets.index(key)
            return answer(q, z, w, Status.MAX_ITER, t0, it - 1,
                          f"cycled: the contact set of round {sets.index(key) + 1} came back after {cycle} rounds",
                          {"sets": sets, "cycle": cycle, "natural_residual": natural_residual(M, q, z, w)})
        sets.append(key)
        z = np.zeros(n)
        if A.any():
            MAA = M[np.ix_(A, A)]
            cond = np.linalg.cond(MAA)
            lam = float(np.linalg.eigvalsh(0.5 * (MAA + MAA.T))[0]) if floor > 0 else np.inf
            if lam <= floor or not cond < COND_MAX:  # no answer: x None (the caller says why, never shows zeros)
                why = (f"M_AA singular to working precision, condition {cond:.1e}" if not cond < COND_MAX else
                       f"M_AA's smallest eigenvalue {lam / floor * NULL_SHARE:.1e} of M's largest, below "
                       f"{NULL_SHARE:.0e}: a rigid motion free")
                return RawSolution(status=Status.ERROR, iterations=it, solve_time=time.perf_counter() - t0,
                                   solver_status=_singular(it, A, unknown, why), extras={"sets": sets})
            z[A] = np.linalg.solve(MAA, -q[A])
        w = M @ z + q
        new = (A & (z > 0)) | (~A & (w < 0))
        if np.array_equal(new, A):
            res = natural_residual(M, q, np.maximum(z, 0.0), w)
            ok = res <= tol
            return answer(q, np.maximum(z, 0.0), w, Status.OPTIMAL if ok else Status.INACCURATE, t0, it,
                          f"the contact set settled after {it} rounds (natural residual {res:.1e})",
                          {"sets": sets, "natural_residual": res})
        A = new
    return answer(q, z, w, Status.MAX_ITER, t0, max_iter, f"max_iter: {max_iter} rounds",
                  {"sets": sets, "natural_residual": natural_residual(M, q, np.maximum(z, 0.0), w)})


def _singular(it: int, A: np.ndarray, unknown: str, why: str) -> str:
    """Why round ``it`` has no answer, naming the set: the supports in contact (A where z are
    reactions, the rows outside A where z are gaps), or A itself for a plain LCP."""
    def rows(sel):
        idx = np.flatnonzero(sel) + 1
        return f"rows {', '.join(map(str, idx))}" if idx.size else "none"

    if unknown == "z":
        return f"round {it}: M_AA is singular for A = the rows solved for ({rows(A)}) ({why})"
    contact = A if unknown == "reactions" else ~A
    return f"round {it}: the supports in contact ({rows(contact)}) do not hold the plate ({why})"


class _Toggle(LCPBackend):
    """The toggle backend: :func:`toggle` told what the LCP's z stands for (``LCP.unknown``)."""

    def solve(self, problem, accuracy="default", options=None) -> RawSolution:
        if not isinstance(problem, LCP):
            return super().solve(problem, accuracy, options)  # says it takes LCPs only
        Accuracy.parse(accuracy)  # a bad accuracy is said before a bad option
        options = check_options(self.name, options, self.options)
        return toggle(problem.M, problem.q, accuracy=accuracy, unknown=problem.unknown, **options)


def penalty(M, q, ratio=None, *, accuracy="default", tol=None) -> RawSolution:
    """Solve LCP(M, q) by the penalty method: LCP(M + ε I, q) exactly, ``ε = ratio · max diag M``
    (module docstring). ``extras``: ``epsilon``, ``penetration`` (max ε z_i, in the units of
    ``w``), ``natural_residual`` (of the original LCP)."""
    t0 = time.perf_counter()
    prob = LCP(M, q)
    M, q, n = prob.M, prob.q, prob.n
    tol = settings(ACCURACY, accuracy, ("tol",), tol=tol)["tol"]
    ratio = check_fraction("ratio", RATIO if ratio is None else ratio)
    if ratio == 0.0:
        raise ProblemError("option ratio must be a number in (0, 1), got 0 (no penalty: the LCP itself)")
    eps = ratio * max(float(np.abs(np.diagonal(M)).max(initial=0.0)), 1e-300)
    inner = bpp(M + eps * np.eye(n), q, accuracy="high")
    if inner.x is None or not inner.status.solved:
        return RawSolution(status=inner.status, iterations=inner.iterations, solve_time=time.perf_counter() - t0,
                           solver_status=f"penalty: the penalised LCP: {inner.solver_status}",
                           extras={"epsilon": eps, **inner.extras})
    z = np.maximum(inner.x, 0.0)
    w = M @ z + q
    res = natural_residual(M, q, z, w)
    pen = float(eps * z.max(initial=0.0))
    ok = res <= tol
    return answer(q, z, w, Status.OPTIMAL if ok else Status.INACCURATE, t0, inner.iterations or 0,
                  f"penalty ε = {eps:.2e}: penetration up to {pen:.2e} (natural residual {res:.1e}"
                  f"{'' if ok else f' > {tol:.0e}'})",
                  {"epsilon": eps, "penetration": pen, "natural_residual": res})


def backends() -> list:
    return [_Toggle("toggle", toggle, ("max_iter", "tol"), exact=False),
            LCPBackend("penalty", penalty, ("ratio", "tol"), exact=False)]
