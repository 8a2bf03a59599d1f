"""The exact contact solve against one raw sparse Cholesky of the same plate.

The floor ("raw") is one CHOLMOD symbolic analysis + numeric factorisation + solve of the
plate's matrix, written directly against cvxopt's bindings (``cvxopt.cholmod``, the CHOLMOD
of the default install), not through plateqp.linalg; the lower triangle is converted to a
cvxopt matrix before the clock starts. The matrix is

* grid: ``plateqp.scenes.families.grid_rigid(n, 30)`` (benchmarks/bench_contact.py's scene family:
  an 8 m slab on four walls, a 30 × 30 grid of rigid one-sided posts with mixed gaps): the
  plate's ``K``;
* bed: a free ACM plate on a tensionless bed (k = 2·10⁴) whose surface falls away towards
  (1, 1) (gap 0.004 x + 0.002 y), under a uniform load and an off-centre point load (about
  half of the plate lifts off): ``K + Bᵀ C B``, every bed spring bonded, on K's stored pattern.

Parts (``--parts``, comma-separated):

* ``goal``: CPU time (``time.process_time``, BLAS on one thread), interleaved in one process,
  medians of ``--repeat``, at ``--meshes`` (default 64,128,256): the whole
  ``pq.solve(scene, accuracy=1e-10)`` call (assembly included; backend and formulation
  "auto"; its KKT check must pass; where 1e-10 lies below the plate's rounding floor, at the
  accuracy :func:`reachable` gives, column ``accuracy``) ÷ raw, and plateqp's own two-sided solve
  (``plateqp.linalg.Factor(K).solve(f)``: equilibrated, refined) ÷ raw; then, each in a fresh
  interpreter, the peak resident memory of the solve above the memory held before it (the
  model built; Linux VmHWM reset through /proc/self/clear_refs) against the raw
  factorisation's, measured the same way. Goals: pq.solve ≤ 2.5× raw at 128² and 256² (≤ 3×
  at 64²), the two-sided solve ≤ 1.1×, memory ≤ 2×.
* ``backends``: at ``--mesh`` (128), the grid scene through pdas and the external QP
  backends (clarabel, qpsolvers:piqp, qpsolvers:proxqp, qpsolvers:scs, osqp) on the primal
  formulation at accuracy 1e-6 and 1e-9, one run each in a fresh interpreter with
  ``--timeout`` (wall): CPU time of ``pq.solve`` on the built model (all threads), × raw, the worst KKT residual reached, and the reaction error
  against pdas's (exact to rounding).
* ``auto``: ``backend="auto"`` on a single cold solve (a new model each time, nothing cached)
  of ``grid_rigid(n, k)`` for ``--auto-meshes`` × ``--auto-ks``, against every exact route
  (pdas on the primal, bpp and lemke on the condensed, bpp on the dual) at accuracy 1e-10,
  CPU time, medians of ``--auto-repeat`` interleaved, each solve in a child forked from the
  benchmark's process (the same heap and imports for every route; run in one process, a
  route's time depended on which route ran before it); and a sweep of ``--sweep-values`` gaps
  of one support (``plateqp.sweep``) through auto and through pdas.
* ``mesh``: the grid scene's ``pq.solve`` ÷ raw for ``--scale-meshes`` (32,64,128,256,512;
  one run at 512²).
* ``residual``: the residual ``f − K u`` that refinement reads, at ``--meshes`` for
  ``--scenes``: in double, in long double (the widened values made once) and by
  ``plateqp.linalg.residual.Residual`` (K split once), the first and a further one, CPU
  medians of ``--repeat`` interleaved.
* ``flops``: why the grid's condensed method costs what it does: at ``--meshes``, one
  factorisation of the grid scene's equilibrated K in AMD order ("plain"), one with the 900
  contact dofs moved last (the condensed method's) and one with only the dofs of the posts in
  contact at the answer moved last (the floor of a Schur complement on the active posts), each
  through plateqp's CHOLMOD seam: CPU time (median of ``--repeat``), multiply-adds counted from
  the factor's supernodes (``plateqp.linalg.cholmod.Cholesky.flops``) and the rate.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_fast.py --parts goal
    python benchmarks/bench_fast.py --parts backends,mesh --scale-meshes 32,64,128,256
    python benchmarks/bench_fast.py --parts flops --meshes 64,128,256

Prints markdown tables, writes benchmarks/results/fast.csv (long format, one row per case).
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
from pathlib import Path

import numpy as np
import scipy.sparse as sp

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.scenes.families import grid_rigid
from plateqp.linalg import Factor
from plateqp.progress import track  # bars on a terminal only
from plateqp.studies.sweep import sweep

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_contact import run_in_subprocess
from bench_scaling import _status_kb  # (VmRSS, VmHWM) from /proc/self/status
from timing import cpu, forked  # noqa: F401  (other scripts import them from here)

KKT_KEYS = ("stationarity", "spring", "primal", "dual", "complementarity", "natural")
OTHERS = ("clarabel", "qpsolvers:piqp", "qpsolvers:proxqp", "qpsolvers:scs", "osqp")
ACCURACY = 1e-10


def bed_scene(n: int) -> pq.Scene:
    """Free n × n plate on a tensionless bed falling away towards (1, 1); about half lifts off."""
    return pq.Scene(name=f"bed{n}", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                    edges={}, loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                    foundation=pq.Foundation(2.0e4, gap={"profile": "linear", "g0": 0.0, "gx": 0.004, "gy": 0.002}))


def make_scene(kind: str, n: int) -> pq.Scene:
    return grid_rigid(n, 30) if kind == "grid" else bed_scene(n)


def plate_matrix(kind: str, model) -> tuple[sp.csc_matrix, np.ndarray]:
    """The floor's matrix and load: the plate's K (grid), K + Bᵀ C B with every bed spring
    bonded (bed), on K's stored pattern: SciPy's ``+`` would drop the assembly's structural zeros
    and with them CHOLMOD's node supervariables (a slower floor: plateqp.linalg.pattern)."""
    if kind == "grid":
        return sp.csc_matrix(model.K), np.asarray(model.f, dtype=float)
    c = model.contacts
    K, BCB = sp.coo_matrix(model.K), sp.coo_matrix(c.B.T @ sp.diags(1.0 / c.rho) @ c.B)
    A = sp.csc_matrix((np.concatenate([K.data, BCB.data]),
                       (np.concatenate([K.row, BCB.row]), np.concatenate([K.col, BCB.col]))), shape=K.shape)
    return A, model.f + c.B.T @ (c.g0 / c.rho)


