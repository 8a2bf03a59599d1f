"""The scenes of the extremes benchmark (``bench_extremes.py``): the base plate on a 3 × 3 grid of
one-sided supports and its variants at the edges of the parameter space, each named with how its
reference is found."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

import plateqp as pq

XS = (0.25, 0.5, 0.75)
PATTERN = np.array([-0.2, 0.1, 0.3, 0.0, -0.1, 0.2, 0.4, 0.0, 0.1])  # × w_free: heave < 0, settlement > 0
E0, H0 = 1.0e7, 0.02


# -- scenes --------------------------------------------------------------------------------------

def grid(n=16, E=E0, h=H0, stiffness="rigid", gaps=0.0, edges="simple", q=10.0, P=100.0, at=(0.7, 0.6)):
    """The base scene; ``gaps`` a number or 9 values (x-major over the grid)."""
    g = np.broadcast_to(np.asarray(gaps, dtype=float), (9,))
    pts = [(x, y) for x in XS for y in XS]
    sups = [pq.Support(x, y, gap=float(v), stiffness=stiffness) for (x, y), v in zip(pts, g)]
    loads = ([pq.UniformLoad(q)] if q else []) + ([pq.PointLoad(P, *at)] if P else [])
    return pq.Scene(name="extreme", plate=pq.Plate(1.0, 1.0, h, E, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                    edges={k: edges for k in ("left", "right", "bottom", "top")} if edges else {},
                    loads=loads, supports=sups)


def D_of(h=H0, E=E0):
    return pq.Plate(1.0, 1.0, h, E, 0.3).D


def without_supports(scene):
    return pq.Scene(name="free", plate=scene.plate, mesh=scene.mesh, edges=scene.edges, loads=scene.loads)


_WFREE: dict = {}


def w_free(n=16):
    """Largest deflection of the base plate and loads with no one-sided supports (E = 1e7)."""
    if n not in _WFREE:
        _WFREE[n] = float(np.abs(pq.solve(without_supports(grid(n))).u[::3]).max())
    return _WFREE[n]


def pair(d_cells, stiffness="rigid", n=16):
    """The centre support of a symmetric scene replaced by two, d_cells of a cell apart."""
    d = d_cells / n
    sc = grid(n, at=(0.5, 0.5))
    sc.supports = [s for i, s in enumerate(sc.supports) if i != 4]
    k = stiffness if stiffness == "rigid" else stiffness * sc.plate.D
    sc.supports += [pq.Support(0.5, 0.5 - d / 2, stiffness=k), pq.Support(0.5, 0.5 + d / 2, stiffness=k)]
    return sc


def touching():
    """The centre support's gap = the deflection there without it: touching, zero reaction."""
    red = grid()
    red.supports = [s for i, s in enumerate(red.supports) if i != 4]
    w = pq.solve(red, backend="lemke", formulation="condensed", accuracy="high").deflection(0.5, 0.5)
    return grid(gaps=np.where(np.arange(9) == 4, w, 0.0))


def floating_triangle():
    sc = grid(edges=None, q=0.0, at=(0.25, 0.375))
    sc.supports = [pq.Support(0.0, 0.0), pq.Support(1.0, 0.0), pq.Support(0.0, 1.0)]
    return sc


@dataclass
class Case:
    name: str
    group: str
    build: object  # () -> Scene
    ref: str = "exact"  # how the reference is found (see reference())
    expect: str = "solution"  # "solution" | "refused" | "no-equilibrium"
    note: str = ""
    timeout: float = 30.0
    extra: dict = field(default_factory=dict)


