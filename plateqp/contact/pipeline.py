"""The contact solve, one direction: scale → route → formulate → solve → recover → check → Result.

Also the two-sided comparison of the source paper: the same scene with every one-sided
support made two-sided (each support holds the plate at its gap, in both directions).
"""

from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass

import numpy as np

from ..accuracy import Accuracy, Status
from ..model.assembly import Model
from ..backends import get_backend
from ..backends.base import RawSolution
from ..errors import MechanismError, NoEquilibriumError, PlateQPWarning, ProblemError, SolverError
from ..linalg import solve_saddle
from ..linalg.keep import keeping, shared
from ..linalg.products import remembering
from ..results import Result
from .answer import to_result
from .formulations import ContactSolution, Formulation, formulate
from .kkt import defect_residual, kkt_report
from .predict import check_predict, predicted_set, wanted
from .routing import choose, fallback_routes, formulations_for
from .scaling import Scaled
from .statics import NO_EQUILIBRIUM, supports_reach

log = logging.getLogger(__name__)


def solve_contact(model: Model, backend: str = "auto", formulation: str = "auto",
                  accuracy: str | float | Accuracy = "default", options: dict | None = None,
                  check_statics: bool = True) -> Result:
    """Solve the contact problem of a built model; see :func:`plateqp.solve`.

    ``check_statics``: before solving, check by statics that the supports can carry the load
    at all (:func:`plateqp.contact.statics.supports_reach`) and raise NoEquilibriumError at once
    if not. Whatever it is set to, a backend's claim of "no equilibrium" (status INFEASIBLE or
    UNBOUNDED, with its certificate) is checked against the same statics, and a false claim is a
    SolverError, never a NoEquilibriumError. Within the asked accuracy of the edge of the
    supports' reach statics cannot tell, and the backend's verdict stands either way.

    With ``backend="auto"``, a first route that stops short (a SolverError, or an answer that
    is not OPTIMAL and not merely at the rounding floor) hands over to the next exact route
    (:func:`plateqp.contact.routing.fallback_routes`); ``extras["route"]`` says which route
    answered and why each one before it stopped. The first route runs exactly as without it.
    """
    if model.soil_flexibility is not None:  # a half-space held matrix-free: solved in the contact forces
        from .pressures import solve_pressures

        return solve_pressures(model, backend, formulation, accuracy, options, check_statics)
    acc = Accuracy.parse(accuracy)  # ProblemError for a bad one, before any work
    options = dict(options or {})
    predict = options.pop("predict", "auto")  # the pipeline's own option, never the backend's
    check_predict(predict)
    t0 = time.perf_counter()
    data = Scaled.from_model(model)
    reach = supports_reach(data, band=acc.tol)
    if check_statics and not reach.possible and not reach.marginal:
        raise NoEquilibriumError(f"{NO_EQUILIBRIUM} ({reach.why}; found by statics, before any solve)")
    # within the band of the asked accuracy around the edge of the supports' reach, statics cannot
    # tell, and a solver's own verdict stands: "no equilibrium" there is no solver failure
    chosen, form = _route(data, backend, formulation)
    step = _Step(model, data, reach, acc, predict)
    if backend != "auto":
        return step.solve(form, chosen, options, t0)
    return _auto(step, form, chosen, options, t0)


def _route(data: Scaled, backend: str, formulation: str) -> tuple[str, Formulation]:
    """The backend and formulated problem asked for ("auto": chosen), checked: the backend takes
    the formulation; one that needs a positive definite Hessian is not given a floating plate."""
    asked_backend, asked_formulation = backend, formulation
    backend, formulation = choose(data, backend, formulation)
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
        backend, formulation = choose(data, asked_backend, "primal")
        b = get_backend(backend)
        form = formulate(data, formulation)
    if getattr(b, "definite", False) and data.floating:  # a SolverError, as the solver's own refusal was
        raise SolverError(
            f"backend {backend!r} needs a positive definite Hessian, and a plate its two-sided supports do not hold "
            f"(free to move as a body) has only a semidefinite one in the primal and condensed formulations; "
            f"formulation='dual' needs two-sided supports (edges, pins) that hold it: add them, or use a backend "
            f"that takes a semidefinite Hessian: pdas (primal), lemke or bpp (condensed), clarabel or osqp")
    return backend, form


