"""``plateqp sweep`` (bisection or exact paths; Ctrl-C and SIGTERM keep the rows done) and
``plateqp regulate`` (gaps for target reactions).
"""

from __future__ import annotations

import contextlib
import json
import sys
import warnings
from pathlib import Path

import numpy as np

from ..accuracy import Status
from ..errors import PlateQPError, ProblemError
from ..progress import Progress
from .common import _options, _backend_name, _stdout_to_stderr, _set_memory_limit, _scene_or_builtin, _numbers, log


def cmd_regulate(args) -> int:
    """Gaps that make the chosen supports carry the target reactions, checked by solving the
    regulated scene (:func:`plateqp.studies.regulate_gaps`)."""
    from ..io.files import check_file
    from ..studies.design import regulate_gaps, shim_sensitivity

    scene = _scene_or_builtin(args.scene)
    target = _numbers(args.target, "--target")
    ns = len(scene.supports)
    chosen = None
    if args.supports is not None:
        numbers = _numbers(args.supports, "--supports", int)
        if any(k < 1 or k > ns for k in numbers) or len(set(numbers)) != len(numbers):
            raise PlateQPError(f"--supports: distinct support numbers 1..{ns} (got {args.supports})")
        chosen = [k - 1 for k in numbers]
    n_reg = ns if chosen is None else len(chosen)
    if len(target) not in (1, n_reg):
        raise PlateQPError(f"--target: one value, or one per regulated support ({n_reg}); got {len(target)}")
    if args.out:
        check_file(args.out, force=args.force, label=f"--out {args.out}", flag="--force")
    _backend_name(args.backend)
    with warnings.catch_warnings(), _stdout_to_stderr(), Progress(2, "regulate: gaps, then the check") as bar:
        warnings.simplefilter("ignore")
        # the gaps, and the contact solve of the scene with exactly those gaps (reg.check)
        reg = regulate_gaps(scene, target if len(target) > 1 else target[0], supports=chosen,
                            backend=args.backend, formulation=args.formulation)
        bar.update(2)  # the gaps and the check, both done by regulate_gaps
    check = reg.check
    shim, shim_note = shim_sensitivity(check, reg.supports)
    error = reg.miss
    ok = check.status == Status.OPTIMAL and error <= 1e-6
    if args.out:
        from ..io.safe import write

        write(args.out, reg.scene.to_toml(), force=args.force, label=f"--out {args.out}")
    # "reaction": what the returned gaps give (the check solve); "reaction_aimed": what they were computed for
    rows = [{"support": int(k) + 1, "gap_before": float(scene.supports[k].gap), "gap": float(reg.gaps[k]),
             "target": float(t), "reaction_aimed": float(a), "reaction": float(r)}
            for k, t, a, r in zip(reg.supports, reg.target, reg.aimed, reg.reactions)]
    if args.json:
        print(json.dumps({"scene": scene.name, "reachable": reg.reachable, "projection": reg.projection,
                          "status": check.status.value, "check_error": error, "supports": rows,
                          "gaps": [float(g) for g in reg.gaps], "out": args.out,
                          "shim_sensitivity": None if shim is None else shim.tolist(),
                          "shim_sensitivity_note": shim_note}, indent=1))
    else:
        print(f"{scene.name}: gaps for {len(rows)} regulated supports (numbers from 1)")
        print(f"{'support':>7} {'gap before':>12} {'gap':>12} {'target R':>12} {'R aimed':>12} {'R':>12}")
        for r in rows:
            print(f"{r['support']:>7} {r['gap_before']:12.5g} {r['gap']:12.5g} {r['target']:12.5g} "
                  f"{r['reaction_aimed']:12.5g} {r['reaction']:12.5g}")
        print(f"check: R is the contact solve with these gaps ({check.status.value}), within {error:.1e} of the "
              "reactions aimed at"
              + (f"; the regulated scene is in {args.out}" if args.out else ""))
        if shim is not None and shim.size:
            i, j = np.unravel_index(np.abs(shim).argmax(), shim.shape)
            print(f"shim tolerance: a gap error d under support {reg.supports[j] + 1} changes the reaction of "
                  f"support {reg.supports[i] + 1} by {shim[i, j]:.4g} x d, the largest of dR_i/dg0_j among the "
                  "regulated supports (--json: shim_sensitivity)")
        elif shim_note:
            print(f"shim tolerance: {shim_note}")
    if not reg.reachable:
        print(f"plateqp: regulate: the target is not in equilibrium with the load: the nearest reachable "
              f"reactions are used (relative distance {reg.projection:.2e})", file=sys.stderr)
        return 5
    if not ok:
        print(f"plateqp: regulate: solving the regulated scene gave reactions {error:.1e} off "
              f"(status {check.status.value})", file=sys.stderr)
        return 5
    return 0


