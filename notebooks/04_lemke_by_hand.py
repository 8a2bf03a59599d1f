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
# # 2. Lemke's method step by step
#
# Lemke's complementary pivoting solves the condensed LCP  R = M z + q, z ≥ 0, R ≥ 0, zᵀR = 0
# (z the gaps, R the reactions). It adds an artificial variable z0 with a *covering vector* d:
# R = M z + q + d z0. Starting from z0 large enough every "reaction" is non-negative: the
# source paper reads d z0 as a **uniform pre-compression** of all supports. Each pivot then
# exchanges one support between the two states (its gap enters the basis: it opens; its
# reaction enters: it presses) until the pre-compression z0 reaches zero.

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
# Notebook 12 opens the method up: the tableau before every pivot, the path of z0, and a plate
# with no equilibrium, where Lemke ends on a ray that proves it.
