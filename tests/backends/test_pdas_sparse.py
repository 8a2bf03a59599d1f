"""pdas's sparse method on many contacts (no cliff): a post on every node, and a bed.

References, none of them pdas's own earlier output:

* an independent algorithm on another formulation: Lemke's method on the condensed LCP;
* statics by hand: the total load (q·a² + P) against the posts' reactions plus the walls'
  (``K_full u − f_full`` at the prescribed w-dofs), and the moments about both axes;
* contact physics from the deflection interpolated at each support: R ≥ 0, gap ≥ 0, R·gap = 0.

And the path: with stiff rows on a held plate and no warm start, the sparse method finds the
contact set by projected Newton on the dual energy (``extras["first_phase"] == "dual"``), and
the exact steps after it only confirm that set and exchange a few rows.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.sparse as sp

import plateqp as pq
from plateqp.scenes import families as F
from plateqp.backends.pdas import factor as pdas_factor
from plateqp.backends.pdas import sparse as pdas_sparse
from plateqp.errors import ProblemError

TOTAL = F.Q * F.A * F.A + F.P  # kN: 10 kN/m² on 8 m × 8 m plus the 300 kN column
MOMENT_X = F.Q * F.A**3 / 2 + F.P * F.PX  # Σ load · x
MOMENT_Y = F.Q * F.A**3 / 2 + F.P * F.PY
SPARSE = {"method": "sparse"}


def solve(scene, backend="pdas", formulation="primal", accuracy=1e-10, options=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene, backend=backend, formulation=formulation, accuracy=accuracy, options=options)


def support_xy(res):
    return res.model.contacts.xy


def wall_reactions(res):
    """Upward forces of the walls at their w-dofs, and where (from the full stiffness)."""
    m = res.model
    nd = m.element.ndof_node
    e = m.K_full @ res.u - m.f_full  # −(wall reaction) at prescribed dofs
    fixed_w = m.fixed[m.fixed % nd == 0]
    return -e[fixed_w], m.grid.node_xy()[fixed_w // nd]


def assert_contact_physics(res, gap0):
    xy = support_xy(res)
    w = res.deflection(xy[:, 0], xy[:, 1])
    gap = gap0 - w
    R = res.reactions
    scale_R, scale_g = np.abs(R).max(), np.abs(gap0).max() + np.abs(w).max()
    assert R.min() >= -1e-10 * scale_R
    assert gap.min() >= -1e-9 * scale_g
    assert np.abs(R * gap).max() <= 1e-9 * scale_R * scale_g


#: Lawson–Hanson's first phase gives up after LH_TIME factorisations' time, measured: tests that
#: expect it to finish lift the limit (a loaded machine must not change the path they check).
NO_LH_LIMIT = 1e9


@pytest.fixture(scope="module")
def every_node_16():
    """A post on every interior node of a 16² slab: pdas's sparse method and Lemke."""
    sc = F.grid_rigid(16, "all")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(pdas_sparse, "LH_TIME", NO_LH_LIMIT)
        res = solve(sc, options=SPARSE)
    return sc, res, solve(sc, "lemke", "condensed", "high")


def test_every_node_a_post_agrees_with_lemke_on_the_condensed_lcp(every_node_16):
    sc, res, ref = every_node_16
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert ref.status == pq.Status.OPTIMAL
    scale = np.abs(ref.reactions).max()
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * scale)
    assert (res.active == ref.active).all()
    assert 0.05 < res.active.mean() < 0.9  # mixed gaps: many posts but not all carry load


def test_every_node_a_post_takes_the_lawson_hanson_first_phase(every_node_16):
    """The flexibility's rows are computed only for the rows the method frees: about as many
    as end in contact, far fewer than the 225 rows; the exact steps confirm its set."""
    _, res, _ = every_node_16
    ex = res.extras
    assert ex["method"] == "sparse" and ex["first_phase"] == "lawson-hanson"
    in_contact = int(res.active.sum())
    assert in_contact <= ex["lh_columns"] < 0.6 * res.active.size
    assert ex["first_phase_steps"] >= in_contact
    assert res.iterations - ex["first_phase_steps"] <= 2  # one exact step (two if it exchanges)


def test_every_node_a_post_takes_the_dual_first_phase_without_lawson_hanson(every_node_16):
    sc, _, ref = every_node_16
    res = solve(sc, options={**SPARSE, "lh_start": False})
    ex = res.extras
    assert ex["method"] == "sparse" and ex["first_phase"] == "dual" and "lh_columns" not in ex
    assert ex["first_phase_steps"] >= 2
    assert res.iterations - ex["first_phase_steps"] <= 4  # the exact steps confirm a near set
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())


