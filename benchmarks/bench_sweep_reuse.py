"""A sweep that keeps the plate's factorisation: CPU time per value after the first ÷ raw.

"raw" is the floor of benchmarks/bench_fast.py: one CHOLMOD symbolic analysis + numeric
factorisation + solve of the plate's matrix, straight through cvxopt (grid: K; bed: K with
every bed spring bonded). Scenes are bench_fast's: ``grid`` (a slab on four walls and 30 × 30
rigid posts) and ``bed`` (a free plate on a tensionless bed). Three kinds of sweep each
(``--kinds``): a gap (grid: post 1's ``supports.1.gap``; bed: the gap field's slope
``foundation.gap.gx``), a load (grid: the pressure ``loads.0.q``; bed: the column's
``loads.1.P``) and a spring stiffness (grid: every post made elastic, ``supports.*.stiffness``;
bed: its modulus ``foundation.k``).

Per mesh and scene, interleaved, ``--repeats`` times (medians reported): raw; a serial sweep
of one value; a serial sweep of ``--values`` values (reuse on, warm starts on: the defaults).
Per value after the first = (sweep of V values − sweep of one) / (V − 1). Every row of every
sweep must be OPTIMAL (its KKT check passed at ``ACCURACY``); the rows carry the route and
the worst KKT residual over the values (the factorisations per value are counted by the tests
tests/studies/test_sweep_halves.py and test_sweep_bed_springs.py, not
here).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_sweep_reuse.py [--meshes 64,128] [--repeats 5]

Writes benchmarks/results/sweep-reuse.csv and prints a markdown table; ``goal_met`` says whether
the per-value ratio is at most :data:`GOAL` (the goal is stated for 128²).
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
from dataclasses import fields
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_fast import ACCURACY, accuracy_above, make_scene, plate_matrix, raw_cholmod, to_cvxopt  # noqa: E402

from plateqp.model.assembly import build_model  # noqa: E402
from plateqp.results import KKTReport  # noqa: E402
from plateqp.studies.sweep import sweep  # noqa: E402


#: per value after the first ÷ raw asked for at 128²
GOAL = 0.3

KINDS = ("gap", "load", "stiffness")


def values_for(scene_kind: str, scene, count: int, kind: str):
    """The PATH and its values of a sweep of ``kind`` (gap, load, stiffness) on the scene."""
    if scene_kind == "grid":
        if kind == "gap":
            g0 = scene.supports[0].gap
            return "supports.1.gap", list(np.linspace(g0 - 0.002, g0 + 0.002, count))
        if kind == "load":
            return "loads.0.q", list(scene.loads[0].q * np.linspace(0.5, 1.5, count))
        return "supports.*.stiffness", list(np.geomspace(1.0e6, 1.0e8, count))
    if kind == "gap":
        return "foundation.gap.gx", list(np.linspace(0.003, 0.005, count))
    if kind == "load":
        return "loads.1.P", list(np.linspace(100.0, 300.0, count))
    return "foundation.k", list(np.geomspace(1.0e4, 4.0e4, count))


def run_sweep(scene, path, vals, accuracy=ACCURACY, check=True):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.process_time()
        r = sweep(scene, path, vals, accuracy=accuracy, executor="serial", progress=False, refine_breakpoints=False)
        dt = time.process_time() - t0
    bad = [row for row in r.rows if row["status"] != "optimal"]
    if bad and check:
        raise SystemExit(f"{scene.name} {path}: {len(bad)} rows not OPTIMAL at {accuracy:g}: {bad[0]['status']} "
                         f"{bad[0]['error']}")
    return dt, r


def reachable(scene, path, vals) -> float:
    """The accuracy asked of the timed sweeps: 1e-10, or where a value's answer is not OPTIMAL
    there only because 1e-10 lies below its rounding floor (the bed from 256²), the step above
    three times the largest floor of the sweep
    (:func:`bench_fast.accuracy_above`). Any other failure stops the run."""
    _, r = run_sweep(scene, path, vals, check=False)
    floors = []
    for row in r.rows:
        if row["status"] == "optimal":
            continue
        k = row.get("kkt")
        rep = KKTReport(**{f.name: k[f.name] for f in fields(KKTReport)}) if k else None
        if rep is None or not rep.at_floor:
            raise SystemExit(f"{scene.name} {path}: a value not OPTIMAL above its floor: {row['status']} {row['error']}")
        floors.append(rep.floor)
    return accuracy_above(max(floors)) if floors else ACCURACY


def row_for(kind: str, n: int, values: int, repeats: int, sweep_kind: str) -> dict:
    scene = make_scene(kind, n)
    A, f = plate_matrix(kind, build_model(scene))
    Ac = to_cvxopt(A)
    path, vals = values_for(kind, scene, values, sweep_kind)
    acc = reachable(scene, path, vals)  # also pays imports and first-use costs out of the clock
    times = {"raw": [], "one": [], "all": []}
    kkt, route = [], None
    for _ in range(repeats):
        t0 = time.process_time()
        raw_cholmod(Ac, f)
        times["raw"].append(time.process_time() - t0)
        times["one"].append(run_sweep(scene, path, vals[:1], acc)[0])
        dt, r = run_sweep(scene, path, vals, acc)
        times["all"].append(dt)
        kkt += [row["kkt_worst"] for row in r.rows]
        route = f"{r.rows[-1]['backend']}/{r.rows[-1]['formulation']}"
    med = {k: statistics.median(v) for k, v in times.items()}
    per = (med["all"] - med["one"]) / (values - 1)
    return {"scene": kind, "mesh": n, "sweep": sweep_kind, "path": path, "values": values, "repeats": repeats,
            "route": route, "accuracy": acc, "raw_s": med["raw"], "first_value_s": med["one"], "sweep_s": med["all"],
            "per_value_s": per, "per_value_ratio": per / med["raw"], "first_ratio": med["one"] / med["raw"],
            "goal_met": per / med["raw"] <= GOAL, "kkt_worst": max(kkt), "all_optimal": True}


def parse_args(doc: str, kinds: tuple, repeats: int, out: str):
    """The arguments of a sweep benchmark (this one, bench_exact_sweep): meshes, scenes, values,
    repeats, the kinds of sweep among ``kinds``, the CSV ``out``; (args, the kinds asked)."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--meshes", default="64,128")
    ap.add_argument("--scenes", default="grid,bed")
    ap.add_argument("--values", type=int, default=11)
    ap.add_argument("--repeats", type=int, default=repeats)
    ap.add_argument("--kinds", default=",".join(kinds), help=f"sweeps to time: {', '.join(kinds)}")
    ap.add_argument("--out", default=str(HERE / "results" / out))
    args = ap.parse_args()
    asked = args.kinds.split(",")
    if not set(asked) <= set(kinds):
        raise SystemExit(f"--kinds: some of {', '.join(kinds)} (got {args.kinds})")
    if args.values < 2 or args.repeats < 1:
        raise SystemExit("--values must be at least 2 and --repeats at least 1")
    return args, asked


