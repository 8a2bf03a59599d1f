"""A coarse mesh's contact set as the first set of the fine solve: the built-in
prediction of ``pq.solve`` (``plateqp.contact.predict``; option ``predict``) against a cold start.

Each scene at ``n × n`` cells is solved three ways, each in a child forked from this process
(``bench_fast.forked``: the same heap for every route), interleaved, ``--repeat`` rounds, CPU
time (``time.process_time``), medians:

* **cold**: ``pq.solve(scene, accuracy=1e-10, backend="pdas", options={"predict": False})``
  (pdas's sparse method on soft rows: a factorisation of the two-sided matrix, a Newton–PCG
  first phase, a second factorisation for the set it settles on);
* **predicted**: ``pq.solve(scene, accuracy=1e-10, backend="pdas", options={"predict": True})``:
  the scene solved first on a mesh of ``n / d`` cells a side (``predict.DIVISOR = d``, set in the
  child; the library's is 4), its deflection read at the fine mesh's contact points, the
  springs it compresses the first set (the Newton phase's factor); the whole call, the coarse
  solve included (``times["predict"]`` alone in the "coarse s" column);
* **raw**: one CHOLMOD analysis, factorisation and solve of the plate with every spring bonded
  (``bench_fast.raw_cholmod``, the goal table's floor).

Scenes (``--scenes``): ``bed``, the goal table's bed (``bench_fast.bed_scene``: a free slab on
a bed falling away towards one corner); ``bump``, that bed with five narrow heaves (radius
3 % of the side, 50 mm: the coarse mesh sees neither their shape nor the slab they lift
around them, so its set is wrong there); ``piles``, ``families.grid_elastic(n, 30)`` (900
soft piles on a walled slab) over a bed settled 1 mm.

Reported: the rows the prediction got wrong against the cold answer's contact set, both
routes' factorisations and solves, their statuses and worst KKT residuals, the largest
difference of their reactions (relative to the largest reaction: both are exact, so this is
rounding), and the times.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_predict.py                 # 64², 128², 256²; d = 4
    python benchmarks/bench_predict.py --meshes 128 --coarse 4,2 --scenes bed,bump --repeat 5

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


def bump_scene(n: int):
    """bed_scene(n) with five narrow heaves (radius 0.03, 50 mm high) where its slab lifts off or
    barely touches, each centred between the nodes of any mesh of 32 cells a side or fewer: 100
    of 4225 springs predicted wrong at 64² (measured), the coarse mesh sees neither the heaves'
    shape nor the slab they lift around them."""
    import plateqp as pq

    sc = bed_scene(n)
    base = pq.Foundation(sc.foundation.k, gap=dict(sc.foundation.gap))
    centres = np.array([(0.3, 0.3), (0.8, 0.2), (0.2, 0.8), (0.7, 0.7), (0.45, 0.85)]) + 0.5 / 32

    def bumped(x, y):
        g = base.gap_at(x, y)
        for cx, cy in centres:
            r2 = ((x - cx) ** 2 + (y - cy) ** 2) / 0.03**2
            g = g - 0.05 * np.where(r2 < 1.0, (1.0 - r2) ** 2, 0.0)
        return g

    sc.foundation = pq.Foundation(sc.foundation.k, gap=bumped)
    sc.name = f"bump{n}"
    sc.validate()
    return sc


def piles_scene(n: int):
    import plateqp as pq
    from plateqp.scenes import families as F
    sc = F.grid_elastic(n, min(30, n - 1))  # (the warm-up at 16²: 15 × 15)
    sc.foundation = pq.Foundation(k=F.BED_MODULUS, gap=0.001)
    sc.validate()
    return sc


SCENES = {"bed": bed_scene, "bump": bump_scene, "piles": piles_scene}


def cold(kind: str, n: int) -> tuple:
    import plateqp as pq

    scene = SCENES[kind](n)
    t0 = time.process_time()
    res = pq.solve(scene, accuracy=ACCURACY, backend="pdas", options={"predict": False})
    dt = time.process_time() - t0
    return (dt, res.status.value, _kkt(res), res.extras["factorisations"], res.extras["solves"],
            res.extras["active"], np.asarray(res.reactions))


def predicted(kind: str, n: int, d: int) -> tuple:
    import plateqp as pq
    from plateqp.model.assembly import build_model
    from plateqp.contact import predict

    predict.DIVISOR = d
    scene = SCENES[kind](n)
    t0 = time.process_time()
    res = pq.solve(scene, accuracy=ACCURACY, backend="pdas", options={"predict": True})
    dt = time.process_time() - t0
    if "rows" not in res.extras["predicted"]:
        raise RuntimeError(f"no prediction: {res.extras['predicted']}")
    A, _ = predict.predicted_set(build_model(scene))  # the set it started from, off the clock
    return (dt, res.times["predict"], res.status.value, _kkt(res), res.extras["factorisations"],
            res.extras["solves"], A, np.asarray(res.reactions))


def raw(kind: str, n: int) -> float:
    from plateqp.model.assembly import build_model
    K, f = plate_matrix("bed", build_model(SCENES[kind](n)))  # every (soft) row bonded
    A = to_cvxopt(K)
    t0 = time.process_time()
    raw_cholmod(A, f)
    return time.process_time() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--meshes", default="64,128,256")
    ap.add_argument("--coarse", default="4", help="divisors d of the mesh for the coarse solve")
    ap.add_argument("--scenes", default="bed,bump,piles", help=f"some of {','.join(SCENES)}")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tag", default="", help="suffix of the CSV name")
    args = ap.parse_args()
    try:
        meshes = [int(v) for v in args.meshes.split(",")]
        divisors = [int(v) for v in args.coarse.split(",")]
    except ValueError:
        ap.error("--meshes and --coarse take comma-separated integers")
    kinds = args.scenes.split(",")
    if any(k not in SCENES for k in kinds):
        ap.error(f"--scenes takes some of {','.join(SCENES)}")
    if args.repeat < 1 or min(divisors) < 2 or any(n // d < 4 for n in meshes for d in divisors):
        ap.error("--repeat ≥ 1, divisors ≥ 2, and every coarse mesh at least 4 cells a side")
    warnings.simplefilter("ignore")
    rows = []
    print("| scene | mesh | coarse | rows | wrong in the prediction | raw s | cold s (fact., solves) | coarse s | "
          "predicted s (fact., solves) | predicted ÷ cold | cold ÷ raw | predicted ÷ raw | statuses | "
          "KKT worst (cold / predicted) | reaction difference |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for kind in kinds:  # imports and first-call costs paid before any clock
        cold(kind, 16), predicted(kind, 16, 2), raw(kind, 16)
    for kind in kinds:
        for n in meshes:
            for d in divisors:
                times = {"raw": [], "cold": [], "predicted": [], "coarse": []}
                for r in range(args.repeat):
                    for route in (("raw", "cold", "predicted"), ("cold", "predicted", "raw"),
                                  ("predicted", "raw", "cold"))[r % 3]:
                        if route == "raw":
                            times["raw"].append(forked(lambda: raw(kind, n)))
                        elif route == "cold":
                            out_c = forked(lambda: cold(kind, n))
                            times["cold"].append(out_c[0])
                        else:
                            out_p = forked(lambda: predicted(kind, n, d))
                            times["predicted"].append(out_p[0])
                            times["coarse"].append(out_p[1])
                med = {k: statistics.median(v) for k, v in times.items()}
                _, st_c, kkt_c, fac_c, sol_c, act_c, R_c = out_c
                _, _, st_p, kkt_p, fac_p, sol_p, act_p, R_p = out_p
                wrong = int(np.sum(act_c != act_p))
                diff = float(np.abs(R_c - R_p).max() / max(np.abs(R_c).max(), 1e-300))
                row = {"scene": kind, "mesh": n, "coarse": n // d, "rows": act_c.size, "wrong": wrong,
                       "raw_s": med["raw"], "cold_s": med["cold"], "coarse_s": med["coarse"],
                       "predicted_s": med["predicted"], "predicted_over_cold": med["predicted"] / med["cold"],
                       "cold_over_raw": med["cold"] / med["raw"], "predicted_over_raw": med["predicted"] / med["raw"],
                       "cold_factorisations": fac_c, "cold_solves": sol_c, "predicted_factorisations": fac_p,
                       "predicted_solves": sol_p, "cold_status": st_c, "predicted_status": st_p, "cold_kkt": kkt_c,
                       "predicted_kkt": kkt_p, "reaction_difference": diff, "runs": args.repeat}
                rows.append(row)
                print(f"| {kind} | {n}² | {n // d}² | {act_c.size} | {wrong} | {med['raw']:.3f} | {med['cold']:.3f} "
                      f"({fac_c}, {sol_c}) | {med['coarse']:.3f} | {med['predicted']:.3f} ({fac_p}, {sol_p}) | "
                      f"{row['predicted_over_cold']:.2f} | {row['cold_over_raw']:.2f} | {row['predicted_over_raw']:.2f} | "
                      f"{st_c} / {st_p} | {kkt_c:.1e} / {kkt_p:.1e} | {diff:.1e} |", flush=True)
    out = HERE / "results" / f"predict{'-' + args.tag if args.tag else ''}.csv"
    write_csv(rows, out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
