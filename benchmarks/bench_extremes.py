"""Extremes: every installed backend × formulation on scenes at the edges of
the parameter space, each against a reference that does not come from the solver under test.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_extremes.py                  # everything
    python benchmarks/bench_extremes.py --cases units-E1,gap-settle-1e2 --backends lemke,osqp
    python benchmarks/bench_extremes.py --list                                  # the cases

Cases (mesh 16² ACM unless named; a 1 × 1 plate, h = 0.02, E = 1e7, ν = 0.3, simply supported,
on a 3 × 3 grid of rigid one-sided supports at the quarter points, a uniform load q = 10 and a
point load P = 100 at (0.7, 0.6): four supports carry it, five lift off):

- units: E = 1 and 1e11 with the gaps scaled by 1/E, the same nondimensional problem: the
  reference is the E = 1e7 solution (reactions identical, w·E identical).
- thickness: h/a = 1e-3 and 0.2 with the gaps scaled by 1/D: w·D and R identical (Kirchhoff).
- stiffness: elastic supports with c a²/D from 1e-8 to 1e12, and a scene mixing rigid and
  c a²/D = 1e-8 supports; the limits (rigid; no support: R = c·w_free) are recorded too.
- gaps: from 1e-12 to 1e2 × the free deflection (mixed heave/settlement pattern); every support
  settled beyond reach (the free plate: R = 0 exactly); one support settled 1e2 × w_free (the
  problem without it); the centre support heaved 1e2 × w_free.
- degenerate: a support touching with exactly zero reaction; no load and zero gaps (R = 0).
- floating: a free plate on the grid; on three supports (statics alone gives R); settled 1e2 ×
  w_free as a body (R of the zero-gap plate); net uplift (no equilibrium).
- near: two supports either side of the centre, d apart, by symmetry carrying equal shares:
  rigid at 1e-1, 1e-3 and 1e-4 of a cell (solved; the condensed form refuses at 1e-4), rigid at
  1e-7 of a cell (refused by design: the split is decided by rounding), elastic at 1e-7 of a
  cell (springs decide the split: solved by the primal and the dual). (Closer than 1e-9 of the
  plate's size two supports are one point, which the scene itself refuses.)
- mesh: the grid scene at 64², 128², 256².

References: two independent exact solvers that must agree (Lemke on the condensed LCP and PDAS
on the sparse primal, both at "high"; Lemke on the dual where the condensed form refuses, or a
sparse LU solve holding PDAS's contact set where both lose digits), or
an invariance, a limit or statics as named above. Error = max of the reaction error
max|R − R_ref| / ‖R_ref‖∞ (/ ΣP where every reference reaction is below tol × ΣP: zero to the
accuracy asked, as the KKT check scales them) and the deflection error max|u − u_ref| / ‖u_ref‖∞.

Outcome of each run at accuracy "high" (KKT tolerance 1e-9):

- accurate: status optimal and error ≤ 100 × tol;
- flagged: the wrapper says inaccurate / max_iter / error (its KKT check, or the solver's own);
- refused: a clear exception (SolverError, ProblemError, NoEquilibriumError, MechanismError),
  which is the designed answer where a case expects a refusal;
- timeout: the per-solve time limit (a clear failure of the bench's making);
- wrong-claimed: status optimal and error > 100 × tol (or optimal where a refusal is due);
- crash: any other exception.

Then the "first rows": failures measured before, reproduced, each shown caught by the KKT check.

Each backend runs in one subprocess ("spawn") that works through its cases one by one, each
with its own time limit; a worker past its limit is killed and a fresh one takes the rest.
Writes benchmarks/results/extremes.csv (one row per case × backend × formulation) and
extremes-first-rows.csv, and prints the markdown tables of benchmarks/README.md ("Extremes").
"""

from __future__ import annotations

import argparse
import csv
import multiprocessing as mp
import os
import platform
import queue
import sys
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))

from bench_contact import run_in_subprocess
from extremes_cases import CASES, PATTERN, Case, D_of, E0, grid, w_free, without_supports

import plateqp as pq

