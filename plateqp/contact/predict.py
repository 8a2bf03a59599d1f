"""A coarse mesh's contact set as the first set of the fine solve (pdas on the primal problem).

A bed's (or a field of soft supports') contact set moves little when the mesh is refined: the
benchmark bed solved at a quarter of the cells a side gets 8 of 16 641 springs wrong at 128²,
5 of 66 049 at 256² (benchmarks/README.md). pdas's sparse method on
soft rows (springs no stiffer than the plate under them) then builds its one factorisation for
that set instead of for every row: its first step finds (nearly) nothing to change, the few
wrong rows are taken by a low-rank correction, and the second factorisation a cold start needs
for the set it settles on is saved. A bad prediction costs PCG iterations, never a wrong
answer (the exact steps and the KKT check decide, as on a cold start).

:func:`predicted_set` is what :func:`plateqp.contact.pipeline.solve_contact` calls; the option
``predict`` of :func:`plateqp.solve` ("auto", True or False) says whether (see :func:`wanted`).
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import scipy.sparse as sp

from ..accuracy import Status
from ..model.assembly import Model, build_model
from ..errors import NoEquilibriumError, PlateQPWarning, ProblemError
from ..estimate import COARSE_FAILURES, with_mesh
from ..model.generators import mesh_cells
from ..linalg import row_stiffness
from .scaling import Scaled

#: The coarse mesh has this many times the cell size of the scene's own (a sixteenth of its cells).
DIVISOR = 4
#: ... and at least this many cells a side (a coarser one loses too much: 25 of 16 641 springs
#: wrong from 16² to 128², 8 from 32²).
COARSE_MIN = 16
#: With ``predict="auto"``: at least this many contact rows (below it the second factorisation a
#: prediction saves costs less than the coarse solve; measured in benchmarks/bench_predict.py).
ROWS_MIN = 4000

__all__ = ["COARSE_MIN", "DIVISOR", "ROWS_MIN", "predicted_set", "soft_rows", "wanted"]


def soft_rows(data: Scaled) -> bool:
    """Every contact row is softer than the plate under it (``ρ_i k_i ≥ 1``, ``k_i`` the plate's
    diagonal stiffness along the row: pdas's test for its Newton first phase, which is where a
    predicted set pays; on stiff rows the exact steps would start from it directly)."""
    k = row_stiffness(sp.diags(data.K.diagonal()), data.B, "diagonal")
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


def predicted_set(model: Model, solve) -> tuple[np.ndarray | None, dict]:
    """The contact set the scene's mesh coarsened DIVISOR times predicts, one entry per contact
    row of ``model`` (a point off the coarse plate: not in contact), and what it cost:
    ``{"mesh": coarse mesh, "rows": rows predicted in contact, "seconds": …}``; ``(None, {"why": …})``
    where the coarse scene cannot be built or solved. ``solve`` is
    :func:`plateqp.contact.pipeline.solve_contact` (passed in: this module stays below it)."""
    t0 = time.perf_counter()
    nx, ny = mesh_cells(model.scene)
    cx, cy = max(1, round(nx / DIVISOR)), max(1, round(ny / DIVISOR))
    try:
        coarse_scene = with_mesh(model.scene, cx, cy)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlateQPWarning)
            coarse = solve(build_model(coarse_scene), backend="pdas", formulation="primal", accuracy="default")
    except (*COARSE_FAILURES, NoEquilibriumError) as exn:
        # the coarse answer is only a start: whatever stops it (a bed region whose coarse cells
        # end short of the load, so that the coarse plate tips off them) leaves the fine solve
        # to start cold, never fails it
        return None, {"mesh": [cx, cy], "why": f"the coarse mesh failed: {type(exn).__name__}: {exn}"}
    if coarse.status != Status.OPTIMAL:
        return None, {"mesh": [cx, cy], "why": f"the coarse solve ended {coarse.status.value}"}
    c = model.contacts
    x, y = c.xy[:, 0], c.xy[:, 1]
    on = coarse.model.grid.locate(x, y)[0] >= 0
    w = np.full(c.m, -np.inf)
    if on.any():
        w[on] = np.asarray(coarse.deflection(x[on], y[on]), dtype=float)
    A = np.nan_to_num(w - c.scene_gaps, nan=-np.inf) > 0
    return A, {"mesh": [cx, cy], "rows": int(A.sum()), "seconds": time.perf_counter() - t0}
