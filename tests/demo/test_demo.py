"""The built-in scenes and ``plateqp demo``: real contact problems, statics, the paper's statements."""

from __future__ import annotations

import dataclasses
import json
import sys

import numpy as np
import pytest

import plateqp as pq
from plateqp import demo, scenes

CONTACT_SCENES = ("heave", "settlement", "stiffness", "contour")


def total_load(sc: pq.Scene) -> float:
    p = sc.plate
    out = 0.0
    for ld in sc.loads:
        if ld.type == "point":
            out += ld.P
        elif ld.type == "uniform":
            out += ld.q * p.a * p.b
        else:
            out += ld.q * (min(ld.x1, p.a) - max(ld.x0, 0)) * (min(ld.y1, p.b) - max(ld.y0, 0))
    return out


@pytest.mark.parametrize("name", CONTACT_SCENES)
def test_builtin_scene_is_a_real_contact_problem(name):
    sc = scenes.load(name)
    assert (sc.mesh.nx, sc.mesh.ny) == (16, 16)  # the paper's mesh
    assert not sc.edges and not sc.pins  # a floating plate: the supports carry everything
    res = pq.solve(sc)  # its time is measured in benchmarks/, not asserted here
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert 0 < res.active.sum() < res.active.size  # mixed contact set
    assert res.reactions.sum() == pytest.approx(total_load(sc), rel=1e-8)  # statics of a floating plate
    story, units = demo.scene_notes(name)
    assert units == ("cm", "kgf") and len(story) > 200


def test_scene_stories_match_the_solutions():
    """The TOML comments name the contact sets; keep them true."""
    lifted = {"heave": [1, 3, 7, 8, 11, 16, 22, 23], "settlement": [6, 7, 8, 14, 16, 17, 19, 22, 24],
              "stiffness": [3, 4, 6, 7, 9, 21]}
    for name, ids in lifted.items():
        res = pq.solve(scenes.load(name), accuracy="high")
        assert list(np.flatnonzero(~res.active) + 1) == ids, name
    assert int(pq.solve(scenes.load("contour")).active.sum()) == 38


def corner_scene() -> pq.Scene:
    """A square on its four corners under a central point load: every support in contact."""
    return pq.Scene(name="corners", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1.0e7, nu=0.3),
                    mesh=pq.MeshSpec(8, 8, "acm"), loads=[pq.PointLoad(P=100.0, x=0.5, y=0.5)],
                    supports=[pq.Support(x, y) for y in (0.0, 1.0) for x in (0.0, 1.0)])


def test_compare_all_in_contact_gives_zero_differences():
    sc = corner_scene()
    one, two = pq.solve(sc, accuracy="high"), pq.solve_bilateral(sc)
    assert one.active.all()
    np.testing.assert_allclose(one.reactions, 25.0, rtol=1e-9)
    c = demo.compare(one, two)
    assert c.n_contact == c.n_supports == 4
    assert c.contact_nodes > 0 and c.liftoff_nodes == 0 and np.isnan(c.dw_liftoff)
    assert c.dw_contact <= 1e-9 * c.w_ref and c.dw_max <= 1e-9 * c.w_ref
    assert abs(c.s1_rel) <= 1e-9 and c.s1_one > 0
    assert c.tension_supports == []
    assert any("no nodes" in line for line in c.lines(("cm", "kgf")))


def test_zones_by_nearest_support():
    """Corner supports, only (0, 0) in contact: its quadrant is the contact zone, ties are neither."""
    sc = corner_scene()
    sc.mesh.nx = sc.mesh.ny = 4
    sc = pq.Scene(**{f.name: getattr(sc, f.name) for f in dataclasses.fields(sc) if f.init})
    res = pq.solve(sc)
    res = dataclasses.replace(res, active=np.array([True, False, False, False]))
    z = res.model.grid.to_grid(demo.zones(res))  # nodes at 0, 0.25, ..., 1; z[j, i] at (x_i, y_j)
    assert (z == 1).sum() == 4 and (z[:2, :2] == 1).all()
    # on x = 0.5 or y = 0.5 up to the centre: equidistant from (0, 0) and a lifted support
    assert (z[2, :3] == 0).all() and (z[:3, 2] == 0).all() and (z == 0).sum() == 5
    assert (z == -1).sum() == 16  # the rest, ties between lifted supports included


