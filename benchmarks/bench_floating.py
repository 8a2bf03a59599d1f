"""A floating slab on a few posts: pdas on the primal
QP against BPP on the condensed LCP, and what ``backend="auto"`` picks, for single solves.

Scenes: :func:`plateqp.scenes.families.floating` ``(n, k)``, the slab held only by a k × k grid of rigid
one-sided posts (edges and corners included; K singular), k = 3, 5, 9, at n = 32, 64, 128.
Routes, each ``pq.solve(scene, …, accuracy=1e-10)``: ``pdas`` (primal formulation: the anchored
first set, then exact steps), ``bpp`` (condensed formulation: a contacts-last factorisation of
the shifted K, the dense LCP) and ``auto``. They run interleaved in one process (route after
route, ``--repeat`` rounds, after one warm-up solve of each), CPU time (``time.process_time``)
of the whole call, medians, each solve in a child forked from the benchmark's process (the
same heap for every route). Reported: time, status, the answer's largest KKT residual
(:mod:`plateqp.contact.kkt`), the factor pdas's exact steps ran on (``extras["factor"]``:
``"trailing"`` for the anchored factorisation with its trailing block replaced) and the ratio
pdas ÷ BPP.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_floating.py            # 32², 64², 128²
    python benchmarks/bench_floating.py --meshes 128 --ks 9 --repeat 5 --tag s26

Prints a markdown table and writes ``benchmarks/results/floating[-<tag>].csv``.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before NumPy loads
    os.environ.setdefault(_var, "1")

import argparse
import statistics
import sys
import time
import warnings
from pathlib import Path

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_fast import forked, write_csv  # noqa: E402

ROUTES = {"pdas": ("pdas", "primal"), "bpp": ("bpp", "condensed"), "auto": ("auto", None)}
FIELDS = ("mesh", "k", "route", "cpu_s", "runs", "status", "kkt_max", "factor", "pdas_over_bpp")


def solve(scene, route: str):
    import plateqp as pq

    backend, formulation = ROUTES[route]
    kw = {"formulation": formulation} if formulation else {}
    t0 = time.process_time()
    res = pq.solve(scene, backend=backend, accuracy=1e-10, **kw)
    return time.process_time() - t0, res


def timed(scene, route: str) -> tuple:
    """:func:`solve` in a child forked from this process (bench_fast.forked: the same heap for
    every route): (CPU s, status, worst KKT residual, the factor pdas ran on)."""
    def run():
        dt, res = solve(scene, route)
        return dt, res.status.value, res.kkt.worst, res.extras.get("factor", "")
    return forked(run)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--meshes", default="32,64,128")
    ap.add_argument("--ks", default="3,5,9")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tag", default="", help="suffix of the CSV name")
    args = ap.parse_args()
    if args.repeat < 1:
        ap.error("--repeat must be at least 1")
    try:
        meshes = [int(v) for v in args.meshes.split(",")]
        ks = [int(v) for v in args.ks.split(",")]
    except ValueError:
        ap.error("--meshes and --ks take comma-separated integers")
    if min(meshes) < 4 or min(ks) < 2:
        ap.error("meshes of at least 4 and at least 2 posts per row")

    import plateqp as pq
    from plateqp.scenes.families import floating

    warnings.simplefilter("ignore", pq.PlateQPWarning)
    rows = []
    print("| mesh | k × k | route | CPU s | status | KKT max | factor | pdas ÷ BPP |")
    print("|---|---|---|---|---|---|---|---|")
    for n in meshes:
        for k in ks:
            scene = floating(n, k)
            for route in ROUTES:  # warm-up: imports and first-call costs paid
                solve(scene, route)
            times: dict[str, list[float]] = {r: [] for r in ROUTES}
            last = {}
            for _ in range(args.repeat):
                for route in ROUTES:
                    dt, *last[route] = timed(scene, route)
                    times[route].append(dt)
            med = {r: statistics.median(t) for r, t in times.items()}
            for route in ROUTES:
                status, worst, factor = last[route]
                row = {"mesh": n, "k": k, "route": route, "cpu_s": med[route], "runs": args.repeat,
                       "status": status, "kkt_max": worst, "factor": factor,
                       "pdas_over_bpp": med["pdas"] / med["bpp"] if route == "pdas" else ""}
                rows.append(row)
                ratio = f"{row['pdas_over_bpp']:.2f}" if route == "pdas" else ""
                print(f"| {n}² | {k} × {k} | {route} | {med[route]:.3f} | {row['status']} | {row['kkt_max']:.1e} "
                      f"| {row['factor']} | {ratio} |", flush=True)
    out = HERE / "results" / f"floating{'-' + args.tag if args.tag else ''}.csv"
    write_csv(rows, out)  # every row has FIELDS, in that order
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
