"""Discretisation error by mesh halving (Richardson): the estimator behind ``accuracy="auto"``.

The finite-element answer of a plate converges as the mesh is refined; the solver's answer
converges to the finite-element one as its tolerance tightens. Past the point where the
solver's error is a small fraction of the mesh's, a tighter tolerance buys nothing
(benchmarks/README.md, "Discretisation against solver error"). This module estimates the
mesh's error by Richardson's argument on meshes that halve: if q(h) = q* + C hᵖ, then

    |q(h) − q*| ≈ |q(h) − q(2h)| / (2ᵖ − 1),

and uses it two ways:

* :func:`auto_tolerance` (``solve(..., accuracy="auto")``): estimate the error of the scene's
  own mesh from the two coarser meshes (h·2, h·4; a quarter and a sixteenth of the work)
  and ask the solver for a fraction of it; once the mesh itself is solved, :func:`confirm`
  checks the estimate against the finer pair (h·2, h) and marks it not trusted when the
  meshes disagree (a warning, and ``trusted: false`` in the result);
* :func:`plateqp.studies.refinement.solve_to_target` (``plateqp solve --target REL``): refine from a coarse mesh until the
  estimated error of max |w| and of the reactions is below REL, solving each mesh at a solver
  tolerance of a tenth of REL: the coarsest mesh and the loosest setting that reach it.

On triangles a mesh of n cells a side has element size L / n (:func:`plateqp.model.generators.mesh_cells`);
the meshes are not nested, so the change of w is read from max |w| alone.

The quantities are the ones engineers read: the largest deflection max |w|, and the
reactions (discrete supports: the largest change of any support's reaction, relative to the
largest reaction; a tensionless bed: the largest bed pressure). The order p defaults to 1.5:
below the elements' order 2 under the point-like reactions of contact (measured 1.73 for
ACM under a point load, tests/model/test_plate.py), so the estimate errs on the safe side.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from collections.abc import Callable

from .model.generators import mesh_cells, with_cells
from .errors import MechanismError, PlateQPWarning, ProblemError, SceneError, SolverError
from .results import Result
from .model.scene import Scene

#: What a coarse mesh may fail with (too few dofs for the supports, a pin off its nodes): skipped.
COARSE_FAILURES = (SceneError, ProblemError, SolverError, MechanismError)

#: Assumed convergence order of the quantities (see the module docstring).
ORDER = 1.5
#: accuracy="auto" asks the solver for this fraction of the estimated mesh error.
FRACTION = 0.1
#: The loosest tolerance accuracy="auto" will ask for (a KKT residual of 1e-3 is "low").
LOOSEST = 1e-3


@dataclass
class Quantities:
    """What the error is measured on, for one solved mesh."""

    mesh: tuple[int, int]
    w_max: float  # max |w| over the plate
    reactions: np.ndarray  # discrete supports' reactions, scene order
    p_max: float | None  # the bed's largest pressure (None without a bed)
    #: w at the nodes on a structured grid's view, (ny+1, nx+1) NaN off the plate (None on triangles)
    w_grid: np.ndarray | None = None

    @classmethod
    def of(cls, res: Result) -> Quantities:
        sc = res.scene
        R, p = np.zeros(0), None
        if np.asarray(res.reactions).size:
            src = res.model.contacts.source
            R = np.asarray(res.reactions, dtype=float)[src == "support"]
            if sc.foundation is not None:  # the bed's pressure: its force over the node's area (k × compression on Winkler's)
                bed = src == "bed"
                area = res.model.bed_areas()[res.model.contacts.index[bed]]
                p = float((np.asarray(res.reactions, dtype=float)[bed] / area).max(initial=0.0))
        w, mesh = res.w_nodes(), res.model.grid
        return cls(mesh_cells(sc), float(np.max(np.abs(w))), R, p,
                   mesh.grid_view(w))


def changes(coarse: Quantities, fine: Quantities) -> dict[str, float]:
    """Relative changes from ``coarse`` to ``fine`` (twice as many cells a side).

    ``w``: of the deflection at the coarse mesh's nodes (which are nodes of the fine one),
    relative to max |w| — the field, not only its maximum, so that a maximum sitting on a
    support held at its gap cannot hide the change; ``reactions``: the largest change of a
    support's reaction relative to the largest reaction; ``bed``: of the largest bed pressure.
    """
    out = {"w": _rel(fine.w_max, coarse.w_max), "reactions": 0.0, "bed": 0.0}
    cw, fw = coarse.w_grid, fine.w_grid
    # a grid's nodes are nodes of the grid with half the cells (a triangle mesh's are not: there max |w|)
    if cw is not None and fw is not None and fw.shape == (2 * cw.shape[0] - 1, 2 * cw.shape[1] - 1):
        d = np.abs(fw[::2, ::2] - cw)
        out["w"] = max(out["w"], float(np.nanmax(d)) / max(fine.w_max, coarse.w_max, 1e-300))
    if fine.reactions.size and coarse.reactions.size == fine.reactions.size:
        scale = max(np.abs(fine.reactions).max(), np.abs(coarse.reactions).max(), 1e-300)
        out["reactions"] = float(np.abs(fine.reactions - coarse.reactions).max() / scale)
    if fine.p_max is not None and coarse.p_max is not None:
        out["bed"] = _rel(fine.p_max, coarse.p_max)
    return out


@dataclass
class ErrorEstimate:
    """Estimated relative discretisation errors of a mesh, from two solved meshes.

    ``w``: of max |w|; ``reactions``: of the discrete supports' reactions (max over supports,
    relative to the largest); ``bed``: of the bed's largest pressure; ``worst``: the largest.
    """

    mesh: tuple[int, int]
    from_meshes: tuple[tuple[int, int], tuple[int, int]]
    order: float
    w: float
    reactions: float = 0.0
    bed: float = 0.0
    #: after the mesh itself is solved (:func:`confirm`): the same error estimated from the
    #: finer pair (h·2, h), and whether it agrees with this one (None: not checked)
    observed: float | None = None
    trusted: bool | None = None
    #: the quantities of the finer coarse mesh (h·2), kept for :func:`confirm`
    basis: Quantities | None = field(default=None, repr=False, compare=False)

    @property
    def worst(self) -> float:
        return max(self.w, self.reactions, self.bed)

    def as_dict(self) -> dict:
        d = {"mesh": list(self.mesh), "from_meshes": [list(m) for m in self.from_meshes], "order": self.order,
             "w": self.w, "reactions": self.reactions, "bed": self.bed, "worst": self.worst}
        if self.trusted is not None:
            d["observed"], d["trusted"] = self.observed, self.trusted
        return d


def _rel(a: float, b: float) -> float:
    return abs(a - b) / max(abs(a), abs(b), 1e-300)


def richardson(coarse: Quantities, fine: Quantities, order: float = ORDER, steps: int = 0) -> ErrorEstimate:
    """The error of the mesh ``steps`` halvings finer than ``fine`` (0: of ``fine`` itself),
    from the change between ``coarse`` (twice the cell size) and ``fine``."""
    f = 1.0 / ((2.0 ** order - 1.0) * 2.0 ** (order * steps))
    d = changes(coarse, fine)
    nx, ny = fine.mesh
    mesh = (nx * 2 ** steps, ny * 2 ** steps)
    return ErrorEstimate(mesh, (coarse.mesh, fine.mesh), order, f * d["w"], f * d["reactions"], f * d["bed"])


#: An estimate is not trusted when the finer pair of meshes changes the answer more than this
#: many times what it predicted (the meshes are not in the asymptotic range: a support next
#: to a clamped edge carries nothing on 2² and 4², 196 on 8², 22 on 128²) ...
DISTRUST_FACTOR = 4.0
#: ... and more than this (below it the change is the solvers' tolerance, not the mesh's).
DISTRUST_FLOOR = 1e-8


def confirm(est: ErrorEstimate, final: Result, order: float = ORDER) -> ErrorEstimate:
    """Check an estimate from the meshes h·4, h·2 against the answer on h itself: the error of
    h estimated again from the pair (h·2, h) (``observed``) must not exceed
    :data:`DISTRUST_FACTOR` × the prediction (and :data:`DISTRUST_FLOOR`); else ``trusted``
    is False (the meshes disagree: Richardson's assumption q(h) = q* + C hᵖ does not hold
    there). Sets and returns ``est``."""
    if est.basis is None:
        return est
    again = richardson(est.basis, Quantities.of(final), order, steps=0)
    est.observed = again.worst
    est.trusted = bool(again.worst <= max(DISTRUST_FACTOR * est.worst, DISTRUST_FLOOR))
    return est


def with_mesh(scene: Scene, nx: int, ny: int) -> Scene:
    """A validated copy of ``scene`` meshed nx × ny cells a side: on a grid nx × ny cells, on
    triangles of element size h = L / nx (:func:`plateqp.model.generators.with_cells`)."""
    return with_cells(scene, nx, ny)


def quiet_solve(solve: Callable[..., Result], scene: Scene, backend: str, formulation: str, tol: float) -> Result:
    """``solve(scene, backend=, formulation=, accuracy=tol)`` without PlateQPWarnings (the status says it)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlateQPWarning)
        return solve(scene, backend=backend, formulation=formulation, accuracy=tol)


