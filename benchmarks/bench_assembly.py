#!/usr/bin/env python3
"""Assembly and sparse factorisation of the plate stiffness matrix: times, memory, fill, accuracy.

A script, not a test (pytest does not collect it). Every measured case runs in a fresh
subprocess, so peak memory (ru_maxrss above the resident size just before the step: C
allocations included) and first-call costs are not polluted by earlier cases.

    python benchmarks/bench_assembly.py                          # assembly vs factorisation table
    python benchmarks/bench_assembly.py --table solvers          # every importable factorisation
    python benchmarks/bench_assembly.py --table precision        # residual floor, refinement
    python benchmarks/bench_assembly.py --profile 256            # cProfile of build_model at 256²
    python benchmarks/bench_assembly.py --sizes 32 64 --repeat 5 --elements acm

Tables are printed as markdown; rows are merged into benchmarks/results/assembly.csv
(keyed by table, element, size and method, so runs of different tables accumulate).

Scene: unit square, h = 0.01, E = 1e7, ν = 0.3, all four edges simply supported, uniform
load 1; an n × n mesh of ACM (3 dofs/node) or BFS (4 dofs/node) elements.

Factorisations ("methods"): plateqp's own ``superlu`` (SuperLU symmetric mode),
``superlu-default`` (SciPy's defaults) and ``cholmod`` (scikit-sparse), all through
:class:`plateqp.linalg.Factor`; and, for comparison, ``pardiso`` (pypardiso, MKL),
``cvxopt`` (cvxopt.cholmod: CHOLMOD inside cvxopt's wheels), ``cholespy`` (CHOLMOD inside
cholespy's wheels) and ``qdldl``. The comparison methods reuse Factor's equilibration and
iterative refinement (only the factor/solve of the scaled matrix differs), so residuals with
and without refinement are comparable across methods. Methods that are not importable are
skipped with a note.
"""

from __future__ import annotations

import argparse
import csv
import gc
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
CSV_PATH = HERE / "results" / "assembly.csv"
ALL_METHODS = ("superlu", "superlu-default", "cholmod", "pardiso", "cvxopt", "cholespy", "qdldl")
CSV_FIELDS = ("table", "element", "n", "method", "n_free", "nnz_K", "assembly_s", "assembly_warm_s",
              "assembly_MB", "factor_s", "factor_first_s", "solve_s", "solve_refined_s", "factor_MB",
              "fill", "res_norefine", "res_refined", "res_floor", "res_mixed", "res_mixed_exact", "fwd_norefine",
              "fwd_refined", "fwd_refined_vs_split", "refs_apart", "backward_err", "assembly_over_factor", "factor_over_cholmod",
              "threads", "blas", "repeat", "note")


# ------------------------------------------------------------------------------------------
# helpers that run inside the worker processes
# ------------------------------------------------------------------------------------------
def _scene(element: str, n: int):
    import plateqp.model.scene as S

    return S.Scene(plate=S.Plate(a=1.0, b=1.0, h=0.01, E=1e7, nu=0.3), mesh=S.MeshSpec(n, n, element),
                   edges={k: "simple" for k in S.EDGE_NAMES}, loads=[S.UniformLoad(1.0)])


def _rss_mb() -> float:
    """Current resident set size (Linux /proc; falls back to the peak elsewhere)."""
    try:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
    except OSError:  # pragma: no cover - not Linux
        return _maxrss_mb()


def _maxrss_mb() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return r / 2**20 if sys.platform == "darwin" else r / 2**10


def _blas_loaded(method: str) -> str:
    """The BLAS a CHOLMOD build uses: the system's libblas.so.3 (whatever Debian's alternatives
    or LD_LIBRARY_PATH resolve) for scikit-sparse, the copy inside the wheel for cvxopt/cholespy."""
    try:
        maps = Path("/proc/self/maps").read_text()
    except OSError:  # pragma: no cover
        return ""
    where = {"cholmod": None, "cvxopt": "cvxopt.libs", "cholespy": "cholespy.libs"}[method]
    names = set()
    for line in maps.splitlines():
        path = line.split()[-1]
        base = os.path.basename(path)
        if not (path.startswith("/") and base.startswith("lib") and "blas" in base):
            continue
        if (where is None and "site-packages" not in path) or (where and where in path):
            names.add(path.split("x86_64-linux-gnu/")[-1] if where is None else "wheel's " + base)
    return "BLAS: " + (", ".join(sorted(names)) or "?")


