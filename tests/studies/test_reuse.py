"""Model re-use (plateqp.studies.reuse): an adapted model equals a fresh build."""

from __future__ import annotations

import numpy as np

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.studies import adapt_model, set_param


def test_adapt_model_equals_a_fresh_build():
    sc = pq.Scene(plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(6, 6),
                  edges={"left": pq.Edge("clamped", w=0.001)}, loads=[pq.UniformLoad(q=5.0)],
                  supports=[pq.Support(0.55, 0.4, gap=0.001), pq.Support(1.0, 1.0, stiffness=1e3)],
                  foundation=pq.Foundation(k=100.0, region=[0.5, 1.0, 0.0, 1.0], gap=0.0))
    base = build_model(sc)
    for path, value in (("supports.1.gap", -0.002), ("supports.*.stiffness", 5e3), ("supports.2.stiffness", "rigid"),
                        ("foundation.k", 300.0), ("foundation.gap", 0.002), ("loads.0.q", -1.0)):
        new = set_param(sc, path, value)
        m = adapt_model(base, new)
        ref = build_model(new)
        np.testing.assert_allclose(m.contacts.g0, ref.contacts.g0, rtol=1e-14, atol=1e-16, err_msg=path)
        np.testing.assert_allclose(m.contacts.rho, ref.contacts.rho, rtol=1e-14, err_msg=path)
        np.testing.assert_allclose(m.f, ref.f, rtol=1e-14, atol=1e-14, err_msg=path)
        assert m.scene is new and m.K is base.K
    assert adapt_model(base, set_param(sc, "plate.h", 0.03)) is None  # K changes: rebuild
    assert adapt_model(base, set_param(sc, "supports.1.x", 0.6)) is None  # B changes: rebuild