def test_compare_sees_lift_off():
    res_one = pq.solve(scenes.load("heave"), accuracy="high")
    res_two = pq.solve_bilateral(scenes.load("heave"))
    c = demo.compare(res_one, res_two)
    assert c.liftoff_nodes > 0 and c.contact_nodes > 0
    assert c.dw_liftoff > c.dw_contact > 0  # the paper: large differences where the plate lifts off
    assert 7 in c.tension_supports and c.min_R_two < 0
    assert abs(c.s1_rel) < 0.1  # and sigma1 near the load almost the same


def test_run_writes_report(tmp_path, capsys, caplog):
    caplog.set_level("INFO", logger="plateqp.demo")
    code = demo.run(["heave"], tmp_path)
    out, err = capsys.readouterr()
    assert code == 0
    assert "heave" in out and "17/25" in out and "two-sided comparison" in out and "ok" in out
    assert "heave: solving one-sided" in caplog.text  # progress: logged (INFO), a bar only on a terminal
    html = (tmp_path / "report.html").read_text()
    assert '<img src="data:image/png;base64,' in html
    pngs = sorted(p.name for p in tmp_path.glob("*.png"))
    core = {f"heave-{k}.png" for k in ("mesh", "surface", "contours", "sections", "difference", "sigma1", "reactions")}
    # plus the convergence panel, drawn when plateqp.studies.convergence is available
    assert core <= set(pngs) <= core | {"heave-convergence.png"}
    assert all((tmp_path / p).read_bytes()[:4] == b"\x89PNG" for p in pngs)
    assert html.count("data:image/png;base64,") == len(pngs)
    rep = json.loads((tmp_path / "heave.json").read_text())
    assert rep["one_sided"]["status"] == "optimal" and "two_sided" in rep
    assert rep["comparison"]["n_contact"] == 17
    # every file written is one the command line checks before any work (--out, --force)
    assert {p.name for p in tmp_path.iterdir()} <= set(demo.output_files(["heave"]))


def test_run_default_folder_and_two_sided_scene(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert demo.run(["slab"]) == 0
    folder = tmp_path / demo.DEFAULT_OUT
    assert (folder / "report.html").exists() and (folder / "slab-contours.png").exists()
    assert "slab" in capsys.readouterr().out


def test_run_unknown_scene_fails_before_work(tmp_path):
    with pytest.raises(pq.SceneError, match="no built-in scene"):
        demo.run(["nonesuch"], tmp_path / "x")
    assert not (tmp_path / "x").exists()


def test_convergence_panel_and_its_fallback(monkeypatch, caplog):
    sc = scenes.load("heave")
    one = pq.solve(sc)
    assert demo.characteristic_supports(one) == [12, 1]  # support 13 (most loaded), 2 (heaved, in contact)
    made = demo.convergence_plot(sc, one)
    if made is not None:  # plateqp.studies is there
        fig, caption = made
        assert fig.axes[0].get_yscale() == "log" and "target" in caption
    monkeypatch.setitem(sys.modules, "plateqp.studies", None)  # as if it were missing
    assert demo.convergence_plot(sc, one) is None
    assert "convergence study skipped" in caplog.text  # a logged warning


def test_run_without_matplotlib_writes_a_report_without_figures(tmp_path, monkeypatch, caplog):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "matplotlib" else real(name, *a))
    assert demo.run(["slab"], tmp_path) == 0
    assert "no figures" in caplog.text
    assert not list(tmp_path.glob("*.png")) and "<img" not in (tmp_path / "report.html").read_text()


# -- what the convergence panel may swallow, and what it must not --------------------------------


def _raise(exn):
    def boom(*args, **kwargs):
        raise exn
    return boom


@pytest.mark.parametrize("exn", [AttributeError("'Result' object has no attribute 'wmax'"),
                                 TypeError("convergence() got an unexpected keyword argument"),
                                 KeyError("reactions.3"), ValueError("unknown quantity"),
                                 ImportError("cannot import name 'ConvergenceTable'")],
                         ids=lambda e: type(e).__name__)
def test_convergence_plot_lets_bugs_through(monkeypatch, exn):
    """A programming error inside the study is not a reason to skip the panel: it surfaces."""
    import plateqp.studies

    sc = corner_scene()
    one = pq.solve(sc)
    monkeypatch.setattr(plateqp.studies, "convergence", _raise(exn))
    with pytest.raises(type(exn)):
        demo.convergence_plot(sc, one)


