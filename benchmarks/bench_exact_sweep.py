"""sweep --exact: CPU time of the exact path a piece, and of the sweep a value after the first, ÷ raw.

"raw" is the floor of benchmarks/bench_fast.py: one CHOLMOD symbolic analysis + numeric
factorisation + solve of the plate's matrix, straight through cvxopt (grid: K; bed: K with
every bed spring bonded). Scenes are bench_fast's: ``grid`` (a slab on four walls and 30 × 30
rigid posts) and ``bed`` (a free plate on a tensionless bed); the parameters that enter
linearly of bench_sweep_reuse (a gap: grid post 1's ``supports.1.gap``, the bed's slope
``foundation.gap.gx``; a load: the grid's pressure ``loads.0.q``, the bed's column ``loads.1.P``).

Per mesh, scene and parameter, interleaved, ``--repeats`` times (medians reported): raw;
:func:`plateqp.studies.exact_path` over the range (``path_s``: the start solve and every piece's
held system, :mod:`plateqp.studies.held`); :func:`plateqp.studies.exact_sweep` of the first value
alone and of ``--values`` values (the path, then a sweep whose values share the model and its
factorisation). Per value after the first = (exact sweep of V values − of one) / (V − 1): the
issue's metric, which here carries the path (its pieces count the contact set's changes over
the range, not the values); per piece = ``path_s`` / the held systems solved. Every value's row
must be OPTIMAL (its KKT check passed at ``ACCURACY``); the held factor's work is counted
(factorisations, Woodbury corrections, refinement steps).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_exact_sweep.py [--meshes 64,128] [--repeats 3]

Writes benchmarks/results/exact-sweep.csv and prints a markdown table.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before NumPy loads
    os.environ.setdefault(_var, "1")

import statistics
import sys
import time
import warnings
from pathlib import Path

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_fast import ACCURACY, make_scene, plate_matrix, raw_cholmod, to_cvxopt  # noqa: E402
from bench_sweep_reuse import GOAL, parse_args, run_table, values_for  # noqa: E402

from plateqp.model.assembly import build_model  # noqa: E402
from plateqp.studies import exact_path, exact_sweep, homotopy  # noqa: E402

KINDS = ("gap", "load")


class Watch:
    """The held factors the paths make (:func:`plateqp.studies.homotopy._held_factor`), to read
    their counts after the run."""

    def __init__(self):
        self.made = []
        self._real = homotopy._held_factor
        homotopy._held_factor = self._make

    def _make(self, data):
        f = self._real(data)
        self.made.append(f)
        return f


def timed(fn):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.process_time()
        out = fn()
        return time.process_time() - t0, out


def row_for(kind: str, n: int, values: int, repeats: int, sweep_kind: str, watch: Watch) -> dict:
    scene = make_scene(kind, n)
    A, f = plate_matrix(kind, build_model(scene))
    Ac = to_cvxopt(A)
    path, vals = values_for(kind, scene, values, sweep_kind)
    timed(lambda: exact_sweep(scene, path, vals[:1], executor="serial", progress=False, accuracy=ACCURACY))  # imports
    times = {"raw": [], "path": [], "one": [], "all": []}
    kkt, held = [], None
    for _ in range(repeats):
        t0 = time.process_time()
        raw_cholmod(Ac, f)
        times["raw"].append(time.process_time() - t0)
        dt, ep = timed(lambda: exact_path(scene, path, vals[0], vals[-1]))
        times["path"].append(dt)
        held = watch.made[-1]
        times["one"].append(timed(lambda: exact_sweep(scene, path, vals[:1], executor="serial", progress=False,
                                                      accuracy=ACCURACY))[0])
        dt, r = timed(lambda: exact_sweep(scene, path, vals, executor="serial", progress=False, accuracy=ACCURACY))
        times["all"].append(dt)
        bad = [row for row in r.rows if row["status"] != "optimal"]
        if bad:
            raise SystemExit(f"{scene.name} {path}: {len(bad)} values not OPTIMAL at {ACCURACY:g}: "
                             f"{bad[0]['status']} {bad[0]['error']}")
        kkt += [row["kkt_worst"] for row in r.rows]
    med = {k: statistics.median(v) for k, v in times.items()}
    per = (med["all"] - med["one"]) / (values - 1)
    calls = held.calls if held is not None else None
    st = held.fac.stats if held is not None else {}
    return {"scene": kind, "mesh": n, "path": path, "values": values, "repeats": repeats,
            "held_mode": None if held is None else ("condensed" if held.condensed else "springs"),
            "pieces": len(ep.pieces), "breakpoints": len(ep.breakpoints), "held_systems": calls,
            "factorisations": st.get("factorisations"), "woodbury": st.get("lowrank"),
            "refinement_steps": None if held is None else held.steps,
            "raw_s": med["raw"], "path_s": med["path"],
            "per_piece_ratio": med["path"] / calls / med["raw"] if calls else None,
            "first_value_s": med["one"], "sweep_s": med["all"], "per_value_s": per,
            "per_value_ratio": per / med["raw"], "goal_met": per / med["raw"] <= GOAL,
            "kkt_worst": max(kkt), "all_optimal": True}


def main():
    args, kinds = parse_args(__doc__, KINDS, 3, "exact-sweep.csv")
    watch = Watch()
    run_table(args, kinds, lambda kind, n, sk: row_for(kind, n, args.values, args.repeats, sk, watch),
              ["scene", "mesh", "path", "pieces", "held", "raw s", "path s", "per piece ÷ raw",
               "**per value ÷ raw**", f"≤ {GOAL}", "KKT worst"],
              lambda r: [r["path"], str(r["pieces"]), str(r["held_mode"]), f"{r['raw_s']:.3f}", f"{r['path_s']:.2f}",
                         f"{r['per_piece_ratio']:.2f}", f"**{r['per_value_ratio']:.2f}**", str(r["goal_met"]),
                         f"{r['kkt_worst']:.1e}"])


if __name__ == "__main__":
    main()
