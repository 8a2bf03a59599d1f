"""accuracy="auto" must not claim an error estimate when the meshes disagree.

A support 5 mm from a clamped edge of a 1 m plate under a uniform load: on 2² and 4² its
point lies in an element held by the edge and it carries nothing; on 8² it carries 196; the
answer converges slowly towards about 22 (128²). The Richardson estimate for 8² from 2² and
4² said 0.6 %; the true error of the reactions on 8² (against 64², an independent, finer
answer) is of order 1. The estimate is now checked against the 8² answer itself, and called
not trusted (a warning, ``"trusted": false`` in the result and the JSON).
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.errors import PlateQPWarning


def near_edge(n: int, x: float = 0.995) -> pq.Scene:
    return pq.Scene(name="near-edge", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(n, n),
                    loads=[pq.UniformLoad(100.0)], supports=[pq.Support(x, 0.52), pq.Support(0.3, 0.5)],
                    edges={"right": pq.Edge("clamped")})


def true_reaction_error(n: int, x: float) -> float:
    fine = pq.solve(near_edge(64, x), backend="bpp", accuracy="high").reactions
    R = pq.solve(near_edge(n, x), backend="bpp", accuracy="high").reactions
    return float(np.abs(R - fine).max() / np.abs(fine).max())


def test_auto_is_not_trusted_when_the_meshes_disagree():
    with pytest.warns(PlateQPWarning, match="meshes disagree"):
        res = pq.solve(near_edge(8), backend="bpp", accuracy="auto")
    est = res.extras["discretisation_error"]
    true = true_reaction_error(8, 0.995)
    assert true > 10 * est["worst"]  # the claim the estimate made is far off ...
    assert est["trusted"] is False and est["observed"] > 10 * est["worst"]  # ... and it says so
    assert res.to_dict()["discretisation_error"]["trusted"] is False


def test_auto_is_trusted_where_the_meshes_agree():
    """The support well inside the plate: the estimate stands, and it is not below the true
    error of the reactions by more than the factor the check allows."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlateQPWarning)
        res = pq.solve(near_edge(16, 0.6), backend="bpp", accuracy="auto")
    est = res.extras["discretisation_error"]
    assert est["trusted"] is True
    assert true_reaction_error(16, 0.6) <= 4 * est["worst"]


def test_cli_says_the_estimate_is_not_trusted(tmp_path, capsys):
    from plateqp.cli import main

    f = tmp_path / "near-edge.toml"
    near_edge(8).to_toml(f)
    assert main(["solve", str(f), "--accuracy", "auto", "--backend", "bpp", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["discretisation_error"]["trusted"] is False
    assert main(["solve", str(f), "--accuracy", "auto", "--backend", "bpp"]) == 0
    assert "the estimate is not to be trusted" in capsys.readouterr().out
