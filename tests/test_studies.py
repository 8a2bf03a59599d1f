"""Studies: scene paths, convergence by mesh halving, sweeps with breakpoints, gap regulation.

Every study result is checked against an independent reference: Timoshenko's series for the
slab, individual ``pq.solve`` calls (fresh model, no warm start) for every sweep row and every
breakpoint, a dense grid of independent solves for "no change was missed", and an independent
contact solve for the regulated gaps.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.assembly import build_model
from plateqp.cli import main
from plateqp.studies import (
    adapt_model,
    convergence,
    get_param,
    most_uniform_stiffness,
    regulate_gaps,
    set_param,
    sweep,
)

SLAB_W = 0.0040624  # Timoshenko: SS square, uniform load, centre w × q a⁴/D
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


# -- scene paths ------------------------------------------------------------------------------

def test_get_and_set_paths():
    sc = fig5()
    assert get_param(sc, "plate.h") == 20.0
    assert get_param(sc, "supports.0.gap") == -0.02
    assert get_param(sc, "supports.*.gap")[:3] == [-0.02, -0.02, 0.0]
    assert get_param(sc, "loads.0.P") == 20000.0
    assert get_param(sc, "edges.left") == "free"  # an edge not named is free

    s2 = set_param(sc, STIFF, 1e4)
    assert get_param(s2, STIFF) == [1e4] * 25 and get_param(sc, STIFF) == ["rigid"] * 25  # a copy
    assert get_param(set_param(s2, "supports.3.stiffness", float("inf")), "supports.3.stiffness") == "rigid"
    assert get_param(set_param(s2, STIFF, "rigid"), STIFF) == ["rigid"] * 25
    nx = get_param(set_param(sc, "mesh.nx", 16.0), "mesh.nx")
    assert nx == 16 and isinstance(nx, int)
    gaps = np.linspace(-0.01, 0.01, 25)
    assert get_param(set_param(sc, "supports.*.gap", gaps), "supports.*.gap") == pytest.approx(gaps)
    s3 = set_param(sc, "edges.left", "clamped")
    assert s3.edges["left"].kind == "clamped" and "left" not in sc.edges
    s4 = pq.Scene(foundation=pq.Foundation(k=100.0), loads=[pq.UniformLoad(q=1.0)])
    assert get_param(set_param(s4, "foundation.k", 50), "foundation.k") == 50


@pytest.mark.parametrize("path, value, words", [
    ("supports.25.gap", 0.0, ["supports.25", "25 supports", "0..24"]),
    ("supports.3.gapp", 0.0, ["supports.3.gapp", "x, y, gap, stiffness"]),
    ("plat.h", 1.0, ["plat", "plate", "mesh", "supports"]),
    ("supports.x.gap", 0.0, ["supports.x", "index", "'*'"]),
    ("foundation.k", 1.0, ["foundation", "no foundation"]),
    ("plate.h.x", 1.0, ["plate.h", "value"]),
    ("supports.3.stiffness", -5.0, ["supports.3.stiffness", "> 0"]),
    ("supports.3.stiffness", "soft", ["supports.3.stiffness", "soft"]),
    ("mesh.nx", 2.5, ["mesh.nx", "integer"]),
    ("edges.middle", "simple", ["edges.middle", "left, right, bottom, top"]),
    ("supports..gap", 0.0, ["bad path"]),
])
def test_bad_paths_and_values_say_what_exists(path, value, words):
    with pytest.raises(pq.SceneError) as exn:
        set_param(fig5(), path, value)
    for w in words:
        assert w in str(exn.value)


# -- convergence by mesh halving ----------------------------------------------------------------

def test_convergence_slab_against_timoshenko():
    sc = pq.Scene(name="slab", plate=pq.Plate(a=1.0, b=1.0, h=0.01, E=2.1e11, nu=0.3), mesh=pq.MeshSpec(8, 8),
                  edges={k: pq.Edge("simple") for k in ("left", "right", "bottom", "top")},
                  loads=[pq.UniformLoad(q=1000.0)])
    tab = convergence(sc, meshes=(2, 4, 8, 16, 32), quantities=("w_max", "w:0.5,0.5"), target=0.01)
    ref = SLAB_W * 1000.0 / sc.plate.D
    w = tab.values["w:0.5,0.5"]
    assert w[-1] == pytest.approx(ref, rel=0.01)  # the finest mesh within 1 %
    np.testing.assert_allclose(tab.values["w_max"], w)  # the maximum is at the centre
    d = tab.diff["w_max"]
    assert np.all(np.diff(d[:-1]) < 0) and np.isnan(d[-1])  # the changes shrink on halving
    assert d[:-1] == pytest.approx(np.abs(np.diff(w)) / np.abs(w[1:]))
    err = np.abs(w - ref)
    assert np.all(np.diff(err) < 0)
    # the paper's finding for deflections: halving 8x8 still changes w by 1.2 %, halving 16x16 by 0.3 %
    assert tab.converged_at["w_max"] == (16, 16)
    assert [r["nx"] for r in tab.rows] == [2, 4, 8, 16, 32] and "w_max diff" in tab.rows[0]
    assert "converged at" in str(tab)


def test_convergence_reactions_on_a_contact_scene():
    sc = fig5()
    sc.loads[0] = pq.PointLoad(P=20000.0, x=200.0, y=200.0)
    tab = convergence(sc, meshes=(4, 8, 16), quantities=("w_max", "reactions.12", "reactions.0"), target=0.01)
    assert all(e is None for e in tab.errors)
    # the paper's finding: reactions converge already on the coarsest meshes
    assert tab.converged_at["reactions.12"] == (4, 4)
    # a lifted support's reaction is zero up to rounding: compared with the largest reaction, not with noise
    assert tab.converged_at["reactions.0"] == (4, 4)


# -- model re-use --------------------------------------------------------------------------------

def test_adapt_model_equals_a_fresh_build():
    sc = pq.Scene(plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(6, 6),
                  edges={"left": pq.Edge("clamped", w=0.001)}, loads=[pq.UniformLoad(q=5.0)],
                  supports=[pq.Support(0.55, 0.4, gap=0.001), pq.Support(1.0, 1.0, stiffness=1e3)],
                  foundation=pq.Foundation(k=100.0, region=[0.5, 1.0, 0.0, 1.0], gap=0.0))
    base = build_model(sc)
    for path, value in (("supports.0.gap", -0.002), ("supports.*.stiffness", 5e3), ("supports.1.stiffness", "rigid"),
                        ("foundation.k", 300.0), ("foundation.gap", 0.002), ("loads.0.q", -1.0)):
        new = set_param(sc, path, value)
        m = adapt_model(base, new)
        ref = build_model(new)
        np.testing.assert_allclose(m.contacts.g0, ref.contacts.g0, rtol=1e-14, atol=1e-16, err_msg=path)
        np.testing.assert_allclose(m.contacts.rho, ref.contacts.rho, rtol=1e-14, err_msg=path)
        np.testing.assert_allclose(m.f, ref.f, rtol=1e-14, atol=1e-14, err_msg=path)
        assert m.scene is new and m.K is base.K
    assert adapt_model(base, set_param(sc, "plate.h", 0.03)) is None  # K changes: rebuild
    assert adapt_model(base, set_param(sc, "supports.0.x", 0.6)) is None  # B changes: rebuild


# -- sweeps ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("path, values", [
    (STIFF, ["rigid", 1e6, 3e4, 1e3, 30.0]),
    ("supports.12.gap", [-0.05, -0.01, 0.0, 0.02]),
    ("loads.0.P", [5000.0, 20000.0, 40000.0]),
    ("plate.h", [15.0, 25.0]),  # changes K: rebuilt for each value
])
def test_sweep_rows_equal_individual_solves(path, values):
    sc = fig5(stiffness=1e4)
    res = sweep(sc, path, values, executor="serial", progress=False, refine_breakpoints=False)
    assert [r["value"] for r in res.rows] == values
    for row, v in zip(res.rows, values):
        ref = solve(set_param(sc, path, v))
        assert row["status"] == "optimal" and row["error"] is None and row["kkt"]["ok"]
        np.testing.assert_allclose(row["reactions"], ref.reactions, rtol=0, atol=1e-9 * ref.reactions.max())
        assert row["active"] == ref.active.tolist()
        assert row["w_max"] == pytest.approx(ref.w_max()[0], rel=1e-9)
        assert row["s1_max"] == pytest.approx(np.nanmax(ref.nodal("s1")), rel=1e-9)
        assert set(ref.to_dict()) | {"value", "s1_max", "kkt_worst", "error"} == set(row)


class _WarmRecorder:
    """A stand-in for a warm-startable backend (bpp/pdas): Lemke underneath, records options."""

    name = "bpp"
    accepts = frozenset({"lcp"})

    def __init__(self):
        self.seen: list = []
        self._lemke = pq.get_backend("lemke")

    def available(self):
        return True

    def version(self):
        return "test"

    def solve(self, problem, accuracy="default", options=None):
        opts = dict(options or {})
        self.seen.append(opts.pop("active", None))
        return self._lemke.solve(problem, accuracy=accuracy, options=opts)


def test_warm_start_only_for_backends_that_take_it(monkeypatch):
    sc = fig5()
    values = ["rigid", 1e5, 1e4, 1e3]
    fake = _WarmRecorder()
    monkeypatch.setitem(pq.registry(), "bpp", fake)
    warm = sweep(sc, STIFF, values, backend="bpp", executor="serial", progress=False, refine_breakpoints=False)
    assert fake.seen[0] is None  # nothing to start from
    for k in range(1, len(values)):  # each value starts from the contact set of the one before
        assert fake.seen[k].tolist() == warm.rows[k - 1]["active"]
    # Lemke takes no warm start: it would reject an unknown option, so this passing says none was sent
    cold = sweep(sc, STIFF, values, backend="lemke", executor="serial", progress=False, refine_breakpoints=False)
    np.testing.assert_allclose(warm.reactions, cold.reactions, rtol=0, atol=1e-9 * cold.reactions.max())


@pytest.mark.parametrize("backend, formulation", [("bpp", "condensed"), ("pdas", "primal")])
def test_warm_started_sweeps_equal_lemke(backend, formulation):
    if backend not in pq.available_backends():
        pytest.skip(f"{backend} is not installed here")
    sc = fig5()
    values = ["rigid", 1e6, 1e5, 3e4, 1e4, 1e3]
    ref = sweep(sc, STIFF, values, backend="lemke", executor="serial", progress=False, refine_breakpoints=False)
    res = sweep(sc, STIFF, values, backend=backend, formulation=formulation, executor="serial", progress=False,
                refine_breakpoints=False)
    assert all(r["status"] == "optimal" for r in res.rows)
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-8 * ref.reactions.max())
    assert res.active == ref.active


def test_warm_start_is_the_backends_own_state_on_the_dual(monkeypatch):
    """bpp's ``active`` is the LCP's z_i = 0: on the dual (z = reactions) that is *not* in
    contact, so the sweep must hand back bpp's own final state, not the contact set."""
    if "bpp" not in pq.available_backends():
        pytest.skip("bpp is not installed here")
    bpp = pq.get_backend("bpp")
    seen = []

    class Spy:
        name, accepts = "bpp", bpp.accepts

        def available(self):
            return True

        def version(self):
            return bpp.version()

        def solve(self, problem, accuracy="default", options=None):
            seen.append((options or {}).get("active"))
            return bpp.solve(problem, accuracy=accuracy, options=options)

    monkeypatch.setitem(pq.registry(), "bpp", Spy())
    sup = [pq.Support(x, y, gap=(-1e-3 if (x, y) == (0.25, 0.25) else 0.0)) for x in (0.25, 0.5, 0.75)
           for y in (0.25, 0.5, 0.75)]
    sc = pq.Scene(plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(8, 8),
                  edges={"left": pq.Edge("simple"), "right": pq.Edge("simple")}, supports=sup,
                  loads=[pq.UniformLoad(q=10.0), pq.PointLoad(P=3.0, x=0.625, y=0.625)])
    values = ["rigid", 1e4, 1e2]
    res = sweep(sc, STIFF, values, backend="bpp", formulation="dual", executor="serial", progress=False,
                refine_breakpoints=False)
    assert not all(res.rows[0]["active"])  # some support lifts off: the complement is not trivial
    assert seen[0] is None and seen[1].tolist() == [not a for a in res.rows[0]["active"]]
    for row, v in zip(res.rows, values):
        ref = solve(set_param(sc, STIFF, v), backend="lemke", formulation="dual")
        np.testing.assert_allclose(row["reactions"], ref.reactions, rtol=0, atol=1e-9 * ref.reactions.max())