def test_lawson_hanson_giving_up_hands_its_reactions_to_the_dual_phase(every_node_16, monkeypatch):
    """No time at all for Lawson–Hanson: it gives up at its first row; the projected Newton
    phase starts from the reactions it reached and the answer is still Lemke's."""
    sc, _, ref = every_node_16
    monkeypatch.setattr(pdas_sparse, "LH_TIME", 0.0)
    res = solve(sc, options={**SPARSE, "trace": True})
    ex = res.extras
    assert res.status == pq.Status.OPTIMAL and ex["first_phase"] == "dual"
    lh = [s for s in ex["trace"] if s["step"] == "lawson-hanson"]
    assert len(lh) == 1 and lh[0]["gave_up"] == "time" and ex["lh_gave_up"] == "time"
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())


def test_lawson_hanson_keeps_its_rows_within_memory(every_node_16, monkeypatch):
    """The rows of M it would keep may take LH_MEMORY bytes per dof: with 16 rows' worth allowed
    it gives up before the 9th row (its buffer doubles) and projected Newton finishes."""
    sc, _, ref = every_node_16
    m, n = ref.active.size, len(ref.model.free)
    monkeypatch.setattr(pdas_sparse, "LH_TIME", NO_LH_LIMIT)
    monkeypatch.setattr(pdas_sparse, "LH_MEMORY", 16 * m * 8 / n)
    res = solve(sc, options=SPARSE)
    ex = res.extras
    assert res.status == pq.Status.OPTIMAL and ex["first_phase"] == "dual" and ex["lh_gave_up"] == "memory"
    assert ex["lh_columns"] <= 8 * pdas_sparse.LH_BLOCK
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())


def test_dual_phase_from_lawson_hanson_reactions_reaches_the_same_answer(every_node_16):
    """Lawson–Hanson stopped after 40 rows (its function gives None): the reactions it reached
    are feasible; the projected Newton phase from them ends at a set from which the exact steps
    give Lemke's answer, in fewer steps than from zero."""
    from plateqp.model.assembly import build_model
    from plateqp.backends.pdas.dense import first_set
    from plateqp.backends.pdas.reduced import ReducedQP
    from plateqp.contact.formulations import formulate
    from plateqp.contact.scaling import Scaled

    sc, _, ref = every_node_16
    pb = ReducedQP(formulate(Scaled.from_model(build_model(sc)), "primal").qp, 10**6)
    sigma = 1e-12
    W = 1.0 / (pb.rho + 1.0 / (1e8 * pb.k))
    kfac = pdas_factor.SpringFactor(pb.K, pb.B, pb.Kd, pb.c, sigma, "auto")
    uf = pdas_sparse.held_plate(pb, kfac, sigma)
    assert uf is not None
    cols = pdas_sparse._Columns(pb, kfac, np.inf)
    asked = []

    def forty(j, force):
        asked.append(j)
        return cols(j, force) if len(asked) <= 40 else None

    out: dict = {}
    A, _ = first_set(forty, pb.g - pb.B @ uf, pb.c, 1e-11, 1e-12 * np.abs(pb.f).sum(), np.inf, out)
    lam0 = out["lam"]
    assert A is None and lam0.min() >= 0 and (lam0 > 0).sum() >= 20
    steps = {}
    for name, start in (("zero", None), ("lh", lam0)):
        fac = pdas_factor.SpringFactor(pb.K, pb.B, pb.Kd, pb.c, sigma, "auto")
        _, _, A, steps[name] = pdas_sparse.dual_newton(pb, fac, kfac, W, sigma, 1e-11, None, uf, start)
        res = solve(sc, options={**SPARSE, "active": A})
        assert res.status == pq.Status.OPTIMAL and res.iterations <= 4
        np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())
    assert steps["lh"] < steps["zero"], steps


@pytest.mark.parametrize("stiffness", [1e7, 1e8])
def test_stiff_elastic_posts_lawson_hanson_on_their_flexibility(stiffness, monkeypatch):
    """Elastic posts stiffer than the plate under them (ρ k < 1): the rows of M carry the
    posts' flexibility ρ on their diagonal; the first set is the final one (one exact step)
    and the reactions are Lemke's on the condensed LCP."""
    import dataclasses

    monkeypatch.setattr(pdas_sparse, "LH_TIME", NO_LH_LIMIT)
    base = F.grid_rigid(16, "all")
    sc = dataclasses.replace(base, supports=F._grid_supports(16, "all", stiffness, interior=True))
    res = solve(sc, options=SPARSE)
    ref = solve(sc, "lemke", "condensed", "high")
    assert res.status == pq.Status.OPTIMAL and res.extras["first_phase"] == "lawson-hanson"
    assert res.iterations - res.extras["first_phase_steps"] == 1
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())


