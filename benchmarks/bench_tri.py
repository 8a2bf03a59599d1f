"""Triangles against the floor: pq.solve on a DKT disc ÷ one raw CHOLMOD factorisation of its K.

The scene: a disc (R = 1) simply supported on its edge, on 12 rigid posts at r = 0.7 R, under a
uniform load and a point load, meshed at R/n. "raw" is one cvxopt CHOLMOD symbolic + numeric +
solve of the same K called directly (``bench_fast.raw_cholmod``). CPU time, one BLAS thread,
the three timed steps interleaved, medians of ``--repeat``; every timed solve must pass its
KKT check. The build is split into its stages (gmsh's mesh, the DKT element stiffness, the
assembly of K: the mesh's ``assemble`` less the stiffness) and timed alone, interleaved with the rest.
Every step runs cold: no kept mesh (``trimesh.MESHES`` off) and no kept assembly pattern; one more
step, "kept", is pq.solve of the same plate again with its mesh kept (a sweep's second value).

    python benchmarks/bench_tri.py                    # R/32, R/64, R/128, medians of 5
    python benchmarks/bench_tri.py --sizes 32,64,128,181 --repeat 5

Writes benchmarks/results/triangles-speed.csv and prints a Markdown table.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before NumPy loads
    os.environ.setdefault(_var, "1")

import argparse
import math
import statistics
import sys
from pathlib import Path

import numpy as np
import scipy.sparse as sp

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.model.elements import DKT
from plateqp.model import trimesh
from plateqp.model.trimesh import TriMesh

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_fast import cpu, kkt_worst, raw_cholmod, to_cvxopt, whole_solve, write_csv


def disc_scene(n: int, R: float = 1.0) -> pq.Scene:
    posts = [pq.Support(0.7 * R * math.cos(2 * math.pi * k / 12), 0.7 * R * math.sin(2 * math.pi * k / 12))
             for k in range(12)]
    return pq.Scene(name=f"disc-R/{n}", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.02, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=R / n), edges={"all": pq.Edge("simple")},
                    loads=[pq.UniformLoad(5.0), pq.PointLoad(100.0, 0.1, 0.2)], supports=posts)


def row(n: int, repeat: int, accuracy: float = 1e-9) -> dict:
    scene = disc_scene(n)
    model = build_model(scene)
    A, f = to_cvxopt(sp.csc_matrix(model.K)), np.asarray(model.f, dtype=float)
    mesh, el = model.grid, DKT()
    D, nu = scene.plate.D, scene.plate.nu
    pos = np.full(model.n_full, -1)
    pos[model.free] = np.arange(model.n_free)
    xy = mesh.nodes[mesh.triangles]

    def assemble():  # cold: the pattern worked out again
        mesh._patterns.clear()
        return mesh.assemble(el, D, nu, pos, model.n_free)

    def kept():  # the mesh made once before, kept: a sweep's next value
        trimesh.MESHES.size = 1
        try:
            return whole_solve(scene, accuracy)
        finally:
            trimesh.MESHES.size = 0

    kept()
    steps = {"raw": lambda: raw_cholmod(A, f), "solve": lambda: whole_solve(scene, accuracy),
             "mesh": lambda: TriMesh.from_scene(scene), "stiffness": lambda: el.stiffness(xy, D, nu),
             "assemble": assemble, "build": lambda: build_model(scene), "kept": kept}
    times = {k: [] for k in steps}
    worst = 0.0
    for _ in range(repeat):
        for k, fn in steps.items():
            t, out = cpu(fn)
            times[k].append(t)
            if k in ("solve", "kept"):
                if not out.kkt.ok:
                    raise SystemExit(f"R/{n}: the KKT check failed ({out.status})")
                worst = max(worst, kkt_worst(out))
    med = {k: statistics.median(v) for k, v in times.items()}
    out = {"size": f"R/{n}", "accuracy": accuracy, "nodes": len(mesh.nodes), "triangles": len(mesh.triangles), "dofs": model.n_free,
           "nnz": model.K.nnz, "kkt_worst": worst, "repeat": repeat}
    out.update({f"{k}_s": v for k, v in med.items()})
    out["assembly_s"] = med["assemble"] - med["stiffness"]  # K from the element matrices
    out["solve_ratio"] = med["solve"] / med["raw"]
    out["kept_ratio"] = med["kept"] / med["raw"]
    out["build_ratio"] = med["build"] / med["raw"]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="32,64,128", help="R/n for each n (comma-separated)")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--accuracy", type=float, default=1e-9,
                    help="asked of every solve (1e-10 is below the rounding floor of the disc's KKT residual from R/128)")
    ap.add_argument("--out", default=str(HERE / "results" / "triangles-speed.csv"))
    args = ap.parse_args()
    try:  # the environment above already asks one thread; threadpoolctl holds BLAS to it if present
        from threadpoolctl import threadpool_limits
    except ImportError:
        from contextlib import nullcontext

        def threadpool_limits(_):
            return nullcontext()

    whole_solve(disc_scene(8))  # warm-up: imports, gmsh
    trimesh.MESHES.size = 0  # every step cold but "kept"
    rows = []
    with threadpool_limits(1):
        for n in (int(v) for v in args.sizes.split(",")):
            rows.append(row(n, args.repeat, args.accuracy))
            r = rows[-1]
            print(f"R/{n}: {r['dofs']} dofs, pq.solve ÷ raw {r['solve_ratio']:.2f}", file=sys.stderr, flush=True)
    write_csv(rows, args.out)
    print(f"\n### DKT disc, 12 posts: pq.solve ÷ raw CHOLMOD (CPU, one BLAS thread, medians of {args.repeat})\n")
    print("| mesh | nodes | dofs | KKT worst | raw s | mesh s | stiffness s | assembly s | build s | pq.solve s "
          "| **pq.solve ÷ raw** | mesh kept: pq.solve ÷ raw |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['size']} | {r['nodes']} | {r['dofs']} | {r['kkt_worst']:.1e} | {r['raw_s']:.3f} | {r['mesh_s']:.3f} | "
              f"{r['stiffness_s']:.3f} | {r['assembly_s']:.3f} | {r['build_s']:.3f} | {r['solve_s']:.3f} | "
              f"**{r['solve_ratio']:.2f}** | {r['kept_ratio']:.2f} |")


if __name__ == "__main__":
    main()
