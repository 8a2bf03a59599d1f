r"""Lemke's complementary pivoting method for LCP(M, q), in pure NumPy.

The problem
-----------
Find ``z ≥ 0`` such that ``w = M z + q ≥ 0`` and ``zᵀ w = 0``.

If ``q ≥ 0`` then ``z = 0`` is a solution and is returned at once. Otherwise
Lemke's method adds one artificial variable ``z0 ≥ 0`` and a *covering vector*
``d > 0`` (default: all ones) and works on

    w − M z − d z0 = q,    w, z, z0 ≥ 0,    w_i z_i = 0  (i = 1 … n).

The source paper of plateqp calls the covering vector a *pre-compression
parameter*: ``d z0`` is added to ``q`` so that every support starts in
compression, ``w = q + d z0 ≥ 0``, and the method then releases ``z0`` until it
is zero. A uniform covering vector ``d = 1`` amounts to a uniform
pre-compression of all supports.

The tableau
-----------
The algorithm keeps the tableau of that system, ``n`` rows and ``2n + 2``
columns. At the start the basis is ``w`` (``B = I``)::

              w_1 … w_n │ z_1 … z_n │  z0   │ rhs
            ┌───────────┼───────────┼───────┼─────┐
      w_1   │           │           │ −d_1  │ q_1 │
       ⋮    │     I     │    −M     │   ⋮   │  ⋮  │
      w_n   │           │           │ −d_n  │ q_n │
            └───────────┴───────────┴───────┴─────┘

After any sequence of pivots the tableau is ``B⁻¹ [I | −M | −d | q]``, where
``B`` holds the columns of the ``n`` basic variables. Hence its first ``n``
columns *are* ``B⁻¹`` and its last column is ``q̄ = B⁻¹ q``, the current values
of the basic variables (the non-basic ones are zero). A pivot on row ``r`` and
column ``j`` is one Gauss–Jordan step: divide row ``r`` by ``T[r, j]`` and
subtract multiples of it from every other row, a rank-one update costing
``O(n²)`` flops.

The steps
---------
1. *Initial pivot.* ``z0`` enters. The row ``r`` that leaves is the one
   with the most negative ``q_r / d_r``; after the pivot
   ``z0 = −q_r / d_r`` and ``w = q + d z0 ≥ 0`` with ``w_r = 0``.
2. *Complementary rule.* The next entering variable is the complement of the
   one that just left (``w_i`` left → ``z_i`` enters, and vice versa).
3. *Ratio test.* With ``a = T[:, j]`` the entering column, the basic
   variables decrease as ``q̄ − a t`` while the entering one grows to ``t``.
   Rows with ``a_i > 0`` block; the leaving row is the minimiser of
   ``q̄_i / a_i``, ties broken by the lexicographic rule below. If ``z0`` is
   among the tied rows it leaves.
4. *Termination.* When ``z0`` leaves the basis, ``z0 = 0`` and the basic
   solution is a complementary solution of LCP(M, q). If no row blocks (the
   entering column has no positive entry) the method has found a *secondary
   ray*: for a copositive-plus ``M`` — in particular any positive
   semidefinite ``M``, the case of plates on one-sided supports — this proves
   that the LCP has no solution, and :class:`~plateqp.errors.NoEquilibriumError`
   is raised. ``M`` is never regularised.

Lexicographic rule
------------------
Under degeneracy (``q̄_i = 0`` for some basic variable, ties in the ratio
test) a plain minimum-ratio rule may cycle. The leaving row is therefore the
lexicographic minimum of the rows of ``[q̄ | B⁻¹]`` divided by ``a_i``, over the
blocking rows: compare the ``q̄`` ratios first, then, among the tied rows,
the first column of ``B⁻¹`` divided by ``a_i``, and so on. This is Lemke's
method applied to the perturbed ``q(ε) = q + (ε, ε², …, εⁿ)`` for an
infinitesimal ``ε > 0`` (Cottle, Pang & Stone, *The Linear Complementarity
Problem*, §4.9; Murty, *Linear Complementarity, Linear and Nonlinear
Programming*, §2.2). The rows of ``B⁻¹`` are linearly independent, so the rule
always designates a single row, every basis is visited at most once and the
method terminates. Ties between floating-point numbers are detected with a
relative tolerance (``zero_tol``). The initial pivot uses the same rule, on
the rows of ``[q | I] / d``.

Accuracy
--------
Lemke's method is a direct (finite) method: at every preset the answer is
exact up to rounding. After termination ``z`` is recomputed from the final
basis by solving the basic system ``B x_B = q`` directly
(:func:`numpy.linalg.solve`), negatives not larger than ``1e-12 · scale`` are
clipped to zero and ``w = M z + q`` is computed from the clipped ``z``. This
final clean-up solve is what gives machine-precision KKT residuals. The
presets in :data:`ACCURACY` only change the pivoting tolerances, how often the
tableau is recomputed from the basis (to stop rounding errors from
accumulating over many pivots), and the residual above which the result is
flagged :attr:`~plateqp.backends.base.Status.INACCURATE`.

Examples
--------
>>> import numpy as np
>>> from plateqp.backends.lemke import lemke
>>> sol = lemke(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0]))
>>> np.round(sol.x * 3, 12)        # z = (4/3, 7/3)
array([4., 7.])
"""