ACCURACY = "high"
TOL = 1e-9
OK_FACTOR = 100.0  # accurate: error ≤ OK_FACTOR × TOL
BOOT_S = 60.0  # a fresh worker's imports, on top of its first task's limit
CLEAR = ("SolverError", "ProblemError", "NoEquilibriumError", "MechanismError")

# -- references (in the parent, in-house exact solvers) ----------------------------------------------

def _solve(scene, backend, formulation):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pq.solve(scene, backend=backend, formulation=formulation, accuracy="high")


def _held(scene, active):
    """The exact solve with the contact set ``active`` held: sparse LU of the saddle-point system
    [K Bᵀ; B −ρ] on that set, refined (no contact solver involved)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from plateqp.model.assembly import build_model
    from plateqp.contact import Scaled

    model = build_model(scene)
    d = Scaled.from_model(model)
    A = np.flatnonzero(active)
    BA = d.B.tocsr()[A]
    H = sp.bmat([[d.K, BA.T], [BA, -sp.diags(d.rho[A])]], format="csc")
    rhs = np.concatenate([d.f, d.g0[A]])
    lu = spla.splu(H)
    x = lu.solve(rhs)
    for _ in range(3):
        x = x + lu.solve(rhs - H @ x)
    R = np.zeros(d.m)
    R[A] = x[d.n:] * d.F0
    return type("Held", (), {"reactions": R, "u": model.expand(d.dof_scale * x[:d.n]),
                             "status": pq.Status.OPTIMAL})()


def _agree(scene, second=("lemke", "condensed")):
    """PDAS on the primal and a second exact solver; they must agree to 1e-9. ``second`` may be
    "held": the saddle-point solve holding PDAS's contact set."""
    a = _solve(scene, "pdas", "primal")
    b = _held(scene, a.active) if second == "held" else _solve(scene, *second)
    scale = max(np.abs(a.reactions).max(), 1e-300)
    diff = max(np.abs(a.reactions - b.reactions).max() / scale, np.abs(a.u - b.u).max() / np.abs(a.u).max())
    ok = a.status == b.status == pq.Status.OPTIMAL and diff <= 1e-9
    other = "the held contact set" if second == "held" else f"{second[0]}/{second[1]}"
    return a.reactions, a.u, f"pdas/primal vs {other}: {diff:.1e}" + ("" if ok else " (DISAGREE)")


