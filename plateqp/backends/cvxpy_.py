"""cvxpy backends: ``cvxpy`` (cvxpy's own choice of solver) and ``cvxpy:NAME``.

The QP is written as a cvxpy problem::

    minimise   ½ xᵀ psd_wrap(P) x + qᵀ x
    subject to G x ≤ h,  A x == b,  x[i] ≥ lb[i],  x[j] ≤ ub[j]   (finite bounds only)

Multiplier signs, checked on problems with known answers (tests/backends/test_backends_qp.py):
cvxpy's ``dual_value`` is ≥ 0 for ``G x ≤ h`` (our ``z`` as is); for ``A x == b`` it is
the ``y`` of ``… + yᵀ(A x − b)`` (our ``y`` as is); for ``x ≥ lb`` it is ≥ 0 (our
``z_box`` is its negative) and for ``x ≤ ub`` it is ≥ 0 (our ``z_box`` as is).

The solve is split as cvxpy documents for ``Problem.get_problem_data``: compile, call
the solver (timed alone), unpack.
"""

from __future__ import annotations

import importlib.metadata
import time
import warnings

import numpy as np
import scipy.sparse as sp

from ..errors import SolverError
from . import clarabel_, osqp_
from .base import ACCURACIES, LCP, QP, Backend, RawSolution, Status, accuracy_tol, one_line, rejected_option, via_qp
from .base import preset as preset_for

try:
    import cvxpy as cp
except ImportError:  # the module must import without the solver
    cp = None

PREFIX = "cvxpy"

# OSQP and Clarabel take the presets of osqp_.py / clarabel_.py (reasons there), without
# ``verbose``, which cvxpy passes itself.
_OSQP = osqp_.presets_for_wrappers()
_CLARABEL = {a: dict(clarabel_.ACCURACY[a]) for a in ACCURACIES}

#: Our presets in each solver's own option names, as cvxpy passes them through.
#: A solver missing here gets its defaults (recorded as ``preset = "defaults"``).
ACCURACY: dict[str, dict[str, dict]] = {
    "OSQP": _OSQP,
    "CLARABEL": _CLARABEL,
    # first-order: 1e-11 is out of reach, 1e-9 with many iterations is its "high"
    "SCS": {
        "low": {"eps_abs": 1e-5, "eps_rel": 1e-5},
        "default": {"eps_abs": 1e-7, "eps_rel": 1e-7, "max_iters": 200_000},
        "high": {"eps_abs": 1e-9, "eps_rel": 1e-9, "max_iters": 500_000},
    },
    # through cvxpy's SOC form ECOS stalls at ~1e-9: asked 1e-10 it says optimal_inaccurate
    # with the same x, so 1e-9 is its "high"
    "ECOS": {
        "low": {"abstol": 1e-5, "reltol": 1e-5, "feastol": 1e-5},
        "default": {"abstol": 1e-8, "reltol": 1e-8, "feastol": 1e-8},
        "high": {"abstol": 1e-9, "reltol": 1e-9, "feastol": 1e-9, "max_iters": 200},
    },
    # CVXOPT diverged past its solution at 1e-10 on a 2-variable test QP: 1e-9 is "high"
    "CVXOPT": {
        "low": {"abstol": 1e-5, "reltol": 1e-5, "feastol": 1e-5},
        "default": {"abstol": 1e-8, "reltol": 1e-8, "feastol": 1e-8},
        "high": {"abstol": 1e-9, "reltol": 1e-9, "feastol": 1e-9, "max_iters": 200},
    },
    "PIQP": {
        "low": {"eps_abs": 1e-5, "eps_rel": 1e-5, "eps_duality_gap_abs": 1e-5, "eps_duality_gap_rel": 1e-5},
        "default": {
            "eps_abs": 1e-8,
            "eps_rel": 1e-9,
            "eps_duality_gap_abs": 1e-8,
            "eps_duality_gap_rel": 1e-9,
        },
        "high": {
            "eps_abs": 1e-11,
            "eps_rel": 1e-11,
            "eps_duality_gap_abs": 1e-11,
            "eps_duality_gap_rel": 1e-11,
            "max_iter": 500,
        },
    },
    # cvxpy's PROXQP interface passes only eps_abs, eps_rel, max_iter, rho, mu_eq, mu_in
    # and "backend" (default "dense": it densifies P); ProxQP's duality-gap check cannot be
    # turned on through it (qpsolvers:proxqp does).
    "PROXQP": {
        "low": {"eps_abs": 1e-5, "eps_rel": 0.0},
        "default": {"eps_abs": 1e-8, "eps_rel": 0.0},
        "high": {"eps_abs": 1e-11, "eps_rel": 0.0},
    },
    "QPALM": {
        "low": {"eps_abs": 1e-5, "eps_rel": 1e-5},
        "default": {"eps_abs": 1e-8, "eps_rel": 1e-8},
        "high": {"eps_abs": 1e-10, "eps_rel": 1e-10},
    },
    # active-set solvers: the tolerances below are feasibility tolerances of the active set
    "DAQP": {
        "low": {"primal_tol": 1e-5},
        "default": {"primal_tol": 1e-6},
        "high": {"primal_tol": 1e-10},
    },
    "HIGHS": {
        "low": {"primal_feasibility_tolerance": 1e-5, "dual_feasibility_tolerance": 1e-5},
        "default": {"primal_feasibility_tolerance": 1e-7, "dual_feasibility_tolerance": 1e-7},
        "high": {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10},
    },
}

