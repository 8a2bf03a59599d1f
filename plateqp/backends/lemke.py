r"""Lemke's complementary pivoting method for LCP(M, q), in pure NumPy.

Finds ``z ≥ 0`` with ``w = M z + q ≥ 0`` and ``zᵀ w = 0``. ``q ≥ 0`` returns ``z = 0`` at once;
otherwise one artificial variable ``z0`` and a covering vector ``d > 0`` (default all ones: the
source paper's uniform *pre-compression* of every support) start the pivoting on the tableau
``B⁻¹ [I | −M | −d | q]``: the initial pivot lets ``z0`` enter, each next entering variable is
the complement of the one that left, the ratio test picks the leaving row, and the method stops
when ``z0`` leaves (a complementary solution) or no row blocks (a secondary ray).

Contract:

- **Termination.** Ties in the ratio test are broken lexicographically over ``[q̄ | B⁻¹] / a``
  (Lemke on ``q + (ε, ε², …)``; Cottle, Pang & Stone §4.9), and ``z0`` leaves first among tied
  rows: every basis is visited at most once. ``max_iter`` bounds the pivots (``MAX_ITER``).
- **No solution.** For copositive-plus ``M`` (any positive semidefinite ``M``) a secondary ray's
  ``z`` part ``y`` is a certificate, ``y ≥ 0``, ``Mᵀy ≤ 0``, ``qᵀy < 0`` (Cottle, Pang & Stone
  Thm 4.4.13), checked on ``M``: status ``INFEASIBLE`` with ``y`` in ``extras["certificate"]``;
  a ray whose ``y`` fails the check is an ``ERROR``. ``M`` is never regularised.
- **Accuracy.** A direct method: ``z`` is recomputed from the final basis (``B x_B = q``,
  :func:`numpy.linalg.solve`), negatives down to ``1e-12`` of its scale clipped, ``w = M z + q``
  from that ``z``. The presets of :data:`ACCURACY` set the pivoting tolerances, how often the
  tableau is recomputed from the basis, and the residual above which the answer is
  ``INACCURATE``.
- **Output.** A :class:`~plateqp.backends.base.RawSolution` (``x = z``, status, pivots in
  ``iterations``); ``trace=True`` records every pivot in ``extras["trace"]`` (teaching).

The design, the tableau drawn out and the lexicographic rule in detail: docs/design/lemke.md.

Examples
--------
>>> import numpy as np
>>> from plateqp.backends.lemke import lemke
>>> sol = lemke(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0]))
>>> np.round(sol.x * 3, 12)        # z = (4/3, 7/3)
array([4., 7.])
"""

from __future__ import annotations

import time
from itertools import chain

import numpy as np

from ..errors import ProblemError
from .base import LCP, RawSolution, Status
from .lcp import LCPBackend, answer, certificate_tol, check_flag, check_int, infeasible, is_certificate, settings

__all__ = ["ACCURACY", "OPTIONS", "BACKEND", "lemke", "backends"]

#: Tolerances of each accuracy preset.
#:
#: ``pivot_tol``
#:     a row blocks in the ratio test only if ``a_i > pivot_tol · max|a|``
#:     (relative pivot tolerance).
#: ``zero_tol``
#:     two ratios are tied in the lexicographic ratio test if they differ by at
#:     most ``zero_tol`` times the largest ratio magnitude of the column.
#: ``refactor_every``
#:     recompute the whole tableau from the current basis after this many
#:     pivots (``0``: never); bounds the growth of rounding errors.
#: ``accept_tol``
#:     relative KKT residual of the cleaned-up answer above which the status is
#:     ``INACCURATE`` instead of ``OPTIMAL``.
#:
#: The answer is exact up to rounding at every preset.
ACCURACY: dict[str, dict[str, float | int]] = {
    "low": {"pivot_tol": 1e-9, "zero_tol": 1e-9, "refactor_every": 0, "accept_tol": 1e-6},
    "default": {"pivot_tol": 1e-11, "zero_tol": 1e-11, "refactor_every": 500, "accept_tol": 1e-8},
    "high": {"pivot_tol": 1e-12, "zero_tol": 1e-12, "refactor_every": 100, "accept_tol": 1e-10},
}

#: Negative entries of the cleaned-up ``z`` down to ``-CLIP_TOL · scale`` are set to zero.
CLIP_TOL = 1e-12


# --------------------------------------------------------------------------- helpers