def test_convergence_plot_lets_a_plotting_bug_through(monkeypatch):
    from plateqp import plotting

    pytest.importorskip("matplotlib")
    sc = corner_scene()
    one = pq.solve(sc)
    monkeypatch.setattr(plotting, "plot_convergence", _raise(AttributeError("'Axes' object has no attribute 'x'")))
    with pytest.raises(AttributeError):
        demo.convergence_plot(sc, one)


def test_convergence_plot_skips_a_scene_the_study_cannot_take(monkeypatch, caplog):
    """A PlateQPError from the study (e.g. a mesh the scene cannot be built on) skips the panel with a note."""
    import plateqp.studies

    sc = corner_scene()
    one = pq.solve(sc)
    monkeypatch.setattr(plateqp.studies, "convergence", _raise(pq.SolverError("no mesh could be solved")))
    assert demo.convergence_plot(sc, one) is None
    assert "convergence study skipped (SolverError: no mesh could be solved)" in caplog.text


# -- plateqp demo --out DIR [--force]: checked before any work, nothing overwritten --------------


@pytest.fixture
def no_work(monkeypatch):
    """demo.run_scene replaced by a recorder that fails: the list stays empty if no work began."""
    calls = []

    def fake(name, *args, **kwargs):
        calls.append(name)
        raise RuntimeError("the demo started working")

    monkeypatch.setattr(demo, "run_scene", fake)
    return calls


def demo_cli(capsys, *argv):
    from plateqp.cli import main

    code = main(["demo", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def refused(code, err, calls, what):
    assert code == 2, err
    assert calls == [], "work began before --out was checked"
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("plateqp: --out") and what in lines[0], err


def test_demo_out_naming_a_file_is_refused_before_work(tmp_path, capsys, no_work):
    f = tmp_path / "taken"
    f.write_text("mine")
    code, _, err = demo_cli(capsys, "slab", "--out", str(f))
    refused(code, err, no_work, "not a folder")
    assert f.read_text() == "mine"


def test_demo_out_that_cannot_be_made_is_refused_before_work(tmp_path, capsys, no_work):
    (tmp_path / "file").write_text("")
    code, _, err = demo_cli(capsys, "slab", "--out", str(tmp_path / "file" / "sub"))
    refused(code, err, no_work, "cannot be made")


def test_demo_out_not_writable_is_refused_before_work(tmp_path, capsys, no_work, monkeypatch):
    import os

    real = os.access
    # chmod does not stop root (the tests may run as root): the check is what is tested
    monkeypatch.setattr(os, "access", lambda p, mode, *a, **k: False if str(p) == str(tmp_path / "ro")
                        else real(p, mode, *a, **k))
    (tmp_path / "ro").mkdir()
    code, _, err = demo_cli(capsys, "slab", "--out", str(tmp_path / "ro"))
    refused(code, err, no_work, "not writable")


@pytest.mark.parametrize("existing", ["report.html", "slab-mesh.png", "slab-sigma1.png", "slab.json"])
def test_demo_does_not_overwrite_without_force(tmp_path, capsys, no_work, existing):
    (tmp_path / existing).write_text("mine")
    code, _, err = demo_cli(capsys, "slab", "--out", str(tmp_path))
    refused(code, err, no_work, f"{existing} exists; use --force")
    assert (tmp_path / existing).read_text() == "mine"


def test_demo_default_folder_is_checked_too(tmp_path, capsys, no_work, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / demo.DEFAULT_OUT).mkdir()
    (tmp_path / demo.DEFAULT_OUT / "report.html").write_text("mine")
    code, _, err = demo_cli(capsys, "slab")
    refused(code, err, no_work, "report.html exists")


def test_demo_unknown_scene_is_refused_before_the_folder(tmp_path, capsys, no_work):
    code, _, err = demo_cli(capsys, "nonesuch", "--out", str(tmp_path / "x"))
    assert code == 2 and "no built-in scene" in err and no_work == []
    assert not (tmp_path / "x").exists()


def test_demo_force_overwrites(tmp_path, capsys):
    for name in ("report.html", "slab-mesh.png", "slab.json"):
        (tmp_path / name).write_text("old")
    code, out, err = demo_cli(capsys, "slab", "--out", str(tmp_path), "--force")
    assert code == 0, err
    assert "slab" in out
    assert "<!DOCTYPE html>" in (tmp_path / "report.html").read_text()
    assert json.loads((tmp_path / "slab.json").read_text())["one_sided"]["status"] == "optimal"
    if (tmp_path / "slab-contours.png").exists():  # figures drawn (matplotlib installed)
        assert (tmp_path / "slab-mesh.png").read_bytes()[:4] == b"\x89PNG"
