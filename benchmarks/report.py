"""The benchmark report: one command regenerates every table and figure of benchmarks/README.md.

    python benchmarks/report.py                  # every part, results/ and figures/ rewritten
    python benchmarks/report.py --quick          # smallest sizes, one repeat, into a temp dir
    python benchmarks/report.py --only sweep     # one part (comma-separated for several)
    python benchmarks/report.py --out DIR        # results, figures and README.md under DIR

Each part runs its benchmark script (bench_*.py, its measurement code unchanged) in a child
process with the script's ``HERE`` pointed at a scratch directory, so a script's own outputs
never land over the committed ones; the part then copies the CSV to
``<out>/results/<what-it-measures>.csv``, draws ``<out>/figures/<what>.png`` and returns its
Markdown section. The README is written from report_template.md: ``{{part}}`` is replaced by the
part's section (table, figure, and the machine, versions, date and command that made it).
``--quick`` writes to a temporary directory unless ``--out`` is given, never over the committed
results, and exits non-zero if any part fails.
"""
from __future__ import annotations

import argparse
import datetime as dt
import json
import math
import os
import platform
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

HERE = Path(__file__).resolve().parent
TEMPLATE = HERE / "report_template.md"
# scripts other work owns: run when present, else the part falls back (see their parts)
TRI_SCRIPT = HERE / "bench_tri.py"
SWEEP_REUSE_SCRIPT = HERE / "bench_sweep_reuse.py"

RUNNER = (
    "import sys, importlib, pathlib; sys.path.insert(0, sys.argv[1]); "
    "m = importlib.import_module(sys.argv[2]); m.HERE = pathlib.Path(sys.argv[3]); "
    "sys.argv = [sys.argv[2] + '.py'] + sys.argv[4:]; m.main()"
)


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, {platform.system()}"


def versions() -> str:
    out = [f"Python {platform.python_version()}"]
    for mod, name in (("numpy", "NumPy"), ("scipy", "SciPy"), ("cvxopt", "cvxopt (CHOLMOD)"),
                      ("sksparse", "scikit-sparse"), ("clarabel", "Clarabel"), ("osqp", "OSQP")):
        try:
            v = getattr(__import__(mod), "__version__", "?")
            out.append(f"{name} {v}")
        except ImportError:
            pass
    return ", ".join(out)


class Part:
    """One section of the report: the script to run, its arguments, the CSV it measures."""

    def __init__(self, name, script, csv, produced, full, quick, section, title):
        self.name, self.script, self.csv, self.produced = name, script, csv, produced
        self.full, self.quick, self.section, self.title = full, quick, section, title

    def run(self, out: Path, quick: bool) -> str:
        scratch = Path(tempfile.mkdtemp(prefix=f"report-{self.name}-"))
        (scratch / "results").mkdir()
        (scratch / "figures").mkdir()
        args = list(self.quick if quick else self.full)
        cmd = [sys.executable, "-c", RUNNER, str(HERE), self.script, str(scratch)] + [
            a.replace("SCRATCH", str(scratch)) for a in args]
        shown = f"python benchmarks/{self.script}.py " + " ".join(
            shlex.quote(a.replace("SCRATCH/", "")) for a in args)
        start = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        took = time.perf_counter() - start
        if proc.returncode != 0:
            raise RuntimeError(f"{self.script} exited {proc.returncode}:\n{proc.stderr[-3000:]}")
        found = sorted((scratch / "results").glob(self.produced))
        src = found[0] if found else scratch / "results" / self.produced
        if not src.exists():
            raise RuntimeError(f"{self.script} wrote no {self.produced}")
        dest = out / "results" / self.csv
        shutil.copyfile(src, dest)
        df = pd.read_csv(dest)
        if df.empty:
            raise RuntimeError(f"{self.script} measured nothing (no rows in {self.produced}):\n"
                               f"{proc.stdout[-2000:]}")
        md = self.section(df, out / "figures")
        meta = (f"*Measured {dt.datetime.now(dt.timezone.utc):%Y-%m-%d %H:%M} UTC in {took:.0f} s on "
                f"{machine()}; {versions()}. Command: `{shown}` (driven by "
                f"`python benchmarks/report.py --only {self.name}`). Data: "
                f"[results/{self.csv}](results/{self.csv}).*")
        shutil.rmtree(scratch, ignore_errors=True)
        return f"{md}\n\n{meta}\n"


