"""Scaling: time and memory against dofs and against contact points, per backend × formulation.

Two sweeps on ``plateqp.scenes.families.grid_rigid`` (an 8 m slab on walls and a k × k grid of rigid
one-sided posts with mixed gaps), at one accuracy (``--accuracy``, default 1e-6, "mid"):

* ``dofs``: n = 16, 32, 64, 128, 256 (``--sizes``) at a fixed grid (``--k``, default 7: 49 posts);
* ``contacts``: k = 5, 9, 15, 31, all (``--ks``; m = k² = 25 … 3969 at n = 64) at fixed mesh(es)
  (``--meshes``, default 64).

Per case, in a fresh interpreter (bench_contact.run_in_subprocess: spawn, warmed up on a tiny
scene): assembly time, formulate time (condensation / flexibility, rebuilt for each repeat),
solve time (the backend alone), the median of ``--repeat`` solves when one takes under a fifth
of the limit, else one; status and worst KKT residual; and **memory**: the peak resident set
size of the subprocess during formulate + solve above its resident size just before
(Linux: the peak, VmHWM, is reset through /proc/self/clear_refs before each step, so C and
Fortran allocations count, not only Python's), plus the process's lifetime peak (ru_maxrss).
A pair that times out (or would need a dense m × m matrix above ``--dense-max-gb``) is
skipped at the larger sizes. Log–log slopes: numpy.polyfit on the largest 3 points solved.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_scaling.py
    python benchmarks/bench_scaling.py --parts contacts --meshes 32,64 --timeout 120
    python benchmarks/bench_scaling.py --report-only

Writes benchmarks/results/scaling.csv (one row per case), benchmarks/results/scaling.md and
benchmarks/figures/scaling_*.png.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before NumPy loads
    os.environ.setdefault(_var, "1")

import argparse
import csv
import math
import platform
import re
import statistics
import sys
import time
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_contact import run_in_subprocess

from plateqp.scenes.families import grid_rigid, positions

PAIRS = ("pdas/primal", "bpp/condensed", "lemke/condensed", "bpp/dual", "clarabel/primal", "clarabel/condensed",
         "osqp/primal", "osqp/condensed", "qpsolvers:proxqp/primal", "qpsolvers:proxqp/condensed",
         "qpsolvers:daqp/condensed", "qpsolvers:piqp/primal")
COLUMNS = ["part", "n", "k", "m", "ndof", "nnz_K", "backend", "formulation", "accuracy", "status", "build_s",
           "formulate_s", "solve_s", "total_s", "repeats", "iterations", "kkt_worst", "mem_step_mb",
           "mem_build_mb", "maxrss_mb", "dense_mb"]


def _status_kb():
    """(VmRSS, VmHWM) in kB from /proc/self/status, or None off Linux."""
    try:
        s = open("/proc/self/status").read()
        return tuple(int(re.search(k + r":\s+(\d+)", s).group(1)) for k in ("VmRSS", "VmHWM"))
    except (OSError, AttributeError):
        return None


def _reset_peak():
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")  # resets VmHWM to the current RSS
        return True
    except OSError:
        return False


def _case(args, q):
    n, k, backend, formulation, accuracy, repeat, timeout = args
    warnings.simplefilter("ignore")
    import resource

    from plateqp.model.assembly import build_model
    from plateqp.contact import solve_contact

    try:  # pay the first-call imports on a tiny scene
        solve_contact(build_model(grid_rigid(4, 3)), backend=backend, formulation=formulation, accuracy=accuracy)
    except Exception:
        pass
    _reset_peak()
    before = _status_kb()
    t0 = time.perf_counter()
    model = build_model(grid_rigid(n, k))
    t_build = time.perf_counter() - t0
    after = _status_kb()
    out = {"build_s": t_build, "ndof": model.n_free, "m": model.contacts.m, "nnz_K": model.K.nnz,
           "mem_build_mb": (after[1] - before[0]) / 1024 if before else None}
    fs, ss, mem = [], [], []
    try:
        for i in range(repeat):
            model.derived.clear()
            peak_ok = _reset_peak()
            before = _status_kb()
            r = solve_contact(model, backend=backend, formulation=formulation, accuracy=accuracy)
            after = _status_kb()
            fs.append(r.times["formulate"])
            ss.append(r.times["solve"])
            if before and peak_ok:
                mem.append((after[1] - before[0]) / 1024)
            if i == 0 and fs[0] + ss[0] > timeout / 5:
                break
        out.update(status=r.status.value, iterations=r.iterations, kkt_worst=r.kkt.worst,
                   formulate_s=statistics.median(fs), solve_s=statistics.median(ss), repeats=len(ss),
                   mem_step_mb=max(mem) if mem else None)
    except Exception as exn:
        out.update(status=f"error: {type(exn).__name__}: {exn}"[:120])
    out["maxrss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    q.put(out)


def run_sweep(part, cases, pairs, args, rows, out):
    """cases: list of (n, k); a pair that fails by time or size is skipped at later cases."""
    dead: dict[str, str] = {}
    for n, k in cases:
        kk = len(positions(n, k, interior=True))
        m = kk * kk
        dense_mb = 8.0 * m * m / 2**20
        for pair in pairs:
            b, f = pair.split("/")
            row = {"part": part, "n": n, "k": k, "m": m, "backend": b, "formulation": f, "accuracy": args.accuracy,
                   "dense_mb": dense_mb if f != "primal" else 0.0}
            if pair in dead:
                row["status"] = dead[pair]
            elif f != "primal" and dense_mb > 1024 * args.dense_max_gb:
                row["status"] = f"skipped (dense {m}×{m}: {dense_mb / 1024:.1f} GB)"
            else:
                r = run_in_subprocess(_case, (n, k, b, f, args.accuracy, args.repeat, args.timeout),
                                      2 * args.timeout + 60)
                row.update(r)
                if "total_s" not in row and row.get("solve_s") is not None:
                    row["total_s"] = row["formulate_s"] + row["solve_s"]
                if row["status"].startswith("timeout") or (row.get("total_s") or 0) > args.timeout:
                    if not row["status"].startswith("timeout"):
                        row["status"] = f"over limit ({row['status']})"
                    dead[pair] = f"skipped (over the limit at a smaller case: n={n}, k={k})"
            rows.append(row)
            print(f"{part:>8} n={n:<4} m={m:<6} {pair:<28} {row['status'][:40]:<40} "
                  f"f+s {_g(row.get('total_s'))} s  (f {_g(row.get('formulate_s'))}, s {_g(row.get('solve_s'))})  "
                  f"mem {_g(row.get('mem_step_mb'))} MB", flush=True)
            write_csv(rows, out, quiet=True)


def _g(v):
    return "–" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.3g}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--parts", default="dofs,contacts")
    ap.add_argument("--sizes", default="16,32,64,128,256")
    ap.add_argument("--k", type=int, default=7, help="posts per row in the dofs sweep")
    ap.add_argument("--meshes", default="64", help="mesh(es) of the contacts sweep")
    ap.add_argument("--ks", default="5,9,15,31,all", help="posts per row in the contacts sweep")
    ap.add_argument("--pairs", default=",".join(PAIRS))
    ap.add_argument("--accuracy", type=float, default=1e-6)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=120.0, help="seconds per solve")
    ap.add_argument("--dense-max-gb", type=float, default=2.0, help="skip condensed/dual past this dense m×m size")
    ap.add_argument("--out", default=str(HERE / "results" / "scaling.csv"))
    ap.add_argument("--figures", default=str(HERE / "figures"))
    ap.add_argument("--report-only", action="store_true")
    args = ap.parse_args()
    out = Path(args.out)
    if args.report_only:
        write_report(read_csv(out), out, Path(args.figures))
        return
    pairs = args.pairs.split(",")
    rows: list[dict] = []
    parts = args.parts.split(",")
    if "dofs" in parts:
        run_sweep("dofs", [(int(n), args.k) for n in args.sizes.split(",")], pairs, args, rows, out)
    if "contacts" in parts:
        from plateqp.progress import track  # a bar on a terminal only
        for n in track([int(v) for v in args.meshes.split(",")], "meshes"):
            ks = [k if k == "all" else int(k) for k in args.ks.split(",")]
            run_sweep("contacts", [(n, k) for k in ks if k == "all" or k <= n - 1], pairs, args, rows, out)
    write_csv(rows, out)
    write_report(rows, out, Path(args.figures))


def write_csv(rows, path, quiet=False):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({c: r.get(c, "") for c in COLUMNS})
    if not quiet:
        print(f"written {path}")


def read_csv(path):
    text = ("part", "k", "backend", "formulation", "status")
    with open(path) as fh:
        return [{c: (v if c in text else (None if v == "" else float(v))) for c, v in r.items()}
                for r in csv.DictReader(fh)]


def solved(r):
    return r.get("status") in ("optimal", "inaccurate") and r.get("total_s") is not None


def slope(xs, ys, last=3):
    """Log–log slope of the largest ``last`` points."""
    if len(xs) < 2:
        return float("nan")
    x, y = np.log(np.asarray(xs[-last:], float)), np.log(np.asarray(ys[-last:], float))
    return float(np.polyfit(x, y, 1)[0])


def series(rows, part, n=None):
    """{pair: [(x, row)]} sorted by x (ndof for dofs, m for contacts)."""
    out = defaultdict(list)
    for r in rows:
        if r["part"] == part and (n is None or r["n"] == n):
            out[f"{r['backend']}/{r['formulation']}"].append(r)
    key = "n" if part == "dofs" else "m"
    return {p: sorted(v, key=lambda r: r[key]) for p, v in out.items()}


def table(rows, part, n=None):
    ser = series(rows, part, n)
    xs = sorted({int(r["n"] if part == "dofs" else r["m"]) for v in ser.values() for r in v})
    xname = "n" if part == "dofs" else "m"
    head = "| backend/formulation | " + " | ".join(f"{xname}={x}" for x in xs) + \
        " | slope (time) | slope (mem) |"
    lines = [head, "|---|" + "---|" * (len(xs) + 2)]
    for p, v in ser.items():
        cells, tx, ty, my = [], [], [], []
        by = {int(r["n"] if part == "dofs" else r["m"]): r for r in v}
        for x in xs:
            r = by.get(x)
            if r is None:
                cells.append("")
            elif solved(r):
                mark = "" if r["status"] == "optimal" else "*"
                cells.append(f"{r['total_s']:.3g} ({r['solve_s']:.2g}) {_g(r.get('mem_step_mb'))} MB{mark}")
                tx.append(r["ndof"] if part == "dofs" else r["m"])
                ty.append(r["total_s"])
                my.append(max(r.get("mem_step_mb") or 0.0, 1e-3))
            else:
                s = r["status"]
                cells.append("timeout" if "timeout" in s or "over limit" in s else
                             "skipped" if s.startswith("skipped") else "error")
        lines.append(f"| {p} | " + " | ".join(cells) + f" | {slope(tx, ty):.2f} | {slope(tx, my):.2f} |")
    return "\n".join(lines)


def write_report(rows, csv_path, figdir):
    md = csv_path.with_suffix(".md")
    lines = ["# Scaling (generated by benchmarks/bench_scaling.py)", "",
             f"Machine: {platform.machine()} {os.cpu_count()} CPUs (shared), Python {platform.python_version()}, "
             f"NumPy {np.__version__}, OPENBLAS_NUM_THREADS=1.", "",
             "Cells: formulate + solve seconds (solve alone in brackets), median of up to 3, and the peak RSS "
             "rise of formulate + solve in MB; * = status inaccurate (KKT above the tolerance). Slopes: "
             "log–log fit on the largest 3 solved points, time against ndof (dofs sweep) or m (contacts sweep).", ""]
    for part in ("dofs", "contacts"):
        ns = sorted({int(r["n"]) for r in rows if r["part"] == part})
        for n in ([None] if part == "dofs" else ns):
            sel = [r for r in rows if r["part"] == part and (n is None or r["n"] == n)]
            if not sel:
                continue
            if part == "dofs":
                k = sel[0]["k"]
                lines += [f"## Against dofs: grid_rigid(n, {k}), m = {int(sel[0]['m'])}", "",
                          "ndof: " + ", ".join(f"n={int(r['n'])}: {int(r['ndof'])}" for r in
                                               {int(r["n"]): r for r in sel if r.get("ndof")}.values()), ""]
            else:
                lines += [f"## Against contact points: grid_rigid({n}, k), {int(sel[0].get('ndof') or 0)} dofs", ""]
            lines += [table(rows, part, n), ""]
    md.write_text("\n".join(lines) + "\n")
    print(f"written {md}")
    try:
        plot(rows, figdir)
    except ImportError:
        print("matplotlib not installed: no figures")


def plot(rows, figdir):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figdir.mkdir(parents=True, exist_ok=True)
    pairs = sorted({f"{r['backend']}/{r['formulation']}" for r in rows})
    cmap = plt.get_cmap("tab20")
    style = {p: (cmap(i % 20), "-" if p.endswith("primal") else "--" if p.endswith("condensed") else ":")
             for i, p in enumerate(pairs)}
    for part in ("dofs", "contacts"):
        ns = sorted({int(r["n"]) for r in rows if r["part"] == part})
        for n in ([None] if part == "dofs" else ns):
            ser = series(rows, part, n)
            if not ser:
                continue
            fig, axes = plt.subplots(1, 2, figsize=(10, 4))
            for p, v in ser.items():
                ok = [r for r in v if solved(r)]
                if not ok:
                    continue
                x = [r["ndof"] if part == "dofs" else r["m"] for r in ok]
                c, ls = style[p]
                axes[0].plot(x, [r["total_s"] for r in ok], ls, color=c, marker="o", ms=3, label=p)
                axes[1].plot(x, [max(r.get("mem_step_mb") or 0, 0.1) for r in ok], ls, color=c, marker="o", ms=3)
            for ax, what in zip(axes, ("formulate + solve (s)", "peak RSS rise of formulate + solve (MB)")):
                ax.set_xscale("log")
                ax.set_yscale("log")
                ax.set_xlabel("free dofs" if part == "dofs" else "contact points m", fontsize=8)
                ax.set_ylabel(what, fontsize=8)
                ax.grid(True, lw=0.3)
                ax.tick_params(labelsize=7)
            fig.legend(*axes[0].get_legend_handles_labels(), fontsize=6, loc="center right", frameon=False)
            title = "against dofs (grid_rigid, k fixed)" if part == "dofs" else f"against contact points ({n}² mesh)"
            fig.suptitle(f"Scaling {title}, accuracy 1e-6", fontsize=9)
            fig.tight_layout(rect=(0, 0, 0.8, 0.95))
            path = figdir / (f"scaling_{part}.png" if n is None else f"scaling_{part}_{n}.png")
            fig.savefig(path, dpi=90)
            plt.close(fig)
            print(f"written {path} ({path.stat().st_size // 1024} kB)")


if __name__ == "__main__":
    main()
