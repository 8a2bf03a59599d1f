"""The ``plateqp`` command: demo, solve, sweep, export, backends.

Errors go to stderr as one line (what is wrong and where) with exit code 2 for bad input,
3 for no equilibrium, 4 for a solver failure, 5 for an answer that missed the asked accuracy
(or a ``--target`` not reached), 130 when interrupted; 1 only for an internal error (a bug:
the line says so; ``PLATEQP_DEBUG=1`` shows the traceback).

While a command works, anything a solver prints on standard output (HiGHS's banner, OSQP's
"Polishing not needed") is sent to standard error, so that ``--json`` output is JSON alone.
Files are written only inside ``--out``, under names made safe from the scene's name, never
over an existing file unless ``--force`` is given, and ``--out`` is checked before any work.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import sys
import warnings
from pathlib import Path

import numpy as np

from . import scenes
from .backends import get_backend, registry
from .accuracy import Status, accuracy_tol
from .contact import formulations_for
from .solving import solve
from .errors import NoEquilibriumError, PlateQPError, ProblemError, SceneError, SolverError
from .scene import Scene


def _probe(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"--probe wants X,Y (got {text!r})") from None
    return x, y


def _accuracy(text: str):
    """--accuracy: a preset, "auto", or a tolerance such as 1e-7."""
    if text in ("low", "default", "high", "auto"):
        return text
    try:
        return accuracy_tol(text)
    except PlateQPError as exn:
        raise argparse.ArgumentTypeError(f"{exn} (or auto)") from None


def _target(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not 1e-8 <= v < 1.0:
        raise argparse.ArgumentTypeError(f"--target wants a relative error between 1e-8 and 1 (got {text!r})")
    return v


def _options(text: str | None) -> dict | None:
    """--options: a JSON object, or a one-line error naming what is wrong with it."""
    if not text:
        return None
    try:
        opts = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exn:
        raise ProblemError(f"--options: not valid JSON ({getattr(exn, 'msg', 'nested too deep')})") from None
    if not isinstance(opts, dict):
        raise ProblemError(f"--options: must be a JSON object such as '{{\"max_iter\": 100}}' (got {type(opts).__name__})")
    return opts


def _backend_name(name: str) -> str:
    """An unknown backend is bad input (exit 2), found before any work."""
    if name != "auto":
        try:
            get_backend(name)
        except SolverError as exn:  # unknown or not installed: what was asked is not there
            raise ProblemError(f"--backend: {exn}") from None
    return name


#: Characters allowed in a file name made from a scene's name.
_SAFE = re.compile(r"[^A-Za-z0-9._-]+")


def safe_filename(name: str) -> str:
    """A scene name as a plain file name: no directories, no leading dot, at most 100 characters."""
    out = _SAFE.sub("_", str(name)).lstrip(".")[:100]
    return out or "scene"


def _out_dir(text: str, files: list[str], force: bool) -> Path:
    """Check ``--out`` before any work: a folder (made if missing) that is writable and holds none
    of ``files`` (unless ``force``)."""
    out = Path(text)
    if out.exists() and not out.is_dir():
        raise ProblemError(f"--out {out}: exists and is not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exn:
        raise ProblemError(f"--out {out}: cannot be made ({exn.strerror or exn})") from None
    if not os.access(out, os.W_OK | os.X_OK):
        raise ProblemError(f"--out {out}: is not writable")
    there = [f for f in files if (out / f).exists()]
    if there and not force:
        raise ProblemError(f"--out {out}: {there[0]} exists; use --force to overwrite")
    return out


@contextlib.contextmanager
def _stdout_to_stderr():
    """Send everything written to standard output (Python's and the C libraries') to standard
    error while the block runs; the command's own output is printed after it."""
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:  # no file descriptor 1 (embedded): Python-level redirection only
        saved = None
    try:
        if saved is not None:
            os.dup2(2, 1)
        with contextlib.redirect_stdout(sys.stderr):
            yield
    finally:
        sys.stdout.flush()
        if saved is not None:
            try:
                sys.__stdout__.flush()
            except (OSError, ValueError, AttributeError):
                pass
            os.dup2(saved, 1)
            os.close(saved)


def _set_memory_limit(text: str | None) -> None:
    if text:
        from .assembly import MEMORY_ENV, parse_bytes

        parse_bytes(text, "--max-memory")
        os.environ[MEMORY_ENV] = text  # worker processes inherit it


