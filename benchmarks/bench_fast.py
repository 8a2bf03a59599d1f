"""The in-house fast solver (issue 6, part 1): pdas against one two-sided factorise-and-solve.

Goal: KKT ≤ 1e-10 in at most 3× the time of one two-sided factorise-and-solve of the same
plate (plateqp.linalg.Factor, the same library), on

* grid: benchmarks/bench_contact.py's scene(n, 30), a simply supported ACM plate on a 30 × 30
  grid of rigid one-sided supports with heave in one corner and settlement in the other;
  two-sided: every support a pin holding w at its gap (Factor of the model's K);
* bed: a free ACM plate on a tensionless bed (k = 2·10⁴) whose surface falls away towards
  (1, 1) (gap 0.004 x + 0.002 y), under a uniform load and an off-centre point load: about half
  of the plate lifts off; two-sided: every spring acting both ways (Factor of K + Bᵀ C B).

Parts (``--parts``, comma-separated):

* ``goal``: pdas (``pq.solve(..., backend="pdas", formulation="primal", accuracy="high")``,
  the backend's own solve time) against the two-sided factorise-and-solve, medians of
  ``--repeat`` interleaved runs, at ``--mesh`` (default 128), once per library (``--bindings``:
  CHOLMOD through scikit-sparse, CHOLMOD from cvxopt's wheels, SuperLU), both sides through
  the same one (plateqp.linalg's flags switched for the run);
* ``backends``: the same scenes through osqp, clarabel, qpsolvers:proxqp and qpsolvers:scs at
  "high" on the primal formulation and Lemke on the condensed one (grid only), one run each
  in a subprocess with ``--timeout``; reactions compared with Lemke's (grid: exact to
  rounding) or with pdas's (bed: KKT at rounding; no other exact solver takes a 16 641-row bed);
* ``mesh``: pdas iterations, factorisations, solves and time ratio for meshes 32² … 256²
  (first library installed).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_fast.py
    python benchmarks/bench_fast.py --parts goal --mesh 64 --repeat 5

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
from plateqp import linalg
from plateqp.assembly import build_model
from plateqp.linalg import Factor
from plateqp.progress import track  # bars on a terminal only

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_contact import run_in_subprocess
from bench_contact import scene as grid_scene

KKT_KEYS = ("stationarity", "spring", "primal", "dual", "complementarity", "natural")
OTHERS = ("osqp", "clarabel", "qpsolvers:proxqp", "qpsolvers:scs")


def bed_scene(n: int) -> pq.Scene:
    """Free n × n plate on a tensionless bed falling away towards (1, 1); about half lifts off."""
    return pq.Scene(name=f"bed{n}", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                    edges={}, loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                    foundation=pq.Foundation(2.0e4, gap={"profile": "linear", "g0": 0.0, "gx": 0.004, "gy": 0.002}))


def make_scene(kind: str, n: int) -> pq.Scene:
    return grid_scene(n, 30) if kind == "grid" else bed_scene(n)


def two_sided(kind: str, n: int, scene: pq.Scene, model):
    """The matrix and load of the same plate with every contact two-sided."""
    if kind == "grid":  # each support a pin holding w at its gap
        pins = pq.Scene(name="pins", plate=scene.plate, mesh=scene.mesh, edges=scene.edges, loads=scene.loads,
                        pins=[pq.Pin(s.x, s.y, w=s.gap) for s in scene.supports])
        m = build_model(pins)
        return m.K, m.f
    c = model.contacts  # every spring acting both ways: K + Bᵀ C B, f + Bᵀ C g0
    C = sp.diags(1.0 / c.rho)
    return sp.csc_matrix(model.K + c.B.T @ C @ c.B), model.f + c.B.T @ (c.g0 / c.rho)


def time_two_sided(K, f, method="auto") -> float:
    t0 = time.perf_counter()
    F = Factor(K, method=method)
    F.solve(f)
    return time.perf_counter() - t0


#: The CHOLMOD bindings (or SuperLU) the goal is measured with: the two-sided solve and pdas
#: both go through the same one (plateqp.linalg's flags switched for the run).
BINDINGS = {
    "sksparse": ({"HAVE_CHOLMOD": True}, "auto", None),
    "cvxopt": ({"HAVE_CHOLMOD": False, "HAVE_CVXOPT": True}, "auto", None),
    "superlu": ({"HAVE_CHOLMOD": False, "HAVE_CVXOPT": False}, "superlu", {"method": "sparse", "factor": "superlu"}),
}


def binding_available(name: str) -> bool:
    return {"sksparse": linalg.HAVE_CHOLMOD, "cvxopt": getattr(linalg, "HAVE_CVXOPT", False)}.get(name, True)


class use_binding:
    """Switch plateqp.linalg's library flags for a block (restored after)."""

    def __init__(self, name: str) -> None:
        self.flags, self.method, self.options = BINDINGS[name]

    def __enter__(self):
        self.saved = {k: getattr(linalg, k, False) for k in self.flags}
        for k, v in self.flags.items():
            setattr(linalg, k, v)
        return self

    def __exit__(self, *exc):
        for k, v in self.saved.items():
            setattr(linalg, k, v)


