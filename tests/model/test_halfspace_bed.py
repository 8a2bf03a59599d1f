"""A plate on a tensionless elastic half-space ([foundation] model = "halfspace"; plateqp.model.soil).

External references (Boussinesq's solution; Johnson, Contact Mechanics, 1985, §§ 3.2, 5.2;
Timoshenko & Goodier, Theory of Elasticity, § 138):
- a rigid circular punch of radius a under a central force P settles P (1 − ν²) / (2 a E), its
  pressure P / (2π a √(a² − r²));
- a uniform pressure q over a circle of radius a on the bare half-space (the plate's stiffness
  vanishing) settles the centre by 2 q a (1 − ν²)/E and the edge by 4 q a (1 − ν²)/(π E);
- statics and the contact conditions under lift-off, and the bonded soil (two-sided) as the
  comparison.
"""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.errors import ProblemError

E_SOIL, NU_SOIL = 3e7, 0.3


def disc(radius: float, size: float, h: float, E: float, loads, **fnd) -> pq.Scene:
    return pq.Scene(plate=pq.Plate(shape={"circle": [0.0, 0.0, radius]}, h=h, E=E, nu=0.2),
                    mesh=pq.MeshSpec(element="dkt", size=size), loads=loads,
                    foundation=pq.Foundation(model="halfspace", E=E_SOIL, nu=NU_SOIL, **fnd))


def test_a_rigid_circular_punch_settles_as_boussinesq_says():
    """A disc 1e3 times stiffer than the soil (E_p h³ / (E_s a³) = 1e3) under a central P: it
    settles P (1 − ν²)/(2 a E) within 2 % on R/16 triangles, the error falling as the mesh
    halves; every node in contact, Σ R = P; the pressure rises towards the edge (the punch's
    1/√(a² − r²)). Asked 1e-6: the stiff disc sinks into the soil as a body, and the condensed
    route's reactions carry K u's rounding along that motion (up to ε Vᵀ|K||u| = 2.5e-7 of the
    load at R/16): at 1e-8 the total reaction was 9e-9 off, on the edge of the accuracy asked."""
    P, a = 1e5, 1.0
    errs = []
    for n in (8, 16):
        res = pq.solve(disc(a, a / n, 0.5, 1e3 * E_SOIL * a**3 / 0.5**3, [pq.PointLoad(P=P, x=0.0, y=0.0)]),
                       accuracy=1e-6)
        assert res.status == pq.Status.OPTIMAL and res.kkt.ok and res.active.all()
        assert res.reactions.sum() == pytest.approx(P, rel=1e-6)
        ref = P * (1 - NU_SOIL**2) / (2 * a * E_SOIL)
        errs.append(abs(res.deflection(0.0, 0.0) / ref - 1))
        r = np.hypot(*res.model.contacts.xy.T)
        area = res.model.bed_areas()[res.model.contacts.index]
        p = res.reactions / area
        inner, outer = p[r < 0.5 * a].mean(), p[(r > 0.7 * a) & (r < 0.85 * a)].mean()
        exact = (1 / np.sqrt(1 - 0.25**2), 1 / np.sqrt(1 - 0.775**2))
        assert outer / inner == pytest.approx(exact[1] / exact[0], rel=0.1)
    assert errs[1] < 0.02 and errs[1] < errs[0]


def test_a_flexible_circular_load_settles_the_bare_half_space():
    """A uniform q over a disc of radius a whose bending stiffness is negligible (E_s a³ / D =
    1e5): its centre settles 2 q a (1 − ν²)/E and its edge 4 q a (1 − ν²)/(π E) within 2 %."""
    q, a = 1e4, 1.0
    h, E = 0.01, 3e7 * 12 * 0.96 / 0.01**3 * 1e-5
    res = pq.solve(disc(a, a / 16, h, E, [pq.UniformLoad(q)]))
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    c = q * a * (1 - NU_SOIL**2) / E_SOIL
    assert res.deflection(0.0, 0.0) == pytest.approx(2 * c, rel=0.02)
    assert res.deflection(a, 0.0) == pytest.approx(4 * c / np.pi, rel=0.02)