def _summary(result, probes=()) -> str:
    w, x, y = result.w_max()
    lines = [f"scene {result.scene.name!r}: {result.formulation} / {result.backend} / {result.accuracy}"
             f" -> {result.status.value}",
             f"  max deflection w = {w:.6g} at ({x:g}, {y:g})",
             f"  residual |Ku - f + B'R|/|f| = {result.residual:.2e}"]
    for px, py in probes:
        lines.append(f"  w({px:g}, {py:g}) = {result.deflection(px, py):.6g}")
    if result.kkt is not None:
        k = result.kkt
        lines.append(f"  KKT: stationarity {k.stationarity:.1e}, primal {k.primal:.1e}, dual {k.dual:.1e},"
                     f" complementarity {k.complementarity:.1e} (tol {k.tol:.0e}: {'ok' if k.ok else 'NOT MET'})")
        lines.append(f"  {int(result.active.sum())} of {result.active.size} supports in contact;"
                     f" sum of reactions {result.reactions.sum():.6g}")
        lines.append("  support      x          y        gap0        reaction     in contact")
        sc = result.scene
        for i, s in enumerate(sc.supports):
            lines.append(f"  {i:5d} {s.x:10.4g} {s.y:10.4g} {s.gap:11.4g} {result.reactions[i]:14.6g}"
                         f"     {'yes' if result.active[i] else 'no'}")
    t = result.times
    lines.append(f"  times: build {t.get('build', 0):.3f} s, solve {t.get('solve', 0):.3f} s, total {t.get('total', 0):.3f} s")
    return "\n".join(lines)


def cmd_solve(args) -> int:
    _set_memory_limit(args.max_memory)
    scene = _scene_or_builtin(args.scene)
    opts = _options(args.options)
    _backend_name(args.backend)
    stem = safe_filename(scene.name)
    out = _out_dir(args.out, [f"{stem}.json", f"{stem}-w.npy"], args.force) if args.out else None
    reached = True
    with warnings.catch_warnings(), _stdout_to_stderr():
        warnings.simplefilter("ignore")  # the status says it; the warning would repeat it on stderr
        if args.target is not None:
            from .studies import solve_to_target

            if opts:
                raise PlateQPError("--target chooses the backend's tolerance itself: drop --options")
            if args.accuracy != "default":
                raise PlateQPError("--target chooses the solver tolerance (a tenth of the target): drop --accuracy")
            tr = solve_to_target(scene, args.target, backend=args.backend, formulation=args.formulation,
                                 max_cells=args.max_mesh,
                                 progress=None if args.json else lambda r: print(
                                     f"  {r['mesh'][0]}x{r['mesh'][1]}: {r['status']} in {r['time']:.2f} s",
                                     file=sys.stderr, flush=True))
            reached, result = tr.reached, tr.result
            if result is None:
                raise PlateQPError(f"--target: no mesh up to {args.max_mesh} cells a side could be solved")
        else:
            result = solve(scene, backend=args.backend, formulation=args.formulation, accuracy=args.accuracy,
                           options=opts)
    if args.json:
        d = result.to_dict(args.probe)
        if args.target is not None:
            d["target"] = {"target": tr.target, "reached": tr.reached, "tolerance": tr.tolerance,
                           "mesh": [result.scene.mesh.nx, result.scene.mesh.ny],
                           "meshes": [{**r, "mesh": list(r["mesh"])} for r in tr.rows]}
        print(json.dumps(d, indent=1))
    else:
        if args.target is not None:
            print(tr)
        print(_summary(result, args.probe))
    if out is not None:
        (out / f"{stem}.json").write_text(json.dumps(result.to_dict(args.probe), indent=1))
        np.save(out / f"{stem}-w.npy", result.w_nodes())
    return 0 if result.status in (Status.OPTIMAL,) and reached else 5


def cmd_demo(args) -> int:
    from .demo import DEFAULT_OUT, output_files, run

    names = [args.name] if args.name else None
    files = output_files(names)  # an unknown scene: SceneError before any folder is made
    out = _out_dir(args.out or DEFAULT_OUT, files, args.force)  # before any work
    return run(names, out)


def cmd_backends(args) -> int:
    rows = []
    for name, b in sorted(registry().items()):
        rows.append({"name": name, "formulations": formulations_for(b), "installed": bool(b.available()),
                     "version": b.version() if b.available() else None})
    if args.json:
        print(json.dumps({"backends": rows}, indent=1))
    else:
        print(f"{'backend':24s} {'installed':9s} {'version':12s} formulations")
        for r in rows:
            print(f"{r['name']:24s} {'yes' if r['installed'] else 'no':9s} {str(r['version'] or '-'):12s} "
                  f"{', '.join(r['formulations'])}")
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