def _label(var: int, n: int) -> tuple[str, int | None]:
    """Neutral name of tableau variable ``var``: ``("w", i)``, ``("z", i)`` or ``("z0", None)``."""
    if var < n:
        return ("w", var)
    if var < 2 * n:
        return ("z", var - n)
    return ("z0", None)


def _complement(var: int, n: int) -> int:
    """Index of the complement of ``w_i`` (``z_i``) or ``z_i`` (``w_i``)."""
    return var + n if var < n else var - n


def _lexmin_row(T: np.ndarray, rows: np.ndarray, denom: np.ndarray, n: int, zero_tol: float,
                prefer: int | None = None) -> int:
    """Lexicographic minimum-ratio row.

    Parameters
    ----------
    T : ndarray, shape (n, 2n+2)
        The tableau; column ``-1`` is ``q̄`` and columns ``0 … n-1`` are ``B⁻¹``.
    rows : ndarray of int
        Candidate (blocking) rows.
    denom : ndarray
        Positive divisors of those rows (the entering column's entries, or ``d``).
    n : int
        Problem size.
    zero_tol : float
        Relative tolerance under which two ratios count as tied.
    prefer : int, optional
        Row returned if it is tied for the minimum ``q̄`` ratio (the row of ``z0``).

    Returns
    -------
    int
        The row whose ``[q̄_i | (B⁻¹)_i] / denom_i`` is lexicographically smallest.
    """
    cand, den = rows, denom
    for k, col in enumerate(chain((T.shape[1] - 1,), range(n))):
        ratio = T[cand, col] / den
        rmin = ratio.min()
        keep = ratio <= rmin + zero_tol * np.abs(ratio).max()
        cand, den = cand[keep], den[keep]
        if k == 0 and prefer is not None and prefer in cand:
            return int(prefer)
        if cand.size == 1:
            break
    return int(cand[0])


def _pivot(T: np.ndarray, r: int, j: int, buf: np.ndarray) -> None:
    """Gauss–Jordan pivot of tableau ``T`` on entry ``(r, j)``, in place, O(n²)."""
    T[r] /= T[r, j]
    col = T[:, j].copy()
    col[r] = 0.0
    np.multiply(col[:, None], T[r][None, :], out=buf)
    T -= buf
    T[:, j] = 0.0  # the entering column is exactly a unit vector
    T[r, j] = 1.0


def _original_tableau(M: np.ndarray, q: np.ndarray, d: np.ndarray) -> np.ndarray:
    n = q.shape[0]
    T = np.zeros((n, 2 * n + 2))
    T[:, :n] = np.eye(n)
    T[:, n:2 * n] = -M
    T[:, 2 * n] = -d
    T[:, 2 * n + 1] = q
    return T


