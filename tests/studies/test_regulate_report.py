"""``plateqp regulate`` reports the reactions its gaps give: solving the scene with exactly the
gaps it returns (read back from its JSON) gives the reactions it printed, to rounding."""

from __future__ import annotations

import json

import numpy as np
import pytest

import plateqp as pq
from plateqp import scenes
from plateqp.cli import main
from plateqp.studies import regulate_gaps


def _regulate(capsys, *argv):
    code = main(["regulate", *map(str, argv), "--json"])
    out = capsys.readouterr()
    return code, json.loads(out.out), out.err


def _solve_with(name, gaps):
    sc = scenes.load(name)
    for s, g in zip(sc.supports, gaps, strict=True):
        s.gap = g
    return pq.solve(sc, accuracy="high").reactions


@pytest.mark.parametrize("target, supports, code_expected", [
    ("100000", "13", 5),  # out of reach: projected onto equilibrium, the plate at the edge of tipping
    ("30000", "13", 0),
    ("12000,12000,12000,12000", "12,13,17,18", 0),
])
def test_reported_reactions_are_those_the_returned_gaps_give(capsys, target, supports, code_expected):
    code, d, err = _regulate(capsys, "heave", "--target", target, "--supports", supports)
    assert code == code_expected, err
    R = _solve_with("heave", d["gaps"])  # an independent solve with exactly the returned gaps
    idx = [r["support"] - 1 for r in d["supports"]]
    reported = np.array([r["reaction"] for r in d["supports"]])
    np.testing.assert_allclose(reported, R[idx], rtol=1e-13, atol=1e-13 * np.abs(R).max())
    # what the gaps were aimed at is reported beside it, and the miss between the two is the check
    aimed = np.array([r["reaction_aimed"] for r in d["supports"]])
    miss = np.abs(reported - aimed).max() / max(np.abs(aimed).max(), np.abs(R).max())
    assert d["check_error"] == pytest.approx(miss, rel=1e-6, abs=1e-300)


def test_regulate_gaps_reactions_are_a_solve_of_its_scene():
    sc = scenes.load("heave")
    reg = regulate_gaps(sc, 100000.0, supports=[12])
    R = pq.solve(reg.scene, accuracy="high").reactions
    np.testing.assert_allclose(reg.reactions, R[reg.supports], rtol=1e-13)
    others = np.setdiff1d(np.arange(len(sc.supports)), reg.supports)
    np.testing.assert_allclose(reg.other_reactions, R[others], rtol=1e-13, atol=1e-13 * np.abs(R).max())
    # statics: the reported reactions of all supports carry the whole load
    assert reg.reactions.sum() + reg.other_reactions.sum() == pytest.approx(R.sum(), rel=1e-13)
    assert not reg.reachable and reg.aimed[0] < 100000.0
