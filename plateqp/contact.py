"""The contact solve: scale, formulate, hand to a backend, recover, check.

Also the two-sided comparison of the source paper: the same scene with every one-sided
support made two-sided (each support holds the plate at its gap, in both directions).
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .assembly import Model
from .backends import get_backend, registry
from .backends.base import accuracy_tol
from .backends.base import Status
from .errors import MechanismError, NoEquilibriumError, ProblemError, SolverError
from .errors import PlateQPWarning
from .formulations import FORMULATIONS, Contact, Scaled, formulate
from .kkt import equilibrium_possible, kkt_report
from .results import Result

NO_EQUILIBRIUM = ("the one-sided supports cannot carry this load: net uplift, or the load "
                  "resultant lies outside the supports' reach, so the plate would lift off")

# The "auto" rules, measured by benchmarks/bench_scaling.py (benchmarks/README.md, "Scaling":
# grid_rigid scenes, n = 16…256, m = 25…3969, accuracy 1e-6, formulate + solve time).
# * backend="auto": on a single solve PDAS on the sparse primal was the fastest exact route
#   everywhere (BPP on the condensed LCP, condensation included: 1.5–4× slower for m ≤ 81,
#   6–23× for m ≥ 225). The condensed route is kept while m ≤ AUTO_LCP_MAX all the same: its
#   condensation is cached and re-used by every solve that shares the model (sweeps, gap
#   regulation: a dense m × m solve per value instead of a factorisation), and BPP's answer
#   did not depend on its warm start (bit-identical serial and parallel sweeps in
#   tests/test_studies.py, where warm-started PDAS differed at 1e-13). Condensed and dual
#   problems go to the first of AUTO_LCP_BACKENDS (BPP: 7–10× faster than Lemke from m = 225
#   on, as exact), primal ones to the first of AUTO_QP_BACKENDS.
# * a named QP backend (osqp, clarabel, qpsolvers:*, …): the condensed problem paid while
#   m ≤ AUTO_CONDENSED_FRACTION × free dofs: the break-even of OSQP, Clarabel and ProxQP was
#   m ≈ 25–50 at 3 k dofs, ≈ 100 at 12 k, ≈ 225–960 at 49 k; never beyond AUTO_CONDENSED_MAX
#   (the dense work grows like m³, its memory like 8 m² bytes).
# * a backend that takes only one of them (lemke, bpp, pgs: LCPs; pdas: the primal) gets it.
AUTO_LCP_MAX = 100
AUTO_CONDENSED_FRACTION = 0.01
AUTO_CONDENSED_MAX = 1000
AUTO_QP_BACKENDS = ("pdas", "clarabel", "qpsolvers:clarabel", "osqp", "cvxpy")
AUTO_LCP_BACKENDS = ("bpp", "lemke")


def condensed_pays(data: Scaled, backend: str = "auto") -> bool:
    """True where formulation="auto" condenses: few contact points (see the rules above).

    ``backend="auto"``: m ≤ AUTO_LCP_MAX; a named QP backend: m ≤ AUTO_CONDENSED_FRACTION ×
    free dofs and m ≤ AUTO_CONDENSED_MAX.
    """
    if backend == "auto":
        return data.m <= AUTO_LCP_MAX
    return data.m <= min(AUTO_CONDENSED_MAX, AUTO_CONDENSED_FRACTION * data.n)


def _first_installed(names: tuple[str, ...]) -> str | None:
    return next((b for b in names if b in registry() and registry()[b].available()), None)


def _choose(data: Scaled, backend: str, formulation: str) -> tuple[str, str]:
    if formulation == "auto":
        takes = list(FORMULATIONS) if backend == "auto" else formulations_for(backend)
        if "condensed" not in takes:
            formulation = "primal" if "primal" in takes else takes[0]
        elif "primal" not in takes:
            formulation = "condensed"
        else:
            formulation = "condensed" if condensed_pays(data, backend) else "primal"
    if formulation not in FORMULATIONS:
        raise ProblemError(f"unknown formulation {formulation!r}; choose one of {FORMULATIONS}")
    if backend == "auto":
        if formulation in ("condensed", "dual"):
            backend = _first_installed(AUTO_LCP_BACKENDS) or "lemke"
        else:
            # pdas takes at most as many contact rows as dofs (a coarse mesh under many supports)
            backend = _first_installed(tuple(b for b in AUTO_QP_BACKENDS if b != "pdas" or data.m <= data.n))
            if backend is None:
                raise SolverError("the primal formulation needs a QP backend; none is installed "
                                  "(pip install 'plateqp[solvers]')")
    return backend, formulation


def formulations_for(backend) -> list[str]:
    """The formulations a backend can solve: every one for a QP backend, condensed and dual for
    an LCP backend, restricted further by the backend's optional ``formulations`` attribute
    (e.g. a solver built for the sparse primal). ``backend``: a Backend or its name."""
    if isinstance(backend, (set, frozenset)):  # a bare ``accepts`` set
        accepts, only = backend, None
    else:
        b = get_backend(backend) if isinstance(backend, str) else backend
        accepts, only = b.accepts, getattr(b, "formulations", None)
    return [f for f in FORMULATIONS if ("qp" in accepts or (f != "primal" and "lcp" in accepts))
            and (only is None or f in only)]


def solve_contact(model: Model, backend: str = "auto", formulation: str = "auto",
                  accuracy: str = "default", options: dict | None = None, check_statics: bool = True) -> Result:
    """Solve the contact problem of a built model; see :func:`plateqp.solve`.

    ``check_statics``: before solving, check by statics that the supports can carry the load
    at all (:func:`plateqp.kkt.equilibrium_possible`) and raise NoEquilibriumError at once
    if not. Whatever it is set to, a backend's claim of "no equilibrium" is checked against
    the same statics, and a false claim is a SolverError, never a NoEquilibriumError.
    """
    accuracy_tol(accuracy)  # ProblemError for a bad one, before any work
    t0 = time.perf_counter()
    data = Scaled.from_model(model)
    possible, why = equilibrium_possible(data)
    if check_statics and not possible:
        raise NoEquilibriumError(f"{NO_EQUILIBRIUM} ({why}; found by statics, before any solve)")
    asked_backend, asked_formulation = backend, formulation
    backend, formulation = _choose(data, backend, formulation)
    b = get_backend(backend)
    if formulation not in formulations_for(b):
        raise ProblemError(f"backend {backend!r} does not take the {formulation} formulation; "
                           f"it takes: {', '.join(formulations_for(b))}")
    try:
        form = formulate(data, formulation)
    except (ProblemError, MechanismError):
        # "auto" chose to condense, but the contact points cannot be condensed onto (too close
        # together, or they do not hold the plate): the primal form needs neither
        if asked_formulation != "auto" or formulation == "primal" or (
                asked_backend != "auto" and "primal" not in formulations_for(asked_backend)):
            raise  # never swap a backend the user named for another one
        backend, formulation = _choose(data, asked_backend, "primal")
        b = get_backend(backend)
        form = formulate(data, formulation)
    problem = form.problem(b.accepts)
    t1 = time.perf_counter()
    try:
        raw = b.solve(problem, accuracy=accuracy, options=options or {})
    except NoEquilibriumError as exn:
        if possible:
            raise SolverError(f"{backend} on the {formulation} problem claimed no equilibrium ({exn}), "
                              "but statics says the supports can carry the load: the solver failed") from exn
        raise NoEquilibriumError(f"{backend} on the {formulation} problem: {NO_EQUILIBRIUM} ({why})") from exn
    t2 = time.perf_counter()
    if raw.status in (Status.INFEASIBLE, Status.UNBOUNDED) and possible:
        raise SolverError(f"{backend} on the {formulation} problem ended {raw.status.value} "
                          f"({raw.solver_status}), but statics says the supports can carry the load: "
                          "the solver failed")
    if raw.status in (Status.INFEASIBLE, Status.UNBOUNDED):
        raise NoEquilibriumError(f"{backend} on the {formulation} problem ended {raw.status.value} "
                                 f"({raw.solver_status}): {NO_EQUILIBRIUM}")
    if raw.x is None:
        raise SolverError(f"{backend} on the {formulation} problem returned no solution: "
                          f"{raw.status.value} ({raw.solver_status})")
    c = form.recover(raw)
    rep = kkt_report(data, c, accuracy)
    status = raw.status
    if status.solved:
        status = Status.OPTIMAL if rep.ok else Status.INACCURATE
    if status != Status.OPTIMAL:
        warnings.warn(f"{backend} on the {formulation} problem: {status.value} "
                      f"(worst KKT residual {rep.worst:.2e}, asked {rep.tol:.0e})", PlateQPWarning, stacklevel=3)
    t3 = time.perf_counter()
    res = to_result(model, data, c, status, backend, formulation, accuracy)
    res.kkt = rep
    res.iterations = raw.iterations
    res.extras = {"solver_status": raw.solver_status, **raw.extras}
    res.times.update(formulate=t1 - t0, solve=t2 - t1, recover=t3 - t2)
    return res


def to_result(model: Model, data: Scaled, c: Contact, status, backend, formulation, accuracy) -> Result:
    """A contact solution of the scaled problem back in the user's units, as a :class:`Result`
    (public: :mod:`plateqp.export` maps any solver's answer back with it)."""
    u = data.dof_scale * c.u
    R = data.F0 * c.R
    s = data.W * c.s
    w = model.contacts.B @ u
    gaps = model.contacts.g0 + s - w
    stat = model.K @ u - model.f + model.contacts.B.T @ R
    res = float(np.linalg.norm(stat) / max(np.linalg.norm(model.f), np.linalg.norm(model.contacts.B.T @ R), 1e-300))
    # in contact: the reaction carries load, or the support touches (gap ≈ 0), both judged at
    # the tolerance of the asked accuracy (an iterative solver leaves R ~ tol · max R on open supports)
    tol = max(accuracy_tol(accuracy), 1e-9)
    active = (R > tol * max(np.abs(R).max(initial=0.0), 1e-300)) | (np.abs(gaps) <= tol * max(data.W, 1e-300))
    return Result(model.scene, model, model.expand(u), status=status, backend=backend, formulation=formulation,
                  accuracy=accuracy, reactions=R, gaps=gaps, compressions=s, active=active, residual=res)


def solve_bilateral(model: Model) -> Result:
    """Every one-sided support made two-sided: B u − ρ R = g0 exactly, R of either sign.

    Solves the sparse saddle-point system [K Bᵀ; B −ρ] (u, R) = (f, g0), which works for a
    floating plate too (as long as the supports hold it).
    """
    t0 = time.perf_counter()
    data = Scaled.from_model(model)
    n, m = data.n, data.m
    A = sp.bmat([[data.K, data.B.T], [data.B, -sp.diags(data.rho)]], format="csc")
    rhs = np.concatenate([data.f, data.g0])
    try:
        lu = spla.splu(A)
        x = lu.solve(rhs)
    except RuntimeError as exn:
        raise ProblemError("the two-sided comparison is singular: the supports do not hold the plate") from exn
    for _ in range(2):  # refinement
        x = x + lu.solve(rhs - A @ x)
    c = Contact(x[:n], x[n:], data.rho * x[n:])
    res = to_result(model, data, c, Status.OPTIMAL, "direct", "bilateral", "high")
    res.active = np.ones(m, dtype=bool)
    res.times = {"solve": time.perf_counter() - t0}
    return res