def cmd_sweep(args) -> int:
    from .studies import sweep

    _set_memory_limit(args.max_memory)
    scene = _scene_or_builtin(args.scene)
    values = _sweep_values(args)
    opts = _options(args.options)
    _backend_name(args.backend)
    with _stdout_to_stderr():
        res = sweep(scene, args.param, values, backend=args.backend, formulation=args.formulation,
                    accuracy=args.accuracy, options=opts, executor="serial" if args.workers <= 1 else None,
                    max_workers=max(args.workers, 1), progress=sys.stderr.isatty(),
                    refine_breakpoints=not args.no_refine, rtol=args.rtol, warm_start=not args.no_warm_start)
    if args.json:
        print(json.dumps(res.to_dict(), indent=1))
    else:
        print(res)
    bad = [r for r in res.rows if r["status"] != Status.OPTIMAL.value]
    if bad:
        print(f"plateqp: sweep: {len(bad)} of {len(res.rows)} values failed or missed the asked accuracy "
              f"(first: {args.param} = {bad[0]['value']}: {bad[0]['error'] or bad[0]['status']})", file=sys.stderr)
        return 5
    return 0


def _scene_or_builtin(text: str) -> Scene:
    """A scene file, or the name of a built-in scene (``plateqp demo`` lists them)."""
    path = Path(text)
    if not path.exists():
        if text in scenes.names():
            return scenes.load(text)
        raise SceneError(f"{text}: no such file, nor a built-in scene ({', '.join(scenes.names())})")
    return Scene.from_toml(path)