def to_cvxopt(K: sp.csc_matrix):
    """The lower triangle of K as a cvxopt sparse matrix (made before the clock starts)."""
    from cvxopt import matrix, spmatrix

    L = sp.tril(K, format="csc")
    cols = np.repeat(np.arange(L.shape[0], dtype=np.int64), np.diff(L.indptr))
    return spmatrix(matrix(L.data.astype(float)), matrix(L.indices.astype(np.int64)), matrix(cols), L.shape)


def raw_cholmod(A, f: np.ndarray) -> np.ndarray:
    """The floor: CHOLMOD's symbolic analysis (its default ordering), numeric factorisation and
    one solve, straight through cvxopt."""
    from cvxopt import cholmod, matrix

    F = cholmod.symbolic(A)
    cholmod.numeric(A, F)
    x = matrix(f.copy())
    cholmod.solve(F, x)
    return np.array(x).ravel()


def accuracy_above(floor: float) -> float:
    """The accuracy to ask where 1e-10 lies below what double precision can show (``floor``, a
    KKT report's rounding floor): the first step of 1, 2, 5 × 10ᵏ at or above three times it."""
    want = 3.0 * floor
    decade = 10.0 ** np.floor(np.log10(want))
    return float(next(m * decade for m in (1.0, 2.0, 5.0, 10.0) if m * decade >= want))