def _sweep_values(args) -> list:
    """--values V1,V2,... ("rigid" allowed) or --range A:B:N[:log]."""
    if args.values is not None:
        out = []
        for v in args.values.split(","):
            v = v.strip()
            if v.lower() in ("rigid", "inf"):
                out.append("rigid")
                continue
            try:
                out.append(int(v) if v.lstrip("+-").isdigit() else float(v))
            except ValueError:
                raise PlateQPError(f"--values: not a number or 'rigid': {v!r}") from None
        if len(out) > args.max_values:
            raise PlateQPError(f"--values: {len(out)} values is more than --max-values {args.max_values}")
        return out
    parts = args.range.split(":")
    try:
        if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] not in ("log", "lin")):
            raise ValueError
        a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise PlateQPError(f"--range wants A:B:N or A:B:N:log (got {args.range!r})") from None
    if n < 1:
        raise PlateQPError(f"--range: N must be >= 1 (got {n})")
    if n > args.max_values:
        raise PlateQPError(f"--range: {n} values is more than --max-values {args.max_values}; "
                           "raise --max-values if you mean it")
    if len(parts) == 4 and parts[3] == "log":
        if a <= 0 or b <= 0:
            raise PlateQPError(f"--range {args.range}: a log range needs A, B > 0")
        return [float(v) for v in np.geomspace(a, b, n)]
    return [float(v) for v in np.linspace(a, b, n)]


def _executor(args, stack: contextlib.ExitStack) -> tuple:
    """(executor, max_workers) of a sweep: a Dask client on ``--scheduler`` (closed when ``stack``
    closes; the cluster keeps running), else local processes (``--workers``, default 2; 1: serial)."""
    if args.scheduler is not None:
        if args.workers is not None:
            raise ProblemError("--workers and --scheduler: choose one (the cluster's workers run the sweep)")
        if not args.scheduler_timeout > 0:
            raise ProblemError(f"--scheduler-timeout: seconds > 0 (got {args.scheduler_timeout})")
        from ..studies.parallel import connect

        client = stack.enter_context(connect(args.scheduler, timeout=args.scheduler_timeout))
        return client, 1
    from ..studies.parallel import available_cores

    if args.workers is not None and args.workers < 1:
        raise ProblemError(f"--workers: at least 1 (1: solve in this process; got {args.workers})")
    cores = available_cores()
    workers = min(2, cores) if args.workers is None else args.workers
    if workers > cores:
        if args.force_workers:
            log.warning("--workers %d --force-workers: %d processes share the %d core(s) this process may use",
                        workers, workers, cores)
        else:
            log.warning("--workers %d: capped at the %d core(s) this process may use "
                        "(add --force-workers to start %d)", workers, cores, workers)
            workers = cores
    return ("serial" if workers <= 1 else None), workers


def _sweep_exact(scene, values, opts, args, executor, workers):
    """sweep --exact: the breakpoints of the exact path (:func:`plateqp.studies.exact_sweep`);
    a parameter that does not enter linearly is a ProblemError (exit 2) before any work."""
    from ..studies import exact_sweep

    if args.no_refine:
        raise ProblemError("--exact and --no-refine: choose one")
    return exact_sweep(scene, args.param, values, backend=args.backend, formulation=args.formulation,
                       accuracy=args.accuracy, options=opts, executor=executor, max_workers=workers,
                       warm_start=not args.no_warm_start, store=args.store)


