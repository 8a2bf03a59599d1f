"""The qpbenchmark test set (plateqp.io.qpbenchmark, plateqp.io.graded): the generated module is a
qpbenchmark ``TestSet`` that loads without plateqp; every stored reference solution satisfies the
KKT conditions of its stored problem (checked here with numpy alone); the three forms of one
instance are independent formulations that give the same reactions; the grade names are as
documented. Small meshes only (8², one 16² instance per support kind)."""

from __future__ import annotations

import hashlib
import json
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from plateqp.errors import ExportError
from plateqp.io import QPBENCHMARK_TOLERANCES, qpbenchmark_class_name, write_qpbenchmark
from plateqp.io.graded import (
    BED_MAX_MESH,
    FORMS,
    GAP_PATTERNS,
    MESHES,
    SUPPORT_KINDS,
    gap_field,
    grade_name,
    graded_problems,
    grades,
    parse_grade,
)

ROOT = Path(__file__).resolve().parents[2]
NAME = "plate_graded"
#: the KKT residuals of a reference, relative to the size of the terms they balance
KKT_TOL = 1e-9


@pytest.fixture(scope="module")
def graded_set(tmp_path_factory):
    """The graded set on 8² (every kind and gap pattern) plus 16² liftoff instances, written as
    a test set with references: (module path, {name: ExportedQP})."""
    out = tmp_path_factory.mktemp("qpb") / "set"
    items = list(graded_problems(meshes=(8,))) + list(graded_problems(meshes=(16,), gaps=("liftoff",)))
    problems = [e for e, _, _ in items]
    module = write_qpbenchmark(problems, out, name=NAME, references={e.name: r for e, r, _ in items},
                               densify_max_n=200, settings=("default", "high_accuracy"))
    return module, {e.name: e for e in problems}


# -- an independent reader of the files (numpy and scipy only) -------------------------------------


def read_problem(path: Path) -> dict:
    """A problem file: qpsolvers' Problem.save layout (absent entries are pickled None) or CSC parts."""
    f = np.load(path, allow_pickle=False)
    out = {}
    for key in ("P", "q", "G", "h", "A", "b", "lb", "ub"):
        if f"{key}_data" in f.files:
            out[key] = sp.csc_matrix((f[f"{key}_data"], f[f"{key}_indices"], f[f"{key}_indptr"]),
                                     shape=tuple(f[f"{key}_shape"]))
        elif key in f.files:
            try:
                out[key] = f[key]
            except ValueError:  # an object array: Problem.save's np.array(None)
                out[key] = None
        else:
            out[key] = None
    return out


def read_reference(path: Path) -> dict:
    f = np.load(path, allow_pickle=False)
    out = {k: (f[k] if k in f.files else None) for k in ("x", "z", "z_box", "reactions")}
    out["objective"] = float(f["objective"])
    out["meta"] = json.loads(str(f["meta"]))
    return out


def problems_of(module: Path):
    for path in sorted((module.parent / "data").iterdir()):
        yield path.stem, read_problem(path), read_reference(module.parent / "solutions" / path.name)


def fingerprint(P, q, G, h, A, b, lb, ub) -> str:
    """A hash of a problem's arrays (matrices dense), the same whoever loaded them."""
    m = hashlib.sha256()
    for v in (P, q, G, h, A, b, lb, ub):
        if v is None:
            m.update(b"None")
        else:
            v = v.toarray() if sp.issparse(v) else np.asarray(v)
            m.update(repr(v.shape).encode())
            m.update(np.ascontiguousarray(v, dtype=float).tobytes())
    return m.hexdigest()


# -- the module: a qpbenchmark TestSet that needs no plateqp ------------------------------------------

# qpbenchmark's interface, for a subprocess where qpbenchmark is not installed: an abstract TestSet
# with the members its load_test_set and run use, and Problem = qpsolvers.Problem with a name
STUB = '''
import abc, os
import qpsolvers

class Problem(qpsolvers.Problem):
    def __init__(self, P, q, G, h, A, b, lb, ub, name):
        super().__init__(P, q, G, h, A, b, lb, ub)
        self.name = name

    @staticmethod
    def load(file):
        p = qpsolvers.Problem.load(file)
        return Problem(p.P, p.q, p.G, p.h, p.A, p.b, p.lb, p.ub, os.path.splitext(os.path.basename(file))[0])

class TestSet(abc.ABC):
    @abc.abstractmethod
    def __iter__(self): ...
    @property
    @abc.abstractmethod
    def description(self): ...
    @property
    @abc.abstractmethod
    def sparse_only(self): ...
    @property
    @abc.abstractmethod
    def title(self): ...
    def define_tolerances(self, runtime=10.0):
        self.tolerances = {name: runtime for name in ("default", "low_accuracy", "mid_accuracy", "high_accuracy")}
    def define_solver_settings(self):
        self.solver_settings = {name: {} for name in self.tolerances}
    def __init__(self):
        self.known_solver_issues, self.known_solver_timeouts = set(), {}
        self.define_tolerances()
        self.define_solver_settings()
'''

