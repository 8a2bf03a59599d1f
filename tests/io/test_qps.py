"""Maros–Meszaros QPS files (plateqp.io.qps), checked against an independent reader and solver.

HiGHS reads the files we write and solves them (the reference is not plateqp's code); its
answer must be the one plateqp's exact solvers (Lemke, PDAS) give on the same scene, and mapped
back through :meth:`ExportedQP.result` it must pass the KKT check on the plate's terms.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.sparse as sp
from io_reference import FORMS, exported_problems, highs_solve, lower_mirror

import plateqp as pq
from plateqp.backends.base import QP
from plateqp.errors import ExportError
from plateqp.io import read_qps, write_qps


@pytest.fixture(scope="module")
def exported():
    """{form: (ExportedQP, plateqp reference Result)} for the small scene."""
    return exported_problems()


@pytest.mark.parametrize("form", FORMS)
def test_qps_solved_by_highs_matches_plateqp(exported, tmp_path, form):
    e, ref = exported[form]
    path = write_qps(e, tmp_path / f"small_{form}.qps")
    x, row_dual, obj, names = highs_solve(path)
    assert names == e.var_names
    x_ref = e.x_from_result(ref)
    assert np.abs(x - x_ref).max() <= 1e-8 * np.abs(x_ref).max()
    assert obj == pytest.approx(e.objective(x_ref), rel=1e-10, abs=1e-12)
    # HiGHS's x mapped back to the plate: KKT met at high accuracy, the same reactions
    z = -row_dual if form == "primal" else None  # HiGHS: row duals of G x <= h are <= 0
    res = e.result(x, z=z, accuracy="high", solver="highs")
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert np.abs(res.reactions - ref.reactions).max() <= 1e-7 * np.abs(ref.reactions).max()
    assert np.array_equal(res.active, ref.active)


@pytest.mark.parametrize("form", FORMS)
def test_qps_round_trip_is_exact(exported, tmp_path, form):
    e, _ = exported[form]
    path = write_qps(e, tmp_path / f"small_{form}.qps")
    qp, info = read_qps(path, with_info=True)
    P0 = lower_mirror(e.qp.P)
    P1 = sp.csc_matrix(qp.P)
    assert P1.shape == P0.shape and (P1 != P0).nnz == 0
    assert np.array_equal(qp.q, e.qp.q)
    if form == "primal":
        assert (sp.csc_matrix(qp.G) != sp.csc_matrix(e.qp.G)).nnz == 0 and np.array_equal(qp.h, e.qp.h)
        assert qp.lb is None and qp.ub is None  # FR bounds
        assert info.row_names == e.row_names
    else:
        assert qp.G is None and np.array_equal(qp.lb, e.qp.lb) and qp.ub is None
    assert qp.A is None and info.var_names == e.var_names and info.name == e.name
    # the metadata (scales, meaning of x) travels as JSON in the comment lines
    header = "\n".join(info.comments)
    meta = json.loads(header[header.index("{"):header.rindex("}") + 1])
    assert meta["formulation"] == form and meta["W"] == e.meta["W"] and meta["F0"] == e.meta["F0"]


def test_qps_general_rows_bounds_and_offset(tmp_path):
    """E rows, finite and negative upper bounds, a fixed variable, the objective constant:
    written by us, read and solved by HiGHS, read back by us."""
    P = np.array([[4.0, 1.0, 0.0, 0.0], [1.0, 3.0, 0.5, 0.0], [0.0, 0.5, 2.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    qp = QP(P=sp.csc_matrix(P), q=np.array([-1.0, 2.0, -3.0, 0.25]),
            G=sp.csc_matrix(np.array([[1.0, 1.0, 0.0, 0.0], [0.0, -1.0, 1.0, 0.0]])), h=np.array([0.5, 1.0]),
            A=sp.csc_matrix(np.array([[1.0, 0.0, 1.0, 1.0]])), b=np.array([1.0 / 3.0]),
            lb=np.array([-np.inf, -2.0, 0.1, 0.2]), ub=np.array([-0.1, np.inf, 5.0, 0.2]))
    path = write_qps(qp, tmp_path / "gen.qps", "GEN", offset=0.7)
    x, _, obj, _ = highs_solve(path)
    assert np.all(x <= qp.ub + 1e-9) and np.all(x >= qp.lb - 1e-9) and x[3] == pytest.approx(0.2)
    assert qp.A @ x == pytest.approx(qp.b) and np.all(qp.G @ x <= qp.h + 1e-9)
    assert obj == pytest.approx(0.5 * x @ P @ x + qp.q @ x + 0.7, rel=1e-12)
    back, info = read_qps(path, with_info=True)
    assert info.offset == 0.7 and info.eq_names == ["e0"]
    for key in ("q", "h", "b", "lb", "ub"):
        assert np.array_equal(getattr(back, key), getattr(qp, key)), key
    for key in ("P", "G", "A"):
        assert (sp.csc_matrix(getattr(back, key)) != sp.csc_matrix(getattr(qp, key))).nnz == 0, key
    # and the optimum of what we read back is HiGHS's
    qpsolvers = pytest.importorskip("qpsolvers")
    y = qpsolvers.solve_qp(back.P, back.q, back.G, back.h, back.A, back.b, back.lb, back.ub, solver="clarabel",
                           tol_gap_abs=1e-12, tol_gap_rel=1e-12, tol_feas=1e-12)
    assert np.abs(y - x).max() < 1e-7


def test_read_qps_g_rows_and_ranges(tmp_path):
    """A hand-written QPS (fixed-looking, G and ranged rows, QUADOBJ): our reader and HiGHS agree."""
    text = """NAME          HAND
