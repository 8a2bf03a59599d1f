"""Work–precision: every backend × formulation × a tolerance ladder, on the scene families.

For each scene (``plateqp.scenes.families``: family × mesh n, default k), each installed backend and
each formulation it takes, and each rung of the ladder 1e-2 … 1e-12 (passed as
``accuracy=tol``: the KKT tolerance, each backend maps it with ``preset()``), one row:
assembly, formulate and solve time, iterations, the backend's own status, ours, every KKT
residual, and the errors of the reactions and of the deflection field (at the nodes) against
a reference solved to machine precision: PDAS on the primal at 1e-12, cross-checked by an
independent exact solver on the condensed LCP (Lemke up to ``--lemke-max`` contact points,
else BPP), the two agreeing to 1e-9 or the report says so.

Each (scene, backend, formulation) runs its ladder, loosest first, in one fresh interpreter
(``spawn``, warmed up on a tiny scene) with a time limit on each rung; a rung that overruns
is killed and recorded as a timeout, and the tighter rungs of that ladder as ``skipped``
(scored as failures; ``--retry`` starts a new interpreter for them instead). The model is
assembled once per ladder; the formulation (condensation / flexibility) is rebuilt for every
rung, so each row's formulate time is that of a fresh call.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_work_precision.py                 # default set
    python benchmarks/bench_work_precision.py --sizes 16,32,64 --cvxpy-max-n 16 --timeout 60
    python benchmarks/bench_work_precision.py --report-only                          # tables + plots from the CSV

Writes benchmarks/results/work_precision.csv (long format, one row per solve),
benchmarks/results/work_precision.md (the report) and benchmarks/figures/work_precision_*.png.

Summary (the qpbenchmark way): per backend/formulation, over every scene, the success rate
and the shifted geometric mean of the solve time (shift 10 s, a failure charged the time
limit, normalised so the best pair is 1) at three levels: low = the 1e-4 rung, mid = 1e-6,
high = 1e-10. Success = the backend said it found a solution AND our worst KKT residual is at
most the tolerance. A "silent wrong answer" is a row where the backend claimed success
(its own status optimal) or our check passed, with an error above 100 × tol.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before NumPy loads
    os.environ.setdefault(_var, "1")

import argparse
import csv
import math
import multiprocessing as mp
import platform
import queue
import sys
import time
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_contact import run_in_subprocess

import plateqp as pq
from plateqp.scenes.families import FAMILIES, family, n_contacts

TOLS = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
LEVELS = {"low": 1e-4, "mid": 1e-6, "high": 1e-10}
KKT_KEYS = ("stationarity", "spring", "primal", "dual", "complementarity", "natural")
#: default supports per row of each family (bed: every node)
DEFAULT_K = {"grid_rigid": 7, "grid_elastic": 7, "floating": 5, "bed": None}
SHIFT = 10.0  # seconds, as qpbenchmark
COLUMNS = ["family", "n", "k", "m", "ndof", "backend", "formulation", "tol", "status", "backend_status",
           "solver_status", "found", "claimed", "success", "build_s", "formulate_s", "solve_s", "iterations",
           *KKT_KEYS, "kkt_worst", "kkt_tol", "kkt_scale", "kkt_ok", "err_R", "err_w", "error", "ref_agree"]


# -- child processes ---------------------------------------------------------------------------

def _warm_up(backend, formulation, accuracy):
    """Pay the first-call imports (solvers, SciPy's LP) on a tiny scene."""
    from plateqp.model.assembly import build_model
    from plateqp.contact import solve_contact

    try:
        solve_contact(build_model(family("grid_rigid", 4, 3)), backend=backend, formulation=formulation,
                      accuracy=accuracy)
    except Exception:  # the real case records any failure
        pass


def _summary(r, nd):
    k = r.kkt.as_dict()
    return {"status": r.status.value, "formulate_s": r.times["formulate"], "solve_s": r.times["solve"],
            "iterations": r.iterations, "solver_status": str(r.extras.get("solver_status", ""))[:60],
            **{key: k[key] for key in KKT_KEYS}, "kkt_worst": r.kkt.worst, "kkt_tol": k["tol"],
            "kkt_scale": k["scale"], "kkt_ok": k["ok"], "R": r.reactions.tolist(), "w": r.u[::nd].tolist()}


def _ladder(args, q):
    """Child: build the scene once, then solve it at every rung; one message per rung."""
    fam, n, k, backend, formulation, tols = args
    warnings.simplefilter("ignore")
    from plateqp.model.assembly import build_model
    from plateqp.backends import get_backend
    from plateqp.contact import solve_contact

    _warm_up(backend, formulation, tols[0])
    t0 = time.perf_counter()
    model = build_model(family(fam, n, k))
    t_build = time.perf_counter() - t0
    nd = model.element.ndof_node
    raw = {}
    try:  # the backend's own verdict, before our KKT check re-labels it
        b = get_backend(backend)
        inner = b.solve

        def spy(problem, accuracy="default", options=None):
            out = inner(problem, accuracy=accuracy, options=options)
            raw["backend_status"] = out.status.value
            return out

        b.solve = spy
    except Exception:
        pass
    q.put({"ready": True, "build_s": t_build, "ndof": model.n_free, "m": model.contacts.m})
    for tol in tols:
        model.derived.clear()  # a fresh formulation per rung
        raw.clear()
        try:
            r = solve_contact(model, backend=backend, formulation=formulation, accuracy=tol)
            q.put({"tol": tol, **_summary(r, nd), **raw})
        except Exception as exn:  # recorded, not hidden
            q.put({"tol": tol, "status": "error", "error": f"{type(exn).__name__}: {exn}"[:160], **raw})


def _reference(args, q):
    """Child: the reference pair, each at 1e-12: PDAS/primal and Lemke (or BPP)/condensed."""
    fam, n, k, lemke_max = args
    warnings.simplefilter("ignore")
    from plateqp.model.assembly import build_model
    from plateqp.contact import solve_contact

    model = build_model(family(fam, n, k))
    nd = model.element.ndof_node
    out = {}
    exact = "lemke" if model.contacts.m <= lemke_max else "bpp"
    for name, (b, f) in (("primary", ("pdas", "primal")), ("check", (exact, "condensed"))):
        try:
            r = solve_contact(model, backend=b, formulation=f, accuracy=1e-12)
            out[name] = {"backend": b, "formulation": f, **_summary(r, nd)}
        except Exception as exn:
            out[name] = {"backend": b, "formulation": f, "status": f"error: {type(exn).__name__}: {exn}"[:120]}
    q.put(out)


def run_ladder(args, timeout, retry=False):
    """Run a ladder in a fresh interpreter, a time limit on each rung; one dict per rung.

    Like bench_contact.run_in_subprocess (spawn, a queue), but streaming: one interpreter for
    the whole ladder (spawning one per solve would cost ~1 s each), each rung under its own limit.
    """
    fam, n, k, backend, formulation, tols = args
    ctx = mp.get_context("spawn")
    q = ctx.Queue()
    p = ctx.Process(target=_ladder, args=(args, q))
    p.start()
    rows, meta = [], {}
    try:
        msg = q.get(timeout=max(120.0, timeout))  # start-up and assembly
        meta = {key: msg[key] for key in ("build_s", "ndof", "m")}
        for i, tol in enumerate(tols):
            try:
                rows.append({**meta, **q.get(timeout=timeout)})
            except queue.Empty:
                what = f"timeout > {timeout:g} s" if p.is_alive() else "crashed"
                rows.append({**meta, "tol": tol, "status": what})
                rest = tols[i + 1:]
                if rest and retry and what.startswith("timeout"):
                    p.terminate()
                    p.join()
                    more = run_ladder((fam, n, k, backend, formulation, rest), timeout, retry)
                    return rows + more
                rows += [{**meta, "tol": t, "status": f"skipped (after {what} at {tol:g})"} for t in rest]
                break
    except queue.Empty:
        rows = [{"tol": t, "status": "crashed before solving" if not p.is_alive() else "timeout in start-up"}
                for t in tols]
    finally:
        if p.is_alive():
            p.terminate()
        p.join()
    return rows


# -- the study -----------------------------------------------------------------------------------

def rel_err(x, ref):
    x, ref = np.asarray(x, float), np.asarray(ref, float)
    if x.shape != ref.shape:
        return float("nan")
    return float(np.abs(x - ref).max() / max(np.abs(ref).max(), 1e-300))


def reference(fam, n, k, lemke_max, timeout):
    """The reference solution of a scene and its cross-check (see module docstring)."""
    out = run_in_subprocess(_reference, (fam, n, k, lemke_max), timeout)
    if "primary" not in out:
        raise SystemExit(f"reference for {fam} n={n}: {out.get('status')}")
    a, b = out["primary"], out["check"]
    ok_a, ok_b = "R" in a and a["status"] == "optimal", "R" in b and b["status"] == "optimal"
    ref = a if ok_a and (not ok_b or a["kkt_worst"] <= b["kkt_worst"] * 10) else b
    other = b if ref is a else a
    agree = max(rel_err(other["R"], ref["R"]), rel_err(other["w"], ref["w"])) if ("R" in other) else float("nan")
    return {"R": np.array(ref["R"]), "w": np.array(ref["w"]), "agree": agree,
            "by": (ref["backend"], ref["formulation"]), "check": (other["backend"], other["formulation"]),
            "R2": np.array(other.get("R", [])), "w2": np.array(other.get("w", [])),
            "kkt": ref.get("kkt_worst"), "active": int((np.array(ref["R"]) > 0).sum())}


def finish_row(row, ref, limit):
    """Errors against the reference and the derived flags of one row.

    The reference's own pair (PDAS/primal) is measured against the cross-check instead, so
    that its error is not zero by construction.
    """
    if "R" in row:
        own = (row["backend"], row["formulation"]) == ref["by"] and ref["R2"].size
        R0, w0 = (ref["R2"], ref["w2"]) if own else (ref["R"], ref["w"])
        row["err_R"] = rel_err(row.pop("R"), R0)
        row["err_w"] = rel_err(row.pop("w"), w0)
    row["found"] = row.get("backend_status") in ("optimal", "inaccurate")
    row["claimed"] = row.get("backend_status") == "optimal"
    worst = row.get("kkt_worst")
    row["success"] = bool(row["found"] and worst is not None and worst <= row["tol"])
    row["ref_agree"] = ref["agree"]
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--families", default=",".join(FAMILIES))
    ap.add_argument("--sizes", default="16,32", help="mesh sizes n (n × n cells)")
    ap.add_argument("--tols", default=",".join(f"{t:g}" for t in TOLS))
    ap.add_argument("--backends", default="all")
    ap.add_argument("--cvxpy-max-n", type=int, default=16,
                    help="run the cvxpy:* routes (the same solvers as the direct and qpsolvers routes, more "
                         "overhead) only up to this n")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per solve (one rung)")
    ap.add_argument("--retry", action="store_true", help="after a timeout, run the tighter rungs anyway")
    ap.add_argument("--lemke-max", type=int, default=1500, help="largest m for Lemke as the cross-check")
    ap.add_argument("--out", default=str(HERE / "results" / "work_precision.csv"))
    ap.add_argument("--figures", default=str(HERE / "figures"), help="directory of the PNG plots")
    ap.add_argument("--report-only", action="store_true", help="tables and plots from --out, no solving")
    args = ap.parse_args()
    out = Path(args.out)
    if args.report_only:
        rows = read_csv(out)
        write_report(rows, out, args.timeout, Path(args.figures))
        return
    tols = tuple(float(t) for t in args.tols.split(","))
    names = pq.available_backends() if args.backends == "all" else args.backends.split(",")
    from plateqp.contact import formulations_for

    pairs = [(b, f) for b in names for f in formulations_for(b)]
    rows = []
    t_start = time.perf_counter()
    from plateqp.progress import track  # a bar on a terminal only
    for n in track([int(v) for v in args.sizes.split(",")], "sizes"):
        for fam in args.families.split(","):
            k = DEFAULT_K[fam]
            ref = reference(fam, n, k, args.lemke_max, 20 * args.timeout)
            m = n_contacts(fam, n, k)
            print(f"\n## {fam} n={n} k={k} m={m}: reference {'/'.join(ref['by'])} (KKT {ref['kkt']:.1e}), "
                  f"{'/'.join(ref['check'])} agrees to {ref['agree']:.1e}; {ref['active']} supports carry load",
                  flush=True)
            for b, f in pairs:
                if b.startswith("cvxpy") and n > args.cvxpy_max_n:
                    continue
                t0 = time.perf_counter()
                for r in run_ladder((fam, n, k, b, f, tols), args.timeout, args.retry):
                    row = finish_row({"family": fam, "n": n, "k": "" if k is None else k, "m": m, "backend": b,
                                      "formulation": f, **r}, ref, args.timeout)
                    rows.append(row)
                line = " ".join(_cell(r) for r in rows[-len(tols):])
                print(f"{b:>20} {f:<9} {time.perf_counter() - t0:6.1f}s  {line}", flush=True)
                write_csv(rows, out, quiet=True)  # as it goes: an interrupted run keeps its rows
    print(f"\ntotal {time.perf_counter() - t_start:.0f} s")
    write_csv(rows, out)
    write_report(rows, out, args.timeout, Path(args.figures))


def _cell(r):
    if r.get("err_R") is None or (isinstance(r.get("err_R"), float) and math.isnan(r["err_R"])):
        return f"[{r['status'][:7]}]"
    mark = "+" if r["success"] else "-"
    return f"{mark}{r['err_R']:.0e}"


# -- CSV -------------------------------------------------------------------------------------------

def write_csv(rows, path, quiet=False):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({c: _cell_out(r.get(c, "")) for c in COLUMNS})
    if not quiet:
        print(f"written {path}")


def _cell_out(v):
    """Floats with 4 significant digits (times, residuals, errors): the CSV stays small."""
    if isinstance(v, float) and not isinstance(v, bool):
        return "" if math.isnan(v) else f"{v:.4g}"
    return "" if v is None else v


def read_csv(path):
    def conv(c, v):
        if v == "":
            return None
        if c in ("found", "claimed", "success", "kkt_ok"):
            return v == "True"
        if c in ("n", "m", "ndof", "iterations"):
            return int(float(v))
        try:
            return float(v) if c not in ("family", "k", "backend", "formulation", "status", "backend_status",
                                         "solver_status", "error") else v
        except ValueError:
            return v
    with open(path) as fh:
        return [{c: conv(c, v) for c, v in r.items()} for r in csv.DictReader(fh)]


# -- report ------------------------------------------------------------------------------------------

def sgm(times, shift=SHIFT):
    """Shifted geometric mean (Π (t + shift))^(1/n) − shift."""
    t = np.asarray(times, float)
    return float(np.exp(np.mean(np.log(t + shift))) - shift)


def scenes_of(rows):
    return sorted({(r["family"], r["n"]) for r in rows}, key=lambda s: (s[1], list(FAMILIES).index(s[0])))


def summary_table(rows, limit, levels=LEVELS, shift=SHIFT):
    """Per (backend, formulation): success rate and sgm of solve time at each level (markdown).

    ``rows`` should hold the same scenes for every pair (the sgm is normalised across pairs).
    """
    by = defaultdict(dict)
    for r in rows:
        by[(r["backend"], r["formulation"])][(r["family"], r["n"], r["tol"])] = r
    scenes = scenes_of(rows)
    stats = {}
    for pair, cases in by.items():
        for lev, tol in levels.items():
            t, ok = [], []
            for fam, n in scenes:
                r = cases.get((fam, n, tol))
                good = r is not None and bool(r["success"])
                ok.append(good)
                t.append(r["solve_s"] if good else limit)
            stats[(pair, lev)] = (100.0 * np.mean(ok), sgm(t, shift))
    best = {lev: min(v[1] for (p, lv), v in stats.items() if lv == lev) for lev in levels}
    lines = ["| backend | formulation | " + " | ".join(f"{lev} success % | {lev} sgm" for lev in levels) + " |",
             "|---|---|" + "---:|---:|" * len(levels)]
    order = sorted(by, key=lambda p: (-sum(stats[(p, lv)][0] for lv in levels),
                                      sum(np.log(stats[(p, lv)][1] / best[lv]) for lv in levels), p))
    for p in order:
        cells = [f"{stats[(p, lev)][0]:.0f} | {stats[(p, lev)][1] / best[lev]:.1f}" for lev in levels]
        lines.append(f"| {p[0]} | {p[1]} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def fast_table(rows, limit, tol):
    """Pairs that succeed on every scene at ``tol``: formulate + solve (solve) seconds per scene."""
    by = defaultdict(list)
    for r in rows:
        if r["tol"] == tol:
            by[(r["backend"], r["formulation"])].append(r)
    scenes = scenes_of(rows)
    lines = ["| backend | formulation | " + " | ".join(f"{f} {n}²" for f, n in scenes) + " |",
             "|---|---|" + "---:|" * len(scenes)]
    keep = []
    for p, rs in by.items():
        d = {(r["family"], r["n"]): r for r in rs}
        if len(d) == len(scenes) and all(d[s]["success"] for s in scenes):
            keep.append((np.exp(np.mean([np.log(d[s]["solve_s"] + d[s]["formulate_s"]) for s in scenes])), p, d))
    for _, p, d in sorted(keep):
        lines.append(f"| {p[0]} | {p[1]} | " + " | ".join(
            f"{d[s]['formulate_s'] + d[s]['solve_s']:.3g} ({d[s]['solve_s']:.2g})" for s in scenes) + " |")
    return "\n".join(lines)


def row_error(r):
    """max(reaction error, deflection error), or None."""
    vals = [v for v in (r.get("err_R"), r.get("err_w")) if v is not None and not math.isnan(v)]
    return max(vals) if vals else None


def wrong_answers(rows):
    """Rows where the backend claimed success, or our KKT check passed, with error > 100 × tol."""
    out = []
    for r in rows:
        e = row_error(r)
        if e is not None and e > 100 * r["tol"] and (r["claimed"] or r["status"] == "optimal"):
            out.append((r, e))
    return out


def scenes_table(rows):
    """Per scene: size, the reference's cross-check, and the smallest worst-KKT any pair reached."""
    lines = ["| scene | k | m | free dofs | cross-check vs reference | best KKT: primal | condensed | dual |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for fam, n in scenes_of(rows):
        sel = [r for r in rows if r["family"] == fam and r["n"] == n]
        r0 = sel[0]
        best = []
        for f in ("primal", "condensed", "dual"):
            v = [r["kkt_worst"] for r in sel if r["formulation"] == f and r.get("kkt_worst") is not None]
            best.append(_f(min(v)) if v else "–")
        lines.append(f"| {fam} {n}² | {r0['k'] or 'every node'} | {r0['m']} | {r0.get('ndof') or '–'} | "
                     f"{_f(r0['ref_agree'])} | " + " | ".join(best) + " |")
    return "\n".join(lines)


def wrong_section(rows):
    wrong = wrong_answers(rows)
    ours = [(r, e) for r, e in wrong if r["status"] == "optimal"]
    lines = [f"Rows: {len(rows)}; error = max(reaction error, deflection error) against the reference.", ""]
    if ours:
        lines += [f"**{len(ours)} rows passed our KKT check with an error above 100 × tol:**", "",
                  "| scene | backend | formulation | tol | KKT worst | err R | err w |", "|---|---|---|---|---|---|---|"]
        lines += [f"| {r['family']} {r['n']}² | {r['backend']} | {r['formulation']} | {r['tol']:g} | "
                  f"{_f(r.get('kkt_worst'))} | {_f(r.get('err_R'))} | {_f(r.get('err_w'))} |" for r, e in ours]
    else:
        lines.append("**None passed our KKT check**: every row with status `optimal` has an error of at most "
                     "100 × tol.")
    claimed = [(r, e) for r, e in wrong if r["status"] != "optimal"]
    lines += ["", f"**{len(claimed)} rows where the backend itself claimed optimal** with an error above "
              "100 × tol; our KKT check labelled every one `inaccurate`. By backend and formulation (worst case):", "",
              "| backend | formulation | rows | scenes | worst: scene, tol | KKT worst | error |",
              "|---|---|---:|---|---|---:|---:|"]
    by = defaultdict(list)
    for r, e in claimed:
        by[(r["backend"], r["formulation"])].append((r, e))
    for (b, f), v in sorted(by.items(), key=lambda kv: -max(e / kv_r["tol"] for kv_r, e in kv[1])):
        r, e = max(v, key=lambda x: x[1] / x[0]["tol"])
        fams = sorted({x["family"] for x, _ in v})
        lines.append(f"| {b} | {f} | {len(v)} | {', '.join(fams)} | {r['family']} {r['n']}², {r['tol']:g} | "
                     f"{_f(r.get('kkt_worst'))} | {_f(e)} |")
    return "\n".join(lines)


def write_report(rows, csv_path, limit, figdir=HERE / "figures"):
    md = csv_path.with_suffix(".md")
    sizes = sorted({r["n"] for r in rows})
    full = {(r["backend"], r["formulation"]) for r in rows if r["n"] == sizes[-1]}
    everywhere = [r for r in rows if (r["backend"], r["formulation"]) in full]
    small = [r for r in rows if r["n"] == sizes[0]]
    lines = [
        "# Work–precision (generated by benchmarks/bench_work_precision.py)", "",
        f"Machine: {platform.machine()}, {os.cpu_count()} CPUs (shared with other jobs), Python "
        f"{platform.python_version()}, NumPy {np.__version__}, OPENBLAS_NUM_THREADS=1. Time limit {limit:g} s "
        "per solve. One run: compare within a table.", "",
        "## Scenes", "",
        "Reference: PDAS/primal at 1e-12; cross-check: Lemke (BPP above --lemke-max) on the condensed LCP at "
        "1e-12 (max relative difference of reactions and deflections). Best KKT: the smallest worst-residual "
        "any backend reached on that formulation (the floor of what can be certified).", "",
        scenes_table(rows), "",
        "## Success rate and shifted geometric mean of solve time", "",
        "Success = the backend said it found a solution and our worst KKT residual ≤ the asked "
        "tolerance; sgm = shifted geometric mean of the solve time (shift 10 s, failures charged the "
        "time limit), normalised so the best pair is 1 (qpbenchmark's metric; with shift 10 s and solves "
        "of milliseconds it mostly counts failures). low = the 1e-4 rung, mid = 1e-6, high = 1e-10. "
        "The dual formulation refuses the floating and bed scenes (K singular): those count as failures.", "",
        f"### Every scene ({', '.join(f'{n}²' for n in sizes)}), the pairs run at every size", "",
        summary_table(everywhere, limit), "",
        f"### {sizes[0]}² scenes only, every pair (the cvxpy:* routes included)", "",
        summary_table(small, limit), "",
        "## Time per scene at mid accuracy (1e-6), pairs that succeed on every scene", "",
        "formulate + solve seconds (solve alone in brackets), one run.", "",
        fast_table(everywhere, limit, 1e-6), "",
        "## Time per scene at high accuracy (1e-10), pairs that succeed on every scene", "",
        fast_table(everywhere, limit, 1e-10), "",
        "## Silent wrong answers: claimed success with error > 100 × tol", "",
        wrong_section(rows), "",
        "## Every row", "", "See work_precision.csv (columns: " + ", ".join(COLUMNS) + ").",
    ]
    md.write_text("\n".join(lines) + "\n")
    print(f"written {md}")
    try:
        plot(rows, figdir)
    except ImportError:
        print("matplotlib not installed: no figures")


def _f(v):
    return "–" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.1e}"


def plot(rows, figdir):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    figdir.mkdir(parents=True, exist_ok=True)
    backends = sorted({r["backend"] for r in rows if not r["backend"].startswith("cvxpy")})
    cmap = plt.get_cmap("tab20")
    colour = {b: cmap(i % 20) for i, b in enumerate(backends)}
    marker = {b: "os^vDP*Xph<>"[i % 12] for i, b in enumerate(backends)}
    for fam in FAMILIES:
        n = max((r["n"] for r in rows if r["family"] == fam), default=None)
        if n is None:
            continue
        sel = [r for r in rows if r["family"] == fam and r["n"] == n and r["backend"] in colour]
        forms = [f for f in ("primal", "condensed", "dual") if any(r["formulation"] == f and r["found"] for r in sel)]
        fig, axes = plt.subplots(1, len(forms), figsize=(4.2 * len(forms), 4.0), sharey=True, squeeze=False)
        for ax, f in zip(axes[0], forms):
            for b in backends:
                pts = sorted((r["solve_s"], max(r["err_R"], 1e-16), r["success"]) for r in sel
                             if r["backend"] == b and r["formulation"] == f and r["found"]
                             and r.get("err_R") is not None and not math.isnan(r["err_R"]))
                if not pts:
                    continue
                x, y, ok = zip(*pts)
                ax.plot(x, y, "-", color=colour[b], lw=0.8, alpha=0.7)
                ax.scatter([a for a, o in zip(x, ok) if o], [c for c, o in zip(y, ok) if o], color=colour[b],
                           marker=marker[b], s=18, label=b)
                ax.scatter([a for a, o in zip(x, ok) if not o], [c for c, o in zip(y, ok) if not o],
                           facecolors="none", edgecolors=colour[b], marker=marker[b], s=18)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            ax.set_ylim(5e-17, 1.0)
            ax.set_title(f"{f}", fontsize=9)
            ax.set_xlabel("solve time (s)", fontsize=8)
            ax.grid(True, which="major", lw=0.3)
            ax.tick_params(labelsize=7)
        axes[0][0].set_ylabel("max reaction error / max R", fontsize=8)
        handles = {}
        for ax in axes[0]:
            for h, lab in zip(*ax.get_legend_handles_labels()):
                handles.setdefault(lab, h)
        fig.legend(handles.values(), handles.keys(), fontsize=6, loc="center right", frameon=False)
        fig.suptitle(f"{fam} {n}²: reaction error vs solve time, ladder 1e-2…1e-12\n"
                     "(hollow: our KKT check failed; errors < 1e-16 drawn at 1e-16)", fontsize=9)
        fig.tight_layout(rect=(0, 0, 0.84, 0.92))
        path = figdir / f"work_precision_{fam}.png"
        fig.savefig(path, dpi=90)
        plt.close(fig)
        print(f"written {path} ({path.stat().st_size // 1024} kB)")


if __name__ == "__main__":
    main()
