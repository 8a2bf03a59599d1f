"""The kernel's share of a solve's CPU time, and what the memory settings of glibc and NumPy
change in it.

CPU time (``time.process_time``, what every goal here counts) is user time plus system time.
On Linux a large solve spends a fifth of it or more in the kernel: each block of fresh memory
it touches is paged in and zeroed there, and glibc hands a large block back to the kernel when
it is freed (``munmap``, or a trim of the heap), so the next solve pays those pages again. Raw
CHOLMOD does the same. Two more things move that share, each set in the environment before the
process starts:

* "kept": ``MALLOC_MMAP_THRESHOLD_=4294967296 MALLOC_TRIM_THRESHOLD_=8589934592``, glibc's
  settings that keep freed blocks in the process for the next solve (large blocks from the
  heap, not from ``mmap``; the heap never trimmed). The process then keeps its peak memory
  after a solve.
* "small pages": ``NUMPY_MADVISE_HUGEPAGE=0``. NumPy asks the kernel for huge pages for every
  array of 4 MB or more (``madvise(MADV_HUGEPAGE)``); where the kernel's transparent huge pages
  are set to ``madvise`` with ``defrag`` ``madvise`` (a common default), a page fault in such
  memory may stall on a synchronous compaction of memory to find a huge page (numpy/numpy#31590
  on GitHub), and the mark stays on the memory after NumPy frees it.

Neither is set by plateqp: both change the whole process (its other arrays, its memory kept
after a solve); they are the user's choice, for a process that solves many times (a scripted
sweep, a benchmark).

Rows: for each scene and mesh, and each setting ("default": none), the user and system time of
raw (bench_fast.raw_cholmod: one cvxopt CHOLMOD symbolic + numeric + solve of the plate's
matrix) and of ``pq.solve`` (accuracy as bench_fast.reachable), medians of ``--repeat`` solves
after one unmeasured solve of each, interleaved in one fresh process a (scene, mesh, setting);
the settings' processes alternate over ``--rounds`` (their order reversed every other round)
and the table gives the median over the rounds. Every timed solve passes its KKT check.

    python benchmarks/bench_kernel.py [--scenes bed,grid] [--meshes 256,512] [--repeat 3] [--rounds 2]

Writes benchmarks/results/kernel.csv and prints a Markdown table. Linux with glibc only (the
settings are glibc's); elsewhere it says so and stops.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before NumPy loads
    os.environ.setdefault(_var, "1")

import argparse
import json
import platform
import resource
import statistics
import subprocess
import sys
import warnings
from pathlib import Path

HERE = Path(__file__).parent

#: the environments measured (see the module docstring)
SETTINGS = {"default": {},
            "kept": {"MALLOC_MMAP_THRESHOLD_": "4294967296", "MALLOC_TRIM_THRESHOLD_": "8589934592"},
            "small pages": {"NUMPY_MADVISE_HUGEPAGE": "0"}}
VARIABLES = {k for env in SETTINGS.values() for k in env}


def _times() -> tuple[float, float]:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime, r.ru_stime


def child(scene_kind: str, n: int, repeat: int) -> dict:
    """In this process: raw and pq.solve, one unmeasured solve of each, then ``repeat`` of each
    interleaved; the medians of their user and system times."""
    sys.path.insert(0, str(HERE))
    import bench_fast as bf

    import plateqp as pq
    from plateqp.model.assembly import build_model

    scene = bf.make_scene(scene_kind, n)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = build_model(scene)
        acc = bf.reachable(scene, model)
    A, f = bf.plate_matrix(scene_kind, model)
    Ac = bf.to_cvxopt(A)
    del model, A

    def run_pq():
        res = pq.solve(scene, accuracy=acc)
        if not res.kkt.ok:
            raise SystemExit(f"{scene_kind} {n}²: pq.solve not OPTIMAL at {acc:g} (worst {res.kkt.worst:.1e})")

    def run_raw():
        bf.raw_cholmod(Ac, f)

    run_raw()
    run_pq()
    times: dict[str, list] = {"raw": [], "pq": []}
    for _ in range(repeat):
        for name, fn in (("raw", run_raw), ("pq", run_pq)):
            u0, s0 = _times()
            fn()
            u1, s1 = _times()
            times[name].append((u1 - u0, s1 - s0))
    out = {"accuracy": acc}
    for name, ts in times.items():
        out[f"{name}_user"] = statistics.median(t[0] for t in ts)
        out[f"{name}_sys"] = statistics.median(t[1] for t in ts)
    return out


def measure(scene_kind: str, n: int, setting: str, repeat: int) -> dict:
    """:func:`child` in a fresh interpreter with the setting's environment."""
    env = {k: v for k, v in os.environ.items() if k not in VARIABLES}
    env.update(SETTINGS[setting])
    proc = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--child", scene_kind, str(n), str(repeat)],
                          env=env, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise SystemExit(f"{scene_kind} {n}² ({setting}): the child failed:\n{proc.stderr[-2000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="bed,grid")
    ap.add_argument("--meshes", default="256,512")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--out", default=str(HERE / "results" / "kernel.csv"))
    ap.add_argument("--child", nargs=3, metavar=("SCENE", "N", "REPEAT"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child[0], int(args.child[1]), int(args.child[2]))))
        return
    sys.path.insert(0, str(HERE))
    from bench_fast import write_csv

    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        why = "the settings measured here are glibc's and Linux's: nothing measured on this system"
        write_csv([{"note": why}], args.out)  # the report's section says so
        print(f"bench_kernel: {why}")
        return

    cases = [(s, int(m)) for s in args.scenes.split(",") if s for m in args.meshes.split(",") if m]
    runs: dict[tuple, list] = {}
    for r in range(args.rounds):
        for scene_kind, n in cases:
            order = list(SETTINGS) if r % 2 == 0 else list(SETTINGS)[::-1]
            for setting in order:
                runs.setdefault((scene_kind, n, setting), []).append(measure(scene_kind, n, setting, args.repeat))
                print(f"  round {r + 1}: {scene_kind} {n}² {setting} done", file=sys.stderr, flush=True)
    rows = []
    for (scene_kind, n, setting), got in runs.items():
        row = {"scene": scene_kind, "mesh": f"{n}²", "setting": setting, "accuracy": got[0]["accuracy"]}
        for key in ("raw_user", "raw_sys", "pq_user", "pq_sys"):
            row[key] = statistics.median(g[key] for g in got)
        row["raw_cpu"] = row["raw_user"] + row["raw_sys"]
        row["pq_cpu"] = row["pq_user"] + row["pq_sys"]
        row["raw_sys_share"] = row["raw_sys"] / row["raw_cpu"]
        row["pq_sys_share"] = row["pq_sys"] / row["pq_cpu"]
        row["ratio"] = row["pq_cpu"] / row["raw_cpu"]
        rows.append(row)
    write_csv(rows, args.out)
    head = ["scene", "mesh", "setting", "raw user s", "raw sys s", "pq user s", "pq sys s", "pq ÷ raw"]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for row in rows:
        print(f"| {row['scene']} | {row['mesh']} | {row['setting']} | {row['raw_user']:.3f} | {row['raw_sys']:.3f} | "
              f"{row['pq_user']:.3f} | {row['pq_sys']:.3f} | {row['ratio']:.2f} |")


if __name__ == "__main__":
    main()
