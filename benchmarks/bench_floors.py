"""What the speed goals not met are up against: the floors, measured.

Some goals of the table in bench_goals.py stay out of reach; this script measures what bounds
each from below, against the same "raw" (one cvxopt CHOLMOD symbolic analysis + numeric
factorisation + solve of the plate's matrix, bench_fast.raw_cholmod; CPU time, one BLAS thread,
medians of ``--repeat``):

* ``grid`` (bench_fast's slab on four walls and 30 × 30 rigid posts, at ``--grid-meshes``): the
  condensed method factorises K once with the posts' deflections ordered last (the trailing block
  is the Schur complement on the posts, from which the flexibility follows). Rows: the numeric
  factorisation of K in CHOLMOD's own order, and with the posts last (time, and multiply-adds
  counted from the factor's supernodes), and how many posts carry the answer (pq.solve's
  active set).
* ``bed`` (bench_fast's free plate on a tensionless bed, at ``--bed-mesh``): a sweep of the
  column's load or of the bed's modulus, 11 values as bench_sweep_reuse's. Rows: the springs
  that change between two values (their median and largest count: a load step moves the contact
  line, a modulus step changes every spring in contact), one numeric refactorisation of the
  plate with every spring bonded on its kept analysis, and CHOLMOD's own in-place update of
  ``k`` springs (``cholmod_l_updown`` in cvxopt's CHOLMOD, called through ctypes: scikit-sparse's
  route, which cvxopt's binding does not expose), the first on a fresh factor apart (CHOLMOD turns
  its supernodal factor into a simplicial one then).
* The whole ``pq.solve`` (the build included; every solve KKT-checked): on the grid by its default
  route (the condensed method) and by the sparse method (``options={"method": "sparse"}``), the
  two interleaved; on the bed at ``--small-bed-meshes`` with the coarse mesh's prediction of its
  contact set timed alone; for each, the same kind of scene at 8² cells (the grid's with 3 × 3
  posts), whose plate's linear algebra is a few per cent of its solve: what any solve costs
  besides its plate (the build, the scaling, the checks, the answer's report).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_floors.py [--grid-meshes 64,128] [--bed-mesh 128] \\
        [--small-bed-meshes 64]

Writes benchmarks/results/floors.csv (one row a quantity: value, unit, and value ÷ raw where
it is a time) and prints it.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before NumPy loads
    os.environ.setdefault(_var, "1")

import argparse
import ctypes
import statistics
import sys
import warnings
from pathlib import Path

import numpy as np
import scipy.sparse as sp

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_fast import ACCURACY, grid_rigid, make_scene, plate_matrix, raw_cholmod, to_cvxopt, write_csv  # noqa: E402
from bench_sweep_reuse import values_for  # noqa: E402
from timing import cpu  # noqa: E402

import plateqp as pq  # noqa: E402
from plateqp.linalg import Cholesky, SchurFactor  # noqa: E402
from plateqp.linalg import seam  # noqa: E402
from plateqp.linalg.cholmod import lower  # noqa: E402
from plateqp.model.assembly import build_model  # noqa: E402
from plateqp.studies.sweep import sweep  # noqa: E402


def median_cpu(fn, repeat: int) -> float:
    """The median CPU time of ``repeat`` calls of ``fn``."""
    return statistics.median(cpu(fn)[0] for _ in range(repeat))


def median_raw(A, f, repeat: int) -> float:
    Ac = to_cvxopt(A)
    raw_cholmod(Ac, f)
    return median_cpu(lambda: raw_cholmod(Ac, f), repeat)


def row(scene, mesh, quantity, value, unit, raw=None) -> dict:
    return {"scene": scene, "mesh": f"{mesh}²", "quantity": quantity, "value": value, "unit": unit,
            "raw_s": raw if raw is not None else "", "per_raw": value / raw if (raw and unit == "s") else ""}


def grid_rows(n: int, repeat: int) -> list[dict]:
    scene = make_scene("grid", n)
    model = build_model(scene)
    A, f = plate_matrix("grid", model)
    raw = median_raw(A, f, repeat)
    K = sp.csc_matrix(model.K)
    posts = np.unique(model.contacts.B.tocsr().indices)

    def plain():
        ch = Cholesky("cvxopt")
        T = lower(K, None, upper=ch.upper)
        ch.analyse(T)
        return ch, T

    times, flops = [], None
    for _ in range(repeat):
        ch, T = plain()
        times.append(cpu(lambda: ch.factor(T))[0])
        flops = ch.flops()
    last_t, last_flops = [], None
    for _ in range(repeat):
        S = SchurFactor(K, posts)
        last_t.append(S.stats["factor_s"])  # its numeric factorisation alone (wall time; one BLAS thread)
        last_flops = S.chol.flops()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = pq.solve(scene, accuracy=ACCURACY)
    active = int(np.asarray(res.extras["active"]).sum())
    routes = whole_solves(scene, {"condensed route (the default)": {},
                                  "sparse method (option method='sparse')": {"method": "sparse"}}, repeat)
    return [row("grid", n, "numeric factorisation, CHOLMOD's order", statistics.median(times), "s", raw),
            row("grid", n, "numeric factorisation, posts last", statistics.median(last_t), "s", raw),
            row("grid", n, "multiply-adds, CHOLMOD's order", flops, "flop"),
            row("grid", n, "multiply-adds, posts last", last_flops, "flop"),
            row("grid", n, "posts", float(posts.size), "count"),
            row("grid", n, "posts carrying the answer", float(active), "count"),
            *(row("grid", n, f"pq.solve, {name}", t, "s", raw) for name, t in routes.items()),
            row("grid", n, f"pq.solve of the same kind of scene at {SMALL}² (a solve's fixed cost)",
                fixed_cost("grid", repeat), "s", raw)]


#: the cells a side of the plate whose whole solve stands for a solve's fixed cost (its plate's
#: linear algebra is a few per cent of it: raw 0.5 ms on the bed, 0.3 on the grid)
SMALL = 8


def whole_solves(scene, options: dict[str, dict], repeat: int) -> dict[str, float]:
    """Median CPU time of the whole pq.solve (the build included) with each ``options``, the
    options interleaved; each solve KKT-checked."""
    times: dict[str, list[float]] = {name: [] for name in options}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name, opts in options.items():  # the first call's imports paid
            pq.solve(scene, accuracy=ACCURACY, options=opts)
        for _ in range(repeat):
            for name, opts in options.items():
                dt, res = cpu(lambda: pq.solve(scene, accuracy=ACCURACY, options=opts))
                if not res.kkt.ok:
                    raise SystemExit(f"{scene.name} ({name}): the KKT check failed ({res.status.value})")
                times[name].append(dt)
    return {name: statistics.median(t) for name, t in times.items()}


def fixed_cost(kind: str, repeat: int) -> float:
    """The whole pq.solve of ``kind``'s scene at SMALL² cells (the grid's with 3 × 3 posts: 30 × 30
    do not fit): what a solve costs besides its plate."""
    return whole_solves(grid_rigid(SMALL, 3) if kind == "grid" else make_scene(kind, SMALL), {"": {}}, repeat)[""]


def small_bed_rows(n: int, repeat: int) -> list[dict]:
    """The bed at ``n``² (its goal is set on the whole solve): the whole solve, a solve's fixed cost
    and the coarse mesh's prediction of its contact set (plateqp.contact.predict), against raw."""
    from plateqp.contact.predict import predicted_set

    scene = make_scene("bed", n)
    model = build_model(scene)
    A, f = plate_matrix("bed", model)
    raw = median_raw(A, f, repeat)
    whole = whole_solves(scene, {"": {}}, repeat)[""]
    predicted_set(model)
    predict = median_cpu(lambda: predicted_set(model), repeat)
    return [row("bed", n, "pq.solve (the default route)", whole, "s", raw),
            row("bed", n, f"pq.solve of the same kind of scene at {SMALL}² (a solve's fixed cost)", fixed_cost("bed", repeat),
                "s", raw),
            row("bed", n, "the coarse mesh's prediction of the contact set", predict, "s", raw)]