def _make_factor(K, method: str):
    """plateqp's Factor for its own methods; otherwise the same equilibration + refinement
    around another library's factor/solve of the scaled matrix."""
    import numpy as np
    import scipy.sparse as sp

    from plateqp.linalg import Factor

    if method in ("superlu", "superlu-default", "cholmod"):
        return Factor(K, method)

    class Other(Factor):
        def __init__(self, K, method):
            self.method = method
            self.order = self.chol = None  # Factor's _raw and solves read them (the library's own here)
            self.K = sp.csc_matrix(K)
            self.s = 1.0 / np.sqrt(self.K.diagonal())
            S = sp.diags(self.s)
            Ks = sp.csc_matrix(S @ self.K @ S)
            n = Ks.shape[0]
            self._fill = None
            if method == "pardiso":
                import pypardiso

                _locate_mkl_rt()
                A = sp.triu(Ks, format="csr")
                A.sort_indices()
                ps = pypardiso.PyPardisoSolver(mtype=2)  # real symmetric positive definite
                ps.factorize(A)
                self._fill = int(ps.iparm[17]) if ps.iparm[17] > 0 else None
                self._solve = lambda b: ps.solve(A, b)
                self._keep = ps
            elif method == "cvxopt":
                from cvxopt import cholmod, matrix, spmatrix

                L = sp.tril(Ks, format="coo")  # cvxopt's CHOLMOD reads the lower triangle
                A = spmatrix(matrix(L.data), matrix(L.row.astype(np.int64)), matrix(L.col.astype(np.int64)),
                             (n, n))
                F = cholmod.symbolic(A, uplo="L")
                cholmod.numeric(A, F)

                def solve(b):
                    B = matrix(np.asarray(b, dtype=float).reshape(n, -1))
                    cholmod.solve(F, B)
                    return np.array(B).reshape(b.shape)

                self._solve = solve
                self._keep = F
                self._fill_fn = lambda: len(cholmod.getfactor(F))  # converts F: call last
            elif method == "cholespy":
                from cholespy import CholeskySolverD, MatrixType

                Ks.sort_indices()
                cs = CholeskySolverD(n, Ks.indptr.astype(np.int32), Ks.indices.astype(np.int32),
                                     Ks.data.astype(np.float64), MatrixType.CSC)

                def solve(b):
                    b = np.ascontiguousarray(b, dtype=np.float64)
                    x = np.zeros_like(b)
                    cs.solve(b, x)
                    return x

                self._solve = solve
                self._keep = cs
            elif method == "qdldl":
                import qdldl

                q = qdldl.Solver(Ks)
                self._solve = lambda b: q.solve(b) if b.ndim == 1 else np.column_stack(
                    [q.solve(c) for c in b.T])
                self._keep = q
                self._fill_fn = lambda: int(q.factors()[0].nnz) + n
            else:
                raise ValueError(f"unknown method {method!r}")

        def _solve_scaled(self, b):
            return self._solve(b)

        def nnz_factor(self):
            if getattr(self, "_fill_fn", None) is not None:
                return self._fill_fn()
            return self._fill

    return Other(K, method)


def _locate_mkl_rt() -> None:
    """pypardiso globs sys.prefix for libmkl_rt on every PyPardisoSolver() when the loader
    cannot find it (pip wheels): do it once and pass the path on, so factor times exclude it."""
    if os.environ.get("PYPARDISO_MKL_RT"):
        return
    import pypardiso

    lib = pypardiso.PyPardisoSolver().libmkl
    os.environ["PYPARDISO_MKL_RT"] = lib._name


def _importable(method: str) -> str | None:
    """None if the method can run here, else why not."""
    mod = {"cholmod": "sksparse.cholmod", "pardiso": "pypardiso", "cvxopt": "cvxopt.cholmod",
           "cholespy": "cholespy", "qdldl": "qdldl"}.get(method)
    if mod is None:
        return None
    try:
        __import__(mod)
        if method == "pardiso":

            _locate_mkl_rt()  # finds libmkl_rt or raises
        return None
    except Exception as exn:  # noqa: BLE001
        return f"{mod} not importable ({type(exn).__name__}: {exn})"