WARM = [("bpp", "condensed"), ("pdas", "primal")]


@pytest.mark.parametrize("backend, formulation", WARM)
@pytest.mark.parametrize("path, values", [
    (STIFF, ["rigid", 1e5, 3e4, 1e4, 3e3, 1e3]),
    ("supports.12.gap", [0.0, 0.01, 0.02, 0.03, 0.05]),  # settlement of the middle support
])
def test_warm_and_cold_sweeps_equal_independent_lemke_solves(backend, formulation, path, values):
    """Warm-started, re-used-cold and from-scratch sweeps all give each value's own answer:
    an independent Lemke solve (fresh model, no warm start), reactions and contact sets."""
    if backend not in pq.available_backends():
        pytest.skip(f"{backend} is not installed here")
    sc = fig5()
    refs = [solve(set_param(sc, path, v), backend="lemke", formulation="condensed") for v in values]
    assert len({tuple(r.active) for r in refs}) >= 3  # the contact set changes along the sweep
    for kw in ({}, {"warm_start": False}, {"reuse": False}):
        res = sweep(sc, path, values, backend=backend, formulation=formulation, executor="serial",
                    progress=False, refine_breakpoints=False, **kw)
        for row, ref in zip(res.rows, refs):
            assert row["status"] == "optimal", kw
            np.testing.assert_allclose(row["reactions"], ref.reactions, rtol=0, atol=1e-8 * ref.reactions.max(),
                                       err_msg=str(kw))
            assert row["active"] == ref.active.tolist(), kw
            t = row["times"]
            parts = t["build"] + t["formulate"] + t["solve"] + t["recover"] + t["post"]
            assert 0 <= t["scene"] <= t["build"] and parts <= t["total"] * (1 + 1e-9)


