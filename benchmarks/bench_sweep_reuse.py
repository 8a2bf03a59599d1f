"""A sweep that keeps the plate's factorisation: CPU time per value after the first ÷ raw.

"raw" is the floor of benchmarks/bench_fast.py: one CHOLMOD symbolic analysis + numeric
factorisation + solve of the plate's matrix, straight through cvxopt (grid: K; bed: K with
every bed spring bonded). Scenes are bench_fast's: ``grid`` (a slab on four walls and 30 × 30
rigid posts; the gap of post 1 swept) and ``bed`` (a free plate on a tensionless bed; the
swept parameter is given by ``--bed-path``, default the gap field's slope ``foundation.gap.gx``).

Per mesh and scene, interleaved, ``--repeats`` times (medians reported): raw; a serial sweep
of one value; a serial sweep of ``--values`` values (reuse on, warm starts on: the defaults).
Per value after the first = (sweep of V values − sweep of one) / (V − 1). Every row of every
sweep must be OPTIMAL (its KKT check passed at ``ACCURACY``); the rows also carry the
linear-algebra counts of the backend where it reports them (factorisations per value).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_sweep_reuse.py [--meshes 64,128] [--repeats 5]

Writes benchmarks/results/sweep-reuse.csv and prints a markdown table.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before NumPy loads
    os.environ.setdefault(_var, "1")

import argparse
import csv
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_fast import ACCURACY, make_scene, plate_matrix, raw_cholmod, to_cvxopt  # noqa: E402

from plateqp.model.assembly import build_model  # noqa: E402
from plateqp.studies.sweep import sweep  # noqa: E402


def values_for(kind: str, scene, count: int, bed_path: str):
    if kind == "grid":
        g0 = scene.supports[0].gap
        return "supports.1.gap", list(np.linspace(g0 - 0.002, g0 + 0.002, count))
    if bed_path == "foundation.gap.gx":
        return bed_path, list(np.linspace(0.003, 0.005, count))
    if bed_path == "foundation.k":
        return bed_path, list(np.geomspace(1.0e4, 4.0e4, count))
    if bed_path == "loads.1.P":
        return bed_path, list(np.linspace(100.0, 300.0, count))
    raise SystemExit(f"--bed-path: one of foundation.gap.gx, foundation.k, loads.1.P (got {bed_path})")


def run_sweep(scene, path, vals):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.process_time()
        r = sweep(scene, path, vals, accuracy=ACCURACY, executor="serial", progress=False, refine_breakpoints=False)
        dt = time.process_time() - t0
    bad = [row for row in r.rows if row["status"] != "optimal"]
    if bad:
        raise SystemExit(f"{scene.name} {path}: {len(bad)} rows not OPTIMAL: {bad[0]['status']} {bad[0]['error']}")
    return dt, r


def row_for(kind: str, n: int, values: int, repeats: int, bed_path: str) -> dict:
    scene = make_scene(kind, n)
    A, f = plate_matrix(kind, build_model(scene))
    Ac = to_cvxopt(A)
    path, vals = values_for(kind, scene, values, bed_path)
    run_sweep(scene, path, vals[:2])  # imports and first-use costs out of the clock
    times = {"raw": [], "one": [], "all": []}
    kkt, route = [], None
    for _ in range(repeats):
        t0 = time.process_time()
        raw_cholmod(Ac, f)
        times["raw"].append(time.process_time() - t0)
        times["one"].append(run_sweep(scene, path, vals[:1])[0])
        dt, r = run_sweep(scene, path, vals)
        times["all"].append(dt)
        kkt += [row["kkt_worst"] for row in r.rows]
        route = f"{r.rows[-1]['backend']}/{r.rows[-1]['formulation']}"
    med = {k: statistics.median(v) for k, v in times.items()}
    per = (med["all"] - med["one"]) / (values - 1)
    return {"scene": kind, "mesh": n, "path": path, "values": values, "repeats": repeats, "route": route,
            "raw_s": med["raw"], "first_value_s": med["one"], "sweep_s": med["all"], "per_value_s": per,
            "per_value_ratio": per / med["raw"], "first_ratio": med["one"] / med["raw"],
            "kkt_worst": max(kkt), "all_optimal": True}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="64,128")
    ap.add_argument("--scenes", default="grid,bed")
    ap.add_argument("--values", type=int, default=11)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--bed-path", default="foundation.gap.gx")
    ap.add_argument("--out", default=str(HERE / "results" / "sweep-reuse.csv"))
    args = ap.parse_args()
    rows = []
    print("| scene | mesh | path | route | raw s | first value ÷ raw | **per value after the first ÷ raw** "
          "| KKT worst |")
    print("|---|---|---|---|---|---|---|---|")
    for n in (int(x) for x in args.meshes.split(",")):
        for kind in args.scenes.split(","):
            row = row_for(kind, n, args.values, args.repeats, args.bed_path)
            rows.append(row)
            print(f"| {kind} | {n}² | {row['path']} | {row['route']} | {row['raw_s']:.3f} | {row['first_ratio']:.2f} "
                  f"| **{row['per_value_ratio']:.2f}** | {row['kkt_worst']:.1e} |", flush=True)
    with open(args.out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
