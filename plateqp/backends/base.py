"""Standard-form problems, raw solutions and the backend protocol.

A backend knows QPs and LCPs, never plates. The problem forms are:

QP (the qpsolvers convention)::

    minimise    ½ xᵀ P x + qᵀ x
    subject to  G x ≤ h,   A x = b,   lb ≤ x ≤ ub

LCP::

    find z ≥ 0 such that w = M z + q ≥ 0 and zᵀ w = 0

Multiplier sign conventions of :class:`RawSolution` (those of qpsolvers):
``z`` ≥ 0 for ``G x ≤ h``; ``y`` free for ``A x = b``; ``z_box`` one entry per
variable, ``z_box < 0`` where the lower bound is active, ``> 0`` where the upper
bound is, so that stationarity reads ``P x + q + Gᵀ z + Aᵀ y + z_box = 0``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..accuracy import ACCURACIES, PRESET_TOL, TOL_RANGE, Accuracy, Status, accuracy_tol, nearest_preset
from ..errors import ProblemError, SolverError

# the shared words, re-exported here for the backends' convenience (they live in plateqp.accuracy)
__all__ = ["ACCURACIES", "PRESET_TOL", "TOL_RANGE", "Accuracy", "Status", "accuracy_tol", "nearest_preset",
           "LCP", "QP", "Backend", "RawSolution", "check_options", "rejected_option", "one_line",
           "preset", "via_qp", "plateqp_version"]


def _is_tolerance(key: str, value) -> bool:
    return (isinstance(value, float) and 0.0 < value < 1.0
            and any(t in key.lower() for t in ("tol", "eps", "gap")))


def preset(table: dict[str, dict], accuracy: str | float | Accuracy, scale: tuple[str, ...] | None = None) -> dict:
    """A backend's native settings for an accuracy (a preset name, a number or an
    :class:`~plateqp.accuracy.Accuracy`).

    ``table`` maps each preset name to settings in the solver's own names. A preset name gets
    its own row. A number ``tol`` gets the row of the nearest preset with every tolerance
    setting multiplied by ``tol / PRESET_TOL[preset]`` (floored at 1e-15): the keys in
    ``scale``, or by default every float setting in (0, 1) whose name holds "tol", "eps" or
    "gap". Iteration limits and switches are the preset's. A bad accuracy is a ProblemError.
    """
    acc = Accuracy.parse(accuracy)
    row = dict(table[acc.preset])
    if acc.is_preset:
        return row
    ratio = acc.tol / PRESET_TOL[acc.preset]
    for key, value in row.items():
        if (key in scale) if scale is not None else _is_tolerance(key, value):
            row[key] = max(float(value) * ratio, 1e-15)
    return row


def _as_vec(v, n: int, name: str) -> np.ndarray | None:
    if v is None:
        return None
    a = np.asarray(v, dtype=float).reshape(-1)
    if a.shape[0] != n:
        raise ProblemError(f"{name} has length {a.shape[0]}, expected {n}")
    return a


@dataclass
class QP:
    """A convex QP in standard form; checks its own shapes on construction."""

    P: Any  # sparse or dense (n, n), symmetric positive semidefinite
    q: np.ndarray
    G: Any = None
    h: np.ndarray | None = None
    A: Any = None
    b: np.ndarray | None = None
    lb: np.ndarray | None = None
    ub: np.ndarray | None = None
    #: True where the caller knows P to be singular (a floating plate's stiffness: rigid
    #: motions), False where it knows P definite, None (the default) where it does not say. A
    #: hint only: pdas skips a factorisation that would fail; no backend trusts it for an answer.
    singular: bool | None = None
    #: (n, k) a basis of P's null space where the caller knows it exactly (a floating plate's
    #: rigid motions, zero on every other variable), or None. A hint only: pdas checks that P
    #: annihilates it before it judges the load's work along a free motion on it.
    null: np.ndarray | None = None

    def __post_init__(self) -> None:
        self.q = np.asarray(self.q, dtype=float).reshape(-1)
        n = self.q.shape[0]
        if self.null is not None:
            self.null = np.asarray(self.null, dtype=float)
            if self.null.ndim != 2 or self.null.shape[0] != n or not np.all(np.isfinite(self.null)):
                raise ProblemError(f"null must be a finite (n, k) array with n={n}, got shape {self.null.shape}")
        if self.P.shape != (n, n):
            raise ProblemError(f"P has shape {self.P.shape}, expected ({n}, {n})")
        for M, v, name in ((self.G, self.h, "G"), (self.A, self.b, "A")):
            if (M is None) != (v is None):
                raise ProblemError(f"{name} and its right-hand side must be given together")
            if M is not None and (M.ndim != 2 or M.shape[1] != n or M.shape[0] != np.size(v)):
                raise ProblemError(f"{name} has shape {M.shape}, incompatible with n={n}")
        if self.h is not None:
            self.h = np.asarray(self.h, dtype=float).reshape(-1)
        if self.b is not None:
            self.b = np.asarray(self.b, dtype=float).reshape(-1)
        self.lb = _as_vec(self.lb, n, "lb")
        self.ub = _as_vec(self.ub, n, "ub")
        for name in ("q", "h", "b"):
            v = getattr(self, name)
            if v is not None and not np.all(np.isfinite(v)):
                raise ProblemError(f"{name} has non-finite entries")

    @property
    def n(self) -> int:
        return self.q.shape[0]

    @property
    def sparse(self) -> bool:
        return sp.issparse(self.P)


#: What the z of an :class:`LCP` may stand for.
LCP_UNKNOWNS = ("z", "reactions", "gaps")


@dataclass
class LCP:
    """A linear complementarity problem LCP(M, q); M dense (n, n).

    ``unknown``: what z stands for, one of :data:`LCP_UNKNOWNS`: "reactions" (the dual form:
    w the gaps), "gaps" (the condensed form: w the reactions), or "z" (a plain LCP). Solvers
    that read it only to phrase their messages or choose a start (``toggle``) may.
    """

    M: np.ndarray
    q: np.ndarray
    unknown: str = "z"

    def __post_init__(self) -> None:
        if self.unknown not in LCP_UNKNOWNS:
            raise ProblemError(f"unknown: one of {', '.join(map(repr, LCP_UNKNOWNS))}, got {self.unknown!r}")
        self.M = np.asarray(self.M.toarray() if sp.issparse(self.M) else self.M, dtype=float)
        self.q = np.asarray(self.q, dtype=float).reshape(-1)
        n = self.q.shape[0]
        if self.M.shape != (n, n):
            raise ProblemError(f"M has shape {self.M.shape}, expected ({n}, {n})")
        if not (np.all(np.isfinite(self.M)) and np.all(np.isfinite(self.q))):
            raise ProblemError("LCP data has non-finite entries")

    @property
    def n(self) -> int:
        return self.q.shape[0]

    def as_qp(self) -> QP:
        """The bound-constrained QP ½ zᵀMz + qᵀz, z ≥ 0 (valid for symmetric PSD M)."""
        return QP(P=self.M, q=self.q, lb=np.zeros(self.n))


@dataclass
class RawSolution:
    """What a backend returns, before any plate-level interpretation.

    For a QP: ``x``, ``z``, ``y``, ``z_box`` (see module docstring for signs).
    For an LCP: ``x`` is z and ``w`` is M z + q.
    """

    status: Status
    x: np.ndarray | None = None
    z: np.ndarray | None = None
    y: np.ndarray | None = None
    z_box: np.ndarray | None = None
    w: np.ndarray | None = None
    obj: float | None = None
    iterations: int | None = None
    solve_time: float = 0.0
    solver_status: str = ""
    extras: dict = field(default_factory=dict)


def plateqp_version() -> str:
    """The version of an in-house backend: plateqp's own."""
    try:
        from importlib.metadata import version as _version

        return f"plateqp {_version('plateqp')}"
    except Exception:  # not installed as a distribution
        return "plateqp"


