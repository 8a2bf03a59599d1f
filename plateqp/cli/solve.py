"""``plateqp solve``: one scene, its summary or JSON, ``--out`` files, ``--sensitivity``.
"""

from __future__ import annotations

import json
import warnings

import numpy as np

from ..accuracy import Status
from ..solving import solve
from ..errors import PlateQPError, ProblemError
from ..io.files import safe_filename
from ..io.vtk import vtu_files, write_vtu
from .common import _options, _backend_name, _out_dir, _stdout_to_stderr, _set_memory_limit, _scene_or_builtin, log


def _check_probes(scene, probes) -> None:
    """Before any work: a probe off the plate (outside it, in an opening or a hole) is a SceneError
    naming it, so that no solve is lost to it."""
    if not probes:
        return
    from ..model.checks import plate_cover

    cover = plate_cover(scene)
    for px, py in probes:
        scene._inside(f"--probe {px:g},{py:g}", px, py, grid=cover)


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
        est = result.extras.get("discretisation_error")
        if est and est.get("trusted") is False:
            lines.append(f"  accuracy auto: the meshes disagree (mesh error estimated {est['worst']:.2g}, then"
                         f" {est['observed']:.2g} from this mesh): the estimate is not to be trusted; refine the mesh")
        if not result.deflection_unique:
            lines.append("  reactions unique, deflection not unique: the supports that carry the load leave a rigid"
                         " motion of the plate free; shown: its lowest position, nearest the level")
        lines.append("  support      x          y        gap0        reaction     in contact   (numbered from 1)")
        sc = result.scene
        for i, s in enumerate(sc.supports):
            lines.append(f"  {i + 1:5d} {s.x:10.4g} {s.y:10.4g} {s.gap:11.4g} {result.reactions[i]:14.6g}"
                         f"     {'yes' if result.active[i] else 'no'}")
    t = result.times
    lines.append(f"  times: build {t.get('build', 0):.3f} s, solve {t.get('solve', 0):.3f} s, total {t.get('total', 0):.3f} s")
    return "\n".join(lines)


def _have_meshio() -> bool:
    try:
        import meshio  # noqa: F401
    except ImportError:
        return False
    return True


def _sensitivity(result, as_json: bool):
    """--sensitivity: the gap-sensitivity matrix dR_i/dg0_j of the solution
    (:func:`plateqp.sensitivity`), as its JSON shape or as lines of text."""
    from ..sensitivity import sensitivity

    sens = sensitivity(result, "gaps")
    if as_json:
        return sens.to_dict()
    if sens.smooth:
        sides = [("dR_i/dg0_j", sens.increasing)]
    else:
        at = ", ".join(str(int(i) + 1) for i in sens.degenerate)  # numbered from 1, as in the table
        sides = [(f"dR_i/dg0_j as the gap increases (support(s) {at} at lift-off)", sens.increasing),
                 (f"dR_i/dg0_j as the gap decreases (support(s) {at} at lift-off)", sens.decreasing)]
    lines = []
    for title, der in sides:
        lines.append(f"  {title}:")
        lines += ["  " + " ".join(f"{v:12.5g}" for v in row) for row in der.reactions]
    return "\n".join(lines)


def cmd_solve(args) -> int:
    _set_memory_limit(args.max_memory)
    scene = _scene_or_builtin(args.scene)
    opts = _options(args.options)
    _backend_name(args.backend)
    _check_probes(scene, args.probe)
    stem = safe_filename(scene.name)
    if args.sensitivity and not scene.one_sided:
        raise ProblemError("--sensitivity: the scene has no one-sided supports (nothing to differentiate)")
    vtu = bool(args.out) and _have_meshio()
    if args.out and not vtu:
        log.warning("meshio is not installed: no .vtu written (pip install 'plateqp[results]')")
    files = [f"{stem}.json", f"{stem}-w.npy"] + (vtu_files(stem) if vtu else [])
    out = _out_dir(args.out, files, args.force) if args.out else None
    reached = True
    with warnings.catch_warnings(), _stdout_to_stderr():
        warnings.simplefilter("ignore")  # the status says it; the warning would repeat it on stderr
        if args.target is not None:
            from ..studies import solve_to_target

            if opts:
                raise PlateQPError("--target chooses the backend's tolerance itself: drop --options")
            if args.accuracy != "default":
                raise PlateQPError("--target chooses the solver tolerance (a tenth of the target): drop --accuracy")
            tr = solve_to_target(scene, args.target, backend=args.backend, formulation=args.formulation,
                                 max_cells=args.max_mesh,
                                 progress=lambda r: log.info("--target: mesh %dx%d: %s in %.2f s", r["mesh"][0],
                                                             r["mesh"][1], r["status"], r["time"]))
            reached, result = tr.reached, tr.result
            if result is None:
                raise PlateQPError(f"--target: no mesh up to {args.max_mesh} cells a side could be solved")
        else:
            result = solve(scene, backend=args.backend, formulation=args.formulation, accuracy=args.accuracy,
                           options=opts)
    log.info("%s: %s on the %s problem: %s in %.3g s", scene.name, result.backend, result.formulation,
             result.status.value, result.times.get("total") or 0.0)
    if args.json:
        d = result.to_dict(args.probe)
        if args.target is not None:
            d["target"] = {"target": tr.target, "reached": tr.reached, "tolerance": tr.tolerance,
                           "mesh": [result.scene.mesh.nx, result.scene.mesh.ny],
                           "meshes": [{**r, "mesh": list(r["mesh"])} for r in tr.rows]}
        if args.sensitivity:
            d["sensitivity"] = _sensitivity(result, True)
        print(json.dumps(d, indent=1))
    else:
        if args.target is not None:
            print(tr)
        print(_summary(result, args.probe))
        if args.sensitivity:
            print(_sensitivity(result, False))
    if out is not None:
        from ..io.safe import write

        label = f"--out {args.out}"
        write(out / f"{stem}.json", json.dumps(result.to_dict(args.probe), indent=1), force=args.force,
              label=label, root=out)
        w = result.w_nodes()
        write(out / f"{stem}-w.npy", lambda tmp: np.save(tmp, w), force=args.force, label=label, root=out)
        if vtu:
            write_vtu(result, out, stem, force=args.force)
    return 0 if result.status in (Status.OPTIMAL,) and reached else 5