def reachable(scene, model) -> float:
    """The accuracy asked of the timed solves: 1e-10, or, where the plate's rounding floor lies
    above it (the bed from 256²: the norm of its stationarity residual over every dof; no answer
    in double precision shows 1e-10 there, and the solve says so), the first step of 1, 2, 5 ×
    10ᵏ at or above three times that floor (:func:`accuracy_above`)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        r = pq.solve(scene, accuracy=ACCURACY, model=model)
    if r.kkt.ok:
        return ACCURACY
    if not r.kkt.at_floor:
        raise SystemExit(f"{scene.name}: the KKT check failed at accuracy {ACCURACY:g} above its floor "
                         f"({r.status.value}: worst {r.kkt.worst:.2e}, floor {r.kkt.floor:.2e})")
    return accuracy_above(r.kkt.floor)


def kkt_worst(res) -> float:
    return max(getattr(res.kkt, k) for k in KKT_KEYS)


def whole_solve(scene, accuracy=ACCURACY):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene, accuracy=accuracy)


def goal_row(kind: str, n: int, repeat: int) -> dict:
    """Medians of interleaved CPU times: raw CHOLMOD, plateqp's two-sided Factor, pq.solve."""
    scene = make_scene(kind, n)
    model = build_model(scene)
    K, f = plate_matrix(kind, model)
    A = to_cvxopt(K)
    x_raw = raw_cholmod(A, f)
    acc = reachable(scene, model)  # first-call imports paid
    steps = {
        "raw": lambda: raw_cholmod(A, f),
        "two_sided": lambda: Factor(K).solve(f),
        "solve": lambda: whole_solve(scene, acc),
    }
    times: dict[str, list[float]] = {k: [] for k in steps}
    res = x2 = None
    for r in range(repeat):
        names = list(steps)
        names = names[r % 3:] + names[:r % 3]  # rotate the order of the three
        for name in names:
            dt, out = cpu(steps[name])
            times[name].append(dt)
            if name == "solve":
                res = out
            elif name == "two_sided":
                x2 = out
    med = {k: statistics.median(v) for k, v in times.items()}
    e = res.extras
    return {
        "part": "goal", "scene": kind, "mesh": n, "dofs": model.n_free, "rows": int(model.contacts.m),
        "backend": res.backend, "formulation": res.formulation, "method": e.get("method"),
        "accuracy": acc, "status": res.status.value, "kkt_worst": kkt_worst(res), "iterations": res.iterations,
        "raw_s": med["raw"], "two_sided_s": med["two_sided"], "solve_s": med["solve"],
        "two_sided_ratio": med["two_sided"] / med["raw"], "solve_ratio": med["solve"] / med["raw"],
        "two_sided_vs_raw_diff": float(np.abs(x2 - x_raw).max() / np.abs(x_raw).max()),
        "build_s": res.times.get("build"), "formulate_s": res.times.get("formulate"),
        "backend_s": res.times.get("solve"), "recover_s": res.times.get("recover"),
        "analyse_s": e.get("analyse_s"), "factor_s": e.get("factor_s"), "extract_s": e.get("extract_s"),
        "dense_s": e.get("dense_s"), "solves": e.get("solves"), "solves_s": e.get("solve_s"),
        "factorisations": e.get("factorisations"), "in_contact": int(res.active.sum()), "repeat": repeat,
    }


# ----------------------------------------------------------------------------- memory, in a fresh interpreter


def _reset_peak() -> bool:
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


def _memory(args, q):
    """Peak resident memory (MB) of one step above what the process held before it."""
    kind, n, what = args
    warnings.simplefilter("ignore")
    whole_solve(grid_rigid(8, 3))  # imports paid
    scene = make_scene(kind, n)
    model = build_model(scene)
    K, f = plate_matrix(kind, model)
    if what == "raw":
        A = to_cvxopt(K)
        step = lambda: raw_cholmod(A, f)  # noqa: E731
    elif what == "two_sided":
        step = lambda: Factor(K).solve(f)  # noqa: E731
    else:
        step = lambda: pq.solve(scene, accuracy=ACCURACY, model=model)  # noqa: E731
    ok = _reset_peak()
    before = _status_kb()
    step()
    after = _status_kb()
    q.put({"mem_mb": (after[1] - before[0]) / 1024 if (ok and before) else None})


