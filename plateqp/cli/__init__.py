"""The ``plateqp`` command: demo, solve, sweep, export, backends.

Errors go to stderr as one line (what is wrong and where) with exit code 2 for bad input,
3 for no equilibrium, 4 for a solver failure, 5 for an answer that missed the asked accuracy
(or a ``--target`` not reached), 130 when interrupted (a sweep: 143 on SIGTERM; it stops its
workers and prints the rows done so far); 1 only for an internal error (a bug:
the line says so; ``PLATEQP_DEBUG=1`` shows the traceback).

``--quiet`` (errors only: no progress bar, note or warning) and ``--verbose`` (``-v``: the
library's INFO messages, ``-vv``: DEBUG) go before or after the command's name. Progress bars
and log messages go to standard error, bars only when it is a terminal (not under CI=true).
While a command works, anything a solver prints on standard output (HiGHS's banner, OSQP's
"Polishing not needed") is sent to standard error, so that ``--json`` output is JSON alone.
Files are written only inside ``--out``, under names made safe from the scene's name, never
over an existing file unless ``--force`` is given, and ``--out`` is checked before any work.
"""

from __future__ import annotations

import argparse
import os
import re
import sys

from ..errors import NoEquilibriumError, PlateQPError, SolverError
from ..io.files import safe_filename
from .common import _accuracy, _out_dir, _output, _probe, _target
from .solve import cmd_solve
from .studies import cmd_regulate, cmd_sweep
from .tools import cmd_backends, cmd_demo, cmd_export, cmd_verify


#: Options whose value may start with a minus sign (a heave, a negative range or probe).
_NUMERIC_OPTIONS = ("--values", "--range", "--target", "--probe")


