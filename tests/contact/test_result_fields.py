"""Every field a contact result reports, against a computation of its own.

The KKT report's residuals are recomputed here from their definitions (the table in
:mod:`plateqp.contact.kkt`), written out support by support, on answers whose errors are
known in closed form: an exact answer (Lemke on the condensed LCP), and that answer with one
reaction made negative, one reaction put at an open support, one spring compressed, one support
penetrated, one reaction moved without its deflections. Each perturbation is far above the
rounding floor, so a field compared at rtol 1e-9 is the formula's value and not noise; at the
exact answer the fields are compared with a margin of the problem's own rounding floor.

The result's other fields are checked the same way: gaps, compressions (R = c s), the contact
set, the residual, the largest deflection and the probes from the dof vector, the reactions by
statics, the iteration count from Lemke's own pivot trace, the times by how they tile the solve,
and the JSON of ``plateqp solve --json`` (:meth:`Result.to_dict`) against the result it prints.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.sparse.linalg as spla

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.backends import get_backend
from plateqp.contact import Scaled
from plateqp.contact.formulations import ContactSolution, formulate
from plateqp.contact.kkt import kkt_report
from plateqp.scenes.families import family

EPS = np.finfo(float).eps
TOL = 1e-6  # the accuracy the reports below are asked at: its floor term in δ is then negligible


def exact(name: str):
    """The scaled data of a 16² family scene on 5×5 supports and its exact contact solution."""
    d = Scaled.from_model(build_model(family(name, 16, 5)))
    form = formulate(d, "condensed")
    c = form.recover(get_backend("lemke").solve(form.problem(frozenset({"lcp"})), accuracy="high"))
    return d, c


def formulas(d: Scaled, u: np.ndarray, R: np.ndarray, s: np.ndarray, tol: float) -> dict:
    """The KKT report's fields from their definitions, support by support (dense, no shared code)."""
    K, B = d.K.toarray(), d.B.toarray()
    BtR = B.T @ R
    force = max(np.linalg.norm(d.f), np.linalg.norm(BtR))
    st = np.linalg.norm(K @ u - d.f + BtR) / force
    floor = EPS * np.linalg.norm(np.abs(K) @ np.abs(u) + np.abs(d.f) + np.abs(B).T @ np.abs(R)) / force
    w = B @ u
    delta = max(np.abs(w).max(), np.abs(d.g0).max(), np.abs(u[d.is_w]).max())
    delta = max(delta, min(floor / tol, 1.0) * d.w_load)
    st = max(st, (st - 10.0 * floor) * d.w_load / delta)
    # statics along each rigid motion the two-sided supports leave free
    BR = np.abs(B).T @ np.abs(R)
    for j in range(d.modes.shape[1]):
        V = d.modes[:, j]
        size = max(sum(abs(V[i] * d.f[i]) for i in range(d.n)), sum(abs(V[i]) * BR[i] for i in range(d.n)),
                   force * np.abs(V).max())
        st = max(st, abs(sum(V[i] * (d.f[i] - BtR[i]) for i in range(d.n))) / size)
    load = np.abs(d.f).sum()
    rho_R = np.abs(R).max() if np.abs(R).max() > tol * load else load
    gap = [d.g0[i] + s[i] - w[i] for i in range(d.m)]
    return {
        "stationarity": st, "floor": floor, "scale": delta * d.W, "tol": tol,
        "spring": max(abs(s[i] - d.rho[i] * R[i]) for i in range(d.m)) / delta,
        "primal": max([0.0] + [-g for g in gap]) / delta,
        "dual": max([0.0] + [-r for r in R]) / rho_R,
        "complementarity": max(abs(R[i] * gap[i]) for i in range(d.m)) / (rho_R * delta),
    }


def in_equilibrium(d: Scaled, c: ContactSolution, j: int, dR: float) -> ContactSolution:
    """``c`` with reaction j moved by dR and the deflections moved with it (K⁻¹ by SuperLU)."""
    R = c.R.copy()
    R[j] += dR
    u = c.u - spla.splu(d.K.tocsc()).solve(d.B[[j]].T.toarray().ravel() * dR)
    return ContactSolution(u, R, d.rho * R)


RESIDUALS = ("stationarity", "spring", "primal", "dual", "complementarity")


def assert_fields(rep, want: dict, rtol: float = 1e-9):
    """Each field of ``want`` as ``rep`` reports it: to rtol, and a residual also to 100 × the
    rounding floor (two evaluations of a residual at rounding level agree to no more)."""
    for key, value in want.items():
        atol = 100.0 * want["floor"] if key in RESIDUALS else 0.0
        np.testing.assert_allclose(getattr(rep, key), value, rtol=rtol, atol=atol, err_msg=key)
    assert rep.ok == (max(rep.stationarity, rep.spring, rep.primal, rep.dual, rep.complementarity,
                          rep.natural) <= rep.tol)