def reference(case: Case) -> dict:
    """R_ref, u_ref (full dofs), how, and a limit comparison where the case has one."""
    sc = case.build()
    out = {"limit": "", "load": _load(sc)}
    if case.ref in ("none",):
        out.update(R=None, u=None, how="expects " + case.expect)
        return out
    if case.ref == "exact":
        out["R"], out["u"], out["how"] = _agree(sc)
    elif case.ref == "exact-dual":
        out["R"], out["u"], out["how"] = _agree(sc, ("lemke", "dual"))
    elif case.ref == "exact-held":
        out["R"], out["u"], out["how"] = _agree(sc, "held")
    elif case.ref in ("scaled-E", "scaled-h"):
        base = grid(gaps=PATTERN * w_free())
        R, u, how = _agree(base)
        ratio = D_of() / sc.plate.D  # w·D invariant
        out.update(R=R, u=u * ratio, how=f"E = 1e7, h = 0.02 scene (w·D, R invariant); {how}")
    elif case.ref == "free":
        out.update(R=np.zeros(9), u=pq.solve(without_supports(sc)).u, how="free plate (two-sided solve), R = 0")
    elif case.ref == "drop-first":
        red = grid()
        red.supports = red.supports[1:]
        R, u, how = _agree(red)
        out.update(R=np.r_[0.0, R], u=u, how=f"the scene without the far support; {how}")
    elif case.ref == "drop-centre":
        red = grid()
        red.supports = [s for i, s in enumerate(red.supports) if i != 4]
        R, u, how = _agree(red)
        out.update(R=np.insert(R, 4, 0.0), u=u, how=f"the scene without the centre support, R = 0 there; {how}")
    elif case.ref == "zero":
        model = pq.solve(without_supports(sc)).u
        out.update(R=np.zeros(9), u=np.zeros_like(model), how="R = 0, u = 0 exactly")
    elif case.ref == "statics":
        P, x, y = 100.0, 0.25, 0.375
        A = np.array([[1, 1, 1], [0, 1, 0], [0, 0, 1]], dtype=float)
        R = np.linalg.solve(A, [P, P * x, P * y])
        out.update(R=R, u=None, how="statics: ΣR = P, ΣR x = P x, ΣR y = P y")
    elif case.ref == "floating-shift":
        R, u, how = _agree(grid(edges=None))
        out.update(R=R, u=None, how=f"the zero-gap floating plate (R unchanged by a rigid drop); {how}")
    else:
        raise ValueError(case.ref)
    # limits, recorded for the physics (not used to classify)
    if case.group == "stiffness" and "kappa" in case.extra:
        k = case.extra["kappa"]
        if k >= 1e8:
            rig = _solve(grid(), "lemke", "condensed").reactions
            out["limit"] = f"vs rigid: {np.abs(out['R'] - rig).max() / rig.max():.1e}"
        if k <= 1e-4:
            free = pq.solve(without_supports(sc))
            c = k * sc.plate.D
            lim = c * np.array([free.deflection(s.x, s.y) - s.gap for s in sc.supports])
            out["limit"] = f"vs c·w_free: {np.abs(out['R'] - lim).max() / lim.max():.1e}"
    if case.group == "gaps" and case.extra.get("gamma", 1.0) <= 1e-6:
        zero = _solve(grid(), "lemke", "condensed").reactions
        out["limit"] = f"vs zero gaps: {np.abs(out['R'] - zero).max() / zero.max():.1e}"
    if case.group == "floating" and out["R"] is not None:
        F = sum(ld.P for ld in sc.loads if isinstance(ld, pq.PointLoad)) + \
            sum(ld.q for ld in sc.loads if isinstance(ld, pq.UniformLoad))  # unit square
        out["limit"] = f"statics ΣR − F: {abs(out['R'].sum() - F) / F:.1e}"
    return out


# -- the worker ---------------------------------------------------------------------------------------

def _one(case_name: str, backend: str, formulation: str, options: dict | None) -> dict:
    case = CASES[case_name]
    sc = case.build()
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = pq.solve(sc, backend=backend, formulation=formulation, accuracy=ACCURACY, options=options)
    except Exception as exn:  # noqa: BLE001 - recorded and classified, not hidden
        return {"exception": type(exn).__name__, "message": str(exn)[:300], "time": time.perf_counter() - t0}
    return {"status": r.status.value, "solver_status": str(r.extras.get("solver_status", ""))[:80],
            "kkt_worst": r.kkt.worst, "reactions": r.reactions, "u": r.u, "time": time.perf_counter() - t0,
            "solve_s": r.times.get("solve")}


def _worker(tasks, q, parent):
    warnings.simplefilter("ignore")
    for i, (case, backend, formulation, options) in enumerate(tasks):
        if os.getppid() != parent:  # the bench was killed: do not work on as an orphan
            return
        q.put(("start", i, None))
        q.put(("done", i, _one(case, backend, formulation, options)))


def run_tasks(tasks: list[tuple], limits: list[float]) -> list[dict]:
    """Run the tasks in one spawned worker, each within its own time limit; a worker past its
    limit (or dead) is replaced by a fresh one for the remaining tasks."""
    ctx = mp.get_context("spawn")  # "spawn": a forked child of a process that ran CHOLMOD hung here
    results: list[dict | None] = [None] * len(tasks)
    start = 0
    while start < len(tasks):
        q = ctx.Queue()
        p = ctx.Process(target=_worker, args=(tasks[start:], q, os.getpid()), daemon=True)
        p.start()
        i = start  # the task waited for
        deadline = time.monotonic() + BOOT_S + limits[i]
        while i < len(tasks):
            try:
                kind, j, payload = q.get(timeout=1.0)
            except queue.Empty:
                if not p.is_alive():
                    results[i] = {"exception": "crashed", "message": f"worker exit code {p.exitcode}"}
                    break
                if time.monotonic() > deadline:
                    results[i] = {"timeout": limits[i]}
                    break
                continue
            if kind == "start":  # the clock of task start + j starts now
                deadline = time.monotonic() + limits[start + j]
                continue
            results[start + j] = payload
            i = start + j + 1
            if i < len(tasks):
                deadline = time.monotonic() + 5.0 + limits[i]
        if p.is_alive():
            p.terminate()
        p.join()
        start = i + 1
    return results


