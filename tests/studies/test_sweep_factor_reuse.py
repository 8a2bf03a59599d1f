"""A sweep over gaps, spring stiffnesses or loads factorises the plate's K once (posts: the
condensed method's factor of K and its flexibility serve every value), or on a bed analyses
its pattern once and factorises only where the contact set changes by more than a low-rank
correction takes; a sweep whose path changes K (thickness, modulus, mesh) factorises it for
every value. Every value's answer is the cold solve's, to rounding, and passes the KKT check."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.paths import set_param
from plateqp.studies.sweep import sweep
from study_scenes import bed

pytestmark = pytest.mark.skipif(not pq.linalg.bindings(), reason="no CHOLMOD binding")

WALLS = {"left": "simple", "right": "simple", "bottom": "simple",
         "top": "simple"}


def posts(n: int = 12) -> pq.Scene:
    """A simply supported slab on a 3 × 3 grid of one-sided posts (rigid and elastic), mixed gaps."""
    sup = []
    for i, x in enumerate((0.3, 0.5, 0.7)):
        for j, y in enumerate((0.3, 0.5, 0.7)):
            stiff = "rigid" if (i + j) % 2 == 0 else 2.0e5
            sup.append(pq.Support(x, y, stiffness=stiff, gap=1e-4 * ((i * 3 + j) % 4)))
    return pq.Scene(name="posts", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                    edges=WALLS, loads=[pq.UniformLoad(2000.0)], supports=sup)


def run(scene, path, values, reuse):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return sweep(scene, path, values, backend="pdas", accuracy=1e-10, executor="serial", progress=False,
                     refine_breakpoints=False, reuse=reuse)


def same_as_cold(hot, cold):
    for h, c in zip(hot.rows, cold.rows):
        assert h["error"] is None and c["error"] is None
        assert h["status"] == "optimal" and h["kkt_worst"] <= 1e-10  # the KKT check, on every value
        assert h["active"] == c["active"]
        R, Rc = np.array(h["reactions"]), np.array(c["reactions"])
        assert np.allclose(R, Rc, rtol=1e-8, atol=1e-9 * np.abs(Rc).max())
        assert h["w_max"] == pytest.approx(c["w_max"], rel=1e-8)


POSTS = [
    ("supports.1.gap", [-4e-4, -1e-4, 2e-4, 5e-4, 8e-4]),  # a gap
    ("supports.2.stiffness", [1e4, 1e5, 1e6, 1e7, "rigid"]),  # a spring's stiffness
    ("loads.0.q", [500.0, 1000.0, 2000.0, 4000.0]),  # a load
]
BED = [
    ("foundation.k", [1.0e4, 2.0e4, 4.0e4, 8.0e4]),  # the bed's modulus
    ("loads.1.P", [50.0, 200.0, 800.0]),  # a load on the bed
    ("foundation.gap.gx", [0.002, 0.003, 0.004, 0.005]),  # the bed's gap field
]


@pytest.mark.parametrize("path, values", POSTS, ids=[c[0] for c in POSTS])
def test_posts_K_factorised_once(path, values, factorisations):
    scene = posts()
    hot = run(scene, path, values, reuse=True)
    once = dict(factorisations)
    cold = run(scene, path, values, reuse=False)
    same_as_cold(hot, cold)
    assert factorisations["n"] - once["n"] >= len(values)  # the cold sweep factorises every value
    assert once["n"] == 1 and once["analyse"] == 1


@pytest.mark.parametrize("path, values", BED, ids=[c[0] for c in BED])
def test_bed_analysed_once(path, values, factorisations):
    scene = bed()
    hot = run(scene, path, values, reuse=True)
    once = dict(factorisations)
    cold = run(scene, path, values, reuse=False)
    same_as_cold(hot, cold)
    assert factorisations["analyse"] - once["analyse"] >= len(values)
    assert once["analyse"] == 1
    assert once["n"] < factorisations["n"] - once["n"]  # fewer factorisations than the cold sweep


@pytest.mark.parametrize("make, path, values", [
    (posts, "plate.h", [0.015, 0.02, 0.025]),  # thickness: a new K
    (posts, "plate.E", [5e6, 1e7, 2e7]),  # modulus: a new K
    (posts, "mesh.nx", [8, 10, 12]),  # the mesh: a new K
    (bed, "plate.h", [0.015, 0.02, 0.03]),
], ids=["posts-h", "posts-E", "posts-mesh", "bed-h"])
def test_a_new_K_is_factorised_again(make, path, values, factorisations):
    scene = make()
    hot = run(scene, path, values, reuse=True)
    assert factorisations["n"] >= len(values)  # a reused factorisation of another K would be wrong
    cold = run(scene, path, values, reuse=False)
    same_as_cold(hot, cold)


def test_stiffness_design_factorises_K_once(factorisations):
    """The stiffness design (one c for every support, searched) solves one K for every c."""
    from plateqp.studies.design import most_uniform_stiffness

    scene = posts()
    scene.supports = [pq.Support(s.x, s.y, stiffness=1e5, gap=s.gap) for s in scene.supports]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        got = most_uniform_stiffness(scene, (1e4, 1e7), scan=5, backend="pdas", accuracy=1e-10)
    assert len(got.evaluations) >= 6
    assert factorisations["n"] == 1 and factorisations["analyse"] == 1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cold = pq.solve(set_param(scene, "supports.*.stiffness", got.c), backend="pdas", accuracy=1e-10)
    assert np.allclose(got.reactions, cold.reactions, rtol=1e-8, atol=1e-9 * np.abs(cold.reactions).max())


def test_a_bed_gap_sweep_takes_each_values_first_solve_from_the_span_of_those_before(monkeypatch):
    """A gap field's values ask for f + Bᵀ W (g + t dg) on the same factor while the contact
    set stays: each value's first solve is the combination of those before it (no solve); the
    field here is a plane, whose tilt the plate takes as a rigid body (taken out first), so the
    rest is the same at every value: one solve on the set, then none. Every value is still the
    cold solve's."""
    from plateqp.backends.pdas.factor import SpringFactor

    calls = []
    orig = SpringFactor.solve_in_span

    def counted(self, b):
        before = self.stats["solves"]
        x = orig(self, b)
        calls.append(self.stats["solves"] - before)
        return x

    monkeypatch.setattr(SpringFactor, "solve_in_span", counted)
    scene = bed()
    path, values = "foundation.gap.gx", [0.002, 0.0025, 0.003, 0.0035, 0.004, 0.005]
    hot = run(scene, path, values, reuse=True)
    # one first solve a value: the first value's on every row's matrix (a cold start), the
    # next on the contact set's, then none
    assert calls == [1, 1] + [0] * (len(values) - 2), calls
    cold = run(scene, path, values, reuse=False)
    same_as_cold(hot, cold)
