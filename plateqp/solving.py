"""The public solve: ``solve(scene, ...)`` and ``solve_bilateral(scene)``.

A scene without one-sided supports is solved directly (one sparse factorisation). A scene
with them goes through a formulation (primal, condensed or dual) and a backend; see
:mod:`plateqp.contact`. (This module is ``solving``, not ``solve``: a submodule named like
the function ``plateqp.solve`` would shadow it.)
"""

from __future__ import annotations

import os
import time
import warnings

import numpy as np

from .accuracy import Accuracy
from .model.assembly import Model, build_model
from .contact import solve_bilateral as _solve_bilateral
from .contact import solve_contact
from .errors import ArgumentError, MechanismError, PlateQPWarning, ProblemError, SceneError, SolverError
from .estimate import auto_tolerance, confirm
from .linalg import Factor
from .model.parts import _short, plain
from .results import Result
from .model.scene import Scene


def describe_modes(model: Model, modes: np.ndarray) -> str:
    """Words for the rigid motions a set of two-sided supports leaves free."""
    k = modes.shape[1]
    what = {1: "one rigid motion", 2: "two rigid motions", 3: "three rigid motions"}.get(k, f"{k} rigid motions")
    return (f"the two-sided supports leave {what} of the plate free (vertical translation and/or "
            "rotation about a line); add pins or edge supports, or one-sided supports that hold it")


def solve_two_sided(model: Model, factor: Factor | None = None) -> tuple[np.ndarray, float, Factor]:
    """u_free and ‖K u − f‖/‖f‖ for the two-sided problem; MechanismError if K is singular."""
    modes = model.rigid_modes()
    if modes.shape[1]:
        raise MechanismError(describe_modes(model, modes))
    factor = factor or Factor(model.K)
    u = factor.solve(model.f)
    return u, factor.residual(u, model.f), factor


def check_arguments(scene, backend="auto", formulation="auto", accuracy="default", options=None, model=None,
                    check_statics=True):
    """The arguments of :func:`solve`, before any work: the scene a Scene, validated again (it
    may have changed since it was built: the same SceneError its construction would give), the
    others of their types, each error naming its argument. Returns ``accuracy`` with a NumPy
    number made a Python one."""
    if not isinstance(scene, Scene):
        hint = {dict: "; build one with Scene.from_dict(d)", str: "; load a file with Scene.from_toml(path)"}
        kind = next((v for k, v in hint.items() if isinstance(scene, k)), "")
        kind = kind or ("; load a file with Scene.from_toml(path)" if isinstance(scene, os.PathLike) else "")
        raise SceneError(f"scene: must be a plateqp Scene (got {_short(scene)}){kind}")
    scene.revalidate()
    if not isinstance(backend, str) or not backend:
        raise SolverError(f"backend: must be a backend name such as \"auto\" or \"lemke\" (got {_short(backend)})")
    if not isinstance(formulation, str):
        raise ProblemError(f"formulation: must be \"auto\", \"primal\", \"condensed\" or \"dual\" "
                           f"(got {_short(formulation)})")
    accuracy = plain(accuracy)
    if not isinstance(accuracy, (str, int, float)) or isinstance(accuracy, bool):
        raise ProblemError(f"accuracy: must be \"low\", \"default\", \"high\", \"auto\" or a tolerance "
                           f"(got {_short(accuracy)})")
    if options is not None and (not isinstance(options, dict) or not all(isinstance(k, str) for k in options)):
        raise ArgumentError(f"options: must be a dict of option names to values, or None (got {_short(options)})")
    if model is not None and not isinstance(model, Model):
        raise ArgumentError(f"model: must be a Model built from this scene (plateqp.model.assembly.build_model), "
                            f"or None (got {_short(model)})")
    if not isinstance(plain(check_statics), bool):
        raise ArgumentError(f"check_statics: must be True or False (got {_short(check_statics)})")
    return accuracy