def table(df: pd.DataFrame, fmt="{:.3g}") -> str:
    def cell(v):
        if isinstance(v, float):
            return "" if pd.isna(v) else fmt.format(v)
        return str(v)
    head = "| " + " | ".join(map(str, df.columns)) + " |"
    rule = "|" + "---|" * len(df.columns)
    rows = ["| " + " | ".join(cell(v) for v in r) + " |" for r in df.itertuples(index=False)]
    return "\n".join([head, rule] + rows)


def figure(fig, figdir: Path, name: str, alt: str) -> str:
    fig.tight_layout()
    fig.savefig(figdir / f"{name}.png", dpi=72)
    plt.close(fig)
    return f"![{alt}](figures/{name}.png)"


# -- the parts' sections: a table and a figure from the part's CSV --------------------------

def wp_section(df, figdir):
    df = df[df["error"].notna() | df["err_R"].notna()].copy()
    df["err"] = pd.to_numeric(df["error"], errors="coerce").fillna(
        pd.to_numeric(df["err_R"], errors="coerce"))
    df["solve_s"] = pd.to_numeric(df["solve_s"], errors="coerce")
    df["err"] = df["err"].clip(lower=1e-16)
    g = df.groupby(["backend", "formulation", "tol"], as_index=False).agg(
        solve_s=("solve_s", "median"), error=("err", "median"), kkt_ok=("kkt_ok", "mean"))
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for (b, f), d in g.groupby(["backend", "formulation"]):
        d = d.sort_values("tol")
        ax.loglog(d["solve_s"], d["error"], "o-", label=f"{b}/{f}", ms=3)
    ax.set_xlabel("solve time, s (median over scenes)")
    ax.set_ylabel("relative error of reactions")
    ax.legend(fontsize=6, ncol=2)
    ax.grid(True, which="both", alpha=.3)
    best = g.sort_values("solve_s").groupby("tol").head(1).sort_values("tol", ascending=False)
    t = best.rename(columns={"kkt_ok": "share KKT-checked"})
    return (table(t) + "\n\n" + "Fastest route per requested accuracy (medians over the scenes).\n\n"
            + figure(fig, figdir, "work-precision", "error against time, one line per backend"))


def cost_section(df, figdir):
    d = df[df["part"] == "goal"] if "part" in df else df
    d = d.groupby(["scene", "mesh", "dofs"], as_index=False)[
        ["raw_s", "two_sided_s", "solve_s", "solve_ratio"]].median()
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for scene, s in d.groupby("scene"):
        ax.loglog(s["dofs"], s["solve_s"], "o-", label=f"pq.solve, {scene}")
        ax.loglog(s["dofs"], s["raw_s"], "s--", label=f"raw CHOLMOD, {scene}")
    ax.set_xlabel("degrees of freedom")
    ax.set_ylabel("time, s (median)")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=.3)
    return table(d) + "\n\n" + figure(fig, figdir, "cost-vs-mesh", "time against dofs")


def contacts_section(df, figdir):
    d = df.groupby(["scene", "k", "contacts", "backend", "accuracy"], as_index=False).agg(
        cpu_s=("cpu_s", "median"), kkt_max=("kkt_max", "max"), status=("status", "first"))
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for (b, acc), s in d[d["scene"] != "bed"].groupby(["backend", "accuracy"]):
        s = s.sort_values("contacts")
        ax.loglog(s["contacts"], s["cpu_s"], "o-", label=f"{b} @ {acc:g}")
    ax.set_xlabel("posts (contact rows)")
    ax.set_ylabel("CPU time, s")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=.3)
    return table(d) + "\n\n" + figure(fig, figdir, "many-contacts", "CPU time against posts")


def sweep_section(df, figdir):
    d = df.groupby(["backend", "formulation", "mode"], as_index=False).agg(
        values=("values", "first"), total_s=("total_s", "median"), iterations=("iterations", "median"))
    d["per_value_ms"] = 1e3 * d["total_s"] / d["values"]
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    labels = [f"{b}/{f} {m}" for b, f, m in zip(d["backend"], d["formulation"], d["mode"])]
    ax.barh(labels, d["per_value_ms"])
    ax.set_xscale("log")
    ax.set_xlabel("time per value of the sweep, ms (median)")
    return table(d) + "\n\n" + figure(fig, figdir, "sweep-cost", "time per sweep value")


