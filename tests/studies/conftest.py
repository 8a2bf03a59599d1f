"""Fixtures of the studies' tests."""

from __future__ import annotations

import pytest

from plateqp.linalg import cholmod


@pytest.fixture
def factorisations(monkeypatch):
    """Counts CHOLMOD's numeric factorisations ("n") and symbolic analyses ("analyse"): every
    sparse Cholesky of the package goes there."""
    count = {"n": 0, "analyse": 0}
    factor, analyse = cholmod.Cholesky.factor, cholmod.Cholesky.analyse

    def counted(self, *args, **kw):
        count["n"] += 1
        return factor(self, *args, **kw)

    def analysed(self, *args, **kw):
        count["analyse"] += 1
        return analyse(self, *args, **kw)

    monkeypatch.setattr(cholmod.Cholesky, "factor", counted)
    monkeypatch.setattr(cholmod.Cholesky, "analyse", analysed)
    return count