def worker_assembly(job: dict) -> dict:
    import importlib

    import numpy as np
    import scipy.sparse as sp

    mod, _, fn = job.get("build", "plateqp.model.assembly:build_model").partition(":")
    build_model = getattr(importlib.import_module(mod), fn)
    sc = _scene(job["element"], job["n"])
    build_model(_scene(job["element"], 4))  # imports and element matrices out of the timing
    gc.collect()
    rss0 = _rss_mb()
    times = []
    for r in range(job["repeat"]):
        t = time.perf_counter()
        m = build_model(sc)
        times.append(time.perf_counter() - t)
        if r == 0:
            mem = _maxrss_mb() - rss0
        if r < job["repeat"] - 1:
            del m
            gc.collect()
    if job.get("save"):
        sp.save_npz(job["save"], m.K.tocsc())
        np.save(job["save"] + ".f.npy", m.f)
    return {"n_free": int(m.K.shape[0]), "nnz_K": int(m.K.nnz),
            "assembly_MB": mem, "times": times}


def worker_factor(job: dict) -> dict:
    import numpy as np
    import scipy.sparse as sp

    K = sp.load_npz(job["matrix"]).tocsr()
    f = np.load(job["matrix"] + ".f.npy")
    method = job["method"]
    # load the library (and MKL, BLAS) before the baseline: memory counts the factorisation only
    why = _importable(method)
    if why:
        return {"skip": why}
    _make_factor(sp.identity(3, format="csr") * 2.0, method).solve(np.ones(3))
    gc.collect()
    rss0 = _rss_mb()
    times, F = [], None
    for r in range(job["repeat"]):
        F = None
        gc.collect()
        t = time.perf_counter()
        F = _make_factor(K, method)
        times.append(time.perf_counter() - t)
        if r == 0:
            x0 = F.solve(f, refine=0)
            x3 = F.solve(f)
            mem = _maxrss_mb() - rss0
    ts = []
    for _ in range(job["nsolve"]):
        t = time.perf_counter()
        F.solve(f, refine=0)
        ts.append(time.perf_counter() - t)
    tr = []
    for _ in range(max(1, job["nsolve"] // 2)):
        t = time.perf_counter()
        F.solve(f)
        tr.append(time.perf_counter() - t)
    prec = _precision(K, f, F, x0, x3) if job.get("precision") else {}
    out = {"factor_s": statistics.median(times), "factor_first_s": times[0], "factor_MB": mem,
           "solve_s": statistics.median(ts), "solve_refined_s": statistics.median(tr),
           "fill": F.nnz_factor(), "res_norefine": F.residual(x0, f), "res_refined": F.residual(x3, f),
           "times": times, "blas": _blas_loaded(method) if method in ("cholmod", "cvxopt", "cholespy") else ""}
    out.update(prec)
    return out


def _precision(K, f, F, x0, x3) -> dict:
    """Rounding floor of the residual and mixed-precision refinement (long double residuals).

    u* = the solution after 5 steps of refinement with residuals accumulated in long double
    (forward error ~1e-13 where long double has a 64-bit mantissa, x86). Its residual, even
    summed in long double, is the least any float64 vector can have: the rounding of u* to
    float64 alone leaves K·δu with |δu| ≤ eps|u*|. floor = eps · ‖ |K| |u| ‖ / ‖f‖ is the
    a-priori bound of that. fwd err: ‖u − u*‖/‖u*‖. backward err: ‖Ku − f‖∞ / (‖K‖∞‖u‖∞ + ‖f‖∞).
    """
    import numpy as np

    eps = np.finfo(float).eps
    KL = K.astype(np.longdouble)
    fL = f.astype(np.longdouble)
    nf = np.linalg.norm(f)

    def res_exact(x):  # residual of the float64 vector x, computed in long double
        return float(np.linalg.norm((fL - KL @ x.astype(np.longdouble)).astype(float)) / nf)

    x = x3.copy()
    for _ in range(5):  # mixed-precision refinement: residual in long double, correction in double
        r = (fL - KL @ x.astype(np.longdouble)).astype(float)
        x = x + F._raw(r)
    xref = x
    # the same with the residual to ~2⁻⁷⁰ of |K||u| (plateqp.linalg.residual, checked against
    # rational arithmetic in tests/linalg/test_residual.py): the two references' distance bounds both
    from plateqp.linalg.residual import Residual

    R = Residual(K)
    x = x3.copy()
    for _ in range(5):
        x = x + F._raw(R(f, x))
    xsplit = x
    floor = eps * np.linalg.norm(abs(K) @ abs(xref)) / nf
    nK = np.max(abs(K).sum(axis=1))
    r3 = K @ x3 - f
    return {"res_floor": floor, "res_mixed": F.residual(xref, f), "res_mixed_exact": res_exact(xref),
            "fwd_norefine": float(np.linalg.norm(x0 - xref) / np.linalg.norm(xref)),
            "fwd_refined": float(np.linalg.norm(x3 - xref) / np.linalg.norm(xref)),
            "fwd_refined_vs_split": float(np.linalg.norm(x3 - xsplit) / np.linalg.norm(xsplit)),
            "refs_apart": float(np.linalg.norm(xref - xsplit) / np.linalg.norm(xsplit)),
            "backward_err": float(np.max(abs(r3)) / (nK * np.max(abs(x3)) + np.max(abs(f)))),
            "longdouble_eps": float(np.finfo(np.longdouble).eps)}


# ------------------------------------------------------------------------------------------
# parent: spawn workers, tabulate
# ------------------------------------------------------------------------------------------
def run_worker(job: dict, threads: int | None) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    if threads:
        for k in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
            env[k] = str(threads)
    proc = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--worker", json.dumps(job)],
                          check=False, env=env, capture_output=True, text=True)
    for line in proc.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
    return {"skip": f"worker failed (exit {proc.returncode}): {' | '.join(tail)}"}


def fmt(v, kind="g"):
    if v is None or v == "" or (isinstance(v, float) and math.isnan(v)):
        return "–"
    if kind == "s":
        return f"{v:.3f}" if v >= 0.01 else f"{v * 1e3:.2f} ms"
    if kind == "mb":
        return f"{v:.0f}"
    if kind == "e":
        return f"{v:.1e}"
    if kind == "x":
        return f"{v:.2f}×"
    if kind == "fill":
        return f"{v / 1e6:.2f} M" if v >= 1e5 else f"{v / 1e3:.0f} k"
    return str(v)


def merge_csv(rows: list[dict], path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    old = []
    if path.exists():
        with path.open() as fh:
            old = list(csv.DictReader(fh))
    key = lambda r: (r["table"], r["element"], str(r["n"]), r["method"])
    new_keys = {key(r) for r in rows}
    keep = [r for r in old if key(r) not in new_keys]
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=CSV_FIELDS, extrasaction="ignore")
        w.writeheader()
        for r in keep + rows:
            w.writerow({k: _csv_value(r.get(k)) for k in CSV_FIELDS})


def _csv_value(v):
    if isinstance(v, float):
        return f"{v:.4g}"
    return "" if v is None else v


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[32, 64, 128, 256], help="mesh n (n × n cells)")
    ap.add_argument("--elements", nargs="+", default=["acm", "bfs"], choices=["acm", "bfs"])
    ap.add_argument("--repeat", type=int, default=3,
                    help="repeats per measurement (median); factorisations at sizes >= --single run once "
                         "(assembly is always repeated, each repeat in a fresh process)")
    ap.add_argument("--single", type=int, default=256, help="sizes from this one up are run once")
    ap.add_argument("--table", choices=["assembly", "solvers", "precision"], default="assembly")
    ap.add_argument("--method", default="superlu",
                    help="assembly table: the factorisation to compare assembly with (plateqp's default "
                         "without CHOLMOD is superlu); CHOLMOD is added as the reference when importable")
    ap.add_argument("--methods", nargs="+", default=list(ALL_METHODS), help="solvers/precision tables")
    ap.add_argument("--threads", type=int, default=None, help="set OMP/MKL/OPENBLAS_NUM_THREADS in workers")
    ap.add_argument("--tag", default="", help="suffix for the method names (e.g. a BLAS variant)")
    ap.add_argument("--build", default="plateqp.model.assembly:build_model", metavar="MODULE:FUNC",
                    help="the assembly to time (e.g. a candidate replacement of build_model on PYTHONPATH)")
    ap.add_argument("--csv", type=Path, default=CSV_PATH)
    ap.add_argument("--no-csv", action="store_true")
    ap.add_argument("--profile", type=int, metavar="N",
                    help="cProfile a first call of build_model on an N × N mesh of --elements[0]")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)

    if args.worker:
        job = json.loads(args.worker)
        sys.path.insert(0, str(ROOT))
        res = worker_assembly(job) if job["kind"] == "assembly" else worker_factor(job)
        print("RESULT " + json.dumps(res))
        return 0
    if args.profile:
        return profile(args.profile, args.elements[0])

    rows = []
    tmp = tempfile.mkdtemp(prefix="plateqp-bench-")
    threads = str(args.threads) if args.threads else f"default ({os.cpu_count()} cores)"
    from plateqp.progress import track  # a bar on a terminal only
    for el in track(args.elements, "elements"):
        for n in args.sizes:
            rep = 1 if n >= args.single else args.repeat
            mpath = os.path.join(tmp, f"{el}{n}.npz")
            # assembly: each repeat in a fresh process (build_model runs once per process in real
            # use, and a first call pays the page faults of all its temporaries), plus in-process
            # warm repeats; assembly_s is the median of the first (cold) calls
            runs = [run_worker({"kind": "assembly", "element": el, "n": n, "repeat": 2 if r else 1,
                                "save": None if r else mpath, "build": args.build}, args.threads)
                    for r in range(args.repeat if args.table == "assembly" else 1)]
            if any("skip" in a for a in runs):
                print(f"{el} {n}: assembly failed: {[a['skip'] for a in runs if 'skip' in a]}", file=sys.stderr)
                continue
            asm = dict(runs[0])
            asm["assembly_s"] = statistics.median(a["times"][0] for a in runs)
            warm = [t for a in runs for t in a["times"][1:]]
            asm["assembly_warm_s"] = statistics.median(warm) if warm else None
            asm["assembly_MB"] = statistics.median(a["assembly_MB"] for a in runs)
            asm.pop("times", None)
            if args.table == "assembly":
                methods = [args.method] + (["cholmod"] if args.method != "cholmod" else [])
            else:
                methods = args.methods
            results = {}
            for meth in methods:
                res = run_worker({"kind": "factor", "matrix": mpath, "method": meth, "repeat": rep,
                                  "nsolve": 5 if n < args.single else 3,
                                  "precision": args.table == "precision"}, args.threads)
                results[meth] = res
                print(f"  {el} {n}² {meth}: " + (res["skip"] if "skip" in res else
                      f"factor {res['factor_s']:.3f} s, solve {res['solve_s']:.4f} s"), file=sys.stderr, flush=True)
            chol = results.get("cholmod", {}).get("factor_s")
            if args.table == "assembly":
                res = results[args.method]
                row = {"table": "assembly", "element": el, "n": n, "method": args.method + args.tag, **asm}
                if "skip" in res:
                    row["note"] = res["skip"]
                else:
                    row.update({k: v for k, v in res.items() if k not in ("times",)})
                    row["assembly_over_factor"] = asm["assembly_s"] / res["factor_s"]
                    row["factor_over_cholmod"] = res["factor_s"] / chol if chol else None
                    row["cholmod_s"] = chol
                row.update(threads=threads, repeat=rep)
                rows.append(row)
            else:
                for meth, res in results.items():
                    row = {"table": args.table, "element": el, "n": n, "method": meth + args.tag,
                           "n_free": asm["n_free"], "nnz_K": asm["nnz_K"], "threads": threads, "repeat": rep}
                    if "skip" in res:
                        row["note"] = res["skip"]
                    else:
                        row.update({k: v for k, v in res.items() if k not in ("times",)})
                        row["factor_over_cholmod"] = res["factor_s"] / chol if chol else None
                    rows.append(row)
            for p in (mpath, mpath + ".f.npy"):
                if os.path.exists(p):
                    os.remove(p)
    print_table(args.table, rows)
    if not args.no_csv:
        merge_csv(rows, args.csv)
        print(f"\n(rows merged into {args.csv})")
    return 0


