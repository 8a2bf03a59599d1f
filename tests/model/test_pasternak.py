"""Pasternak's tensionless foundation (plateqp.model.soil): springs k joined by a shear layer c2,
the soil's surface its own unknowns.

External references:
- an infinite plate on a two-parameter foundation under a point load (Kerr 1964; Selvadurai,
  Elastic Analysis of Soil-Foundation Interaction, 1979, ch. 5): with ξ⁴ + (c2/D)ξ² + k/D =
  (ξ² + a1)(ξ² + a2), w(r) = P [K0(√a2 r) − K0(√a1 r)] / (2π D (a1 − a2)) (modified Bessel
  functions of complex argument), at the centre w0 = P (π/2 − atan(c2/s)) / (2π s),
  s = √(4Dk − c2²); for c2 = 0 Hertz's P / (8√(Dk)) and the Kelvin function kei;
- a uniform load on a free plate: the plate and the soil settle q/k everywhere (the shear
  layer stays flat);
- c2 = 0: Winkler's bed, solved through its springs' flexibility on the contact rows (another
  formulation of the same soil);
- statics and the contact conditions themselves (R ≥ 0, gap ≥ 0, R·gap = 0, the soil's own
  equilibrium where the plate lifts off).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy import special

import plateqp as pq
from plateqp.errors import SceneError

E, H, NU = 3e10, 0.2, 0.2
D = E * H**3 / (12 * (1 - NU**2))
K_SOIL = 1e8
ELL = (D / K_SOIL) ** 0.25  # the plate's characteristic length on the springs alone
P = 1e5


def kerr(c2: float, r) -> np.ndarray:
    """w(r) of the infinite plate on a Pasternak foundation under P at r = 0 (the module's text)."""
    b, c = c2 / D, K_SOIL / D
    disc = np.sqrt(complex(b * b - 4 * c))
    a1, a2 = (b + disc) / 2, (b - disc) / 2
    r = np.asarray(r, dtype=float)
    return (P / (2 * np.pi * D) * (special.kv(0, np.sqrt(a2) * r) - special.kv(0, np.sqrt(a1) * r)) / (a1 - a2)).real


def centre(c2: float) -> float:
    s = np.sqrt(4 * D * K_SOIL - c2**2)
    return P * (np.pi / 2 - np.arctan(c2 / s)) / (2 * np.pi * s)


def test_the_closed_forms_agree_with_each_other_and_with_hertz_and_kelvin():
    """The reference itself: the Bessel form at r → 0 is the centre's closed form; at c2 = 0
    it is Hertz's P/(8√(Dk)) and −P ℓ² kei(r/ℓ) / (2π D)."""
    for c2 in (0.0, 1e6, 0.9 * 2 * np.sqrt(D * K_SOIL)):
        assert kerr(c2, 1e-12) == pytest.approx(centre(c2), rel=1e-9)
    assert centre(0.0) == pytest.approx(P / (8 * np.sqrt(D * K_SOIL)), rel=1e-14)
    r = np.array([0.5, 1.0, 2.0]) * ELL
    np.testing.assert_allclose(kerr(0.0, r), -P * ELL**2 / (2 * np.pi * D) * special.kei(r / ELL), rtol=1e-12)


def point_load_scene(c2: float, mesh: pq.MeshSpec, size: float = 10 * ELL) -> pq.Scene:
    return pq.Scene(plate=pq.Plate(a=size, b=size, h=H, E=E, nu=NU), mesh=mesh,
                    loads=[pq.PointLoad(P=P, x=size / 2, y=size / 2)],
                    foundation=pq.Foundation(k=K_SOIL, model="pasternak", shear=c2))


@pytest.mark.parametrize("mesh", [pq.MeshSpec(nx=40, ny=40), pq.MeshSpec(element="dkt", size=10 * ELL / 40)],
                         ids=["acm", "dkt"])
@pytest.mark.parametrize("c2", [0.0, 1e7, 0.5 * 2 * np.sqrt(1e8 * 3e10 * 0.2**3 / (12 * 0.96))],
                         ids=["winkler", "light", "strong"])
def test_a_point_load_on_a_large_plate_bonded_to_the_soil_against_the_closed_form(mesh, c2):
    """The soil bonded (two-sided), a plate 10ℓ wide (its edges free, 5ℓ from the load):
    the deflection at the load and ℓ from it within 1.5 % of the infinite plate's; the shear
    layer's stiffening (w0 with c2 over w0 without) within 0.5 %."""
    L = 10 * ELL
    res = pq.solve_bilateral(point_load_scene(c2, mesh))
    base = pq.solve_bilateral(point_load_scene(0.0, mesh))
    w = res.deflection([L / 2, L / 2 + ELL], [L / 2, L / 2])
    np.testing.assert_allclose(w, kerr(c2, [1e-12, ELL]), rtol=0.015)
    ratio = res.deflection(L / 2, L / 2) / base.deflection(L / 2, L / 2)
    assert ratio == pytest.approx(centre(c2) / centre(0.0), rel=0.005)
    assert res.residual < 1e-9


@pytest.mark.parametrize("mesh", [pq.MeshSpec(nx=8, ny=6), pq.MeshSpec(element="dkt", size=0.25)], ids=["acm", "dkt"])
def test_a_uniform_load_on_a_free_plate_settles_q_over_k(mesh):
    """A free plate under q on a Pasternak bed over its whole area: plate and soil settle q/k
    (the shear layer flat: no shear force); every row in contact, the reactions carry q·a·b.
    DKT's uniform load has no moments at the free edge: exact to rounding; ACM's slope loads
    there bend the plate by O(h²) of q/k (0.09 % at 8 × 6 cells, measured)."""
    q, k = 2e4, 1e7
    sc = pq.Scene(plate=pq.Plate(a=2.0, b=1.5, h=H, E=E, nu=NU), mesh=mesh, loads=[pq.UniformLoad(q)],
                  foundation=pq.Foundation(k=k, model="pasternak", shear=1e6))
    res = pq.solve(sc, backend="bpp", formulation="condensed", accuracy=1e-10)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok and res.active.all()
    tol = 1e-7 if mesh.element == "dkt" else 2e-3
    np.testing.assert_allclose(res.nodal("w"), q / k, rtol=tol)
    np.testing.assert_allclose(res.compressions, q / k, rtol=tol)  # the soil's settlement
    assert res.reactions.sum() == pytest.approx(q * 3.0, rel=1e-9)


def test_without_shear_the_soil_unknowns_give_winklers_answer():
    """c2 = 0: the same soil as Winkler's springs on the contact rows (another formulation),
    with a trough that lifts the plate off over part of a bed region, on both meshes."""
    for mesh in (pq.MeshSpec(nx=12, ny=12), pq.MeshSpec(element="dkt", size=0.2)):
        gap = {"profile": "trough", "x": 1.0, "y": 1.2, "radius": 0.6, "depth": 2e-3}
        kw = dict(plate=pq.Plate(a=2.0, b=2.0, h=0.15, E=E, nu=NU), mesh=mesh, edges={"left": "simple"},
                  loads=[pq.UniformLoad(3e4), pq.PointLoad(P=5e4, x=1.5, y=0.5)])
        pas = pq.solve(pq.Scene(**kw, foundation=pq.Foundation(k=5e7, model="pasternak", shear=0.0, gap=gap,
                                                             region=[0.0, 2.0, 0.4, 2.0])), accuracy=1e-10)
        win = pq.solve(pq.Scene(**kw, foundation=pq.Foundation(k=5e7, gap=gap, region=[0.0, 2.0, 0.4, 2.0])),
                       accuracy=1e-10)
        assert pas.kkt.ok and win.kkt.ok
        assert 0 < (~pas.active).sum() < pas.active.size  # some of the bed lifts off
        scale = np.abs(win.reactions).max()
        np.testing.assert_allclose(pas.reactions, win.reactions, rtol=0, atol=1e-8 * scale)
        np.testing.assert_allclose(pas.u, win.u, rtol=0, atol=1e-8 * np.abs(win.u).max())
        np.testing.assert_allclose(pas.compressions, win.compressions, rtol=0, atol=1e-8 * np.abs(win.u).max())


def test_tensionless_lift_off_keeps_statics_and_the_soil_follows_its_own_equilibrium():
    """A corner load on a clamped-free plate: part of the bed lifts off. Statics (Σ R and the
    moments of R balance the loads and the edge), the contact conditions to rounding, and where
    the plate has lifted off the soil's surface is not at rest: the shear layer drags it down
    beside the contact (v > 0 at some lifted node), and the soil's rows of K v = R hold there
    with R = 0. The bonded soil (two-sided) pulls the plate down where this one lets go."""
    sc = pq.Scene(plate=pq.Plate(a=3.0, b=3.0, h=0.15, E=E, nu=NU), mesh=pq.MeshSpec(nx=16, ny=16),
                  loads=[pq.PointLoad(P=2e5, x=0.4, y=0.4)],
                  foundation=pq.Foundation(k=2e7, model="pasternak", shear=5e6))
    # 1e-9: the free plate sinks as a body, and the condensed route's reactions carry K u's
    # rounding along that motion (the KKT check's statics: 5e-11 of the load here)
    res = pq.solve(sc, backend="bpp", formulation="condensed", accuracy=1e-9)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    R, gap, v = res.reactions, res.gaps, res.compressions
    assert R.sum() == pytest.approx(2e5, rel=1e-9)  # a free plate: the soil carries it all
    xy = res.model.contacts.xy
    np.testing.assert_allclose(R @ xy, [2e5 * 0.4, 2e5 * 0.4], rtol=1e-9)
    assert R.min() >= 0 and gap.min() >= -1e-12 * np.abs(v).max()
    assert np.abs(R * gap).max() <= 1e-12 * R.max() * np.abs(v).max()
    lifted = gap > 1e-9 * np.abs(v).max()
    assert lifted.sum() > 10
    assert (v[lifted] > 1e-6 * v.max()).any()  # the layer drags the free surface down
    m = res.model
    Ks = m.K[m.n_free:, m.n_free:]
    np.testing.assert_allclose(Ks @ v, R, rtol=0, atol=1e-9 * R.max())  # the soil's equilibrium
    bonded = pq.solve_bilateral(sc)
    assert bonded.reactions.min() < 0 < bonded.reactions.max()  # the bonded soil pulls somewhere
    assert res.deflection(0.4, 0.4) > bonded.deflection(0.4, 0.4)


def from_text(text: str) -> pq.Scene:
    import tomllib

    return pq.Scene.from_dict(tomllib.loads(text))


def test_the_scene_language_round_trips_and_names_what_is_wrong():
    text = """
name = "slab on pasternak"
[plate]
a = 2.0
b = 2.0
h = 0.2
E = 3e10
nu = 0.2
[mesh]
nx = 8
ny = 8
[[loads]]
type = "uniform"
q = 1e4
[foundation]
model = "pasternak"
k = 1e7
shear = 1e6
gap = 0.001
"""
    sc = from_text(text)
    assert sc.foundation.model == "pasternak" and sc.foundation.shear == 1e6
    again = from_text(sc.to_toml())
    assert again.foundation == sc.foundation
    assert "model" not in from_text(text.replace('model = "pasternak"\n', "").replace(
        "shear = 1e6\n", "")).to_dict()["foundation"]  # Winkler's default is not written out
    bad = [
        (text.replace("shear = 1e6\n", ""), "foundation.shear: missing"),
        (text.replace('"pasternak"', '"winkel"'), "foundation.model: unknown soil model"),
        (text.replace("shear = 1e6", "shear = -1.0"), "foundation.shear"),
        (text.replace('model = "pasternak"', 'model = "winkler"'), "foundation.shear: the winkler model does not take"),
        (text.replace('model = "pasternak"', 'model = "halfspace"'), "foundation.k: the halfspace model does not take"),
        (text.replace('model = "pasternak"\nk = 1e7\nshear = 1e6', 'model = "halfspace"\nE = 3e7\nnu = 0.7'),
         "foundation.nu: Poisson's ratio 0.7 is outside"),
        (text.replace('model = "pasternak"\nk = 1e7\nshear = 1e6', 'model = "halfspace"\nE = 3e7'),
         "foundation.nu: missing"),
    ]
    for t, words in bad:
        with pytest.raises(SceneError, match=words.replace("(", r"\(")):
            from_text(t)


def test_a_pasternak_bed_solves_alike_by_every_formulation_and_exact_backend():
    """A plate held on two edges on a Pasternak bed with a heave bump: the primal (pdas), the
    condensed (bpp, lemke) and the dual (bpp) problems give the same reactions."""
    sc = pq.Scene(plate=pq.Plate(a=2.0, b=1.5, h=0.15, E=E, nu=NU), mesh=pq.MeshSpec(nx=10, ny=8),
                  edges={"left": "simple", "right": "simple"}, loads=[pq.UniformLoad(2e4)],
                  foundation=pq.Foundation(k=3e7, model="pasternak", shear=2e6,
                                           gap={"profile": "bump", "x": 1.0, "y": 0.75, "radius": 0.5, "depth": 1e-3}))
    ref = pq.solve(sc, backend="bpp", formulation="condensed", accuracy=1e-10)
    assert ref.kkt.ok and 0 < ref.active.sum() < ref.active.size
    scale = np.abs(ref.reactions).max()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for backend, form in (("pdas", "primal"), ("lemke", "condensed"), ("bpp", "dual")):
            res = pq.solve(sc, backend=backend, formulation=form, accuracy=1e-10)
            assert res.status == pq.Status.OPTIMAL and res.kkt.ok, (backend, form)
            np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-7 * scale)


