"""qpsolvers backends: ``qpsolvers:NAME`` for every solver in ``qpsolvers.available_solvers``.

qpsolvers uses our problem form and our multiplier signs (ours are copied from it):
``z ≥ 0`` for ``G x ≤ h``, ``y`` for ``A x = b``, ``z_box < 0`` on an active lower bound,
``> 0`` on an active upper bound. The tests check them solver by solver.

qpsolvers' ``Solution.found`` is its own verdict (and does not test multiplier signs);
we do not use it when the solver tells more: each solver's own status, read from
``Solution.extras``, goes through that solver's row of :data:`STATUS_MAP`. Where
qpsolvers keeps no status (daqp, highs, quadprog) ``found`` is all there is.
"""

from __future__ import annotations

import importlib.metadata
import time
import warnings

import numpy as np
import scipy.sparse as sp

from ..errors import ProblemError, SolverError
from . import clarabel_, osqp_
from .base import ACCURACIES, LCP, QP, Backend, RawSolution, Status, accuracy_tol, one_line, rejected_option, via_qp
from .base import preset as preset_for

try:
    import qpsolvers
except ImportError:  # the module must import without the solver
    qpsolvers = None

PREFIX = "qpsolvers"

# OSQP and Clarabel take the presets of osqp_.py / clarabel_.py (reasons there), without
# ``verbose``, which qpsolvers sets itself.
_OSQP = osqp_.presets_for_wrappers()
_CLARABEL = {a: dict(clarabel_.ACCURACY[a]) for a in ACCURACIES}