def test_warm_start_makes_an_unchanged_contact_set_one_step():
    """A settlement sweep: started from the step before, every value whose contact set is that
    of the value before takes one step (the start is the answer), and the sweep takes fewer
    steps in all than the same sweep started cold; bisection finds the same breakpoints."""
    sc = fig5()
    path, values = "supports.12.gap", list(np.linspace(0.0, 0.05, 11))
    for backend, formulation in WARM:
        if backend not in pq.available_backends():
            continue
        kw = {"backend": backend, "formulation": formulation, "executor": "serial", "progress": False}
        warm = sweep(sc, path, values, refine_breakpoints=False, **kw)
        cold = sweep(sc, path, values, refine_breakpoints=False, warm_start=False, **kw)
        assert warm.active == cold.active
        same = [k for k in range(1, len(values)) if warm.active[k] == warm.active[k - 1]]
        assert len(same) >= 4
        assert all(warm.rows[k]["iterations"] == 1 for k in same), [r["iterations"] for r in warm.rows]
        its_warm = sum(r["iterations"] for r in warm.rows)
        its_cold = sum(r["iterations"] for r in cold.rows)
        assert its_warm < its_cold, (backend, its_warm, its_cold)
        assert warm.rows[0]["iterations"] == cold.rows[0]["iterations"]  # the first value starts cold
    bw = sweep(sc, path, values[:4], rtol=1e-2, **kw).breakpoints
    bc = sweep(sc, path, values[:4], rtol=1e-2, warm_start=False, **kw).breakpoints
    assert bw and bw == bc