def _updown(ch: Cholesky, C: sp.csc_matrix):
    """``updown(update)``: ``L Lᵀ ± C Cᵀ`` in place by CHOLMOD's cholmod_l_updown (C's rows in
    the factor's order), C handed to CHOLMOD once, before any call is timed."""
    d = ch.direct
    fn = d.s.c.cholmod_l_updown
    fn.argtypes = [ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p]
    fn.restype = ctypes.c_int
    C = sp.csc_matrix(C)
    C.sort_indices()
    p, i = C.indptr.astype(np.int64), C.indices.astype(np.int64)
    x = np.ascontiguousarray(C.data, dtype=float)
    S = seam._Sparse(C.shape[0], C.shape[1], int(p[-1]), p.ctypes.data, i.ctypes.data, None, x.ctypes.data, None, 0,
                     seam._ITYPE_LONG, seam._XTYPE_REAL, seam._DTYPE_DOUBLE, 1, 1)

    def updown(update: bool, arrays=(p, i, x)) -> None:  # the arrays S points into, held as long as it
        if not fn(1 if update else 0, ctypes.byref(S), d.L, d.cm):
            raise RuntimeError("cholmod_l_updown failed")

    return updown


def bed_rows(n: int, repeat: int) -> list[dict]:
    scene = make_scene("bed", n)
    model = build_model(scene)
    A, f = plate_matrix("bed", model)
    raw = median_raw(A, f, repeat)
    out = []
    for kind in ("load", "stiffness"):
        path, vals = values_for("bed", scene, 11, kind)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = sweep(scene, path, vals, accuracy=ACCURACY, executor="serial", progress=False,
                        refine_breakpoints=False)
        sets = [np.asarray(r["active"], dtype=bool) for r in res.rows]
        if kind == "load":
            moved = [int((a ^ b).sum()) for a, b in zip(sets, sets[1:])]
        else:  # every spring in contact at either value changes its stiffness
            moved = [int((a | b).sum()) for a, b in zip(sets, sets[1:])]
        out += [row("bed", n, f"springs changed a value, {path} (median)", float(np.median(moved)), "count"),
                row("bed", n, f"springs changed a value, {path} (largest)", float(max(moved)), "count")]
    T = sp.triu(A, format="csc")
    T.sort_indices()
    ch = Cholesky("cvxopt")
    if ch.direct is None:
        raise SystemExit("bench_floors needs cvxopt's CHOLMOD through plateqp's seam")
    ch.analyse(T)
    ch.factor(T)
    out.append(row("bed", n, "numeric refactorisation (analysis kept)", median_cpu(lambda: ch.factor(T), repeat),
                   "s", raw))
    # springs along a ring (a contact line), in the factor's order
    c = model.contacts
    perm = seam.view(int(seam.view(ch.direct.L.value, 3, np.uint64)[seam._PERM]), A.shape[0], np.int64)
    where = np.empty_like(perm)
    where[perm] = np.arange(perm.size)
    centre = c.xy.mean(axis=0)
    radius = np.hypot(*(c.xy - centre).T)
    ring = np.argsort(np.abs(radius - 0.3 * radius.max()))
    Bc = c.B.tocsr()

    def springs(k):
        rows = np.sort(ring[:k])
        Br = Bc[rows].tocoo()
        w = np.sqrt(1.0 / c.rho[rows])
        return sp.csc_matrix((w[Br.row] * Br.data, (where[Br.col], Br.row)), shape=(A.shape[0], k))

    first = []
    for _ in range(repeat):
        ch.analyse(T)  # a factor CHOLMOD updated is simplicial: a new analysis makes it supernodal again
        ch.factor(T)
        one = _updown(ch, springs(1))
        first.append(cpu(lambda: one(False))[0])
        one(True)
    out.append(row("bed", n, "in-place downdate of 1 spring on a fresh factor (its conversion)",
                   statistics.median(first), "s", raw))
    for k in (16, 64, 256):
        updown = _updown(ch, springs(k))
        t = []
        for _ in range(repeat):
            t.append(cpu(lambda: updown(False))[0])
            updown(True)
        out.append(row("bed", n, f"in-place downdate of {k} springs (simplicial factor)", statistics.median(t), "s",
                       raw))
    simplicial = median_cpu(lambda: ch.solve(f), repeat)
    ch.analyse(T)
    ch.factor(T)
    supernodal = median_cpu(lambda: ch.solve(f), repeat)
    out += [row("bed", n, "one solve, supernodal factor", supernodal, "s", raw),
            row("bed", n, "one solve, simplicial factor (after an update)", simplicial, "s", raw)]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid-meshes", default="64,128")
    ap.add_argument("--bed-mesh", type=int, default=128)
    ap.add_argument("--small-bed-meshes", default="64", help="the bed's whole solve, fixed cost and prediction")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--out", default=str(HERE / "results" / "floors.csv"))
    a = ap.parse_args()
    rows = []
    for n in (int(x) for x in a.grid_meshes.split(",") if x.strip()):
        rows += grid_rows(n, a.repeat)
    if a.bed_mesh:
        rows += bed_rows(a.bed_mesh, a.repeat)
    for n in (int(x) for x in a.small_bed_meshes.split(",") if x.strip()):
        rows += small_bed_rows(n, a.repeat)
    print("| scene | mesh | quantity | value | unit | ÷ raw |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        ratio = f"{r['per_raw']:.3g}" if r["per_raw"] != "" else ""
        print(f"| {r['scene']} | {r['mesh']} | {r['quantity']} | {r['value']:.4g} | {r['unit']} | {ratio} |", flush=True)
    write_csv(rows, a.out)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
