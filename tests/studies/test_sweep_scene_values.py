"""A sweep's scene per value, made without a deep copy and checked only where it changed
(plateqp.model.variation), against the reference: set_param's deep copy validated whole."""

from __future__ import annotations

import math

import numpy as np
import pytest

import plateqp as pq
from plateqp.errors import SceneError
from plateqp.model.paths import check_values as full_check_values
from plateqp.model.paths import set_param
from plateqp.model.variation import check_values, is_value_leaf, with_value
from plateqp.scenes.families import grid_elastic


def scene(stiff=False):
    sc = grid_elastic(8, 2)
    if stiff:  # D = 2.5e102: a spring or a load of 1e-100 is out of the magnitudes' range (scales.check_scales)
        sc.plate = pq.Plate(8.0, 8.0, 30.0, 1e99, 0.3)
    sc.supports[1].stiffness = "rigid"
    return pq.Scene(sc.name, sc.plate, sc.mesh, sc.edges, sc.openings, sc.pins, sc.loads, sc.supports,
                    pq.Foundation(1.0e5, gap={"profile": "linear", "g0": 0.0, "gx": 1e-3, "gy": 0.0}))


BAD = [math.nan, math.inf, -math.inf, 1e300, -1e-300, "soft", "rigid", [1.0], None, True, 0.0, -2.0]
GOOD = [1e-3, -2e-3, 0.0, 1e-11, 1e11, 1e-100, 1e100, np.float64(2.5e-3), np.array(1e-3), "1e-3", 3.0e4, "inf", math.inf]
PATHS = ["supports.1.gap", "supports.2.stiffness", "supports.*.gap", "supports.*.stiffness", "loads.0.q",
         "loads.1.P", "foundation.k", "foundation.gap", "foundation.gap.gx", "foundation.gap.gy"]


def outcome(fn):
    try:
        return "ok", fn()
    except SceneError as exn:
        return "error", str(exn)


@pytest.mark.parametrize("stiff", [False, True])
@pytest.mark.parametrize("path", PATHS)
def test_a_value_leaf_gives_the_scene_and_the_error_a_deep_copy_validated_whole_gives(path, stiff):
    assert is_value_leaf(path)
    base = scene(stiff)
    before = set_param(base, "name", base.name)  # a deep copy of it, to see it unchanged
    n = len(base.supports)
    per_item = [list(np.linspace(1e-3, 2e-3, n)), np.linspace(1e4, 2e4, n), [1e-3] * (n - 1), [1e4, "rigid"] * (n // 2),
                [1e-3, math.nan] * (n // 2), [10.0, 20.0]]
    for v in GOOD + BAD + per_item + [{"profile": "uniform", "g0": 1e-3}, {"profile": "trough"}]:
        want = outcome(lambda: set_param(base, path, v))
        got = outcome(lambda: with_value(base, path, v))
        assert got[0] == want[0], (path, v, got, want)
        if want[0] == "ok":
            assert got[1] == want[1], (path, v)  # field for field
        else:
            assert got[1] == want[1], (path, v)  # the same one-line message
        assert outcome(lambda: check_values(base, path, [1e-3, v])) == outcome(
            lambda: full_check_values(base, path, [1e-3, v])), (path, v)
    assert base == before


def test_the_scene_made_shares_what_did_not_change_and_copies_what_did():
    base = scene()
    new = with_value(base, "supports.1.gap", 2e-3)
    assert new.supports[0] is not base.supports[0] and base.supports[0].gap != 2e-3
    assert new.supports[2] is base.supports[2] and new.plate is base.plate
    new = with_value(base, "foundation.gap.gx", 2e-3)
    assert base.foundation.gap["gx"] == 1e-3 and new.foundation.gap["gx"] == 2e-3
    assert new.supports is base.supports


def test_a_path_that_is_no_value_leaf_goes_through_set_param():
    base = scene()
    assert not is_value_leaf("plate.h") and not is_value_leaf("supports.1.x")
    assert with_value(base, "plate.h", 0.02) == set_param(base, "plate.h", 0.02)
    with pytest.raises(SceneError, match="supports.0"):
        with_value(base, "supports.0.gap", 1e-3)