def test_lift_off_on_a_half_space_keeps_statics_and_the_contact_conditions():
    """A square slab on a half-space, loaded near a corner: the far side lifts off. Statics
    (Σ R = P, Σ R x = P x_P), R ≥ 0, gap ≥ 0, R·gap = 0 to rounding; the soil settles beside
    the contact where no pressure acts (the half-space spreads its settlement), and the bonded
    soil pulls somewhere."""
    P = 2e5
    sc = pq.Scene(plate=pq.Plate(a=3.0, b=3.0, h=0.2, E=3e10, nu=0.2), mesh=pq.MeshSpec(nx=12, ny=12),
                  loads=[pq.PointLoad(P=P, x=0.5, y=0.6)],
                  foundation=pq.Foundation(model="halfspace", E=E_SOIL, nu=NU_SOIL))
    res = pq.solve(sc, backend="bpp", formulation="condensed", accuracy=1e-10)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    R, gap, v = res.reactions, res.gaps, res.compressions
    xy = res.model.contacts.xy
    assert R.sum() == pytest.approx(P, rel=1e-9)
    np.testing.assert_allclose(R @ xy, [P * 0.5, P * 0.6], rtol=1e-9)
    assert R.min() >= 0 and gap.min() >= -1e-10 * v.max()
    assert np.abs(R * gap).max() <= 1e-10 * R.max() * v.max()
    lifted = gap > 1e-6 * v.max()
    assert lifted.sum() > 10 and (v[lifted] > 1e-3 * v.max()).any()
    bonded = pq.solve_bilateral(sc)
    assert bonded.reactions.min() < 0


def test_the_grid_and_triangles_agree_on_a_half_space():
    """The same square slab under a uniform load and a corner point load on ACM 16² and DKT
    h = 1/16 of its side: the settlement under the load within 1 %."""
    kw = dict(plate=pq.Plate(a=2.0, b=2.0, h=0.2, E=3e10, nu=0.2), loads=[pq.UniformLoad(1e4), pq.PointLoad(P=1e5, x=0.5, y=0.5)],
              foundation=pq.Foundation(model="halfspace", E=E_SOIL, nu=NU_SOIL))
    grid = pq.solve(pq.Scene(mesh=pq.MeshSpec(nx=16, ny=16), **kw))
    tri = pq.solve(pq.Scene(mesh=pq.MeshSpec(element="dkt", size=2.0 / 16), **kw))
    assert grid.kkt.ok and tri.kkt.ok
    assert grid.deflection(0.5, 0.5) == pytest.approx(tri.deflection(0.5, 0.5), rel=0.01)


def test_a_half_space_too_large_for_the_dense_route_is_refused_before_it_is_built(monkeypatch):
    from plateqp.model import soil

    monkeypatch.setattr(soil, "HALFSPACE_DENSE_MAX", 50)
    sc = pq.Scene(plate=pq.Plate(a=2.0, b=2.0, h=0.2, E=3e10, nu=0.2), mesh=pq.MeshSpec(nx=8, ny=8),
                  loads=[pq.UniformLoad(1e4)], foundation=pq.Foundation(model="halfspace", E=E_SOIL, nu=NU_SOIL))
    with pytest.raises(ProblemError, match="81 bed nodes"):
        pq.solve(sc)


def test_a_points_area_in_several_polygons_loads_as_their_union():
    """``flexibility(..., owner=...)``: four quarter squares owned by one point load the soil as
    the whole square does (Love's rectangle, an independent closed form), in pressures and in
    forces; a point that owns nothing is refused."""
    from plateqp.model import halfspace as hs

    pts = np.array([[0.0, 0.0], [3.0, 0.5]])
    quarters = [np.array([[x0, y0], [x0 + 1, y0], [x0 + 1, y0 + 1], [x0, y0 + 1]], dtype=float)
                for x0 in (-1.0, 0.0) for y0 in (-1.0, 0.0)]
    far = np.array([[2.5, 0.0], [3.5, 0.0], [3.5, 1.0], [2.5, 1.0]])
    H = hs.flexibility(pts, quarters + [far], E_SOIL, NU_SOIL, owner=[0, 0, 0, 0, 1])
    f = hs.boussinesq_factor(E_SOIL, NU_SOIL)
    expect = np.array([[hs.rectangle_potential(x, y, -1, 1, -1, 1), hs.rectangle_potential(x, y, 2.5, 3.5, 0, 1)]
                       for x, y in pts]) * f
    np.testing.assert_allclose(H, expect, rtol=1e-12)
    Hf = hs.flexibility(pts, quarters + [far], E_SOIL, NU_SOIL, owner=[0, 0, 0, 0, 1], per="force")
    np.testing.assert_allclose(Hf, expect / [4.0, 1.0], rtol=1e-12)
    with pytest.raises(ProblemError, match="point 1 owns no polygon"):
        hs.flexibility(pts, quarters, E_SOIL, NU_SOIL, owner=[0, 0, 0, 0])