def _negative_values_joined(argv: list[str]) -> list[str]:
    """``--values -0.2,0`` as ``--values=-0.2,0``: argparse takes a value that starts with '-' and is
    not a plain number for an option and fails with "expected one argument"."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in _NUMERIC_OPTIONS and i + 1 < len(argv) and re.match(r"-[\d.]", argv[i + 1]):
            out.append(f"{a}={argv[i + 1]}")
            i += 2
            continue
        out.append(a)
        i += 1
    return out


def _output_flags(p, here: bool) -> None:
    """--quiet / --verbose on the main parser (``here``) and on each command (there the defaults are
    SUPPRESS, so a flag given before the command's name is not reset by the command's parser)."""
    g = p.add_mutually_exclusive_group()
    g.add_argument("-q", "--quiet", action="store_true", default=False if here else argparse.SUPPRESS,
                   help="errors only: no progress bar, note or warning on standard error")
    g.add_argument("-v", "--verbose", action="count", default=0 if here else argparse.SUPPRESS,
                   help="the library's log messages on standard error (-v: INFO, -vv: DEBUG)")


class _Parser(argparse.ArgumentParser):
    """argparse with its errors as one line (what is wrong, and where to read the usage) and
    exit code 2, instead of the usage followed by the error."""

    def error(self, message):
        cmd = self.prog.split(" ", 1)[1] + ": " if " " in self.prog else ""
        self.exit(2, f"plateqp: {cmd}{message} (see {self.prog} --help)\n")


def main(argv=None) -> int:
    ap = _Parser(prog="plateqp", description="Thin plates on one-sided supports, contact as a convex QP.")
    _output_flags(ap, True)
    sub = ap.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("demo", help="solve a built-in scene and print a summary")
    from ..demo import names_all  # matplotlib stays unimported until a figure is drawn

    d.add_argument("name", nargs="?", help=f"a built-in scene or a study (the paper's figures, regulation, the soils): one of: "
                   f"{', '.join(names_all())} (default: all)")
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
    s.add_argument("--options", help="backend options as a JSON object, passed through untouched (but for \"predict\": see plateqp.solve)")
    s.add_argument("--json", action="store_true")
    s.add_argument("--sensitivity", action="store_true",
                   help="add the exact gap sensitivities dR_i/dg0_j of the solution (with --json: a 'sensitivity' object)")
    s.add_argument("--out", metavar="DIR", help="write <name>.json, <name>-w.npy (nodal w) and, with meshio, "
                   "<name>.vtu and <name>-supports.vtu (ParaView) into DIR")
    s.add_argument("--force", action="store_true", help="--out: overwrite files that exist")
    s.add_argument("--max-memory", metavar="BYTES",
                   help="refuse meshes estimated to need more (e.g. 8G; default 80%% of this machine's memory)")
    w = sub.add_parser("sweep", help="solve a scene for a range of one parameter; find where the contact set changes")
    w.add_argument("scene")
    w.add_argument("--param", required=True, metavar="PATH", help="e.g. supports.*.stiffness, supports.3.gap (support "
                   "number 3: supports are numbered from 1, as in the tables), loads.0.P")
    wv = w.add_mutually_exclusive_group(required=True)
    wv.add_argument("--values", metavar="V1,V2,...", help="values in sweep order ('rigid' allowed for a stiffness)")
    wv.add_argument("--range", metavar="A:B:N[:log]", help="N values from A to B, evenly or log spaced")
    w.add_argument("--backend", default="auto")
    w.add_argument("--formulation", default="auto", choices=["auto", "primal", "condensed", "dual"])
    w.add_argument("--accuracy", default="default", type=_accuracy,
                   help="low, default, high, a tolerance such as 1e-7, or auto")
    w.add_argument("--options", help="backend options as a JSON object, passed through untouched (but for \"predict\": see plateqp.solve)")
    w.add_argument("--rtol", type=float, default=1e-3, help="relative width of each breakpoint's bracket")
    w.add_argument("--no-refine", action="store_true", help="report changes between values without bisection")
    w.add_argument("--exact", action="store_true",
                   help="breakpoints exactly, by parametric pivoting, for a parameter that enters linearly "
                        "(a gap, a load, a prescribed displacement); refused for a stiffness")
    w.add_argument("--workers", type=int, default=None, help="local worker processes (default 2; 1: serial); "
                   "at most the cores this process may use, unless --force-workers")
    w.add_argument("--force-workers", action="store_true",
                   help="start --workers N processes even when N is more than the cores (with a warning)")
    w.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="run the sweep on the existing Dask cluster "
                   "whose scheduler is at this address (not with --workers)")
    w.add_argument("--scheduler-timeout", type=float, default=10.0, metavar="S",
                   help="--scheduler: seconds to wait for the scheduler to answer (default 10)")
    w.add_argument("--no-warm-start", action="store_true",
                   help="start each value's solve cold (warm starts: bpp and pdas, from the previous contact set)")
    w.add_argument("--max-values", type=int, default=10_000, metavar="N", help="most values a sweep takes")
    w.add_argument("--max-memory", metavar="BYTES", help="refuse meshes estimated to need more (e.g. 8G)")
    w.add_argument("--json", action="store_true")
    w.add_argument("--store", metavar="FILE.jsonl", help="write each row as it is solved; if FILE holds rows of "
                   "this same sweep (a stopped run), solve only the values it lacks")
    w.add_argument("--out", metavar="FILE.nc", help="the rows as an xarray Dataset in netCDF (value as the "
                   "dimension); checked before any work")
    w.add_argument("--force", action="store_true", help="--out: overwrite the file if it exists")
    x = sub.add_parser("export", help="write the contact problem as a QPS file or a qpbenchmark test set")
    x.add_argument("scene", help="a scene file, or the name of a built-in scene")
    x.add_argument("--formulation", default="primal", choices=["primal", "condensed", "dual"])
    x.add_argument("--format", default="qps", choices=["qps", "qpbenchmark"],
                   help="qps: one Maros-Meszaros QPS file; qpbenchmark: a directory with the .npz and the test-set module")
    x.add_argument("--out", required=True, metavar="PATH", help="the .qps file, or the test set's directory")
    x.add_argument("--name", help="problem name (default: SCENE_FORMULATION)")
    x.add_argument("--testset", default="plateqp_contact", help="qpbenchmark test-set module name")
    x.add_argument("--force", action="store_true", help="overwrite an existing file / write into a non-empty directory")
    r = sub.add_parser("regulate", help="gaps that make chosen supports carry target reactions (checked by a solve)")
    r.add_argument("scene", help="a scene file, or the name of a built-in scene")
    r.add_argument("--target", required=True, metavar="R[,R...]",
                   help="target reactions (compression >= 0): one for all, or one per regulated support")
    r.add_argument("--supports", metavar="N[,N...]", help="the regulated supports, numbered from 1 (default: all)")
    r.add_argument("--backend", default="auto")
    r.add_argument("--formulation", default="auto", choices=["auto", "primal", "condensed", "dual"])
    r.add_argument("--json", action="store_true")
    r.add_argument("--out", metavar="FILE.toml", help="write the regulated scene (checked before any work)")
    r.add_argument("--force", action="store_true", help="--out: overwrite the file if it exists")
    v = sub.add_parser("verify", help="the verification ladder: closed forms and independent references on "
                       "meshes that halve (error, observed rate, pass/fail); exit code 5 if a case fails")
    v.add_argument("--quick", action="store_true", help="two meshes per case (a few seconds) instead of three or four")
    v.add_argument("--case", action="append", metavar="NAME", help="run only this case (repeatable; names: "
                   "the first column of the table)")
    v.add_argument("--json", action="store_true", help="the rows as JSON")
    b = sub.add_parser("backends", help="list the backends and the formulations each takes")
    b.add_argument("--json", action="store_true")
    for p in sub.choices.values():
        _output_flags(p, False)
    # a bad flag: one line and SystemExit(2) (_Parser.error); --help: SystemExit(0)
    args = ap.parse_args(_negative_values_joined(sys.argv[1:] if argv is None else list(argv)))
    if args.quiet and args.verbose:
        ap.error("--quiet and --verbose: choose one")
    saved_limit = os.environ.get("PLATEQP_MAX_MEMORY")  # --max-memory holds for this command only
    try:
        with _output(args.quiet, args.verbose):
            return {"demo": cmd_demo, "solve": cmd_solve, "sweep": cmd_sweep, "backends": cmd_backends,
                    "export": cmd_export, "regulate": cmd_regulate, "verify": cmd_verify}[args.cmd](args)
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


__all__ = ["main", "safe_filename", "_out_dir"]
