r"""Projected Gauss–Seidel (PGS, with over-relaxation: PSOR) for LCP(M, q), in NumPy.

Finds ``z ≥ 0`` with ``w = M z + q ≥ 0`` and ``zᵀ w = 0`` for symmetric positive semidefinite
``M`` with a positive diagonal (the optimality condition of min ½ zᵀMz + qᵀz, z ≥ 0): the
baseline iterative method, for teaching and comparison (Cryer 1971; Cottle, Pang & Stone §5.2).
One sweep updates every component in turn from the latest values of the others,
``z_i ← max(0, z_i − ω (q_i + M_i z) / M_ii)`` (``ω = 1``: PGS; ``0 < ω < 2``: PSOR), with
``w`` kept up to date by one ``daxpy`` per component that moves and recomputed as ``M z + q``
every ``RESYNC`` sweeps and before stopping (so the returned ``w`` and residual are exact).

Contract:

- **Convergence.** For symmetric PSD ``M`` with a positive diagonal and ``0 < ω < 2`` the
  objective falls monotonically and, when the LCP has a solution, ``w`` converges linearly, at
  a rate set by the conditioning of ``M`` (slow for a plate's 10⁴–10⁶).
- **Stopping.** After every sweep, on the relative natural residual
  ``r = max |min(M_ii z_i, w_i)| / max(‖w‖∞, ‖q‖∞)`` (:func:`plateqp.backends.lcp.natural_residual`):
  ``OPTIMAL`` once ``r ≤ tol`` of the preset in :data:`ACCURACY`. If ``max_iter`` sweeps or
  ``time_limit`` seconds run out first, the status is ``MAX_ITER`` with the last iterate in
  ``x`` and ``w`` and the limit in ``solver_status``. An LCP without a solution makes ``z``
  grow without bound: it ends on a limit, never ``OPTIMAL``.

The design and the cost of a sweep: docs/design/pgs.md.

Examples
--------
>>> import numpy as np
>>> from plateqp.backends.pgs import pgs
>>> sol = pgs(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0]), accuracy="high")
>>> sol.status.value, np.round(sol.x * 3, 8)     # z = (4/3, 7/3)
('optimal', array([4., 7.]))
"""

from __future__ import annotations

import time

import numpy as np
from scipy.linalg.blas import daxpy

from ..errors import ProblemError
from .base import LCP, RawSolution, Status
from .lcp import LCPBackend, answer, check_int, natural_residual, settings

__all__ = ["ACCURACY", "OPTIONS", "BACKEND", "pgs", "backends"]

#: Stopping tolerance of each accuracy preset: the sweeps stop when the relative natural
#: residual ``r`` (module docstring) is at most ``tol``.
ACCURACY: dict[str, dict[str, float]] = {
    "low": {"tol": 1e-5},
    "default": {"tol": 1e-8},
    "high": {"tol": 1e-11},
}

#: Defaults of the limits: sweeps, and seconds of wall-clock time.
MAX_ITER = 100_000
TIME_LIMIT = 60.0

#: ``w`` is recomputed as ``M z + q`` every ``RESYNC`` sweeps (and before stopping).
RESYNC = 10


def _sweep(rows: list, step: list, z: list, w: np.ndarray) -> None:
    """One projected Gauss–Seidel sweep, in place on ``z`` (a list) and ``w`` (kept = M z + q)."""
    for i in range(len(z)):
        zi = z[i]
        new = zi - step[i] * w[i]
        if new < 0.0:  # noqa: PLR1730 (a branch is cheaper than max() in this loop)
            new = 0.0
        if new != zi:
            z[i] = new
            daxpy(rows[i], w, a=new - zi)  # w += (new − zi) M[i], in place


