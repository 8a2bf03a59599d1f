"""Sweeps of one scene parameter, with the breakpoints where the working scheme changes.

One row per value: reactions, contact set, w_max, max σ1, KKT report, status, times (the
fields of ``plateqp solve --json`` plus ``value``). Between two successive values whose contact
sets differ, the change is located by bisection (:mod:`plateqp.studies.breakpoints`). Re-use:
the model (stiffness matrix, contact operator) is built once per worker and only the gaps,
support flexibilities or loads are changed in a copy when the parameter does not change K
(:func:`plateqp.studies.reuse.adapt_model`); the max nodal σ1 of each row is then computed
with operators built once per mesh (:class:`plateqp.model.recovery.NodalOperator`). Warm starts
(``options={"active": ...}``: the previous solve's own final state, ``Result.extras["active"]``,
else its contact set) go only to backends that take them (:data:`WARM_START_BACKENDS`), with
re-use on; ``warm_start=False`` turns them off alone. Where the values are solved:
:mod:`plateqp.studies.parallel`.
"""

from __future__ import annotations

import json
import logging
import math
import time
import uuid
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from ..errors import ProblemError
from ..model.paths import as_number, get_param
from ..model.variation import check_values
from ..model.scene import Scene
from .breakpoints import Bisection, contact_set, refine_bracket
from ..progress import Progress
from .parallel import SERIAL_BELOW, make_runner
from .worker import WARM_START_BACKENDS, Context, forget, next_start, run_chunk, seed, solve_value

logger = logging.getLogger(__name__)


