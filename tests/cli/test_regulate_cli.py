"""``plateqp regulate``: gaps that make chosen supports carry target reactions.

External reference (closed form, Kirchhoff plate theory): a free square plate (side a) on four
rigid corner supports under a uniform load carries q a²/4 at each corner; the only redundant
reaction pattern is the twist (+, −, +, −), whose stiffness is k = 2 D (1 − ν) / a² (the pure
twist w = c x y, represented exactly by the ACM element). Reactions q a²/4 + t (+, −, +, −)
need gaps whose twist component Σ pⱼ gⱼ = −t / k; the gaps closest to the scene's zero gaps
are gⱼ = −t pⱼ / (4 k).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from plateqp.cli import main

A, H, E, NU, Q = 1.0, 0.01, 2.1e11, 0.3, 1000.0
D = E * H**3 / (12 * (1 - NU**2))
K_TWIST = 2 * D * (1 - NU) / A**2

SCENE = """name = "corners"
[plate]
a = 1.0
b = 1.0
h = 0.01
E = 2.1e11
nu = 0.3
[mesh]
nx = 8
ny = 8
element = "acm"
[[loads]]
type = "uniform"
q = 1000.0
""" + "".join(f"[[supports]]\nx = {x}\ny = {y}\n" for x, y in ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)))


@pytest.fixture
def corners(tmp_path):
    p = tmp_path / "corners.toml"
    p.write_text(SCENE)
    return p


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_twist_gaps_match_the_closed_form(capsys, corners, tmp_path):
    t = 50.0
    target = [Q / 4 + t, Q / 4 - t, Q / 4 + t, Q / 4 - t]
    out = tmp_path / "sub" / "regulated.toml"
    code, stdout, err = run(capsys, "regulate", corners, "--target", ",".join(map(str, target)), "--json",
                            "--out", out)
    assert code == 0, err
    d = json.loads(stdout)
    p = np.array([1.0, -1.0, 1.0, -1.0])
    np.testing.assert_allclose(d["gaps"], -t * p / (4 * K_TWIST), rtol=1e-9)
    np.testing.assert_allclose([r["reaction"] for r in d["supports"]], target, rtol=1e-9)
    assert [r["support"] for r in d["supports"]] == [1, 2, 3, 4] and d["reachable"]
    # the regulated scene written is the one checked: solving it gives the target again
    code, stdout, err = run(capsys, "solve", out, "--json", "--accuracy", "high")
    assert code == 0, err
    np.testing.assert_allclose(json.loads(stdout)["reactions"], target, rtol=1e-9)


def test_a_target_out_of_equilibrium_is_projected_and_says_so(capsys, corners):
    code, stdout, err = run(capsys, "regulate", corners, "--target", "300", "--json")
    assert code == 5 and err.count("\n") == 1 and "not in equilibrium" in err
    d = json.loads(stdout)
    assert not d["reachable"]
    np.testing.assert_allclose([r["reaction"] for r in d["supports"]], Q / 4, rtol=1e-9)  # statics


@pytest.mark.parametrize("argv, words", [
    (("--target", "300", "--supports", "0"), "support numbers 1..4"),
    (("--target", "300", "--supports", "1,1"), "distinct"),
    (("--target", "300", "--supports", "5"), "1..4"),
    (("--target", "1,2,3", "--supports", "1,2"), "one per regulated support (2)"),
    (("--target", "abc"), "--target"),
    (("--target", "-5"), "reactions must be finite and >= 0"),
])
def test_bad_arguments_are_one_line_errors(capsys, corners, argv, words):
    code, _, err = run(capsys, "regulate", corners, *argv)
    assert code == 2 and err.count("\n") == 1 and words in err, err


def test_out_is_checked_before_any_work(capsys, corners, tmp_path):
    out = tmp_path / "mine.toml"
    out.write_text("keep me")
    code, stdout, err = run(capsys, "regulate", corners, "--target", "250", "--out", out)
    assert code == 2 and "exists" in err and stdout == ""
    assert out.read_text() == "keep me"


def test_supports_are_numbered_from_one(capsys, corners, tmp_path):
    out = tmp_path / "two.toml"
    code, stdout, err = run(capsys, "regulate", corners, "--target", "300", "--supports", "1,3", "--json",
                            "--out", out)
    assert code == 0, err
    d = json.loads(stdout)
    assert [r["support"] for r in d["supports"]] == [1, 3]
    np.testing.assert_allclose(d["gaps"], [-25 / K_TWIST, 0, -25 / K_TWIST, 0], rtol=1e-8)  # Σ p g = −t/k, t = 50
    code, stdout, err = run(capsys, "solve", out, "--json", "--accuracy", "high")
    # supports 1 and 3 (opposite corners) carry 300; statics leaves 200 for 2 and 4
    np.testing.assert_allclose(json.loads(stdout)["reactions"], [300, 200, 300, 200], rtol=1e-9)


def test_regulate_reports_the_shim_tolerance(tmp_path, capsys):
    """--json's shim_sensitivity (dR_i/dg0_j among the regulated supports, from the active set)
    against finite differences: the regulated scene re-solved with one shim thinner."""
    import plateqp as pq
    from plateqp.model.paths import set_param

    out = tmp_path / "reg.toml"
    rc = main(["regulate", "heave", "--target", "11000", "--supports", "12,13,17,18", "--json",
               "--out", str(out)])
    d = json.loads(capsys.readouterr().out)
    assert rc == 0 and d["shim_sensitivity_note"] is None
    S = np.array(d["shim_sensitivity"])
    assert S.shape == (4, 4)
    sc = pq.Scene.from_toml(out)
    idx = [11, 12, 16, 17]
    base = pq.solve(sc, accuracy="high").reactions[idx]
    gaps = np.array([s.gap for s in sc.supports])
    h = 1e-5  # cm
    for j, k in enumerate(idx):
        g = gaps.copy()
        g[k] += h
        fd = (pq.solve(set_param(sc, "supports.*.gap", g), accuracy="high").reactions[idx] - base) / h
        np.testing.assert_allclose(S[:, j], fd, rtol=1e-6, atol=1e-6 * np.abs(S).max())