def test_sensitivities_on_a_pasternak_bed_are_the_finite_differences_of_the_solves():
    """dR/dg0 and the load factor's derivative (plateqp.sensitivity) against finite differences
    of two exact solves (another computation of the same derivative); the plate's deflection
    derivative is the plate's, not the gap to the soil. The soil's own parameters are in K, not
    on its rows: ``foundation.k`` is not among the stiffness parameters."""

    def scene(g0=0.0, q=2e4):
        return pq.Scene(plate=pq.Plate(a=2.0, b=1.5, h=0.15, E=E, nu=NU), mesh=pq.MeshSpec(nx=10, ny=8),
                        edges={"left": "simple", "right": "simple"}, loads=[pq.UniformLoad(q)],
                        foundation=pq.Foundation(k=3e7, model="pasternak", shear=2e6,
                                                 gap={"profile": "linear", "g0": -5e-4 + g0, "gx": 3e-4}))

    res = pq.solve(scene(), backend="bpp", formulation="condensed", accuracy=1e-11)
    assert 0 < (~res.active).sum()
    d = 1e-8
    moved = pq.solve(scene(g0=d), backend="bpp", formulation="condensed", accuracy=1e-11)
    s = pq.sensitivity(res, "gaps")
    fd = (moved.reactions - res.reactions) / d
    np.testing.assert_allclose(np.asarray(s).sum(axis=1), fd, rtol=0, atol=1e-6 * np.abs(fd).max())
    xy = res.model.contacts.xy
    dw = (moved.at(xy[:, 0], xy[:, 1]) - res.at(xy[:, 0], xy[:, 1])) / d
    np.testing.assert_allclose(s.deflections.sum(axis=1), dw, rtol=0, atol=1e-6 * np.abs(dw).max())
    heavier = pq.solve(scene(q=2e4 + 1.0), backend="bpp", formulation="condensed", accuracy=1e-11)
    sl = np.asarray(pq.sensitivity(res, "loads"))[:, 0]
    np.testing.assert_allclose((heavier.reactions - res.reactions) * 2e4, sl, rtol=0, atol=1e-6 * np.abs(sl).max())
    assert pq.sensitivity(res, "stiffness").labels == []


