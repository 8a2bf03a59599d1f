"""In-house LCP solvers on the condensed LCP of a 64×64 ACM plate with 30×30 supports (n = 900):
block principal pivoting (cold and warm-started), projected Gauss–Seidel / SOR, and Lemke.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_lcp.py

Prints one line per case (status, iterations, median time, natural residual, reaction error
against Lemke at `high`).
"""
import sys, time, json, statistics
from pathlib import Path
sys.path.insert(0, str(Path(__file__).parent))
import numpy as np, plateqp as pq
from bench_contact import scene
from plateqp.model.assembly import build_model
from plateqp.contact import Scaled, formulate
from plateqp.backends import get_backend
from plateqp.backends.bpp import natural_residual

lemke, bpp, pgs = (get_backend(b) for b in ("lemke", "bpp", "pgs"))  # the registered backends


def lcp_of(sc):
    return formulate(Scaled.from_model(build_model(sc)), "condensed").lcp
N = int(sys.argv[1]) if len(sys.argv) > 1 else 64
sc = scene(N, 30)
lcp = lcp_of(sc)
sc2 = scene(N, 30); sc2.loads = [pq.UniformLoad(20.0), pq.PointLoad(220.0, 0.7, 0.6)]   # +10 % point load
lcp2 = lcp_of(sc2)
sc3 = scene(N, 30); sc3.loads = [pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.72, 0.6)]  # point load moved 0.02 a
lcp3 = lcp_of(sc3)
print("n =", lcp.n, flush=True)
ref = lemke.solve(lcp, "high")
Mmax = np.abs(ref.w).max()
def run(label, f, reps=3):
    ts, out = [], None
    for _ in range(reps):
        t = time.perf_counter(); out = f(); ts.append(time.perf_counter() - t)
    x = out.x
    err = np.abs(out.w - ref.w).max() / Mmax if out.w is not None else float("nan")
    row = dict(case=label, status=out.status.value, iterations=out.iterations, time_median=statistics.median(ts),
               times=[round(t, 4) for t in ts], natural=natural_residual(lcp.M, lcp.q, x, lcp.M @ x + lcp.q),
               reaction_err_rel=err, contact_set_equal=bool(np.array_equal(x == 0, ref.x == 0)))
    print(json.dumps(row), flush=True)
    return out
c = run("bpp cold default", lambda: bpp.solve(lcp, "default"))
run("bpp cold high", lambda: bpp.solve(lcp, "high"))
run("bpp warm: solution's set", lambda: bpp.solve(lcp, "high", {"active": c.extras["active"]}))
a2 = bpp.solve(lcp2, "high").extras["active"]
a3 = bpp.solve(lcp3, "high").extras["active"]
print("sets differ by", int((a2 != c.extras["active"]).sum()), int((a3 != c.extras["active"]).sum()), flush=True)
run("bpp warm: set of P+10%", lambda: bpp.solve(lcp, "high", {"active": a2}))
run("bpp warm: set of load moved 0.02a", lambda: bpp.solve(lcp, "high", {"active": a3}))
run("lemke default", lambda: lemke.solve(lcp, "default"))
run("lemke high", lambda: lemke.solve(lcp, "high"))
run("pgs low", lambda: pgs.solve(lcp, "low"))
run("pgs default", lambda: pgs.solve(lcp, "default"))
run("pgs high (60 s limit)", lambda: pgs.solve(lcp, "high"), reps=1)
run("psor 1.5 default", lambda: pgs.solve(lcp, "default", {"omega": 1.5}), reps=1)
run("pgs default warm z0 of P+10%", lambda: pgs.solve(lcp, "default", {"z0": bpp.solve(lcp2, "high").x}), reps=1)