#: Installed cvxpy solvers we do not register although they accept a QP, and why.
SKIP: dict[str, str] = {
    "ECOS_BB": "branch-and-bound wrapper of ECOS for mixed-integer problems; on a QP it is ECOS",
}

#: Python distribution of each solver, for version().
_DIST = {"HIGHS": "highspy", "PROXQP": "proxsuite"}

#: cvxpy status → our status.
STATUS_MAP: dict[str, Status] = {
    "optimal": Status.OPTIMAL,
    "optimal_inaccurate": Status.INACCURATE,
    "infeasible": Status.INFEASIBLE,
    "infeasible_inaccurate": Status.INFEASIBLE,
    "unbounded": Status.UNBOUNDED,
    "unbounded_inaccurate": Status.UNBOUNDED,
    "infeasible_or_unbounded": Status.ERROR,  # cannot tell which: let the caller decide
    "user_limit": Status.MAX_ITER,
    "solver_error": Status.ERROR,
}


def qp_solvers() -> list[str]:
    """Installed cvxpy solvers that take a convex QP (natively or as a second-order cone problem)."""
    if cp is None:
        return []
    from cvxpy.constraints import SOC
    from cvxpy.reductions.solvers import defines

    out = []
    for name in cp.installed_solvers():
        conic = defines.SOLVER_MAP_CONIC.get(name)
        takes_qp = name in defines.SOLVER_MAP_QP or (conic is not None and SOC in conic.SUPPORTED_CONSTRAINTS)
        if takes_qp and name not in SKIP:
            out.append(name)
    return out


def _build(qp: QP):
    x = cp.Variable(qp.n)
    P = sp.csc_matrix(qp.P) if sp.issparse(qp.P) else np.asarray(qp.P, dtype=float)
    objective = cp.Minimize(0.5 * cp.quad_form(x, cp.psd_wrap(P)) + qp.q @ x)
    cons: dict[str, object] = {}
    if qp.G is not None:
        cons["G"] = qp.G @ x <= qp.h
    if qp.A is not None:
        cons["A"] = qp.A @ x == qp.b
    ilb = np.flatnonzero(np.isfinite(qp.lb)) if qp.lb is not None else np.zeros(0, dtype=int)
    iub = np.flatnonzero(np.isfinite(qp.ub)) if qp.ub is not None else np.zeros(0, dtype=int)
    if ilb.size:
        cons["lb"] = x[ilb] >= qp.lb[ilb]
    if iub.size:
        cons["ub"] = x[iub] <= qp.ub[iub]
    return cp.Problem(objective, list(cons.values())), x, cons, ilb, iub


