"""Sweep of support stiffness: 32×32 ACM plate, 8×8 = 64 elastic supports (three heaved), 50 values
from c = 1e6 down to 1, Lemke on the condensed form, with and without re-use (the model built
once, only the gaps/springs/loads changed, and the condensation cached), serial.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_sweep.py [--refine] [--parallel] [--once]
"""
import sys, time, numpy as np, plateqp as pq
from plateqp.studies import sweep
a = 400.0
sup = [pq.Support(25 + 50 * i, 25 + 50 * j, gap=(-0.02 if (i, j) in ((0, 0), (1, 0), (0, 1)) else 0.0))
       for j in range(8) for i in range(8)]
sc = pq.Scene(name="fig5-64", plate=pq.Plate(a=a, b=a, h=20.0, E=2e5, nu=0.2), mesh=pq.MeshSpec(32, 32),
              loads=[pq.PointLoad(P=20000.0, x=150.0, y=250.0), pq.UniformLoad(q=0.05)], supports=sup)
if __name__ == "__main__":
    vals = list(np.geomspace(1e6, 1.0, 50))
    refine = "--refine" in sys.argv
    pq.solve(sc)  # warm-up: first-call imports
    for reuse in ((False, True) if "--once" in sys.argv else (False, True, False, True)):
        t = time.perf_counter()
        r = sweep(sc, "supports.*.stiffness", vals, executor="serial", progress=False, reuse=reuse,
                  refine_breakpoints=refine)
        dt = time.perf_counter() - t
        build = sum(x["times"]["build"] for x in r.rows); solve = sum(x["times"]["solve"] for x in r.rows)
        print(f"reuse={reuse}: total {dt:.2f} s (values {r.times['values']:.2f} s, breakpoints {r.times['breakpoints']:.2f} s,"
              f" {r.times['bisection_solves']} bisection solves), per-row build {build:.2f} s, backend solve {solve:.2f} s,"
              f" {len(r.breakpoints)} breakpoints, backend {r.rows[0]['backend']}/{r.rows[0]['formulation']}")
    if "--parallel" in sys.argv:
        t = time.perf_counter()
        r = sweep(sc, "supports.*.stiffness", vals, progress=False, refine_breakpoints=refine)
        print(f"2 processes, reuse=True: total {time.perf_counter() - t:.2f} s ({r.times['executor']})")