#: Our presets in each solver's own option names (qpsolvers passes them through).
#: Solvers missing here (quadprog has no tolerance option) get their defaults, recorded
#: as ``preset = "defaults"``.
ACCURACY: dict[str, dict[str, dict]] = {
    "osqp": _OSQP,
    "clarabel": _CLARABEL,
    # CVXOPT diverged past its solution at 1e-10 on a 2-variable test QP: 1e-9 is "high"
    "cvxopt": {
        "low": {"abstol": 1e-5, "reltol": 1e-5, "feastol": 1e-5},
        "default": {"abstol": 1e-8, "reltol": 1e-8, "feastol": 1e-8},
        "high": {"abstol": 1e-9, "reltol": 1e-9, "feastol": 1e-9, "maxiters": 200},
    },
    "ecos": {
        "low": {"abstol": 1e-5, "reltol": 1e-5, "feastol": 1e-5},
        "default": {"abstol": 1e-8, "reltol": 1e-8, "feastol": 1e-8},
        "high": {"abstol": 1e-10, "reltol": 1e-10, "feastol": 1e-10, "max_iters": 200},
    },
    # first-order: 1e-11 is out of reach, 1e-9 with many iterations is its "high"
    "scs": {
        "low": {"eps_abs": 1e-5, "eps_rel": 1e-5},
        "default": {"eps_abs": 1e-7, "eps_rel": 1e-7, "max_iters": 200_000},
        "high": {"eps_abs": 1e-9, "eps_rel": 1e-9, "max_iters": 500_000},
    },
    "piqp": {
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
    # ProxQP does not check the duality gap by default: its sparse backend then called a
    # point with residuals < 1e-11 but x off by 7e-7 "solved". We turn the check on.
    "proxqp": {
        "low": {"eps_abs": 1e-5, "eps_rel": 0.0, "check_duality_gap": True, "eps_duality_gap_abs": 1e-5},
        "default": {"eps_abs": 1e-8, "eps_rel": 0.0, "check_duality_gap": True, "eps_duality_gap_abs": 1e-8},
        "high": {"eps_abs": 1e-11, "eps_rel": 0.0, "check_duality_gap": True, "eps_duality_gap_abs": 1e-11},
    },
    "qpalm": {
        "low": {"eps_abs": 1e-5, "eps_rel": 1e-5},
        "default": {"eps_abs": 1e-8, "eps_rel": 1e-8},
        "high": {"eps_abs": 1e-10, "eps_rel": 1e-10},
    },
    # active-set solvers: these are the feasibility tolerances of the active set
    "daqp": {
        "low": {"primal_tol": 1e-5},
        "default": {"primal_tol": 1e-6},
        "high": {"primal_tol": 1e-10},
    },
    "highs": {
        "low": {"primal_feasibility_tolerance": 1e-5, "dual_feasibility_tolerance": 1e-5},
        "default": {"primal_feasibility_tolerance": 1e-7, "dual_feasibility_tolerance": 1e-7},
        "high": {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10},
    },
}

#: Python distribution of each solver, for version().
_DIST = {"highs": "highspy", "proxqp": "proxsuite"}

#: Per solver: its status (as :func:`_solver_status` spells it) → our status. Where
#: qpsolvers keeps no status the key is "found" / "not found".
_FOUND = {"found": Status.OPTIMAL, "not found": Status.ERROR}
STATUS_MAP: dict[str, dict[str, Status]] = {
    "osqp": osqp_.STATUS_MAP,
    "clarabel": clarabel_.STATUS_MAP,
    "cvxopt": {
        "optimal": Status.OPTIMAL,
        "primal infeasible": Status.INFEASIBLE,
        "dual infeasible": Status.UNBOUNDED,
        "unknown": Status.ERROR,  # max iterations or a singular KKT system
    },
    "ecos": {  # exitFlag
        "0": Status.OPTIMAL,
        "10": Status.INACCURATE,
        "1": Status.INFEASIBLE,
        "11": Status.INFEASIBLE,
        "2": Status.UNBOUNDED,
        "12": Status.UNBOUNDED,
        "-1": Status.MAX_ITER,
        "-2": Status.ERROR,
        "-3": Status.ERROR,
        "-4": Status.ERROR,
        "-7": Status.ERROR,
    },
    "scs": {  # status_val
        "1": Status.OPTIMAL,
        "2": Status.INACCURATE,
        "-2": Status.INFEASIBLE,
        "-7": Status.INFEASIBLE,
        "-1": Status.UNBOUNDED,
        "-6": Status.UNBOUNDED,
        "-3": Status.ERROR,
        "-4": Status.ERROR,
        "-5": Status.ERROR,
        "0": Status.ERROR,
    },
    "piqp": {
        "PIQP_SOLVED": Status.OPTIMAL,
        "PIQP_PRIMAL_INFEASIBLE": Status.INFEASIBLE,
        "PIQP_DUAL_INFEASIBLE": Status.UNBOUNDED,
        "PIQP_MAX_ITER_REACHED": Status.MAX_ITER,
        "PIQP_NUMERICS": Status.ERROR,
        "PIQP_UNSOLVED": Status.ERROR,
        "PIQP_INVALID_SETTINGS": Status.ERROR,
    },
    "proxqp": {
        "PROXQP_SOLVED": Status.OPTIMAL,
        "PROXQP_PRIMAL_INFEASIBLE": Status.INFEASIBLE,
        "PROXQP_SOLVED_CLOSEST_PRIMAL_FEASIBLE": Status.INFEASIBLE,
        "PROXQP_DUAL_INFEASIBLE": Status.UNBOUNDED,
        "PROXQP_MAX_ITER_REACHED": Status.MAX_ITER,
        "PROXQP_NOT_RUN": Status.ERROR,
    },
    "qpalm": {
        "solved": Status.OPTIMAL,
        "primal infeasible": Status.INFEASIBLE,
        "dual infeasible": Status.UNBOUNDED,
        "maximum iterations reached": Status.MAX_ITER,
        "time limit exceeded": Status.MAX_ITER,
        "dual terminated": Status.ERROR,
        "user cancelled": Status.ERROR,
        "unsolved": Status.ERROR,
        "error": Status.ERROR,
    },
    # quadprog's only failure qpsolvers lets pass silently is "constraints are
    # inconsistent, no solution"; any other ValueError it turns into a warning.
    "quadprog": {"found": Status.OPTIMAL, "no solution": Status.INFEASIBLE, "not found": Status.ERROR},
    "daqp": _FOUND,
    "highs": _FOUND,
}


def _name(v) -> str:
    """An enum member's name (``Status.PIQP_SOLVED`` → ``PIQP_SOLVED``), else ``str``."""
    return getattr(v, "name", None) or str(v).rsplit(".", 1)[-1]


#: Keywords qpsolvers itself takes besides the solver's settings (``solve_problem`` and, per
#: solver, its wrapper's own arguments).
_WRAPPER_KEYWORDS = {"initvals", "verbose"}
_SOLVER_KEYWORDS = {"piqp": {"backend"}}


def _dropped_settings(solver: str, options: dict | None) -> list[str]:
    """The options that qpsolvers would drop without a word: its piqp and qpalm wrappers set
    each keyword on the solver's settings object and skip those it lacks (a warning only when
    verbose). Their settings objects list what they take; other solvers complain themselves."""
    if not options or solver not in ("piqp", "qpalm"):
        return []
    module = importlib.import_module(solver)
    settings = module.SparseSolver().settings if solver == "piqp" else module.Settings()
    known = {a for a in dir(settings) if not a.startswith("_")} | _WRAPPER_KEYWORDS | _SOLVER_KEYWORDS.get(solver, set())
    return sorted(set(options) - known)


def _solver_status(solver: str, sol, caught: list[str]) -> tuple[str, int | None]:
    """The solver's own status and iteration count, as far as qpsolvers kept them."""
    e = sol.extras if isinstance(sol.extras, dict) else {}
    info = e.get("info")
    if solver == "osqp" and info is not None:
        return osqp_.osqp.SolverStatus(info.status_val).name, int(info.iter)
    if solver == "clarabel" and "status" in e:
        return str(e["status"]), None
    if solver == "cvxopt" and "status" in e:
        return str(e["status"]), e.get("iterations")
    if solver == "ecos" and "exitFlag" in e:
        return str(e["exitFlag"]), e.get("iter")
    if solver == "scs" and "status_val" in e:
        return str(e["status_val"]), e.get("iter")
    if solver in ("piqp", "proxqp", "qpalm") and info is not None:
        return _name(info.status), int(info.iter)
    if solver == "quadprog":
        if sol.found:
            it = e.get("iterations")
            return "found", int(np.atleast_1d(it)[0]) if it is not None else None
        return ("not found" if any("quadprog raised" in w for w in caught) else "no solution"), None
    return ("found" if sol.found else "not found"), None


def _matrices(qp: QP, solver: str):
    """P, G, A in the storage the solver takes: all CSC for sparse-capable solvers given a
    sparse P or for sparse-only ones, dense arrays otherwise."""
    sparse_ok = solver in qpsolvers.sparse_solvers
    dense_ok = solver in qpsolvers.dense_solvers
    # A dense-only solver (quadprog, daqp, ecos here) cannot take a sparse matrix at all:
    # densifying is the price of using it, paid here and nowhere else.
    use_sparse = sparse_ok and (qp.sparse or not dense_ok)
    if not use_sparse:
        rows = qp.n + sum(0 if M is None else M.shape[0] for M in (qp.G, qp.A))
        need = 8.0 * qp.n * rows
        if need > DENSE_BYTES_MAX:
            raise SolverError(f"qpsolvers/{solver} takes dense matrices only: this problem (n = {qp.n}) would "
                              f"need {need / 2**30:.0f} GiB; use a sparse backend (osqp, clarabel, pdas) or "
                              "the condensed formulation")

    def conv(M):
        if M is None:
            return None
        if use_sparse:
            return sp.csc_matrix(M)
        return M.toarray() if sp.issparse(M) else np.asarray(M, dtype=float)

    return conv(qp.P), conv(qp.G), conv(qp.A)


#: Densifying for a dense-only solver (quadprog, daqp, ecos here) is refused above this many bytes
#: of matrices: at 256² the primal's P alone would be 286 GiB (a MemoryError, or minutes of swap).
DENSE_BYTES_MAX = 2.0 * 2**30

#: Solvers that qpsolvers refuses to give infinite bounds: their finite bounds go into G.
FINITE_BOUNDS_ONLY = frozenset({"ecos"})


def _bounds_as_rows(qp: QP):
    """``qp`` with its finite bounds appended to G as rows ``-x ≤ -lb``, ``x ≤ ub``, and
    the map from that QP's ``z`` back to ours: ``(z, z_box)``."""
    n = qp.n
    m = 0 if qp.G is None else qp.G.shape[0]
    ilb = np.flatnonzero(np.isfinite(qp.lb)) if qp.lb is not None else np.zeros(0, dtype=int)
    iub = np.flatnonzero(np.isfinite(qp.ub)) if qp.ub is not None else np.zeros(0, dtype=int)
    eye = sp.identity(n, format="csr")
    blocks = ([sp.csr_matrix(qp.G)] if m else []) + [-eye[ilb], eye[iub]]
    G = sp.vstack(blocks, format="csr")
    lbs = qp.lb[ilb] if qp.lb is not None else np.zeros(0)
    ubs = qp.ub[iub] if qp.ub is not None else np.zeros(0)
    h = np.concatenate(([qp.h] if m else []) + [-lbs, ubs])
    moved = QP(P=qp.P, q=qp.q, G=G if qp.sparse else G.toarray(), h=h, A=qp.A, b=qp.b)

    def split(z_all):
        z_box = np.zeros(n)
        z_box[ilb] -= z_all[m : m + ilb.size]
        z_box[iub] += z_all[m + ilb.size :]
        return (z_all[:m] if m else None), z_box

    return moved, split


def solve_qp(qp: QP, solver: str, accuracy: str = "default", options: dict | None = None) -> RawSolution:
    """Solve a :class:`QP` with qpsolvers' ``solver``."""
    if qpsolvers is None:
        raise SolverError("qpsolvers backends are not installed (pip install qpsolvers)")
    if solver not in qpsolvers.available_solvers:
        raise SolverError(f"qpsolvers has no solver {solver!r} here; it has {qpsolvers.available_solvers}")
    accuracy_tol(accuracy)  # a clear error for a bad accuracy
    if dropped := _dropped_settings(solver, options):
        raise ProblemError(f"unknown option(s) {dropped} for backend {PREFIX}:{solver} (not settings of {solver})")
    table = ACCURACY.get(solver)
    preset = preset_for(table, accuracy) if table else {}
    opts = {**preset, **(options or {})}
    has_box = qp.lb is not None or qp.ub is not None
    infinite = any(v is not None and not np.all(np.isfinite(v)) for v in (qp.lb, qp.ub))
    original, split = qp, None
    if solver in FINITE_BOUNDS_ONLY and infinite:
        qp, split = _bounds_as_rows(qp)
    P, G, A = _matrices(qp, solver)
    problem = qpsolvers.Problem(P, qp.q, G, qp.h, A, qp.b, qp.lb, qp.ub)
    with warnings.catch_warnings(record=True) as caught_w:
        warnings.simplefilter("always")
        try:
            t0 = time.perf_counter()
            sol = qpsolvers.solve_problem(problem, solver=solver, **opts)
            wall = time.perf_counter() - t0
        except qpsolvers.SolverError as exn:  # the solver failed on this problem
            if (bad := rejected_option(f"{PREFIX}:{solver}", options, exn)) is not None:
                raise bad from exn
            return RawSolution(
                status=Status.ERROR,
                solver_status=f"SolverError: {exn}",
                extras={"preset": preset if table else "defaults", "options": opts},
            )
        except qpsolvers.ProblemError as exn:  # e.g. quadprog and ecos need P positive definite
            why = (f" ({solver} needs P positive definite; this P is only semidefinite: a form of the problem "
                   "whose P is definite, or a solver that takes a semidefinite P)"
                   if solver in DEFINITE_ONLY and "definite" in str(exn) else "")
            raise SolverError(f"qpsolvers/{solver} rejected the problem: {exn}{why}") from exn
        except (qpsolvers.ParamError, TypeError, ValueError, AttributeError) as exn:
            raise rejected_option(f"{PREFIX}:{solver}", options, exn) or SolverError(
                f"qpsolvers/{solver} failed: {one_line(exn)}") from exn
        except (MemoryError, OverflowError) as exn:
            raise SolverError(f"qpsolvers/{solver} cannot hold this problem (n = {qp.n}): {exn}") from exn
    caught = [str(w.message) for w in caught_w]
    name, iterations = _solver_status(solver, sol, caught)
    status = STATUS_MAP.get(solver, _FOUND).get(name, Status.ERROR)
    out = RawSolution(
        status=status,
        iterations=None if iterations is None else int(iterations),
        # qpsolvers times the solver call alone (perf_counter); older versions did not
        solve_time=float(sol.solve_time) if sol.solve_time is not None else wall,
        solver_status=name,
        extras={
            "found": sol.found,
            "preset": preset if table else "defaults",
            "options": opts,
            "build_time": sol.build_time,
            "warnings": caught,
        },
    )
    if status in (Status.INFEASIBLE, Status.UNBOUNDED) or sol.x is None:
        return out  # what x holds then is an iterate or a certificate, not a solution
    x = np.asarray(sol.x, dtype=float).reshape(-1)
    if not np.all(np.isfinite(x)):
        return out
    out.x = x
    out.obj = float(sol.obj) if sol.obj is not None else float(0.5 * x @ (original.P @ x) + original.q @ x)

    def mult(v, present):
        if not present or v is None:
            return None
        v = np.asarray(v, dtype=float).reshape(-1)
        return v if v.size else None

    out.y = mult(sol.y, qp.A is not None)
    if split is None:
        out.z = mult(sol.z, qp.G is not None)
        out.z_box = mult(sol.z_box, has_box)
    else:
        z_all = mult(sol.z, True)
        out.z, out.z_box = split(z_all) if z_all is not None else (None, None)
    return out




def solve(
    problem: QP | LCP, solver: str, accuracy: str = "default", options: dict | None = None
) -> RawSolution:
    """Solve a QP, or an LCP with symmetric PSD M as its QP (x = z, w = M z + q)."""
    return via_qp(problem, lambda qp: solve_qp(qp, solver, accuracy, options))


#: Solvers that factorise P and so need it positive definite: quadprog (Goldfarb–Idnani's dual
#: method starts from P's Cholesky factor) and ecos (qpsolvers writes the QP as a cone program
#: through P's Cholesky factor). qpsolvers refuses a semidefinite P for both.
DEFINITE_ONLY = frozenset({"quadprog", "ecos"})


class QpsolversBackend(Backend):
    """``qpsolvers:NAME``; ``definite`` for the solvers of :data:`DEFINITE_ONLY`."""

    accepts = frozenset({"qp", "lcp"})

    def __init__(self, solver: str):
        self.solver = solver
        self.name = f"{PREFIX}:{solver}"
        self.definite = solver in DEFINITE_ONLY

    def __repr__(self) -> str:
        return f"QpsolversBackend({self.name!r})"

    def available(self) -> bool:
        return qpsolvers is not None and self.solver in qpsolvers.available_solvers

    def version(self) -> str | None:
        if qpsolvers is None:
            return None
        try:
            v = importlib.metadata.version(_DIST.get(self.solver, self.solver))
        except importlib.metadata.PackageNotFoundError:
            return qpsolvers.__version__
        return f"{qpsolvers.__version__} ({self.solver} {v})"

    def solve(self, problem: QP | LCP, accuracy: str = "default", options: dict | None = None) -> RawSolution:
        return solve(problem, self.solver, accuracy, options)


def backends() -> list[QpsolversBackend]:
    """One backend per solver qpsolvers finds here (per preset table if qpsolvers is absent)."""
    names = list(qpsolvers.available_solvers) if qpsolvers is not None else list(ACCURACY)
    return [QpsolversBackend(n) for n in names]
