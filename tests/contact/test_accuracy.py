"""Numeric accuracies: ``accuracy=1e-7`` as well as the presets.

The reference is Lemke's exact answer on the condensed problem; a backend asked for a
tolerance must either meet it (reactions within a small multiple of it) or say it did not.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.backends import available_backends
from plateqp.backends.base import PRESET_TOL, accuracy_tol, nearest_preset, preset
from plateqp.errors import ProblemError


def scene():
    """Simply supported plate on a 3×3 grid of one-sided supports, centre one heaved, the rest
    settled: some supports lift off."""
    sups = [pq.Support(x, y, gap=(-1e-3 if (x, y) == (0.5, 0.5) else 2e-3))
            for x in (0.25, 0.5, 0.75) for y in (0.25, 0.5, 0.75)]
    return pq.Scene(name="acc", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1.0e7, nu=0.3),
                    mesh=pq.MeshSpec(8, 8), edges={k: "simple" for k in ("left", "right", "bottom", "top")},
                    loads=[pq.UniformLoad(40.0)], supports=sups)


@pytest.fixture(scope="module")
def reference():
    return pq.solve(scene(), backend="lemke", formulation="condensed", accuracy="high")


def solve(backend, formulation, accuracy):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene(), backend=backend, formulation=formulation, accuracy=accuracy)


@pytest.mark.parametrize("bad", ["ultra", 0.0, 1.0, -1e-6, 1e-16, float("nan"), True, None, [1e-6]])
def test_bad_accuracy_is_a_clear_error(bad):
    with pytest.raises(ProblemError, match="accuracy"):
        pq.solve(scene(), backend="lemke", accuracy=bad)


def test_numbers_and_presets():
    assert accuracy_tol("high") == 1e-9 and accuracy_tol(1e-7) == 1e-7 and accuracy_tol("1e-7") == 1e-7
    assert nearest_preset(2e-4) == "low" and nearest_preset(1e-7) == "default" and nearest_preset(1e-12) == "high"
    table = {"low": {"eps": 1e-5, "max_iter": 10, "polish": False},
             "default": {"eps": 1e-8, "max_iter": 10, "polish": True},
             "high": {"eps": 1e-11, "max_iter": 99, "polish": True}}
    for name, tol in PRESET_TOL.items():  # a preset's own tolerance as a number: the preset's row
        assert preset(table, tol) == table[name]
    row = preset(table, 1e-5)  # one decade looser than "default": eps one decade looser
    assert math.isclose(row["eps"], 1e-7) and row["max_iter"] == 10 and row["polish"] is True
    assert preset(table, 1e-12)["eps"] == pytest.approx(1e-14)
    assert preset(table, 1e-12, scale=())["eps"] == 1e-11


def _iterative():
    return [b for b in ("osqp", "clarabel") if b in available_backends()]


@pytest.mark.parametrize("backend", _iterative())
def test_tolerance_ladder_is_met_or_flagged(backend, reference):
    """Down a ladder of tolerances: each answer called optimal has reactions within 20·tol of
    the exact ones (relative to the largest), and the error shrinks as the tolerance does."""
    Rmax = np.abs(reference.reactions).max()
    errors = {}
    for tol in (1e-2, 1e-4, 1e-6, 1e-8, 1e-10):
        res = solve(backend, "primal", tol)
        assert res.accuracy == tol and res.kkt.tol == tol
        err = np.abs(res.reactions - reference.reactions).max() / Rmax
        errors[tol] = err
        if res.status == pq.Status.OPTIMAL:
            assert res.kkt.worst <= tol
            assert err <= 20 * tol, (tol, err, res.kkt)
    assert errors[1e-10] < 1e-3 * max(errors[1e-2], 1e-9)


def test_exact_backends_take_numbers(reference):
    for backend, formulation in (("lemke", "condensed"), ("bpp", "condensed"), ("pdas", "primal"),
                                 ("pgs", "condensed")):
        res = solve(backend, formulation, 1e-10)
        assert res.status == pq.Status.OPTIMAL
        np.testing.assert_allclose(res.reactions, reference.reactions, rtol=0,
                                   atol=1e-8 * np.abs(reference.reactions).max())