def _auto(step: _Step, form: Formulation, backend: str, options: dict, t0: float) -> Result:
    """backend="auto": the chosen route, and where it stops short the next exact routes
    (:func:`plateqp.contact.routing.fallback_routes`), keeping the first OPTIMAL answer, else
    the one with the smallest KKT residual."""
    route = f"{backend}/{form.name}"
    tried: list[dict] = []
    first_error = None
    with warnings.catch_warnings(record=True) as said:  # said again below if this answer is kept
        warnings.simplefilter("always", PlateQPWarning)
        try:
            res = step.solve(form, backend, options, t0, depth=5)
        except SolverError as exn:
            res, first_error = None, exn
            tried.append({"route": route, "status": "error", "why": str(exn)})
        else:
            tried.append(_attempt(route, res))
    if res is not None and (res.status == Status.OPTIMAL or res.kkt.at_floor):
        for w in said:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        res.extras["route"] = {"answered": route, "tried": tried}
        return res
    best = res
    for nb, nf in fallback_routes(step.data, route):
        t1 = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", PlateQPWarning)  # one warning, for the answer kept
                # the options given were for the first route; another backend takes its defaults
                nxt = step.solve(formulate(step.data, nf), nb, {}, t1, depth=5)
        except (SolverError, ProblemError, MechanismError) as exn:
            tried.append({"route": f"{nb}/{nf}", "status": "error", "why": str(exn)})
            continue
        tried.append(_attempt(f"{nb}/{nf}", nxt))
        if best is None or (nxt.kkt is not None and best.kkt is not None and nxt.kkt.worst < best.kkt.worst):
            best = nxt
        if nxt.status == Status.OPTIMAL:
            break
    if best is None:
        raise SolverError("backend auto: no route answered: "
                          + "; ".join(f"{t['route']}: {t['why']}" for t in tried)) from first_error
    best.extras["route"] = {"answered": f"{best.backend}/{best.formulation}", "tried": tried}
    best.times["total_routes"] = time.perf_counter() - t0
    if best.status == Status.OPTIMAL:
        log.info("backend auto: %s answered after %s", tried[-1]["route"],
                 "; ".join(f"{t['route']} {t['why']}" for t in tried[:-1]))
    else:
        warnings.warn(f"backend auto: no route answered to the accuracy asked; kept {best.backend} on the "
                      f"{best.formulation} problem ({best.extras['why']}); tried "
                      + "; ".join(f"{t['route']}: {t.get('why', t['status'])}" for t in tried), PlateQPWarning,
                      stacklevel=4)
    return best


def _attempt(route: str, res: Result) -> dict:
    """What one route of backend="auto" did: its status, and why it stopped short if it did."""
    out = {"route": route, "status": res.status.value}
    if res.status != Status.OPTIMAL:
        out["why"] = res.extras.get("why") or res.status.value
    return out