from __future__ import annotations

import sys
import time
from itertools import chain

import numpy as np

from ..errors import NoEquilibriumError, ProblemError
from .base import LCP, QP, RawSolution, Status, plateqp_version, preset

__all__ = ["name", "accepts", "ACCURACY", "available", "version", "solve", "lemke", "backends"]

name = "lemke"
accepts = frozenset({"lcp"})

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

#: Keys accepted in the ``options`` dict of :func:`solve`.
OPTIONS = ("covering", "max_iter", "trace") + tuple(ACCURACY["default"])

#: Negative entries of the cleaned-up ``z`` down to ``-CLIP_TOL · scale`` are set to zero.
CLIP_TOL = 1e-12

_RAY_MESSAGE = (
    "Lemke's method ended on a secondary ray: the one-sided supports cannot carry this load "
    "(net uplift, or the load resultant lies outside the supports' reach). "
    "For a positive semidefinite M this proves that the LCP has no solution."
)


def available() -> bool:
    """Lemke's method needs NumPy only: always available."""
    return True


version = plateqp_version  # the backend is part of plateqp


def backends() -> list:
    """The backends this module provides: the module itself.

    Returns
    -------
    list
        ``[module]``; the module has ``name``, ``accepts``, ``available``,
        ``version`` and ``solve``, i.e. it satisfies the ``Backend`` protocol.
    """
    return [sys.modules[__name__]]


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