CHILD = '''
import json, os, sys
from importlib import import_module
sys.modules["plateqp"] = None  # import plateqp fails from here on
sys.path = [p for p in sys.path if p and os.path.abspath(p) != ROOT]
sys.path.insert(0, STUB_DIR) if STUB_DIR else None
sys.path.append(SET_DIR)  # as qpbenchmark's load_test_set does
module = import_module(NAME)
ts = getattr(module, CLS)()
import qpbenchmark
assert isinstance(ts, qpbenchmark.TestSet)
out = {"description": ts.description, "title": ts.title, "sparse_only": ts.sparse_only,
       "runtime": {k: getattr(v, "runtime", v) for k, v in ts.tolerances.items()},
       "settings": sorted(ts.solver_settings),
       "issues": sorted(ts.known_solver_issues),
       "problems": [(p.name, FINGERPRINT(p.P, p.q, p.G, p.h, p.A, p.b, p.lb, p.ub)) for p in ts],
       "plateqp_loaded": any(m == "plateqp" or m.startswith("plateqp.") for m, v in sys.modules.items() if v)}
print(json.dumps(out))
'''


def test_module_is_a_testset_that_loads_without_plateqp(graded_set, tmp_path):
    """Imported as qpbenchmark imports it, in a fresh interpreter where plateqp cannot be imported
    (qpbenchmark itself, or a stand-in with its TestSet interface if it is not installed): every
    problem comes back exactly as exported, in the documented order."""
    module, exported = graded_set
    try:
        import qpbenchmark  # noqa: F401

        stub_dir = ""
    except ImportError:
        (tmp_path / "qpbenchmark.py").write_text(STUB)
        stub_dir = str(tmp_path)
    code = "\n".join([
        "import hashlib, numpy as np, scipy.sparse as sp",
        textwrap.dedent(__import__("inspect").getsource(fingerprint)),
        f"ROOT, STUB_DIR, SET_DIR = {str(ROOT)!r}, {stub_dir!r}, {str(module.parent)!r}",
        f"NAME, CLS, FINGERPRINT = {NAME!r}, {qpbenchmark_class_name(NAME)!r}, fingerprint",
        CHILD])
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path,
                         env={"PATH": "/usr/bin:/bin", "OPENBLAS_NUM_THREADS": "1"})
    assert run.returncode == 0, run.stderr[-2000:]
    got = json.loads(run.stdout.strip().splitlines()[-1])
    assert not got["plateqp_loaded"]
    assert [n for n, _ in got["problems"]] == list(exported)
    for name, fp in got["problems"]:
        qp = exported[name].qp
        assert fp == fingerprint(qp.P, qp.q, qp.G, qp.h, qp.A, qp.b, qp.lb, qp.ub), name
    assert got["sparse_only"] is False  # dense and sparse problems: every solver runs
    assert "primal" in got["description"] and "dual" in got["description"] and got["title"]
    # qpbenchmark's tolerances (and time limit) for the two settings kept, of its four
    assert set(QPBENCHMARK_TOLERANCES) > {"default", "high_accuracy"}
    assert set(got["runtime"]) == {"default", "high_accuracy"} and set(got["runtime"].values()) == {10.0}
    assert got["settings"] == ["default", "high_accuracy"]
    # densify_max_n=200: the dense-only solvers are not given the primal problems with n > 200
    big = {n for n, e in exported.items() if e.formulation == "primal" and e.qp.n > 200}
    assert big and {p for p, _ in got["issues"]} == big and {s for _, s in got["issues"]} >= {"daqp", "quadprog"}


def test_dense_problems_are_qpsolvers_files_and_sparse_ones_stay_sparse(graded_set):
    qpsolvers = pytest.importorskip("qpsolvers")
    module, exported = graded_set
    for name, e in exported.items():
        path = module.parent / "data" / f"{name}.npz"
        if e.formulation == "primal":
            assert "P_data" in np.load(path).files  # never densified
            continue
        p = qpsolvers.Problem.load(str(path))
        assert np.array_equal(p.P, e.qp.P) and np.array_equal(p.q, e.qp.q) and np.array_equal(p.lb, e.qp.lb)
        assert p.G is None and p.A is None and p.ub is None


