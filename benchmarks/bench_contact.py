"""First contact table: every backend × formulation on a 64 × 64 plate with a grid of supports.

For each case: build (assembly + formulation) time, solve time, the KKT residuals, the status,
and the largest reaction error against a reference (Lemke on the condensed LCP at `high`,
which is exact up to rounding, its KKT residuals below 1e-12).

    python benchmarks/bench_contact.py                      # 10×10 and 30×30 support grids
    python benchmarks/bench_contact.py --grids 10 --timeout 60 --backends lemke,clarabel

Each backend runs in a subprocess with a time limit (a timed-out case is recorded as such).
Writes benchmarks/results/contact.csv and prints a markdown table.
"""

from __future__ import annotations

import argparse
import csv
import multiprocessing as mp
import queue
import time
import warnings
from pathlib import Path

import numpy as np

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.contact import formulations_for, solve_contact

HERE = Path(__file__).parent


def scene(n_mesh: int, n_grid: int) -> pq.Scene:
    """A simply supported square plate, an n_grid² grid of rigid one-sided supports on mesh
    nodes with mixed gaps (heave in one corner, settlement in the opposite), a point load and
    self-weight: a real contact problem with a mixed working scheme."""
    a = 1.0
    xs = np.linspace(a / (n_grid + 1), a * n_grid / (n_grid + 1), n_grid)
    xs = np.round(xs * n_mesh / a) * a / n_mesh  # snap to nodes
    sups = []
    for x in xs:
        for y in xs:
            g = 2e-4 * (x + y - a)  # heave (g < 0) near (0, 0), settlement near (a, a)
            sups.append(pq.Support(float(x), float(y), gap=float(g)))
    return pq.Scene(name=f"grid{n_grid}", plate=pq.Plate(a, a, 0.02, 1e7, 0.3),
                    mesh=pq.MeshSpec(n_mesh, n_mesh, "acm"),
                    edges={k: "simple" for k in ("left", "right", "bottom", "top")},
                    loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.7, 0.6)], supports=sups)


def _run(args, q):
    n_mesh, n_grid, backend, formulation, accuracy = args
    warnings.simplefilter("ignore")
    # a fresh interpreter: pay the first-call imports (solvers, SciPy's LP) on a tiny scene first
    try:
        solve_contact(build_model(scene(4, 1)), backend=backend, formulation=formulation, accuracy=accuracy)
    except Exception:  # the real case below records any failure
        pass
    sc = scene(n_mesh, n_grid)
    t0 = time.perf_counter()
    model = build_model(sc)
    t_asm = time.perf_counter() - t0
    try:
        r = solve_contact(model, backend=backend, formulation=formulation, accuracy=accuracy)
        q.put({"status": r.status.value, "build": t_asm + r.times["formulate"], "solve": r.times["solve"],
               "kkt": r.kkt.as_dict(), "reactions": r.reactions.tolist(), "active": int(r.active.sum())})
    except Exception as exn:  # recorded, not hidden
        q.put({"status": f"error: {type(exn).__name__}: {str(exn)[:80]}"})


def run_in_subprocess(target, args, timeout):
    """Run target(args, queue) in a fresh interpreter with a time limit; its dict, or a status.

    "spawn", not fork: a forked child of a process that had run CHOLMOD hung here. The answer
    is read while the child runs: a child whose answer is larger than the pipe's buffer
    cannot exit before it is read (joining first deadlocked on a 257² deflection field).
    """
    ctx = mp.get_context("spawn")
    q = ctx.Queue()
    p = ctx.Process(target=target, args=(args, q))
    p.start()
    t_end = time.perf_counter() + timeout
    out = None
    while out is None and time.perf_counter() < t_end:
        try:
            out = q.get(timeout=0.2)
        except queue.Empty:
            if not p.is_alive():  # exited: its answer (if any) is in the pipe by now
                try:
                    out = q.get(timeout=1.0)
                except queue.Empty:
                    break
    p.join(5.0)
    if p.is_alive():
        p.terminate()
        p.join()
    if out is None:
        return {"status": f"timeout > {timeout:g} s" if time.perf_counter() >= t_end else "crashed"}
    return out


def run_case(args, timeout):
    return run_in_subprocess(_run, args, timeout)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", type=int, default=64)
    ap.add_argument("--grids", default="10,30")
    ap.add_argument("--backends", default="all")
    ap.add_argument("--accuracy", default="high")
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--out", default=str(HERE / "results" / "contact.csv"))
    ap.add_argument("--skip-cvxpy", action="store_true", help="leave out cvxpy:* (the same solvers as the direct and qpsolvers routes)")
    args = ap.parse_args()
    names = pq.available_backends() if args.backends == "all" else args.backends.split(",")
    if args.skip_cvxpy:
        names = [n for n in names if not n.startswith("cvxpy")]
    rows = []
    from plateqp.progress import track  # a bar on a terminal only
    for g in track([int(v) for v in args.grids.split(",")], "grids"):
        ref = run_case((args.mesh, g, "lemke", "condensed", "high"), 10 * args.timeout)
        R0 = np.array(ref["reactions"])
        print(f"\n### {args.mesh}×{args.mesh} ACM plate, {g}×{g} supports ({ref['active']} in contact); "
              f"reference Lemke/condensed, worst KKT {max(v for k, v in ref['kkt'].items() if k not in ('tol', 'scale', 'ok')):.1e}\n")
        print("| backend | formulation | status | build s | solve s | KKT worst | reaction error |")
        print("|---|---|---|---|---|---|---|")
        for b in names:
            for f in formulations_for(b):
                r = run_case((args.mesh, g, b, f, args.accuracy), args.timeout)
                row = {"mesh": args.mesh, "grid": g, "backend": b, "formulation": f, "accuracy": args.accuracy,
                       "status": r["status"], "build_s": r.get("build"), "solve_s": r.get("solve")}
                if "kkt" in r:
                    k = r["kkt"]
                    keys = ("stationarity", "spring", "primal", "dual", "complementarity", "natural")
                    row.update({key: k[key] for key in keys})
                    row["kkt_worst"] = max(k[key] for key in keys)
                    row["reaction_error"] = float(np.abs(np.array(r["reactions"]) - R0).max() / np.abs(R0).max())
                rows.append(row)
                fmt = lambda v, f="{:.3g}": "–" if v is None else f.format(v)  # noqa: E731
                print(f"| {b} | {f} | {row['status']} | {fmt(row.get('build_s'))} | {fmt(row.get('solve_s'))} | "
                      f"{fmt(row.get('kkt_worst'), '{:.1e}')} | {fmt(row.get('reaction_error'), '{:.1e}')} |", flush=True)
    keys = sorted({k for r in rows for k in r}, key=lambda k: list(rows[0]).index(k) if k in rows[0] else 99)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    print(f"\nwritten {args.out}")


if __name__ == "__main__":
    main()