def disc_section(df, figdir):
    d = df.groupby(["family", "mesh", "backend", "tol"], as_index=False)[
        ["solve_s", "err_w", "err_R"]].median()
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for (fam, b, tol), s in d.groupby(["family", "backend", "tol"]):
        ax.loglog(s["mesh"], s["err_R"], "o-", ms=3, label=f"{fam} {b} tol {tol:g}")
    ax.set_xlabel("mesh n (n × n cells)")
    ax.set_ylabel("reaction error against the finest reference")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=6)
    ax.grid(True, which="both", alpha=.3)
    return table(d) + "\n\n" + figure(fig, figdir, "discretisation", "error against mesh")


def extremes_section(df, figdir):
    d = df[["case", "group", "backend", "formulation", "outcome", "error", "kkt_worst", "time_s"]]
    counts = df.pivot_table(index="backend", columns="outcome", values="case",
                            aggfunc="count", fill_value=0).reset_index()
    bad = d[d["outcome"].isin(["wrong-claimed", "crash", "timeout"])]
    rows = ("Runs whose outcome is wrong-claimed, a crash or a timeout (every run: the data file):\n\n"
            + table(bad)) if len(bad) else "No run is wrong-claimed, crashed or timed out (every run: the data file)."
    return "Outcomes per backend:\n\n" + table(counts) + "\n\n" + rows


#: the goals of pq.solve ÷ raw on the DKT disc: at about 12k dofs, and from 100k dofs on
TRI_GOALS = ((10_000, 20_000, 4.0), (100_000, float("inf"), 2.5))


def tri_section(df, figdir):
    verdicts = []
    for lo, hi, goal in TRI_GOALS:
        at = df[(df["dofs"] >= lo) & (df["dofs"] < hi)]
        for r in at.itertuples():
            verdicts.append(f"{r.size} ({r.dofs} dofs) {r.solve_ratio:.2f} (goal ≤ {goal:g}: "
                            f"{'met' if r.solve_ratio <= goal else 'not met'})")
    return ("pq.solve on the DKT disc (R = 1, 12 rigid posts, q and an off-centre P, meshed at R/n) ÷ one raw "
            "CHOLMOD factorise-and-solve of the same K, every step cold (a new mesh, its assembly pattern worked "
            "out again); the build split into gmsh's mesh, the element stiffness and the assembly; `kept_ratio` "
            "the same solve with its mesh kept (a sweep's next value). Goals: ≤ 4 × at about 12k dofs, ≤ 2.5 × "
            "from 100k dofs. " + ("; ".join(verdicts) + "." if verdicts else "This run has no row to judge.")
            + "\n\n" + table(df))


#: the goal of a sweep's cost per value after the first ÷ raw, at 128²
REUSE_GOAL = 0.3


def reuse_section(df, figdir):
    at = df[df["mesh"] == 128]
    if len(at):
        met = at[at["per_value_ratio"] <= REUSE_GOAL]
        verdict = (f"At 128² the goal is met by {len(met)} of {len(at)} sweeps ("
                   + ", ".join(f"{r.scene} {r.path} {r.per_value_ratio:.2f}" for r in at.itertuples()) + ").")
    else:
        verdict = "This run has no 128² row: the goal is not judged."
    return ("A sweep that keeps the plate's factorisation, its scaled data and its QP between values (a gap, "
            "a load or a spring stiffness sweeping): the cost of a value after the first, divided by one raw "
            "CHOLMOD factorise-and-solve of the same K (`per_value_ratio`), with the worst KKT residual over "
            f"the values. The goal: at most {REUSE_GOAL} at 128², every value exact and KKT-checked. "
            + verdict + "\n\n" + table(df))


def exact_section(df, figdir):
    at = df[df["mesh"] == 128]
    verdict = ""
    if len(at):
        verdict = ("At 128²: " + ", ".join(
            f"{r.scene} {r.path} {int(r.pieces)} piece{'s' if int(r.pieces) != 1 else ''}, {r.per_piece_ratio:.2f} a piece, "
            f"{r.per_value_ratio:.2f} a value"
            for r in at.itertuples()) + f" (the sweep goal, {REUSE_GOAL} a value, met by "
            f"{int((at['per_value_ratio'] <= REUSE_GOAL).sum())} of {len(at)}). ")
    return ("`sweep --exact` (plateqp.studies.exact_sweep): the exact path over the range, each piece's held "
            "system on one kept factorisation (plateqp.studies.held: `held_mode` springs or condensed), then the "
            "values on the model the path shares. `per_piece_ratio`: the path's CPU time (its start solve "
            "included) a held system, ÷ one raw CHOLMOD factorise-and-solve of the same K; `per_value_ratio`: "
            "(the exact sweep of V values − of one) / (V − 1) ÷ raw, which carries the path: its pieces count "
            "the contact set's changes over the range (a bed's load moves its lift-off line node by node), "
            "not the values. " + verdict + "\n\n" + table(df))


