r"""The seam shared by the in-house LCP solvers (:mod:`~plateqp.backends.lemke`,
:mod:`~plateqp.backends.bpp`, :mod:`~plateqp.backends.pgs`).

Each of them is a function ``method(M, q, ..., *, accuracy, **tolerances) → RawSolution`` on
LCP(M, q): find ``z ≥ 0`` with ``w = M z + q ≥ 0`` and ``zᵀ w = 0``. What they share is here,
once:

* :class:`LCPBackend`, the backend each module registers: it refuses anything but an
  :class:`~plateqp.backends.base.LCP` (a ProblemError), checks the accuracy and then the
  option names, and calls the method;
* :func:`settings`, a method's tolerances for an accuracy (its preset row, a numeric accuracy
  scaling the tolerance keys, keyword overrides), each checked;
* the checks of option values (:func:`check_fraction`, :func:`check_int`, :func:`check_flag`);
* :func:`natural_residual`, the acceptance test of an answer;
* :func:`answer`, the RawSolution of a candidate ``z``; :func:`infeasible`, the one of a
  certificate that LCP(M, q) has no solution, checked by :func:`is_certificate`.

The certificate of infeasibility is Farkas': ``y ≥ 0`` with ``Mᵀy ≤ 0`` and ``qᵀy < 0``. For
a solution ``z`` it would give ``0 ≤ yᵀw = (Mᵀy)ᵀz + qᵀy < 0``. (On a plate on one-sided
supports, ``y`` is a rigid motion that the load drives and no support resists: net uplift,
or a load outside the supports' reach.)
"""

from __future__ import annotations

import time
from typing import Callable

import numpy as np

from ..accuracy import Accuracy
from ..errors import ProblemError
from .base import LCP, Backend, RawSolution, Status, check_options, preset

__all__ = ["LCPBackend", "settings", "check_fraction", "check_int", "check_flag", "natural_residual",
           "answer", "infeasible", "is_certificate", "certificate_tol"]


class LCPBackend(Backend):
    """An in-house LCP solver as a backend (the shape of :class:`~plateqp.backends.base.Backend`).

    Parameters
    ----------
    name : str
        Registry name.
    method : callable
        ``method(M, q, accuracy=..., **options) → RawSolution``.
    options : tuple of str
        The option names ``solve`` passes on to ``method``; any other is a ProblemError.
    exact, warm_start : bool
        The capabilities (see :class:`~plateqp.backends.base.Backend`).
    """

    accepts = frozenset({"lcp"})

    def __init__(self, name: str, method: Callable[..., RawSolution], options: tuple[str, ...], *,
                 exact: bool, warm_start: bool = False) -> None:
        self.name, self.method, self.options = name, method, tuple(options)
        self.exact, self.warm_start = exact, warm_start

    def solve(self, problem, accuracy: str | float | Accuracy = "default",
              options: dict | None = None) -> RawSolution:
        """Solve an :class:`~plateqp.backends.base.LCP`; see the method's own docstring.

        Raises
        ------
        ProblemError
            Not an LCP, a bad accuracy, an unknown option or a bad option value.
        """
        if not isinstance(problem, LCP):
            raise ProblemError(f"the {self.name} backend solves LCPs only, got {type(problem).__name__}")
        Accuracy.parse(accuracy)  # a bad accuracy is said before a bad option
        options = check_options(self.name, options, self.options)
        return self.method(problem.M, problem.q, accuracy=accuracy, **options)


# --------------------------------------------------------------------------- settings, options


def check_fraction(key: str, value) -> float:
    """An option that must be a number in [0, 1) (a relative tolerance)."""
    if isinstance(value, (bool, np.bool_)) or not (np.isscalar(value) and not isinstance(value, str)
                                                  and np.isfinite(value) and 0 <= value < 1):
        raise ProblemError(f"option {key} must be a number in [0, 1), got {value!r}")
    return float(value)