ROWS
 N  COST
 G  R1
 L  R2
 E  R3
COLUMNS
    X1        COST      1.0        R1        1.0
    X1        R2        1.0        R3        1.0
    X2        COST      -2.0       R1        1.0
    X2        R3        -1.0
    X3        R2        1.0
RHS
    RHS       R1        1.0        R2        4.0
    RHS       R3        0.5        COST      -1.5
RANGES
    RNG       R2        2.5        R3        1.0
BOUNDS
 UP BND       X1        3.0
 MI BND       X2
 UP BND       X2        2.0
 FR BND       X3
QUADOBJ
    X1        X1        2.0
    X2        X1        0.5
    X2        X2        1.0
    X3        X3        4.0
ENDATA
"""
    path = tmp_path / "hand.qps"
    path.write_text(text)
    qp, info = read_qps(path, with_info=True)
    assert info.offset == 1.5 and info.var_names == ["X1", "X2", "X3"]
    assert qp.A is None  # the ranged E row is two inequalities
    assert qp.G.shape == (5, 3)  # R1 (>=), R2 both sides, R3 both sides
    assert qp.P.toarray() == pytest.approx(np.array([[2.0, 0.5, 0.0], [0.5, 1.0, 0.0], [0.0, 0.0, 4.0]]))
    x, _, obj, _ = highs_solve(path)
    qpsolvers = pytest.importorskip("qpsolvers")
    y = qpsolvers.solve_qp(qp.P, qp.q, qp.G, qp.h, qp.A, qp.b, qp.lb, qp.ub, solver="clarabel",
                           tol_gap_abs=1e-12, tol_gap_rel=1e-12, tol_feas=1e-12)
    assert np.abs(y - x).max() < 1e-7
    assert obj == pytest.approx(0.5 * y @ qp.P @ y + qp.q @ y + info.offset, abs=1e-9)


def test_write_qps_refuses_bad_names(tmp_path):
    qp = QP(P=sp.identity(2, format="csc"), q=np.ones(2))
    with pytest.raises(ExportError, match="spaces"):
        write_qps(qp, tmp_path / "a.qps", var_names=["a b", "c"])
    with pytest.raises(ExportError, match="unique"):
        write_qps(qp, tmp_path / "a.qps", var_names=["a", "a"])