def solve_qp(
    qp: QP, solver: str | None = None, accuracy: str = "default", options: dict | None = None
) -> RawSolution:
    """Solve a :class:`QP` through cvxpy with ``solver`` (None: cvxpy's choice)."""
    if cp is None:
        raise SolverError("cvxpy backends are not installed (pip install cvxpy)")
    accuracy_tol(accuracy)  # a clear error for a bad accuracy
    name = PREFIX if solver is None else f"{PREFIX}:{solver}"
    prob, x, cons, ilb, iub = _build(qp)
    try:
        used = solver if solver is not None else prob.get_problem_data(solver=None)[1].solver.name()
        table = ACCURACY.get(used)
        preset = preset_for(table, accuracy) if table else {}
        opts = {**preset, **(options or {})}
        # some interfaces read the options again when unpacking: compile with them
        with warnings.catch_warnings():  # an indefinite P is said by the error below, not twice
            warnings.filterwarnings("ignore", message="Forming a nonconvex expression")
            data, chain, inverse_data = prob.get_problem_data(solver=used, solver_opts=dict(opts))
    except (cp.error.SolverError, ValueError, TypeError, AttributeError, KeyError) as exn:
        # e.g. ECOS and CVXOPT take P through a factorisation of it (a cone program), and
        # cvxpy raises ValueError("... indefinite ...") when P is indefinite by rounding
        raise rejected_option(name, options, exn) or SolverError(
            f"cvxpy cannot pass this problem to {solver or 'its default solver'}: {one_line(exn)}") from exn
    except (MemoryError, OverflowError) as exn:  # e.g. CVXOPT's index overflow at 128² (n = 49k)
        raise SolverError(f"cvxpy/{solver or 'default'} cannot hold this problem (n = {qp.n}): {exn}; "
                          "use a sparse backend (osqp, clarabel, pdas) or the condensed formulation") from exn
    try:
        t0 = time.perf_counter()
        # solve_via_data may write its defaults into the dict it gets: give it a copy
        raw = chain.solve_via_data(prob, data, False, False, dict(opts))
        solve_time = time.perf_counter() - t0
    except cp.error.SolverError as exn:
        if (bad := rejected_option(name, options, exn)) is not None:
            raise bad from exn
        return RawSolution(
            status=Status.ERROR,
            solver_status=f"solver_error: {exn}",
            extras={"solver": used, "preset": preset if table else "defaults", "options": opts},
        )
    except (ValueError, TypeError, AttributeError, KeyError) as exn:  # bad option, wrong types
        raise rejected_option(name, options, exn) or SolverError(
            f"cvxpy/{used} failed: {one_line(exn)}") from exn
    except (MemoryError, OverflowError) as exn:  # DAQP and PROXQP densify P: 286 GiB at 256²
        raise SolverError(f"cvxpy/{used} cannot hold this problem (n = {qp.n}): {exn}; "
                          "use a sparse backend (osqp, clarabel, pdas) or the condensed formulation") from exn

    extras = {"solver": used, "preset": preset if table else "defaults", "options": opts}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "solution may be inaccurate": our status says so
        try:
            prob.unpack_results(raw, chain, inverse_data)
        except cp.error.SolverError:  # cvxpy raises for the solver_error status
            return RawSolution(
                status=Status.ERROR, solve_time=solve_time, solver_status="solver_error", extras=extras
            )
    status = STATUS_MAP.get(prob.status, Status.ERROR)
    stats = prob.solver_stats
    out = RawSolution(
        status=status,
        iterations=int(stats.num_iters) if stats is not None and stats.num_iters is not None else None,
        solve_time=solve_time,
        solver_status=str(prob.status),
        extras=extras,
    )
    if stats is not None and stats.solve_time is not None:
        extras["solver_reported_time"] = float(stats.solve_time)
    if x.value is None or status in (Status.INFEASIBLE, Status.UNBOUNDED):
        return out
    out.x = np.asarray(x.value, dtype=float).reshape(-1)
    out.obj = float(prob.value) if prob.value is not None and np.isfinite(prob.value) else None

    def dual(key):
        v = cons[key].dual_value if key in cons else None
        return None if v is None else np.asarray(v, dtype=float).reshape(-1)

    out.z = dual("G")
    out.y = dual("A")
    if qp.lb is not None or qp.ub is not None:
        z_box = np.zeros(qp.n)
        lam_lb, lam_ub = dual("lb"), dual("ub")
        if lam_lb is not None:
            z_box[ilb] -= lam_lb  # cvxpy: ≥ 0 on x ≥ lb; ours: ≤ 0 on the lower bound
        if lam_ub is not None:
            z_box[iub] += lam_ub
        missing = (ilb.size and lam_lb is None) or (iub.size and lam_ub is None)
        out.z_box = None if missing else z_box
    return out




def solve(
    problem: QP | LCP, accuracy: str = "default", options: dict | None = None, solver: str | None = None
) -> RawSolution:
    """Solve a QP, or an LCP with symmetric PSD M as its QP (x = z, w = M z + q)."""
    return via_qp(problem, lambda qp: solve_qp(qp, solver, accuracy, options))


class CvxpyBackend(Backend):
    """``cvxpy`` (solver None: cvxpy's choice) or ``cvxpy:NAME``."""

    accepts = frozenset({"qp", "lcp"})

    def __init__(self, solver: str | None = None):
        self.solver = solver
        self.name = PREFIX if solver is None else f"{PREFIX}:{solver}"

    def __repr__(self) -> str:
        return f"CvxpyBackend({self.name!r})"

    def available(self) -> bool:
        if cp is None:
            return False
        return self.solver is None or self.solver in qp_solvers()

    def version(self) -> str | None:
        if cp is None:
            return None
        if self.solver is None:
            return cp.__version__
        dist = _DIST.get(self.solver, self.solver.lower())
        try:
            return f"{cp.__version__} ({self.solver} {importlib.metadata.version(dist)})"
        except importlib.metadata.PackageNotFoundError:
            return cp.__version__

    def solve(self, problem: QP | LCP, accuracy: str = "default", options: dict | None = None) -> RawSolution:
        return solve(problem, accuracy, options, solver=self.solver)


def backends() -> list[CvxpyBackend]:
    """``cvxpy`` and one ``cvxpy:NAME`` per installed QP-capable solver.

    Without cvxpy: one per row of the preset table, all unavailable.
    """
    names = qp_solvers() if cp is not None else list(ACCURACY)
    return [CvxpyBackend(None)] + [CvxpyBackend(n) for n in names]