def kkt_worst(res) -> float:
    return max(getattr(res.kkt, k) for k in KKT_KEYS)


def run_pdas(scene, model, options=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene, backend="pdas", formulation="primal", accuracy="high", model=model, options=options)


def pdas_row(kind, n, scene, model, repeat, options=None, method="auto"):
    """Medians of interleaved runs of the two-sided factorise-and-solve and pdas."""
    K2, f2 = two_sided(kind, n, scene, model)
    base, solve, total = [], [], []
    res = None
    for _ in range(repeat):
        base.append(time_two_sided(K2, f2, method))
        t0 = time.perf_counter()
        res = run_pdas(scene, model, options)
        total.append(time.perf_counter() - t0)
        solve.append(res.times["solve"])
    e = res.extras
    b, s = statistics.median(base), statistics.median(solve)
    return res, {
        "scene": kind, "mesh": n, "dofs": model.n_free, "rows": int(model.contacts.m), "solver": "pdas",
        "formulation": "primal", "status": res.status.value, "method": e.get("method"),
        "two_sided_s": b, "solve_s": s, "ratio": s / b, "pq_solve_total_s": statistics.median(total),
        "kkt_worst": kkt_worst(res), "iterations": res.iterations,
        "factorisations": e.get("factorisations"), "solves": e.get("solves"), "updated_rows": e.get("updated_rows"),
        "analyse_s": e.get("analyse_s"), "factor_s": e.get("factor_s"), "extract_s": e.get("extract_s"),
        "update_s": e.get("update_s"), "dense_s": e.get("dense_s"), "triangular_solve_s": e.get("solve_s"),
        "in_contact": int(res.active.sum()), "repeat": repeat, "cholmod": e.get("cholmod") or e.get("factor"),
    }


# ----------------------------------------------------------------------------- other backends


def _other(args, q):
    kind, n, backend, formulation = args
    warnings.simplefilter("ignore")
    scene = make_scene(kind, n)
    model = build_model(scene)
    try:
        r = pq.solve(scene, backend=backend, formulation=formulation, accuracy="high", model=model)
        q.put({"status": r.status.value, "solve_s": r.times["solve"], "build_s": r.times.get("formulate"),
               "kkt_worst": kkt_worst(r), "reactions": r.reactions.tolist(), "iterations": r.iterations,
               "in_contact": int(r.active.sum())})
    except Exception as exn:  # recorded, not hidden
        q.put({"status": f"error: {type(exn).__name__}: {str(exn)[:80]}"})