def write_rows(rows: list, out: str) -> None:
    """The rows as CSV at ``out`` (its folder made)."""
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    with open(out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {out}")


def run_table(args, kinds: list, row_of, header: list, line) -> None:
    """Every mesh × scene × kind of sweep asked: ``row_of(kind, n, sweep_kind)``, each printed as
    a Markdown row (``line(row)``, under ``header``) as it comes, then all written to ``args.out``."""
    rows = []
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for n in (int(x) for x in args.meshes.split(",")):
        for kind in args.scenes.split(","):
            for sweep_kind in kinds:
                row = row_of(kind, n, sweep_kind)
                rows.append(row)
                print(f"| {kind} | {n}² | " + " | ".join(line(row)) + " |", flush=True)
    write_rows(rows, args.out)


def main():
    args, kinds = parse_args(__doc__, KINDS, 5, "sweep-reuse.csv")
    run_table(args, kinds, lambda kind, n, sk: row_for(kind, n, args.values, args.repeats, sk),
              ["scene", "mesh", "path", "route", "raw s", "first value ÷ raw", "**per value after the first ÷ raw**",
               f"≤ {GOAL}", "KKT worst"],
              lambda r: [r["path"], r["route"], f"{r['raw_s']:.3f}", f"{r['first_ratio']:.2f}",
                         f"**{r['per_value_ratio']:.2f}**", str(r["goal_met"]), f"{r['kkt_worst']:.1e}"])


if __name__ == "__main__":
    main()
