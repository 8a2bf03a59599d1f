"""The speed goals in one table: every goal, its figure measured today, met or not.

Each figure is CPU time (``time.process_time``, BLAS on one thread) ÷ "raw": one cvxopt
CHOLMOD symbolic analysis + numeric factorisation + solve of the same plate matrix, called
directly (``bench_fast.raw_cholmod``), the steps interleaved in one process, medians of
``--repeat`` (of ``--big-repeat`` from 512²: one noisy run of 512² put the bed at 2.00 where the
run before had 1.64). Every timed solve must pass its KKT check at accuracy 1e-10
(a failed check stops the run), or, where the plate's rounding floor lies above 1e-10 (the bed
from 256²), at the first step of 1, 2, 5 × 10ᵏ at or above three times that floor (column
``accuracy``). The rows:

* ``solve``: the whole ``pq.solve(scene, accuracy=1e-10)`` (assembly included) on bench_fast's
  grid (a slab on four walls, 30 × 30 rigid posts) and bed (a free plate on a tensionless bed)
  at ``--meshes`` and ``--big`` (medians of ``--big-repeat``), and on bench_tri's DKT disc (R = 1, 12 posts, q + P)
  at ``--disc-sizes`` (R/n; the mesh generated inside the timed call: no kept mesh). Goals: ≤ 3× at 64²,
  ≤ 2.5× at 128², ≤ 2× at 256² and 512²; on the disc ≤ 4× at about 12k dofs and ≤ 2.5× at
  ≥ 100k dofs. ``ratio_lo`` and ``ratio_hi``: the lowest and the highest of the repeats' own
  ratios (each repeat times one raw and one solve, next to each other): a goal between them is
  met or missed by the machine's state, not by the code.
* ``memory``: the peak resident memory of ``pq.solve`` on the built model above what the process
  held before it, against the raw factorisation's, each in a fresh interpreter (Linux VmHWM
  reset through /proc/self/clear_refs), medians of ``--memory-repeat`` interleaved pairs (the
  heap's layout moves a solve's peak by tens of MB from one process to the next), at
  ``--memory-meshes`` and ``--memory-disc``. Goal ≤ 1.5×
  at 256² and on the disc from R/100 (about 110k dofs); smaller plates are shown without a goal.
* ``sweep``: bench_sweep_reuse's sweeps at ``--sweep-mesh`` (a gap, a load and a spring
  stiffness on the grid and on the bed; ``--values`` values, serial, reuse on): CPU time per
  value after the first ÷ raw. Goal ≤ 0.3 at 128², every value OPTIMAL (at 1e-10, or as above
  at the accuracy the sweep's largest floor allows).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_goals.py            # the full table (~10 min)
    python benchmarks/bench_goals.py --meshes 32 --big "" --disc-sizes 8 --memory-meshes "" \\
        --memory-disc "" --sweep-mesh 32 --values 3 --repeat 1         # a smoke run

Writes benchmarks/results/goals.csv and prints a Markdown table.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before NumPy loads
    os.environ.setdefault(_var, "1")

import argparse
import statistics
import sys
import warnings
from pathlib import Path

import numpy as np
import scipy.sparse as sp

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
import bench_fast as bf  # noqa: E402
import bench_sweep_reuse as bsr  # noqa: E402
from bench_contact import run_in_subprocess  # noqa: E402
from bench_scaling import _status_kb  # noqa: E402

import plateqp as pq  # noqa: E402
from plateqp.model.assembly import build_model  # noqa: E402

#: pq.solve ÷ raw asked for on the grid and the bed, by mesh (the largest mesh not above n)
SOLVE_GOALS = {64: 3.0, 128: 2.5, 256: 2.0}
#: pq.solve ÷ raw asked for on the DKT disc: ≤ 4× near 12k dofs, ≤ 2.5× from 100k dofs
DISC_GOALS = ((100_000, 2.5), (10_000, 4.0))
MEMORY_GOAL = 1.5
SWEEP_GOAL = bsr.GOAL


def solve_goal(n: int) -> float | None:
    keys = [k for k in SOLVE_GOALS if k <= n]
    return SOLVE_GOALS[max(keys)] if keys else None


def disc_goal(dofs: int) -> float | None:
    return next((g for lo, g in DISC_GOALS if dofs >= lo), None)


def disc_scene(n: int) -> pq.Scene:
    import bench_tri  # imports bench_fast itself: loaded here, when a disc is asked for

    return bench_tri.disc_scene(n)


def scene_for(kind: str, n: int) -> pq.Scene:
    return disc_scene(n) if kind == "disc" else bf.make_scene(kind, n)


def plate_matrix(kind: str, model) -> tuple[sp.csc_matrix, np.ndarray]:
    if kind == "disc":
        return sp.csc_matrix(model.K), np.asarray(model.f, dtype=float)
    return bf.plate_matrix(kind, model)


def cold() -> None:
    """No kept triangle mesh: every timed solve meshes its plate (plateqp keeps the last
    geometries' meshes; a second solve of one plate would time the kept one)."""
    from plateqp.model import trimesh

    trimesh.MESHES.clear()


def solve_row(kind: str, n: int, repeat: int) -> dict:
    """raw and the whole pq.solve interleaved (the order alternating), medians; cold."""
    scene = scene_for(kind, n)
    model = build_model(scene)
    K, f = plate_matrix(kind, model)
    A = bf.to_cvxopt(K)
    acc = bf.reachable(scene, model)  # also pays the first call's imports
    times: dict[str, list[float]] = {"raw": [], "solve": []}
    worst, res = 0.0, None
    for r in range(repeat):
        for name in (("raw", "solve") if r % 2 == 0 else ("solve", "raw")):
            if name == "raw":
                times["raw"].append(bf.cpu(lambda: bf.raw_cholmod(A, f))[0])
                continue
            cold()
            dt, res = bf.cpu(lambda: bf.whole_solve(scene, acc))
            if not res.kkt.ok:
                raise SystemExit(f"{kind} {n}: the KKT check failed at accuracy {acc:g} ({res.status.value})")
            worst = max(worst, bf.kkt_worst(res))
            times["solve"].append(dt)
    raw, solve = float(np.median(times["raw"])), float(np.median(times["solve"]))
    pairs = np.array(times["solve"]) / np.array(times["raw"])  # each repeat's own ratio: the spread
    dofs = int(model.n_free)
    goal = disc_goal(dofs) if kind == "disc" else solve_goal(n)
    return {"goal": "solve", "scene": kind, "mesh": f"R/{n}" if kind == "disc" else f"{n}²", "dofs": dofs,
            "route": f"{res.backend}/{res.formulation}", "accuracy": acc, "repeat": repeat, "unit": "s", "raw": raw, "measured": solve,
            "ratio": solve / raw, "ratio_lo": float(pairs.min()), "ratio_hi": float(pairs.max()), "limit": goal,
            "met": None if goal is None else solve / raw <= goal, "kkt_worst": worst}


def _memory(args, q):
    """Peak resident memory (MB) of one step above what the process held before it."""
    kind, n, what = args
    warnings.simplefilter("ignore")
    bf.whole_solve(bf.grid_rigid(8, 3))  # imports paid
    scene = scene_for(kind, n)
    model = build_model(scene)
    if what == "raw":
        K, f = plate_matrix(kind, model)
        A = bf.to_cvxopt(K)
        step = lambda: bf.raw_cholmod(A, f)  # noqa: E731
    else:
        acc = bf.reachable(scene, model)
        step = lambda: pq.solve(scene, accuracy=acc, model=model)  # noqa: E731
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")  # VmHWM reset to the current RSS
    except OSError:
        q.put({"mem_mb": None})
        return
    before = _status_kb()
    out = step()
    after = _status_kb()
    ok = what == "raw" or bool(out.kkt.ok)
    q.put({"mem_mb": (after[1] - before[0]) / 1024 if before else None, "ok": ok})


def memory_row(kind: str, n: int, timeout: float, repeat: int = 3) -> dict:
    got: dict = {"raw": [], "solve": []}
    for _ in range(repeat):
        for what in ("raw", "solve"):
            one = run_in_subprocess(_memory, (kind, n, what), timeout)
            if "mem_mb" not in one:  # the child failed or timed out: said, not a blank cell
                raise SystemExit(f"{kind} {n}: the {what} memory run gave no figure: {one}")
            if one.get("ok") is False:
                raise SystemExit(f"{kind} {n}: the KKT check failed in the memory run")
            got[what].append(one["mem_mb"])
    r, s = (None if None in got[w] else statistics.median(got[w]) for w in ("raw", "solve"))
    ratio = s / r if (r and s is not None) else None
    goal = MEMORY_GOAL if n >= (100 if kind == "disc" else 256) else None  # asked at 256² and ~180k dofs
    return {"goal": "memory", "scene": kind, "mesh": f"R/{n}" if kind == "disc" else f"{n}²", "unit": "MB", "raw": r,
            "measured": s, "ratio": ratio, "limit": goal,
            "met": None if (ratio is None or goal is None) else ratio <= goal, "repeat": repeat}


def sweep_row(kind: str, n: int, values: int, repeat: int, sweep_kind: str) -> dict:
    r = bsr.row_for(kind, n, values, repeat, sweep_kind)
    return {"goal": "sweep", "scene": kind, "mesh": f"{n}²", "route": r["route"], "accuracy": r["accuracy"], "repeat": repeat,
            "detail": f"{r['path']} ({values} values)", "unit": "s", "raw": r["raw_s"], "measured": r["per_value_s"],
            "ratio": r["per_value_ratio"], "limit": SWEEP_GOAL if n >= 128 else None,
            "met": r["per_value_ratio"] <= SWEEP_GOAL if n >= 128 else None, "kkt_worst": r["kkt_worst"]}


def ints(s: str) -> list[int]:
    return [int(v) for v in s.split(",") if v.strip()]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="64,128,256", help="grid and bed meshes, medians of --repeat")
    ap.add_argument("--big", default="512", help="grid and bed meshes, medians of --big-repeat")
    ap.add_argument("--big-repeat", type=int, default=3)
    ap.add_argument("--scenes", default="grid,bed")
    ap.add_argument("--disc-sizes", default="32,128", help="DKT disc sizes R/n")
    ap.add_argument("--memory-meshes", default="256", help="grid and bed meshes of the memory rows")
    ap.add_argument("--memory-disc", default="128", help="disc sizes of the memory rows")
    ap.add_argument("--sweep-mesh", type=lambda v: int(v) if v.strip() else 0, default=128,
                    help="mesh of the sweep rows (empty or 0: none)")
    ap.add_argument("--values", type=int, default=11)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--memory-repeat", type=int, default=3, help="fresh-process pairs of each memory row")
    ap.add_argument("--timeout", type=float, default=900.0, help="wall limit of each memory run (s)")
    ap.add_argument("--out", default=str(HERE / "results" / "goals.csv"))
    a = ap.parse_args(argv)
    scenes = [s for s in a.scenes.split(",") if s]
    cases = [lambda k=k, n=n: solve_row(k, n, a.repeat) for n in ints(a.meshes) for k in scenes]
    cases += [lambda k=k, n=n: solve_row(k, n, a.big_repeat) for n in ints(a.big) for k in scenes]
    cases += [lambda n=n: solve_row("disc", n, a.repeat) for n in ints(a.disc_sizes)]
    cases += [lambda k=k, n=n: memory_row(k, n, a.timeout, a.memory_repeat) for n in ints(a.memory_meshes)
              for k in scenes]
    cases += [lambda n=n: memory_row("disc", n, a.timeout, a.memory_repeat) for n in ints(a.memory_disc)]
    cases += [lambda k=k, s=s: sweep_row(k, a.sweep_mesh, a.values, a.repeat, s)
              for k in scenes for s in bsr.KINDS] if a.sweep_mesh else []
    bf.table([], a.out, "Speed goals (CPU, one BLAS thread; ratios to raw CHOLMOD)",
             ["goal", "scene", "mesh", "route", "accuracy", "detail", "unit", "raw", "measured", "ratio", "limit", "met",
              "KKT worst"],
             cases,
             lambda r: [r["goal"], r["scene"], r["mesh"], r.get("route", ""), bf.fmt(r.get("accuracy"), "{:g}"),
                        r.get("detail", ""), r["unit"],
                        bf.fmt(r["raw"]), bf.fmt(r["measured"]), bf.fmt(r["ratio"], "{:.2f}"),
                        bf.fmt(r["limit"], "{:g}"), {True: "yes", False: "**no**", None: "–"}[r["met"]],
                        bf.fmt(r.get("kkt_worst"), "{:.1e}")])
    print(f"\nwritten {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
