"""``plateqp demo soils``: one heaved slab on Winkler's springs, Pasternak's bed and the elastic
half-space, side by side, with the numbers it prints checked against the results' own fields.

The physics the three pressure maps must show, from the literature:

* Winkler's springs (Winkler 1867): the pressure at a point is k times the soil's settlement
  there, and the soil's surface moves only where it is pressed (Selvadurai, *Elastic analysis
  of soil-foundation interaction*, Elsevier 1979, the chapter on soil models: the Winkler
  model's surface deflection is confined to the loaded region, discontinuous at its edge;
  Kerr, "Elastic and viscoelastic foundation models", J. Appl. Mech. 31, 1964).
* Pasternak's shear layer and the elastic half-space couple the surface: it is continuous and
  settles beyond the loaded region (Selvadurai 1979 and Kerr 1964, the two-parameter and the
  continuum models).
* The elastic half-space under a stiff foundation concentrates the contact pressure at the
  foundation's edges and, strongest, at its corners (Boussinesq's rigid punch, p ∝ 1/√(a² − r²),
  unbounded at the edge: Johnson, *Contact Mechanics*, 1985, § 3.2; for rectangular slabs the
  tables of Gorbunov-Posadov & Malikova, *Design of structures on elastic foundation*, 1973, and
  Selvadurai 1979, rigid rectangular foundations): a corner carries more pressure than the middle
  of its edge although it settles less, and an edge more than the interior. On Winkler's springs
  the same places carry pressure in proportion to their settlement.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
from pathlib import Path

import numpy as np
import pytest

import plateqp as pq
from plateqp import demo
from plateqp.demo import soils

NAMES = ("Winkler", "Pasternak", "half-space")
NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """``plateqp demo soils --out DIR`` from another working folder; the study it computed is
    recorded (the same objects the printed table was made from)."""
    from plateqp.cli import main

    out = tmp_path_factory.mktemp("out")
    cwd = tmp_path_factory.mktemp("cwd")
    seen = []
    real = soils.soil_study

    def record(*args, **kwargs):
        st = real(*args, **kwargs)
        seen.append(st)
        return st

    here = os.getcwd()
    buf = io.StringIO()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(soils, "soil_study", record)
        os.chdir(cwd)
        try:
            with contextlib.redirect_stdout(buf):
                code = main(["demo", "soils", "--out", str(out)])
        finally:
            os.chdir(here)
    assert len(seen) == 1
    return {"code": code, "out": out, "cwd": cwd, "stdout": buf.getvalue(), "study": seen[0]}


def pressure(r) -> np.ndarray:
    return r.reactions / r.model.bed_areas()[r.model.contacts.index]


def applied_load(scene: pq.Scene) -> float:
    a, b = scene.plate.a, scene.plate.b
    return sum(ld.q * a * b if ld.type == "uniform" else ld.P for ld in scene.loads)


def node(r, x: float, y: float) -> int:
    xy = r.model.contacts.xy
    return int(np.flatnonzero(np.hypot(xy[:, 0] - x, xy[:, 1] - y) < 1e-9)[0])


# -- the run -------------------------------------------------------------------------------------
def test_soils_is_a_study_of_the_default_demo():
    assert "soils" in demo.names_all()
    files = demo.output_files(None)  # plateqp demo with no name runs everything
    assert {"soils.json", "soils-pressure.png", "soils-sections.png"} <= set(files)


def test_the_study_runs_and_writes_only_under_out(run):
    assert run["code"] == 0, run["stdout"]
    written = {p.name for p in run["out"].iterdir()}
    assert written <= set(demo.output_files(["soils"]))
    assert {"soils.json", "soils-pressure.png", "soils-sections.png", "report.html"} <= written
    assert all((run["out"] / f).read_bytes()[:4] == b"\x89PNG" for f in written if f.endswith(".png"))
    assert list(run["cwd"].iterdir()) == []  # nothing in the working folder


def test_every_solve_is_optimal_and_kkt_checked(run):
    st = run["study"]
    assert list(st.results) == list(NAMES)
    for name, r in st.results.items():
        assert r.status == pq.Status.OPTIMAL and r.kkt.ok, name
    assert st.ok


def test_statics_the_soil_carries_the_whole_load(run):
    """Heave changes how the load is spread, not how much there is."""
    for name, r in run["study"].results.items():
        load = applied_load(r.scene)
        assert load == pytest.approx(soils.Q * soils.A**2 + soils.P, rel=1e-12)
        assert abs(r.reactions.sum() - load) <= 1e-6 * load, name
        assert r.reactions.min() >= 0.0, name  # tensionless


def test_every_soil_lifts_off_somewhere(run):
    for name, r in run["study"].results.items():
        assert 0 < (~r.active).sum() < r.active.size, name


# -- the printed and written numbers are the results' own ------------------------------------------
def expected(r) -> dict:
    p = pressure(r)
    areas = r.model.bed_areas()[r.model.contacts.index]
    return {"w_max": r.w_max()[0], "p_max": p.max(), "lifted_share": areas[~r.active].sum() / areas.sum(),
            "lifted_nodes": int((~r.active).sum()), "bed_nodes": int(r.active.size),
            "Mx_max": r.section(*soils.SECTION, quantity="Mx")[1].max(), "kkt_worst": r.kkt.worst,
            "status": r.status.value}


def test_printed_table_equals_the_results(run):
    rows = {line.split()[0]: line for line in run["stdout"].splitlines() if line.strip().split()[:1]
            and line.split()[0] in NAMES}
    assert set(rows) == set(NAMES), run["stdout"]
    for name, r in run["study"].results.items():
        e = expected(r)
        nums = [float(v) for v in NUMBER.findall(rows[name][len(name):])]
        # w max [mm] (3 decimals), p max [kPa] (1), at x, y [m], lifted share [%] (1), of n nodes,
        # Mx max [kN·m/m] (1), KKT worst (2 digits)
        w, p, _x, _y, share, lifted, nodes, mx, kkt = nums
        assert abs(w - e["w_max"] * 1e3) <= 5e-4 + 1e-9, name
        assert abs(p - e["p_max"] / 1e3) <= 0.05 + 1e-9, name
        assert abs(share - 100 * e["lifted_share"]) <= 0.05 + 1e-9, name
        assert (lifted, nodes) == (e["lifted_nodes"], e["bed_nodes"]), name
        assert abs(mx - e["Mx_max"] / 1e3) <= 0.05 + 1e-9, name
        assert kkt == pytest.approx(e["kkt_worst"], rel=0.051), name
        assert rows[name].rstrip().endswith(e["status"]), name


def test_json_and_report_carry_the_same_numbers(run):
    data = json.loads((run["out"] / "soils.json").read_text())
    for name, r in run["study"].results.items():
        e, got = expected(r), data["soils"][name]
        for key, value in e.items():
            if isinstance(value, str):
                assert got[key] == value, (name, key)
            else:
                assert got[key] == pytest.approx(value, rel=1e-12, abs=0), (name, key)
    cal = run["study"].calibration
    assert data["calibration"]["k"] == cal.k and data["calibration"]["c2"] == cal.c2
    html = (run["out"] / "report.html").read_text()
    assert "Study “soils”" in html
    for line in soils.table(run["study"]).splitlines():
        assert line.replace("&", "&amp;") in html


# -- the physics ---------------------------------------------------------------------------------
def test_winkler_pressure_is_k_times_the_local_settlement(run):
    st = run["study"]
    r = st.results["Winkler"]
    on, v = r.active, r.compressions
    np.testing.assert_allclose(pressure(r)[on], st.calibration.k * v[on], rtol=1e-8)
    assert np.all(v[~on] == 0.0)  # a spring nobody presses does not move


@pytest.mark.parametrize("name", ["Pasternak", "half-space"])
def test_coupled_soils_settle_beyond_the_contact(run, name):
    r = run["study"].results[name]
    v = r.compressions
    assert v[~r.active].max() > 0.1 * v.max()


def test_half_space_pressure_peaks_at_the_corners_and_edges(run):
    """Along the far edge x = 4 m (away from the heave, in contact on every soil): the half-space's
    corner carries more than the edge's middle though it settles less, and the edge more than the
    interior; Winkler's springs there carry pressure in proportion to the settlement."""
    res = run["study"].results
    corner, middle, inner = (4.0, 0.0), (4.0, 2.0), (3.0, 1.0)
    for name in NAMES:
        r = res[name]
        assert all(r.active[node(r, *pt)] for pt in (corner, middle, inner)), name
    hs, wk = res["half-space"], res["Winkler"]
    p, v = pressure(hs), hs.compressions
    c, m, i = (node(hs, *pt) for pt in (corner, middle, inner))
    assert v[c] < v[m] and p[c] > p[m] > p[i]
    assert p[c] / v[c] > 3 * p[i] / v[i]  # the corner is far stiffer than the interior
    pw, vw = pressure(wk), wk.compressions
    c, m, i = (node(wk, *pt) for pt in (corner, middle, inner))
    assert vw[c] < vw[m] and pw[c] < pw[m]
    assert pw[c] / vw[c] == pytest.approx(pw[i] / vw[i], rel=1e-8)
    assert p[c] > 3 * pw[c]  # the continuum's corner, against the spring's


def test_the_lesson_uses_the_demos_scene():
    """One definition of the scene and of the fitting of k and c2: the lesson imports them."""
    src = (Path(__file__).resolve().parents[2] / "notebooks" / "13_choosing_a_soil_model.py").read_text()
    assert "from plateqp.demo import soils" in src
    assert "import brentq" not in src and "def foot_error" not in src and "pq.Plate(a=4.0" not in src


def test_existing_figure_is_not_overwritten_without_force(tmp_path, capsys, monkeypatch):
    from plateqp.cli import main

    calls = []
    monkeypatch.setattr(demo, "run_study", lambda *a, **k: calls.append(a) or (_ for _ in ()).throw(
        RuntimeError("the demo started working")))
    (tmp_path / "soils-pressure.png").write_text("mine")
    code = main(["demo", "soils", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and calls == [] and "soils-pressure.png exists" in err
    assert (tmp_path / "soils-pressure.png").read_text() == "mine"