def _load(scene) -> float:
    return sum(abs(ld.P) if isinstance(ld, pq.PointLoad) else abs(ld.q) for ld in scene.loads)


def _rel(diff: float, scale: float) -> float:
    """diff / scale, with 0/0 = 0 (no load, no reaction: an exact zero is exact)."""
    return 0.0 if diff == 0.0 else float(diff / max(scale, 1e-300))


def classify(case: Case, ref: dict, res: dict) -> tuple[str, float | None]:
    """The outcome of one run (see the module docstring) and its error against the reference."""
    if "timeout" in res:
        return "timeout", None
    if "exception" in res:
        return ("refused" if res["exception"] in CLEAR and res["message"] else "crash"), None
    if case.expect != "solution":  # a refusal was due: a solved status is a wrong claim
        return ("wrong-claimed" if res["status"] == "optimal" else "flagged"), None
    R, Rref = np.asarray(res["reactions"]), ref["R"]
    # reactions all below the asked tolerance of the load are zero to that accuracy: the load is
    # then their scale, as in the KKT check (kkt.reaction_scale); 1e-12 of the load before called
    # an open support's 1e-12 of the load an error of 1 ("gap-settle-1", every backend)
    scale = np.abs(Rref).max()
    err = _rel(np.abs(R - Rref).max(), scale if scale > TOL * ref["load"] else ref["load"])
    if ref["u"] is not None:
        u, uref = np.asarray(res["u"]), ref["u"]
        err = max(err, _rel(np.abs(u - uref).max(), np.abs(uref).max()))
    if res["status"] == "optimal":
        return ("accurate" if err <= OK_FACTOR * TOL else "wrong-claimed"), err
    return "flagged", err


# -- first rows: the failures measured before, reproduced --------------------------------------------

OSQP_DEFAULTS = {"eps_abs": 1e-3, "eps_rel": 1e-3, "polishing": False, "max_iter": 4000}


def _first_rows_child(args, q):
    """One demonstration; puts a dict (status: our verdict, claim: the solver's own)."""
    kind, params = args
    warnings.simplefilter("ignore")
    try:
        q.put(_first_row(kind, params))
    except Exception as exn:  # noqa: BLE001 - the demonstration's outcome, whatever it is
        q.put({"verdict": f"{type(exn).__name__}: {str(exn)[:160]}", "claim": "", "error": None})


def _first_row(kind, params):
    if kind == "unscaled-clarabel":
        from plateqp.model.assembly import build_model
        from plateqp.backends import clarabel_
        from plateqp.backends.base import QP
        from plateqp.contact import ContactSolution as Contact, Scaled
        from plateqp.contact.kkt import kkt_report

        E = params["E"]
        sc = grid(E=E, gaps=PATTERN * w_free() * E0 / E)
        m = build_model(sc)
        c = m.contacts
        # the raw problem in the scene's own units: what plateqp would hand over without Scaled
        raw = clarabel_.solve_qp(QP(P=m.K.tocsc(), q=-m.f, G=c.B.tocsc(), h=c.g0), accuracy="high")
        d = Scaled.from_model(m)
        rep = kkt_report(d, Contact(raw.x / d.dof_scale, raw.z / d.F0, np.zeros(d.m)), "high")
        R0 = _solve(sc, "lemke", "condensed").reactions
        scaled = _solve(sc, "clarabel", "primal")
        return {"claim": f"{raw.solver_status} ({raw.status.value})",
                "verdict": "optimal" if rep.ok and raw.status.solved else "inaccurate",
                "kkt": rep.worst, "error": float(np.abs(raw.z - R0).max() / R0.max()),
                "scaled": f"scaled: {scaled.status.value}, KKT {scaled.kkt.worst:.1e}, error "
                          f"{np.abs(scaled.reactions - R0).max() / R0.max():.1e}"}
    sc = {"soft": lambda: grid(stiffness=params.get("kappa", 1e-4) * D_of()),
          "floating": lambda: grid(edges=None),
          "grid": lambda: grid(),
          "mixed": lambda: grid(gaps=PATTERN * w_free())}[params["scene"]]()
    R0 = _solve(sc, "pdas", "primal").reactions
    try:
        r = pq.solve(sc, backend=params["backend"], formulation=params["formulation"], accuracy="high",
                     options=params.get("options"))
    except pq.PlateQPError as exn:
        return {"claim": "", "verdict": f"{type(exn).__name__}: {str(exn)[:120]}", "kkt": None, "error": None}
    return {"claim": str(r.extras.get("solver_status", "")), "verdict": r.status.value, "kkt": r.kkt.worst,
            "error": float(np.abs(r.reactions - R0).max() / max(np.abs(R0).max(), 1e-300))}