def check_int(key: str, value, low: int) -> int:
    """An option that must be an integer ≥ ``low``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < low:
        raise ProblemError(f"option {key} must be an integer ≥ {low}, got {value!r}")
    return int(value)


def check_flag(key: str, value) -> bool:
    """An option that must be True or False."""
    if not isinstance(value, (bool, np.bool_)):
        raise ProblemError(f"option {key} must be True or False, got {value!r}")
    return bool(value)


def settings(table: dict[str, dict], accuracy: str | float | Accuracy, scale: tuple[str, ...],
             **overrides) -> dict:
    """A method's settings for ``accuracy``: the row of ``table`` for it (the keys in ``scale``
    scaled to a numeric accuracy, :func:`~plateqp.backends.base.preset`), then every override
    that is not None; every tolerance (a key ending in ``tol``) is checked to be in [0, 1).
    A bad accuracy or value is a ProblemError."""
    row = preset(table, accuracy, scale=scale)
    row.update({k: v for k, v in overrides.items() if v is not None})
    for key, value in row.items():
        if key.endswith("tol"):
            row[key] = check_fraction(key, value)
    return row


# --------------------------------------------------------------------------- answers


def natural_residual(M: np.ndarray, q: np.ndarray, z: np.ndarray, w: np.ndarray) -> float:
    r"""Relative natural residual of a candidate solution of LCP(M, q), with ``w = M z + q``.

    .. math::

        r = \frac{\max_i |\min(d_i z_i,\ w_i)|}{\max(\|w\|_\infty, \|q\|_\infty)},
        \qquad d = \mathrm{diag}(M).

    Zero exactly at a solution; it sees a negative ``z_i`` or ``w_i`` and a violated
    complementarity alike. ``z`` is weighted by the diagonal so that both terms are in the
    units of ``w``, and the measure does not change when a row and its column are scaled. The
    scale is that of ``w`` and ``q``, never that of ``z``: an iterate that runs away (no
    solution) must not make its own residual look small. BPP's acceptance test and PGS's
    stopping test.
    """
    if z.size == 0:
        return 0.0
    dz = np.abs(np.diagonal(M)) * z
    num = np.abs(np.minimum(dz, w)).max()
    scale = max(np.abs(w).max(), np.abs(q).max())
    if scale == 0.0:
        return 0.0 if num == 0.0 else float("inf")
    return float(num / scale)


def answer(q: np.ndarray, z: np.ndarray, w: np.ndarray, status: Status, t0: float, iterations: int,
           message: str, extras: dict) -> RawSolution:
    """The RawSolution of a candidate ``z`` with ``w = M z + q``: ``x = z``, ``w``, the objective
    ``½ zᵀMz + qᵀz = ½ zᵀ(w + q)``, and the time since ``t0`` (``time.perf_counter``)."""
    return RawSolution(status=status, x=z, w=w, obj=float(0.5 * z @ (w + q)), iterations=iterations,
                       solve_time=time.perf_counter() - t0, solver_status=message, extras=extras)


def certificate_tol(n: int) -> float:
    """The default relative tolerance of :func:`is_certificate` for an LCP of size ``n``: a
    thousand times the rounding of a product ``M y`` (``max(1e-12, 10 n ε)``)."""
    return 1e3 * max(1e-12, 10 * n * np.finfo(float).eps)


def is_certificate(M: np.ndarray, q: np.ndarray, y: np.ndarray | None, tol: float) -> bool:
    """``y ≥ 0``, ``Mᵀy ≤ 0`` (up to ``tol · max|M| · max y · √n``) and ``qᵀy < 0``, checked on the
    full ``M``: a proof that LCP(M, q) has no solution (see the module docstring)."""
    if y is None or y.size == 0:
        return False
    ny = np.abs(y).max()
    if ny == 0 or y.min() < 0:
        return False
    return bool((M.T @ y).max() <= tol * np.abs(M).max() * ny * np.sqrt(q.shape[0]) and q @ y < 0)


def infeasible(y: np.ndarray, t0: float, iterations: int, how: str, extras: dict) -> RawSolution:
    """Status ``INFEASIBLE`` with the certificate ``y`` (scaled to ``max y = 1``) in
    ``extras["certificate"]``; ``how`` says how the method found it."""
    extras["certificate"] = y / np.abs(y).max()
    return RawSolution(status=Status.INFEASIBLE, iterations=iterations, solve_time=time.perf_counter() - t0,
                       solver_status=f"{how}: y ≥ 0 with Mᵀy ≤ 0 and qᵀy < 0 (extras['certificate']) "
                                     "proves that LCP(M, q) has no solution", extras=extras)