def test_sweep_s1_max_equals_result_nodal_on_a_plate_with_an_opening():
    """With re-use the rows' max nodal σ1 comes from operators built once per mesh: the same
    number as Result.nodal of an independent solve, here with cut-out cells and a bed."""
    sc = pq.Scene(plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(8, 8),
                  edges={"left": pq.Edge("simple")}, openings=[pq.Opening(0.6, 1.0, 0.6, 1.0)],
                  loads=[pq.UniformLoad(q=5.0), pq.PointLoad(P=2.0, x=0.3, y=0.7)],
                  supports=[pq.Support(1.0, 0.25, gap=0.001), pq.Support(0.25, 1.0)],
                  foundation=pq.Foundation(k=3e4, region=[0.5, 1.0, 0.0, 0.5]))
    res = sweep(sc, "foundation.k", [1e4, 3e4, 1e5], executor="serial", progress=False, refine_breakpoints=False)
    for row, v in zip(res.rows, [1e4, 3e4, 1e5]):
        ref = solve(set_param(sc, "foundation.k", v))
        assert row["s1_max"] == pytest.approx(float(np.nanmax(ref.nodal("s1"))), rel=1e-12)


@pytest.mark.parametrize("bad", ["yes", 1, None, np.array([True])])
def test_warm_start_must_be_a_bool(bad):
    with pytest.raises(pq.ProblemError, match="warm_start must be True or False"):
        sweep(fig5(), STIFF, [1e4], executor="serial", progress=False, warm_start=bad)


