"""The work of a sweep's worker: solve the scene with PATH = value, and record the row.

A worker (this process or another) keeps, per sweep, the base model built once and the
nodal operator of its mesh (:func:`plateqp.model.recovery.nodal_operator`); with re-use each value's
model is the base adapted to it (:func:`plateqp.studies.reuse.adapt_model`), and the solves
share the factorisations of its K (:func:`plateqp.linalg.keep.sharing`). Warm starts
(``options={"active": ...}``: the previous solve's own final state, ``Result.extras["active"]``,
else its contact set) go only to backends that take them (:data:`WARM_START_BACKENDS`).
"""

from __future__ import annotations

import contextlib
import time
import warnings
from collections import OrderedDict
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model.assembly import Model, build_model
from ..contact.routing import repeated_solves
from ..errors import NoEquilibriumError, PlateQPWarning
from ..linalg.keep import sharing
from ..model.variation import with_value
from ..model.recovery import NodalOperator, nodal_operator
from ..model.scene import Scene
from ..solving import solve
from .reuse import adapt_model

#: Backends that accept ``options={"active": bool array}`` as a warm start.
WARM_START_BACKENDS = ("bpp", "pdas")


@dataclass
class Context:
    """What a worker needs to solve one value (picklable; the model is cached per process)."""

    token: str
    scene: Scene
    path: str
    backend: str
    formulation: str
    accuracy: str
    options: dict | None
    reuse: bool
    warm_start: bool = True


@dataclass
class Base:
    """What a worker keeps of a sweep: the base model and, built on first use, the operator
    of the rows' nodal fields on its mesh (:class:`plateqp.model.recovery.NodalOperator`)."""

    model: Model
    nodal: NodalOperator | None = None


_MODELS: OrderedDict[str, Base] = OrderedDict()  # per process: the base of a sweep
_MODELS_KEEP = 4


def base_of(ctx: Context) -> Base:
    """The base of the sweep ``ctx`` in this process, built on first use (the last few are kept)."""
    b = _MODELS.get(ctx.token)
    if b is None:
        b = Base(build_model(ctx.scene))
        _MODELS[ctx.token] = b
        while len(_MODELS) > _MODELS_KEEP:
            _MODELS.popitem(last=False)
    return b


def seed(ctx: Context, model: Model) -> None:
    """Make ``model`` (built from ``ctx.scene`` with PATH at some value) the base of the sweep
    ``ctx`` in this process: its values adapt it and share what its solves kept."""
    _MODELS[ctx.token] = Base(model)
    while len(_MODELS) > _MODELS_KEEP:
        _MODELS.popitem(last=False)


def forget(token: str) -> None:
    """Drop the base of the sweep ``token`` from this process."""
    _MODELS.pop(token, None)


def solve_value(ctx: Context, value, warm=None):
    """Solve the scene with PATH = value.

    Returns (row, contact set as a bool tuple or None, (backend, warm-start state) or None).
    The warm-start state is the backend's own ``extras["active"]`` when it returns one (bpp's
    is in the LCP's terms: on the dual formulation True means *not* in contact), else the
    contact set. Never raises for a failed solve: the row records the error and status.
    """

    t0 = time.perf_counter()
    try:
        # only what the value changes copied and checked (the sweep checked its scene: check_values)
        scene = with_value(ctx.scene, ctx.path, value, checked=True)
        t_scene = time.perf_counter() - t0
        model = base = None
        if ctx.reuse:
            base = base_of(ctx)
            model = adapt_model(base.model, scene)
        t_adapt = time.perf_counter() - t0
        opts = dict(ctx.options or {})
        if warm is not None:
            opts["active"] = np.asarray(warm, dtype=bool)
        again = (repeated_solves, sharing) if ctx.reuse else (contextlib.nullcontext, contextlib.nullcontext)
        with warnings.catch_warnings(), again[0](), again[1]():
            warnings.simplefilter("ignore", PlateQPWarning)  # the row's status says it
            res = solve(scene, backend=ctx.backend, formulation=ctx.formulation, accuracy=ctx.accuracy,
                        options=opts or None, model=model)
        t_post = time.perf_counter()
        row = {"value": value, **res.to_dict()}
        if model is not None:  # an adapted model shares the base's mesh: its operator serves
            if base.nodal is None:
                base.nodal = nodal_operator(base.model)
            row["s1_max"] = float(np.nanmax(base.nodal(res.u, res.scene.plate, "s1")))
        else:
            row["s1_max"] = float(np.nanmax(res.nodal("s1")))
        row["kkt_worst"] = res.kkt.worst if res.kkt is not None else None
        row["error"] = None
        t1 = time.perf_counter()
        times = row["times"]
        times["build"] = (times["build"] or 0.0) + t_adapt
        times["total"] = t1 - t0
        times.update(scene=t_scene, formulate=res.times.get("formulate"), recover=res.times.get("recover"),
                     post=t1 - t_post)
        active = tuple(np.asarray(res.active, dtype=bool).tolist())
        state = np.asarray(res.extras.get("active", res.active), dtype=bool).copy()
        return row, active, (res.backend, state)
    except Exception as exn:  # never lose a sweep to one value: record it and go on
        status = "infeasible" if isinstance(exn, NoEquilibriumError) else "error"
        row = {"value": value, "scene": ctx.scene.name, "backend": ctx.backend, "formulation": ctx.formulation,
               "accuracy": ctx.accuracy, "status": status, "w_max": None, "w_max_x": None, "w_max_y": None,
               "probes": [], "reactions": None, "active": None, "gaps": None, "residual": None,
               "deflection_unique": None, "kkt": None,
               "iterations": None,
               "times": {"build": None, "solve": None, "total": time.perf_counter() - t0, "scene": None,
                         "formulate": None, "recover": None, "post": None},
               "s1_max": None, "kkt_worst": None, "error": f"{type(exn).__name__}: {exn}"}
        return row, None, None


def next_start(ctx: Context, state):
    """The warm start for the next solve: only for backends that take one, and only with re-use
    and warm starts on."""
    if state is None or not (ctx.reuse and ctx.warm_start) or state[0] not in WARM_START_BACKENDS:
        return None
    return state[1]


def run_chunk(ctx: Context, items: list[tuple[int, Any]], state=None):
    """Solve values in order, each warm-started from the one before when the backend allows."""
    from .parallel import stream_row

    out = []
    for i, v in items:
        row, _, new = solve_value(ctx, v, next_start(ctx, state))
        out.append((i, row))
        stream_row(ctx.token, i, row)  # in our worker processes: to the sweep now, not with the chunk
        state = new or state
    return out


__all__ = ["Base", "Context", "WARM_START_BACKENDS", "base_of", "forget", "run_chunk", "next_start", "seed",
           "solve_value"]