def _check_accuracy(accuracy: str | float) -> dict:
    return preset(ACCURACY, accuracy, scale=("accept_tol",))


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
        Covering vector ``d`` ("pre-compression parameter"), strictly
        positive; a scalar is broadcast. Default all ones, a uniform
        pre-compression of all supports.
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
        exceeds ``accept_tol``; ``MAX_ITER``), ``x = z``, ``w = M z + q``,
        ``obj = ½ zᵀMz + qᵀz``, ``iterations`` (number of pivots, the initial
        ``z0`` pivot included), ``solve_time`` (seconds). On ``MAX_ITER``,
        ``x`` and ``w`` are ``None`` and ``extras`` holds the last iterate
        ``"z"``, ``"w"`` and ``"z0"``.

    Raises
    ------
    NoEquilibriumError
        Ray termination: the one-sided supports cannot carry the load.
    ProblemError
        Malformed data, a non-positive covering vector, a bad option value.
    """
    t0 = time.perf_counter()
    prob = LCP(M, q)  # validates shapes, densifies, checks finiteness
    M, q, n = prob.M, prob.q, prob.n

    tol = _check_accuracy(accuracy)
    for key, val in (("pivot_tol", pivot_tol), ("zero_tol", zero_tol),
                     ("refactor_every", refactor_every), ("accept_tol", accept_tol)):
        if val is not None:
            tol[key] = val
    for key in ("pivot_tol", "zero_tol", "accept_tol"):
        if not (np.isscalar(tol[key]) and np.isfinite(tol[key]) and 0 <= tol[key] < 1):
            raise ProblemError(f"option {key} must be a number in [0, 1), got {tol[key]!r}")
    refac = tol["refactor_every"]
    if isinstance(refac, bool) or not isinstance(refac, (int, np.integer)) or refac < 0:
        raise ProblemError(f"option refactor_every must be an integer ≥ 0, got {refac!r}")

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

    if max_iter is None:
        max_iter = 50 * n + 100
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise ProblemError(f"option max_iter must be a positive integer, got {max_iter!r}")
    if not isinstance(trace, (bool, np.bool_)):
        raise ProblemError(f"option trace must be True or False, got {trace!r}")

    steps: list[dict] = []
    extras: dict = {"trace": steps} if trace else {}

    if n == 0 or np.all(q >= 0):
        z = np.zeros(n)
        return RawSolution(status=Status.OPTIMAL, x=z, w=q.copy(), obj=0.0, iterations=0,
                           solve_time=time.perf_counter() - t0, solver_status="q >= 0: z = 0",
                           extras=extras)

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
            raise NoEquilibriumError(_RAY_MESSAGE + f" (ray after {it} pivots, entering "
                                     f"{_label(entering, n)[0]}[{_label(entering, n)[1]}])")
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
    Mmax = np.abs(M).max()
    zscale = max(np.abs(z).max(), np.abs(q).max() / Mmax if Mmax > 0 else 0.0, np.finfo(float).tiny)
    z[(z < 0) & (z >= -CLIP_TOL * zscale)] = 0.0
    Mz = M @ z
    w = Mz + q
    wscale = max(np.abs(q).max(), Mmax * np.abs(z).max(), np.finfo(float).tiny)
    residual = max(max(0.0, -z.min()) / zscale, max(0.0, -w.min()) / wscale,
                   np.abs(z * w).max() / (zscale * wscale))
    status = Status.OPTIMAL if residual <= tol["accept_tol"] else Status.INACCURATE
    extras.update(kkt_residual=float(residual), refactorisations=n_refactor, cleanup=cleanup)
    return RawSolution(status=status, x=z, w=w, obj=float(0.5 * z @ Mz + q @ z), iterations=it,
                       solve_time=time.perf_counter() - t0,
                       solver_status="z0 left the basis", extras=extras)


def solve(problem, accuracy: str = "default", options: dict | None = None) -> RawSolution:
    """Solve an :class:`~plateqp.backends.base.LCP` by Lemke's method (Backend protocol).

    Parameters
    ----------
    problem : LCP
        The problem; a :class:`~plateqp.backends.base.QP` is rejected.
    accuracy : {"low", "default", "high"} or float (a KKT tolerance; see base.preset)
        Preset of :data:`ACCURACY`.
    options : dict, optional
        Overrides, keys among :data:`OPTIONS`: ``covering``, ``max_iter``,
        ``trace``, ``pivot_tol``, ``zero_tol``, ``refactor_every``,
        ``accept_tol`` (see :func:`lemke`).

    Returns
    -------
    RawSolution
        See :func:`lemke`.

    Raises
    ------
    ProblemError
        Not an LCP, unknown accuracy or option.
    NoEquilibriumError
        Ray termination: the one-sided supports cannot carry this load.
    """
    if isinstance(problem, QP) or not isinstance(problem, LCP):
        raise ProblemError(f"the lemke backend solves LCPs only, got {type(problem).__name__}")
    _check_accuracy(accuracy)
    options = dict(options or {})
    unknown = sorted(set(options) - set(OPTIONS))
    if unknown:
        raise ProblemError(f"unknown option(s) {unknown} for backend lemke; known: {list(OPTIONS)}")
    return lemke(problem.M, problem.q, accuracy=accuracy, **options)
