"""The built-in shaped scene "tank" (a round raft on posts with heave, DKT on a gmsh mesh), from
the command line and in the demo; the demo's grid-only parts are skipped with a stated reason.

References: statics of a floating plate (the posts carry the whole load, q times the meshed
area, and its moment: Σ R_i (x_i, y_i) = q ∫ (x, y) dA, 0 for the centred disc) and the
mirror symmetry of the scene about the x axis (posts and heave symmetric: mirrored posts carry
equal reactions).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import plateqp as pq
from plateqp import demo, scenes

pytest.importorskip("gmsh")


@pytest.fixture(scope="module")
def tank():
    return pq.solve(scenes.load("tank"), accuracy="high")


def test_tank_statics_and_symmetry(tank):
    sc = tank.scene
    assert sc.triangles and not sc.edges and not sc.pins  # floating on its posts
    assert tank.ok and tank.kkt.ok
    mesh = tank.model.grid
    q = sc.loads[0].q
    area = mesh.areas()
    centroid = (mesh.nodes[mesh.triangles].mean(axis=1) * area[:, None]).sum(axis=0)
    F = q * area.sum()
    xy = np.array([[s.x, s.y] for s in sc.supports])
    assert tank.reactions.sum() == pytest.approx(F, rel=1e-8)
    np.testing.assert_allclose(tank.reactions @ xy, q * centroid, atol=1e-8 * F * 500)
    mirror = [int(np.argmin(np.hypot(xy[:, 0] - x, xy[:, 1] + y))) for x, y in xy]
    np.testing.assert_allclose(tank.reactions, tank.reactions[mirror], rtol=2e-3, atol=1e-6 * F)
    assert 0 < tank.active.sum() < tank.active.size  # a real contact problem


def test_tank_story_matches_the_solution(tank):
    """The TOML comment names the lifted posts; keep it true."""
    assert list(np.flatnonzero(~tank.active) + 1) == [2, 3, 7, 10, 18]
    story, units = demo.scene_notes("tank")
    assert units == ("cm", "kgf") and "2, 3, 7, 10 and 18" in story and "14 of 19" in story


@pytest.mark.parametrize("form", ["primal", "condensed"])
def test_tank_from_the_command_line(capsys, form):
    from plateqp.cli import main

    code = main(["solve", "tank", "--formulation", form, "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["status"] == "optimal" and out["kkt"]["ok"]
    assert sum(out["active"]) == 14


def test_demo_on_the_tank_skips_the_grid_parts_with_reasons(tmp_path, capsys):
    code = demo.run(["tank"], tmp_path)
    out, err = capsys.readouterr()
    assert code == 0
    assert "tank" in out and "14/19" in out
    assert "tank: comparison skipped:" in out and "tank: convergence skipped:" in out
    assert "two-sided comparison" not in out
    assert "convergence study skipped" not in err  # not even tried: no study on a mesh it cannot halve
    pngs = {p.name for p in tmp_path.glob("*.png")}
    assert pngs == {f"tank-{k}.png" for k in ("mesh", "surface", "contours", "sections", "difference", "sigma1",
                                                "reactions")}
    assert {p.name for p in tmp_path.iterdir()} <= set(demo.output_files(["tank"]))
    rep = json.loads((tmp_path / "tank.json").read_text())
    assert "two_sided" in rep and "comparison" not in rep
    assert set(rep["skipped"]) == {"comparison", "convergence"} and "triangle mesh" in rep["skipped"]["comparison"]
    html = (tmp_path / "report.html").read_text()
    assert html.count("class='skipped'") == 2 and "triangles" in html
    assert html.count("data:image/png;base64,") == len(pngs)
