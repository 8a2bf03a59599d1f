"""Discretisation error against solver error, on the scene families (plateqp.scenes.families).

For each family and mesh n² (8 … 128), the scene is solved by an exact in-house solver (pdas on
the primal: the finite-element answer of that mesh) and by an iterative backend at a ladder of
tolerances (1e-2 … 1e-10). Every answer is compared with a converged reference (the same
scene on a 256² mesh, pdas at 1e-12): the error of the deflection field (at the 8² mesh's
nodes, relative to max |w|) and of the reactions (discrete supports: max change relative to the
largest; the bed: its largest pressure). The exact answer's error is the mesh's own error; an
iterative answer's error falls with the tolerance until it meets it, and no further.

Also records, per mesh, the tolerance ``accuracy="auto"`` would choose (a tenth of the
Richardson estimate from the two coarser meshes, plateqp.estimate).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_discretisation.py            # all families
    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_discretisation.py --families grid_rigid --max-mesh 64

Writes benchmarks/results/discretisation.csv and benchmarks/figures/discretisation-<family>.png.

``--elements``: the elements against each other instead (DKT triangles against the ACM and BFS
rectangles): Navier's simply supported square under uniform load, w at the centre against the
double series (0.00406235 q a⁴/D), on meshes of n cells a side (DKT: gmsh triangles of size
a/n), error and CPU time (``time.process_time``: build = mesh + assembly, solve = the sparse
factorisation and solve) against the number of free dofs; medians of ``--reps`` runs, the
elements and meshes interleaved within each run.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_discretisation.py --elements   # about 3 min

Writes benchmarks/results/discretisation-elements.csv and figures/discretisation-elements.png.
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))

from bench_contact import run_in_subprocess  # noqa: E402

TOLS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8, 1e-10)
REF_MESH = 256
COARSEST = 8


def _quantities(res):
    from plateqp.estimate import Quantities

    q = Quantities.of(res)
    return {"w": q.w_grid, "w_max": q.w_max, "R": q.reactions, "p": q.p_max}  # the grid view


def errors(q, ref):
    """Relative errors of a mesh's quantities against the reference's."""
    step = (ref["w"].shape[0] - 1) // (COARSEST)
    s = (q["w"].shape[0] - 1) // COARSEST
    ew = float(np.nanmax(np.abs(q["w"][::s, ::s] - ref["w"][::step, ::step])) / ref["w_max"])
    eR = float(np.abs(q["R"] - ref["R"]).max() / np.abs(ref["R"]).max()) if ref["R"].size else float("nan")
    ep = abs(q["p"] / ref["p"] - 1) if ref["p"] else float("nan")
    return ew, eR, ep


def _solve_group(args, out):
    """In a fresh interpreter: one family × mesh × backend, every tolerance (or the exact one)."""
    name, n, backend, formulation, tols = args
    warnings.simplefilter("ignore")
    import plateqp as pq
    from plateqp.model.assembly import build_model
    from plateqp.scenes.families import family

    sc = family(name, n)
    model = build_model(sc)
    rows = []
    pq.solve(family(name, 8), backend=backend, formulation=formulation, accuracy=1e-3)  # warm-up imports
    for tol in tols:
        try:
            r = pq.solve(sc, backend=backend, formulation=formulation, accuracy=tol, model=model)
            q = _quantities(r)
            rows.append({"tol": tol, "status": r.status.value, "solve": r.times["solve"],
                         "kkt": r.kkt.worst, "q": q})
        except Exception as exn:  # recorded, not hidden
            rows.append({"tol": tol, "status": f"error: {type(exn).__name__}: {str(exn)[:80]}"})
    out.put({"rows": rows})


def navier_centre(n_terms: int = 401) -> float:
    """w D / (q a⁴) at the centre of a simply supported square under uniform q: Navier's series
    16/π⁶ Σ_{m,n odd} (−1)^((m+n)/2−1) / (m n (m² + n²)²) (Timoshenko & Woinowsky-Krieger § 30)."""
    m = np.arange(1, n_terms + 1, 2, dtype=float)[:, None]
    k = np.arange(1, n_terms + 1, 2, dtype=float)[None, :]
    sign = (-1.0) ** ((m - 1) / 2 + (k - 1) / 2)
    return 16 / np.pi**6 * float(np.sum(sign / (m * k * (m**2 + k**2) ** 2)))


def _element_scene(element: str, n: int):
    import plateqp as pq

    return pq.Scene(name=f"navier-{element}-{n}", plate=pq.Plate(a=1.0, b=1.0, h=0.01, E=1.0e7, nu=0.3),
                    mesh=pq.MeshSpec(n, n, element, size=1.0 / n if element == "dkt" else None),
                    edges={k: "simple" for k in ("left", "right", "bottom", "top")}, loads=[pq.UniformLoad(1.0)])


def elements_study(meshes, reps: int, out: Path) -> list[dict]:
    """DKT against ACM and BFS on Navier's square: error and CPU time against dofs (see the docstring)."""
    import plateqp as pq
    from plateqp.model.assembly import build_model
    from plateqp.solving import solve_two_sided

    ref_coef = navier_centre()
    elements = ("acm", "bfs", "dkt")
    times: dict[tuple[str, int], list[tuple[float, float]]] = {(e, n): [] for e in elements for n in meshes}
    facts: dict[tuple[str, int], tuple[int, float]] = {}
    build_model(_element_scene("dkt", 4))  # warm-up: imports, gmsh
    for rep in range(reps):
        for n in meshes:
            for el in elements:
                sc = _element_scene(el, n)
                t0 = time.process_time()
                model = build_model(sc)
                t1 = time.process_time()
                u, _, _ = solve_two_sided(model)
                t2 = time.process_time()
                times[(el, n)].append((t1 - t0, t2 - t1))
                if rep == 0:
                    res = pq.solve(sc, model=model)
                    w = float(res.deflection(0.5, 0.5))
                    facts[(el, n)] = (model.n_free, w * sc.plate.D / ref_coef - 1.0)
        print(f"run {rep + 1}/{reps} done", flush=True)
    rows = []
    for el in elements:
        for n in meshes:
            t = np.array(times[(el, n)])
            dofs, err = facts[(el, n)]
            rows.append({"element": el, "mesh": n, "dofs": dofs, "err_w_centre": err,
                         "build_cpu_s": float(np.median(t[:, 0])), "solve_cpu_s": float(np.median(t[:, 1])),
                         "total_cpu_s": float(np.median(t.sum(axis=1))), "reps": reps})
            r = rows[-1]
            print(f"  {el:4s} {n:4d} dofs {dofs:7d} err {err:+.3e} build {r['build_cpu_s']:.4f} s "
                  f"solve {r['solve_cpu_s']:.4f} s", flush=True)
    out.parent.mkdir(parents=True, exist_ok=True)
    keys = list(rows[0])
    with open(out, "w", newline="") as fh:
        wr = csv.DictWriter(fh, keys)
        wr.writeheader()
        wr.writerows(rows)
    _plot_elements(rows, elements)
    return rows


