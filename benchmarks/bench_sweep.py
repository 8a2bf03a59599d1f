"""Sweeps: re-use of the model and warm starts.

Scene: the paper's fig. 5 set-up at scale, a 32 × 32 ACM plate (400 × 400, h = 20, kgf and cm)
on 8 × 8 = 64 elastic supports (three heaved by 0.02), a point load and self-weight; the
support stiffness is swept over ``--values`` (default 50) values from 1e6 down to 1.

Each backend runs in three modes, in one process, interleaved (every mode once per repeat,
``--repeats`` repeats, medians reported):

* ``cold``  — ``reuse=False``: every value rebuilt (assembly, condensation) and solved from
  scratch, no warm start;
* ``reuse`` — ``reuse=True, warm_start=False``: the model built once, the condensation cached,
  every solve started cold;
* ``warm``  — ``reuse=True, warm_start=True``: as ``reuse``, each solve started from the final
  state of the one before (bpp and pdas; Lemke takes no warm start, so it runs cold and reuse).

Backends: ``bpp`` on the condensed LCP, ``pdas`` on the sparse primal QP, ``lemke`` on the
condensed LCP (the reference: no warm start possible). Serial executor, breakpoints not
refined for the main table; ``--refine`` adds a table with every change of the contact set
bisected to 1e-3 (``--refine-repeats`` repeats). Every run's reactions and contact sets are
compared with Lemke's cold sweep.

Per row the sweep records its time parts (``row["times"]``: scene copy and validation, model
adapted or built, formulation, backend solve, recovery and KKT report, row post-processing)
and the backend's iterations (bpp: principal pivoting splits; pdas: active sets solved;
Lemke: pivots).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_sweep.py [--repeats 3] [--refine] [--parallel]

Prints markdown tables; writes benchmarks/results/sweep.csv (one row per run, long format)
and benchmarks/results/sweep-steps.csv (iterations per sweep step, cold vs warm).
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before NumPy loads
    os.environ.setdefault(_var, "1")

import argparse
import csv
import platform
import statistics
import time
from pathlib import Path

import numpy as np

import plateqp as pq
from plateqp.studies import WARM_START_BACKENDS, sweep

HERE = Path(__file__).parent
PATH = "supports.*.stiffness"
a = 400.0
sup = [pq.Support(25 + 50 * i, 25 + 50 * j, gap=(-0.02 if (i, j) in ((0, 0), (1, 0), (0, 1)) else 0.0))
       for j in range(8) for i in range(8)]
sc = pq.Scene(name="fig5-64", plate=pq.Plate(a=a, b=a, h=20.0, E=2e5, nu=0.2), mesh=pq.MeshSpec(32, 32),
              loads=[pq.PointLoad(P=20000.0, x=150.0, y=250.0), pq.UniformLoad(q=0.05)], supports=sup)

#: backend -> formulation
BACKENDS = {"bpp": "condensed", "pdas": "primal", "lemke": "condensed"}
#: mode -> sweep keywords
MODES = {"cold": {"reuse": False}, "reuse": {"reuse": True, "warm_start": False},
         "warm": {"reuse": True, "warm_start": True}}
#: the row time parts, in the order of the data flow ("build" in a row includes "scene")
PARTS = ("scene", "build", "formulate", "solve", "recover", "post", "other")


def modes_for(backend: str) -> tuple[str, ...]:
    return ("cold", "reuse", "warm") if backend in WARM_START_BACKENDS else ("cold", "reuse")


def run(backend: str, mode: str, values: list, refine: bool) -> dict:
    """One timed sweep; its total, time parts (summed over rows), iterations and answer."""
    t = time.perf_counter()
    r = sweep(sc, PATH, values, backend=backend, formulation=BACKENDS[backend], executor="serial",
              progress=False, refine_breakpoints=refine, **MODES[mode])
    total = time.perf_counter() - t
    bad = [row for row in r.rows if row["error"] or row["status"] != "optimal"]
    if bad:
        raise SystemExit(f"{backend}/{mode}: {len(bad)} rows failed, first: {bad[0]['status']} {bad[0]['error']}")
    parts = dict.fromkeys(PARTS, 0.0)
    for row in r.rows:
        tm = row["times"]
        parts["scene"] += tm["scene"]
        parts["build"] += tm["build"] - tm["scene"]
        for k in ("formulate", "solve", "recover", "post"):
            parts[k] += tm[k]
        parts["other"] += tm["total"] - tm["build"] - tm["formulate"] - tm["solve"] - tm["recover"] - tm["post"]
    return {"backend": backend, "formulation": BACKENDS[backend], "mode": mode, "refine": refine,
            "total": total, "values_time": r.times["values"], "breakpoints_time": r.times["breakpoints"],
            "bisection_solves": r.times["bisection_solves"], "breakpoints": len(r.breakpoints),
            "bisection_iterations": r.times["bisection_iterations"],
            "iterations": [row["iterations"] for row in r.rows], "parts": parts,
            "reactions": r.reactions, "active": r.active, "bps": r.breakpoints}


def interleaved(backends, values, repeats: int, refine: bool) -> list[dict]:
    """Every (backend, mode) once per repeat, the order rotated from one repeat to the next."""
    cases = [(b, m) for b in backends for m in modes_for(b)]
    out = []
    from plateqp.progress import track  # a bar on a terminal only
    for k in track(range(repeats), "repeats"):
        for b, m in cases[k % len(cases):] + cases[: k % len(cases)]:
            res = run(b, m, values, refine)
            res["repeat"] = k
            out.append(res)
            print(f"  repeat {k}: {b:5s} {m:5s} {res['total']:7.2f} s", flush=True)
    return out


def check(runs: list[dict], ref: dict) -> None:
    """Every run's reactions and contact sets against the reference (Lemke, cold)."""
    scale = np.abs(ref["reactions"]).max()
    for r in runs:
        r["dR"] = float(np.abs(r["reactions"] - ref["reactions"]).max() / scale)
        r["same_sets"] = r["active"] == ref["active"]
        if r["refine"]:
            r["same_sets"] = r["same_sets"] and [(b["before"], b["after"]) for b in r["bps"]] == \
                [(b["before"], b["after"]) for b in ref["bps"]]


