"""Scene families (plateqp.scenes.families): physics of each family, supports on nodes, the auto rule.

The checks are statics and contact physics computed here from the answer's fields, not the
solver's own report: total load by hand (q·a² + P), wall reactions from the full stiffness
(K_full u − f_full at the prescribed dofs), force and moment balance, R ≥ 0, gap ≥ 0 and
R·gap = 0 from the deflection interpolated at each support.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.scenes import families as F
from plateqp.model.assembly import build_model
TOTAL = F.Q * F.A * F.A + F.P  # kN: 10 kN/m² on 8 m × 8 m plus the 300 kN column
MOMENT_X = F.Q * F.A * F.A * F.A / 2 + F.P * F.PX  # Σ load · x about the y axis
MOMENT_Y = F.Q * F.A * F.A * F.A / 2 + F.P * F.PY


def solve(scene, backend="lemke", formulation="condensed", accuracy="high"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene, backend=backend, formulation=formulation, accuracy=accuracy)


def wall_reactions(res):
    """Upward forces of the two-sided supports at their w-dofs, and their positions (x, y)."""
    m = res.model
    nd = m.element.ndof_node
    e = m.K_full @ res.u - m.f_full  # = −(wall reaction) at prescribed dofs, 0 at free ones
    fixed_w = m.fixed[m.fixed % nd == 0]
    xy = m.grid.node_xy()[fixed_w // nd]
    return -e[fixed_w], xy


def support_xy(res):
    return res.model.contacts.xy


CASES = [("grid_rigid", 8, 5), ("grid_rigid", 16, 7), ("grid_elastic", 8, 7), ("grid_elastic", 16, 5),
         ("floating", 8, 5), ("floating", 16, 9), ("bed", 8, None), ("bed", 16, None)]


@pytest.mark.parametrize("name,n,k", CASES)
def test_global_equilibrium(name, n, k):
    """Σ reactions (one-sided + walls) = total load, and the moments of both balance."""
    sc = F.family(name, n, k)
    res = solve(sc)
    assert res.status == pq.Status.OPTIMAL
    total = TOTAL if name != "bed" else F.P
    mx = MOMENT_X if name != "bed" else F.P * F.PX
    my = MOMENT_Y if name != "bed" else F.P * F.PY
    xy = support_xy(res)
    R = res.reactions
    Rw, wxy = wall_reactions(res)
    assert abs(R.sum() + Rw.sum() - total) <= 1e-8 * total
    assert abs(R @ xy[:, 0] + Rw @ wxy[:, 0] - mx) <= 1e-8 * mx
    assert abs(R @ xy[:, 1] + Rw @ wxy[:, 1] - my) <= 1e-8 * my
    if name in ("floating", "bed"):
        assert Rw.size == 0  # nothing but the one-sided supports holds the plate


@pytest.mark.parametrize("name,n,k", CASES)
def test_contact_conditions_from_the_field(name, n, k):
    """R ≥ 0, gap ≥ 0, R·gap = 0 with gap = g0 + R/c − w(x_i, y_i) from the interpolated field."""
    sc = F.family(name, n, k)
    res = solve(sc)
    xy = support_xy(res)
    w = res.deflection(xy[:, 0], xy[:, 1])
    rho = res.model.contacts.rho
    gap = res.model.contacts.g0 + rho * res.reactions - w
    R = res.reactions
    wscale = np.abs(w).max()
    assert R.min() >= -1e-9 * R.max()
    assert gap.min() >= -1e-9 * wscale
    assert np.abs(R * gap).max() <= 1e-9 * R.max() * wscale
    lifted = gap > 1e-6 * wscale
    assert lifted.any() and (~lifted).any(), "a real contact problem: some lift off, some carry"


def test_two_exact_solvers_agree():
    """Lemke on the condensed LCP and PDAS on the sparse primal: the benchmark's reference pair."""
    for name, k in (("grid_rigid", 7), ("grid_elastic", 7), ("floating", 5), ("bed", None)):
        sc = F.family(name, 16, k)
        a = solve(sc, "lemke", "condensed")
        b = solve(sc, "pdas", "primal")
        scale = np.abs(a.reactions).max()
        np.testing.assert_allclose(b.reactions, a.reactions, rtol=0, atol=1e-9 * scale)


