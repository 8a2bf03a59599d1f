"""Every file plateqp writes stays inside the folder named: links are never followed.

References are file-system facts: after each command, ``os.lstat`` says what stands at each
name (a regular file, or the link left as it was), and the link's target outside the folder is
read back (still absent, or byte for byte what it was).
"""

from __future__ import annotations

import importlib.util
import json
import os
import stat

import numpy as np
import pytest

from io_reference import run_cli

SMALL = """name = "small"
[plate]
a = 1.0
b = 1.0
h = 0.02
E = 1.0e7
nu = 0.3
[mesh]
nx = 4
ny = 4
[edges]
all = "simple"
[[loads]]
type = "uniform"
q = 1.0
[[supports]]
x = 0.5
y = 0.5
gap = 0.0
"""

HAVE_MESHIO = importlib.util.find_spec("meshio") is not None
HAVE_XARRAY = importlib.util.find_spec("xarray") is not None




def one_line(code, err, expect=2):
    assert code == expect, err
    assert err.count("\n") == 1 and err.startswith("plateqp: "), err


@pytest.fixture
def scene(tmp_path):
    p = tmp_path / "small.toml"
    p.write_text(SMALL)
    return p


def is_file(p) -> bool:
    return stat.S_ISREG(os.lstat(p).st_mode)


def is_link(p) -> bool:
    return os.path.islink(p)


# -- solve --out ------------------------------------------------------------------------------

def test_solve_out_never_writes_through_a_dangling_link(capsys, tmp_path, scene):
    out, away = tmp_path / "out", tmp_path / "away"
    out.mkdir()
    away.mkdir()
    os.symlink(away / "escaped.json", out / "small.json")
    code, _, err = run_cli(capsys, "solve", scene, "--out", out)
    one_line(code, err)
    assert "small.json" in err and "--force" in err
    assert not (away / "escaped.json").exists() and is_link(out / "small.json")
    code, _, err = run_cli(capsys, "solve", scene, "--out", out, "--force")
    assert code == 0, err
    assert not os.path.lexists(away / "escaped.json"), "the link's target was created"
    assert is_file(out / "small.json") and json.loads((out / "small.json").read_text())["scene"] == "small"


@pytest.mark.parametrize("name", ["small.json", "small-w.npy"] + (["small.vtu", "small-supports.vtu"]
                                                                  if HAVE_MESHIO else []))
def test_solve_out_force_replaces_a_link_not_its_target(capsys, tmp_path, scene, name):
    out, victim = tmp_path / "out", tmp_path / "victim.txt"
    out.mkdir()
    victim.write_text("mine")
    os.symlink(victim, out / name)
    code, _, err = run_cli(capsys, "solve", scene, "--out", out)
    one_line(code, err)
    assert victim.read_text() == "mine"
    code, _, err = run_cli(capsys, "solve", scene, "--out", out, "--force")
    assert code == 0, err
    assert victim.read_text() == "mine" and is_file(out / name)
    if name.endswith(".npy"):
        assert np.load(out / name).ndim >= 1


@pytest.mark.parametrize("dangling", [False, True])
@pytest.mark.parametrize("force", [False, True])
def test_solve_out_that_is_a_link_is_refused(capsys, tmp_path, scene, dangling, force):
    away = tmp_path / "away"
    if not dangling:
        away.mkdir()
    os.symlink(away, tmp_path / "out")
    code, _, err = run_cli(capsys, "solve", scene, "--out", tmp_path / "out", *(["--force"] if force else []))
    one_line(code, err)
    assert "link" in err
    assert (not away.exists()) if dangling else list(away.iterdir()) == []


def test_solve_out_no_temporary_file_is_left(capsys, tmp_path, scene):
    out = tmp_path / "out"
    assert run_cli(capsys, "solve", scene, "--out", out)[0] == 0
    assert run_cli(capsys, "solve", scene, "--out", out, "--force")[0] == 0
    assert all(is_file(p) and not p.name.startswith(".") for p in out.iterdir())


# -- demo --out --------------------------------------------------------------------------------

def test_demo_out_never_writes_report_through_a_link(capsys, tmp_path):
    out, victim = tmp_path / "out", tmp_path / "victim.html"
    out.mkdir()
    os.symlink(tmp_path / "escaped.html", out / "report.html")
    code, _, err = run_cli(capsys, "demo", "slab", "--out", out)
    one_line(code, err)
    assert "report.html" in err and not (tmp_path / "escaped.html").exists()
    victim.write_text("mine")
    os.symlink(victim, out / "slab.json")
    code, _, err = run_cli(capsys, "demo", "slab", "--out", out, "--force")
    assert code == 0, err
    assert not os.path.lexists(tmp_path / "escaped.html") and victim.read_text() == "mine"
    assert is_file(out / "report.html") and is_file(out / "slab.json")


def test_demo_out_that_is_a_link_is_refused(capsys, tmp_path):
    away = tmp_path / "away"
    away.mkdir()
    os.symlink(away, tmp_path / "out")
    code, _, err = run_cli(capsys, "demo", "slab", "--out", tmp_path / "out", "--force")
    one_line(code, err)
    assert list(away.iterdir()) == []