def run_other(args, timeout):
    return run_in_subprocess(_other, args, timeout)


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


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--parts", default="goal,backends,mesh")
    ap.add_argument("--mesh", type=int, default=128)
    ap.add_argument("--meshes", default="32,64,128,256")
    ap.add_argument("--scenes", default="grid,bed")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--backends", default=",".join(OTHERS))
    ap.add_argument("--bindings", default="sksparse,cvxopt,superlu",
                    help="libraries for the goal part (the first installed is used for the rest)")
    ap.add_argument("--out", default=str(HERE / "results" / "fast.csv"))
    args = ap.parse_args()
    parts = args.parts.split(",")
    kinds = args.scenes.split(",")
    rows: list[dict] = []
    print(f"threads: OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}; "
          f"CHOLMOD (scikit-sparse): {pq.linalg.HAVE_CHOLMOD}")

    if "goal" in parts or "backends" in parts:
        n = args.mesh
        bindings = [b for b in args.bindings.split(",") if b and binding_available(b)]
        print(f"\n### {n}×{n} ACM plate: pdas against one two-sided factorise-and-solve (medians of {args.repeat})\n")
        print("Both through the same library: plateqp.linalg.Factor for the two-sided solve, "
              "plateqp.linalg's Cholesky / SchurFactor (or Factor's SuperLU) for pdas.\n")
        print("| scene | library | dofs | contact rows | in contact | method | two-sided s | pdas s | ratio | "
              "KKT worst | iterations | factorisations | solves |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        refs = {}
        for kind in track(kinds, "kinds"):
            scene = make_scene(kind, n)
            model = build_model(scene)
            for name in bindings:
                with use_binding(name) as bnd:
                    res, row = pdas_row(kind, n, scene, model, args.repeat, bnd.options, bnd.method)
                row.update(part="goal", library=name)
                rows.append(row)
                if name == bindings[0]:
                    refs[kind] = res.reactions
                print(f"| {kind} | {name} | {row['dofs']} | {row['rows']} | {row['in_contact']} | {row['method']} | "
                      f"{row['two_sided_s']:.3f} | {row['solve_s']:.3f} | **{row['ratio']:.2f}** | "
                      f"{row['kkt_worst']:.1e} | {row['iterations']} | {row['factorisations']} | {row['solves']} |",
                      flush=True)
        print("\nwhere the pdas time goes (seconds, last run):\n")
        print("| scene | library | analyse | factorise | extract L_cc | updates | dense | solves |")
        print("|---|---|---|---|---|---|---|---|")
        for r in rows:
            if r.get("part") == "goal":
                print(f"| {r['scene']} | {r['library']} | {fmt(r['analyse_s'])} | {fmt(r['factor_s'])} | "
                      f"{fmt(r['extract_s'])} | {fmt(r['update_s'])} | {fmt(r['dense_s'])} | "
                      f"{fmt(r['triangular_solve_s'])} |")

    if "backends" in parts:
        n = args.mesh
        names = [b for b in args.backends.split(",") if b]
        avail = set(pq.available_backends())
        for kind in track(kinds, "kinds"):
            cases = [(b, "primal") for b in names if b in avail]
            if kind == "grid":
                cases.append(("lemke", "condensed"))
            ref = refs[kind]
            lemke = None
            if kind == "grid":
                lemke = run_other((kind, n, "lemke", "condensed"), 10 * args.timeout)
                if "reactions" in lemke:
                    ref = np.array(lemke["reactions"])
            what = "Lemke on the condensed LCP" if kind == "grid" else "pdas"
            print(f"\n### {n}×{n} {kind}: the QP backends at 'high' (one run each, {args.timeout:g} s limit); "
                  f"reaction error against {what}\n")
            print("| solver | formulation | status | build s | solve s | × two-sided | KKT worst | reaction error |")
            print("|---|---|---|---|---|---|---|---|")
            pd = next(r for r in rows if r.get("part") == "goal" and r["scene"] == kind)
            b = pd["two_sided_s"]
            err = float(np.abs(refs[kind] - ref).max() / np.abs(ref).max()) if kind == "grid" else 0.0
            print(f"| pdas | primal | {pd['status']} | – | {pd['solve_s']:.3g} | {pd['ratio']:.2f} | "
                  f"{pd['kkt_worst']:.1e} | {fmt(err if kind == 'grid' else None, '{:.1e}')} |")
            for backend, form in cases:
                r = lemke if (backend == "lemke" and lemke is not None) else run_other((kind, n, backend, form), args.timeout)
                row = {"part": "backends", "scene": kind, "mesh": n, "solver": backend, "formulation": form,
                       "status": r["status"], "solve_s": r.get("solve_s"), "build_s": r.get("build_s"),
                       "two_sided_s": b, "ratio": r["solve_s"] / b if "solve_s" in r else None,
                       "kkt_worst": r.get("kkt_worst"), "iterations": r.get("iterations"),
                       "in_contact": r.get("in_contact")}
                if "reactions" in r:
                    row["reaction_error"] = float(np.abs(np.array(r["reactions"]) - ref).max() / np.abs(ref).max())
                rows.append(row)
                print(f"| {backend} | {form} | {row['status']} | {fmt(row['build_s'])} | {fmt(row['solve_s'])} | "
                      f"{fmt(row['ratio'], '{:.1f}')} | "
                      f"{fmt(row['kkt_worst'], '{:.1e}')} | {fmt(row.get('reaction_error'), '{:.1e}')} |", flush=True)

    if "mesh" in parts:
        meshes = [int(v) for v in args.meshes.split(",")]
        print(f"\n### pdas against mesh size (medians of {args.repeat}; iterations = active sets solved, "
              "Newton–PCG steps included)\n")
        print("| scene | mesh | dofs | rows | in contact | method | iterations | factorisations | solves | "
              "two-sided s | pdas s | ratio | KKT worst |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for kind in track(kinds, "kinds"):
            for n in meshes:
                scene = make_scene(kind, n)
                model = build_model(scene)
                _, row = pdas_row(kind, n, scene, model, args.repeat if n < 256 else 1)
                row["part"] = "mesh"
                rows.append(row)
                print(f"| {kind} | {n} | {row['dofs']} | {row['rows']} | {row['in_contact']} | {row['method']} | "
                      f"{row['iterations']} | {row['factorisations']} | {row['solves']} | {row['two_sided_s']:.3f} | "
                      f"{row['solve_s']:.3f} | {row['ratio']:.2f} | {row['kkt_worst']:.1e} |", flush=True)

    write_csv(rows, args.out)
    print(f"\nwritten {args.out}")


if __name__ == "__main__":
    main()