@dataclass
class _Step:
    """What every route of one solve shares: the model, its scaled data, the statics of the
    supports' reach, the accuracy asked and the prediction option."""

    model: Model
    data: Scaled
    reach: object
    acc: Accuracy
    predict: object

    def solve(self, form: Formulation, backend: str, options: dict, t0: float, depth: int = 4) -> Result:
        """One route: a formulated problem solved by one backend, recovered and checked (and
        corrected where the formulation's own data explain a failing answer). ``depth``: the
        stack level of the user's call, for the warning."""
        b = get_backend(backend)
        with remembering():  # K u on the final u: read by the backend, the KKT report and the Result
            raw, t_predict, predicted, solve_s, t1 = self._first(form, b, backend, options)
            res = finish(self.model, form, raw, self.acc, backend)
            form, raw, res, corrections, iterations, failed, more = _corrections(
                self.model, form, raw, res, b, backend, options, self.acc)
        solve_s += more
        if res.status != Status.OPTIMAL:
            why = ""
            if res.kkt.at_floor:
                why = (f"; the stationarity residual is at its rounding floor ({res.kkt.floor:.1e}) on this plate: "
                       "no answer in double precision can show the accuracy asked, ask "
                       f"{10.0 ** np.ceil(np.log10(res.kkt.floor)):.0e} or more")
            said = f"{raw.solver_status}; " if raw.solver_status and raw.status != Status.OPTIMAL else ""
            res_why = f"{said}worst KKT residual {res.kkt.worst:.2e}, asked {res.kkt.tol:.0e}{why}"
            warnings.warn(f"{backend} on the {form.name} problem: {res.status.value} ({res_why})", PlateQPWarning,
                          stacklevel=depth)
        res.iterations = iterations
        res.extras = {"solver_status": raw.solver_status, **raw.extras, "predicted": predicted}
        if res.status != Status.OPTIMAL:  # why it stopped short, in words (Result.to_dict: "why")
            res.extras["why"] = f"{res.status.value}: {res_why}"
        if form.max_corrections:
            res.extras["corrections"] = corrections
            if failed is not None:
                res.extras["correction_failed"] = failed
        res.times.update(formulate=t1 - t0 - t_predict, predict=t_predict, solve=solve_s,
                         recover=time.perf_counter() - t1 - solve_s)
        return res

    def _first(self, form: Formulation, b, backend: str, options: dict):
        """The backend's first answer (started from the coarse mesh's contact set where that is
        wanted): (raw, predict time, what the prediction did, solve time, its start). A backend's
        claim of no equilibrium is checked against statics."""
        formulation = form.name
        problem = form.problem(b.accepts)
        t1 = time.perf_counter()
        first = options
        predicted = {"why": wanted(self.model, self.data, backend, formulation, options, self.predict)}
        if predicted["why"] is None:  # the coarse mesh's contact set starts the solve
            A0, predicted = predicted_set(self.model)
            if A0 is not None:
                first = dict(options, active=A0)
        t_predict = time.perf_counter() - t1
        t1 = time.perf_counter()
        with keeping(kept_factors(self.data)):
            raw = b.solve(problem, accuracy=self.acc, options=first)
        t2 = time.perf_counter()
        if raw.status in (Status.INFEASIBLE, Status.UNBOUNDED):  # the backend's certificate, in QP/LCP terms
            verdict = f"{backend} on the {formulation} problem ended {raw.status.value} ({raw.solver_status})"
            if self.reach.certain:
                raise SolverError(f"{verdict}, but statics says the supports can carry the load: the solver failed")
            raise NoEquilibriumError(f"{verdict}: {NO_EQUILIBRIUM} ({self.reach.why})")
        if raw.x is None:
            raise SolverError(f"{backend} on the {formulation} problem returned no solution: "
                              f"{raw.status.value} ({raw.solver_status})")
        return raw, t_predict, predicted, t2 - t1, t1