def auto_tolerance(scene: Scene, solve: Callable[..., Result], backend: str = "auto", formulation: str = "auto",
                   fraction: float = FRACTION, order: float = ORDER) -> tuple[float, ErrorEstimate | None]:
    """The solver tolerance for ``accuracy="auto"``: ``fraction`` × the estimated relative
    discretisation error of the scene's mesh, within [1e-12, :data:`LOOSEST`].

    ``solve`` is :func:`plateqp.solve` (passed in, so that this module stays below it). The
    estimate solves the scene on the meshes with twice and four times the cell size (at a
    tight tolerance, with the same backend and formulation). A mesh too coarse to halve
    twice (fewer than 4 cells a side), or coarse meshes that cannot be built or solved, give
    (:data:`LOOSEST`, None): on such a mesh the discretisation error dwarfs 1e-3 anyway.
    """
    nx, ny = mesh_cells(scene)
    if min(nx, ny) < 4:
        return LOOSEST, None
    qs = []
    try:
        for k in (4, 2):
            coarse = with_mesh(scene, max(1, round(nx / k)), max(1, round(ny / k)))
            res = quiet_solve(solve, coarse, backend, formulation, 1e-9)
            qs.append(Quantities.of(res))
    except COARSE_FAILURES:
        return LOOSEST, None
    est = richardson(qs[0], qs[1], order, steps=1)
    est.mesh = (nx, ny)
    est.basis = qs[1] if qs[1].mesh == (round(nx / 2), round(ny / 2)) and 2 * qs[1].mesh[0] == nx \
        and 2 * qs[1].mesh[1] == ny else None
    tol = float(np.clip(fraction * est.worst, 1e-12, LOOSEST))
    return tol, est


__all__ = ["COARSE_FAILURES", "DISTRUST_FACTOR", "DISTRUST_FLOOR", "ErrorEstimate", "confirm", "Quantities", "auto_tolerance", "changes", "quiet_solve", "richardson",
           "with_mesh"]
