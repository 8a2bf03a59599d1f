"""Grade a qpbenchmark run of the plateqp test set against the stored reference solutions.

    /tmp/qpbvenv/bin/python benchmarks/qpbenchmark/grade.py benchmarks/qpbenchmark/plateqp_graded.py \\
        --results benchmarks/qpbenchmark/results/plateqp_graded.csv [--settings high_accuracy,default]

qpbenchmark's CSV says whether a solver claimed a solution and how small its residuals and duality
gap were; it keeps no x. This script replays every call that CSV holds as found (the same
problem, solver and settings: the test set's own ``solver_settings``, through qpbenchmark's
``time_solve_problem``), takes the reactions from the solver's answer (primal: the multipliers
z of the gap rows; condensed: P x + q; dual: x) and compares them with the reference's:
``reaction_error = max |R − R_ref| / max |R_ref|``. Calls qpbenchmark recorded as not found, or
past the time limit, are graded as failures without a rerun. Writes ``grades.csv`` (one row per
call) and ``grades.md`` (per settings and solver: qpbenchmark's success and the share of problems
with the reactions right to 1e-6, by grade) beside the results CSV; run again, it grades only the
calls its ``grades.csv`` lacks. Runs where qpbenchmark runs (numpy, qpsolvers, qpbenchmark);
plateqp is not needed.
"""

from __future__ import annotations

import argparse
import csv
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

#: reactions within this relative error count as right
RIGHT = 1e-6


def reactions(problem, solution, form: str):
    """The scaled reactions of a solver's answer, by form (None if it gave none)."""
    if solution is None or not solution.found or solution.x is None:
        return None
    if form == "primal":
        return None if solution.z is None else np.asarray(solution.z, dtype=float)
    if form == "condensed":
        return np.asarray(problem.P @ solution.x + problem.q, dtype=float).ravel()
    return np.asarray(solution.x, dtype=float)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("test_set", help="the test-set module (plateqp_graded.py)")
    ap.add_argument("--results", required=True, help="qpbenchmark's results CSV of that test set")
    ap.add_argument("--settings", default="high_accuracy,default", help="settings to grade, comma separated")
    args = ap.parse_args(argv)
    from qpbenchmark.benchmark import load_test_set
    from qpbenchmark.utils import time_solve_problem

    module_path = Path(args.test_set).resolve()
    test_set = load_test_set(str(module_path))
    module = sys.modules[module_path.stem]
    settings = [s for s in args.settings.split(",") if s]
    with open(args.results, newline="") as fh:
        ran = {(r["problem"], r["solver"], r["settings"]): r for r in csv.DictReader(fh)}
    out = Path(args.results).with_name("grades.csv")
    done = {}
    if out.exists():  # a second run grades only what the first did not
        with open(out, newline="") as fh:
            for r in csv.DictReader(fh):
                r.update(mesh=int(r["mesh"]), reaction_error=float(r["reaction_error"]),
                         qpbenchmark_success=r["qpbenchmark_success"] == "True")
                done[(r["problem"], r["solver"], r["settings"])] = r
    rows = []
    for problem in test_set:
        ref = module.reference(problem.name)
        grade = ref["meta"]["grade"]
        R_ref = ref["reactions"]
        for solver in sorted(test_set.solvers):
            for s in settings:
                r = ran.get((problem.name, solver, s))
                if r is None:
                    continue
                if (problem.name, solver, s) in done:
                    rows.append(done[(problem.name, solver, s)])
                    continue
                err = np.nan
                # a call past the time limit failed by qpbenchmark's rule whatever its answer: not replayed
                if r["found"] == "True" and float(r["runtime"]) <= test_set.tolerances[s].runtime:
                    solution, _ = time_solve_problem(problem, solver, **test_set.solver_settings[s][solver])
                    R = reactions(problem, solution, grade["form"])
                    if R is not None and R.shape == R_ref.shape:
                        err = float(np.abs(R - R_ref).max() / np.abs(R_ref).max())
                rows.append({"problem": problem.name, **grade, "solver": solver, "settings": s,
                             "found": r["found"], "qpbenchmark_success": _success(r, test_set.tolerances[s]),
                             "reaction_error": err})
        print(f"{problem.name}: graded", flush=True)
    with open(out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    out.with_suffix(".md").write_text(summary(rows, settings))
    print(f"wrote {out} and {out.with_suffix('.md')}")
    return 0


def _success(row, tol) -> bool:
    """qpbenchmark's success: found, residuals and gap within the settings' tolerances, in time."""
    return (row["found"] == "True" and float(row["primal_residual"]) <= tol.primal
            and float(row["dual_residual"]) <= tol.dual and float(row["duality_gap"]) <= tol.gap
            and float(row["runtime"]) <= tol.runtime)


def summary(rows, settings) -> str:
    """Markdown: per settings, two tables (qpbenchmark's success; reactions right to RIGHT), each
    per solver, overall and by each grade axis, in % of the problems."""
    axes = {"form": ("primal", "condensed", "dual"), "mesh": sorted({r["mesh"] for r in rows}),
            "kind": ("rigid", "elastic", "bed"), "gaps": ("zero", "heave", "settle", "mixed", "liftoff")}
    tests = {"success (qpbenchmark's criterion: found, residuals and duality gap within the settings' "
             "tolerances, within the time limit)": lambda r: r["qpbenchmark_success"],
             f"reactions right to {RIGHT:g} (max |R − R_ref| / max |R_ref|; answer replayed)":
             lambda r: r["reaction_error"] <= RIGHT}
    lines = ["# plateqp_graded: qpbenchmark's verdict and the reactions against the references", "",
             "Each cell: % of that column's problems. 'claimed, wrong': qpbenchmark successes whose "
             f"reactions are off by more than {RIGHT:g}.", ""]
    head = ["solver", "all"] + [f"{v}²" if a == "mesh" else str(v) for a, vals in axes.items() for v in vals]
    for s in settings:
        sub = [r for r in rows if r["settings"] == s]
        by = defaultdict(list)
        for r in sub:
            by[r["solver"]].append(r)
        lines += [f"## {s}", ""]
        for title, ok in tests.items():
            lines += [f"{title}:", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
            for solver, rs in sorted(by.items()):
                cells = [solver, f"{100 * sum(map(ok, rs)) / len(rs):.0f}"]
                for a, vals in axes.items():
                    for v in vals:
                        g = [r for r in rs if r[a] == v]
                        cells.append(f"{100 * sum(map(ok, g)) / len(g):.0f}" if g else "–")
                lines.append("| " + " | ".join(cells) + " |")
            lines.append("")
        wrong = [r for r in sub if r["qpbenchmark_success"] and not r["reaction_error"] <= RIGHT]
        lines.append(f"Claimed, wrong: {len(wrong)} calls" + ("." if not wrong else ", by solver (number; "
                     "smallest … largest reaction error; gap patterns): " + "; ".join(
            f"{solver} ({len(ws)}; {min(w['reaction_error'] for w in ws):.0e} … "
            f"{max(w['reaction_error'] for w in ws):.0e}; "
            + ", ".join(f"{g} {sum(w['gaps'] == g for w in ws)}" for g in axes["gaps"]
                        if any(w["gaps"] == g for w in ws)) + ")"
            for solver, ws in sorted(_group(wrong, "solver").items())) + "."))
        lines.append("")
    return "\n".join(lines)


def _group(rows, key) -> dict:
    out = defaultdict(list)
    for r in rows:
        out[r[key]].append(r)
    return out


if __name__ == "__main__":
    sys.exit(main())