def _plot_elements(rows, elements):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4.2))
    for el in elements:
        r = [x for x in rows if x["element"] == el]
        d = [x["dofs"] for x in r]
        a1.loglog(d, [abs(x["err_w_centre"]) for x in r], "o-", label=el.upper())
        a2.loglog(d, [x["total_cpu_s"] for x in r], "o-", label=el.upper())
    a1.set_xlabel("free dofs")
    a1.set_ylabel("|w centre / Navier − 1|")
    a2.set_xlabel("free dofs")
    a2.set_ylabel("CPU s (build + solve, median)")
    for a in (a1, a2):
        a.legend()
        a.grid(True, which="both", lw=0.3)
    fig.suptitle("Simply supported square, uniform load: elements against Navier's series", fontsize=10)
    fig.tight_layout()
    (HERE / "figures").mkdir(exist_ok=True)
    fig.savefig(HERE / "figures" / "discretisation-elements.png", dpi=90)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--elements", action="store_true", help="DKT against ACM/BFS on Navier's square (see the docstring)")
    ap.add_argument("--reps", type=int, default=5, help="--elements: runs per element and mesh (medians)")
    ap.add_argument("--families", default="grid_rigid,grid_elastic,floating,bed")
    ap.add_argument("--max-mesh", type=int, default=128)
    ap.add_argument("--backend", default="clarabel", help="the iterative backend (primal formulation)")
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per family × mesh × backend")
    ap.add_argument("--out", default=str(HERE / "results" / "discretisation.csv"))
    args = ap.parse_args(argv)
    if args.elements:
        meshes = [n for n in (4, 8, 16, 32, 64, 128) if n <= args.max_mesh]
        out = Path(args.out) if args.out != str(HERE / "results" / "discretisation.csv") \
            else HERE / "results" / "discretisation-elements.csv"
        elements_study(meshes, args.reps, out)
        return 0
    from plateqp.studies import auto_tolerance
    from plateqp.scenes.families import family

    meshes = [n for n in (8, 16, 32, 64, 128) if n <= args.max_mesh]
    fams = args.families.split(",")
    out_rows = []
    from plateqp.progress import track  # a bar on a terminal only
    for name in track(fams, "families"):
        t0 = time.perf_counter()
        ref = run_in_subprocess(_solve_group, (name, REF_MESH, "pdas", "primal", (1e-12,)), 3 * args.timeout)
        if "rows" not in ref or "q" not in ref["rows"][0]:
            print(f"{name}: reference failed: {ref}")
            continue
        rq = ref["rows"][0]["q"]
        print(f"{name}: reference {REF_MESH}² in {time.perf_counter() - t0:.1f} s, max |w| {rq['w_max']:.4g}")
        for n in meshes:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                auto, _ = auto_tolerance(family(name, n), backend="pdas", formulation="primal")
            for backend, tols in (("pdas", (1e-12,)), (args.backend, TOLS)):
                got = run_in_subprocess(_solve_group, (name, n, backend, "primal", tols), args.timeout)
                for r in got.get("rows", [{"tol": t, "status": got.get("status", "timeout")} for t in tols]):
                    row = {"family": name, "mesh": n, "backend": backend, "tol": r["tol"], "status": r["status"],
                           "solve_s": r.get("solve"), "kkt_worst": r.get("kkt"), "auto_tol": auto}
                    if "q" in r:
                        row["err_w"], row["err_R"], row["err_bed"] = errors(r["q"], rq)
                    out_rows.append(row)
                    print(f"  {name} {n:4d}² {backend:9s} tol {r['tol']:.0e} {r['status']:>10s} "
                          f"err w {row.get('err_w', float('nan')):.2e} R {row.get('err_R', float('nan')):.2e} "
                          f"bed {row.get('err_bed', float('nan')):.2e}  auto tol {auto:.1e}", flush=True)
    keys = ["family", "mesh", "backend", "tol", "status", "solve_s", "kkt_worst", "err_w", "err_R", "err_bed", "auto_tol"]
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w", newline="") as fh:
        w = csv.DictWriter(fh, keys)
        w.writeheader()
        for r in out_rows:
            w.writerow({k: r.get(k) for k in keys})
    plot(out_rows, fams, args.backend)
    return 0