def test_warm_start_false_sends_no_start(monkeypatch):
    fake = _WarmRecorder()
    monkeypatch.setitem(pq.registry(), "bpp", fake)
    sweep(fig5(), STIFF, ["rigid", 1e5, 1e4], backend="bpp", executor="serial", progress=False,
          refine_breakpoints=False, warm_start=False)
    assert fake.seen == [None, None, None]


def test_a_failed_value_is_recorded_and_the_sweep_goes_on():
    res = sweep(fig5(), "loads.0.P", [10000.0, -1e6, 20000.0], executor="serial", progress=False)
    bad = res.rows[1]
    assert bad["status"] == "infeasible" and "NoEquilibriumError" in bad["error"] and bad["reactions"] is None
    assert res.rows[0]["status"] == res.rows[2]["status"] == "optimal"
    assert np.isnan(res.reactions[1]).all()
    assert all(b["between"] != [10000.0, -1e6] for b in res.breakpoints)


def test_stiffness_study_finds_every_change_of_working_scheme():
    """The paper's fig. 5: c from ∞ (rigid) down to 1; each breakpoint checked by independent
    solves just either side of it, and a dense grid of 200 values finds no other change."""
    sc = fig5()
    values = ["rigid", *np.geomspace(1e6, 1.0, 13).tolist()]
    res = sweep(sc, STIFF, values, progress=False, rtol=1e-3)  # default executor: local processes
    bps = res.breakpoints
    assert len(bps) >= 5
    ats = np.array([b["at"] for b in bps])
    for b in bps:
        lo, hi = sorted(b["bracket"])
        assert b["at"] is not None and hi / lo <= 1 + 1e-3  # bracketed to 1e-3 relative
        assert b["before"] != b["after"]
        # probe at at·(1 ± 2e-3), or halfway to a neighbouring breakpoint that is closer than that
        others = np.abs(np.log(ats / b["at"]))
        delta = min(2e-3, 0.5 * others[others > 0].min())
        assert delta > np.log(hi / lo)  # still outside the bracket
        above = contact_set(solve(set_param(sc, STIFF, b["at"] * np.exp(delta))).active)
        below = contact_set(solve(set_param(sc, STIFF, b["at"] * np.exp(-delta))).active)
        assert (above, below) == (b["before"], b["after"])  # the sweep runs down in c
    # nothing missed: every change on a dense grid lies in a reported bracket, and only there
    dense = np.geomspace(1e6, 1.0, 200)
    sets = [contact_set(solve(set_param(sc, STIFF, c)).active) for c in dense]
    assert res.rows[0]["active"] == solve(sc).active.tolist()  # the rigid row
    for k in range(len(dense) - 1):
        inside = [b for b in bps if dense[k + 1] < b["at"] < dense[k]]
        if sets[k] == sets[k + 1]:
            assert not inside, f"a reported change between {dense[k + 1]:g} and {dense[k]:g} the grid does not see"
        else:
            assert inside, f"the contact set changes between {dense[k + 1]:g} and {dense[k]:g}: not reported"
            assert (inside[0]["before"], inside[-1]["after"]) == (sets[k], sets[k + 1])
    # the rows themselves agree with the dense grid where they meet it
    assert res.rows[1]["active"] == solve(set_param(sc, STIFF, 1e6)).active.tolist()
    assert "changes of the contact set" in str(res)