class Backend:
    """The one shape of a backend: every backend is an instance of a subclass of this class.

    A backend module defines ``backends() -> list[Backend]``; the registry
    (:mod:`plateqp.backends`) lists the module in one line. The capabilities are declared as
    class (or instance) attributes, and callers read them instead of lists of names:

    ``name``
        registry name.
    ``accepts``
        the problem kinds it takes, a subset of ``{"qp", "lcp"}``.
    ``formulations``
        the names of the standard forms (``"primal"``, ``"condensed"``, ``"dual"``) it may be
        given, where it is built for some only; ``None``: every form its ``accepts`` allows.
    ``exact``
        a direct method: its answer is exact up to rounding at every accuracy (the accuracy
        sets only its acceptance tolerances).
    ``warm_start``
        takes ``options["active"]``, a bool array, as its first active set, and returns its
        final one in ``extras["active"]`` (in the problem's own terms) for the next solve.
    ``definite``
        needs ``P`` positive definite (it factorises ``P``): a QP whose ``P`` is only
        semidefinite (``QP.singular``) is refused.

    Methods: ``available()`` (importable here), ``version()``, and
    ``solve(problem, accuracy, options) → RawSolution``. Options are the solver's own and
    override the accuracy preset; an option the backend does not know is a
    :class:`~plateqp.errors.ProblemError` (:func:`check_options`, :func:`rejected_option`).
    """

    name: str = ""
    accepts: frozenset[str] = frozenset()
    formulations: tuple[str, ...] | None = None
    exact: bool = False
    warm_start: bool = False
    definite: bool = False

    def available(self) -> bool:
        return True

    def version(self) -> str | None:
        return plateqp_version()

    def solve(self, problem: QP | LCP, accuracy: str | float | Accuracy = "default",
              options: dict | None = None) -> RawSolution:
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"


