"""Many contacts: pdas against the external backends from 9 posts to a
post on every interior node, and on the tensionless bed.

Scenes (:mod:`plateqp.scenes.families`, kN and m): ``grid_rigid(n, k)``, the slab on four walls and a
k × k grid of rigid one-sided posts with mixed gaps, for k = 3, 10, 30, 45, 63 and ``"all"``
(n − 1: every interior node a post), and ``bed(n)``, the free slab on a tensionless Winkler bed
(a one-sided spring at every node). pdas takes its condensed method up to ``max_dense``
contact dofs ("auto": 2000 up to about 71², 3537 at 128², 4000 from about 144²) and its sparse method
above that and on the bed (a floating plate).

Each case runs ``pq.solve(scene, backend=B, formulation="primal", accuracy=tol)`` in a fresh
interpreter (spawn) with a time limit (``--timeout``), after one small warm-up solve there;
the time is the CPU time (``time.process_time``) of the whole call, the median of
``--repeat`` runs (one run when the first takes over 60 s). Reported: iterations, the
factorisations pdas made (``extras["factorisations"]``), its method, the largest KKT residual
of the answer (plateqp's own check, :mod:`plateqp.contact.kkt`), whether it meets the
tolerance asked (``kkt_ok``) and 1e-10, and the status.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_many_contacts.py            # 128², 1e-9 and 1e-6
    python benchmarks/bench_many_contacts.py --quick                           # 64², short
    python benchmarks/bench_many_contacts.py --mesh 128 --ks 63,all --backends pdas,clarabel
    python benchmarks/bench_many_contacts.py --edges one --ks 10,30,45 --backends pdas \
        --pdas-options anchor_start=false --tag one-plain     # a slab free to turn, plain PDAS

Prints a markdown table and writes ``benchmarks/results/many_contacts-<mesh>[-<tag>].csv``
(one row per case).
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
from pathlib import Path

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_contact import run_in_subprocess  # noqa: E402

KKT_KEYS = ("stationarity", "spring", "primal", "dual", "complementarity", "natural")
BACKENDS = ("pdas", "clarabel", "qpsolvers:piqp", "osqp")
FIELDS = ("mesh", "scene", "k", "contacts", "backend", "accuracy", "cpu_s", "runs", "iterations",
          "factorisations", "method", "kkt_max", "kkt_ok", "kkt_1e-10", "status")


EDGES = ("four", "one", "free")


def make_scene(name: str, n: int, k, edges: str = "four"):
    """``bed(n)``, or ``grid_rigid(n, k)`` on its four walls, simply supported on its left edge
    only (``edges="one"``: free to turn about it) or on none (``"free"``: a floating slab on
    the posts alone): K singular in the last two."""
    import plateqp as pq
    from plateqp.scenes.families import bed, grid_rigid

    if name == "bed":
        return bed(n)
    sc = grid_rigid(n, k)
    if edges == "four":
        return sc
    held = {"left": pq.Edge("simple")} if edges == "one" else {}
    return pq.Scene(name=f"{sc.name}-{edges}", plate=sc.plate, mesh=sc.mesh, edges=held, loads=sc.loads,
                    supports=sc.supports)


def _run(args, q):
    """In the child: warm up, then time ``repeat`` solves of one case."""
    name, n, k, backend, acc, repeat, edges, options = args
    try:
        import warnings

        import numpy as np

        import plateqp as pq

        warnings.simplefilter("ignore")  # an inaccurate answer is reported in the table
        pq.solve(make_scene("grid", 8, 3), backend=backend, formulation="primal", accuracy=acc)  # warm-up
        scene = make_scene(name, n, k, edges)
        times = []
        r = None
        for i in range(repeat):
            t0 = time.process_time()
            r = pq.solve(scene, backend=backend, formulation="primal", accuracy=acc, options=options)
            times.append(time.process_time() - t0)
            if times[0] > 60.0:
                break
        kmax = max(float(getattr(r.kkt, key)) for key in KKT_KEYS)
        ex = r.extras or {}
        q.put({"cpu_s": statistics.median(times), "runs": len(times), "iterations": r.iterations,
               "factorisations": ex.get("factorisations", ""), "method": ex.get("method", ""),
               "kkt_max": kmax, "kkt_ok": bool(r.kkt.ok), "kkt_1e-10": bool(kmax <= 1e-10),
               "status": str(getattr(r.status, "name", r.status)), "contacts": int(np.size(r.reactions))})
    except Exception as exn:  # reported in the table, not raised
        q.put({"status": f"error: {type(exn).__name__}: {str(exn)[:120]}"})


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", type=int, default=128)
    ap.add_argument("--ks", default="3,10,30,45,63,all,bed", help="posts per row (or all), and bed")
    ap.add_argument("--backends", default=",".join(BACKENDS))
    ap.add_argument("--accuracies", default="1e-9,1e-6", help="pdas runs at the first only (a direct method)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=400.0)
    ap.add_argument("--quick", action="store_true", help="64², repeat 1, timeout 120 s")
    ap.add_argument("--tag", default="", help="suffix of the CSV name (e.g. baseline)")
    ap.add_argument("--edges", default="four", choices=EDGES,
                    help="the post grids' slab on four walls, on its left edge only, or on none")
    ap.add_argument("--pdas-options", default="", metavar="KEY=VALUE,...",
                    help="options for pdas only, e.g. anchor_start=false (true/false, numbers, words)")
    a = ap.parse_args()
    pdas_options = {}
    for item in filter(None, a.pdas_options.split(",")):
        key, sep, val = item.partition("=")
        if not sep or not key:
            ap.error(f"--pdas-options: {item!r} is not KEY=VALUE")
        low = val.strip().lower()
        if low in ("true", "false"):
            pdas_options[key.strip()] = low == "true"
        else:
            try:
                pdas_options[key.strip()] = float(val) if any(c in val for c in ".eE") else int(val)
            except ValueError:
                pdas_options[key.strip()] = val.strip()
    if a.quick:
        a.mesh, a.repeat, a.timeout = 64, 1, 120.0
    n = a.mesh
    cases = []
    for kk in a.ks.split(","):
        name, k = ("bed", None) if kk == "bed" else ("grid", kk if kk == "all" else int(kk))
        if k != "all" and k is not None and k > n - 1:
            continue
        for acc in a.accuracies.split(","):
            for b in a.backends.split(","):
                if b == "pdas" and acc != a.accuracies.split(",")[0]:
                    continue
                cases.append((name, n, k, b, float(acc)))
    out = HERE / "results" / f"many_contacts-{n}{'-' + a.tag if a.tag else ''}.csv"
    rows = []
    print("| scene | k | contacts | backend | accuracy | CPU s | iterations | factorisations | method | "
          "KKT max | ok | status |\n|---|---|---|---|---|---|---|---|---|---|---|---|", flush=True)
    for name, n_, k, b, acc in cases:
        opts = pdas_options if b == "pdas" else None
        res = run_in_subprocess(_run, (name, n_, k, b, acc, a.repeat, a.edges, opts), a.timeout)
        scene = "bed" if name == "bed" else ("grid_rigid" if a.edges == "four" else f"grid_rigid-{a.edges}")
        row = {"mesh": n_, "scene": scene, "k": "" if k is None else k,
               "backend": b, "accuracy": acc, **res}
        rows.append(row)
        kk = row.get("kkt_max")
        print(f"| {row['scene']} | {row['k']} | {row.get('contacts', '')} | {b} | {acc:g} | "
              f"{row.get('cpu_s', float('nan')):.2f} | {row.get('iterations', '')} | {row.get('factorisations', '')} | "
              f"{row.get('method', '')} | {'' if kk is None else f'{kk:.1e}'} | {row.get('kkt_ok', '')} | "
              f"{row['status']} |", flush=True)
        with open(out, "w", newline="") as fh:  # rewritten after every case: a long run keeps what it has
            w = csv.DictWriter(fh, fieldnames=FIELDS, extrasaction="ignore")
            w.writeheader()
            w.writerows(rows)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
