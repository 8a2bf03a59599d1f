"""Pick the mesh for a target: the coarsest mesh (halving) whose estimated error meets it.

The estimator (Richardson on halving meshes) is :mod:`plateqp.estimate`.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from .accuracy import TOL_RANGE
from .errors import PlateQPWarning, ProblemError
from .estimate import COARSE_FAILURES, FRACTION, LOOSEST, ORDER, ErrorEstimate, Quantities, changes, quiet_solve, richardson, with_mesh
from .estimate import auto_tolerance as _auto_tolerance
from .results import Result
from .scene import Scene
from .solving import solve


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
            lines.append(f"reached on {self.result.scene.mesh.nx}x{self.result.scene.mesh.ny}")
        else:
            lines.append("NOT reached on the meshes tried: raise --max-mesh, or loosen the target")
        return "\n".join(lines)


def start_mesh(scene: Scene, cells: int = 4) -> tuple[int, int]:
    """``cells`` on the shorter side, the other in proportion to the scene's own mesh."""
    nx, ny = scene.mesh.nx, scene.mesh.ny
    if nx <= ny:
        return cells, max(cells, round(cells * ny / nx))
    return max(cells, round(cells * nx / ny)), cells


def solve_to_target(scene: Scene, target: float, backend: str = "auto", formulation: str = "auto",
                    start: tuple[int, int] | None = None, max_cells: int = 256,
                    order: float = ORDER, progress=None) -> TargetResult:
    """The coarsest mesh (halving from ``start``) whose estimated relative error of max |w|
    and of the reactions is at most ``target``, each mesh solved at a tolerance of
    ``target``/10.

    Each mesh's error is estimated from the change since the mesh before (Richardson, order
    ``order``, or the order observed on the last three meshes when that is lower, down to 1:
    never a higher one, which pre-asymptotic meshes can fake). The answer is the result on the first mesh whose estimate meets the target; meshes that
    cannot be built or solved (a pin off their nodes, more supports than the backend takes
    on so few dofs) are skipped. ``progress``: called with each row.
    """
    if not (isinstance(target, (int, float)) and 1e-12 <= target < 1.0):
        raise ProblemError(f"target {target!r} must be a relative error from 1e-12 to below 1")
    tol = float(target)
    solver_tol = float(np.clip(target / 10.0, TOL_RANGE[0], LOOSEST))
    nx, ny = start or start_mesh(scene)
    out = TargetResult(target=tol, tolerance=solver_tol, result=None)
    prev: list[Quantities] = []
    while max(nx, ny) <= max_cells:
        t0 = time.perf_counter()
        try:
            sc = with_mesh(scene, nx, ny)
            res = quiet_solve(solve, sc, backend, formulation, solver_tol)
        except COARSE_FAILURES as exn:
            out.rows.append({"mesh": (nx, ny), "w_max": float("nan"), "estimate": None, "status": "skipped",
                             "time": time.perf_counter() - t0, "error": str(exn)})
            nx, ny = 2 * nx, 2 * ny
            continue
        q = Quantities.of(res)
        est = None
        if prev and prev[-1].mesh == (nx // 2, ny // 2):
            p = order
            if len(prev) >= 2 and prev[-2].mesh == (nx // 4, ny // 4):
                d1, d2 = changes(prev[-2], prev[-1]), changes(prev[-1], q)
                for k in d2:
                    if d2[k] > 1e-12 and d1[k] > 1e-12:
                        p = min(p, max(1.0, float(np.log2(d1[k] / d2[k]))))
            est = richardson(prev[-1], q, p)
        row = {"mesh": (nx, ny), "w_max": q.w_max, "estimate": est.as_dict() if est else None,
               "status": res.status.value, "time": time.perf_counter() - t0, "error": None}
        out.rows.append(row)
        if progress is not None:
            progress(row)
        prev.append(q)
        out.result = res
        if est is not None and est.worst <= target and res.ok:
            out.reached = True
            break
        nx, ny = 2 * nx, 2 * ny
    if not out.reached:
        warnings.warn(f"target {target:g} not reached up to {max_cells} cells a side", PlateQPWarning, stacklevel=2)
    return out


def auto_tolerance(scene: Scene, backend: str = "auto", formulation: str = "auto", fraction: float = FRACTION,
                   order: float = ORDER) -> tuple[float, ErrorEstimate | None]:
    """:func:`plateqp.estimate.auto_tolerance` with :func:`plateqp.solve` as the solver."""
    return _auto_tolerance(scene, solve, backend=backend, formulation=formulation, fraction=fraction, order=order)


__all__ = ["ErrorEstimate", "Quantities", "TargetResult", "auto_tolerance", "richardson", "solve_to_target"]