def test_lawson_hanson_gives_up_on_a_broad_contact(monkeypatch):
    """A stiff bed on a simply supported plate, 287 of 361 springs in contact at the end: with
    LH_PROBE rows freed most rows are still pressed, so Lawson–Hanson (one row a step) gives up
    there, having computed one row a solve; the projected Newton phase finishes, and the
    reactions are Lemke's."""
    monkeypatch.setattr(pdas_sparse, "LH_TIME", NO_LH_LIMIT)
    walls = {e: "simple" for e in ("left", "right", "bottom", "top")}
    sc = pq.Scene(name="stiff bed", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(20, 20, "acm"),
                  edges=walls, loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                  foundation=pq.Foundation(1e9, gap={"profile": "linear", "g0": -1e-6, "gx": 1e-5, "gy": 0.5e-5}))
    res = solve(sc, options=SPARSE)
    ref = solve(sc, "lemke", "condensed", "high")
    ex = res.extras
    assert res.status == pq.Status.OPTIMAL and ex["first_phase"] == "dual" and ex["lh_gave_up"] == "pressed"
    assert ex["lh_columns"] == pdas_sparse.LH_PROBE
    assert res.active.sum() > 0.5 * res.active.size
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())


def test_every_node_a_post_statics_24(monkeypatch):
    """24²: 529 posts, walls on four sides; force and moment balance by hand, contact physics."""
    monkeypatch.setattr(pdas_sparse, "LH_TIME", NO_LH_LIMIT)
    sc = F.grid_rigid(24, "all")
    res = solve(sc, options=SPARSE)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok and res.extras["first_phase"] == "lawson-hanson"
    Rw, xyw = wall_reactions(res)
    xy = support_xy(res)
    R = res.reactions
    np.testing.assert_allclose(R.sum() + Rw.sum(), TOTAL, rtol=1e-9)
    np.testing.assert_allclose(R @ xy[:, 0] + Rw @ xyw[:, 0], MOMENT_X, rtol=1e-9)
    np.testing.assert_allclose(R @ xy[:, 1] + Rw @ xyw[:, 1], MOMENT_Y, rtol=1e-9)
    assert R.sum() > 0.3 * TOTAL  # the posts carry a real share, not only the walls
    assert_contact_physics(res, np.array([s.gap for s in sc.supports]))


def test_monotone_steps_alone_reach_the_same_answer(every_node_16, monkeypatch):
    """No full steps allowed (every step searched back until ψ falls): the globalised
    branch alone finds the set; the answer is Lemke's."""
    sc, _, ref = every_node_16
    monkeypatch.setattr(pdas_sparse, "DUAL_RISES", -1)
    res = solve(sc, options={**SPARSE, "trace": True, "lh_start": False})
    assert res.status == pq.Status.OPTIMAL and res.extras["first_phase"] == "dual"
    alphas = [s["alpha"] for s in res.extras["trace"] if str(s["step"]).startswith("dual") and "alpha" in s]
    assert alphas and min(alphas) < 1.0  # the arc was searched back
    energies = [s["energy"] for s in res.extras["trace"] if "energy" in s]
    assert all(b <= a + 1e-10 * abs(a) for a, b in zip(energies, energies[1:]))  # ψ never rises
    scale = np.abs(ref.reactions).max()
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * scale)


def test_plain_pdas_without_the_dual_start_agrees(every_node_16, monkeypatch):
    monkeypatch.setattr(pdas_sparse, "LH_TIME", NO_LH_LIMIT)
    sc, _, ref = every_node_16
    res = solve(sc, options={**SPARSE, "dual_start": False, "lh_start": False})
    assert res.extras["first_phase"] == "none"
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())
    res = solve(sc, options={**SPARSE, "dual_start": False})  # Lawson–Hanson alone
    assert res.extras["first_phase"] == "lawson-hanson"
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())
    for key in ("dual_start", "lh_start"):
        with pytest.raises(ProblemError, match=key):
            solve(sc, options={**SPARSE, key: "yes"})