class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped by Ctrl-C (or a SIGTERM its caller turned into one) after its worker
    processes were stopped; ``result`` is the :class:`SweepResult` of the values done so far
    (``result.interrupted`` says which were not). A KeyboardInterrupt, so code that does not
    know it stops as before."""

    def __init__(self, result: "SweepResult"):
        super().__init__(f"sweep interrupted: {result.interrupted['done']} of {result.interrupted['of']} values done")
        self.result = result


@dataclass
class SweepResult:
    """The rows of a sweep (one per value) and the breakpoints between them.

    ``rows``: dicts with the fields of ``plateqp solve --json`` plus ``value``, ``s1_max``,
    ``kkt_worst`` and ``error`` (None, or the failure of that value: its status is then
    "infeasible" for no equilibrium, else "error"). A row's ``times`` (seconds) has, besides
    ``build`` (scene copy and model, adapted or built), ``solve`` (the backend) and ``total``,
    the parts ``scene`` (copy and validation of the scene), ``formulate`` (scaling, statics
    check, formulation), ``recover`` (fields and KKT report) and ``post`` (the row itself:
    w_max, s1_max, lists). ``breakpoints``: dicts
    ``{between: [v1, v2], at, bracket: [lo, hi], before, after}``, where the contact set
    (indices of the contact points in contact) changes from ``before`` to ``after`` at
    ``at`` (the middle of the final bracket; None if it could not be refined). ``times``:
    seconds for "values", "breakpoints" and "total"; "bisection_solves" (solves the bisection
    took) and "bisection_iterations" (the backend's iterations in them); "executor".
    """

    path: str
    values: list
    rows: list[dict]
    breakpoints: list[dict]
    times: dict = field(default_factory=dict)
    #: None, or for a sweep stopped by Ctrl-C / SIGTERM (:class:`SweepInterrupted`):
    #: ``{"done": k, "of": n, "not_done": [values]}``; ``rows`` then holds the k rows done
    interrupted: dict | None = None

    def to_dict(self) -> dict:
        """The JSON shape of ``plateqp sweep --json``: {rows, breakpoints}, and ``interrupted``
        for a sweep that was stopped (see the field). In it the breakpoints' ``before`` and
        ``after`` number the contact points from 1 (supports in scene order, then bed nodes),
        as the tables do; :attr:`breakpoints` keeps Python's indices from 0."""
        d = {"rows": self.rows,
             "breakpoints": [{**b, "before": numbered(b["before"]), "after": numbered(b["after"])}
                             for b in self.breakpoints]}
        if self.interrupted is not None:
            d["interrupted"] = self.interrupted
        return d

    def to_xarray(self):
        """The rows as an :class:`xarray.Dataset` with the dimension ``value`` (the parameter;
        "rigid" as inf) and ``point`` (the contact points: supports in scene order, then bed
        nodes): ``reactions`` and ``active`` (value, point); ``status``, ``w_max``, ``s1_max``,
        ``kkt_worst``, ``n_contact`` and ``time`` per value (NaN where a value failed)."""
        from ..io.fields import _optional

        xr = _optional("xarray")
        vals = np.array([np.inf if v == "rigid" else float(v) for v in (r["value"] for r in self.rows)])
        R = self.reactions
        m = R.shape[1] if R.ndim == 2 else 0
        act = np.array([[bool(a) for a in r["active"]] if r["active"] is not None else [False] * m
                        for r in self.rows], dtype=bool).reshape(len(self.rows), m)

        def col(key):
            return np.array([np.nan if r.get(key) is None else float(r[key]) for r in self.rows])

        data = {
            "reactions": (("value", "point"), R.reshape(len(self.rows), m),
                          {"long_name": "reaction (positive pushes the plate up)", "units": "F"}),
            "active": (("value", "point"), act, {"long_name": "in contact"}),
            "status": (("value",), np.array([str(r["status"]) for r in self.rows])),
            "w_max": (("value",), col("w_max"), {"long_name": "largest |w|, with its sign", "units": "L"}),
            "s1_max": (("value",), col("s1_max"), {"long_name": "largest nodal σ1", "units": "F/L^2"}),
            "kkt_worst": (("value",), col("kkt_worst"), {"long_name": "worst KKT residual"}),
            "n_contact": (("value",), act.sum(axis=1)),
            "time": (("value",), np.array([float(r["times"]["total"]) if r.get("times") else np.nan
                                           for r in self.rows]), {"units": "s"}),
        }
        attrs = {"parameter": self.path, "breakpoints": json.dumps(self.breakpoints, default=str)}
        if self.interrupted is not None:
            attrs["interrupted"] = json.dumps(self.interrupted, default=str)
        return xr.Dataset(data, coords={"value": ("value", vals, {"long_name": self.path}),
                                        "point": ("point", np.arange(1, m + 1))}, attrs=attrs)

    @property
    def reactions(self) -> np.ndarray:
        """(n_values, m) reactions; NaN rows for failed values."""
        m = max((len(r["reactions"]) for r in self.rows if r["reactions"] is not None), default=0)
        return np.array([r["reactions"] if r["reactions"] is not None else [np.nan] * m for r in self.rows])

    @property
    def active(self) -> list:
        """Contact set (bool list) per value; None for failed values."""
        return [r["active"] for r in self.rows]

    def __str__(self) -> str:
        head = (f"{'value':>12s} {'status':>10s} {'contact':>8s} {'sum R':>12s} {'w_max':>12s}"
                f" {'max s1':>12s} {'KKT worst':>9s} {'time s':>8s}")
        lines = [f"sweep of {self.path}: {len(self.rows)} values", head]
        if self.interrupted is not None:
            lines[0] += (f" (interrupted: {self.interrupted['done']} of {self.interrupted['of']} done;"
                         f" not done: {_few(self.interrupted['not_done'])})")
        for r in self.rows:
            v = r["value"]
            vs = v if isinstance(v, str) else f"{v:.6g}"
            if r["error"]:
                lines.append(f"{vs:>12s} {r['status']:>10s}   {r['error']}")
                continue
            lines.append(f"{vs:>12s} {r['status']:>10s} {sum(r['active']):>4d}/{len(r['active']):<3d}"
                         f" {sum(r['reactions']):12.6g} {r['w_max']:12.6g} {r['s1_max']:12.6g}"
                         f" {r['kkt_worst'] if r['kkt_worst'] is not None else float('nan'):9.1e}"
                         f" {r['times']['total']:8.3f}")
        if self.breakpoints:
            lines.append("changes of the contact set (working scheme; contact points numbered from 1: the supports"
                         " in scene order, then bed nodes):")
            for b in self.breakpoints:
                on = [i + 1 for i in sorted(set(b["after"]) - set(b["before"]))]
                off = [i + 1 for i in sorted(set(b["before"]) - set(b["after"]))]
                where = f"at {b['at']:.6g}" if b["at"] is not None else f"in {b['bracket']}"
                lines.append(f"  between {b['between'][0]} and {b['between'][1]}: {where};"
                             f" comes into contact {on or '-'}, lifts off {off or '-'}"
                             + (f" ({b['note']})" if b.get("note") else ""))
        failed = sum(r["active"] is None for r in self.rows)
        if self.interrupted is not None:
            lines.append("the sweep was interrupted: changes of the contact set were not all searched")
        elif not self.breakpoints and failed:
            lines.append(f"the contact set is the same for every value solved ({failed} of {len(self.rows)}"
                         " failed: nothing is said of them)")
        elif not self.breakpoints:
            lines.append("the contact set is the same for every value")
        return "\n".join(lines)


def numbered(indices) -> list[int]:
    """Contact-point indices from 0 (Python's) as the numbers users read, from 1."""
    return [int(i) + 1 for i in indices]


def _few(values, keep: int = 3) -> str:
    """A list of values for a table's line: all when few, else the first and last and how many."""
    vs = [v if isinstance(v, str) else f"{v:.6g}" for v in values]
    if len(vs) <= 2 * keep:
        return "[" + ", ".join(vs) + "]"
    return f"{len(vs)} values: [{', '.join(vs[:keep])}, ..., {', '.join(vs[-keep:])}]"


def sweep(scene: Scene, path: str, values: Iterable, backend: str = "auto", formulation: str = "auto",
          accuracy: str = "default", executor=None, progress: bool = True, refine_breakpoints: bool = True,
          rtol: float = 1e-3, options: dict | None = None, reuse: bool = True, max_workers: int = 2,
          bisection: str = "auto", warm_start: bool = True, store=None, model=None) -> SweepResult:
    """Solve ``scene`` for each value of the field PATH; find where the contact set changes.

    Parameters
    ----------
    scene, path : the scene and the field to vary (see :func:`plateqp.model.paths.set_param`; the
        same path language as ``plateqp sweep --param``: ``supports.1.gap`` is the first
        support, supports being numbered from 1 as in every table)
    values : the values, in sweep order ("rigid" allowed for a stiffness); every one is
        checked against the scene before any solve (:func:`plateqp.model.variation.check_values`)
    backend, formulation, accuracy, options : as for :func:`plateqp.solve`
    executor : None (local processes, ``max_workers`` of them, or this process for fewer
        than :data:`SERIAL_BELOW` values), "serial", "process", any
        :class:`concurrent.futures.Executor`, or a Dask ``distributed.Client`` (each of these
        gets one value per task, so that each row comes back as it is solved; plateqp's own
        processes solve chunks of values and send each row as it is solved). Local
        processes start from a fresh interpreter (forkserver/spawn), so a script that sweeps
        with them needs the usual ``if __name__ == "__main__":`` guard.
    progress : a progress bar on stderr, drawn only when stderr is a terminal and not under
        CI (:mod:`plateqp.progress`; tqdm if installed, else a counter line)
    refine_breakpoints : bisect each change of the contact set between successive values
        until its bracket is within ``rtol`` relative
    reuse : build the model once and change only gaps, stiffnesses or loads in a copy (the
        condensation is then computed once too); False rebuilds and solves everything from
        scratch for each value, without warm starts (the reference for timing the re-use)
    warm_start : with ``reuse``, start each solve of a backend that takes a warm start
        (:data:`WARM_START_BACKENDS`) from the final state of the solve before it (in a
        chunk of values, or in a bisection from the bracket's end it continues); False
        re-uses the model but starts every solve cold (to measure what warm starts save).
        Other backends ignore it. Each row's ``iterations`` counts the backend's steps.
    bisection : "auto" (geometric when every value is positive and they span a decade or
        more, else linear), "geometric" or "linear"
    store : None, or a file (JSON Lines, :mod:`plateqp.studies.store`) where each row is
        written as soon as it is solved; if the file holds rows of this same sweep (same scene,
        path, values and solver settings) from a stopped run, those values are not solved
        again. A file of another sweep is a ProblemError.
    model : None, or a model built before from ``scene`` with PATH at another value (what
        :func:`plateqp.studies.exact_sweep` built for its path): the values solved in this
        process adapt it (:func:`plateqp.studies.reuse.adapt_model`) and re-use what its solves
        kept (the factorisation of K, the scaled data) instead of building their own

    Returns
    -------
    SweepResult. A value whose solve fails is recorded as a row with its status and error;
    the sweep goes on. A change between a failed value and its neighbours is not bisected.

    Raises
    ------
    SweepInterrupted
        on Ctrl-C (KeyboardInterrupt) while it runs: our worker processes are stopped at once
        (not waited for), and the exception carries the rows done so far. While the sweep
        waits on its workers, a Ctrl-C or SIGTERM is acted on when that wait returns (within
        0.1 s; :class:`plateqp.studies.parallel.SignalGate`). Should the pool's manager thread
        not end after the stop (a warning says so), the interpreter's exit would wait for it:
        :func:`plateqp.studies.parallel.exit_if_left_running` ends the process once your output
        is written (``plateqp sweep`` does this).
    """
    values = [v.item() if isinstance(v, np.generic) else v for v in values]
    if not values:
        raise ProblemError("sweep: no values given")
    if bisection not in ("auto", "geometric", "linear"):
        raise ProblemError(f"bisection must be 'auto', 'geometric' or 'linear' (got {bisection!r})")
    if not isinstance(warm_start, (bool, np.bool_)):
        raise ProblemError(f"warm_start must be True or False (got {warm_start!r})")
    current = get_param(scene, path)  # a bad path fails here, naming what exists
    check_values(scene, path, values)  # and a bad value, any of them, before any solve
    first = current[0] if isinstance(current, list) else current
    is_int = isinstance(first, int) and not isinstance(first, bool)  # mesh.nx: bisect on integers
    finite = [x for x in (as_number(v) for v in values) if math.isfinite(x)]
    geometric = {"geometric": True, "linear": False}.get(
        bisection, bool(finite) and min(finite) > 0 and max(finite) >= 10.0 * min(finite))
    if geometric and not (finite and min(finite) > 0):
        raise ProblemError("geometric bisection needs positive values")
    bis = Bisection(geometric, rtol, 1e-3 * max((abs(x) for x in finite), default=1.0), is_int)

    rowstore = None
    if store is not None:
        from .. import __version__
        from .store import RowStore, scene_fingerprint

        rowstore = RowStore(store, {"scene": scene_fingerprint(scene), "name": str(scene.name), "path": path,
                                    "values": values, "backend": backend, "formulation": formulation,
                                    "accuracy": accuracy, "options": options, "version": __version__})
    t0 = time.perf_counter()
    ctx = Context(uuid.uuid4().hex, scene, path, backend, formulation, accuracy, options, reuse,
                   bool(warm_start))
    if model is not None and reuse:
        seed(ctx, model)
    runner = make_runner(executor, len(values), max_workers, ctx)
    n = len(values)
    rows: list[dict | None] = [None] * n
    actives: list = [None] * n
    found: dict[int, list[dict]] = {}
    solves = bisection_steps = 0
    stopped = False
    if rowstore is not None:  # values a stopped run already solved
        for i, row in rowstore.done.items():
            rows[i] = row
            actives[i] = tuple(row["active"]) if row.get("active") is not None else None
    todo = [i for i in range(n) if rows[i] is None]

    def take(i: int, row: dict) -> bool:
        """Keep the row of value ``i`` (and store it) unless it is kept already."""
        if rows[i] is not None:
            return False
        rows[i] = row
        actives[i] = tuple(row["active"]) if row["active"] is not None else None
        if rowstore is not None:
            rowstore.append(i, row)
        return True

    logger.info("sweep of %s: %d values (%d from the store), executor %s with %d worker(s)", path, n, n - len(todo),
                runner.kind, runner.workers)
    try:
        bar = Progress(len(todo), f"sweep {path}", progress)
        try:
            if runner.kind == "serial":
                # a plain loop, warm-starting each value from the one before
                state = None
                for i in todo:
                    row, act, new = solve_value(ctx, values[i], next_start(ctx, state))
                    rows[i], actives[i] = row, act
                    if rowstore is not None:
                        rowstore.append(i, row)
                    state = new or state
                    bar.update()
            else:
                # our own processes send each row as it is solved (runner.rows), so chunks of values
                # keep their warm starts; other executors get one value per task, each row returned
                # as it is solved
                stream = runner.rows is not None
                size = max(1, math.ceil(len(todo) / (4 * runner.workers))) if stream else 1
                chunks = [[(i, values[i]) for i in todo[j:j + size]] for j in range(0, len(todo), size)]
                futs = {runner.submit(run_chunk, ctx, ch): ch for ch in chunks}

                def finished(fut):
                    try:
                        return fut.result()
                    except Exception:  # a worker died or could not run it: do this chunk here
                        return run_chunk(ctx, futs[fut])

                if stream:
                    pending = set(futs)
                    while pending:
                        done = runner.wait_any(pending)
                        got = [(i, row) for tok, i, row in runner.drain() if tok == ctx.token]
                        for fut in done:
                            pending.discard(fut)
                            got += finished(fut)
                        bar.update(sum(take(i, row) for i, row in got))
                else:
                    for key, fut in runner.as_completed(futs):
                        bar.update(sum(take(i, row) for i, row in finished(key)))
        finally:
            bar.close()
        t1 = time.perf_counter()

        # breakpoints between successive values whose contact sets differ
        pairs = [i for i in range(n - 1)
                 if actives[i] is not None and actives[i + 1] is not None and actives[i] != actives[i + 1]]
        if refine_breakpoints and pairs:
            bar = Progress(len(pairs), "refining breakpoints", progress)
            try:
                args = {i: (ctx, bis, values[i], actives[i], values[i + 1], actives[i + 1]) for i in pairs}
                futs = {runner.submit(refine_bracket, *args[i]): i for i in pairs}
                for key, fut in runner.as_completed(futs):
                    i = futs[key]
                    try:
                        found[i], (k, steps) = fut.result()
                    except Exception:  # a worker died: refine this one here
                        found[i], (k, steps) = refine_bracket(*args[i])
                    solves += k
                    bisection_steps += steps
                    bar.update()
            finally:
                bar.close()
        else:
            for i in pairs:
                found[i] = [{"between": [values[i], values[i + 1]], "at": None,
                             "bracket": [values[i], values[i + 1]],
                             "before": contact_set(actives[i]), "after": contact_set(actives[i + 1])}]
    except KeyboardInterrupt:
        stopped = True
        runner.abort()
        for tok, i, row in getattr(runner, "drain_left", ()):  # rows sent before the workers stopped
            if tok == ctx.token:
                take(i, row)
        done = [i for i in range(n) if rows[i] is not None]
        partial = SweepResult(path, [values[i] for i in done], [rows[i] for i in done],
                              [b for i in sorted(found) for b in found[i]],
                              times={"total": time.perf_counter() - t0, "executor": runner.kind},
                              interrupted={"done": len(done), "of": n,
                                           "not_done": [values[i] for i in range(n) if rows[i] is None]})
        raise SweepInterrupted(partial) from None
    finally:
        if not stopped:
            runner.close()
        forget(ctx.token)
    breakpoints = [b for i in sorted(found) for b in found[i]]
    t2 = time.perf_counter()
    return SweepResult(path, values, rows, breakpoints,
                       times={"values": t1 - t0, "breakpoints": t2 - t1, "total": t2 - t0,
                              "bisection_solves": solves, "bisection_iterations": bisection_steps,
                              "executor": runner.kind})


__all__ = ["SERIAL_BELOW", "SweepInterrupted", "SweepResult", "WARM_START_BACKENDS", "sweep"]
