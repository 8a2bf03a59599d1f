"""Mesh refinement by halving: the convergence table of a study, and the coarsest mesh that
meets a target error.

Both solve one scene on meshes that halve (:func:`solve_on_meshes`, with
:func:`plateqp.estimate.with_mesh`); they differ in what they read from the answers.

Convergence (:func:`convergence`)
---------------------------------
The source paper's criterion: solve on meshes that halve (2, 4, 8, 16, 32 cells a side) and
watch each quantity's relative change from one mesh to the next. A mesh counts as converged
for a quantity when halving it (and every finer mesh after it) changes the quantity by less
than ``target``.

A target error (:func:`solve_to_target`, ``plateqp solve --target REL``)
------------------------------------------------------------------------
Refine from a coarse mesh until the estimated error of max |w| and of the reactions is below
REL, each mesh solved at a solver tolerance of a tenth of REL: the coarsest mesh and the
loosest setting that reach it. The estimate is Richardson's (:mod:`plateqp.estimate`,
:class:`~plateqp.estimate.Quantities`, :func:`~plateqp.estimate.richardson`), which is also
what ``accuracy="auto"`` uses (:func:`auto_tolerance`).

Triangle meshes
---------------
On a triangle-meshed scene (``mesh.element = "dkt"``) a mesh of n "cells a side" is the gmsh
mesh of element size h = L / n, L the plate's larger bounding-box side
(:func:`plateqp.model.generators.mesh_cells`): halving the mesh halves h. The meshes are not nested,
so the change on halving is read from max |w| (and the reactions), not from the field at the
coarse mesh's nodes.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..accuracy import TOL_RANGE
from ..model.generators import mesh_cells, start_cells
from ..errors import PlateQPError, PlateQPWarning, ProblemError, SceneError
from ..progress import track
from ..estimate import (COARSE_FAILURES, FRACTION, LOOSEST, ORDER, ErrorEstimate, Quantities, changes, quiet_solve,
                        richardson, with_mesh)
from ..estimate import auto_tolerance as _auto_tolerance
from ..results import Result
from ..model.scene import Scene
from ..solving import solve

# =============================================================================================
# The shared loop: one scene on a sequence of meshes
# =============================================================================================


@dataclass
class MeshSolve:
    """One mesh of a refinement: the result, or the error it failed with (``result`` None)."""

    mesh: tuple[int, int]
    result: Result | None
    error: PlateQPError | None
    seconds: float


def solve_on_meshes(scene: Scene, meshes: Iterable[tuple[int, int]], backend: str = "auto",
                    formulation: str = "auto", accuracy: str | float = "default",
                    skip: tuple[type[Exception], ...] = (PlateQPError,)) -> Iterator[MeshSolve]:
    """Solve ``scene`` on each (nx, ny) of ``meshes`` in turn (lazily: stop when you have enough).

    Each mesh is a validated copy of the scene (:func:`plateqp.estimate.with_mesh`) solved
    without PlateQPWarnings (the result's status says it). A mesh that cannot be built or
    solved with an error of a class in ``skip`` is yielded with that error; others propagate.
    """
    for nx, ny in track(meshes, "meshes"):  # a bar on a terminal (plateqp.progress)
        t0 = time.perf_counter()
        try:
            res = quiet_solve(solve, with_mesh(scene, nx, ny), backend, formulation, accuracy)
        except skip as exn:
            yield MeshSolve((nx, ny), None, exn, time.perf_counter() - t0)
            continue
        yield MeshSolve((nx, ny), res, None, time.perf_counter() - t0)


def halvings(start: tuple[int, int], max_cells: int) -> Iterator[tuple[int, int]]:
    """``start``, then meshes with twice as many cells a side, while no side exceeds ``max_cells``."""
    nx, ny = start
    while max(nx, ny) <= max_cells:
        yield nx, ny
        nx, ny = 2 * nx, 2 * ny


# =============================================================================================
# Convergence by mesh halving
# =============================================================================================

@dataclass
class ConvergenceTable:
    """Quantities on a sequence of meshes and their relative change on halving each mesh.

    ``diff[q][k] = |q_{k+1} − q_k| / |q_{k+1}|``: the change of quantity q when mesh k is
    halved (NaN on the finest mesh). ``converged_at[q]``: the coarsest mesh from which every
    further halving changes q by less than ``target`` (None if none does).
    """

    meshes: list[tuple[int, int]]
    quantities: list[str]
    values: dict[str, np.ndarray]
    diff: dict[str, np.ndarray]
    converged_at: dict[str, tuple[int, int] | None]
    target: float
    errors: list[str | None] = field(default_factory=list)

    @property
    def rows(self) -> list[dict]:
        """One dict per mesh: nx, ny, each quantity and its change on halving ("<q> diff")."""
        out = []
        for k, (nx, ny) in enumerate(self.meshes):
            r: dict[str, Any] = {"nx": nx, "ny": ny}
            for q in self.quantities:
                r[q] = float(self.values[q][k])
                r[f"{q} diff"] = float(self.diff[q][k])
            r["error"] = self.errors[k] if self.errors else None
            out.append(r)
        return out

    def __str__(self) -> str:
        head = f"{'mesh':>9s}" + "".join(f" {q:>16s} {'change':>9s}" for q in self.quantities)
        lines = [head]
        for k, (nx, ny) in enumerate(self.meshes):
            line = f"{f'{nx}x{ny}':>9s}"
            for q in self.quantities:
                d = self.diff[q][k]
                line += f" {self.values[q][k]:16.6g} {('' if np.isnan(d) else f'{d:9.2%}'):>9s}"
            if self.errors and self.errors[k]:
                line += f"   ({self.errors[k]})"
            lines.append(line)
        for q in self.quantities:
            m = self.converged_at[q]
            lines.append(f"{q}: " + (f"converged at {m[0]}x{m[1]} (change < {self.target:g})" if m
                                     else f"not converged to {self.target:g} on these meshes"))
        return "\n".join(lines)


def quantity(result, name: str) -> float:
    """A named scalar of a result: ``w_max`` (signed w of largest |w|), ``s1_max`` (max nodal σ1),
    ``reactions.I`` (reaction at contact point I; also ``R3``), ``sum_reactions``,
    ``w:X,Y`` (deflection at a point)."""
    if name == "w_max":
        return result.w_max()[0]
    if name == "s1_max":
        return float(np.nanmax(result.nodal("s1")))
    if name == "sum_reactions":
        return float(np.sum(result.reactions))
    if name.startswith("reactions.") or (name.startswith("R") and name[1:].isdigit()):
        i = int(name.split(".", 1)[1] if "." in name else name[1:])
        if not 0 <= i < result.reactions.size:
            raise SceneError(f"quantity {name!r}: no contact point {i} (the scene has {result.reactions.size})")
        return float(result.reactions[i])
    if name.startswith("w:"):
        x, y = (float(v) for v in name[2:].split(","))
        return float(result.deflection(x, y))
    raise ValueError(f"unknown quantity {name!r}; use w_max, s1_max, sum_reactions, reactions.I, or w:X,Y")


def _quantity_scale(result, name: str) -> float:
    """The size of the family a built-in quantity belongs to (max |w|, max |R|, max |σ1|), so a
    quantity that is zero (a lifted support's reaction) is compared with its family, not with noise."""
    if name.startswith("reactions.") or name == "sum_reactions" or (name.startswith("R") and name[1:].isdigit()):
        return float(np.abs(result.reactions).max(initial=0.0))
    if name == "w_max" or name.startswith("w:"):
        return float(np.nanmax(np.abs(result.w_nodes())))
    if name == "s1_max":
        return float(np.nanmax(np.abs(result.nodal("s1"))))
    return 0.0


def convergence(scene: Scene, meshes: Sequence = (2, 4, 8, 16, 32),
                quantities: Sequence = ("w_max",), target: float = 0.01, backend: str = "auto",
                formulation: str = "auto", accuracy: str = "default") -> ConvergenceTable:
    """Solve ``scene`` on meshes that halve and tabulate each quantity and its change.

    Parameters
    ----------
    meshes : cells a side (``n`` → nx = n, ny = n × the scene's ny/nx), or (nx, ny) pairs,
        coarse to fine; on triangles ``n`` is the element size L / n (see the module docstring)
    quantities : names understood by :func:`quantity`, or (name, callable(result) → float) pairs
    target : relative change under which a quantity counts as converged

    Supports off the nodes of a coarse mesh act through the element's interpolation; pins
    must lie on the nodes of every mesh (else that mesh's row records the SceneError).
    """
    cx, cy = mesh_cells(scene)
    ratio = cy / cx
    mesh_list = [(int(m[0]), int(m[1])) if isinstance(m, (tuple, list)) else (int(m), max(1, round(m * ratio)))
                 for m in meshes]
    names, funcs = [], []
    for q in quantities:
        if isinstance(q, str):
            names.append(q)
            funcs.append(lambda r, q=q: (quantity(r, q), _quantity_scale(r, q)))
        else:
            names.append(str(q[0]))
            funcs.append(lambda r, fn=q[1]: (float(fn(r)), 0.0))
    vals = {q: np.full(len(mesh_list), np.nan) for q in names}
    scales = {q: np.zeros(len(mesh_list)) for q in names}
    errors: list[str | None] = []
    for k, one in enumerate(solve_on_meshes(scene, mesh_list, backend, formulation, accuracy)):
        if one.error is not None:
            errors.append(f"{type(one.error).__name__}: {one.error}")
            continue
        try:
            for q, fn in zip(names, funcs):
                vals[q][k], scales[q][k] = fn(one.result)
            errors.append(None if one.result.ok else f"status {one.result.status.value}")
        except PlateQPError as exn:
            errors.append(f"{type(exn).__name__}: {exn}")
    diff, conv = {}, {}
    for q in names:
        v = vals[q]
        d = np.full(len(v), np.nan)
        for k in range(len(v) - 1):
            # relative to the finer value, floored by 1e-9 of its family's size (or of |q| over the meshes)
            fam = scales[q][k + 1] or (np.nanmax(np.abs(v)) if np.any(np.isfinite(v)) else 0.0)
            den = max(abs(v[k + 1]), 1e-9 * fam)
            d[k] = abs(v[k + 1] - v[k]) / den if den > 0 else 0.0
        diff[q] = d
        conv[q] = None
        for k in range(len(v) - 2, -1, -1):  # from the finest pair back while the changes stay small
            if not d[k] < target:
                break
            conv[q] = mesh_list[k]
    return ConvergenceTable(mesh_list, names, vals, diff, conv, target, errors)


# =============================================================================================
# The coarsest mesh for a target error
# =============================================================================================

@dataclass
class TargetResult:
    """What :func:`solve_to_target` did: the meshes it solved, each one's estimated error, and
    the result on the mesh it chose (``result``; None if none reached the target)."""

    target: float
    tolerance: float
    result: Result | None
    rows: list[dict] = field(default_factory=list)
    reached: bool = False

    def __str__(self) -> str:
        lines = [f"target {self.target:g} relative in max |w| and reactions; solver tolerance {self.tolerance:g}",
                 f"{'mesh':>9s} {'max |w|':>12s} {'est. err w':>11s} {'est. err R':>11s} {'status':>10s} {'time':>8s}"]
        for r in self.rows:
            e = r["estimate"]
            ew = "" if e is None else f"{e['w']:.1e}"
            eR = "" if e is None else f"{max(e['reactions'], e['bed']):.1e}"
            lines.append(f"{r['mesh'][0]:>4d}x{r['mesh'][1]:<4d} {r['w_max']:12.5g} {ew:>11s} {eR:>11s} "
                         f"{r['status']:>10s} {r['time']:7.2f}s")
        if self.reached:
            sc = self.result.scene
            lines.append(f"reached on {sc.mesh.nx}x{sc.mesh.ny}" + self.result.model.grid.size_note(sc))
        else:
            lines.append("NOT reached on the meshes tried: raise --max-mesh, or loosen the target")
        return "\n".join(lines)


def start_mesh(scene: Scene, cells: int = 4) -> tuple[int, int]:
    """``cells`` on the shorter side, the other in proportion to the scene's own mesh (on
    triangles: (cells, cells), element size L / cells): :func:`plateqp.model.generators.start_cells`."""
    return start_cells(scene, cells)


def _estimate(prev: list[Quantities], q: Quantities, order: float) -> ErrorEstimate | None:
    """Richardson's estimate of the error of ``q`` from the mesh before (half as many cells a
    side), at ``order`` or the order observed on the last three meshes when lower (down to 1)."""
    nx, ny = q.mesh
    if not prev or prev[-1].mesh != (nx // 2, ny // 2):
        return None
    p = order
    if len(prev) >= 2 and prev[-2].mesh == (nx // 4, ny // 4):
        d1, d2 = changes(prev[-2], prev[-1]), changes(prev[-1], q)
        for k in d2:
            if d2[k] > 1e-12 and d1[k] > 1e-12:
                p = min(p, max(1.0, float(np.log2(d1[k] / d2[k]))))
    return richardson(prev[-1], q, p)


def solve_to_target(scene: Scene, target: float, backend: str = "auto", formulation: str = "auto",
                    start: tuple[int, int] | None = None, max_cells: int = 256,
                    order: float = ORDER, progress=None) -> TargetResult:
    """The coarsest mesh (halving from ``start``) whose estimated relative error of max |w|
    and of the reactions is at most ``target``, each mesh solved at a tolerance of
    ``target``/10.

    Each mesh's error is estimated from the change since the mesh before (Richardson, order
    ``order``, or the order observed on the last three meshes when that is lower, down to 1:
    never a higher one, which pre-asymptotic meshes can fake). The answer is the result on the
    first mesh whose estimate meets the target; meshes that cannot be built or solved (a pin
    off their nodes, more supports than the backend takes on so few dofs) are skipped.
    ``progress``: called with each row.
    """
    if not (isinstance(target, (int, float)) and 1e-12 <= target < 1.0):
        raise ProblemError(f"target {target!r} must be a relative error from 1e-12 to below 1")
    tol = float(target)
    solver_tol = float(np.clip(target / 10.0, TOL_RANGE[0], LOOSEST))
    out = TargetResult(target=tol, tolerance=solver_tol, result=None)
    prev: list[Quantities] = []
    meshes = halvings(start or start_mesh(scene), max_cells)
    for one in solve_on_meshes(scene, meshes, backend, formulation, solver_tol, skip=COARSE_FAILURES):
        if one.error is not None:
            out.rows.append({"mesh": one.mesh, "w_max": float("nan"), "estimate": None, "status": "skipped",
                             "time": one.seconds, "error": str(one.error)})
            continue
        res = one.result
        q = Quantities.of(res)
        est = _estimate(prev, q, order)
        row = {"mesh": one.mesh, "w_max": q.w_max, "estimate": est.as_dict() if est else None,
               "status": res.status.value, "time": one.seconds, "error": None}
        out.rows.append(row)
        if progress is not None:
            progress(row)
        prev.append(q)
        out.result = res
        if est is not None and est.worst <= target and res.ok:
            out.reached = True
            break
    if not out.reached:
        warnings.warn(f"target {target:g} not reached up to {max_cells} cells a side", PlateQPWarning, stacklevel=2)
    return out


def auto_tolerance(scene: Scene, backend: str = "auto", formulation: str = "auto", fraction: float = FRACTION,
                   order: float = ORDER) -> tuple[float, ErrorEstimate | None]:
    """:func:`plateqp.estimate.auto_tolerance` with :func:`plateqp.solve` as the solver."""
    return _auto_tolerance(scene, solve, backend=backend, formulation=formulation, fraction=fraction, order=order)


__all__ = ["ConvergenceTable", "MeshSolve", "TargetResult", "auto_tolerance", "convergence", "halvings", "quantity",
           "solve_on_meshes", "solve_to_target", "start_mesh"]