def med(runs, backend, mode, key):
    v = [r[key] if key in r else r["parts"][key] for r in runs if r["backend"] == backend and r["mode"] == mode]
    return statistics.median(v) if v else float("nan")


def table(runs: list[dict], backends, title: str) -> str:
    lines = [title, "",
             "| backend / formulation | mode | total s | cold / mode | iterations (sum) | "
             + " | ".join(PARTS) + " | max ΔR / max R | same contact sets |",
             "|---|---|---|---|---|" + "---|" * len(PARTS) + "---|---|"]
    for b in backends:
        cold = med(runs, b, "cold", "total")
        for m in modes_for(b):
            these = [r for r in runs if r["backend"] == b and r["mode"] == m]
            tot = med(runs, b, m, "total")
            its = sum(i or 0 for i in these[0]["iterations"])
            parts = " | ".join(f"{med(runs, b, m, p):.2f}" for p in PARTS)
            lines.append(f"| {b} / {BACKENDS[b]} | {m} | {tot:.2f} | {cold / tot:.1f}× | {its} | {parts} | "
                         f"{max(r['dR'] for r in these):.0e} | {'yes' if all(r['same_sets'] for r in these) else 'NO'} |")
    return "\n".join(lines)


def steps_table(runs: list[dict], values: list) -> tuple[str, list[dict]]:
    """Iterations per sweep step, cold vs warm, for the warm-startable backends."""
    ref = next(r for r in runs if r["backend"] == "lemke" and r["mode"] == "cold") if any(
        r["backend"] == "lemke" for r in runs) else runs[0]
    nset = [sum(a) for a in ref["active"]]
    changed = [False] + [ref["active"][k] != ref["active"][k - 1] for k in range(1, len(values))]
    cols = [(b, m) for b in BACKENDS for m in ("cold", "warm")
            if any(r["backend"] == b and r["mode"] == m for r in runs)]
    its = {c: next(r for r in runs if (r["backend"], r["mode"]) == c)["iterations"] for c in cols}
    csv_rows = []
    for k, v in enumerate(values):
        for (b, m) in cols:
            csv_rows.append({"backend": b, "formulation": BACKENDS[b], "mode": m, "step": k, "value": v,
                             "in_contact": nset[k], "set_changed": changed[k], "iterations": its[(b, m)][k]})
    lines = ["Iterations per sweep step (deterministic; step 0 starts cold in every mode):", "",
             "| steps | " + " | ".join(f"{b} {m}" for b, m in cols) + " |",
             "|---|" + "---|" * len(cols)]

    def summary(sel, label):
        cells = []
        for c in cols:
            x = [its[c][k] for k in sel]
            cells.append(f"{sum(x)} (mean {np.mean(x):.2f}, max {max(x)})" if x else "-")
        lines.append(f"| {label} | " + " | ".join(cells) + " |")

    rest = list(range(1, len(values)))
    summary([0], "step 0")
    summary([k for k in rest if changed[k]], f"contact set changed ({sum(changed)} steps)")
    summary([k for k in rest if not changed[k]], f"contact set unchanged ({len(rest) - sum(changed)} steps)")
    summary(list(range(len(values))), f"all {len(values)} steps")
    return "\n".join(lines), csv_rows