# -- single files: export, regulate, sweep --out and --store ---------------------------------

def _single_file_commands(scene, path):
    cmds = [("export", scene, "--formulation", "dual", "--out", path),
            ("regulate", scene, "--target", "1.0", "--out", path)]
    if HAVE_XARRAY:
        cmds.append(("sweep", scene, "--param", "supports.1.gap", "--values", "0,0.001", "--workers", "1",
                     "--out", path))
    return cmds


@pytest.mark.parametrize("k", range(3 if HAVE_XARRAY else 2))
def test_single_file_outputs_replace_the_link_never_its_target(capsys, tmp_path, scene, k):
    victim = tmp_path / "victim.txt"
    victim.write_text("mine")
    suffix = [".qps", ".toml", ".nc"][k]
    link = tmp_path / f"result{suffix}"
    os.symlink(victim, link)
    argv = _single_file_commands(scene, link)[k]
    code, _, err = run_cli(capsys, *argv)
    one_line(code, err)
    code, _, err = run_cli(capsys, *argv, "--force")
    assert code == 0, err
    assert victim.read_text() == "mine" and is_file(link)


@pytest.mark.parametrize("k", range(3 if HAVE_XARRAY else 2))
def test_single_file_outputs_never_create_a_dangling_links_target(capsys, tmp_path, scene, k):
    suffix = [".qps", ".toml", ".nc"][k]
    link = tmp_path / f"result{suffix}"
    os.symlink(tmp_path / f"escaped{suffix}", link)
    argv = _single_file_commands(scene, link)[k]
    assert run_cli(capsys, *argv, "--force")[0] == 0
    assert not os.path.lexists(tmp_path / f"escaped{suffix}") and is_file(link)


@pytest.mark.parametrize("dangling", [False, True])
def test_sweep_store_that_is_a_link_is_refused(capsys, tmp_path, scene, dangling):
    target = tmp_path / "rows-elsewhere.jsonl"
    if not dangling:
        target.write_text("")
    os.symlink(target, tmp_path / "rows.jsonl")
    code, _, err = run_cli(capsys, "sweep", scene, "--param", "supports.1.gap", "--values", "0,0.001",
                           "--store", tmp_path / "rows.jsonl")
    one_line(code, err)
    assert "link" in err
    assert (not target.exists()) if dangling else target.read_text() == ""


def test_sweep_store_that_is_a_fifo_is_refused_at_once(capsys, tmp_path, scene):
    os.mkfifo(tmp_path / "rows.jsonl")
    code, _, err = run_cli(capsys, "sweep", scene, "--param", "supports.1.gap", "--values", "0,0.001",
                           "--store", tmp_path / "rows.jsonl")
    one_line(code, err)
    assert "not a regular file" in err


# -- Python: Result.write_vtu --------------------------------------------------------------------

@pytest.mark.skipif(not HAVE_MESHIO, reason="meshio is not installed")
def test_write_vtu_makes_its_folder_and_replaces_links_only_when_forced(tmp_path):
    import plateqp as pq
    from plateqp.errors import ExportError

    sc = pq.Scene.from_toml_string(SMALL) if hasattr(pq.Scene, "from_toml_string") else None
    if sc is None:
        p = tmp_path / "s.toml"
        p.write_text(SMALL)
        sc = pq.Scene.from_toml(p)
    res = pq.solve(sc)
    paths = res.write_vtu(tmp_path / "new" / "deeper")
    assert all(is_file(p) for p in paths)
    victim = tmp_path / "victim.txt"
    victim.write_text("mine")
    out = tmp_path / "links"
    out.mkdir()
    os.symlink(victim, out / "small.vtu")
    with pytest.raises(ExportError, match="exists"):
        res.write_vtu(out)
    res.write_vtu(out, force=True)
    assert victim.read_text() == "mine" and is_file(out / "small.vtu")
    os.symlink(out, tmp_path / "linked")
    with pytest.raises(ExportError, match="link"):
        res.write_vtu(tmp_path / "linked", force=True)


def test_python_writers_replace_a_link_and_leave_its_target(tmp_path):
    """Scene.to_toml(path) and plotting.style.save write through no link: a link at the path
    (dangling, or to a file outside) is replaced by the file, its target left as it was."""
    import matplotlib

    import plateqp as pq

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from plateqp.plotting.style import save

    outside = tmp_path / "outside"
    outside.mkdir()
    kept = outside / "kept.txt"
    kept.write_text("mine")
    work = tmp_path / "work"
    work.mkdir()
    for name, write in (("scene.toml", lambda p: pq.Scene(mesh=pq.MeshSpec(4, 4)).to_toml(p)),
                        ("figure.png", lambda p: save(Figure(), p))):
        dangling, to_file = work / f"dangling-{name}", work / f"to-file-{name}"
        dangling.symlink_to(outside / f"new-{name}")
        to_file.symlink_to(kept)
        for link in (dangling, to_file):
            write(link)
            assert not link.is_symlink() and link.stat().st_size > 0
        assert not (outside / f"new-{name}").exists() and kept.read_text() == "mine"
