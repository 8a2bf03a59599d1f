"""Support numbers a user reads or types are the tables' numbers, from 1; argparse errors are one line.

References: the scene's own list (``scene.supports[k]`` is support number k + 1 in every table),
and each sweep row's contact flags (a breakpoint's contact sets are the rows' flags, numbered).
"""

from __future__ import annotations

import json

import pytest

import plateqp as pq
from plateqp import scenes
from plateqp.errors import SceneError
from plateqp.model.paths import get_param, set_param
from io_reference import run_cli


def three_supports():
    return pq.Scene(name="three", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(4, 4),
                    edges={"left": "simple", "right": "simple"},
                    loads=[pq.UniformLoad(q=1.0)],
                    supports=[pq.Support(0.25, 0.5, gap=0.001), pq.Support(0.5, 0.5, gap=0.002),
                              pq.Support(0.75, 0.5, gap=0.003)])




def one_line(code, err, expect=2):
    assert code == expect, err
    assert err.count("\n") == 1 and err.startswith("plateqp: "), err


# -- paths ---------------------------------------------------------------------------------------

def test_a_path_names_the_support_by_its_table_number():
    sc = three_supports()
    assert get_param(sc, "supports.1.gap") == 0.001 and get_param(sc, "supports.3.gap") == 0.003
    new = set_param(sc, "supports.2.gap", -0.5)
    assert [s.gap for s in new.supports] == [0.001, -0.5, 0.003]
    assert get_param(sc, "supports.*.gap") == [0.001, 0.002, 0.003]


@pytest.mark.parametrize("path, words", [("supports.0.gap", "numbered from 1"), ("supports.4.gap", "1..3"),
                                         ("supports.-1.gap", "numbered from 1")])
def test_a_support_number_out_of_the_table_is_a_clear_error(path, words):
    with pytest.raises(SceneError, match=words.replace(".", r"\.")) as info:
        get_param(three_supports(), path)
    assert "\n" not in str(info.value)


def test_a_path_naming_the_list_suggests_numbers_from_1():
    with pytest.raises(SceneError, match=r"supports\.1\.gap"):
        set_param(three_supports(), "supports", 0.0)


def test_cli_sweep_of_supports_1_changes_the_tables_support_1(capsys, tmp_path):
    f = tmp_path / "three.toml"
    three_supports().to_toml(f)
    code, out, err = run_cli(capsys, "sweep", f, "--param", "supports.1.gap", "--values", "0.5,0.6", "--json",
                             "--no-refine", "--workers", "1")
    assert code == 0, err
    for row, v in zip(json.loads(out)["rows"], (0.5, 0.6)):
        assert row["gaps"][0] > 0.4 and row["gaps"][1] < 0.1 and row["gaps"][2] < 0.1  # support 1 settled by v
    code, _, err = run_cli(capsys, "sweep", f, "--param", "supports.0.gap", "--values", "0.5", "--workers", "1")
    one_line(code, err)
    assert "numbered from 1" in err


def test_a_scene_error_names_supports_by_their_table_numbers(tmp_path):
    sc = three_supports()
    sc.supports.append(pq.Support(0.5, 0.5, gap=0.0))  # support 4 on support 2's point
    with pytest.raises(SceneError, match=r"supports\.4: lies on the same point as supports\.2"):
        sc.validate()


# -- JSON ----------------------------------------------------------------------------------------

def _heave_file(tmp_path):
    sc = pq.Scene.from_toml(scenes.path("heave"))
    sc.mesh.nx = sc.mesh.ny = 8
    f = tmp_path / "heave8.toml"
    sc.to_toml(f)
    return f


@pytest.mark.parametrize("exact", [False, True])
def test_sweep_json_breakpoints_number_supports_from_1(capsys, tmp_path, exact):
    argv = ["sweep", _heave_file(tmp_path), "--param", "supports.2.gap", "--values", "-0.3,-0.2,-0.1,0.0,0.1",
            "--json", "--workers", "1"] + (["--exact"] if exact else ["--no-refine"])
    code, out, err = run_cli(capsys, *argv)
    assert code == 0, err
    d = json.loads(out)
    rows, bps = d["rows"], d["breakpoints"]
    assert bps, "the heave sweep changes its contact set"
    numbered = [[j + 1 for j, a in enumerate(r["active"]) if a] for r in rows]
    m = len(rows[0]["active"])
    for b in bps:
        assert all(1 <= k <= m for k in b["before"] + b["after"])
    if not exact:
        for b in bps:
            k = [r["value"] for r in rows].index(b["between"][0])
            assert b["before"] == numbered[k] and b["after"] == numbered[k + 1]
    else:
        assert bps[0]["before"] == numbered[0] and bps[-1]["after"] == numbered[-1]
        for p in d["pieces"]:
            assert all(1 <= k <= m for k in p["contact"])
        assert d["pieces"][0]["contact"] == numbered[0]


def test_sensitivity_json_names_supports_by_their_table_numbers(capsys, tmp_path):
    f = tmp_path / "three.toml"
    three_supports().to_toml(f)
    code, out, err = run_cli(capsys, "solve", f, "--json", "--sensitivity")
    assert code == 0, err
    assert json.loads(out)["sensitivity"]["parameters"] == ["supports.1.gap", "supports.2.gap", "supports.3.gap"]


# -- argparse --------------------------------------------------------------------------------------

@pytest.mark.parametrize("argv", [["solve", "x.toml", "--bogus"], ["sweep", "heave"], ["frobnicate"],
                                  ["solve", "heave", "--formulation", "nope"], [],
                                  ["sweep", "heave", "--param", "plate.h", "--values", "1", "--workers", "two"]])
def test_a_bad_flag_is_one_line_and_exit_2(capsys, argv):
    code, out, err = run_cli(capsys, *argv)
    one_line(code, err)
    assert "usage:" not in err and out == ""


def test_help_still_prints_the_usage(capsys):
    code, out, _ = run_cli(capsys, "sweep", "--help")
    assert code == 0 and "usage:" in out and "--param" in out
