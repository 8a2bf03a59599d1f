"""qpbenchmark test sets (plateqp.io.qpbenchmark): the .npz files read with numpy and scipy alone
and solved by Clarabel through qpsolvers; the generated module run as qpbenchmark would run it."""

from __future__ import annotations

import importlib.util
import json
import sys
import types
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
from io_reference import FORMS, exported_problems

from plateqp.errors import ExportError
from plateqp.io import QPBENCHMARK_TOLERANCES, qpbenchmark_class_name, read_npz, write_qpbenchmark


@pytest.fixture(scope="module")
def exported():
    """{form: (ExportedQP, plateqp reference Result)} for the small scene."""
    return exported_problems()


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


def load_module(path: Path, name: str):
    """Import a generated test-set module from its file, as qpbenchmark does."""
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_qpbenchmark_module_loads_with_qpbenchmark(exported, tmp_path):
    pytest.importorskip("qpbenchmark")
    module = write_qpbenchmark([exported["primal"][0]], tmp_path / "set", name="plate_one")
    ts = getattr(load_module(module, "plate_one"), qpbenchmark_class_name("plate_one"))()
    (problem,) = list(ts)
    assert problem.name == exported["primal"][0].name and ts.sparse_only


def test_generated_module_loads_every_problem_without_plateqp(exported, tmp_path, monkeypatch):
    """The generated module runs with numpy, scipy and (here a stand-in for) qpbenchmark alone,
    plateqp made unimportable, and gives back every problem exactly as exported."""
    stub = types.ModuleType("qpbenchmark")

    class Problem:
        def __init__(self, P, q, G, h, A, b, lb, ub, name):
            self.P, self.q, self.G, self.h, self.A, self.b, self.lb, self.ub, self.name = P, q, G, h, A, b, lb, ub, name

    stub.Problem, stub.TestSet, stub.Tolerance = Problem, object, lambda **kw: kw
    monkeypatch.setitem(sys.modules, "qpbenchmark", stub)
    problems = [exported[f][0] for f in FORMS]
    module = write_qpbenchmark(problems, tmp_path / "set", name="plate_all", data_dir="data/all")
    monkeypatch.setitem(sys.modules, "plateqp", None)  # `import plateqp` fails from here on
    ts = load_module(module, "plate_all").PlateAll()
    loaded = list(ts)
    assert [p.name for p in loaded] == [e.name for e in problems]
    for e, p in zip(problems, loaded):
        for key in ("P", "G", "A"):
            want, got = getattr(e.qp, key), getattr(p, key)
            assert (want is None) == (got is None) and sp.issparse(want) == sp.issparse(got), key
            if want is not None:
                assert got.shape == want.shape and (sp.csc_matrix(got) != sp.csc_matrix(want)).nnz == 0, key
        for key in ("q", "h", "b", "lb", "ub"):
            want, got = getattr(e.qp, key), getattr(p, key)
            assert (want is None and got is None) or np.array_equal(want, got), key
    ts.define_tolerances()
    assert {k: t["gap"] for k, t in ts.tolerances.items()} == {k: v[0] for k, v in QPBENCHMARK_TOLERANCES.items()}
    assert ts.sparse_only  # the primal P is sparse


def test_write_qpbenchmark_refuses_non_empty_directory(exported, tmp_path):
    out = tmp_path / "set"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    with pytest.raises(ExportError, match="not an empty directory"):
        write_qpbenchmark([exported["dual"][0]], out)
    write_qpbenchmark([exported["dual"][0]], out, force=True)
    assert (out / "keep.txt").read_text() == "mine"
    with pytest.raises(ExportError, match="identifier"):
        write_qpbenchmark([exported["dual"][0]], tmp_path / "other", name="not-a-module")
