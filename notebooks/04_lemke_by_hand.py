# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.6
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # 4. Lemke's method by hand
#
# Lemke's complementary pivoting solves the condensed LCP  R = M z + q, z ≥ 0, R ≥ 0, zᵀR = 0
# (z the gaps, R the reactions). It adds an artificial variable z0 with a *covering vector* d:
# R = M z + q + d z0. Starting from z0 large enough every "reaction" is non-negative: the
# source paper reads d z0 as a **uniform pre-compression** of all supports. Each pivot then
# exchanges one support between the two states (its gap enters the basis: it opens; its
# reaction enters: it presses) until the pre-compression z0 reaches zero.


# %% [markdown]
# ## Learning goals
#
# * read Lemke's complementary pivoting as a story about supports: an artificial uniform
#   pre-compression z0 that is relaxed pivot by pivot, each pivot a support opening or pressing;
# * follow z0 down to zero and read the working scheme at the end;
# * check the answer against an independent formulation (the primal problem, solved by PDAS);
# * see that the covering vector changes the path, not the answer, and that a Lemke stopped early
#   has no answer to give.

# %%
import numpy as np
import plateqp as pq
from plateqp.backends import lemke
from plateqp.model.assembly import build_model
from plateqp.contact import Scaled, formulate

supports = [pq.Support(x, y, gap=(-0.05 if (x, y) in ((0.5, 0.0), (1.0, 0.0)) else 0.0))
            for x in (0.5, 0.75, 1.0) for y in (0.0, 0.5, 1.0)]
scene = pq.Scene(name="nb2", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
                 edges={"left": "simple"}, loads=[pq.PointLoad(40.0, 0.7, 0.7)], supports=supports)
data = Scaled.from_model(build_model(scene))   # nondimensional: gaps in units of data.W
lcp = formulate(data, "condensed").lcp
raw = lemke.lemke(lcp.M, lcp.q, trace=True)
names = {"z": "gap of support", "w": "reaction at support"}
for step in raw.extras["trace"]:
    e, l = step["entering"], step["leaving"]
    ent = "z0 (pre-compression)" if e[0] == "z0" else f"{names[e[0]]} {e[1]}"
    lea = "z0 (pre-compression)" if l[0] == "z0" else f"{names[l[0]]} {l[1]}"
    print(f"pivot {step['step']:2d}: enters {ent:28s} leaves {lea:28s} z0 = {step['z0']:.4g}")

# %% [markdown]
# Every pivot is a support entering or leaving contact; when z0 leaves, the working scheme is found:

# %%
z = raw.x
R = lcp.M @ z + lcp.q
for i, s in enumerate(scene.supports):
    state = "contact" if R[i] > 1e-12 else "lifted off"
    print(f"support {i} at ({s.x}, {s.y}) gap0 {s.gap:+.3f}: {state:10s} R = {R[i] * data.F0:8.4f}, gap = {z[i] * data.W:.2e}")
assert np.all(z >= 0) and np.all(R >= -1e-12) and abs(z @ R) < 1e-12

# %% [markdown]
# ## Any positive covering vector gives the same answer
# The pre-compression may be non-uniform: the path of pivots changes, the solution does not
# (M is positive definite here because the simple edge holds the plate).

# %%
for d in (np.ones(lcp.n), np.linspace(1, 5, lcp.n), np.random.default_rng(0).uniform(0.1, 10, lcp.n)):
    r = lemke.lemke(lcp.M, lcp.q, covering=d)
    print(f"{r.iterations:2d} pivots, max |z - z_uniform| = {np.abs(r.x - z).max():.1e}")
    np.testing.assert_allclose(r.x, z, atol=1e-12)

# %% [markdown]
# Lesson 5 opens the method up: the tableau before every pivot, the path of z0, and a plate
# with no equilibrium, where Lemke ends on a ray that proves it.

# %% [markdown]
# ## The pre-compression relaxed, pivot by pivot
#
# The value of the artificial variable z0 after each pivot. It falls monotonically here (it need
# not in general: lesson 5 shows a path where it rises), and the method ends when z0 leaves the
# basis at zero.

# %%
import matplotlib.pyplot as plt
steps = [0] + [s["step"] for s in raw.extras["trace"]]
z0 = [raw.extras["trace"][0]["z0"]] + [s["z0"] for s in raw.extras["trace"]]
fig, ax = plt.subplots(figsize=(5, 2.6))
ax.plot(steps, z0, "o-")
ax.set_xlabel("pivot"); ax.set_ylabel("z0 (uniform pre-compression)"); fig.tight_layout()
plt.show()

# %% [markdown]
# ### Exercise 1: an independent check
#
# Solve the same scene on the primal formulation (every displacement, no condensation) with
# plateqp's PDAS backend and check that its reactions equal Lemke's (scaled back by data.F0).
# Then check statics: the simple edge lies on x = 0, so its reactions have no moment about that
# line; the posts' reactions alone balance the moment of the point load, 40 × 0.7.

# %%
primal = pq.solve(scene, backend="pdas", formulation="primal", accuracy="high")
print("primal:", np.round(primal.reactions, 4))
print("lemke: ", np.round(R * data.F0, 4))
np.testing.assert_allclose(primal.reactions, R * data.F0, atol=1e-8 * 40)
xs = np.array([s.x for s in scene.supports])
print("moment of the posts' reactions about x = 0:", primal.reactions @ xs, "load's:", 40 * 0.7)
assert abs(primal.reactions @ xs - 40 * 0.7) < 1e-8 * 28 and primal.reactions.min() >= -1e-10

# %% [markdown]
# ### Exercise 2: break it, stop Lemke early
#
# Allow Lemke only two pivots (`max_iter=2`). The path ends while z0 is still positive: the
# supports still carry an artificial pre-compression, so there is no solution of the LCP to
# report. Check that the method says so (its status is not optimal) instead of returning a point.

# %%
early = lemke.lemke(lcp.M, lcp.q, max_iter=2)
print("status after two pivots:", early.status, "| z0 still", raw.extras["trace"][1]["z0"])
assert early.status != pq.Status.OPTIMAL and early.x is None
assert raw.extras["trace"][1]["z0"] > 0

# %% [markdown]
# ## Summary
#
# * Lemke's method adds a uniform pre-compression z0 and relaxes it; each pivot moves one support
#   between contact and lift-off, and z0 = 0 ends it with the working scheme.
# * The covering vector is a choice of path: any positive one gives the same solution here.
# * The answer agrees with the primal formulation solved independently; a Lemke stopped before
#   z0 = 0 has no answer, and says so.
