"""The exported contact problem (plateqp.io.export) and the ``plateqp export`` command.

The exported QP must be the very one a QP backend is handed; the command writes it where asked
(the file-safety cases are in tests/io/test_files.py). The external references (HiGHS on the QPS
files, Clarabel on the .npz) are in tests/io/test_qps.py and tests/io/test_qpbenchmark.py.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from io_reference import exported_problems, run_cli, small_scene

import plateqp as pq
from plateqp import scenes
from plateqp.io import contact_qp, read_qps


@pytest.fixture(scope="module")
def exported():
    """{form: (ExportedQP, plateqp reference Result)} for the small scene."""
    return exported_problems()


def test_contact_qp_is_the_backends_problem(exported):
    """The exported QP is the one a QP backend is handed (same data, same formulation)."""
    from plateqp.model.assembly import build_model
    from plateqp.contact import Scaled, formulate

    e, _ = exported["primal"]
    qp = formulate(Scaled.from_model(build_model(small_scene())), "primal").problem(frozenset({"qp"}))
    assert (sp.csc_matrix(qp.P) != sp.csc_matrix(e.qp.P)).nnz == 0 and np.array_equal(qp.q, e.qp.q)
    assert e.meta["n_contacts"] == 5 and e.meta["n_elastic"] == 2 and len(e.row_names) == 5
    assert e.var_names[-2:] == ["t_1", "t_3"]  # the elastic supports' spring variables
    with pytest.raises(pq.ProblemError, match="formulation"):
        contact_qp(small_scene(), "auto")


# -- command line ------------------------------------------------------------------------------


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