# -- the references: KKT of the stored problem, checked with numpy --------------------------------


def kkt_residuals(d: dict, ref: dict) -> dict:
    """Relative KKT residuals of (x, z, z_box) for min ½xᵀPx + qᵀx, Gx ≤ h, lb ≤ x (no A, no ub)."""
    P, q, G, h, lb = d["P"], d["q"], d["G"], d["h"], d["lb"]
    x = ref["x"]
    z = ref["z"] if G is not None else np.zeros(0)
    zb = ref["z_box"] if lb is not None else np.zeros_like(x)
    Px = P @ x
    Gz = G.T @ z if G is not None else np.zeros_like(x)
    size = max(np.abs(Px).max(), np.abs(q).max(), np.abs(Gz).max(), np.abs(zb).max())
    slack = h - G @ x if G is not None else np.zeros(0)
    above = x - lb if lb is not None else np.zeros(0)
    # the data are nondimensional (deflections by W, forces by F0): 1 is their natural unit
    slack_scale = max(np.abs(h).max(initial=0.0) if h is not None else 0.0, np.abs(x).max(), 1.0)
    dual_scale = max(np.abs(z).max(initial=0.0), np.abs(zb).max(initial=0.0), 1.0)
    return {
        "stationarity": np.abs(Px + q + Gz + zb).max() / size,
        "primal": max(np.max(-slack, initial=0.0), np.max(-above, initial=0.0)) / slack_scale,
        "dual": max(np.max(-z, initial=0.0), np.max(zb, initial=0.0)) / dual_scale,
        "complementarity": max(np.max(np.abs(z * slack), initial=0.0),
                               np.max(np.abs(zb * above), initial=0.0) if lb is not None else 0.0)
                           / (dual_scale * slack_scale),
        "objective": abs(0.5 * x @ Px + q @ x - ref["objective"]) / max(1.0, abs(ref["objective"])),
    }


def test_every_reference_satisfies_kkt_of_its_stored_problem(graded_set):
    module, exported = graded_set
    seen = 0
    for name, d, ref in problems_of(module):
        assert d["A"] is None and d["ub"] is None
        r = kkt_residuals(d, ref)
        assert max(r.values()) <= KKT_TOL, (name, r)
        if exported[name].formulation != "primal":
            assert ref["z"] is None and np.array_equal(d["lb"], np.zeros_like(ref["x"]))
        seen += 1
    assert seen == len(exported)


def test_three_forms_of_an_instance_give_the_same_reactions(graded_set):
    """Reactions from each form's stored problem and reference, each its own way: primal, the
    multipliers z of the gap rows; condensed, R = P z + q; dual, x itself."""
    module, exported = graded_set
    by_instance = {}
    for name, d, ref in problems_of(module):
        g = parse_grade(name)
        if g["form"] == "primal":
            R = ref["z"]
        elif g["form"] == "condensed":
            R = d["P"] @ ref["x"] + d["q"]
        else:
            R = ref["x"]
        by_instance.setdefault((g["mesh"], g["kind"], g["gaps"]), {})[g["form"]] = R
    assert len(by_instance) == 15 + 3
    for key, forms in by_instance.items():
        assert set(forms) == set(FORMS)
        R = forms["dual"]
        assert (R > 0).any()
        for form in ("primal", "condensed"):
            assert np.abs(forms[form] - R).max() <= 1e-9 * np.abs(R).max(), (key, form)


def test_liftoff_instances_are_degenerate_and_the_others_not_all_in_contact(graded_set):
    """liftoff: some points touch with zero reaction (gap = R = 0); read from the condensed form,
    where x is the gaps and P x + q the reactions."""
    module, _ = graded_set
    for name, d, ref in problems_of(module):
        g = parse_grade(name)
        if g["form"] != "condensed":
            continue
        gap, R = ref["x"], d["P"] @ ref["x"] + d["q"]
        both_zero = (np.abs(gap) <= 1e-10 * np.abs(gap).max(initial=1.0)) & (np.abs(R) <= 1e-10 * np.abs(R).max())
        if g["gaps"] == "liftoff":
            assert both_zero.sum() >= 5, name
        elif g["gaps"] == "mixed":
            assert not both_zero.any() and (gap > 0).sum() >= 5, name  # strictly complementary, many lift off


# -- the grid and its names ---------------------------------------------------------------------------


