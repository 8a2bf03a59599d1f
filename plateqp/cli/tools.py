"""``plateqp demo``, ``plateqp backends``, ``plateqp export``, ``plateqp verify``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..backends import registry
from ..contact import formulations_for
from .common import _out_dir, _scene_or_builtin


def cmd_demo(args) -> int:
    from ..demo import DEFAULT_OUT, output_files, run

    names = [args.name] if args.name else None
    files = output_files(names)  # an unknown scene: SceneError before any folder is made
    out = _out_dir(args.out or DEFAULT_OUT, files, args.force)  # before any work
    return run(names, out, force=args.force)


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


def cmd_export(args) -> int:
    """``plateqp export``: the contact problem as a QPS file or a qpbenchmark test set."""
    from ..errors import ExportError
    from ..io import check_testset_dir, contact_qp, write_qpbenchmark, write_qps
    from ..io.files import check_file

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


#: ``plateqp verify``'s exit code when a case fails (0: every case passes).
VERIFY_FAILED = 5


def cmd_verify(args) -> int:
    """``plateqp verify``: the verification ladder as a table (or JSON rows); 5 if a case fails."""
    from ..studies.verify import format_rows, verify

    rows = verify(quick=args.quick, names=args.case)
    finals = [r for r in rows if r.passed is not None]
    if args.json:
        print(json.dumps({"quick": bool(args.quick), "passed": sum(r.passed for r in finals),
                          "cases": len(finals), "rows": [r.to_dict() for r in rows]}, indent=1))
    else:
        print(format_rows(rows))
    return 0 if all(r.passed for r in finals) else VERIFY_FAILED
