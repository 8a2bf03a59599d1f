"""plateqp regulate (plateqp.studies.regulate_gaps) assembles the plate once: the check solve
adapts the model built for the gaps; its answer is a cold solve's of the regulated scene."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp import solving
from plateqp.scenes.families import grid_elastic, grid_rigid
from plateqp.studies import design, regulate_gaps


@pytest.mark.parametrize("make", [lambda: grid_rigid(12, 3), lambda: grid_elastic(12, 3)])
def test_regulate_assembles_the_plate_once_and_checks_as_a_cold_solve(make, monkeypatch):
    scene = make()
    built = [0]

    def counting(real):
        def build(sc):
            built[0] += 1
            return real(sc)
        return build

    monkeypatch.setattr(design, "build_model", counting(design.build_model))
    monkeypatch.setattr(solving, "build_model", counting(solving.build_model))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        reg = regulate_gaps(scene, 40.0)
    assert built[0] == 1, f"the plate assembled {built[0]} times"
    monkeypatch.undo()
    cold = pq.solve(reg.scene, accuracy="high")
    assert reg.check.status == cold.status == pq.Status.OPTIMAL
    assert np.abs(reg.check.reactions - cold.reactions).max() <= 1e-10 * np.abs(cold.reactions).max()
    assert reg.miss <= 1e-8