FIRST_ROWS = [
    ("unscaled Clarabel, E = 1e11 (the raw problem, no Scaled)", "unscaled-clarabel", {"E": 1e11}),
    ("unscaled Clarabel, E = 1 (the raw problem, no Scaled)", "unscaled-clarabel", {"E": 1.0}),
    ("OSQP own defaults, soft supports c a²/D = 1e-4, primal", "pq",
     {"scene": "soft", "backend": "osqp", "formulation": "primal", "options": OSQP_DEFAULTS}),
    ("OSQP own defaults, soft supports c a²/D = 1e-4, condensed", "pq",
     {"scene": "soft", "backend": "osqp", "formulation": "condensed", "options": OSQP_DEFAULTS}),
    ("OSQP own defaults, soft supports c a²/D = 1, primal", "pq",
     {"scene": "soft", "kappa": 1.0, "backend": "osqp", "formulation": "primal", "options": OSQP_DEFAULTS}),
    ("quadprog, floating plate, primal", "pq", {"scene": "floating", "backend": "qpsolvers:quadprog", "formulation": "primal"}),
    ("quadprog, floating plate, condensed", "pq",
     {"scene": "floating", "backend": "qpsolvers:quadprog", "formulation": "condensed"}),
    ("OSQP own defaults, condensed vector (mixed gaps)", "pq",
     {"scene": "mixed", "backend": "osqp", "formulation": "condensed", "options": OSQP_DEFAULTS}),
    ("SCS eps 1e-4, condensed vector (mixed gaps)", "pq",
     {"scene": "mixed", "backend": "qpsolvers:scs", "formulation": "condensed",
      "options": {"eps_abs": 1e-4, "eps_rel": 1e-4}}),
    ("HiGHS (qpsolvers), primal (mixed gaps)", "pq", {"scene": "mixed", "backend": "qpsolvers:highs", "formulation": "primal"}),
    ("HiGHS (cvxpy), primal (mixed gaps)", "pq", {"scene": "mixed", "backend": "cvxpy:HIGHS", "formulation": "primal"}),
]


# -- main ----------------------------------------------------------------------------------------------

