"""Sweeps (plateqp.studies.sweep, .worker, .breakpoints): every row and every breakpoint is
checked against independent ``pq.solve`` calls (fresh model, no warm start), and a dense grid of
independent solves for "no change was missed"; the ``plateqp sweep`` command line. On a triangle
mesh, a load sweep re-assembles the load vector on the same mesh (checked against fresh builds and
the closed form of a simply supported disc on a central one-sided support), and a moved point load
gets a new mesh."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import plateqp as pq
from plateqp.cli import main
from plateqp.model.assembly import build_model
from plateqp.studies import set_param, sweep
from plateqp.studies.reuse import adapt_model
from study_scenes import STIFF, contact_set, fig5, solve


@pytest.mark.parametrize("path, values", [
    (STIFF, ["rigid", 1e6, 3e4, 1e3, 30.0]),
    ("supports.13.gap", [-0.05, -0.01, 0.0, 0.02]),
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
    ("supports.13.gap", [0.0, 0.01, 0.02, 0.03, 0.05]),  # settlement of the middle support
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
    path, values = "supports.13.gap", list(np.linspace(0.0, 0.05, 11))
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
    path = "supports.13.gap"
    res = sweep(sc, path, [0.0, 0.05], executor="serial", progress=False, rtol=1e-3)
    assert len(res.breakpoints) >= 4
    for b in res.breakpoints:
        lo, hi = b["bracket"]
        assert 0.0 < lo < b["at"] < hi < 0.05 and hi - lo <= 1e-3 * max(abs(lo), abs(hi))
        w = hi - lo
        assert contact_set(solve(set_param(sc, path, lo - w / 2)).active) == b["before"]
        assert contact_set(solve(set_param(sc, path, hi + w / 2)).active) == b["after"]


# -- command line ---------------------------------------------------------------------------------

def test_cli_sweep_json(capsys, tmp_path):
    path = tmp_path / "fig5.toml"
    fig5().to_toml(path)
    code = main(["sweep", str(path), "--param", STIFF, "--values", "rigid,1e6,5e5", "--json", "--workers", "1"])
    out = capsys.readouterr()
    assert code == 0 and out.err == ""
    d = json.loads(out.out)
    assert set(d) == {"rows", "breakpoints", "method"} and d["method"] == "bisection"
    one = solve(fig5()).to_dict()
    assert [r["value"] for r in d["rows"]] == ["rigid", 1e6, 5e5]
    for r in d["rows"]:
        assert set(one) <= set(r) and r["status"] == "optimal"
    assert d["breakpoints"]
    for b in d["breakpoints"]:
        assert {"between", "at", "before", "after"} <= set(b)
        assert b["between"] in (["rigid", 1e6], [1e6, 5e5])
    np.testing.assert_allclose(d["rows"][0]["reactions"], one["reactions"], rtol=1e-9, atol=1e-6)

    code = main(["sweep", str(path), "--param", "supports.13.gap", "--range", "0.0:0.04:3", "--no-refine"])
    out = capsys.readouterr()
    assert code == 0 and "sweep of supports.13.gap: 3 values" in out.out

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
    (["--param", "supports.31.gap", "--values", "0"], 2, ["supports.31", "25 supports"]),
    (["--param", "loads.0.P", "--range", "1:2:x"], 2, ["--range"]),
    (["--param", "loads.0.P", "--values", "1e4,-1e6", "--workers", "1"], 5, ["1 of 2", "NoEquilibriumError"]),
])
def test_cli_sweep_errors(capsys, tmp_path, argv, code, words):
    path = tmp_path / "fig5.toml"
    fig5().to_toml(path)
    assert main(["sweep", str(path), *argv]) == code
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and all(w in err for w in words)


# -- load sweeps on a triangle mesh (a disc: the closed form of a simply supported plate) --------

R, NU = 1.0, 0.3


def disc(**kw) -> pq.Scene:
    """A simply supported disc meshed in DKT triangles (a shape the rectangle grid cannot mesh)."""
    return pq.Scene(name="disc", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.01, E=1.0e7, nu=NU),
                    mesh=pq.MeshSpec(element="dkt", size=R / 8), edges={"all": pq.Edge("simple")}, **kw)


D = disc().plate.D
W_PER_Q = (5 + NU) * R**4 / (64 * (1 + NU) * D)  # centre deflection per unit q, simply supported
ALPHA = (3 + NU) * R**2 / (16 * math.pi * (1 + NU) * D)  # centre deflection per unit central force
G0 = 1e-3


def test_load_sweep_on_a_disc_matches_fresh_builds_and_the_closed_form():
    pytest.importorskip("gmsh")
    sc = disc(loads=[pq.UniformLoad(1.0)], supports=[pq.Support(0.0, 0.0, gap=G0)])
    q_star = G0 / W_PER_Q  # the load at which the plate reaches the support
    values = [0.5 * q_star, 2.0 * q_star, 4.0 * q_star]
    res = sweep(sc, "loads.0.q", values, progress=False, executor="serial", rtol=1e-6)
    for q, row in zip(values, res.rows):
        assert row["error"] is None and row["status"] == "optimal"
        fresh = pq.solve(set_param(sc, "loads.0.q", q), accuracy="high")  # a new mesh and assembly
        np.testing.assert_allclose(row["reactions"], fresh.reactions, rtol=1e-8, atol=1e-10 * q)
        exact = max(0.0, (W_PER_Q * q - G0) / ALPHA)  # superposition (Timoshenko §§ 16-19)
        assert row["reactions"][0] == pytest.approx(exact, rel=0.02, abs=1e-9 * q)
    (bp,) = res.breakpoints
    assert bp["at"] == pytest.approx(q_star, rel=0.01)  # the discretisation error of w_q at R/8


def test_a_moved_point_load_gets_a_new_mesh():
    pytest.importorskip("gmsh")
    sc = disc(loads=[pq.PointLoad(1.0, 0.2, 0.1)], supports=[pq.Support(0.0, 0.0, gap=0.0)])
    base = build_model(sc)
    assert adapt_model(base, set_param(sc, "loads.0.P", 2.0)) is not None  # same nodes: re-used
    assert adapt_model(base, set_param(sc, "loads.0.x", 0.3)) is None  # the load's node moves
    res = sweep(sc, "loads.0.x", [0.2, 0.3], progress=False, executor="serial", refine_breakpoints=False)
    for x, row in zip([0.2, 0.3], res.rows):
        fresh = pq.solve(set_param(sc, "loads.0.x", x))
        np.testing.assert_allclose(row["reactions"], fresh.reactions, rtol=1e-9)