def test_floating_plate_is_held_only_by_its_posts_and_lifts_off():
    sc = F.floating(16, 5)
    model = build_model(sc)
    assert model.rigid_modes().shape[1] == 3  # free slab: translation and two rotations
    res = solve(sc, "pdas", "primal")
    assert res.status == pq.Status.OPTIMAL
    assert (~res.active).sum() >= 2 and res.active.sum() >= 3
    np.testing.assert_allclose(res.reactions.sum(), TOTAL, rtol=1e-10)


def test_bed_lifts_off_away_from_the_load():
    sc = F.bed(16)
    res = solve(sc, "pdas", "primal")
    xy = support_xy(res)
    d = np.hypot(xy[:, 0] - F.PX, xy[:, 1] - F.PY)
    w = res.deflection(xy[:, 0], xy[:, 1])
    assert res.active[np.argmin(d)] and w[np.argmin(d)] > 0  # pressed in under the column
    far = d > 4.0
    assert (~res.active[far]).all() and (w[far] < 0).all()  # the far part rises off the bed
    assert 0.1 < res.active.mean() < 0.9
    np.testing.assert_allclose(res.reactions.sum(), F.P, rtol=1e-10)


@pytest.mark.parametrize("n", [8, 16, 32, 64, 128, 256])
@pytest.mark.parametrize("name", ["grid_rigid", "floating"])
def test_supports_sit_on_nodes(name, n):
    """For every n and a range of k (and "all"), every support is a mesh node, and k² of them."""
    from plateqp.model.grid import Grid

    kmax = n - 1 if name != "floating" else n + 1
    ks = sorted({3, 5, 7, min(15, kmax), min(17, kmax), kmax} - {1})
    for k in [*ks, "all"]:
        xs = F.positions(n, k, interior=name != "floating")
        kk = kmax if k == "all" else k
        assert len(xs) == kk and len(np.unique(xs)) == kk
        h = F.A / n
        np.testing.assert_allclose(xs / h, np.round(xs / h), atol=1e-12)  # on a node
        assert xs.min() >= (h if name != "floating" else 0.0) and xs.max() <= F.A - (h if name != "floating" else 0.0)
        if n <= 32 or k == 7:  # build only the cheap ones
            sc = F.family(name, n, k)
            grid = Grid.from_scene(sc)
            assert len(sc.supports) == kk**2
            assert all(grid.node_at(s.x, s.y) is not None for s in sc.supports)
            assert F.n_contacts(name, n, k) == kk**2


def test_even_spacing_when_the_grid_divides_the_mesh():
    np.testing.assert_allclose(np.diff(F.positions(32, 7, interior=True)), 1.0)
    np.testing.assert_allclose(np.diff(F.positions(32, 17, interior=False)), 0.5)
    assert F.n_contacts("bed", 16) == 17**2 == len(build_model(F.bed(16)).contacts.g0)


def test_gaps_are_mixed():
    g = np.array([s.gap for s in F.grid_rigid(32, 7).supports])
    assert (g < 0).any() and (g == 0).any() and (g > 0).any()
    assert g.min() >= -F.GAP and g.max() <= F.GAP
    assert F.gap_pattern(0.0, 0.0) == -F.GAP and F.gap_pattern(F.A, F.A) == F.GAP
    assert F.gap_pattern(F.A / 2, F.A / 2) == 0.0
    assert all(s.stiffness == F.PILE_STIFFNESS for s in F.grid_elastic(16, 3).supports)


