"""pdas on degenerate contact problems: it must finish, exactly.

External references: statics (a floating plate on two supports carries the load by the lever
rule, whatever its stiffness: the ACM element holds the rigid motions exactly, so the consistent
loads have the resultant and moments of the applied ones) and lemke on the condensed form (an
independent formulation and method) for held plates.
"""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.backends.base import Status

PLATE = pq.Plate(a=1.0, b=1.0, h=0.01, E=2.1e11, nu=0.3)


def test_diagonal_supports_with_balanced_load():
    # Two rigid supports at opposite corners, upward 300 at the other two: the load is balanced
    # about the diagonal, so the rotation about it is free. Statics: 2 R = 1000 − 600.
    scene = pq.Scene(name="diag", plate=PLATE, mesh=pq.MeshSpec(8, 8, element="acm"),
                     loads=[pq.UniformLoad(1000.0), pq.PointLoad(-300.0, 0.0, 0.0), pq.PointLoad(-300.0, 1.0, 1.0)],
                     supports=[pq.Support(0.0, 1.0), pq.Support(1.0, 0.0)])
    r = pq.solve(scene, backend="pdas", formulation="primal")
    assert r.status is Status.OPTIMAL
    np.testing.assert_allclose(r.reactions, [200.0, 200.0], rtol=1e-9)
    assert r.deflection_unique is False


@pytest.mark.parametrize("seed", range(6))
def test_supports_on_a_line_with_the_load_on_it(seed):
    # Two supports symmetric about the centre, the uniform load's resultant (the centre) and a
    # point load on the line through them: a rotation about that line is free. Lever rule.
    rng = np.random.default_rng(seed)
    n = 8
    while True:
        i, j = (int(v) for v in rng.integers(0, n + 1, 2))
        if (i, j) != (n - i, n - j) and 2 * i != n:
            break
    p1, p2 = np.array([i, j]) / n, np.array([n - i, n - j]) / n
    t, q, P = float(rng.uniform(0.1, 0.9)), float(rng.uniform(100, 1000)), float(rng.uniform(100, 1000))
    x, y = t * p1 + (1 - t) * p2
    rigid = [True, bool(rng.random() < 0.5)]
    scene = pq.Scene(name=f"line-{seed}", plate=PLATE, mesh=pq.MeshSpec(n, n, element="acm"),
                     loads=[pq.UniformLoad(q), pq.PointLoad(P, float(x), float(y))],
                     supports=[pq.Support(*map(float, p), stiffness="rigid" if rig else 1e7)
                               for p, rig in zip((p1, p2), rigid)])
    r = pq.solve(scene, backend="pdas", formulation="primal")
    assert r.status is Status.OPTIMAL
    np.testing.assert_allclose(r.reactions, [q / 2 + t * P, q / 2 + (1 - t) * P], rtol=1e-9)


@pytest.mark.parametrize("method", ["auto", "sparse"])
@pytest.mark.parametrize("seed", range(6))
def test_two_supports_exactly_at_lift_off(seed, method):
    # A plate simply supported on two edges; two of its supports get exactly the gap the load
    # closes (found with every support far away), the others random gaps: pdas against lemke.
    rng = np.random.default_rng(100 + seed)
    n = 8
    pts = []
    while len(pts) < 5:
        p = (int(rng.integers(1, n)) / n, int(rng.integers(1, n)) / n)
        if p not in pts:
            pts.append(p)
    stiff = ["rigid" if rng.random() < 0.6 else float(10 ** rng.uniform(5, 7)) for _ in pts]
    loads = [pq.UniformLoad(float(rng.uniform(500, 2000))),
             pq.PointLoad(float(rng.uniform(100, 500)), float(rng.uniform(0.3, 0.7)), float(rng.uniform(0.3, 0.7)))]

    def scene(gaps):
        return pq.Scene(name=f"lift-{seed}", plate=PLATE, mesh=pq.MeshSpec(n, n, element="acm"),
                        edges={"left": "simple", "right": "simple"}, loads=loads,
                        supports=[pq.Support(x, y, gap=float(g), stiffness=k) for (x, y), g, k in zip(pts, gaps, stiff)])

    far = np.ones(len(pts))
    free = pq.solve(scene(far), backend="lemke", formulation="condensed")
    closes = far - free.gaps  # the deflection at each support
    gaps = closes * rng.uniform(0.5, 1.5, len(pts))
    gaps[:2] = closes[:2]  # exactly at lift-off
    ref = pq.solve(scene(gaps), backend="lemke", formulation="condensed", accuracy="high")
    r = pq.solve(scene(gaps), backend="pdas", formulation="primal", options={"method": method})
    assert r.status is Status.OPTIMAL
    total = loads[0].q + loads[1].P  # the load on the plate (rounding of a zero reaction is relative to it)
    np.testing.assert_allclose(r.reactions, ref.reactions, rtol=1e-9, atol=1e-9 * total)