def check_options(backend: str, options: dict | None, known) -> dict:
    """A copy of ``options``; a ProblemError naming the unknown keys (and the known ones)."""
    options = dict(options or {})
    unknown = sorted(set(options) - set(known))
    if unknown:
        raise ProblemError(f"unknown option(s) {unknown} for backend {backend}; known: {list(known)}")
    return options


def rejected_option(backend: str, options: dict | None, exn: BaseException) -> ProblemError | None:
    """For a solver that checks its own options: if its complaint ``exn`` names one of the
    options the user gave (an unknown setting, or a bad value of one), the ProblemError to
    raise instead of a solver failure; else None (the complaint is about something else)."""
    text = str(exn)
    named = [k for k in (options or {}) if re.search(rf"(?<![A-Za-z0-9_]){re.escape(str(k))}(?![A-Za-z0-9_])", text)]
    if not named:
        return None
    return ProblemError(f"backend {backend} rejected option(s) {named}: {one_line(exn)}")


def one_line(exn: BaseException) -> str:
    """The first line of an exception's message (its type's name if it has none), for a
    one-line error that wraps it."""
    text = str(exn).strip()
    return text.splitlines()[0] if text else type(exn).__name__


def via_qp(problem: QP | LCP, solve_qp) -> RawSolution:
    """Solve a QP with ``solve_qp``, or an LCP with symmetric M as its QP (x = z, w = M z + q).

    Shared by the QP backends: an LCP with non-symmetric M is not the KKT system of a QP,
    so a QP backend refuses it with a SolverError.
    """
    if not isinstance(problem, LCP):
        return solve_qp(problem)
    M = problem.M
    if not np.allclose(M, M.T, rtol=1e-10, atol=1e-12 * max(1.0, np.abs(M).max())):
        raise SolverError("a QP backend solves an LCP only for symmetric M")
    out = solve_qp(problem.as_qp())
    if out.x is not None:
        out.w = M @ out.x + problem.q
    return out