def test_gap_sweep_bisects_linearly():
    """A settlement of the middle support, 0 to 0.05 cm: supports come into contact and lift
    off; each change is bracketed to rtol × max |value| and confirmed by independent solves."""
    sc = fig5()
    path = "supports.12.gap"
    res = sweep(sc, path, [0.0, 0.05], executor="serial", progress=False, rtol=1e-3)
    assert len(res.breakpoints) >= 4
    for b in res.breakpoints:
        lo, hi = b["bracket"]
        assert 0.0 < lo < b["at"] < hi < 0.05 and hi - lo <= 1e-3 * max(abs(lo), abs(hi))
        w = hi - lo
        assert contact_set(solve(set_param(sc, path, lo - w / 2)).active) == b["before"]
        assert contact_set(solve(set_param(sc, path, hi + w / 2)).active) == b["after"]


def test_dask_local_cluster_equals_serial():
    distributed = pytest.importorskip("distributed")
    sc = fig5()
    values = [1e5, 5e4, 2e4, 1e4]
    serial = sweep(sc, STIFF, values, executor="serial", progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        par = sweep(sc, STIFF, values, executor=client, progress=False)
    assert par.times["executor"] == "dask"
    np.testing.assert_array_equal(par.reactions, serial.reactions)
    assert par.breakpoints == serial.breakpoints


def test_process_pool_equals_serial():
    sc = fig5()
    values = [1e5, 3e4, 1e4, 3e3]
    serial = sweep(sc, STIFF, values, executor="serial", progress=False, refine_breakpoints=False)
    par = sweep(sc, STIFF, values, executor="process", progress=False, refine_breakpoints=False)
    assert par.times["executor"] == "futures"
    np.testing.assert_array_equal(par.reactions, serial.reactions)
    assert [r["active"] for r in par.rows] == [r["active"] for r in serial.rows]


# -- regulating the reactions by the gaps ---------------------------------------------------------

def _check_regulated(reg, supports, target):
    R = solve(reg.scene, accuracy="high").reactions  # the independent check
    np.testing.assert_allclose(R[supports], target, rtol=1e-6, atol=1e-6 * np.max(target))
    return R


def test_regulate_gaps_equal_contour_reactions_on_a_floating_plate():
    sc = contour()
    R0 = solve(sc).reactions
    assert R0.std() / R0.mean() > 0.5  # the corners lift off on rigid supports
    target = 10.0 / 16  # q a b spread equally
    reg = regulate_gaps(sc, target)
    assert reg.reachable
    _check_regulated(reg, np.arange(16), np.full(16, target))


def test_regulate_gaps_held_plate_any_target_some_supports():
    sup = [pq.Support(x, y, stiffness=(5e3 if x > 0.5 else "rigid"))
           for x in (0.25, 0.5, 0.75) for y in (0.25, 0.5, 0.75)]
    sc = pq.Scene(plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(8, 8),
                  edges={"left": pq.Edge("simple"), "right": pq.Edge("simple")},
                  loads=[pq.UniformLoad(q=10.0)], supports=sup)
    target = np.array([0.3, 0.9, 0.5, 0.2])
    chosen = [0, 2, 4, 8]
    reg = regulate_gaps(sc, target, supports=chosen)
    R = _check_regulated(reg, chosen, target)
    others = [1, 3, 5, 6, 7]
    np.testing.assert_allclose(R[others], reg.other_reactions, rtol=1e-6, atol=1e-9)
    assert [s.gap for k, s in enumerate(reg.scene.supports) if k in others] == [0.0] * 5  # untouched


def test_regulate_gaps_projects_an_unbalanced_target_onto_equilibrium():
    # an eccentric load: equal contour reactions cannot balance its moment
    sc = contour(stiffness=1e4, loads=[pq.UniformLoad(q=10.0), pq.PointLoad(P=5.0, x=0.75, y=0.5)])
    reg = regulate_gaps(sc, 15.0 / 16)
    assert not reg.reachable and reg.projection > 0.05
    R = reg.reactions
    xy = np.array([(s.x, s.y) for s in sc.supports])
    assert R.sum() == pytest.approx(15.0, rel=1e-9)  # force balance
    assert R @ xy[:, 0] == pytest.approx(10.0 * 0.5 + 5.0 * 0.75, rel=1e-9)  # moment balance
    _check_regulated(reg, np.arange(16), R)


def test_regulate_gaps_floating_plate_with_unregulated_supports():
    sc = contour()
    reg = regulate_gaps(sc, 0.5, supports=[1, 2, 3, 5, 6, 7])
    R = _check_regulated(reg, [1, 2, 3, 5, 6, 7], reg.reactions)
    assert R.sum() == pytest.approx(10.0, rel=1e-9)


def test_most_uniform_stiffness_against_a_scan():
    # a plate on an elastic contour and a central column: stiff contour supports load the
    # mid-sides, soft ones the corners, in between the pressure is most uniform
    sc = contour(pins=[pq.Pin(0.5, 0.5)])
    best = most_uniform_stiffness(sc, (10.0, 1e6))
    cs = np.geomspace(10.0, 1e6, 41)
    cv = []
    for c in cs:
        R = solve(set_param(sc, STIFF, c)).reactions
        cv.append(R.std() / R.mean())
    k = int(np.argmin(cv))
    assert 0 < k < len(cs) - 1  # an interior optimum
    assert cs[k - 1] < best.c < cs[k + 1] and not best.at_bound
    assert best.cv <= min(cv) + 1e-12
    R = solve(set_param(sc, STIFF, best.c)).reactions
    assert R.std() / R.mean() == pytest.approx(best.cv, rel=1e-9)
    # without the column the plate floats on equal springs: softer is always more uniform
    assert most_uniform_stiffness(contour(), (10.0, 1e6), scan=9).at_bound


# -- command line ---------------------------------------------------------------------------------

def test_cli_sweep_json(capsys, tmp_path):
    path = tmp_path / "fig5.toml"
    fig5().to_toml(path)
    code = main(["sweep", str(path), "--param", STIFF, "--values", "rigid,1e6,5e5", "--json", "--workers", "1"])
    out = capsys.readouterr()
    assert code == 0 and out.err == ""
    d = json.loads(out.out)
    assert set(d) == {"rows", "breakpoints"}
    one = solve(fig5()).to_dict()
    assert [r["value"] for r in d["rows"]] == ["rigid", 1e6, 5e5]
    for r in d["rows"]:
        assert set(one) <= set(r) and r["status"] == "optimal"
    assert d["breakpoints"]
    for b in d["breakpoints"]:
        assert {"between", "at", "before", "after"} <= set(b)
        assert b["between"] in (["rigid", 1e6], [1e6, 5e5])
    np.testing.assert_allclose(d["rows"][0]["reactions"], one["reactions"], rtol=1e-9, atol=1e-6)

    code = main(["sweep", str(path), "--param", "supports.12.gap", "--range", "0.0:0.04:3", "--no-refine"])
    out = capsys.readouterr()
    assert code == 0 and "sweep of supports.12.gap: 3 values" in out.out

    # warm or cold, bpp gives the same answers
    runs = [json.loads((main(["sweep", str(path), "--param", STIFF, "--values", "1e6,5e5,1e5", "--json",
                              "--workers", "1", "--backend", "bpp", *flag]), capsys.readouterr().out)[1])
            for flag in ([], ["--no-warm-start"])]
    for warm, cold in zip(runs[0]["rows"], runs[1]["rows"]):
        np.testing.assert_allclose(warm["reactions"], cold["reactions"], rtol=1e-9, atol=1e-6)

    code = main(["sweep", str(path), "--param", "loads.0.P", "--range", "1e3:1e5:3:log", "--json", "--no-refine"])
    d = json.loads(capsys.readouterr().out)
    assert [r["value"] for r in d["rows"]] == pytest.approx([1e3, 1e4, 1e5])
    assert all(b["at"] is None for b in d["breakpoints"])  # not refined: the change lies between the values


@pytest.mark.parametrize("argv, code, words", [
    (["--param", "supports.30.gap", "--values", "0"], 2, ["supports.30", "25 supports"]),
    (["--param", "loads.0.P", "--range", "1:2:x"], 2, ["--range"]),
    (["--param", "loads.0.P", "--values", "1e4,-1e6", "--workers", "1"], 5, ["1 of 2", "NoEquilibriumError"]),
])
def test_cli_sweep_errors(capsys, tmp_path, argv, code, words):
    path = tmp_path / "fig5.toml"
    fig5().to_toml(path)
    assert main(["sweep", str(path), *argv]) == code
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and all(w in err for w in words)
