"""Export to standard formats (QPS, qpbenchmark), checked against independent readers and solvers.

The references are not plateqp's own code: HiGHS reads the QPS files and solves them, the .npz
files are read here with numpy/scipy alone and solved by Clarabel through qpsolvers, and both
must give the solution plateqp's exact solvers (Lemke, PDAS) give on the same scene.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

import plateqp as pq
from plateqp import scenes
from plateqp.backends.base import QP
from plateqp.cli import main
from plateqp.export import (
    QPBENCHMARK_TOLERANCES,
    ExportError,
    contact_qp,
    qpbenchmark_class_name,
    read_npz,
    read_qps,
    write_npz,
    write_qpbenchmark,
    write_qps,
)

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


@pytest.fixture(scope="module")
def exported():
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


# -- QPS ---------------------------------------------------------------------------------------


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


# -- qpbenchmark test sets ---------------------------------------------------------------------


def load_npz_independently(path: Path):
    """The .npz layout, read with numpy and scipy alone (not plateqp's reader)."""
    f = np.load(path, allow_pickle=False)
    out = {}
    for key in ("P", "G", "A"):
        if key in f.files:
            out[key] = f[key]
        elif f"{key}_data" in f.files:
            out[key] = sp.csc_matrix((f[f"{key}_data"], f[f"{key}_indices"], f[f"{key}_indptr"]),
                                     shape=tuple(f[f"{key}_shape"]))
        else:
            out[key] = None
    for key in ("q", "h", "b", "lb", "ub"):
        out[key] = f[key] if key in f.files else None
    return out, json.loads(str(f["meta"]))


@pytest.mark.filterwarnings("ignore:Converted matrix")  # qpsolvers: the dense condensed P
def test_qpbenchmark_npz_solved_by_clarabel(exported, tmp_path):
    qpsolvers = pytest.importorskip("qpsolvers")
    if "clarabel" not in qpsolvers.available_solvers:
        pytest.skip("clarabel is not installed for qpsolvers")
    problems = [exported[f][0] for f in FORMS]
    module = write_qpbenchmark(problems, tmp_path / "set", name="plate_small")
    data = tmp_path / "set" / "data"
    assert sorted(p.name for p in data.iterdir()) == sorted(f"{e.name}.npz" for e in problems)
    for form in FORMS:
        e, ref = exported[form]
        d, meta = load_npz_independently(data / f"{e.name}.npz")
        assert meta["formulation"] == form and meta["var_names"] == e.var_names
        if form == "primal":
            assert sp.issparse(d["P"]) and sp.issparse(d["G"])  # never densified
        problem = qpsolvers.Problem(d["P"], d["q"], d["G"], d["h"], d["A"], d["b"], d["lb"], d["ub"])
        sol = qpsolvers.solve_problem(problem, solver="clarabel", tol_gap_abs=1e-11, tol_gap_rel=1e-11,
                                      tol_feas=1e-11)
        assert sol.found
        x_ref = e.x_from_result(ref)
        assert np.abs(sol.x - x_ref).max() <= 1e-6 * np.abs(x_ref).max()
        # and plateqp's own reader gives back the very arrays
        qp = read_npz(data / f"{e.name}.npz")
        assert np.array_equal(qp.q, e.qp.q)
        assert (sp.csc_matrix(qp.P) != sp.csc_matrix(e.qp.P)).nnz == 0
    # the generated module: valid Python, the class name qpbenchmark looks for, every problem listed
    text = module.read_text()
    compile(text, str(module), "exec")
    assert f"class {qpbenchmark_class_name('plate_small')}(TestSet)" in text and "class PlateSmall(" in text
    for e in problems:
        assert repr(e.name) in text
    for settings, (tol, _) in QPBENCHMARK_TOLERANCES.items():
        assert repr(settings) in text and repr(tol) in text


def test_qpbenchmark_module_loads_with_qpbenchmark(exported, tmp_path):
    pytest.importorskip("qpbenchmark")
    import importlib.util

    module = write_qpbenchmark([exported["primal"][0]], tmp_path / "set", name="plate_one")
    spec = importlib.util.spec_from_file_location("plate_one", module)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    ts = getattr(mod, qpbenchmark_class_name("plate_one"))()
    (problem,) = list(ts)
    assert problem.name == exported["primal"][0].name and ts.sparse_only


def test_write_qpbenchmark_refuses_non_empty_directory(exported, tmp_path):
    out = tmp_path / "set"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    with pytest.raises(ExportError, match="not empty"):
        write_qpbenchmark([exported["dual"][0]], out)
    write_qpbenchmark([exported["dual"][0]], out, force=True)
    assert (out / "keep.txt").read_text() == "mine"
    with pytest.raises(ExportError, match="identifier"):
        write_qpbenchmark([exported["dual"][0]], tmp_path / "other", name="not-a-module")


def test_npz_round_trip_dense_and_sparse(tmp_path):
    qp = QP(P=np.array([[2.0, 1.0], [1.0, 2.0]]), q=np.array([1.0, -1.0]), G=sp.csc_matrix(np.eye(2)),
            h=np.array([1.0, 2.0]), lb=np.array([-1.0, -np.inf]))
    path = write_npz(qp, tmp_path / "p.npz", meta={"note": "x"})
    back, meta = read_npz(path, with_meta=True)
    assert isinstance(back.P, np.ndarray) and np.array_equal(back.P, qp.P)
    assert sp.issparse(back.G) and np.array_equal(back.G.toarray(), np.eye(2))
    assert np.array_equal(back.lb, qp.lb) and back.ub is None and back.A is None and meta == {"note": "x"}


def test_contact_qp_is_the_backends_problem(exported):
    """The exported QP is the one a QP backend is handed (same data, same formulation)."""
    from plateqp.assembly import build_model
    from plateqp.contact import Scaled, formulate

    e, _ = exported["primal"]
    qp = formulate(Scaled.from_model(build_model(small_scene())), "primal").problem(frozenset({"qp"}))
    assert (sp.csc_matrix(qp.P) != sp.csc_matrix(e.qp.P)).nnz == 0 and np.array_equal(qp.q, e.qp.q)
    assert e.meta["n_contacts"] == 5 and e.meta["n_elastic"] == 2 and len(e.row_names) == 5
    assert e.var_names[-2:] == ["t_1", "t_3"]  # the elastic supports' spring variables
    with pytest.raises(pq.ProblemError, match="formulation"):
        contact_qp(small_scene(), "auto")


# -- command line ------------------------------------------------------------------------------


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_export_qps_and_refuses_to_overwrite(capsys, tmp_path):
    out = tmp_path / "heave.qps"
    code, stdout, _ = run_cli(capsys, "export", "heave", "--formulation", "condensed", "--out", out)
    assert code == 0 and "heave_condensed" in stdout
    qp, info = read_qps(out, with_info=True)
    sc = scenes.load("heave")
    assert qp.n == len(sc.supports) and info.name == "heave_condensed"
    before = out.read_text()
    code, _, err = run_cli(capsys, "export", "heave", "--out", out)
    assert code == 2 and "exists" in err and "--force" in err and len(err.strip().splitlines()) == 1
    assert out.read_text() == before
    code, _, _ = run_cli(capsys, "export", "heave", "--out", out, "--force")  # primal now
    assert code == 0 and read_qps(out).n > len(sc.supports)


def test_cli_export_qpbenchmark_from_a_scene_file(capsys, tmp_path):
    scene_file = tmp_path / "small.toml"
    small_scene().to_toml(scene_file)
    out = tmp_path / "set"
    code, _, _ = run_cli(capsys, "export", scene_file, "--formulation", "dual", "--format", "qpbenchmark",
                         "--out", out, "--testset", "small_set")
    assert code == 0
    assert (out / "small_set.py").exists() and (out / "data" / "small_dual.npz").exists()
    code, _, err = run_cli(capsys, "export", scene_file, "--format", "qpbenchmark", "--out", out)
    assert code == 2 and "not an empty directory" in err
    assert sorted(p.name for p in (out / "data").iterdir()) == ["small_dual.npz"]  # untouched


@pytest.mark.parametrize("argv, words", [
    (["export", "no-such-scene", "--out", "{tmp}/x.qps"], "no such file"),
    (["export", "heave", "--formulation", "dual", "--out", "{tmp}/x.qps"], "floats"),
    (["export", "slab", "--out", "{tmp}/x.qps"], "no one-sided supports"),
    (["export", "heave", "--format", "qpbenchmark", "--testset", "9lives", "--out", "{tmp}/set"], "identifier"),
    (["export", "heave", "--out", "{tmp}"], "is a directory"),
])
def test_cli_export_errors(capsys, tmp_path, argv, words):
    code, _, err = run_cli(capsys, *[a.format(tmp=tmp_path) for a in argv])
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.qps").exists() and not (tmp_path / "set").exists()