OUTCOMES = ("accurate", "flagged", "refused", "timeout", "wrong-claimed", "crash")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default="all")
    ap.add_argument("--backends", default="all")
    ap.add_argument("--skip-cvxpy", action="store_true", help="leave out cvxpy:* (the same solvers as qpsolvers:*)")
    ap.add_argument("--no-first-rows", action="store_true")
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--out", default=str(HERE / "results" / "extremes.csv"))
    args = ap.parse_args()
    if args.list:
        for c in CASES.values():
            print(f"{c.name:22s} {c.group:11s} ref={c.ref:15s} expect={c.expect:15s} {c.note}")
        return
    from plateqp.contact import formulations_for

    cases = list(CASES.values()) if args.cases == "all" else [CASES[n] for n in args.cases.split(",")]
    names = pq.available_backends() if args.backends == "all" else args.backends.split(",")
    if args.skip_cvxpy:
        names = [n for n in names if not n.startswith("cvxpy")]
    t_start = time.time()
    refs = {}
    from plateqp.progress import track  # a bar on a terminal only
    for c in track(cases, "references"):
        t0 = time.perf_counter()
        refs[c.name] = reference(c)
        print(f"reference {c.name}: {refs[c.name]['how']} {refs[c.name]['limit']} ({time.perf_counter() - t0:.1f} s)",
              flush=True)
    rows = []
    from plateqp.progress import track  # a bar on a terminal only
    for b in track(names, "backends"):
        tasks, limits, meta = [], [], []
        for c in cases:
            for f in formulations_for(b):
                tasks.append((c.name, b, f, None))
                limits.append(c.timeout)
                meta.append((c, f))
        t0 = time.perf_counter()
        results = run_tasks(tasks, limits)
        counts = {}
        for (c, f), res in zip(meta, results):
            outcome, err = classify(c, refs[c.name], res)
            counts[outcome] = counts.get(outcome, 0) + 1
            rows.append({"case": c.name, "group": c.group, "backend": b, "formulation": f, "outcome": outcome,
                         "status": res.get("status") or res.get("exception") or ("timeout" if "timeout" in res else ""),
                         "error": err, "kkt_worst": res.get("kkt_worst"), "time_s": res.get("time"),
                         "solver_status": res.get("solver_status", ""), "message": res.get("message", ""),
                         "reference": refs[c.name]["how"], "note": c.note})
            if outcome in ("wrong-claimed", "crash"):
                print(f"  !! {c.name} {b} {f}: {outcome} {res.get('status') or res.get('exception')} "
                      f"err {err} {res.get('message', '')}", flush=True)
        print(f"{b}: {counts} ({time.perf_counter() - t0:.0f} s)", flush=True)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with open(out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"\nwritten {out} ({len(rows)} rows, {time.time() - t_start:.0f} s)")

    first = []
    if not args.no_first_rows:
        for label, kind, params in FIRST_ROWS:
            if kind == "pq" and params["backend"] not in pq.available_backends():
                continue
            r = run_in_subprocess(_first_rows_child, (kind, params), 120)
            first.append({"row": label, **{k: r.get(k) for k in ("claim", "verdict", "kkt", "error", "scaled")},
                          "status": r.get("status", "")})
        fo = out.with_name(out.stem + "-first-rows.csv")
        with open(fo, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(first[0]))
            w.writeheader()
            w.writerows(first)
        print(f"written {fo}")
    print_tables(rows, first, cases)


def _fmt(v, f="{:.1e}"):
    return "–" if v is None or v == "" else f.format(v)


def print_tables(rows, first, cases):
    print(f"\nMachine: {platform.machine()}, {platform.python_version()}, "
          f"plateqp {pq.__version__}, {len({r['backend'] for r in rows})} backends\n")
    print("| case | what | reference | " + " | ".join(OUTCOMES) + " |")
    print("|---|---|---|" + "---|" * len(OUTCOMES))
    for c in cases:
        rs = [r for r in rows if r["case"] == c.name]
        if not rs:
            continue
        cnt = [sum(r["outcome"] == o for r in rs) for o in OUTCOMES]
        print(f"| {c.name} | {c.note} | {c.ref} | " + " | ".join(str(n) for n in cnt) + " |")
    print("\n| backend | " + " | ".join(OUTCOMES) + " |")
    print("|---|" + "---|" * len(OUTCOMES))
    for b in sorted({r["backend"] for r in rows}):
        rs = [r for r in rows if r["backend"] == b]
        print(f"| {b} | " + " | ".join(str(sum(r['outcome'] == o for r in rs)) for o in OUTCOMES) + " |")
    tot = [sum(r["outcome"] == o for r in rows) for o in OUTCOMES]
    print("| **all** | " + " | ".join(f"**{n}**" for n in tot) + " |")
    if first:
        print("\n| first row | solver's claim | our verdict | KKT worst | reaction error | note |")
        print("|---|---|---|---|---|---|")
        for r in first:
            print(f"| {r['row']} | {r['claim'] or '–'} | {r['verdict']} | {_fmt(r['kkt'])} | {_fmt(r['error'])} | "
                  f"{r.get('scaled') or ''} |")


if __name__ == "__main__":
    main()
