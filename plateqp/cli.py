"""The ``plateqp`` command: demo, solve, backends.

Errors go to stderr as one line (what is wrong and where) with exit code 2 for bad input,
3 for no equilibrium, 4 for a solver failure.
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

import numpy as np

from . import scenes
from .backends import registry
from .backends.base import Status
from .contact import formulations_for
from .driver import solve
from .errors import NoEquilibriumError, PlateQPError, SolverError
from .scene import Scene


def _probe(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"--probe wants X,Y (got {text!r})") from None
    return x, y


def result_dict(result, probes=()) -> dict:
    """The JSON shape of ``plateqp solve --json`` (DESIGN.md)."""
    w, x, y = result.w_max()
    d = {
        "scene": result.scene.name,
        "backend": result.backend,
        "formulation": result.formulation,
        "accuracy": result.accuracy,
        "status": result.status.value,
        "w_max": w,
        "w_max_x": x,
        "w_max_y": y,
        "probes": [{"x": px, "y": py, "w": float(result.deflection(px, py))} for px, py in probes],
        "reactions": result.reactions.tolist(),
        "active": result.active.tolist(),
        "gaps": result.gaps.tolist(),
        "residual": result.residual,
        "kkt": result.kkt.as_dict() if result.kkt is not None else None,
        "iterations": result.iterations,
        "times": {k: result.times.get(k) for k in ("build", "solve", "total")},
    }
    return d


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
    scene = Scene.from_toml(args.scene)
    opts = json.loads(args.options) if args.options else None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the status says it; the warning would repeat it on stderr
        result = solve(scene, backend=args.backend, formulation=args.formulation, accuracy=args.accuracy,
                       options=opts)
    if args.json:
        print(json.dumps(result_dict(result, args.probe), indent=1))
    else:
        print(_summary(result, args.probe))
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / f"{scene.name}.json").write_text(json.dumps(result_dict(result, args.probe), indent=1))
        np.save(out / f"{scene.name}-w.npy", result.w_nodes())
    return 0 if result.status in (Status.OPTIMAL,) else 5


def cmd_demo(args) -> int:
    names = [args.name] if args.name else scenes.names()
    out = Path(args.out) if args.out else None
    for name in names:
        scene = scenes.load(name)
        result = solve(scene, accuracy="high")
        print(_summary(result))
        report = {"one_sided": result_dict(result)}
        if scene.one_sided:
            from .assembly import build_model
            from .contact import solve_bilateral

            two = solve_bilateral(build_model(scene))
            w1, w2 = result.w_nodes(), two.w_nodes()
            dw = np.nanmax(np.abs(w1 - w2))
            print(f"  two-sided comparison: max |w_one-sided - w_two-sided| = {dw:.4g}"
                  f" (two-sided max w {np.nanmax(np.abs(w2)):.4g});"
                  f" two-sided reactions range [{two.reactions.min():.4g}, {two.reactions.max():.4g}]")
            report["two_sided"] = result_dict(two)
        if out is not None:
            out.mkdir(parents=True, exist_ok=True)
            (out / f"{name}.json").write_text(json.dumps(report, indent=1))
            print(f"  report written to {out / (name + '.json')}")
        print()
    return 0


def cmd_backends(args) -> int:
    rows = []
    for name, b in sorted(registry().items()):
        rows.append({"name": name, "formulations": formulations_for(b.accepts), "installed": bool(b.available()),
                     "version": b.version() if b.available() else None})
    if args.json:
        print(json.dumps({"backends": rows}, indent=1))
    else:
        print(f"{'backend':24s} {'installed':9s} {'version':12s} formulations")
        for r in rows:
            print(f"{r['name']:24s} {'yes' if r['installed'] else 'no':9s} {str(r['version'] or '-'):12s} "
                  f"{', '.join(r['formulations'])}")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="plateqp", description="Thin plates on one-sided supports, contact as a convex QP.")
    sub = ap.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("demo", help="solve a built-in scene and print a summary")
    d.add_argument("name", nargs="?", help=f"one of: {', '.join(scenes.names())} (default: all)")
    d.add_argument("--out", help="folder for the reports")
    s = sub.add_parser("solve", help="solve a scene file")
    s.add_argument("scene")
    s.add_argument("--backend", default="auto")
    s.add_argument("--formulation", default="auto", choices=["auto", "primal", "condensed", "dual"])
    s.add_argument("--accuracy", default="default", choices=["low", "default", "high"])
    s.add_argument("--probe", type=_probe, action="append", default=[], metavar="X,Y")
    s.add_argument("--options", help="backend options as a JSON object, passed through untouched")
    s.add_argument("--json", action="store_true")
    s.add_argument("--out")
    b = sub.add_parser("backends", help="list the backends and the formulations each takes")
    b.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    try:
        return {"demo": cmd_demo, "solve": cmd_solve, "backends": cmd_backends}[args.cmd](args)
    except NoEquilibriumError as exn:
        print(f"plateqp: no equilibrium: {exn}", file=sys.stderr)
        return 3
    except SolverError as exn:
        print(f"plateqp: solver error: {exn}", file=sys.stderr)
        return 4
    except PlateQPError as exn:
        print(f"plateqp: {exn}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