def pgs(M, q, omega=1.0, max_iter=None, time_limit=None, z0=None, *, accuracy="default",
        tol=None) -> RawSolution:
    """Solve LCP(M, q) by projected Gauss–Seidel / projected SOR sweeps.

    Parameters
    ----------
    M : array_like or sparse matrix, shape (n, n)
        Symmetric positive semidefinite with a positive diagonal (densified).
        Only the rows of ``M`` are read: for a non-symmetric ``M`` the
        iteration is projected Gauss–Seidel on the rows, without a
        convergence guarantee.
    q : array_like, shape (n,)
    omega : float, optional
        Relaxation factor ``ω ∈ (0, 2)`` (default 1: Gauss–Seidel; > 1:
        over-relaxation).
    max_iter : int, optional
        Maximum number of sweeps (default :data:`MAX_ITER`).
    time_limit : float, optional
        Wall-clock seconds after which the sweeps stop (default
        :data:`TIME_LIMIT`), checked after every sweep.
    z0 : array_like, shape (n,), optional
        Warm start (negative entries are set to zero). Default ``z = 0``.
    accuracy : {"low", "default", "high"} or float, optional
        Preset of :data:`ACCURACY`.
    tol : float, optional
        Overrides the preset's stopping tolerance.

    Returns
    -------
    RawSolution
        ``status`` ``OPTIMAL`` (the natural residual reached ``tol``) or
        ``MAX_ITER`` (a limit was reached first; ``solver_status`` says which),
        ``x = z`` and ``w = M z + q`` in both cases, ``obj``, ``iterations``
        (sweeps), ``solve_time``. ``extras``: ``natural_residual``,
        ``active`` (``z == 0``, the form :mod:`~plateqp.backends.bpp` takes as
        a warm start), ``omega``.

    Raises
    ------
    ProblemError
        Malformed data or a bad option value.

    Notes
    -----
    A component with ``M_ii ≤ 0`` cannot be updated (the step divides by
    ``M_ii``); for a PSD ``M`` its row is zero (up to rounding: a plate
    floating on three supports gives ``M ≈ 0``), so ``z_i`` does not act
    on ``w`` and is held at its start value (0 unless ``z0`` says otherwise).
    If that prevents convergence the sweeps end on a limit, ``MAX_ITER``.
    """
    t0 = time.perf_counter()
    prob = LCP(M, q)
    M, q, n = prob.M, prob.q, prob.n
    tol = settings(ACCURACY, accuracy, ("tol",), tol=tol)["tol"]
    if isinstance(omega, bool) or not (np.isscalar(omega) and np.isfinite(omega) and 0 < omega < 2):
        raise ProblemError(f"option omega must be a number in (0, 2), got {omega!r}")
    max_iter = check_int("max_iter", MAX_ITER if max_iter is None else max_iter, 1)
    if time_limit is None:
        time_limit = TIME_LIMIT
    if isinstance(time_limit, bool) or not (np.isscalar(time_limit) and time_limit > 0):
        raise ProblemError(f"option time_limit must be a positive number of seconds, got {time_limit!r}")
    d = np.diagonal(M).copy()
    held = ~(d > 0)  # a zero row of a PSD M (up to rounding): z_i cannot move w, hold it
    d[held] = 1.0
    if z0 is None:
        z = np.zeros(n)
    else:
        z = np.asarray(z0, dtype=float).reshape(-1)
        if z.shape != (n,) or not np.all(np.isfinite(z)):
            raise ProblemError(f"option z0 must be a finite array of length {n}")
        z = np.maximum(z, 0.0)

    w = M @ z + q
    res = natural_residual(M, q, z, w)
    rows = list(np.ascontiguousarray(M))  # row views: M[i] without indexing in the loop
    step = np.where(held, 0.0, omega / d).tolist()
    zl = z.tolist()
    sweeps = 0
    ended = None
    fresh = True  # w is M z + q computed afresh, not the running update
    while True:
        if res <= tol:
            if fresh:
                break
            w, fresh = M @ z + q, True  # confirm on a fresh w before stopping
            res = natural_residual(M, q, z, w)
            continue
        if sweeps >= max_iter:
            ended = f"sweep limit {max_iter} reached"
            break
        if time.perf_counter() - t0 >= time_limit:
            ended = f"time limit {time_limit:g} s reached after {sweeps} sweeps"
            break
        _sweep(rows, step, zl, w)
        sweeps += 1
        z = np.array(zl)
        fresh = sweeps % RESYNC == 0
        if fresh:  # clear the drift of the running updates
            w = M @ z + q
        res = natural_residual(M, q, z, w)
    if not fresh:
        w = M @ z + q
        res = natural_residual(M, q, z, w)
    status = Status.OPTIMAL if ended is None else Status.MAX_ITER
    message = (f"natural residual {res:.1e} ≤ {tol:.0e} after {sweeps} sweeps" if ended is None
               else f"{ended}; natural residual {res:.1e} > {tol:.0e}")
    if held.any():
        message += f" ({int(held.sum())} components with M_ii ≤ 0 held at their start value)"
    return answer(q, z, w, status, t0, sweeps, message,
                  {"natural_residual": res, "active": z == 0, "omega": float(omega)})


#: Keys accepted in the ``options`` dict of the backend's ``solve``.
OPTIONS = ("omega", "max_iter", "time_limit", "z0") + tuple(ACCURACY["default"])

#: The ``pgs`` backend: iterative (its answer is as accurate as asked), warm-started only by
#: ``options["z0"]``, an iterate, not by an active set.
BACKEND = LCPBackend("pgs", pgs, OPTIONS, exact=False)


def backends() -> list[LCPBackend]:
    """The backends this module provides: ``[BACKEND]``."""
    return [BACKEND]