@pytest.mark.parametrize("path, values", [("foundation.k", [2e7, 3e7, 5e7]), ("foundation.gap.g0", [-8e-4, -5e-4, 0.0]),
                                          ("foundation.shear", [1e6, 4e6])])
def test_a_sweep_of_a_pasternak_bed_gives_what_cold_solves_give(path, values):
    """A sweep re-uses the model only where K stays: a Pasternak soil's k and shear are in K
    (the model is rebuilt), its gap is not (adapted). Every value equals a cold solve of that
    scene (another computation of the same answer)."""
    from plateqp.model.paths import set_param
    from plateqp.studies.sweep import sweep

    base = pq.Scene(plate=pq.Plate(a=2.0, b=1.5, h=0.15, E=E, nu=NU), mesh=pq.MeshSpec(nx=10, ny=8),
                    edges={"left": "simple", "right": "simple"}, loads=[pq.UniformLoad(2e4)],
                    foundation=pq.Foundation(k=3e7, model="pasternak", shear=2e6,
                                             gap={"profile": "linear", "g0": -5e-4, "gx": 3e-4}))
    out = sweep(base, path, values, executor="serial", progress=False, refine_breakpoints=False, accuracy=1e-10)
    assert [row["value"] for row in out.rows] == values
    for v, row in zip(values, out.rows):
        cold = pq.solve(set_param(base, path, v), accuracy=1e-10)
        np.testing.assert_allclose(row["reactions"], cold.reactions, rtol=0, atol=1e-8 * np.abs(cold.reactions).max())


def test_a_large_pasternak_bed_starts_from_a_coarse_meshs_contact_set():
    """4225 rows on a 64² Pasternak bed: backend "auto" starts pdas from the 16² mesh's set (its
    rows are rigid, its soil unknowns soft: a coarse set is close); the answer is a cold
    start's, with fewer factorisations."""
    sc = pq.Scene(plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(64, 64),
                  edges={"left": "simple", "right": "simple"},
                  loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                  foundation=pq.Foundation(model="pasternak", k=2.0e4, shear=2.0e2,
                                           gap={"profile": "linear", "g0": 0.0, "gx": 0.004, "gy": 0.0}))
    res = pq.solve(sc, accuracy=1e-8)
    cold = pq.solve(sc, accuracy=1e-8, options={"predict": False})
    assert res.kkt.ok and cold.kkt.ok
    assert res.extras["predicted"]["mesh"] == [16, 16]
    assert res.extras["factorisations"] < cold.extras["factorisations"]
    np.testing.assert_allclose(res.reactions, cold.reactions, rtol=0, atol=1e-7 * np.abs(cold.reactions).max())
