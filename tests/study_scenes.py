"""Scenes and the independent reference solve shared by the studies' tests (test_sweep,
test_parallel, test_design, test_refinement, test_paths, test_reuse, the bed sweeps and pdas's
unshifted factor)."""

from __future__ import annotations

import warnings

import plateqp as pq

STIFF = "supports.*.stiffness"


def solve(scene, **kw) -> pq.Result:
    """The independent reference: a fresh model, the default route, no warm start."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene, **kw)


def fig5(n=8, stiffness="rigid") -> pq.Scene:
    """The paper's fig. 5 set-up: a square plate on a 5 × 5 grid of elastic supports, three of
    them heaved (negative gaps), a point load and self-weight (kgf, cm)."""
    heaved = {(0, 0), (1, 0), (0, 1)}
    sup = [pq.Support(100.0 * i, 100.0 * j, gap=(-0.02 if (i, j) in heaved else 0.0), stiffness=stiffness)
           for j in range(5) for i in range(5)]
    return pq.Scene(name="fig5", plate=pq.Plate(a=400.0, b=400.0, h=20.0, E=2.0e5, nu=0.2),
                    mesh=pq.MeshSpec(n, n, "acm"), supports=sup,
                    loads=[pq.PointLoad(P=20000.0, x=150.0, y=250.0), pq.UniformLoad(q=0.05)])


def contour(n=4, stiffness="rigid", **kw) -> pq.Scene:
    """A unit square plate on a contour of 4n one-sided supports (the paper's fig. 6)."""
    pts = ([(k / n, 0.0) for k in range(n)] + [(1.0, k / n) for k in range(n)]
           + [(1.0 - k / n, 1.0) for k in range(n)] + [(0.0, 1.0 - k / n) for k in range(n)])
    kw.setdefault("loads", [pq.UniformLoad(q=10.0)])
    return pq.Scene(name="contour", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1.0e7, nu=0.3),
                    mesh=pq.MeshSpec(8, 8), supports=[pq.Support(x, y, stiffness=stiffness) for x, y in pts], **kw)


def contact_set(active) -> list[int]:
    return [i for i, a in enumerate(active) if a]


def bed(n: int = 10) -> pq.Scene:
    """A free plate on a tensionless bed falling away towards (1, 1): part of it lifts off."""
    return pq.Scene(name="bed", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                    edges={}, loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                    foundation=pq.Foundation(2.0e4, gap={"profile": "linear", "g0": 0.0, "gx": 0.004, "gy": 0.002}))