def cmd_export(args) -> int:
    """``plateqp export``: the contact problem as a QPS file or a qpbenchmark test set."""
    from .errors import ExportError
    from .io import check_testset_dir, contact_qp, write_qpbenchmark, write_qps
    from .io.files import check_file

    out = Path(args.out)
    if args.format == "qps":
        check_file(out, force=args.force, label=f"--out {out}", flag="--force")
    else:
        check_testset_dir(out, args.testset, force=args.force, label=f"--out {out}")
    scene = _scene_or_builtin(args.scene)
    exported = contact_qp(scene, args.formulation, name=args.name)
    if args.format == "qps":
        try:
            out.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exn:
            raise ExportError(f"--out {out}: cannot make its folder ({exn.strerror or exn})") from None
        path = write_qps(exported, out)
    else:
        path = write_qpbenchmark([exported], out, name=args.testset, force=args.force)
    qp = exported.qp
    print(f"wrote {path}: {exported.name} ({exported.formulation}), {qp.n} variables, "
          f"{0 if qp.G is None else qp.G.shape[0]} inequality rows, "
          f"{'sparse' if qp.sparse else 'dense'} P ({qp.P.nnz if qp.sparse else np.count_nonzero(qp.P)} nonzeros)")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="plateqp", description="Thin plates on one-sided supports, contact as a convex QP.")
    sub = ap.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("demo", help="solve a built-in scene and print a summary")
    d.add_argument("name", nargs="?", help=f"one of: {', '.join(scenes.names())} (default: all)")
    d.add_argument("--out", metavar="DIR", help="folder for the figures, JSON files and report.html "
                   "(default: ./plateqp-demo)")
    d.add_argument("--force", action="store_true", help="--out: overwrite files that exist")
    s = sub.add_parser("solve", help="solve a scene file (or a built-in scene)")
    s.add_argument("scene", help="a scene file, or the name of a built-in scene")
    s.add_argument("--backend", default="auto")
    s.add_argument("--formulation", default="auto", choices=["auto", "primal", "condensed", "dual"])
    s.add_argument("--accuracy", default="default", type=_accuracy,
                   help="low, default, high (KKT tolerance 1e-3, 1e-6, 1e-9), a tolerance such as 1e-7, "
                        "or auto (a tenth of the mesh's estimated discretisation error)")
    s.add_argument("--target", type=_target, metavar="REL",
                   help="pick the coarsest mesh (halving from 4 cells a side) whose estimated relative error "
                        "of max |w| and of the reactions is at most REL, solved at a tolerance of REL/10")
    s.add_argument("--max-mesh", type=int, default=256, metavar="N", help="--target: most cells a side")
    s.add_argument("--probe", type=_probe, action="append", default=[], metavar="X,Y")
    s.add_argument("--options", help="backend options as a JSON object, passed through untouched")
    s.add_argument("--json", action="store_true")
    s.add_argument("--out", metavar="DIR", help="write <name>.json and <name>-w.npy (nodal w) into DIR")
    s.add_argument("--force", action="store_true", help="--out: overwrite files that exist")
    s.add_argument("--max-memory", metavar="BYTES",
                   help="refuse meshes estimated to need more (e.g. 8G; default 80%% of this machine's memory)")
    w = sub.add_parser("sweep", help="solve a scene for a range of one parameter; find where the contact set changes")
    w.add_argument("scene")
    w.add_argument("--param", required=True, metavar="PATH", help="e.g. supports.*.stiffness, supports.3.gap, loads.0.P")
    wv = w.add_mutually_exclusive_group(required=True)
    wv.add_argument("--values", metavar="V1,V2,...", help="values in sweep order ('rigid' allowed for a stiffness)")
    wv.add_argument("--range", metavar="A:B:N[:log]", help="N values from A to B, evenly or log spaced")
    w.add_argument("--backend", default="auto")
    w.add_argument("--formulation", default="auto", choices=["auto", "primal", "condensed", "dual"])
    w.add_argument("--accuracy", default="default", type=_accuracy,
                   help="low, default, high, a tolerance such as 1e-7, or auto")
    w.add_argument("--options", help="backend options as a JSON object, passed through untouched")
    w.add_argument("--rtol", type=float, default=1e-3, help="relative width of each breakpoint's bracket")
    w.add_argument("--no-refine", action="store_true", help="report changes between values without bisection")
    w.add_argument("--workers", type=int, default=2, help="local worker processes (1: serial)")
    w.add_argument("--no-warm-start", action="store_true",
                   help="start each value's solve cold (warm starts: bpp and pdas, from the previous contact set)")
    w.add_argument("--max-values", type=int, default=10_000, metavar="N", help="most values a sweep takes")
    w.add_argument("--max-memory", metavar="BYTES", help="refuse meshes estimated to need more (e.g. 8G)")
    w.add_argument("--json", action="store_true")
    x = sub.add_parser("export", help="write the contact problem as a QPS file or a qpbenchmark test set")
    x.add_argument("scene", help="a scene file, or the name of a built-in scene")
    x.add_argument("--formulation", default="primal", choices=["primal", "condensed", "dual"])
    x.add_argument("--format", default="qps", choices=["qps", "qpbenchmark"],
                   help="qps: one Maros-Meszaros QPS file; qpbenchmark: a directory with the .npz and the test-set module")
    x.add_argument("--out", required=True, metavar="PATH", help="the .qps file, or the test set's directory")
    x.add_argument("--name", help="problem name (default: SCENE_FORMULATION)")
    x.add_argument("--testset", default="plateqp_contact", help="qpbenchmark test-set module name")
    x.add_argument("--force", action="store_true", help="overwrite an existing file / write into a non-empty directory")
    b = sub.add_parser("backends", help="list the backends and the formulations each takes")
    b.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    saved_limit = os.environ.get("PLATEQP_MAX_MEMORY")  # --max-memory holds for this command only
    try:
        return {"demo": cmd_demo, "solve": cmd_solve, "sweep": cmd_sweep, "backends": cmd_backends,
                "export": cmd_export}[args.cmd](args)
    except KeyboardInterrupt:
        print("plateqp: interrupted", file=sys.stderr)
        return 130
    except NoEquilibriumError as exn:
        print(f"plateqp: no equilibrium: {exn}", file=sys.stderr)
        return 3
    except SolverError as exn:
        print(f"plateqp: solver error: {exn}", file=sys.stderr)
        return 4
    except PlateQPError as exn:
        print(f"plateqp: {exn}", file=sys.stderr)
        return 2
    except MemoryError:
        print("plateqp: out of memory: use a coarser mesh, or fewer contact points", file=sys.stderr)
        return 2
    except Exception as exn:  # noqa: BLE001 - a bug: one line, not a traceback (PLATEQP_DEBUG=1 shows it)
        if os.environ.get("PLATEQP_DEBUG"):
            raise
        print(f"plateqp: internal error (a bug in plateqp, please report it with the command): "
              f"{type(exn).__name__}: {str(exn).splitlines()[0] if str(exn) else ''}", file=sys.stderr)
        return 1
    finally:
        if saved_limit is None:
            os.environ.pop("PLATEQP_MAX_MEMORY", None)
        else:
            os.environ["PLATEQP_MAX_MEMORY"] = saved_limit


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