def _basis_matrix(M: np.ndarray, d: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """Columns of ``[I | −M | −d]`` of the basic variables, in row order."""
    n = basis.shape[0]
    B = np.zeros((n, n))
    for row, var in enumerate(basis):
        if var < n:
            B[var, row] = 1.0
        elif var < 2 * n:
            B[:, row] = -M[:, var - n]
        else:
            B[:, row] = -d
    return B


def _ray_direction(T: np.ndarray, basis: np.ndarray, entering: int, n: int) -> np.ndarray:
    """The ``z`` part of the direction of a secondary ray: the entering variable grows by ``t``,
    the basic ones change by ``−a t`` (``a`` its column, with no positive entry)."""
    d = np.zeros(2 * n + 1)
    d[basis] = -T[:, entering]
    d[entering] = 1.0
    return np.maximum(d[n:2 * n], 0.0)  # entries below the pivot tolerance are rounding


# --------------------------------------------------------------------------- the method


def lemke(M, q, covering=None, max_iter=None, trace=False, *, accuracy="default",
          pivot_tol=None, zero_tol=None, refactor_every=None, accept_tol=None) -> RawSolution:
    """Solve LCP(M, q) by Lemke's complementary pivoting method.

    Find ``z ≥ 0`` with ``w = M z + q ≥ 0`` and ``zᵀ w = 0``.

    Parameters
    ----------
    M : array_like or sparse matrix, shape (n, n)
        The LCP matrix (densified). For positive semidefinite ``M`` a ray
        termination proves that no solution exists.
    q : array_like, shape (n,)
        The LCP vector.
    covering : array_like or float, optional
        Covering vector ``d`` (the source paper's "pre-compression
        parameter", see the module docstring), strictly positive; a scalar
        is broadcast. Default all ones.
    max_iter : int, optional
        Maximum number of pivots (default ``50 n + 100``). Reaching it gives
        ``Status.MAX_ITER``, not an exception.
    trace : bool, optional
        Record every pivot in ``extras["trace"]`` as
        ``{"step": k, "entering": (kind, i), "leaving": (kind, i), "z0": value}``
        with ``kind`` one of ``"z"``, ``"w"``, ``"z0"`` (``i`` is ``None`` for
        ``z0``) and ``value`` the artificial variable after the pivot.
    accuracy : {"low", "default", "high"} or float, optional
        Preset of :data:`ACCURACY`; the keyword tolerances below override it.
    pivot_tol, zero_tol, refactor_every, accept_tol : optional
        See :data:`ACCURACY`.

    Returns
    -------
    RawSolution
        ``status`` (``OPTIMAL``; ``INACCURATE`` if the cleaned-up residual
        exceeds ``accept_tol``; ``MAX_ITER``; ``INFEASIBLE`` on a secondary
        ray with a checked certificate, ``ERROR`` on one without), ``x = z``,
        ``w = M z + q``, ``obj = ½ zᵀMz + qᵀz``, ``iterations`` (number of
        pivots, the initial ``z0`` pivot included), ``solve_time`` (seconds).
        On ``MAX_ITER``, ``x`` and ``w`` are ``None`` and ``extras`` holds the
        last iterate ``"z"``, ``"w"`` and ``"z0"``. On ``INFEASIBLE``,
        ``extras["certificate"]`` holds ``y ≥ 0`` with ``Mᵀy ≤ 0``,
        ``qᵀy < 0``; on a ray without one, ``extras["ray"]`` its ``z`` part.

    Raises
    ------
    ProblemError
        Malformed data, a non-positive covering vector, a bad option value.
    """
    t0 = time.perf_counter()
    prob = LCP(M, q)  # validates shapes, densifies, checks finiteness
    M, q, n = prob.M, prob.q, prob.n

    tol = settings(ACCURACY, accuracy, ("accept_tol",), pivot_tol=pivot_tol, zero_tol=zero_tol,
                   refactor_every=refactor_every, accept_tol=accept_tol)
    refac = check_int("refactor_every", tol["refactor_every"], 0)

    if covering is None:
        d = np.ones(n)
    else:
        d = np.asarray(covering, dtype=float)
        if d.ndim == 0:
            d = np.full(n, float(d))
        d = d.reshape(-1)
        if d.shape[0] != n:
            raise ProblemError(f"covering vector has length {d.shape[0]}, expected {n}")
        if not (np.all(np.isfinite(d)) and np.all(d > 0)):
            raise ProblemError("the covering vector must be finite and strictly positive")

    max_iter = check_int("max_iter", 50 * n + 100 if max_iter is None else max_iter, 1)
    trace = check_flag("trace", trace)

    steps: list[dict] = []
    extras: dict = {"trace": steps} if trace else {}

    if n == 0 or q.min() >= -CLIP_TOL * np.abs(q).max():
        # z = 0 solves it: q ≥ 0 up to rounding. A q_i of −1e-16 beside entries of 10 is a zero
        # (on a plate: a support exactly at lift-off); pivoting on its row would chase rounding,
        # and where its column of M is zero up to rounding too, end on a ray that proves nothing.
        return _accepted(M, q, np.zeros(n), tol, t0, 0, "q >= 0 (up to rounding): z = 0", extras)

    Z0, RHS = 2 * n, 2 * n + 1
    T = _original_tableau(M, q, d)
    buf = np.empty_like(T)
    basis = np.arange(n)  # basis[row] = variable basic in that row; w_i is variable i
    n_refactor = 0

    def record(k: int, entering: int, leaving: int) -> None:
        if trace:
            z0rows = np.flatnonzero(basis == Z0)
            z0 = float(T[z0rows[0], RHS]) if z0rows.size else 0.0
            steps.append({"step": k, "entering": _label(entering, n),
                          "leaving": _label(leaving, n), "z0": z0})

    # Initial pivot: z0 enters; lexicographic minimum of rows of [q | I] / d.
    r = _lexmin_row(T, np.arange(n), d, n, tol["zero_tol"])
    _pivot(T, r, Z0, buf)
    leaving, basis[r] = int(basis[r]), Z0
    it = 1
    record(it, Z0, leaving)

    while leaving != Z0:
        if it >= max_iter:
            zc = np.zeros(n)
            zrows = np.flatnonzero((basis >= n) & (basis < Z0))
            zc[basis[zrows] - n] = T[zrows, RHS]
            z0rows = np.flatnonzero(basis == Z0)
            extras.update(z=zc, w=M @ zc + q, z0=float(T[z0rows[0], RHS]) if z0rows.size else 0.0)
            return RawSolution(status=Status.MAX_ITER, iterations=it,
                               solve_time=time.perf_counter() - t0,
                               solver_status=f"iteration limit {max_iter} reached", extras=extras)
        entering = _complement(leaving, n)
        a = T[:, entering]
        amax = np.abs(a).max()
        rows = np.flatnonzero(a > tol["pivot_tol"] * amax) if amax > 0 else np.array([], int)
        if rows.size == 0:
            kind, i = _label(entering, n)
            how = f"Lemke's method ended on a secondary ray after {it} pivots (entering {kind}[{i}])"
            y = _ray_direction(T, basis, entering, n)
            if is_certificate(M, q, y, certificate_tol(n)):
                return infeasible(y, t0, it, how, extras)
            extras["ray"] = y
            return RawSolution(status=Status.ERROR, iterations=it, solve_time=time.perf_counter() - t0,
                               solver_status=f"{how}, whose direction is no certificate of infeasibility "
                                             "(M is not copositive-plus): nothing is proved", extras=extras)
        z0row = int(np.flatnonzero(basis == Z0)[0])
        r = _lexmin_row(T, rows, a[rows], n, tol["zero_tol"], prefer=z0row)
        _pivot(T, r, entering, buf)
        leaving, basis[r] = int(basis[r]), entering
        it += 1
        record(it, entering, leaving)
        if refac and it % refac == 0 and leaving != Z0:
            try:  # recompute B⁻¹[I | −M | −d | q] from scratch
                T[:] = np.linalg.solve(_basis_matrix(M, d, basis), _original_tableau(M, q, d))
                T[:, basis] = 0.0
                T[np.arange(n), basis] = 1.0
                n_refactor += 1
            except np.linalg.LinAlgError:
                pass

    # Final clean-up solve on the basic columns (z0 is non-basic now).
    z = np.zeros(n)
    zrows = np.flatnonzero(basis >= n)
    try:
        xB = np.linalg.solve(_basis_matrix(M, d, basis), q)
        cleanup = "solve"
    except np.linalg.LinAlgError:
        xB = T[:, RHS].copy()
        cleanup = "tableau (basis matrix singular)"
    z[basis[zrows] - n] = xB[zrows]
    extras.update(refactorisations=n_refactor, cleanup=cleanup)
    return _accepted(M, q, z, tol, t0, it, "z0 left the basis", extras)


def _accepted(M: np.ndarray, q: np.ndarray, z: np.ndarray, tol: dict, t0: float, it: int, message: str,
              extras: dict) -> RawSolution:
    """The answer ``z``: negatives down to ``CLIP_TOL`` of its scale clipped, ``w = M z + q``, and
    ``OPTIMAL`` if its relative KKT residual (``extras["kkt_residual"]``) is at most ``accept_tol``."""
    Mmax = np.abs(M).max(initial=0.0)
    zscale = max(np.abs(z).max(initial=0.0), np.abs(q).max(initial=0.0) / Mmax if Mmax > 0 else 0.0,
                 np.finfo(float).tiny)
    z[(z < 0) & (z >= -CLIP_TOL * zscale)] = 0.0
    w = M @ z + q
    wscale = max(np.abs(q).max(initial=0.0), Mmax * np.abs(z).max(initial=0.0), np.finfo(float).tiny)
    residual = max(max(0.0, -z.min(initial=0.0)) / zscale, max(0.0, -w.min(initial=0.0)) / wscale,
                   np.abs(z * w).max(initial=0.0) / zscale / wscale)
    status = Status.OPTIMAL if residual <= tol["accept_tol"] else Status.INACCURATE
    extras["kkt_residual"] = float(residual)
    return answer(q, z, w, status, t0, it, message, extras)


#: Keys accepted in the ``options`` dict of the backend's ``solve``.
OPTIONS = ("covering", "max_iter", "trace") + tuple(ACCURACY["default"])

#: The ``lemke`` backend: exact, no warm start (its start is the covering vector).
BACKEND = LCPBackend("lemke", lemke, OPTIONS, exact=True)


def backends() -> list[LCPBackend]:
    """The backends this module provides: ``[BACKEND]``."""
    return [BACKEND]