def test_floating_plate_skips_the_dual_phase():
    """K singular (no walls): the dual energy needs K⁻¹, so that phase declines; Lawson–Hanson
    runs on the anchored plate's flexibility instead (tests/backends/test_pdas_floating.py), or, with
    ``anchor_start=False``, no first phase runs. Either answer carries the whole load by statics."""
    for options, phase in ((SPARSE, "anchored lawson-hanson"), ({**SPARSE, "anchor_start": False}, "none")):
        res = solve(F.floating(16, 9), options=options)
        assert res.status == pq.Status.OPTIMAL and res.extras["first_phase"] == phase
        np.testing.assert_allclose(res.reactions.sum(), TOTAL, rtol=1e-9)


def test_bed_24_statics_and_contact_physics():
    """Free slab on a tensionless bed (625 one-sided springs): the springs carry the column."""
    sc = F.bed(24)
    res = solve(sc, options=SPARSE)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok and res.extras["first_phase"] == "newton"
    np.testing.assert_allclose(res.reactions.sum(), F.P, rtol=1e-9)
    xy = support_xy(res)
    np.testing.assert_allclose(res.reactions @ xy[:, 0], F.P * F.PX, rtol=1e-9)
    np.testing.assert_allclose(res.reactions @ xy[:, 1], F.P * F.PY, rtol=1e-9)
    assert 0.05 < res.active.mean() < 0.95
    assert res.reactions.min() >= -1e-10 * res.reactions.max()


# ----------------------------------------------------------------- the factor's low-rank corrections


@pytest.fixture(scope="module")
def bed_8_matrices():
    from plateqp.model.assembly import build_model
    m = build_model(F.bed(8))
    K = m.K.tocsc()
    return K, m.contacts.B.tocsr(), K.diagonal().copy()


def _h_inverse(K, B, Kd, w, sigma, b):
    """An independent reference: SciPy's sparse LU of ``K + σ diag(K) + Bᵀ diag(w) B``."""
    import scipy.sparse.linalg as spla

    H = sp.csc_matrix(K + sp.diags(sigma * Kd) + B.T @ sp.diags(w) @ B)
    return spla.spsolve(H, b)


@pytest.mark.parametrize("method", ["cvxopt", "linalg"])
@pytest.mark.parametrize("rows", ["within", "across"])
def test_the_factor_solves_h_whether_the_rows_lie_in_k_pattern_or_not(bed_8_matrices, method, rows):
    """The matrix the factor is built on, against SciPy's LU of ``H(w)``: bed rows (each within
    one element: built on K's triangle alone) and rows that couple dofs K does not (K's
    pattern plus ``|B|ᵀ|B|``)."""
    from plateqp.linalg import bindings

    if method == "cvxopt" and "cvxopt" not in bindings():
        pytest.skip("cvxopt's CHOLMOD is not installed")
    K, B, Kd = bed_8_matrices
    n = K.shape[0]
    if rows == "across":  # and ten rows each on two dofs at opposite ends of the plate
        i = np.arange(10)
        B = sp.vstack([B, sp.csr_matrix((np.tile([1.0, -0.5], 10), (np.repeat(i, 2), np.column_stack(
            [i, n - 1 - i]).ravel())), shape=(10, n))], format="csr")
    m, sigma = B.shape[0], 1e-12
    rng = np.random.default_rng(5)
    w = rng.uniform(0.5, 2.0, m) * Kd.max()
    w[::7] = 0.0  # some rows off (the bed's others hold the plate)
    fac = pdas_factor.SpringFactor(K, B, Kd, np.full(m, Kd.max()), sigma, method)
    assert (fac.pattern_nnz == K.nnz) == (rows == "within")
    fac.set(w)
    b = rng.standard_normal(n)
    ref = _h_inverse(K, B, Kd, w, sigma, b)
    np.testing.assert_allclose(fac.solve(b), ref, rtol=0, atol=1e-10 * np.abs(ref).max())


@pytest.mark.parametrize("method", ["cvxopt", "linalg"])
def test_a_twin_factor_shares_the_pattern_and_solves_its_own_matrix(bed_8_matrices, method):
    """The sparse method's factor of K alone is a twin of its active-set factor: the pattern
    arrays are the same objects (built once), each factor solves its own H(w) (SciPy's LU)."""
    from plateqp.linalg import bindings

    if method == "cvxopt" and "cvxopt" not in bindings():
        pytest.skip("cvxopt's CHOLMOD is not installed")
    K, B, Kd = bed_8_matrices
    m, sigma = B.shape[0], 1e-12
    fac = pdas_factor.SpringFactor(K, B, Kd, np.full(m, Kd.max()), sigma, method)
    twin = fac.twin()
    assert twin.base is fac.base and twin.pair_pos is fac.pair_pos and twin.chol is not fac.chol or fac.chol is None
    rng = np.random.default_rng(7)
    w = rng.uniform(0.5, 2.0, m) * Kd.max()
    w2 = rng.uniform(0.1, 0.3, m) * Kd.max()  # other springs (K alone is singular: a free plate)
    fac.set(w)
    twin.set(w2)
    b = rng.standard_normal(K.shape[0])
    for f, ww in ((fac, w), (twin, w2), (fac, w)):
        ref = _h_inverse(K, B, Kd, ww, sigma, b)
        np.testing.assert_allclose(f.solve(b), ref, rtol=0, atol=1e-10 * np.abs(ref).max())
    assert fac.stats["factorisations"] == 1 and twin.stats["factorisations"] == 1