def _corrections(model: Model, form: Formulation, raw: RawSolution, res: Result, b, backend: str, options: dict,
                 acc: Accuracy):
    """Re-solves where the formulation's own data explain a failing answer (the dual's G from the
    trailing block: Dual.defect); the backend's own error is never corrected. Not worth a
    re-solve: a change below a tenth of the tolerance, or below a quarter of the worst residual
    (the rest is the backend's, which another round keeps). The answer kept is always the best
    one checked: a round that fails, or ends worse, is dropped (and said as ``failed``), never
    raised over an answer in hand. Returns (form, raw, res, corrections, iterations, failed,
    solve time)."""
    iterations, corrections, solve_s, failed = raw.iterations, 0, 0.0, None
    while corrections < form.max_corrections and raw.status.solved and not res.kkt.ok:
        e = form.defect(raw)
        size = defect_residual(form.data, form.recover(raw), e, form.lcp.M, acc.tol)
        if not np.isfinite(size) or size <= 0.1 * acc.tol or 4.0 * size < res.kkt.worst:
            break
        nxt = form.corrected(e)
        opts = dict(options)
        if getattr(b, "warm_start", False) and "active" in raw.extras and "active" not in opts:
            opts["active"] = raw.extras["active"]
        t3 = time.perf_counter()
        try:
            with keeping(kept_factors(form.data)):
                again = b.solve(nxt.problem(b.accepts), accuracy=acc, options=opts)
        except (SolverError, ProblemError) as exn:
            failed = f"{type(exn).__name__}: {exn}"
            break
        finally:
            solve_s += time.perf_counter() - t3
        if again.x is None or again.status in (Status.INFEASIBLE, Status.UNBOUNDED):
            failed = f"{again.status.value} ({again.solver_status})"
            break
        checked = finish(model, nxt, again, acc, backend)
        if not checked.kkt.worst <= res.kkt.worst:
            failed = f"worse (worst KKT residual {checked.kkt.worst:.2e} against {res.kkt.worst:.2e})"
            break
        form, raw, res, corrections = nxt, again, checked, corrections + 1
        if raw.iterations is not None:
            iterations = (iterations or 0) + raw.iterations
    return form, raw, res, corrections, iterations, failed, solve_s


def kept_factors(data: Scaled) -> list | None:
    """The list of factorisations the model keeps for its K and B (in ``Model.derived``, which
    the models adapted from it share: :func:`plateqp.studies.reuse.adapt_model`), lent to the
    backend's solve inside :func:`plateqp.linalg.keep.sharing` (a sweep, the stiffness design);
    None elsewhere (a single solve keeps no factor alive beside its Result) or where the data came
    from no model."""
    keep = data.derived
    if keep is None or data.K_src is None or not shared():
        return None
    for K, B, kind, value in keep:
        if K is data.K_src and B is data.B_src and kind == "factors":
            return value
    value: list = []
    keep.append((data.K_src, data.B_src, "factors", value))
    return value


def finish(model: Model, form: Formulation, raw: RawSolution, accuracy: str | float | Accuracy,
           backend: str) -> Result:
    """Recover the plate's fields from a backend's answer, check them against the KKT conditions
    and return the Result: OPTIMAL only if the residuals meet ``accuracy`` (a backend's own
    INACCURATE, MAX_ITER or ERROR is kept). Shared by :func:`solve_contact` and by
    :meth:`plateqp.io.export.ExportedQP.result` (another solver's answer to an exported QP)."""
    acc = Accuracy.parse(accuracy)
    c = form.recover(raw)
    rep = kkt_report(form.data, c, acc)
    status = raw.status
    if status.solved:
        status = Status.OPTIMAL if rep.ok else Status.INACCURATE
    res = to_result(model, form.data, c, status, backend, form.name, acc)
    res.kkt = rep
    return res


def solve_bilateral(model: Model) -> Result:
    """Every one-sided support made two-sided: B u − ρ R = g0 exactly, R of either sign.

    Solves the sparse saddle-point system [K Bᵀ; B −ρ] (u, R) = (f, g0), which works for a
    floating plate too (as long as the supports hold it).
    """
    if model.soil_flexibility is not None:  # a half-space held matrix-free: the same system by CG
        from .pressures import solve_bonded

        return solve_bonded(model)
    t0 = time.perf_counter()
    data = Scaled.from_model(model)
    try:
        u, R = solve_saddle(data.K, data.B, data.rho, data.f, data.g0)
    except MechanismError as exn:
        raise ProblemError("the two-sided comparison is singular: the supports do not hold the plate") from exn
    c = ContactSolution(u, R, data.rho * R)
    res = to_result(model, data, c, Status.OPTIMAL, "direct", "bilateral", "high")
    res.active = np.ones(data.m, dtype=bool)
    res.times = {"solve": time.perf_counter() - t0}
    return res