def memory(kind: str, n: int, what: str, timeout: float) -> float | None:
    return run_in_subprocess(_memory, (kind, n, what), timeout).get("mem_mb")


# ----------------------------------------------------------------------------- other backends


def _other(args, q):
    n, backend, accuracy = args
    warnings.simplefilter("ignore")
    scene = make_scene("grid", n)
    model = build_model(scene)
    try:
        t0 = time.process_time()
        r = pq.solve(scene, backend=backend, formulation="primal", accuracy=accuracy, model=model)
        q.put({"status": r.status.value, "solve_s": time.process_time() - t0, "formulate_s": r.times.get("formulate"),
               "kkt_worst": kkt_worst(r), "reactions": r.reactions.tolist(), "iterations": r.iterations})
    except Exception as exn:  # recorded, not hidden
        q.put({"status": f"error: {type(exn).__name__}: {str(exn)[:80]}"})


# ----------------------------------------------------------------------------- flops


def flops_row(n: int, repeat: int) -> dict:
    """One factorisation of the grid scene's K in AMD order, one with the contact dofs last, and
    one with only the dofs of the posts in contact at the answer last (what a Schur complement
    on the active posts alone would cost, were that set known before the factorisation): CPU
    time (medians, interleaved) and the multiply-adds read from each factor."""
    from plateqp.linalg.cholmod import Cholesky, lower
    from plateqp.linalg.factor import equilibration

    scene = make_scene("grid", n)
    model = build_model(scene)
    K = sp.csc_matrix(model.K)
    B = sp.csr_matrix(model.contacts.B)
    last = np.unique(B.indices)
    active = np.unique(B[whole_solve(scene).active].indices)
    s = equilibration(K, None)
    first = Cholesky("cvxopt")
    if first.direct is None:
        raise SystemExit("--parts flops needs plateqp's CHOLMOD seam (cvxopt's wheels)")
    amd = first.order(lower(K, s, upper=first.upper))

    def moved_last(dofs):
        mask = np.zeros(K.shape[0], dtype=bool)
        mask[dofs] = True
        return np.concatenate([amd[~mask[amd]], dofs])

    orders = {"plain": amd, "last": moved_last(last), "active": moved_last(active)}
    times: dict[str, list[float]] = {k: [] for k in orders}
    flops = {}
    for r in range(repeat):
        for name in (orders if r % 2 == 0 else reversed(list(orders))):
            chol = Cholesky("cvxopt")
            A = lower(K, s, upper=chol.upper)
            chol.analyse(A, order=orders[name])
            dt, _ = cpu(lambda: chol.factor(A))
            times[name].append(dt)
            flops[name] = chol.flops()
    return {"part": "flops", "scene": "grid", "mesh": n, "dofs": K.shape[0], "rows": int(last.size),
            "plain_s": statistics.median(times["plain"]), "last_s": statistics.median(times["last"]),
            "plain_flops": flops["plain"], "last_flops": flops["last"], "in_contact": int(active.size),
            "active_s": statistics.median(times["active"]), "active_flops": flops["active"], "repeat": repeat}


# ----------------------------------------------------------------------------- residual


