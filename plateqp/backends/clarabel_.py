r"""Clarabel backend, called directly.

Clarabel solves

.. math::

    \min_x \tfrac12 x^T P x + q^T x \quad \text{s.t.} \quad C x + s = d, \; s \in K

with dual ``z ∈ K*`` and stationarity ``P x + q + Cᵀ z = 0``. We stack

====================  ==========  ===============  ===================================
rows                  cone        right-hand side  our multiplier
====================  ==========  ===============  ===================================
``A``                 zero        ``b``            ``y = z``
``G``                 nonneg.     ``h``            ``z = z`` (≥ 0)
``-I`` (finite lb)    nonneg.     ``-lb``          ``z_box -= z`` (lower bound: ≤ 0)
``+I`` (finite ub)    nonneg.     ``ub``           ``z_box += z`` (upper bound: ≥ 0)
====================  ==========  ===============  ===================================

so only the lower-bound rows change sign. Infinite bounds get no row.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from ..errors import ProblemError, SolverError
from .base import LCP, QP, Backend, RawSolution, Status, preset, via_qp

try:
    import clarabel
except ImportError:  # the module must import without the solver
    clarabel = None

NAME = "clarabel"

#: Our accuracy presets in Clarabel's setting names ("default" is Clarabel's own default).
ACCURACY: dict[str, dict] = {
    "low": {"tol_gap_abs": 1e-5, "tol_gap_rel": 1e-5, "tol_feas": 1e-5, "tol_ktratio": 1e-4},
    "default": {"tol_gap_abs": 1e-8, "tol_gap_rel": 1e-8, "tol_feas": 1e-8, "tol_ktratio": 1e-6},
    "high": {
        "tol_gap_abs": 1e-11,
        "tol_gap_rel": 1e-11,
        "tol_feas": 1e-11,
        "tol_ktratio": 1e-9,
        "max_iter": 500,
    },
}

#: Clarabel defaults we change for every preset: only printing (it prints by default).
OVERRIDES: dict = {"verbose": False}

#: Clarabel status (``str(SolverStatus)``) → our status.
STATUS_MAP: dict[str, Status] = {
    "Solved": Status.OPTIMAL,
    "AlmostSolved": Status.INACCURATE,
    "PrimalInfeasible": Status.INFEASIBLE,
    "AlmostPrimalInfeasible": Status.INFEASIBLE,
    "DualInfeasible": Status.UNBOUNDED,
    "AlmostDualInfeasible": Status.UNBOUNDED,
    "MaxIterations": Status.MAX_ITER,
    "MaxTime": Status.MAX_ITER,
    "NumericalError": Status.ERROR,
    "InsufficientProgress": Status.ERROR,
    "CallbackTerminated": Status.ERROR,
    "Unsolved": Status.ERROR,
}


def _settings(accuracy: str | float, options: dict | None):
    chosen = {**OVERRIDES, **preset(ACCURACY, accuracy), **(options or {})}
    settings = clarabel.DefaultSettings()
    for key, value in chosen.items():
        try:
            setattr(settings, key, value)
        except (AttributeError, TypeError) as exn:  # an unknown setting, a wrong type
            if key in (options or {}):
                raise ProblemError(f"backend {NAME} rejected option {key}={value!r}: {exn}") from exn
            raise SolverError(f"Clarabel rejected setting {key}={value!r}: {exn}") from exn
    return settings, chosen


def solve_qp(qp: QP, accuracy: str = "default", options: dict | None = None) -> RawSolution:
    """Solve a :class:`QP` with Clarabel; see the module docstring for the multiplier mapping."""
    if clarabel is None:
        raise SolverError("backend 'clarabel' is not installed (pip install clarabel)")
    settings, chosen = _settings(accuracy, options)
    n = qp.n
    meq = 0 if qp.A is None else qp.A.shape[0]
    m = 0 if qp.G is None else qp.G.shape[0]
    ilb = np.flatnonzero(np.isfinite(qp.lb)) if qp.lb is not None else np.zeros(0, dtype=int)
    iub = np.flatnonzero(np.isfinite(qp.ub)) if qp.ub is not None else np.zeros(0, dtype=int)
    eye = sp.identity(n, format="csr")
    blocks, rhs = [], []
    if meq:
        blocks.append(sp.csr_matrix(qp.A))
        rhs.append(qp.b)
    if m:
        blocks.append(sp.csr_matrix(qp.G))
        rhs.append(qp.h)
    if ilb.size:
        blocks.append(-eye[ilb])
        rhs.append(-qp.lb[ilb])
    if iub.size:
        blocks.append(eye[iub])
        rhs.append(qp.ub[iub])
    C = sp.vstack(blocks, format="csc") if blocks else sp.csc_matrix((0, n))
    d = np.concatenate(rhs) if rhs else np.zeros(0)
    cones = []
    if meq:
        cones.append(clarabel.ZeroConeT(meq))
    if m + ilb.size + iub.size:
        cones.append(clarabel.NonnegativeConeT(m + ilb.size + iub.size))
    P = sp.triu(sp.csc_matrix(qp.P), format="csc")  # Clarabel reads the upper triangle

    try:
        solver = clarabel.DefaultSolver(P, qp.q, C, d, cones, settings)
        t0 = time.perf_counter()
        res = solver.solve()
        solve_time = time.perf_counter() - t0
    except (KeyboardInterrupt, SystemExit):
        raise
    except BaseException as exn:  # Rust panics arrive as pyo3's PanicException, a BaseException
        raise SolverError(f"Clarabel failed: {exn}") from exn

    name = str(res.status)
    status = STATUS_MAP.get(name, Status.ERROR)
    out = RawSolution(
        status=status,
        iterations=int(res.iterations),
        solve_time=solve_time,
        solver_status=name,
        extras={
            "r_prim": float(res.r_prim),
            "r_dual": float(res.r_dual),
            "obj_val_dual": float(res.obj_val_dual),
            "clarabel_solve_time": float(res.solve_time),
            "settings": chosen,
        },
    )
    # On infeasibility x and z hold a certificate, not a solution: keep it in extras only.
    if status in (Status.INFEASIBLE, Status.UNBOUNDED):
        out.extras["certificate_x" if status is Status.UNBOUNDED else "certificate_z"] = np.array(
            res.x if status is Status.UNBOUNDED else res.z
        )
        return out
    x = np.array(res.x, dtype=float)
    zc = np.array(res.z, dtype=float)
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(zc))):
        return out
    out.x = x
    out.obj = float(res.obj_val)
    out.y = zc[:meq] if meq else None
    out.z = zc[meq : meq + m] if m else None
    if qp.lb is not None or qp.ub is not None:
        z_box = np.zeros(n)
        k = meq + m
        z_box[ilb] -= zc[k : k + ilb.size]
        z_box[iub] += zc[k + ilb.size :]
        out.z_box = z_box
    return out




def solve(problem: QP | LCP, accuracy: str = "default", options: dict | None = None) -> RawSolution:
    """Solve a QP, or an LCP with symmetric PSD M as its QP (x = z, w = M z + q)."""
    return via_qp(problem, lambda qp: solve_qp(qp, accuracy, options))


class ClarabelBackend(Backend):
    """The ``clarabel`` backend (see :class:`plateqp.backends.base.Backend`): interior point."""

    name = NAME
    accepts = frozenset({"qp", "lcp"})

    def available(self) -> bool:
        return clarabel is not None

    def version(self) -> str | None:
        return getattr(clarabel, "__version__", None) if clarabel is not None else None

    def solve(self, problem: QP | LCP, accuracy: str = "default", options: dict | None = None) -> RawSolution:
        return solve(problem, accuracy, options)


def backends() -> list[ClarabelBackend]:
    return [ClarabelBackend()]