@pytest.mark.parametrize("name", ["grid_rigid", "grid_elastic"])
def test_exact_answer_reports_its_formulas_to_its_rounding_floor(name):
    d, c = exact(name)
    rep = kkt_report(d, c, TOL)
    assert_fields(rep, formulas(d, c.u, c.R, c.s, TOL))
    assert rep.ok and not rep.at_floor and rep.worst <= TOL


def test_negative_reaction_sets_dual():
    """A reaction of −α max R at an open support: dual = α (ρ_R stays the largest reaction)."""
    d, c = exact("grid_rigid")
    j = int(np.flatnonzero(c.R == 0)[0])
    alpha = 1e-5
    p = in_equilibrium(d, c, j, -alpha * c.R.max())
    rep = kkt_report(d, p, TOL)
    assert_fields(rep, formulas(d, p.u, p.R, p.s, TOL) | {"dual": alpha})
    assert rep.natural >= alpha and not rep.ok


def test_reaction_at_an_open_support_sets_complementarity():
    """A reaction of α max R at an open support j, the deflections left as they were (moved with
    it, the supports in contact would open by its influence and their products R_i·gap_i take
    over): complementarity = α·gap_j / δ, every other product being rounding."""
    d, c = exact("grid_rigid")
    j = int(np.flatnonzero(c.R == 0)[0])
    alpha = 1e-5
    R = c.R.copy()
    R[j] = alpha * c.R.max()
    rep = kkt_report(d, ContactSolution(c.u, R, d.rho * R), TOL)
    want = formulas(d, c.u, R, d.rho * R, TOL)
    gap_j = float(d.g0[j] + d.rho[j] * R[j] - (d.B[[j]] @ c.u)[0])
    assert gap_j > 0  # open
    assert_fields(rep, want | {"complementarity": alpha * gap_j / (want["scale"] / d.W)})
    assert rep.complementarity > 1e3 * want["floor"] and rep.natural >= alpha and not rep.ok


def test_compressed_spring_sets_spring():
    """An elastic support's compression off its R/c by β δ: spring = β."""
    d, c = exact("grid_elastic")
    assert (d.rho > 0).all()
    want = formulas(d, c.u, c.R, c.s, TOL)
    delta = want["scale"] / d.W
    beta = 1e-5
    s = c.s.copy()
    s[int(np.argmax(c.R))] += beta * delta
    rep = kkt_report(d, ContactSolution(c.u, c.R, s), TOL)
    assert_fields(rep, formulas(d, c.u, c.R, s, TOL) | {"spring": beta})


def test_penetrated_support_sets_primal():
    """The plate pushed past an open support's gap by γ δ (its reaction kept 0): primal = γ."""
    d, c = exact("grid_rigid")
    j = int(np.flatnonzero(c.R == 0)[0])
    want = formulas(d, c.u, c.R, c.s, TOL)
    delta = want["scale"] / d.W
    gamma = 1e-4
    gap_j = float(d.g0[j] + c.s[j] - (d.B[[j]] @ c.u)[0])
    g0 = d.g0.copy()
    g0[j] -= gap_j + gamma * delta  # the support moved to γ δ inside the plate
    d.g0 = g0
    rep = kkt_report(d, c, TOL)
    assert_fields(rep, formulas(d, c.u, c.R, c.s, TOL) | {"primal": gamma}, rtol=1e-6)


def test_moved_reaction_sets_stationarity():
    d, c = exact("grid_rigid")
    R = c.R.copy()
    R[int(np.argmax(R))] *= 1.0 + 1e-6
    rep = kkt_report(d, ContactSolution(c.u, R, d.rho * R), TOL)
    want = formulas(d, c.u, R, d.rho * R, TOL)
    assert want["stationarity"] > 1e3 * want["floor"]
    assert_fields(rep, want, rtol=1e-6)


# -- a solved result: every field of plateqp solve --json -------------------------------------

def floating_scene() -> pq.Scene:
    """A free square (no edge held) on four rigid posts at its quarter points and one post far
    below its middle (open), a uniform load and an off-centre point load: whatever the split
    between the posts, their reactions must balance the load's force and its two moments."""
    sups = [pq.Support(x, y) for x in (0.25, 0.75) for y in (0.25, 0.75)]
    sups.append(pq.Support(0.5, 0.5, gap=1.0))  # far below the plate: open
    return pq.Scene(name="floating", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8, "acm"),
                    loads=[pq.UniformLoad(10.0), pq.PointLoad(3.0, 0.625, 0.375)], supports=sups)


@pytest.fixture(scope="module")
def solved():
    return pq.solve(floating_scene(), backend="lemke", formulation="condensed", accuracy="high",
                    options={"trace": True})