def soils_section(df, figdir):
    hs = df[(df["soil"] == "halfspace") & df["raw_s"].notna()]
    timed = hs[~hs["route"].astype(str).str.contains("fresh process")]
    at128 = timed[timed["mesh"] == 128]
    mem = hs[hs["route"].astype(str).str.contains("fresh process")]
    verdict = (f"The half-space at 128² contact cells: {at128['solve_ratio'].iloc[0]:.1f}× raw (goal ≤ 10×: "
               f"{'met' if at128['solve_ratio'].iloc[0] <= 10 else 'not met'}). " if len(at128) else "")
    if len(mem):
        r = mem.iloc[0]
        verdict += (f"At {int(r['mesh'])}² ({int(r['contacts'])} bed nodes) it solves in a process of its own: peak "
                    f"resident memory {r['memory_solve_mb']:.0f} MB above the imports against {r['memory_raw_mb']:.0f} MB "
                    f"for the raw factorisation, {r['solve_ratio']:.1f}× its CPU time, {r['status']}. ")
    return ("Each soil under the same plate (held on two edges, part of the bed lifting off): pq.solve from "
            "the scene (the build included) ÷ one raw CHOLMOD factorise-and-solve of the plate with every "
            "Winkler spring bonded. The half-space takes its soil's unknowns into K up to 1000 bed nodes "
            "(16² here) and is held matrix-free above (`matrix_free`; `matvecs` products of B K⁻¹ Bᵀ + H, "
            "each one sparse solve and the soil's FFTs). " + verdict + "\n\n" + table(df))


def goals_section(df, figdir):
    d = df.copy()
    met = d["met"].map({True: "yes", False: "**no**"}).fillna("–")
    short = d[d["met"].notna()]
    hit = int((short["met"] == True).sum())  # noqa: E712 - a pandas column
    d["met"] = met
    edge = []
    if "ratio_lo" in d:  # the repeats' spread (solve rows): a goal inside it is on the edge
        spread = d["ratio_lo"].notna()
        d["repeats"] = ""
        d.loc[spread, "repeats"] = [f"{lo:.3g}–{hi:.3g}" for lo, hi in zip(d.loc[spread, "ratio_lo"], d.loc[spread, "ratio_hi"])]
        inside = spread & d["limit"].notna() & (d["ratio_lo"] <= d["limit"]) & (d["limit"] <= d["ratio_hi"])
        edge = [f"{r.scene} {r.mesh}" for r in d[inside].itertuples()]
    cols = [c for c in ("goal", "scene", "mesh", "route", "accuracy", "detail", "unit", "raw", "measured", "ratio",
                        "repeats", "limit", "met", "kkt_worst") if c in d]
    said = (f" On the edge (the limit within the repeats' own ratios, met or missed by the machine's state): "
            f"{', '.join(edge)}." if edge else "")
    return f"Goals met today: {hit} of {len(short)}.{said}\n\n" + table(d[cols].astype(object).fillna(""))