def residual_row(kind: str, n: int, repeat: int) -> dict:
    """The residual ``f − K u`` that ``Factor.solve``'s refinement reads, three ways, on the
    floor's matrix and a raw solve's ``u``: in double (the floor: one SciPy product); in long
    double (what refinement read in earlier versions: the values widened once,
    then a long-double product); and by ``plateqp.linalg.residual.Residual`` (the split of K,
    then three double products). CPU ms, medians of ``repeat`` interleaved; "first" includes
    the one-time widening or split, "again" is a further residual with it."""
    from plateqp.linalg.factor import equilibration
    from plateqp.linalg.residual import Residual

    model = build_model(make_scene(kind, n))
    K, f = plate_matrix(kind, model)
    K = sp.csc_matrix(K)
    s = equilibration(K)
    u = Factor(K).solve(f, refine=0)

    def widened():
        return sp.csc_matrix((K.data.astype(np.longdouble), K.indices, K.indptr), shape=K.shape)

    def long_double(KL):
        return (f.astype(np.longdouble) - KL @ u.astype(np.longdouble)).astype(np.float64)

    KL, R = widened(), Residual(K, s, symmetric=True)
    steps = {
        "double": lambda: f - K @ u,
        "long_first": lambda: long_double(widened()),
        "long_again": lambda: long_double(KL),
        "split_first": lambda: Residual(K, s, symmetric=True)(f, u),
        "split_again": lambda: R(f, u),
    }
    times: dict[str, list[float]] = {k: [] for k in steps}
    for r in range(repeat):
        names = list(steps)
        names = names[r % len(names):] + names[:r % len(names)]
        for name in names:
            times[name].append(cpu(steps[name])[0])
    med = {k: 1e3 * statistics.median(v) for k, v in times.items()}
    return {"part": "residual", "scene": kind, "mesh": n, "dofs": K.shape[0], "nnz": K.nnz, "repeat": repeat,
            **{f"{k}_ms": v for k, v in med.items()}}


# ----------------------------------------------------------------------------- backend="auto"

ROUTES = (("auto", "auto"), ("pdas", "primal"), ("bpp", "condensed"), ("lemke", "condensed"), ("bpp", "dual"))