def test_reactions_gaps_and_contact_set(solved):
    r, sc = solved, floating_scene()
    assert r.status == pq.Status.OPTIMAL
    P, q = 3.0, 10.0
    xy = np.array([(s.x, s.y) for s in sc.supports])
    # statics: vertical force and the two moments about the origin
    np.testing.assert_allclose(r.reactions.sum(), q + P, rtol=1e-12)
    np.testing.assert_allclose(r.reactions @ xy[:, 0], q * 0.5 + P * 0.625, rtol=1e-12)
    np.testing.assert_allclose(r.reactions @ xy[:, 1], q * 0.5 + P * 0.375, rtol=1e-12)
    assert r.reactions[4] == 0.0
    # gaps: g0 + s − w at each support, w read from the dof vector (the posts sit on nodes)
    w = np.array([r.deflection(x, y) for x, y in xy])
    g0 = np.array([s.gap for s in sc.supports])
    np.testing.assert_allclose(r.gaps, g0 + r.compressions - w, rtol=0, atol=1e-12 * np.abs(g0).max())
    np.testing.assert_allclose(r.gaps[:4], 0.0, atol=1e-9 * np.abs(w).max())
    assert r.active.tolist() == [True] * 4 + [False]


def test_residual_w_max_probes_and_kkt_in_user_units(solved):
    r = solved
    m = r.model
    u = r.u[m.free]
    R = r.reactions
    BtR = m.contacts.B.T @ R
    res = np.linalg.norm(m.K @ u - m.f + BtR) / max(np.linalg.norm(m.f), np.linalg.norm(BtR))
    np.testing.assert_allclose(r.residual, res, rtol=1e-9, atol=1e-15)
    # w_max: the largest |w| over the nodes, w the first of the ACM's three dofs a node
    w = r.u[0::3]
    k = int(np.argmax(np.abs(w)))
    xy = m.grid.node_xy()
    assert r.w_max() == (pytest.approx(w[k], rel=1e-15), pytest.approx(xy[k][0]), pytest.approx(xy[k][1]))
    # a probe at a node is that node's dof
    assert r.to_dict(probes=[tuple(xy[10])])["probes"][0]["w"] == pytest.approx(w[10], rel=1e-12)
    # the KKT report on the user's result, recomputed on its scaled data
    d = Scaled.from_model(m)
    want = formulas(d, u / d.dof_scale, R / d.F0, r.compressions / d.W, 1e-9)
    assert_fields(r.kkt, want, rtol=1e-6)


def test_iterations_are_the_pivots_and_times_tile_the_solve(solved):
    r = solved
    trace = r.extras["trace"]
    assert r.iterations == len(trace) == trace[-1]["step"] > 0
    assert trace[-1]["leaving"] == ("z0", None)
    t = r.times
    parts = [t[k] for k in ("build", "formulate", "predict", "solve", "recover")]
    assert all(np.isfinite(parts)) and min(parts) >= 0.0 and t["solve"] > 0.0
    assert sum(parts) <= t["total"] * (1.0 + 1e-12)  # disjoint parts of the solve's own interval


def test_json_prints_the_result(solved):
    r = solved
    out = json.loads(json.dumps(r.to_dict()))
    assert out["status"] == r.status.value and out["backend"] == "lemke" and out["formulation"] == "condensed"
    assert out["scene"] == "floating" and out["accuracy"] == "high"
    assert out["reactions"] == r.reactions.tolist() and out["gaps"] == r.gaps.tolist()
    assert out["active"] == r.active.tolist() and out["residual"] == r.residual
    assert out["deflection_unique"] is True and out["iterations"] == r.iterations
    assert (out["w_max"], out["w_max_x"], out["w_max_y"]) == r.w_max()
    assert out["times"] == {k: r.times[k] for k in ("build", "solve", "total")}
    kkt = out["kkt"]
    for key in ("stationarity", "spring", "primal", "dual", "complementarity", "natural", "tol", "scale", "floor"):
        assert kkt[key] == getattr(r.kkt, key), key
    assert kkt["ok"] is r.kkt.ok


def test_compressions_are_the_springs_law():
    """Elastic piles: each compression is its reaction over the pile's stiffness (R = c s), zero
    where the pile carries nothing, and the gaps close where the piles act."""
    sc = family("grid_elastic", 16, 5)
    r = pq.solve(sc, backend="lemke", formulation="condensed", accuracy="high")
    c = np.array([s.stiffness for s in sc.supports], dtype=float)
    assert r.status == pq.Status.OPTIMAL and (r.reactions > 0).any() and (r.reactions == 0).any()
    np.testing.assert_allclose(r.compressions, r.reactions / c, rtol=1e-9, atol=1e-12 * np.abs(r.compressions).max())
    on = r.reactions > 0
    assert r.active[on].all()
    np.testing.assert_allclose(r.gaps[on], 0.0, atol=1e-9 * np.abs(r.compressions).max())