def test_bad_arguments():
    with pytest.raises(ValueError, match="distinct nodes"):
        F.grid_rigid(8, 8)  # 8 interior posts per row on 7 interior nodes
    with pytest.raises(ValueError, match="distinct nodes"):
        F.floating(8, 10)
    with pytest.raises(ValueError, match="unknown family"):
        F.family("nonesuch", 8)
    with pytest.raises(TypeError, match="integer"):
        F.grid_rigid(8, 2.5)
    with pytest.raises(ValueError, match=">= 2"):
        F.bed(1)
    assert set(F.FAMILIES) == {"grid_rigid", "grid_elastic", "floating", "bed"}
    assert F.family("bed", 8).foundation is not None
    assert len(F.family("grid_rigid", 8, "all").supports) == 49


# -- formulation="auto" / backend="auto" (plateqp.contact._choose), measured in bench_scaling ------

def choice(scene, backend="auto", formulation="auto"):
    from plateqp.contact import choose as _choose
    from plateqp.contact import Scaled

    return _choose(Scaled.from_model(build_model(scene)), backend, formulation)


@pytest.mark.parametrize("scene,backend,expected", [
    # backend="auto" on a single solve: PDAS on the sparse primal, a floating plate too
    # (repeated solves: see test_auto_rule_for_repeated_solves)
    (lambda: F.floating(16, 5), "auto", ("pdas", "primal")),  # m = 25
    (lambda: F.grid_rigid(16, 7), "auto", ("pdas", "primal")),  # m = 49
    (lambda: F.grid_rigid(64, 9), "auto", ("pdas", "primal")),  # m = 81
    (lambda: F.grid_rigid(32, 15), "auto", ("pdas", "primal")),  # m = 225
    (lambda: F.bed(16), "auto", ("pdas", "primal")),  # m = 289, every node
    # a named QP backend: condensed while m ≤ 10 % of the free dofs (and ≤ 1000)
    (lambda: F.grid_rigid(32, 15), "osqp", ("osqp", "condensed")),  # m = 225 ≤ 300.7
    (lambda: F.grid_rigid(32, "all"), "osqp", ("osqp", "primal")),  # m = 961 > 300.7
    (lambda: F.grid_rigid(64, 30), "clarabel", ("clarabel", "condensed")),  # m = 900 ≤ 1000 < 1216
    (lambda: F.grid_rigid(64, "all"), "clarabel", ("clarabel", "primal")),  # m = 3969 > 1000
    # a backend that takes one kind only gets it, whatever m
    (lambda: F.grid_rigid(32, "all"), "lemke", ("lemke", "condensed")),  # m = 961
    (lambda: F.grid_rigid(16, 3), "pdas", ("pdas", "primal")),  # m = 9
])
def test_auto_rule(scene, backend, expected):
    if backend != "auto" and backend not in pq.available_backends():
        pytest.skip(f"{backend} not installed")
    assert choice(scene(), backend) == expected


def test_auto_rule_for_repeated_solves():
    """Solves that share K and B (a sweep): the condensed route while m ≤ 100."""
    from plateqp.contact.routing import repeated_solves

    with repeated_solves():
        assert choice(F.grid_rigid(16, 7)) == ("bpp", "condensed")  # m = 49
        assert choice(F.grid_rigid(64, 9)) == ("bpp", "condensed")  # m = 81
        assert choice(F.grid_rigid(32, 15)) == ("pdas", "primal")  # m = 225
    assert choice(F.grid_rigid(16, 7)) == ("pdas", "primal")


def test_auto_backend_for_an_explicit_formulation():
    sc = F.grid_rigid(16, 7)
    assert choice(sc, "auto", "condensed") == ("bpp", "condensed")
    assert choice(sc, "auto", "dual") == ("bpp", "dual")
    assert choice(sc, "auto", "primal") == ("pdas", "primal")


def test_auto_end_to_end_agrees_with_an_exact_solver():
    """pq.solve with both "auto" reports what it chose, and the answer is Lemke's."""
    for sc in (F.grid_rigid(16, 7), F.grid_rigid(16, 15), F.floating(16, 5)):  # m = 49, 225, 25
        res = solve(sc, backend="auto", formulation="auto", accuracy="high")
        ref = solve(sc, "lemke", "condensed")
        assert res.status == pq.Status.OPTIMAL
        assert (res.backend, res.formulation) == ("pdas", "primal")
        np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())