def plot(rows, fams, backend):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    figdir = HERE / "figures"
    figdir.mkdir(exist_ok=True)
    for name in fams:
        fr = [r for r in rows if r["family"] == name and "err_w" in r]
        if not fr:
            continue
        key = "err_bed" if name == "bed" else "err_R"
        label = "bed pressure" if name == "bed" else "reactions"
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        meshes = sorted({r["mesh"] for r in fr})
        colours = plt.cm.viridis(np.linspace(0, 0.9, len(meshes)))
        for n, col in zip(meshes, colours):
            it = sorted((r for r in fr if r["mesh"] == n and r["backend"] == backend), key=lambda r: -r["tol"])
            ex = [r for r in fr if r["mesh"] == n and r["backend"] == "pdas"]
            if it:
                ax.loglog([r["tol"] for r in it], [max(r[key], 1e-16) for r in it], "o-", color=col, label=f"{n}²")
            if ex:
                ax.axhline(max(ex[0][key], 1e-16), color=col, ls=":", lw=1)
            if it:
                ax.axvline(it[0]["auto_tol"], color=col, ls="--", lw=0.8)
        ax.invert_xaxis()
        ax.set_xlabel(f"{backend} tolerance (accuracy=…)")
        ax.set_ylabel(f"relative error of {label} vs {REF_MESH}² reference")
        ax.set_title(f"{name}: solver error meets mesh error (dotted: exact solve of each mesh;\n"
                     "dashed: tolerance chosen by accuracy=\"auto\")", fontsize=9)
        ax.legend(title="mesh", fontsize=8)
        fig.tight_layout()
        fig.savefig(figdir / f"discretisation-{name}.png", dpi=90)
        plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