def _route(scene, b: str, f: str) -> tuple:
    """One solve by route ``b/f``: (CPU s, solved, the route taken, worst KKT residual)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        dt, res = cpu(lambda: pq.solve(scene, backend=b, formulation=f, accuracy=ACCURACY))
    return dt, bool(res.status.solved), f"{res.backend}/{res.formulation}", kkt_worst(res)


def auto_row(n: int, k: int, repeat: int, routes=ROUTES) -> dict:
    """Single cold solves of grid_rigid(n, k): auto and each exact route (CPU s, medians), each
    in a child forked from this process (:func:`forked`: the same heap for every route)."""
    scene = grid_rigid(n, k)
    ROUTES = routes  # noqa: N806
    times: dict[str, list[float]] = {f"{b}/{f}": [] for b, f in ROUTES}
    chosen, kkt = None, {}
    for r in range(repeat):
        for i in range(len(ROUTES)):
            b, f = ROUTES[(i + r) % len(ROUTES)]
            try:
                dt, solved, route, worst = forked(lambda: _route(scene, b, f))
            except Exception:  # a route that does not apply here (recorded as missing)
                continue
            if not solved:
                continue
            times[f"{b}/{f}"].append(dt)
            kkt[f"{b}/{f}"] = worst
            if b == "auto":
                chosen = route
    med = {key: statistics.median(v) for key, v in times.items() if v}
    exact = {key: v for key, v in med.items() if key != "auto/auto"}
    best = min(exact, key=exact.get)
    row = {"part": "auto", "scene": "grid", "mesh": n, "k": k, "rows": k * k, "auto_route": chosen,
           "fastest_route": best, "auto_s": med.get("auto/auto"), "fastest_s": exact[best],
           "auto_ratio": med["auto/auto"] / exact[best] if "auto/auto" in med else None}
    for key, v in med.items():
        row[f"{key}_s"] = v
    return row


def sweep_row(n: int, k: int, values: int) -> dict:
    """One support's gap swept over ``values`` values: auto against pdas (CPU s, one run each,
    after a two-value sweep of each on a small plate: the first sweep of a process otherwise
    pays the imports of the sweep's and the route's modules, 0.2 s, more than a 32² sweep)."""
    out = {"part": "sweep", "scene": "grid", "mesh": n, "k": k, "rows": k * k, "values": values}
    for scene, count, keep in ((grid_rigid(8, 3), 2, False), (grid_rigid(n, k), values, True)):
        g0 = scene.supports[0].gap
        vals = list(np.linspace(g0 - 0.002, g0 + 0.002, count))
        for backend in ("auto", "pdas"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                dt, _ = cpu(lambda: sweep(scene, "supports.1.gap", vals, backend=backend, accuracy=ACCURACY,
                                          executor="serial", progress=False, refine_breakpoints=False))
            if keep:
                out[f"{backend}_s"] = dt
    return out


# ----------------------------------------------------------------------------- output


def fmt(v, f="{:.3g}"):
    return "–" if v is None else f.format(v)


def write_csv(rows, path):
    keys: list[str] = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


def table(rows: list[dict], out: str, title: str, head: list[str], cases, cells) -> None:
    """A markdown table: each case (a callable returning a row) run, kept in ``rows``, printed
    as ``cells(row)`` and the CSV rewritten (a long run keeps what it measured)."""
    print(f"\n### {title}\n")
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for case in cases:
        row = case()
        rows.append(row)
        print("| " + " | ".join(str(c) for c in cells(row)) + " |", flush=True)
        write_csv(rows, out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--parts", default="goal,backends,mesh")
    ap.add_argument("--meshes", default="64,128,256", help="meshes of the goal part")
    ap.add_argument("--scenes", default="grid,bed")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--memory", action=argparse.BooleanOptionalAction, default=True)
    ap.add_argument("--mesh", type=int, default=128, help="mesh of the backends part")
    ap.add_argument("--accuracies", default="1e-6,1e-9", help="accuracies of the backends part")
    ap.add_argument("--backends", default=",".join(OTHERS))
    ap.add_argument("--scale-meshes", default="32,64,128,256,512")
    ap.add_argument("--auto-meshes", default="32,64,128,256")
    ap.add_argument("--auto-ks", default="3,5,7,10,15,30")
    ap.add_argument("--auto-repeat", type=int, default=3)
    ap.add_argument("--auto-routes", default=",".join(f"{b}/{f}" for b, f in ROUTES),
                    help="backend/formulation pairs of the auto part")
    ap.add_argument("--no-sweep", action="store_true", help="auto part: skip the sweep")
    ap.add_argument("--sweep-values", type=int, default=20)
    ap.add_argument("--timeout", type=float, default=300.0)
    ap.add_argument("--out", default=str(HERE / "results" / "fast.csv"))
    args = ap.parse_args()
    parts = args.parts.split(",")
    kinds = args.scenes.split(",")
    rows: list[dict] = []
    print(f"threads: OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}; "
          f"CHOLMOD bindings in plateqp.linalg: {pq.linalg.bindings() or 'none (SuperLU)'}")

    if "goal" in parts:
        print(f"\n### pq.solve(scene, accuracy={ACCURACY:g}) and the two-sided solve ÷ raw CHOLMOD "
              f"(CPU s, medians of {args.repeat} interleaved)\n")
        print("| scene | mesh | dofs | rows | route | iterations | KKT worst | raw s | two-sided ÷ raw | "
              "pq.solve s | **pq.solve ÷ raw** | memory MB (solve / raw) |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for n in track([int(v) for v in args.meshes.split(",")], "meshes"):
            for kind in kinds:
                row = goal_row(kind, n, args.repeat)
                if args.memory:
                    for what in ("raw", "two_sided", "solve"):
                        row[f"mem_{what}_mb"] = memory(kind, n, what, args.timeout)
                    if row["mem_raw_mb"] and row["mem_solve_mb"] is not None:
                        row["mem_ratio"] = row["mem_solve_mb"] / row["mem_raw_mb"]
                rows.append(row)
                print(f"| {kind} | {n}² | {row['dofs']} | {row['rows']} | {row['backend']}/{row['formulation']}"
                      f" ({row['method']}) | {row['iterations']} | {row['kkt_worst']:.1e} | {row['raw_s']:.3f} | "
                      f"{row['two_sided_ratio']:.2f} | {row['solve_s']:.3f} | **{row['solve_ratio']:.2f}** | "
                      f"{fmt(row.get('mem_solve_mb'), '{:.0f}')} / {fmt(row.get('mem_raw_mb'), '{:.0f}')} |",
                      flush=True)
                write_csv(rows, args.out)

    if "backends" in parts:
        n = args.mesh
        model = build_model(make_scene("grid", n))
        K, f = plate_matrix("grid", model)
        A = to_cvxopt(K)
        raw = statistics.median(cpu(lambda: raw_cholmod(A, f))[0] for _ in range(3))
        avail = set(pq.available_backends())
        print(f"\n### {n}² grid_rigid({n}, 30), primal formulation: one run each in a fresh interpreter "
              f"({args.timeout:g} s wall limit; CPU time of pq.solve on the built model, all threads; raw CHOLMOD "
              f"{raw:.3f} s)\n")
        print("| backend | accuracy | status | solve s | × raw | KKT worst | reaction error vs pdas |")
        print("|---|---|---|---|---|---|---|")
        for acc in (float(v) for v in args.accuracies.split(",")):
            ref = run_in_subprocess(_other, (n, "pdas", acc), args.timeout)
            for backend in ["pdas"] + [b for b in args.backends.split(",") if b]:
                if backend != "pdas" and backend not in avail:
                    continue
                r = ref if backend == "pdas" else run_in_subprocess(_other, (n, backend, acc), args.timeout)
                row = {"part": "backends", "scene": "grid", "mesh": n, "backend": backend, "formulation": "primal",
                       "accuracy": acc, "status": r["status"], "solve_s": r.get("solve_s"), "raw_s": raw,
                       "solve_ratio": r["solve_s"] / raw if r.get("solve_s") else None,
                       "kkt_worst": r.get("kkt_worst"), "iterations": r.get("iterations")}
                if "reactions" in r and "reactions" in ref:
                    a, b = np.array(r["reactions"]), np.array(ref["reactions"])
                    row["reaction_error"] = float(np.abs(a - b).max() / np.abs(b).max())
                rows.append(row)
                print(f"| {backend} | {acc:g} | {row['status']} | {fmt(row['solve_s'])} | "
                      f"{fmt(row['solve_ratio'], '{:.1f}')} | {fmt(row['kkt_worst'], '{:.1e}')} | "
                      f"{fmt(row.get('reaction_error'), '{:.1e}')} |", flush=True)
                write_csv(rows, args.out)

    if "auto" in parts:
        for b, f in ROUTES:  # first-call imports paid
            try:
                pq.solve(grid_rigid(8, 3), backend=b, formulation=f)
            except Exception:
                pass
        print(f"\n### backend='auto' on a single cold solve of grid_rigid(n, k), accuracy {ACCURACY:g} "
              f"(CPU s, medians of {args.auto_repeat} interleaved)\n")
        print("| mesh | k | m | auto's route | auto s | fastest exact route | its s | auto ÷ fastest | "
              "pdas/primal s | bpp/condensed s |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for n in (int(v) for v in args.auto_meshes.split(",")):
            for k in (int(v) for v in args.auto_ks.split(",")):
                if k > n - 1:
                    continue
                routes = tuple(tuple(r.split("/")) for r in args.auto_routes.split(","))
                row = auto_row(n, k, args.auto_repeat, routes)
                rows.append(row)
                print(f"| {n}² | {k} | {k * k} | {row['auto_route']} | {fmt(row['auto_s'])} | {row['fastest_route']} | "
                      f"{fmt(row['fastest_s'])} | {fmt(row['auto_ratio'], '{:.2f}')} | "
                      f"{fmt(row.get('pdas/primal_s'))} | {fmt(row.get('bpp/condensed_s'))} |", flush=True)
                write_csv(rows, args.out)
        if args.no_sweep:
            args.auto_meshes = ""
        print(f"\n### a sweep of {args.sweep_values} gaps of one support (plateqp.sweep; CPU s, one run)\n")
        print("| mesh | k | m | auto s | pdas s | auto ÷ pdas |")
        print("|---|---|---|---|---|---|")
        for n in (int(v) for v in args.auto_meshes.split(",") if v):
            for k in (3, 10):
                row = sweep_row(n, k, args.sweep_values)
                rows.append(row)
                print(f"| {n}² | {k} | {k * k} | {row['auto_s']:.3g} | {row['pdas_s']:.3g} | "
                      f"{row['auto_s'] / row['pdas_s']:.2f} |", flush=True)
                write_csv(rows, args.out)

    if "mesh" in parts:
        print("\n### grid_rigid(n, 30): pq.solve ÷ raw CHOLMOD against the mesh (CPU, medians; one run from 512²)\n")
        print("| mesh | dofs | route | iterations | KKT worst | raw s | two-sided ÷ raw | pq.solve s | pq.solve ÷ raw |")
        print("|---|---|---|---|---|---|---|---|---|")
        for n in (int(v) for v in args.scale_meshes.split(",")):
            row = goal_row("grid", n, args.repeat if n < 512 else 1)
            row["part"] = "mesh"
            rows.append(row)
            print(f"| {n}² | {row['dofs']} | {row['backend']}/{row['formulation']} ({row['method']}) | "
                  f"{row['iterations']} | {row['kkt_worst']:.1e} | {row['raw_s']:.3f} | {row['two_sided_ratio']:.2f} | "
                  f"{row['solve_s']:.3f} | {row['solve_ratio']:.2f} |", flush=True)
            write_csv(rows, args.out)

    if "flops" in parts:
        table(rows, args.out,
              "grid_rigid(n, 30): CHOLMOD's factorisation of K, plain (AMD), with the contact dofs last, and "
              f"with only the dofs in contact at the answer last (CPU s, medians of {args.repeat})",
              ["mesh", "dofs", "contact dofs", "plain s", "plain G flops", "GF/s", "last s", "last G flops", "GF/s",
               "time ratio", "flop ratio", "in contact", "active last s", "active last G flops"],
              (lambda n=n: flops_row(n, args.repeat) for n in (int(v) for v in args.meshes.split(","))),
              lambda row: [f"{row['mesh']}²", row["dofs"], row["rows"], f"{row['plain_s']:.3f}",
                           f"{row['plain_flops'] / 1e9:.2f}", f"{row['plain_flops'] / row['plain_s'] / 1e9:.1f}",
                           f"{row['last_s']:.3f}", f"{row['last_flops'] / 1e9:.2f}",
                           f"{row['last_flops'] / row['last_s'] / 1e9:.1f}", f"{row['last_s'] / row['plain_s']:.2f}",
                           f"{row['last_flops'] / row['plain_flops']:.2f}", row["in_contact"],
                           f"{row['active_s']:.3f}", f"{row['active_flops'] / 1e9:.2f}"])

    if "residual" in parts:
        table(rows, args.out,
              "The residual f − K u of refinement: double, long double, split (CPU ms, medians of "
              f"{args.repeat} interleaved)",
              ["scene", "mesh", "nnz K", "double", "long double, first", "again", "split, first", "again",
               "first: split ÷ long", "again: split ÷ long"],
              (lambda kind=kind, n=n: residual_row(kind, n, args.repeat)
               for kind in kinds for n in (int(v) for v in args.meshes.split(","))),
              lambda row: [row["scene"], f"{row['mesh']}²", row["nnz"], f"{row['double_ms']:.2f}",
                           f"{row['long_first_ms']:.2f}", f"{row['long_again_ms']:.2f}",
                           f"{row['split_first_ms']:.2f}", f"{row['split_again_ms']:.2f}",
                           f"{row['split_first_ms'] / row['long_first_ms']:.2f}",
                           f"{row['split_again_ms'] / row['long_again_ms']:.2f}"])

    write_csv(rows, args.out)
    print(f"\nwritten {args.out}")


if __name__ == "__main__":
    main()
