"""A coarse mesh's contact set as pdas's warm start, on the tensionless bed (issue 11: an
experiment measured here, not what ``pq.solve`` does by default).

The bed of ``bench_fast.py`` (a free slab on a tensionless Winkler bed falling away towards one
corner, about half lifting off) at ``n × n`` cells is solved three ways, each in a child forked
from this process (``bench_fast.forked``: the same heap for every route), interleaved,
``--repeat`` rounds, CPU time (``time.process_time``), medians:

* **cold**: ``pq.solve(bed(n), accuracy=1e-10)`` (pdas's sparse method: a factorisation of the
  two-sided matrix, a Newton–PCG first phase, a second factorisation for the set it settles on);
* **predicted**: the same bed at ``n / d`` cells solved first (``accuracy="default"``: only its
  contact set is used), its deflection read at the fine mesh's contact points, every spring it
  compresses taken as active, and that set handed to the fine solve as pdas's warm start
  (``options={"active": ...}``: the exact steps start from it at once); the time is the whole of
  it, the coarse solve included;
* **raw**: one CHOLMOD analysis, factorisation and solve of the plate with every spring bonded
  (``bench_fast.raw_cholmod``, the goal table's floor).

Reported: the springs the prediction got wrong against the cold answer's contact set, both
routes' factorisations and solves, their statuses and worst KKT residuals, the largest
difference of their reactions (relative to the largest reaction: both are exact, so this is
rounding), and the times.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_predict.py                 # 128², 256²; d = 4, 2
    python benchmarks/bench_predict.py --meshes 128 --coarse 4 --repeat 5

Prints a markdown table and writes ``benchmarks/results/predict[-<tag>].csv``.
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

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_fast import bed_scene, forked, plate_matrix, raw_cholmod, to_cvxopt, write_csv  # noqa: E402

ACCURACY = 1e-10


def _kkt(res) -> float:
    return float(res.kkt.worst)


def cold(n: int) -> tuple:
    import plateqp as pq

    t0 = time.process_time()
    res = pq.solve(bed_scene(n), accuracy=ACCURACY, backend="pdas")
    dt = time.process_time() - t0
    return (dt, res.status.value, _kkt(res), res.extras["factorisations"], res.extras["solves"],
            res.extras["active"], np.asarray(res.reactions))


def predicted(n: int, d: int) -> tuple:
    import plateqp as pq
    from plateqp.assembly import build_model

    t0 = time.process_time()
    coarse = pq.solve(bed_scene(n // d), backend="pdas")
    scene = bed_scene(n)
    model = build_model(scene)
    c = model.contacts
    active = np.asarray(coarse.deflection(c.xy[:, 0], c.xy[:, 1])) - c.g0 > 0
    t1 = time.process_time()
    res = pq.solve(scene, accuracy=ACCURACY, backend="pdas", model=model, options={"active": active})
    dt = time.process_time() - t0
    return (dt, t1 - t0, res.status.value, _kkt(res), res.extras["factorisations"], res.extras["solves"],
            active, np.asarray(res.reactions))


def raw(n: int) -> float:
    from plateqp.assembly import build_model

    K, f = plate_matrix("bed", build_model(bed_scene(n)))
    A = to_cvxopt(K)
    t0 = time.process_time()
    raw_cholmod(A, f)
    return time.process_time() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--meshes", default="128,256")
    ap.add_argument("--coarse", default="4,2", help="divisors d of the mesh for the coarse solve")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tag", default="", help="suffix of the CSV name")
    args = ap.parse_args()
    try:
        meshes = [int(v) for v in args.meshes.split(",")]
        divisors = [int(v) for v in args.coarse.split(",")]
    except ValueError:
        ap.error("--meshes and --coarse take comma-separated integers")
    if args.repeat < 1 or min(divisors) < 2 or any(n // d < 4 for n in meshes for d in divisors):
        ap.error("--repeat ≥ 1, divisors ≥ 2, and every coarse mesh at least 4 cells a side")
    warnings.simplefilter("ignore")
    rows = []
    print("| mesh | coarse | springs | wrong in the prediction | raw s | cold s (fact., solves) | coarse s | "
          "predicted s (fact., solves) | predicted ÷ cold | cold ÷ raw | predicted ÷ raw | statuses | "
          "KKT worst (cold / predicted) | reaction difference |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    cold(16), predicted(16, 2), raw(16)  # imports and first-call costs paid before any clock
    for n in meshes:
        for d in divisors:
            times = {"raw": [], "cold": [], "predicted": [], "coarse": []}
            for r in range(args.repeat):
                for route in (("raw", "cold", "predicted"), ("cold", "predicted", "raw"),
                              ("predicted", "raw", "cold"))[r % 3]:
                    if route == "raw":
                        times["raw"].append(forked(lambda: raw(n)))
                    elif route == "cold":
                        out_c = forked(lambda: cold(n))
                        times["cold"].append(out_c[0])
                    else:
                        out_p = forked(lambda: predicted(n, d))
                        times["predicted"].append(out_p[0])
                        times["coarse"].append(out_p[1])
            med = {k: statistics.median(v) for k, v in times.items()}
            _, st_c, kkt_c, fac_c, sol_c, act_c, R_c = out_c
            _, _, st_p, kkt_p, fac_p, sol_p, act_p, R_p = out_p
            wrong = int(np.sum(act_c != act_p))
            diff = float(np.abs(R_c - R_p).max() / max(np.abs(R_c).max(), 1e-300))
            row = {"mesh": n, "coarse": n // d, "springs": act_c.size, "wrong": wrong, "raw_s": med["raw"],
                   "cold_s": med["cold"], "coarse_s": med["coarse"], "predicted_s": med["predicted"],
                   "predicted_over_cold": med["predicted"] / med["cold"], "cold_over_raw": med["cold"] / med["raw"],
                   "predicted_over_raw": med["predicted"] / med["raw"], "cold_factorisations": fac_c,
                   "cold_solves": sol_c, "predicted_factorisations": fac_p, "predicted_solves": sol_p,
                   "cold_status": st_c, "predicted_status": st_p, "cold_kkt": kkt_c, "predicted_kkt": kkt_p,
                   "reaction_difference": diff, "runs": args.repeat}
            rows.append(row)
            print(f"| {n}² | {n // d}² | {act_c.size} | {wrong} | {med['raw']:.3f} | {med['cold']:.3f} ({fac_c}, {sol_c}) | "
                  f"{med['coarse']:.3f} | {med['predicted']:.3f} ({fac_p}, {sol_p}) | "
                  f"{row['predicted_over_cold']:.2f} | {row['cold_over_raw']:.2f} | {row['predicted_over_raw']:.2f} | "
                  f"{st_c} / {st_p} | {kkt_c:.1e} / {kkt_p:.1e} | {diff:.1e} |", flush=True)
    out = HERE / "results" / f"predict{'-' + args.tag if args.tag else ''}.csv"
    write_csv(rows, out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
