"""The held systems of an exact path on one kept factorisation (plateqp.studies.held) against an
independent formulation: the whole saddle-point system [K Bᵀ; B −diag(ρ)] factorised by sparse LU
(plateqp.linalg.solve_saddle, what every piece took before).

- Random held sets on a free plate on a tensionless bed (soft rows: the spring 1/ρ itself, a
  few changed rows by Woodbury), on elastic posts (soft: their springs too), on a floating slab's
  rigid posts (penalty springs, refinement), and on rigid posts under a slab its edges hold (K
  alone, the rows condensed): the same (u, R_H) as LU, and the held system's residual at rounding.
- A held set that leaves a rigid motion free: the factor refuses it (SingularMatrixError), so the
  caller's LU and its MechanismError decide.
- Whole exact paths (a bed's load, with hundreds of pieces; a post's gap): the same breakpoints,
  contact sets and reactions as the path solved by LU alone.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.contact.scaling import Scaled
from plateqp.linalg import SingularMatrixError, solve_saddle
from plateqp.model.assembly import build_model
from plateqp.scenes.families import floating, grid_elastic, grid_rigid
from plateqp.studies import exact_path, homotopy
from plateqp.studies.held import HeldFactor


def bed(n: int) -> pq.Scene:
    """A free square plate on a tensionless bed falling away towards (1, 1), a column's load."""
    return pq.Scene(name=f"bed{n}", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                    edges={}, loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                    foundation=pq.Foundation(2.0e4, gap={"profile": "linear", "g0": 0.0, "gx": 0.004, "gy": 0.002}))


def residual(data, H, u, R, F, G) -> float:
    """The held system's normwise backward error (max over columns)."""
    K, B = data.K, data.B.tocsr()[H]
    r_u = F - K @ u - B.T @ R
    r_H = B @ u - G - data.rho[H][:, None] * R
    size = (abs(K).sum(axis=1).max() * np.abs(u).max() + abs(B).sum(axis=1).max() * np.abs(R).max()
            + np.abs(F).max() + np.abs(G).max())
    return float(max(np.abs(r_u).max(), np.abs(r_H).max()) / size)


@pytest.mark.parametrize("make, size, condensed", [
    (lambda: bed(12), 0.6, False), (lambda: grid_rigid(12, 4), 0.5, True),
    (lambda: grid_elastic(12, 4), 0.5, False), (lambda: floating(12, 4), 0.9, False),
], ids=["bed", "rigid posts", "elastic posts", "floating on rigid posts"])
def test_held_systems_are_those_of_the_saddle_point_system(make, size, condensed):
    data = Scaled.from_model(build_model(make()))
    rng = np.random.default_rng(3)
    held = HeldFactor(data)
    assert held.condensed is condensed  # a held plate with stiff rows: K alone; else springs on the rows
    H0 = np.flatnonzero(rng.random(data.m) < size)
    sets = [H0]
    for _ in range(4):  # a few rows in and out at a time: the Woodbury corrections or refactorisations
        flip = rng.choice(data.m, size=3, replace=False)
        mask = np.zeros(data.m, dtype=bool)
        mask[sets[-1]] = True
        mask[flip] = ~mask[flip]
        sets.append(np.flatnonzero(mask))
    for H in sets:
        F = np.column_stack([data.f, rng.standard_normal(data.n) * np.abs(data.f).max(), np.zeros(data.n)])
        G = np.column_stack([data.g0[H], rng.standard_normal(H.size) * 1e-3, np.eye(H.size)[:, 0]])
        u, R = held(H, F, G)
        u_lu, R_lu = solve_saddle(data.K, data.B.tocsr()[H], data.rho[H], F, G)
        assert residual(data, H, u, R, F, G) <= 1e-14
        for j in range(F.shape[1]):
            assert np.abs(u[:, j] - u_lu[:, j]).max() <= 1e-9 * np.abs(u_lu[:, j]).max()
            assert np.abs(R[:, j] - R_lu[:, j]).max() <= 1e-9 * np.abs(R_lu[:, j]).max()
    assert held.calls == len(sets)


def test_a_held_set_that_leaves_the_plate_free_is_refused():
    data = Scaled.from_model(build_model(floating(8, 3)))
    assert data.floating
    H = np.array([0, 1])  # two posts of one row: the plate turns about their line
    with pytest.raises(SingularMatrixError):
        HeldFactor(data)(H, data.f[:, None], data.g0[H][:, None])


@pytest.mark.parametrize("make, path, start, stop", [
    (lambda: bed(12), "loads.1.P", 100.0, 300.0),
    (lambda: grid_rigid(12, 4), "supports.5.gap", -2e-3, 2e-3),
], ids=["bed load", "post gap"])
def test_the_path_on_the_kept_factor_is_the_path_by_lu(make, path, start, stop, monkeypatch):
    scene = make()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        fast = exact_path(scene, path, start, stop)
        monkeypatch.setattr(homotopy, "_held_factor", lambda data: None)
        lu = exact_path(scene, path, start, stop)
    assert len(lu.breakpoints) >= 3
    assert [b["after"] for b in fast.breakpoints] == [b["after"] for b in lu.breakpoints]
    at_fast, at_lu = np.array([b["at"] for b in fast.breakpoints]), np.array([b["at"] for b in lu.breakpoints])
    assert np.abs(at_fast - at_lu).max() <= 1e-9 * max(abs(start), abs(stop))
    for t in np.linspace(start, stop, 9):
        R = lu.reactions(t)
        assert np.abs(fast.reactions(t) - R).max() <= 1e-9 * np.abs(R).max(), t
