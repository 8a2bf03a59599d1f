"""Where an export writes (plateqp.io.files): only where it was asked, never over
something that exists without --force, and a path that cannot be written is refused in one line
(exit code 2) before the problem is built, with nothing written.

Each case here failed before the checks: a traceback (exit 1) after the work and after partial
writes, or a file written outside the path asked for.
"""

from __future__ import annotations

import dataclasses
import os

import pytest
from io_reference import exported_problems, run_cli

from plateqp.errors import ExportError, PlateQPError
from plateqp.io import write_qpbenchmark, write_qps


@pytest.fixture(scope="module")
def dual():
    """The small scene's dual problem, exported (a small dense QP)."""
    return exported_problems()["dual"][0]


def tree(root) -> dict[str, str]:
    """Every path below ``root`` (links not followed) and what it is, to see that nothing changed."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for n in dirnames + filenames:
            p = os.path.join(dirpath, n)
            out[os.path.relpath(p, root)] = ("link" if os.path.islink(p) else "dir" if os.path.isdir(p)
                                             else open(p, "rb").read().hex())
    return out


def one_line(err: str) -> bool:
    return len(err.strip().splitlines()) == 1 and "Traceback" not in err


# -- plateqp export --format qps ---------------------------------------------------------------


@pytest.mark.parametrize("scene", ["heave", "slab"])
def test_qps_out_below_a_file_is_refused_before_any_work(capsys, tmp_path, scene):
    """``--out FILE/x.qps``: was an internal error (exit 1) after the problem was built; for a
    scene that cannot be exported (slab: no one-sided supports), the path is checked first."""
    (tmp_path / "afile").write_text("mine")
    code, _, err = run_cli(capsys, "export", scene, "--out", tmp_path / "afile" / "x.qps")
    assert code == 2 and one_line(err) and "not a directory" in err and "afile" in err
    assert (tmp_path / "afile").read_text() == "mine"


def test_qps_out_a_dangling_link_is_not_written_through(capsys, tmp_path):
    """A link at ``--out`` pointing nowhere: writing through it wrote a file elsewhere."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    link = tmp_path / "here" / "x.qps"
    link.parent.mkdir()
    link.symlink_to(elsewhere / "target.qps")
    code, _, err = run_cli(capsys, "export", "heave", "--out", link)
    assert code == 2 and one_line(err) and "exists" in err and "--force" in err
    assert list(elsewhere.iterdir()) == []


def test_qps_out_in_an_unwritable_folder_is_refused_before_any_work(capsys, tmp_path, monkeypatch):
    """An unwritable folder was found only when writing (PermissionError, exit 1). The tests run
    as root here, where every folder is writable: os.access is made to say no."""
    real = os.access
    monkeypatch.setattr(os, "access", lambda p, mode, **kw: False if str(p) == str(tmp_path) else real(p, mode, **kw))
    code, _, err = run_cli(capsys, "export", "slab", "--out", tmp_path / "sub" / "x.qps")
    assert code == 2 and one_line(err) and "not writable" in err
    assert tree(tmp_path) == {}


def test_write_qps_failure_is_an_export_error(dual, tmp_path):
    """In Python, a file that cannot be written is an ExportError (one line), not an OSError."""
    (tmp_path / "afile").write_text("mine")
    with pytest.raises(ExportError, match="cannot write"):
        write_qps(dual, tmp_path / "afile" / "x.qps")


# -- plateqp export --format qpbenchmark / write_qpbenchmark ------------------------------------


def test_testset_out_below_a_file_is_refused_before_any_work(capsys, tmp_path):
    (tmp_path / "afile").write_text("mine")
    code, _, err = run_cli(capsys, "export", "slab", "--format", "qpbenchmark", "--out", tmp_path / "afile" / "set")
    assert code == 2 and one_line(err) and "not a directory" in err
    assert tree(tmp_path) == {"afile": b"mine".hex()}


@pytest.mark.parametrize("in_the_way, kind", [
    ("results", "file"),  # a folder goes there
    ("data", "file"),
    ("plateqp_contact.py", "dir"),  # the module goes there
    ("data/heave_primal.npz", "dir"),  # known only once the problem is named: checked before writing
])
def test_testset_force_with_something_in_the_way_writes_nothing(capsys, tmp_path, in_the_way, kind):
    """--force into a directory where a file stands in a folder's place (or the reverse) was an
    internal error (exit 1) after data/ and some .npz were already written."""
    out = tmp_path / "set"
    (out / "keep").mkdir(parents=True)
    (out / "keep" / "mine.txt").write_text("mine")
    p = out / in_the_way
    p.parent.mkdir(parents=True, exist_ok=True)
    p.mkdir() if kind == "dir" else p.write_text("in the way")
    before = tree(out)
    code, _, err = run_cli(capsys, "export", "heave", "--format", "qpbenchmark", "--out", out, "--force")
    assert code == 2 and one_line(err) and "in the way" in err
    assert tree(out) == before


@pytest.mark.parametrize("data_dir", ["../outside", "data/../../outside", "ABS"])
def test_write_qpbenchmark_data_dir_stays_inside(dual, tmp_path, data_dir):
    """``data_dir`` was joined to the directory unchecked: '..' or an absolute path wrote the
    .npz files outside it."""
    if data_dir == "ABS":
        data_dir = str(tmp_path / "outside")
    with pytest.raises(ExportError, match="inside"):
        write_qpbenchmark([dual], tmp_path / "set", data_dir=data_dir)
    assert tree(tmp_path) == {}


def test_write_qpbenchmark_problem_names_cannot_leave_the_directory(dual, tmp_path):
    """An ExportedQP's name was used unchecked as a file name (a (name, QP) pair's was made safe)."""
    evil = dataclasses.replace(dual, name="../../escaped")
    write_qpbenchmark([evil], tmp_path / "a" / "set")
    assert sorted(tree(tmp_path / "a")) == ["set", "set/data", "set/data/.._.._escaped.npz", "set/plateqp_contact.py",
                                            "set/results"]
    with pytest.raises(PlateQPError, match="unique"):  # names are compared once made safe
        write_qpbenchmark([dual, dataclasses.replace(dual, name=f"/{dual.name}")], tmp_path / "b")
    assert not (tmp_path / "b").exists()