def print_table(table: str, rows: list[dict]) -> None:
    if table == "assembly":
        head = ["element", "n", "dofs", "nnz(K)", "assembly s", "(warm)", "assembly MB", "factor", "factor s",
                "CHOLMOD s", "factor/CHOLMOD", "assembly/factor", "assembly/CHOLMOD", "solve s", "factor MB",
                "fill", "res (no refine)", "res (refined)"]
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for r in rows:
            chol = r.get("cholmod_s")
            print("| " + " | ".join([
                r["element"], f"{r['n']}²", str(r.get("n_free", "–")), fmt(r.get("nnz_K"), "fill"),
                fmt(r.get("assembly_s"), "s"), fmt(r.get("assembly_warm_s"), "s"), fmt(r.get("assembly_MB"), "mb"),
                r["method"],
                fmt(r.get("factor_s"), "s"), fmt(chol, "s"), fmt(r.get("factor_over_cholmod"), "x"),
                fmt(r.get("assembly_over_factor"), "x"),
                fmt(r["assembly_s"] / chol if chol else None, "x"), fmt(r.get("solve_s"), "s"),
                fmt(r.get("factor_MB"), "mb"), fmt(r.get("fill"), "fill"), fmt(r.get("res_norefine"), "e"),
                fmt(r.get("res_refined"), "e")]) + " |")
    elif table == "solvers":
        head = ["element", "n", "dofs", "method", "factor s", "×CHOLMOD", "solve s", "solve+refine s",
                "factor MB", "fill", "res (no refine)", "res (refined)", "note"]
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for r in rows:
            print("| " + " | ".join([
                r["element"], f"{r['n']}²", str(r.get("n_free", "–")), r["method"], fmt(r.get("factor_s"), "s"),
                fmt(r.get("factor_over_cholmod"), "x"), fmt(r.get("solve_s"), "s"),
                fmt(r.get("solve_refined_s"), "s"), fmt(r.get("factor_MB"), "mb"), fmt(r.get("fill"), "fill"),
                fmt(r.get("res_norefine"), "e"), fmt(r.get("res_refined"), "e"),
                (r.get("note") or r.get("blas") or "")[:60]]) + " |")
    else:
        head = ["element", "n", "method", "res (no refine)", "res (refine ≤3)", "res of u* (float64 sum)",
                "res of u* (long-double sum)", "floor eps‖|K||u|‖/‖f‖", "fwd err (no refine)",
                "fwd err (refine ≤3)", "fwd err (refine ≤3) vs split u*", "u* − split u*", "backward err"]
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for r in rows:
            print("| " + " | ".join([
                r["element"], f"{r['n']}²", r["method"], fmt(r.get("res_norefine"), "e"),
                fmt(r.get("res_refined"), "e"), fmt(r.get("res_mixed"), "e"), fmt(r.get("res_mixed_exact"), "e"),
                fmt(r.get("res_floor"), "e"),
                fmt(r.get("fwd_norefine"), "e"), fmt(r.get("fwd_refined"), "e"),
                fmt(r.get("fwd_refined_vs_split"), "e"), fmt(r.get("refs_apart"), "e"),
                fmt(r.get("backward_err"), "e")]) + " |")


def profile(n: int, element: str) -> int:
    import cProfile
    import io
    import pstats

    sys.path.insert(0, str(ROOT))
    from plateqp.model.assembly import build_model
    sc = _scene(element, n)
    build_model(_scene(element, 4))  # imports only: the profiled call is a first (cold) call, as in use
    pr = cProfile.Profile()
    pr.enable()
    build_model(sc)
    pr.disable()
    for key in ("tottime", "cumulative"):
        s = io.StringIO()
        pstats.Stats(pr, stream=s).strip_dirs().sort_stats(key).print_stats(15)
        print(s.getvalue())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