def floors_section(df, figdir):
    d = df.copy()

    def get(scene, mesh, quantity, col="value"):
        hit = d[(d["scene"] == scene) & (d["mesh"] == mesh) & (d["quantity"] == quantity)]
        return float(hit[col].iloc[0]) if len(hit) else float("nan")

    lines = []
    for mesh in sorted(d[d["scene"] == "grid"]["mesh"].unique(), key=lambda m: int(str(m).rstrip("²"))):
        more = get("grid", mesh, "multiply-adds, posts last") / get("grid", mesh, "multiply-adds, CHOLMOD's order")
        lines.append(
            f"- Grid {mesh}: with the posts last, the one factorisation does {more:.1f}× the multiply-adds of "
            f"CHOLMOD's own order and takes {get('grid', mesh, 'numeric factorisation, posts last', 'per_raw'):.2f} "
            f"raw alone (in CHOLMOD's order: "
            f"{get('grid', mesh, 'numeric factorisation, CHOLMOD' + chr(39) + 's order', 'per_raw'):.2f}); "
            f"{get('grid', mesh, 'posts carrying the answer'):.0f} of {get('grid', mesh, 'posts'):.0f} posts carry "
            "the answer." + _whole_solves(get, "grid", mesh))
    for mesh in d[d["scene"] == "bed"]["mesh"].unique():
        q = d[(d["scene"] == "bed") & (d["mesh"] == mesh)]["quantity"]
        load = next((x for x in q if "loads" in x and "(median)" in x), None)
        modulus = next((x for x in q if "foundation.k" in x and "(median)" in x), None)
        if load is None or modulus is None:
            continue
        lines.append(
            f"- Bed {mesh}: a load value moves {get('bed', mesh, load):.0f} springs (median; up to "
            f"{get('bed', mesh, load.replace('(median)', '(largest)')):.0f}), a modulus value changes "
            f"{get('bed', mesh, modulus):.0f} (every spring in contact). One numeric refactorisation costs "
            f"{get('bed', mesh, 'numeric refactorisation (analysis kept)', 'per_raw'):.2f} raw and one solve "
            f"{get('bed', mesh, 'one solve, supernodal factor', 'per_raw'):.3f}; CHOLMOD's own update of 256 "
            f"springs {get('bed', mesh, 'in-place downdate of 256 springs (simplicial factor)', 'per_raw'):.2f}, "
            f"after {get('bed', mesh, 'in-place downdate of 1 spring on a fresh factor (its conversion)', 'per_raw'):.2f} "
            "to make its factor simplicial, on which a solve costs "
            f"{get('bed', mesh, 'one solve, simplicial factor (after an update)', 'per_raw'):.3f}.")
    for mesh in d[d["scene"] == "bed"]["mesh"].unique():
        if d[(d["scene"] == "bed") & (d["mesh"] == mesh) & (d["quantity"] == "pq.solve (the default route)")].empty:
            continue
        lines.append(f"- Bed {mesh}: the whole solve takes {get('bed', mesh, 'pq.solve (the default route)', 'per_raw'):.2f} "
                     f"raw, of which the coarse mesh's prediction of its contact set "
                     f"{get('bed', mesh, 'the coarse mesh' + chr(39) + 's prediction of the contact set', 'per_raw'):.2f}."
                     + _whole_solves(get, "bed", mesh))
    cols = ["scene", "mesh", "quantity", "value", "unit", "raw_s", "per_raw"]
    return "\n".join(lines) + "\n\n" + table(d[cols].astype(object).fillna(""))


def _whole_solves(get, scene: str, mesh) -> str:
    """The floors' whole-solve rows of ``scene`` at ``mesh`` in words ("" where not measured)."""
    fixed = get(scene, mesh, "pq.solve of the same kind of scene at 8² (a solve's fixed cost)", "per_raw")
    out = ""
    if scene == "grid":
        cond = get("grid", mesh, "pq.solve, condensed route (the default)", "per_raw")
        sparse = get("grid", mesh, "pq.solve, sparse method (option method='sparse')", "per_raw")
        if not math.isnan(cond):  # measured
            out += f" The whole solve: {cond:.2f} raw by the condensed route, {sparse:.2f} by the sparse method."
    if not math.isnan(fixed):
        out += (f" A solve of the same kind of scene at 8² cells (its plate's linear algebra a few per cent of it: "
                f"what any solve costs besides its plate) takes {fixed:.2f} of this plate's raw.")
    return out


def _change(now: float, before: float) -> str:
    """``now`` against ``before`` in words: "12% less", "3% more"."""
    pct = 100.0 * (now / before - 1.0)
    return f"{abs(pct):.0f}% {'more' if pct > 0 else 'less'}"