@pytest.mark.parametrize("method", ["cvxopt", "linalg"])
def test_a_few_changed_rows_solve_by_woodbury_on_the_factor_in_hand(bed_8_matrices, method, monkeypatch):
    from plateqp.linalg import bindings

    # on an 8² plate a factorisation costs a few solves: the cost rule alone would refactorise
    monkeypatch.setattr(pdas_factor, "LOWRANK_COST", 1e9)
    if method == "cvxopt" and "cvxopt" not in bindings():
        pytest.skip("cvxopt's CHOLMOD is not installed")
    K, B, Kd = bed_8_matrices
    m, sigma = B.shape[0], 1e-12
    rng = np.random.default_rng(3)
    w0 = rng.uniform(0.5, 2.0, m) * Kd.max()
    fac = pdas_factor.SpringFactor(K, B, Kd, np.full(m, Kd.max()), sigma, method)
    fac.set(w0)
    b = rng.standard_normal(K.shape[0])
    fac.solve(b)  # a measured solve time for the cost rule
    w1 = w0.copy()
    w1[[3, 17, 40]] = 0.0  # three springs leave
    w1[[5, 6]] *= 3.0  # two get stiffer
    fac.set(w1)
    assert fac.stats["factorisations"] == 1 and fac.stats["lowrank"] == 1 and not fac.clean
    ref = _h_inverse(K, B, Kd, w1, sigma, b)
    x = fac.solve(b)
    np.testing.assert_allclose(x, ref, rtol=0, atol=1e-9 * np.abs(ref).max())
    H1 = K + sp.diags(sigma * Kd) + B.T @ sp.diags(w1) @ B  # backward error at rounding
    assert np.abs(H1 @ x - b).max() <= 1e-12 * np.abs(b).max()
    # back to the factor's own w: the correction is dropped, the factor solves as it is
    fac.set(w0)
    assert fac.clean and fac.stats["factorisations"] == 1
    ref0 = _h_inverse(K, B, Kd, w0, sigma, b)
    np.testing.assert_allclose(fac.solve(b), ref0, rtol=0, atol=1e-9 * np.abs(ref0).max())
    # too many rows for a correction: a factorisation
    w2 = w0.copy()
    w2[: pdas_factor.LOWRANK_MAX + 1] = 0.0
    fac.set(w2)
    assert fac.stats["factorisations"] == 2 and fac.clean


def test_a_rigid_row_entering_or_leaving_refactorises(bed_8_matrices, monkeypatch):
    """A penalty row κ = 1e8 times stiffer than its dofs: Woodbury would lose ~8 digits (leaving:
    cancellation in the capacitance, as a downdate; entering: B x carries an error ε|x| that
    the row's weight multiplies into the residual). The factor is rebuilt instead, and its
    solve's backward error stays at rounding."""
    monkeypatch.setattr(pdas_factor, "LOWRANK_COST", 1e9)
    K, B, Kd = bed_8_matrices
    m, sigma = B.shape[0], 1e-12
    c = np.full(m, Kd.max())
    w0 = np.full(m, 1e8 * Kd.max())
    w0[::2] = 0.0
    fac = pdas_factor.SpringFactor(K, B, Kd, c, sigma, "linalg")
    fac.set(w0)
    b = np.ones(K.shape[0])
    for row, n_fac in ((1, 2), (2, 3)):  # row 1 leaves, then row 2 enters
        w = fac.w.copy()
        w[row] = 1e8 * Kd.max() - w[row]
        fac.set(w)
        assert fac.stats["factorisations"] == n_fac and fac.stats["lowrank"] == 0 and fac.clean
        H = K + sp.diags(sigma * Kd) + B.T @ sp.diags(w) @ B
        x = fac.solve(b)
        assert np.abs(H @ x - b).max() <= 1e-9 * np.abs(b).max()