def _cases() -> list[Case]:
    wf = w_free
    D = D_of()
    cs = [
        Case("units-E1", "units", lambda: grid(E=1.0, gaps=PATTERN * wf() * E0 / 1.0), "scaled-E",
             note="E = 1, gaps × 1e7", extra={"E": 1.0}),
        Case("units-E1e11", "units", lambda: grid(E=1e11, gaps=PATTERN * wf() * E0 / 1e11), "scaled-E",
             note="E = 1e11, gaps × 1e-4", extra={"E": 1e11}),
        Case("thick-h1e-3", "thickness", lambda: grid(h=1e-3, gaps=PATTERN * wf() * D / D_of(1e-3)), "scaled-h",
             note="h/a = 1e-3", extra={"h": 1e-3}),
        Case("thick-h0.2", "thickness", lambda: grid(h=0.2, gaps=PATTERN * wf() * D / D_of(0.2)), "scaled-h",
             note="h/a = 0.2", extra={"h": 0.2}),
    ]
    for k in (1e-8, 1e-4, 1.0, 1e4, 1e8, 1e12):
        cs.append(Case(f"stiff-{k:g}", "stiffness", (lambda k=k: grid(stiffness=k * D)), "exact",
                       note=f"c a²/D = {k:g}", extra={"kappa": k}))
    cs.append(Case("stiff-mixed", "stiffness",
                   lambda: _mixed_stiffness(), "exact", note="rigid and c a²/D = 1e-8 side by side"))
    for gam in (1e-12, 1e-6, 1e-2, 1.0, 1e2):
        cs.append(Case(f"gap-mixed-{gam:g}", "gaps", (lambda gam=gam: grid(gaps=PATTERN / 0.4 * gam * wf())),
                       "exact", note=f"mixed heave/settlement up to {gam:g} w_free", extra={"gamma": gam}))
    cs += [
        Case("gap-settle-1", "gaps", lambda: grid(gaps=1.0 * wf()), "free", note="all settled 1 × w_free: nothing touches"),
        Case("gap-settle-1e2", "gaps", lambda: grid(gaps=1e2 * wf()), "free", note="all settled 1e2 × w_free"),
        Case("gap-far-1e2", "gaps", lambda: grid(gaps=np.r_[1e2 * wf(), np.zeros(8)]), "drop-first",
             note="one support settled 1e2 × w_free, the rest touching"),
        Case("gap-heave-1e2", "gaps", lambda: grid(gaps=np.where(np.arange(9) == 4, -1e2 * wf(), 0.0)), "exact",
             note="centre support heaved 1e2 × w_free"),
        Case("degenerate-touching", "degenerate", touching, "drop-centre",
             note="centre support touching with zero reaction"),
        Case("degenerate-no-load", "degenerate", lambda: grid(q=0.0, P=0.0), "zero",
             note="no load, zero gaps: every support touches, R = 0"),
        Case("floating-grid", "floating", lambda: grid(edges=None), "exact", note="free plate on the 3 × 3 grid"),
        Case("floating-triangle", "floating", floating_triangle, "statics",
             note="free plate on 3 supports: R by statics"),
        Case("floating-settled-1e2", "floating", lambda: grid(edges=None, gaps=1e2 * wf()), "floating-shift",
             note="free plate, all settled 1e2 × w_free (a rigid drop)"),
        Case("floating-uplift", "floating", lambda: grid(edges=None, gaps=1e2 * wf(), q=-10.0, P=-100.0), "none",
             "no-equilibrium", note="free plate, net uplift"),
        Case("near-rigid-1e-1", "near", lambda: pair(1e-1), "exact", note="rigid pair 0.1 cell apart"),
        Case("near-rigid-1e-3", "near", lambda: pair(1e-3), "exact", note="rigid pair 1e-3 cell apart"),
        Case("near-rigid-1e-4", "near", lambda: pair(1e-4), "exact-held", note="rigid pair 1e-4 cell apart"),
        Case("near-rigid-1e-7", "near", lambda: pair(1e-7), "none", "refused",
             note="rigid pair 1e-7 cell apart: refused by design"),
        Case("near-elastic-1e-7", "near", lambda: pair(1e-7, stiffness=1e3), "exact-dual",
             note="elastic pair (c a²/D = 1e3) 1e-7 cell apart"),
    ]
    for n in (64, 128, 256):
        cs.append(Case(f"mesh-{n}", "mesh", (lambda n=n: grid(n)), "exact", note=f"{n}² mesh",
                       timeout=30.0 if n < 256 else 60.0))
    return cs


def _mixed_stiffness():
    sc = grid()
    for i, s in enumerate(sc.supports):
        s.stiffness = "rigid" if i % 2 else 1e-8 * sc.plate.D
    return sc


CASES = {c.name: c for c in _cases()}