def cmd_sweep(args) -> int:
    from ..studies import SweepInterrupted, sweep
    from ..studies.parallel import exit_if_left_running

    _set_memory_limit(args.max_memory)
    scene = _scene_or_builtin(args.scene)
    values = _sweep_values(args)
    opts = _options(args.options)
    _backend_name(args.backend)
    if args.out:  # before any work
        from ..io.fields import _optional
        from ..io.files import check_file

        if Path(args.out).suffix.lower() not in NETCDF:
            raise ProblemError(f"--out {args.out}: the format follows the extension, and plateqp writes "
                               f"netCDF ({', '.join(NETCDF)}); name a .nc file")
        _optional("xarray")
        check_file(args.out, force=args.force, label=f"--out {args.out}", flag="--force")
    with _sigterm_as_interrupt() as seen, contextlib.ExitStack() as stack:
        executor, workers = _executor(args, stack)
        res = None
        try:
            with _stdout_to_stderr():
                if args.exact:
                    res = _sweep_exact(scene, values, opts, args, executor, workers)
                else:
                    res = sweep(scene, args.param, values, backend=args.backend, formulation=args.formulation,
                                accuracy=args.accuracy, options=opts, executor=executor, max_workers=workers,
                                refine_breakpoints=not args.no_refine, rtol=args.rtol,
                                warm_start=not args.no_warm_start, store=args.store)
            seen.armed = False  # every value is done: a SIGTERM from here on waits for the rows' output
        except SweepInterrupted as exn:
            part = exn.result
            _write_netcdf(part, args.out, args.force)
            print(json.dumps({"method": "none" if args.no_refine else "bisection", **part.to_dict()}, indent=1)
                  if args.json else part)
            sys.stdout.flush()
            left = part.interrupted["not_done"]
            where = 'JSON, with "interrupted"' if args.json else "the table"
            print(f"plateqp: sweep interrupted ({'SIGTERM' if seen.signals else 'Ctrl-C'}), workers stopped: the"
                  f" {part.interrupted['done']} of {part.interrupted['of']} values done are on standard output"
                  f" ({where}); not done: {len(left)}"
                  + (f" (from {args.param} = {left[0]})" if left else ""), file=sys.stderr)
            code = 143 if seen.signals else 130
            exit_if_left_running(code)  # all is written: a stuck pool thread must not hold the exit
            return code
        except KeyboardInterrupt:
            if res is None:
                raise
            seen.signals.append(None)  # the stop came between the last value and the disarming
        _write_netcdf(res, args.out, args.force)
        if args.json:
            print(json.dumps({"method": "none" if args.no_refine else "bisection", **res.to_dict()}, indent=1))
        else:
            print(res)
    if seen.signals:  # a stop came after the last value: the whole sweep is on standard output
        print(f"plateqp: stopped after the sweep's {len(res.rows)} values were done: they are all on standard "
              "output", file=sys.stderr)
        return 143
    bad = [r for r in res.rows if r["status"] != Status.OPTIMAL.value]
    if bad:
        print(f"plateqp: sweep: {len(bad)} of {len(res.rows)} values failed or missed the asked accuracy "
              f"(first: {args.param} = {bad[0]['value']}: {bad[0]['error'] or bad[0]['status']})", file=sys.stderr)
        return 5
    return 0


#: The extensions ``sweep --out`` takes: netCDF (any other is refused before any work).
NETCDF = (".nc", ".nc3", ".cdf", ".netcdf")


def _write_netcdf(res, out, force: bool) -> None:
    """--out FILE.nc: the rows as an xarray Dataset (:meth:`SweepResult.to_xarray`), netCDF 3
    through SciPy (no netCDF library needed), by :mod:`plateqp.io.safe`'s rules; the file was
    checked before any work."""
    if not out:
        return
    from ..io.safe import write

    ds = res.to_xarray()
    write(out, lambda tmp: ds.to_netcdf(tmp, engine="scipy"), force=force, label=f"--out {out}")


@contextlib.contextmanager
def _sigterm_as_interrupt():
    """While the block runs, SIGTERM raises KeyboardInterrupt (so a sweep stops its workers and
    keeps its rows, as on Ctrl-C) while the yielded state is ``armed``; once disarmed (the sweep
    is done) a SIGTERM is only recorded, so that the rows' output is written whole. The state's
    ``signals`` is non-empty once SIGTERM came."""
    import signal
    from types import SimpleNamespace

    seen = SimpleNamespace(signals=[], armed=True)

    def on_term(signum, frame):
        seen.signals.append(signum)
        if seen.armed:
            raise KeyboardInterrupt

    try:
        old = signal.signal(signal.SIGTERM, on_term)
    except ValueError:  # not the main thread: leave SIGTERM alone
        yield seen
        return
    try:
        yield seen
    finally:
        signal.signal(signal.SIGTERM, old)