def solve(scene: Scene, backend: str = "auto", formulation: str = "auto", accuracy: str | float = "default",
          options: dict | None = None, model: Model | None = None, check_statics: bool = True) -> Result:
    """Solve a scene.

    Parameters
    ----------
    scene : the :class:`~plateqp.model.scene.Scene`
    backend : a name from :func:`plateqp.available_backends` ("auto": pdas on the sparse
        primal; bpp on the condensed problem in a sweep (which re-uses the condensation) with
        at most 100 contact points; the rule and its measurements:
        :mod:`plateqp.contact.routing`, benchmarks/README.md; where that route stops short, the
        next exact one, and ``extras["route"]`` says which answered and why the others stopped)
    formulation : "primal", "condensed", "dual" or "auto" (with a named backend: the form it
        takes; with a QP backend that takes all, condensed while m ≤ 10 % of the dofs and ≤ 1000)
    accuracy : "low", "default" or "high" (KKT tolerance 1e-3, 1e-6, 1e-9), or a tolerance
        between 1e-14 and 0.1 (each backend maps it to its own settings: the nearest preset's,
        with its tolerances scaled; see :func:`plateqp.backends.base.preset`), or "auto": a
        tenth of the discretisation error of the scene's mesh, estimated from the two coarser
        meshes (:func:`plateqp.estimate.auto_tolerance`; ``extras["discretisation_error"]``),
        then checked against this mesh's answer (:func:`plateqp.estimate.confirm`: a
        PlateQPWarning and ``"trusted": false`` there when the meshes disagree)
    options : passed to the backend untouched, but for ``predict`` ("auto", True or False):
        start pdas on the primal problem from the contact set of the scene's mesh coarsened
        four times ("auto": where every contact row is soft and there are at least 4000 of
        them; :mod:`plateqp.contact.predict`; ``extras["predicted"]`` says what was done or why not)
    model : a model built before from the same scene (skips the assembly)
    check_statics : check first, by statics alone, that the one-sided supports can carry the
        load (else NoEquilibriumError before any solve); set False to let the backend find out

    Returns
    -------
    Result, whose ``status`` says whether the KKT residuals meet the asked accuracy.

    Raises
    ------
    SceneError
        If ``scene`` is not a valid Scene (checked again here: it may have been changed since
        it was built), before any work.
    PlateQPError
        One of its kinds, naming the argument, for any other bad argument
        (:func:`check_arguments`), before any work.
    """
    accuracy = check_arguments(scene, backend, formulation, accuracy, options, model, check_statics)
    auto = isinstance(accuracy, str) and accuracy == "auto"
    if not auto:
        accuracy = Accuracy.parse(accuracy)  # a bad accuracy fails before any work
    t0 = time.perf_counter()
    # backend "mprgp" solves a half-space on the grid matrix-free at any size (plateqp.contact.pressures)
    model = model or build_model(scene, soil_operator=True if backend == "mprgp" else None)
    t_build = time.perf_counter() - t0
    if not scene.one_sided:
        t1 = time.perf_counter()
        u, res, _ = solve_two_sided(model)
        t2 = time.perf_counter()
        return Result(scene, model, model.expand(u), residual=res,
                      accuracy="auto" if auto else accuracy.asked,
                      times={"build": t_build, "solve": t2 - t1, "total": t2 - t0})
    if auto:
        t_est = time.perf_counter()
        accuracy, estimate = auto_tolerance(scene, solve, backend=backend, formulation=formulation)
        t_est = time.perf_counter() - t_est
    result = solve_contact(model, backend=backend, formulation=formulation, accuracy=accuracy,
                           options=options, check_statics=check_statics)
    if auto:
        result.extras["accuracy"] = "auto"
        if estimate is not None and result.status.solved:
            confirm(estimate, result)
            if estimate.trusted is False:
                warnings.warn(f'accuracy="auto": the meshes disagree (error of the {scene.mesh.nx}x{scene.mesh.ny}'
                              f" mesh estimated {estimate.worst:.2g} from the two coarser meshes, {estimate.observed:.2g}"
                              " from the next coarser and this one): the error estimate is not to be trusted;"
                              " refine the mesh (plateqp solve --target)", PlateQPWarning, stacklevel=2)
        result.extras["discretisation_error"] = estimate.as_dict() if estimate is not None else None
        result.times["estimate"] = t_est
    result.times["build"] = t_build
    result.times["total"] = time.perf_counter() - t0
    return result


def solve_bilateral(scene: Scene, model: Model | None = None) -> Result:
    """The paper's comparison: the same scene with every one-sided support made two-sided."""
    check_arguments(scene, model=model)
    return _solve_bilateral(model or build_model(scene))
