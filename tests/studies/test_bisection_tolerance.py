"""The user sets how tightly a sweep brackets each change of the working scheme (``rtol``,
``plateqp sweep --rtol``) for a parameter that does not enter linearly (a stiffness)."""

from __future__ import annotations

import math

import pytest

import plateqp as pq
from plateqp.cli import main
from plateqp.studies import set_param, sweep
from study_scenes import STIFF, contact_set, fig5, solve


def test_tight_tolerance_brackets_each_change():
    sc = fig5(n=4)
    res = sweep(sc, STIFF, [1e5, 1e3, 10.0], progress=False, rtol=1e-9, executor="serial")
    assert res.breakpoints
    for b in res.breakpoints:
        lo, hi = sorted(b["bracket"])
        assert b["at"] is not None and hi / lo - 1 <= 1e-9
        # independent solves just outside the bracket see the two contact sets the sweep reports
        above = contact_set(solve(set_param(sc, STIFF, hi * (1 + 1e-9))).active)
        below = contact_set(solve(set_param(sc, STIFF, lo * (1 - 1e-9))).active)
        assert (above, below) == (b["before"], b["after"])


@pytest.mark.parametrize("rtol", [0.0, -1e-3, math.nan, math.inf, 1.5, 1e-17, "1e-3", True])
def test_bad_tolerance_is_refused(rtol):
    with pytest.raises(pq.ProblemError, match="rtol"):
        sweep(fig5(n=4), STIFF, [1e5, 10.0], progress=False, rtol=rtol, executor="serial")


def test_cli_refuses_a_bad_tolerance(capsys):
    rc = main(["sweep", "heave", "--param", "supports.*.stiffness", "--values", "1e6,1e3", "--rtol", "0"])
    err = capsys.readouterr().err
    assert rc != 0 and "rtol" in err and "Traceback" not in err