def test_grade_names_are_as_documented(graded_set):
    module, exported = graded_set
    pattern = re.compile(r"^n\d{2}_(rigid|elastic|bed)_(zero|heave|settle|mixed|liftoff)_(primal|condensed|dual)$")
    assert all(pattern.match(n) for n in exported)
    assert list(exported)[:3] == ["n08_rigid_zero_primal", "n08_rigid_zero_condensed", "n08_rigid_zero_dual"]
    for name, _, ref in problems_of(module):
        assert parse_grade(name) == ref["meta"]["grade"]
        assert grade_name(**ref["meta"]["grade"]) == name
    # the full grid: 4 meshes x 3 kinds x 5 patterns, no bed above 32², three forms each
    assert MESHES == (8, 16, 32, 64) and SUPPORT_KINDS == ("rigid", "elastic", "bed")
    assert GAP_PATTERNS == ("zero", "heave", "settle", "mixed", "liftoff") and FORMS == ("primal", "condensed", "dual")
    full = grades()
    assert len(full) == 4 * 3 * 5 - 5 and BED_MAX_MESH == 32 and (64, "bed", "zero") not in full
    readme = (ROOT / "benchmarks" / "qpbenchmark" / "README.md").read_text()
    for word in (*SUPPORT_KINDS, *GAP_PATTERNS, *FORMS, "n08_rigid_heave_primal", "64²"):
        assert word in readme, word
    with pytest.raises(Exception, match="not a graded instance name"):
        parse_grade("n8_rigid_heave")


def test_gap_patterns_as_documented():
    """heave −δ at (0, 0), settle +δ at (a, a), zero 0, mixed within ±δ with both signs (δ = 1 mm)."""
    from plateqp.scenes.families import GAP, A

    assert gap_field("heave", 0.0, 0.0) == pytest.approx(-GAP) and gap_field("heave", A, A) == 0.0
    assert gap_field("settle", A, A) == pytest.approx(GAP) and gap_field("settle", 0.0, 0.0) == 0.0
    t = np.linspace(0, A, 65)
    m = gap_field("mixed", t[:, None], t[None, :])
    assert np.abs(m).max() <= GAP * (1 + 1e-12) and m.min() < -0.5 * GAP and m.max() > 0.5 * GAP
    assert not gap_field("zero", t, t).any()


# -- writing -------------------------------------------------------------------------------------------


def test_write_qpbenchmark_refuses_non_empty_directory_and_missing_references(graded_set, tmp_path):
    _, exported = graded_set
    dual = exported["n08_rigid_heave_dual"]
    out = tmp_path / "set"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    with pytest.raises(ExportError, match="not an empty directory"):
        write_qpbenchmark([dual], out)
    write_qpbenchmark([dual], out, force=True)
    assert (out / "keep.txt").read_text() == "mine" and not (out / "solutions").exists()
    with pytest.raises(ExportError, match="no reference solution"):
        write_qpbenchmark([dual], tmp_path / "other", references={})
    assert not (tmp_path / "other").exists()
    with pytest.raises(ExportError, match="identifier"):
        write_qpbenchmark([dual], tmp_path / "other", name="not-a-module")
    with pytest.raises(ExportError, match="choose among"):
        write_qpbenchmark([dual], tmp_path / "other", settings=("fast",))
    assert not (tmp_path / "other").exists()


@pytest.mark.filterwarnings("ignore:Converted")  # qpsolvers: the dense forms handed to a sparse solver
def test_an_outside_solver_reads_the_files_and_finds_the_reference(graded_set):
    """Clarabel (through qpsolvers) on the stored problems of one non-degenerate instance, read
    back independently: its reactions are the reference's, in every form."""
    qpsolvers = pytest.importorskip("qpsolvers")
    if "clarabel" not in qpsolvers.available_solvers:
        pytest.skip("clarabel is not installed for qpsolvers")
    module, _ = graded_set
    for form in FORMS:
        name = grade_name(8, "elastic", "mixed", form)
        d = read_problem(module.parent / "data" / f"{name}.npz")
        ref = read_reference(module.parent / "solutions" / f"{name}.npz")
        sol = qpsolvers.solve_problem(qpsolvers.Problem(**d), solver="clarabel", tol_gap_abs=1e-12,
                                      tol_gap_rel=1e-12, tol_feas=1e-12)
        assert sol.found, name
        R = sol.z if form == "primal" else (d["P"] @ sol.x + d["q"] if form == "condensed" else sol.x)
        assert np.abs(R - ref["reactions"]).max() <= 1e-6 * np.abs(ref["reactions"]).max(), name