def kernel_section(df, figdir):
    d = df.copy()
    if "setting" not in d or not (d["setting"] == "default").any():
        return "*(not measured here: the settings are glibc's and Linux's)*"
    lines = []
    for (scene, mesh), g in d.groupby(["scene", "mesh"], sort=False):
        base = g[g["setting"] == "default"].iloc[0]
        line = (f"- {scene.capitalize()} {mesh}: the kernel's share of the CPU time, raw "
                f"{100 * base['raw_sys_share']:.0f}%, pq.solve {100 * base['pq_sys_share']:.0f}%; pq.solve ÷ raw "
                f"{base['ratio']:.2f}")
        for setting in g["setting"]:
            if setting == "default":
                continue
            k = g[g["setting"] == setting].iloc[0]
            line += (f". {setting.capitalize()}: raw {_change(k['raw_cpu'], base['raw_cpu'])}, pq.solve "
                     f"{_change(k['pq_cpu'], base['pq_cpu'])} CPU time, pq.solve ÷ raw {k['ratio']:.2f}")
        lines.append(line + ".")
    cols = ["scene", "mesh", "setting", "accuracy", "raw_user", "raw_sys", "pq_user", "pq_sys", "ratio"]
    return "\n".join(lines) + "\n\n" + table(d[cols].astype(object).fillna(""))


def parts() -> dict[str, Part]:
    p = {}
    p["goals"] = Part(
        "goals", "bench_goals", "goals.csv", "goals.csv",
        ["--out", "OUT"],
        ["--meshes", "32", "--big", "", "--disc-sizes", "8", "--memory-meshes", "32", "--memory-disc", "8",
         "--sweep-mesh", "32", "--values", "3", "--repeat", "1", "--memory-repeat", "1", "--out", "OUT"],
        goals_section, "Speed goals")
    p["floors"] = Part(
        "floors", "bench_floors", "floors.csv", "floors.csv", ["--out", "OUT"],
        ["--grid-meshes", "64", "--bed-mesh", "32", "--repeat", "1", "--out", "OUT"],
        floors_section, "What the goals not met are up against")
    p["kernel"] = Part(
        "kernel", "bench_kernel", "kernel.csv", "kernel.csv", ["--repeat", "2", "--out", "OUT"],
        ["--scenes", "bed", "--meshes", "32", "--repeat", "1", "--rounds", "1", "--out", "OUT"],
        kernel_section, "The kernel's share of a solve")
    p["work-precision"] = Part(
        "work-precision", "bench_work_precision", "work-precision.csv", "work_precision.csv",
        ["--sizes", "16", "--timeout", "60"],
        ["--sizes", "8", "--families", "grid_rigid", "--tols", "1e-4,1e-8",
         "--backends", "bpp,pdas,clarabel,osqp", "--timeout", "30"],
        wp_section, "Work against precision")
    p["cost-vs-mesh"] = Part(
        "cost-vs-mesh", "bench_fast", "cost-vs-mesh.csv", "cost-vs-mesh.csv",
        ["--parts", "goal", "--meshes", "32,64,128", "--repeat", "3", "--no-memory"],
        ["--parts", "goal", "--meshes", "32", "--repeat", "1", "--no-memory"],
        cost_section, "Cost against mesh size")
    p["cost-vs-mesh"].full += ["--out", "OUT"]
    p["cost-vs-mesh"].quick += ["--out", "OUT"]
    p["many-contacts"] = Part(
        "many-contacts", "bench_many_contacts", "many-contacts.csv", "many_contacts-*.csv",
        ["--mesh", "64", "--ks", "3,10,30,all,bed", "--repeat", "1", "--timeout", "120"],
        ["--mesh", "16", "--ks", "3,all", "--repeat", "1", "--backends", "pdas,clarabel",
         "--accuracies", "1e-6", "--timeout", "60"],
        contacts_section, "Many contacts")
    p["sweep"] = Part(
        "sweep", "bench_sweep", "sweep-cost.csv", "sweep.csv",
        ["--values", "20", "--repeats", "1"], ["--values", "3", "--repeats", "1", "--backends", "pdas"],
        sweep_section, "Cost per value of a sweep")
    p["discretisation"] = Part(
        "discretisation", "bench_discretisation", "discretisation-error.csv", "discretisation.csv",
        ["--families", "grid_rigid,bed", "--max-mesh", "64", "--timeout", "120"],
        ["--families", "grid_rigid", "--max-mesh", "16", "--timeout", "60"],
        disc_section, "Discretisation against solver error")
    p["extremes"] = Part(
        "extremes", "bench_extremes", "extremes.csv", "extremes.csv",
        ["--skip-cvxpy", "--no-first-rows"],
        ["--cases", "stiff-1", "--backends", "pdas", "--no-first-rows"],
        extremes_section, "Extremes")
    if TRI_SCRIPT.exists():
        p["triangles"] = Part("triangles", "bench_tri", "triangles-speed.csv", "triangles-speed.csv",
                              ["--repeat", "3"], ["--sizes", "16", "--repeat", "1"],
                              tri_section, "Triangles")
    if SWEEP_REUSE_SCRIPT.exists():
        p["sweep-reuse"] = Part("sweep-reuse", "bench_sweep_reuse", "sweep-reuse.csv", "sweep-reuse.csv",
                                [], ["--meshes", "32", "--scenes", "grid", "--values", "3", "--repeats", "1"],
                                reuse_section, "Sweeps reusing the factorisation")
    p["exact-sweep"] = Part("exact-sweep", "bench_exact_sweep", "exact-sweep.csv", "exact-sweep.csv",
                            ["--out", "OUT"],
                            ["--meshes", "32", "--scenes", "grid", "--kinds", "gap", "--values", "3", "--repeats", "1",
                             "--out", "OUT"],
                            exact_section, "Exact sweeps")
    p["soils"] = Part("soils", "bench_soils", "soils.csv", "soils.csv",
                      ["--hs-memory", "512", "--out", "OUT"],
                      ["--meshes", "16", "--hs-meshes", "8,32", "--repeats", "1", "--out", "OUT"],
                      soils_section, "Soils")
    for part in p.values():  # scripts taking --out: point it at the scratch results
        for lst in (part.full, part.quick):
            if "--out" in lst:
                lst[lst.index("--out") + 1] = "SCRATCH/results/" + part.produced
    return p


