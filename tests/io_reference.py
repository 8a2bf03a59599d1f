"""The reference problem of the io tests: a small scene exported in every formulation, solved by
plateqp's exact solvers, and HiGHS as an independent reader and solver of QPS files (imported by
tests/io/test_export.py, test_qps.py, test_qpbenchmark.py; pytest puts tests/ on sys.path)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

import plateqp as pq
from plateqp.cli import main
from plateqp.io import contact_qp

FORMS = ("primal", "condensed", "dual")
# plateqp's reference solver for each form: exact pivoting, or PDAS (KKT ~1e-13)
REFERENCE = {"primal": "pdas", "condensed": "lemke", "dual": "lemke"}


def small_scene() -> pq.Scene:
    """8 × 8, two simple edges, five one-sided supports: heave and settlement, rigid and
    elastic; one support lifts off, four touch."""
    supports = [pq.Support(0.25, 0.25, gap=-0.002), pq.Support(0.75, 0.25, gap=0.0, stiffness=2e4),
                pq.Support(0.25, 0.75, gap=0.001), pq.Support(0.75, 0.75, gap=0.0005, stiffness=5e4),
                pq.Support(0.5, 0.5, gap=0.0)]
    return pq.Scene(name="small", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(8, 8, "acm"),
                    edges={"left": pq.Edge("simple"), "right": pq.Edge("simple")},
                    loads=[pq.PointLoad(P=100.0, x=0.6, y=0.55), pq.UniformLoad(q=20.0)], supports=supports)


def exported_problems():
    """{form: (ExportedQP, plateqp reference Result)} for the small scene."""
    sc = small_scene()
    out = {}
    for form in FORMS:
        e = contact_qp(sc, form)
        ref = pq.solve(sc, backend=REFERENCE[form], formulation=form, accuracy="high")
        assert ref.status == pq.Status.OPTIMAL
        out[form] = (e, ref)
    active = out["condensed"][1].active
    assert active.any() and not active.all()  # a real contact problem: some touch, some lift off
    return out


def lower_mirror(P) -> sp.csc_matrix:
    """What a QPS file holds: the lower triangle, read back symmetric."""
    P = sp.csc_matrix(P)
    return (sp.tril(P) + sp.tril(P, -1).T).tocsc()


def highs_solve(path: Path):
    """Read a QPS file with HiGHS (which wants the .mps extension) and solve it exactly."""
    highspy = pytest.importorskip("highspy")
    mps = path.with_suffix(".mps")
    if not mps.exists():
        os.symlink(path.name, mps)
    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    # HiGHS ≥ 1.16 warns (kWarning) that it ignores Hessian entries ≤ 1e-9: the assembly's
    # cancellation noise (≤ 5e-15 of the diagonal) that the exact export keeps; an error fails
    assert h.readModel(str(mps)) in (highspy.HighsStatus.kOk, highspy.HighsStatus.kWarning)
    h.setOptionValue("qp_regularization_value", 0.0)  # HiGHS regularises its QPs by 1e-7 by default
    h.setOptionValue("primal_feasibility_tolerance", 1e-10)
    h.setOptionValue("dual_feasibility_tolerance", 1e-10)
    h.run()
    assert h.modelStatusToString(h.getModelStatus()) == "Optimal"
    sol = h.getSolution()
    names = [h.getColName(j)[1] for j in range(h.getNumCol())]
    return (np.array(sol.col_value), np.array(sol.row_dual), h.getInfo().objective_function_value, names)


def run_cli(capsys, *argv):
    """``plateqp ARGV...`` in-process: (exit code, stdout, stderr); argparse's SystemExit read as
    its exit code."""
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exn:
        code = exn.code
    out = capsys.readouterr()
    return code, out.out, out.err

