"""``plateqp verify``: the verification ladder, run as a user runs it, and checked to be able to fail.

External references for the ladder's own closed forms: Timoshenko & Woinowsky-Krieger's printed
coefficients (simply supported square, uniform load 0.00406 q a⁴/D, central point load
0.01160 P a²/D; Tables 8 and 23), Hertz's plate on an elastic bed w₀ = P / (8 √(k D)), and the
clamped annulus's own edge conditions.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

from plateqp.studies import verify as V

pytest.importorskip("gmsh")


def test_closed_forms_against_printed_coefficients():
    assert V.navier_uniform(1, 1, 0.5, 0.5) == pytest.approx(0.00406, abs=5e-6)
    assert V.navier_point(1, 1, 0.5, 0.5, 0.5, 0.5) == pytest.approx(0.01160, abs=5e-5)
    D, k = 2.0, 50.0
    assert V.hertz_bed(0.0, 3.0, k, D) == pytest.approx(3.0 / (8 * math.sqrt(k * D)), rel=1e-12)
    # the annulus keeps its edge conditions: clamped, w = w' = 0 on both circles (finite differences)
    w = lambda r: V.annulus(r, 1.0, 0.3, 0.3, "clamped")  # noqa: E731
    e = 1e-6
    for r in (0.3, 1.0):
        assert abs(w(r)) < 1e-12 and abs((w(r + e) - w(r - e)) / (2 * e)) < 1e-8
    assert w(0.65) > 0


def test_verify_quick_from_the_command_line():
    """The command a user runs: every case passes, at least ten, each with its finest mesh judged."""
    out = subprocess.run([sys.executable, "-m", "plateqp.cli", "verify", "--quick", "--json"],
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["cases"] >= 10 and data["passed"] == data["cases"]
    rows = data["rows"]
    finals = [r for r in rows if r["passed"] is not None]
    assert len(finals) == data["cases"] and all(r["error"] <= r["tol"] for r in finals)
    # the convergent cases show their order on the meshes run: ACM and DKT about 2 under a uniform load
    rate = {r["case"]: r["rate"] for r in finals}
    assert rate["navier-ss-uniform"] == pytest.approx(2.0, abs=0.2)
    assert rate["disc-simple-uniform"] == pytest.approx(2.0, abs=0.3)
    assert rate["navier-ss-uniform-bfs"] == pytest.approx(4.0, abs=0.3)


def test_a_wrong_reference_fails(monkeypatch, capsys):
    """Broken on purpose: a reference 5 % off fails its case, and the command says so (exit code 5)."""
    from plateqp.cli import main

    cases = V.cases()

    def broken():
        out = []
        for c in cases:
            if c.name == "disc-clamped-uniform":
                ref = c.reference
                c = V.Case(**{**c.__dict__, "reference": lambda ref=ref: 1.05 * ref()})
            out.append(c)
        return out

    monkeypatch.setattr(V, "cases", broken)
    assert main(["verify", "--quick", "--case", "disc-clamped-uniform", "--case", "floating-statics"]) == 5
    text = capsys.readouterr().out
    assert "FAIL" in text and "1 of 2 cases pass" in text


def test_unknown_case_is_named(capsys):
    from plateqp.cli import main

    assert main(["verify", "--case", "no-such-case"]) == 2
    assert "unknown case 'no-such-case'" in capsys.readouterr().err
