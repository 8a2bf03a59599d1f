"""Soils: the cost of a tensionless Winkler, Pasternak and half-space bed against raw CHOLMOD.

    python benchmarks/bench_soils.py                       # meshes 32, 64, 128 (half-space 16 … 128)
    python benchmarks/bench_soils.py --meshes 16 --hs-meshes 8 --repeats 1    # quick
    python benchmarks/bench_soils.py --hs-memory 512       # the half-space at 512²: peak memory, once
    python benchmarks/bench_soils.py --meshes "" --hs-meshes 64,128    # the half-space rows alone

The scene: a 1 × 1 plate (h = 0.02, E = 1e7, ν = 0.3) simply supported on its left and right
edges, under q = 20 and P = 200 at (0.6, 0.55), on soil over its whole area whose gap falls away
towards x = 1 (g0 = 0.004 x: part of the bed lifts off). Winkler k = 2e4; Pasternak the same k
and a shear layer c2 = 2e2 (its length √(c2/k) = 0.1); a half-space E = 1e4, ν = 0.3.

"raw" is benchmarks/bench_fast.py's floor: one CHOLMOD symbolic analysis + numeric
factorisation + solve of the plate's K with every Winkler spring bonded (K + Bᵀ C B), through
cvxopt. Per mesh and soil, interleaved, ``--repeats`` times: raw, then pq.solve (backend and
formulation "auto", accuracy 1e-8) from the scene (the model's build included); CPU time
(time.process_time, one BLAS thread), medians. The half-space takes the route its size gives
(``route``: its soil's unknowns in K up to plateqp.model.soil.HALFSPACE_OPERATOR_FROM bed nodes,
else matrix-free in the contact forces, ``matvecs`` products of its operator). Writes
results/soils.csv.

``--hs-memory N``: the half-space at N² in two fresh processes, the raw factorisation and the
solve, each's peak resident memory above its imports (ru_maxrss) and CPU time; appended to the
CSV as ``memory_*`` rows.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
import warnings
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import pandas as pd  # noqa: E402

import plateqp as pq  # noqa: E402
from plateqp.model.assembly import build_model  # noqa: E402

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_fast import plate_matrix, raw_cholmod, to_cvxopt  # noqa: E402

SOILS = {
    "winkler": dict(k=2.0e4),
    "pasternak": dict(model="pasternak", k=2.0e4, shear=2.0e2),
    "halfspace": dict(model="halfspace", E=1.0e4, nu=0.3),
}


def scene(soil: str, n: int) -> pq.Scene:
    return pq.Scene(name=f"{soil}{n}", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                    edges={"left": "simple", "right": "simple"},
                    loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                    foundation=pq.Foundation(gap={"profile": "linear", "g0": 0.0, "gx": 0.004, "gy": 0.0},
                                             **SOILS[soil]))


def cpu(fn):
    t0 = time.process_time()
    out = fn()
    return time.process_time() - t0, out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--meshes", default="32,64,128", help="cells a side for Winkler and Pasternak")
    ap.add_argument("--hs-meshes", default="16,32,64,128", help="cells a side for the half-space")
    ap.add_argument("--hs-memory", type=int, default=0, help="also the half-space at this mesh: peak memory, once")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=str(HERE / "results" / "soils.csv"))
    args = ap.parse_args(argv)
    cases = [(s, int(n)) for n in args.meshes.split(",") if n for s in ("winkler", "pasternak")]
    cases += [("halfspace", int(n)) for n in args.hs_meshes.split(",") if n]
    rows = []
    with warnings.catch_warnings():  # imports and first-call costs out of the first case's clock
        warnings.simplefilter("ignore")
        for soil in SOILS:
            pq.solve(scene(soil, 8), accuracy=1e-8)
    for soil, n in cases:
        floor = build_model(scene("winkler", n))
        A, f = plate_matrix("bed", floor)
        Ac = to_cvxopt(A)
        raw_t, solve_t, info = [], [], {}
        for _ in range(args.repeats):
            raw_t.append(cpu(lambda: raw_cholmod(Ac, f))[0])
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t, res = cpu(lambda: pq.solve(scene(soil, n), accuracy=1e-8))
            solve_t.append(t)
            info = dict(route=f"{res.backend}/{res.formulation}", status=res.status.value, kkt_worst=res.kkt.worst,
                        contacts=int(res.model.contacts.m), in_contact=int(res.active.sum()),
                        soil_unknowns=int(res.model.n_soil), build_s=res.times.get("build", float("nan")),
                        matrix_free=res.model.soil_flexibility is not None,
                        matvecs=res.extras.get("matvecs", 0))
        raw, solve = statistics.median(raw_t), statistics.median(solve_t)
        rows.append(dict(soil=soil, mesh=n, dofs=A.shape[0], raw_s=raw, solve_s=solve, solve_ratio=solve / raw, **info))
        print(f"{soil:10s} {n:4d}  raw {raw:.3g} s  solve {solve:.3g} s  ratio {solve / raw:.1f}  "
              f"{info['route']} {info['status']} kkt {info['kkt_worst']:.1e}", flush=True)
    if args.hs_memory:
        rows.append(memory_row(args.hs_memory))
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(rows).to_csv(out, index=False)
    return 0


CHILD = """
import os, resource, sys, time, warnings
os.environ["OPENBLAS_NUM_THREADS"] = "1"
sys.path.insert(0, {here!r})
import plateqp as pq
from plateqp.model.assembly import build_model
import bench_soils as bs
from bench_fast import plate_matrix, raw_cholmod, to_cvxopt
n = {n}
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t0 = time.process_time()
if {raw}:
    A, f = plate_matrix("bed", build_model(bs.scene("winkler", n)))
    raw_cholmod(to_cvxopt(A), f)
    extra = ""
else:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pq.solve(bs.scene("halfspace", n), accuracy=1e-8)
    extra = (f" {{res.status.value}} {{res.kkt.worst:.3e}} {{res.extras.get('matvecs', 0)}} {{res.model.contacts.m}} "
             f"{{res.backend}}/{{res.formulation}}")
t = time.process_time() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(f"{{(peak - base) / 1024:.1f}} {{t:.3f}}" + extra)
"""


def memory_row(n: int) -> dict:
    """The half-space at n²: the raw factorisation and the solve, each in a fresh process."""
    import subprocess

    def run(raw: bool) -> list[str]:
        code = CHILD.format(here=str(Path(__file__).resolve().parent), n=n, raw=raw)  # the scripts' own folder
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
        return out.stdout.split()

    raw, sol = run(True), run(False)
    row = dict(soil="halfspace", mesh=n, memory_raw_mb=float(raw[0]), memory_solve_mb=float(sol[0]),
               raw_s=float(raw[1]), solve_s=float(sol[1]), solve_ratio=float(sol[1]) / float(raw[1]),
               status=sol[2], kkt_worst=float(sol[3]), matvecs=int(sol[4]), contacts=int(sol[5]),
               matrix_free=True, route=f"{sol[6]} (fresh process)")
    print(f"halfspace  {n:4d}  memory: raw {raw[0]} MB, solve {sol[0]} MB; CPU raw {raw[1]} s, solve {sol[1]} s; "
          f"{sol[2]} kkt {sol[3]}", flush=True)
    return row


if __name__ == "__main__":
    raise SystemExit(main())