def write_csv(path: Path, rows: list[dict]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--values", type=int, default=50)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--backends", default=",".join(BACKENDS))
    ap.add_argument("--refine", action="store_true", help="also run with every breakpoint bisected")
    ap.add_argument("--refine-repeats", type=int, default=1)
    ap.add_argument("--parallel", action="store_true", help="also bpp warm with two local processes")
    ap.add_argument("--out", default=str(HERE / "results" / "sweep.csv"))
    args = ap.parse_args(argv)
    backends = [b for b in args.backends.split(",") if b]
    values = list(np.geomspace(1e6, 1.0, args.values))
    print(f"# sweep of {PATH}: {len(values)} values, 32x32 ACM, 64 supports; {platform.node()}, "
          f"{os.cpu_count()} cores, OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}", flush=True)
    pq.solve(sc)  # warm-up: first-call imports
    for b in backends:
        sweep(sc, PATH, values[:3], backend=b, formulation=BACKENDS[b], executor="serial", progress=False,
              refine_breakpoints=False)

    runs = interleaved(backends, values, args.repeats, refine=False)
    ref = next((r for r in runs if r["backend"] == "lemke" and r["mode"] == "cold"), None)
    ref = ref or run("lemke", "cold", values, False)
    check(runs, ref)
    print()
    print(table(runs, backends, f"Serial, breakpoints not refined; medians of {args.repeats} interleaved "
                                "repeats; time parts summed over the rows (s)"))
    print()
    text, step_rows = steps_table(runs, values)
    print(text)
    print()
    all_runs = runs
    if args.refine:
        rruns = interleaved(backends, values, args.refine_repeats, refine=True)
        rref = next((r for r in rruns if r["backend"] == "lemke" and r["mode"] == "cold"), None)
        rref = rref or run("lemke", "cold", values, True)
        check(rruns, rref)
        lines = [f"With every change bisected to 1e-3 (medians of {args.refine_repeats}):", "",
                 ("| backend | mode | total s | cold / mode | values s | breakpoints s | bisection solves |"
                  " their iterations | breakpoints | same as Lemke |"), "|---|---|---|---|---|---|---|---|---|---|"]
        for b in backends:
            cold = med(rruns, b, "cold", "total")
            for m in modes_for(b):
                these = [r for r in rruns if r["backend"] == b and r["mode"] == m]
                lines.append(f"| {b} | {m} | {med(rruns, b, m, 'total'):.2f} | {cold / med(rruns, b, m, 'total'):.1f}× | "
                             f"{med(rruns, b, m, 'values_time'):.2f} | {med(rruns, b, m, 'breakpoints_time'):.2f} | "
                             f"{these[0]['bisection_solves']} | {these[0]['bisection_iterations']} | "
                             f"{these[0]['breakpoints']} | "
                             f"{'yes' if all(r['same_sets'] for r in these) else 'NO'} |")
        print("\n".join(lines))
        print()
        all_runs = runs + rruns
    if args.parallel:
        t = time.perf_counter()
        r = sweep(sc, PATH, values, backend="bpp", formulation="condensed", progress=False, refine_breakpoints=False)
        print(f"bpp warm, 2 local processes: {time.perf_counter() - t:.2f} s ({r.times['executor']})")

    out = Path(args.out)
    write_csv(out, [{"backend": r["backend"], "formulation": r["formulation"], "mode": r["mode"],
                     "refine": r["refine"], "repeat": r["repeat"], "values": len(values),
                     "total_s": round(r["total"], 4), "values_s": round(r["values_time"], 4),
                     "breakpoints_s": round(r["breakpoints_time"], 4), "bisection_solves": r["bisection_solves"],
                     "bisection_iterations": r["bisection_iterations"],
                     "breakpoints": r["breakpoints"], "iterations": sum(i or 0 for i in r["iterations"]),
                     **{f"{p}_s": round(r["parts"][p], 4) for p in PARTS},
                     "max_dR_rel": f"{r['dR']:.1e}", "same_sets": r["same_sets"]} for r in all_runs])
    write_csv(out.with_name(out.stem + "-steps.csv"), step_rows)
    print(f"wrote {out} and {out.with_name(out.stem + '-steps.csv')}")


if __name__ == "__main__":
    main()
