"""A coarse mesh's contact set as the first set of the fine solve (pdas on the primal problem).

A bed's (or a field of soft supports') contact set moves little when the mesh is refined: the
benchmark bed solved at a quarter of the cells a side gets 8 of 16 641 springs wrong at 128²,
5 of 66 049 at 256² (benchmarks/README.md). pdas's sparse method on
soft rows (springs no stiffer than the plate under them) then builds its one factorisation for
that set instead of for every row: its first step finds (nearly) nothing to change, the few
wrong rows are taken by a low-rank correction, and the second factorisation a cold start needs
for the set it settles on is saved. A bad prediction costs PCG iterations, never a wrong
answer (the exact steps and the KKT check decide, as on a cold start).

:func:`predicted_set` is what :func:`plateqp.contact.pipeline.solve_contact` calls (the coarse
problem solved directly, with only what the start needs: :func:`coarse_deflections`); the option
``predict`` of :func:`plateqp.solve` ("auto", True or False) says whether (see :func:`wanted`).
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import scipy.sparse as sp

from ..accuracy import Accuracy, Status
from ..backends import get_backend
from ..model.assembly import Model, build_model
from ..errors import NoEquilibriumError, PlateQPWarning, ProblemError, SolverError
from ..estimate import COARSE_FAILURES, with_mesh
from ..model.generators import mesh_cells
from ..linalg import SingularMatrixError, row_stiffness
from .formulations import formulate
from .scaling import Scaled
from .statics import NO_EQUILIBRIUM, settle, supports_reach

#: The coarse mesh has this many times the cell size of the scene's own (a sixteenth of its cells).
DIVISOR = 4
#: ... and at least this many cells a side (a coarser one loses too much: 25 of 16 641 springs
#: wrong from 16² to 128², 8 from 32²).
COARSE_MIN = 16
#: With ``predict="auto"``: at least this many contact rows (below it the second factorisation a
#: prediction saves costs less than the coarse solve; measured in benchmarks/bench_predict.py).
ROWS_MIN = 4000
#: Newton steps on a coarse mesh of springs (:func:`spring_deflections`) before its solve is left
#: to pdas (the benchmark bed's 16² mesh settles in 4 to 6).
NEWTON_STEPS = 25

__all__ = ["COARSE_MIN", "DIVISOR", "ROWS_MIN", "coarse_deflections", "predicted_set", "soft_rows", "spring_deflections", "wanted"]


def soft_rows(data: Scaled) -> bool:
    """Every contact row is softer than the plate under it (``ρ_i k_i ≥ 1``, ``k_i`` the plate's
    diagonal stiffness along the row: pdas's test for its Newton first phase, which is where a
    predicted set pays; on stiff rows the exact steps would start from it directly)."""
    k = row_stiffness(data.K, data.B, "diagonal")  # K's diagonal alone (remembered for the KKT report)
    return bool(np.all(data.rho * k >= 1.0))


def wanted(model: Model, data: Scaled, backend: str, formulation: str, options: dict, predict) -> str | None:
    """None where a coarse mesh's contact set should start the solve; else why not (a sentence,
    kept in ``extras["predicted"]``). ``predict``: "auto" (on soft rows or a soil with unknowns of
    its own (a Pasternak bed of 128²: 25 factorisations cold, 19 from the 32² mesh's set), at least
    ROWS_MIN of them, a coarse mesh of COARSE_MIN cells a side or more), True (wherever a coarse mesh can
    be built and the route takes a first set), False."""
    if predict is False:
        return "predict=False"
    if backend != "pdas" or formulation != "primal":
        return f"the route is {backend} on the {formulation} problem (only pdas on the primal takes a first set)"
    if "active" in options:
        return "a warm start was given"
    nx, ny = mesh_cells(model.scene)
    if min(nx, ny) // DIVISOR < (COARSE_MIN if predict == "auto" else 2):
        return f"the mesh ({nx} x {ny}) is too coarse to coarsen {DIVISOR} times"
    if predict == "auto":
        if data.m < ROWS_MIN:
            return f"{data.m} contact rows (fewer than {ROWS_MIN})"
        if not soft_rows(data) and data.soil is None:  # a coupled soil's rows are rigid, its unknowns soft
            return "some contact rows are stiffer than the plate under them"
    return None


def check_predict(value) -> None:
    """ProblemError unless ``value`` is "auto", True or False."""
    if not (value is True or value is False or (isinstance(value, str) and value == "auto")):
        raise ProblemError(f"option predict must be 'auto', True or False, got {value!r}")


def predicted_set(model: Model) -> tuple[np.ndarray | None, dict]:
    """The contact set the scene's mesh coarsened DIVISOR times predicts, one entry per contact
    row of ``model`` (a point off the coarse plate: not in contact), and what it cost:
    ``{"mesh": coarse mesh, "rows": rows predicted in contact, "seconds": …}``; ``(None, {"why": …})``
    where the coarse scene cannot be built or solved. The coarse problem is solved by pdas on the
    primal directly (:func:`coarse_deflections`): the set only starts the fine solve, whose exact
    steps and KKT check decide the answer, so the coarse answer gets no Result and no KKT report."""
    t0 = time.perf_counter()
    nx, ny = mesh_cells(model.scene)
    cx, cy = max(1, round(nx / DIVISOR)), max(1, round(ny / DIVISOR))
    c = model.contacts
    x, y = c.xy[:, 0], c.xy[:, 1]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlateQPWarning)
            w, why = coarse_deflections(build_model(with_mesh(model.scene, cx, cy)), x, y)
    except (*COARSE_FAILURES, NoEquilibriumError) as exn:
        # the coarse answer is only a start: whatever stops it (a bed region whose coarse cells
        # end short of the load, so that the coarse plate tips off them) leaves the fine solve
        # to start cold, never fails it
        return None, {"mesh": [cx, cy], "why": f"the coarse mesh failed: {type(exn).__name__}: {exn}"}
    if w is None:
        return None, {"mesh": [cx, cy], "why": why}
    A = np.nan_to_num(w - c.scene_gaps, nan=-np.inf) > 0
    return A, {"mesh": [cx, cy], "rows": int(A.sum()), "seconds": time.perf_counter() - t0}


def _no_equilibrium(data: Scaled, acc: Accuracy) -> None:
    """NoEquilibriumError where statics says the supports cannot carry the load (asked only
    after the coarse solve stopped short: a solve that ends OPTIMAL needs no such check)."""
    reach = supports_reach(data, band=acc.tol)
    if not reach.possible and not reach.marginal:
        raise NoEquilibriumError(f"{NO_EQUILIBRIUM} ({reach.why}; found by statics)")


def coarse_deflections(coarse: Model, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray | None, str]:
    """The deflection of the coarse model's answer at the points (x, y), −inf at a point off the
    coarse plate; (None, why) where the backend's answer is not OPTIMAL. NoEquilibriumError where
    the solve stops short and statics says the coarse supports cannot carry the load. Where every
    row is a spring, by :func:`spring_deflections` (Newton's steps on the contact set, started
    from the set of the coarse mesh's own coarse mesh where it is large enough for one: one
    factorisation, a few changed rows by Woodbury, no refinement: only the set is read from it);
    else, or where that gives none, pdas on the primal (accuracy "default"), started, as the
    pipeline would, from that set where :func:`wanted` says so. The answer in the user's units as
    :func:`plateqp.contact.answer.to_result` makes it (a floating plate's canonical deflection:
    :func:`plateqp.contact.statics.settle`)."""
    springs = _springs_only(coarse)
    start, asked = None, False
    if springs and not _too_small_to_predict(coarse):
        start, asked = predicted_set(coarse)[0], True
    if springs:
        u = spring_deflections(coarse, start)
        if u is not None:
            return _at_points(coarse, coarse.expand(u), x, y), ""
    acc = Accuracy.parse("default")
    data = Scaled.from_model(coarse)
    form = formulate(data, "primal")
    b = get_backend("pdas")
    options = {}
    if wanted(coarse, data, "pdas", "primal", options, "auto") is None:  # a coarse mesh large enough starts
        A0 = start if asked else predicted_set(coarse)[0]                # from its own coarse mesh's set
        if A0 is not None:
            options["active"] = A0
    try:
        raw = b.solve(form.problem(b.accepts), accuracy=acc, options=options)
    except SolverError:
        _no_equilibrium(data, acc)
        raise
    if raw.status != Status.OPTIMAL or raw.x is None:
        _no_equilibrium(data, acc)
        return None, f"the coarse solve ended {raw.status.value}"
    sol = form.recover(raw)
    u_s = settle(data, sol.u, sol.R, sol.s, max(acc.tol, 1e-9))[0] if data.floating else sol.u
    return _at_points(coarse, coarse.expand(data.dof_scale * u_s), x, y), ""


def _too_small_to_predict(model: Model) -> bool:
    """:func:`wanted`'s size rules ("auto"): fewer than ROWS_MIN contact rows, or a mesh too
    coarse to coarsen again (a pdas solve of it would start cold)."""
    nx, ny = mesh_cells(model.scene)
    return model.contacts.m < ROWS_MIN or min(nx, ny) // DIVISOR < COARSE_MIN


def _at_points(coarse: Model, u: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The deflection of the coarse model's full dofs ``u`` at the points (x, y), −inf at a point
    off the coarse plate: the element's basis in the cell the mesh locates each point in, as
    :func:`plateqp.model.assembly.interpolation` takes it, summed with the cell's dofs directly
    (one search of the points, no operator built for one product)."""
    mesh = coarse.grid
    cell, local = mesh.locate(x, y)
    on = cell >= 0
    w = np.full(x.shape, -np.inf)
    if on.any():
        cell = cell[on]
        N = coarse.element.basis(mesh.nodes[mesh.cells[cell]], local[on], 0, 0)
        w[on] = np.einsum("pk,pk->p", N, u[coarse.cell_dofs[cell]])
    return w


def _springs_only(coarse: Model) -> bool:
    """Every contact row of ``coarse`` is a spring (ρ > 0) and no soil has unknowns of its own."""
    c = coarse.contacts
    return not coarse.n_soil and c is not None and bool(np.all(c.rho > 0))


def spring_deflections(coarse: Model, start: np.ndarray | None = None) -> np.ndarray | None:
    r"""The coarse model's answer (its free dofs) where every contact row is a spring (ρ > 0, no
    soil with unknowns of its own), by Newton's method on the contact set: the minimiser of

    .. math:: \tfrac12 u^T K u - f^T u + \tfrac12 \sum_i \max(0, B_i u - g_i)^2 / \rho_i

    is the solution of :math:`(K + B_A^T \rho_A^{-1} B_A) u = f + B_A^T \rho_A^{-1} g_A` on the set
    :math:`A = \{i : B_i u > g_i\}` it gives; starting from ``start`` (default: every row
    pressed), each step solves for its set and takes the rows that press, until the set repeats
    (the answer, exact to rounding). None where a row is rigid, the plate is not held by a set (a singular matrix) or
    the set does not repeat within NEWTON_STEPS steps: the caller then solves with pdas. Only the
    contact set is read from it (the fine solve's exact steps and KKT check decide the answer);
    no scaling, formulation or backend is built around so small a problem."""
    if not _springs_only(coarse):
        return None
    from ..backends.pdas.factor import SpringFactor

    c = coarse.contacts

    B, g, k = c.B.tocsr(), c.g0, 1.0 / c.rho
    K = sp.csc_matrix(coarse.K)
    Kd = K.diagonal()
    if not np.all(Kd > 0):
        return None
    Bt = B.T.tocsr()
    # K + Bᵀ diag(k_A) B on one analysis whatever the set (a few changed rows by Woodbury)
    F = SpringFactor(K, B, Kd, k, 0.0, "auto")
    A = np.ones(c.m, dtype=bool) if start is None else np.array(start, dtype=bool)
    for _ in range(NEWTON_STEPS):
        kA = np.where(A, k, 0.0)
        try:
            F.set(kA)
            u = F.solve(coarse.f + Bt @ (kA * g))
        except (SolverError, SingularMatrixError):
            return None
        pressed = B @ u > g
        if np.array_equal(pressed, A):
            return u if np.all(np.isfinite(u)) else None
        A = pressed
    return None