def one_model_section(out: Path) -> str:
    """The before/after table of one model per scene (kept as measured: not re-run here)."""
    src = HERE / "results" / "goal-one-model.csv"
    if not src.exists():
        return "*(results/goal-one-model.csv missing)*"
    df = pd.read_csv(src)
    if out.resolve() != HERE.resolve():
        (out / "results").mkdir(parents=True, exist_ok=True)
        shutil.copyfile(src, out / "results" / src.name)
    d = df.groupby(["variant", "scene", "mesh"], as_index=False)[["raw_s", "solve_s", "solve_ratio"]].median()
    return table(d)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="smallest sizes, one repeat, into --out (a temp dir)")
    ap.add_argument("--only", default="", help="comma-separated parts (default: all)")
    ap.add_argument("--out", default=None, help="directory of results/, figures/ and README.md")
    ap.add_argument("--list", action="store_true", help="list the parts")
    a = ap.parse_args(argv)
    ps = parts()
    if a.list:
        print("\n".join(ps))
        return 0
    names = [n for n in a.only.split(",") if n] or list(ps)
    unknown = [n for n in names if n not in ps]
    if unknown:
        ap.error(f"--only: unknown part {unknown[0]!r} (parts: {', '.join(ps)})")
    out = Path(a.out) if a.out else (Path(tempfile.mkdtemp(prefix="report-")) if a.quick else HERE)
    (out / "results").mkdir(parents=True, exist_ok=True)
    (out / "figures").mkdir(parents=True, exist_ok=True)
    cache = out / "results" / "sections.json"   # sections of parts not re-run keep their text
    sections = json.loads(cache.read_text()) if cache.exists() else {}
    failed = []
    for n in names:
        part = ps[n]
        print(f"report: {n} ...", flush=True)
        try:
            sections[n] = part.run(out, a.quick)
            print(f"report: {n} done", flush=True)
        except Exception as exc:  # noqa: BLE001 - every failure reported, exit status non-zero
            failed.append(n)
            print(f"report: {n} FAILED: {exc}", file=sys.stderr, flush=True)
    sections["one-model"] = one_model_section(out)
    cache.write_text(json.dumps(sections, indent=1))
    text = TEMPLATE.read_text()
    hooks = {"triangles": "bench_tri.py", "sweep-reuse": "bench_sweep_reuse.py"}
    for n, script in hooks.items():  # parts whose scripts are not here yet
        if n not in ps:
            text = text.replace("{{" + n + "}}", f"*(measured by `{script}` when present: "
                                f"`python benchmarks/report.py --only {n}`)*")
    for n in list(ps) + ["one-model"]:
        text = text.replace("{{" + n + "}}", sections.get(n, f"*(part {n} not run yet: "
                                                       f"`python benchmarks/report.py --only {n}`)*"))
    (out / "README.md").write_text(text)
    print(f"report: wrote {out / 'README.md'}" + (f"; FAILED: {', '.join(failed)}" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
