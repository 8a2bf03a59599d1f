r"""OSQP backend, called directly (osqp ≥ 1.0 API).

OSQP solves

.. math::

    \min_x \tfrac12 x^T P x + q^T x \quad \text{s.t.} \quad l \le C x \le u

and returns one multiplier ``y`` per row of ``C`` with the stationarity
``P x + q + Cᵀ y = 0``: ``y < 0`` where the lower side is active, ``y > 0``
where the upper side is. We stack ``C = [G; A; I]`` with
``l = [-∞; b; lb]`` and ``u = [h; b; ub]``, so OSQP's ``y`` splits into our
``z`` (≥ 0, upper side only), ``y`` (equality rows) and ``z_box`` (same sign
rule as ours) with no sign change.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from ..errors import ProblemError, SolverError
from .base import ACCURACIES, LCP, QP, Backend, RawSolution, Status, preset, rejected_option, via_qp

try:
    import osqp
except ImportError:  # the module must import without the solver
    osqp = None

NAME = "osqp"

#: Our accuracy presets in OSQP's own setting names.
ACCURACY: dict[str, dict] = {
    "low": {"eps_abs": 1e-5, "eps_rel": 1e-5, "polishing": False},
    "default": {"eps_abs": 1e-8, "eps_rel": 1e-8, "polishing": True},
    "high": {"eps_abs": 1e-11, "eps_rel": 1e-11, "polishing": True},
}

#: OSQP defaults we change for every preset, in one place. Why: the contact QPs are hard
#: for OSQP; at its default eps 1e-3, max_iter 4000 and no polishing it returned reactions
#: ≈ 1e-21 and called them solved. ACCURACY tightens eps and turns polishing on; here ADMM
#: gets room to reach those tolerances, and printing is off. adaptive_rho is already
#: OSQP's default: it is listed so that the setting we rely on is stated.
OVERRIDES: dict = {"max_iter": 200_000, "adaptive_rho": True, "verbose": False}

#: OSQP status (``SolverStatus`` member name) → our status.
STATUS_MAP: dict[str, Status] = {
    "OSQP_SOLVED": Status.OPTIMAL,
    "OSQP_SOLVED_INACCURATE": Status.INACCURATE,
    "OSQP_PRIMAL_INFEASIBLE": Status.INFEASIBLE,
    "OSQP_PRIMAL_INFEASIBLE_INACCURATE": Status.INFEASIBLE,
    "OSQP_DUAL_INFEASIBLE": Status.UNBOUNDED,
    "OSQP_DUAL_INFEASIBLE_INACCURATE": Status.UNBOUNDED,
    "OSQP_MAX_ITER_REACHED": Status.MAX_ITER,
    "OSQP_TIME_LIMIT_REACHED": Status.MAX_ITER,
    "OSQP_NON_CVX": Status.ERROR,
    "OSQP_SIGINT": Status.ERROR,
    "OSQP_UNSOLVED": Status.ERROR,
}


def _settings(accuracy: str | float, options: dict | None) -> dict:
    return {**OVERRIDES, **preset(ACCURACY, accuracy), **(options or {})}


def _finite_or_none(v) -> np.ndarray | None:
    if v is None:
        return None
    a = np.asarray(v, dtype=float)
    return a.copy() if np.all(np.isfinite(a)) else None



def presets_for_wrappers() -> dict[str, dict]:
    """Our OSQP presets as cvxpy or qpsolvers pass them on (they set ``verbose`` themselves)."""
    return {a: {**{k: v for k, v in OVERRIDES.items() if k != "verbose"}, **ACCURACY[a]} for a in ACCURACIES}

def solve_qp(qp: QP, accuracy: str = "default", options: dict | None = None) -> RawSolution:
    """Solve a :class:`QP` with OSQP; see the module docstring for the multiplier mapping."""
    if osqp is None:
        raise SolverError("backend 'osqp' is not installed (pip install osqp)")
    settings = _settings(accuracy, options)
    n = qp.n
    blocks, lo, up = [], [], []
    m = 0 if qp.G is None else qp.G.shape[0]
    meq = 0 if qp.A is None else qp.A.shape[0]
    if m:
        blocks.append(sp.csc_matrix(qp.G))
        lo.append(np.full(m, -np.inf))
        up.append(qp.h)
    if meq:
        blocks.append(sp.csc_matrix(qp.A))
        lo.append(qp.b)
        up.append(qp.b)
    has_box = qp.lb is not None or qp.ub is not None
    if has_box:
        blocks.append(sp.identity(n, format="csc"))
        lo.append(qp.lb if qp.lb is not None else np.full(n, -np.inf))
        up.append(qp.ub if qp.ub is not None else np.full(n, np.inf))
    C = sp.vstack(blocks, format="csc") if blocks else sp.csc_matrix((0, n))
    lo_v = np.concatenate(lo) if lo else np.zeros(0)
    up_v = np.concatenate(up) if up else np.zeros(0)
    P = sp.triu(sp.csc_matrix(qp.P), format="csc")  # OSQP reads the upper triangle

    solver = osqp.OSQP()
    try:
        solver.setup(P, qp.q, C, lo_v, up_v, **settings)
        t0 = time.perf_counter()
        res = solver.solve(raise_error=False)
        solve_time = time.perf_counter() - t0
    except osqp.OSQPException as exn:  # carries an osqp error code, e.g. 1 = data validation
        code = exn.args[0] if exn.args else None
        what = osqp.SolverError(code).name if code in set(osqp.SolverError) else repr(exn)
        if what == "OSQP_SETTINGS_VALIDATION_ERROR" and options:
            raise ProblemError(f"OSQP rejected its settings (options given: {sorted(options)}): {what}") from exn
        raise SolverError(f"OSQP rejected the problem or settings: {what}") from exn
    except (ValueError, TypeError) as exn:  # an unknown setting, a wrong type
        raise rejected_option(NAME, options, exn) or SolverError(f"OSQP failed: {exn}") from exn

    info = res.info
    name = osqp.SolverStatus(info.status_val).name
    status = STATUS_MAP.get(name, Status.ERROR)
    # On infeasibility OSQP leaves its last (diverging) iterate in x and y: drop it.
    certificate = status in (Status.INFEASIBLE, Status.UNBOUNDED)
    x = None if certificate else _finite_or_none(res.x)
    ycat = None if certificate else _finite_or_none(res.y)
    out = RawSolution(
        status=status,
        x=x,
        obj=float(info.obj_val) if x is not None and np.isfinite(info.obj_val) else None,
        iterations=int(info.iter),
        solve_time=solve_time,
        solver_status=str(info.status),
        extras={
            "status_polish": int(info.status_polish),
            "prim_res": float(info.prim_res),
            "dual_res": float(info.dual_res),
            "osqp_solve_time": float(info.solve_time),
            "setup_time": float(info.setup_time),
            "settings": settings,
        },
    )
    if ycat is not None:
        out.z = ycat[:m] if m else None
        out.y = ycat[m : m + meq] if meq else None
        out.z_box = ycat[m + meq :] if has_box else None
    if status is Status.INFEASIBLE:
        out.extras["prim_inf_cert"] = _finite_or_none(res.prim_inf_cert)
    if status is Status.UNBOUNDED:
        out.extras["dual_inf_cert"] = _finite_or_none(res.dual_inf_cert)
    return out




def solve(problem: QP | LCP, accuracy: str = "default", options: dict | None = None) -> RawSolution:
    """Solve a QP, or an LCP with symmetric PSD M as its QP (x = z, w = M z + q)."""
    return via_qp(problem, lambda qp: solve_qp(qp, accuracy, options))


class OSQPBackend(Backend):
    """The ``osqp`` backend (see :class:`plateqp.backends.base.Backend`): iterative (ADMM)."""

    name = NAME
    accepts = frozenset({"qp", "lcp"})

    def available(self) -> bool:
        return osqp is not None

    def version(self) -> str | None:
        return getattr(osqp, "__version__", None) if osqp is not None else None

    def solve(self, problem: QP | LCP, accuracy: str = "default", options: dict | None = None) -> RawSolution:
        return solve(problem, accuracy, options)


def backends() -> list[OSQPBackend]:
    return [OSQPBackend()]
