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
# # 3. KKT conditions and the LCP: three formulations of one contact problem
#
# A plate on one-sided supports minimises its potential energy subject to *gap ≥ 0*. We write the
# three standard forms of plateqp (primal, condensed, dual) **by hand in cvxpy** from the same
# nondimensional data, solve each, and check the KKT conditions ourselves with NumPy:
#
# * stationarity  K u − f + Bᵀ R = 0
# * primal feasibility  gap = g0 + s − B u ≥ 0
# * dual feasibility  R ≥ 0
# * complementarity  R_i · gap_i = 0 for every support


# %% [markdown]
# ## Learning goals
#
# * write the contact problem of a plate three ways (primal: every displacement; condensed: the
#   gaps at the supports; dual: the reactions) and solve each as a QP;
# * state the four KKT conditions (stationarity, primal feasibility, dual feasibility,
#   complementarity) and check them by hand on a solution;
# * see that the KKT system of the condensed QP *is* the linear complementarity problem
#   R = M z + q, z ≥ 0, R ≥ 0, zᵀR = 0 that Lemke's method (lessons 4 and 5) solves;
# * know why the dual needs a plate that is held: it needs K⁻¹.

# %%
import numpy as np
import cvxpy as cp
import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.contact import Scaled, formulate

# a free plate on a 3 x 3 grid of rigid supports; one corner support settled, a point load
supports = [pq.Support(x, y, gap=(0.002 if (x, y) == (1.0, 1.0) else 0.0))
            for x in (0.0, 0.5, 1.0) for y in (0.0, 0.5, 1.0)]
scene = pq.Scene(name="nb1", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
                 loads=[pq.PointLoad(50.0, 0.6, 0.4), pq.UniformLoad(5.0)], supports=supports)
d = Scaled.from_model(build_model(scene))   # K, f, B, g0, rho: nondimensional
print(f"{d.n} free dofs, {d.m} supports, floating plate: {d.floating}")

# %% [markdown]
# ## Primal: all dofs
# minimise ½ uᵀKu − fᵀu subject to B u ≤ g0 (rigid supports, so no spring variables).
# The plate floats (no two-sided support), so K is only positive *semi*definite; the QP is
# still bounded because the supports can carry the load.

# %%
u = cp.Variable(d.n)
cons = [d.B @ u <= d.g0]
primal = cp.Problem(cp.Minimize(0.5 * cp.quad_form(u, cp.psd_wrap(d.K)) - d.f @ u), cons)
primal.solve(solver="CLARABEL")
u_p, R_p = u.value, cons[0].dual_value
print(primal.status, "reactions (scaled):", np.round(R_p, 4))

# %% [markdown]
# ## Condensed: the gaps at the supports (the source paper's route)
# Static condensation of every non-contact dof gives the LCP R = M z + q with z the gaps:
# the KKT system of  minimise ½ zᵀMz + qᵀz, z ≥ 0.

# %%
cond = formulate(d, "condensed")
M, q = cond.lcp.M, cond.lcp.q
z = cp.Variable(d.m)
c2 = [z >= 0]
cp.Problem(cp.Minimize(0.5 * cp.quad_form(z, cp.psd_wrap(M)) + q @ z), c2).solve(solver="CLARABEL")
R_c = M @ z.value + q       # the reactions are the multipliers of z >= 0
print("reactions (scaled):", np.round(R_c, 4))

# %% [markdown]
# ## Dual: the reactions
# With the flexibility G = B K⁻¹ Bᵀ the gaps are gap = G R + d. K⁻¹ needs two-sided supports
# that hold the plate: ours floats, so plateqp refuses the dual clearly. We hold the plate with
# three pins (its supports then act on top of a held plate) to show the dual.

# %%
try:
    formulate(d, "dual")
except pq.ProblemError as exn:
    print("refused:", exn)

held = pq.Scene(name="nb1-held", plate=scene.plate, mesh=scene.mesh, loads=scene.loads,
                supports=[s for s in supports if (s.x, s.y) not in ((0, 0), (1, 0), (0, 1))],
                pins=[pq.Pin(0.0, 0.0), pq.Pin(1.0, 0.0), pq.Pin(0.0, 1.0)])
dh = Scaled.from_model(build_model(held))
dual = formulate(dh, "dual")
R = cp.Variable(dh.m)
cp.Problem(cp.Minimize(0.5 * cp.quad_form(R, cp.psd_wrap(dual.lcp.M)) + dual.lcp.q @ R), [R >= 0]).solve(solver="CLARABEL")
cond_h = formulate(dh, "condensed")
zh = cp.Variable(dh.m)
cp.Problem(cp.Minimize(0.5 * cp.quad_form(zh, cp.psd_wrap(cond_h.lcp.M)) + cond_h.lcp.q @ zh), [zh >= 0]).solve(solver="CLARABEL")
print("dual      R:", np.round(R.value, 5))
print("condensed R:", np.round(cond_h.lcp.M @ zh.value + cond_h.lcp.q, 5))

# %% [markdown]
# ## The KKT conditions, checked by hand (primal solution of the floating plate)

# %%
gap = d.g0 - d.B @ u_p
stationarity = np.linalg.norm(d.K @ u_p - d.f + d.B.T @ R_p) / np.linalg.norm(d.f)
print(f"stationarity      {stationarity:.1e}")
print(f"min gap           {gap.min():.1e}   (>= 0 up to the solver tolerance)")
print(f"min reaction      {R_p.min():.1e}   (>= 0)")
print(f"max |R_i gap_i|   {np.abs(R_p * gap).max():.1e}")
assert stationarity < 1e-6 and gap.min() > -1e-6 and R_p.min() > -1e-6
np.testing.assert_allclose(R_p, R_c, atol=1e-5 * np.abs(R_c).max())   # primal and condensed agree

# %% [markdown]
# ## The same through plateqp, in the user's units, with its own KKT report

# %%
res = pq.solve(scene, backend="lemke", formulation="condensed", accuracy="high")
print(res.status, res.kkt.as_dict())
print("reactions:", np.round(res.reactions, 3), " sum:", res.reactions.sum(), "= load", 50 + 5)
np.testing.assert_allclose(res.reactions / d.F0, R_c, atol=1e-5 * np.abs(R_c).max())

# %% [markdown]
# ## One answer, three routes
#
# The reactions of the nine supports from the primal QP (cvxpy's multipliers), the condensed QP
# (R = M z + q) and plateqp's Lemke on the condensed LCP (in the user's units, scaled back). The
# bars coincide: three formulations of one convex problem have one solution.

# %%
import matplotlib.pyplot as plt
k = np.arange(d.m)
fig, ax = plt.subplots(figsize=(6, 2.8))
ax.bar(k - 0.25, R_p, 0.25, label="primal (multipliers)")
ax.bar(k, R_c, 0.25, label="condensed (M z + q)")
ax.bar(k + 0.25, res.reactions / d.F0, 0.25, label="plateqp lemke")
ax.set_xlabel("support"); ax.set_ylabel("reaction (scaled)"); ax.legend(fontsize=7)
fig.tight_layout(); plt.show()

# %% [markdown]
# ### Exercise 1: statics
#
# The plate floats: the nine supports carry the whole load. Check, in the user's units, that the
# reactions balance the point load (50 at (0.6, 0.4)) and the uniform load (5 per unit area on the
# unit square, its resultant 5 at the centre): the force and the moments about both axes.

# %%
xs = np.array([s.x for s in supports]); ys = np.array([s.y for s in supports])
R = res.reactions
print(f"force {R.sum():.6f}, moment about y-axis {R @ xs:.6f}, about x-axis {R @ ys:.6f}")
assert abs(R.sum() - (50 + 5)) < 1e-8 * 55
assert abs(R @ xs - (50 * 0.6 + 5 * 0.5)) < 1e-8 * 55
assert abs(R @ ys - (50 * 0.4 + 5 * 0.5)) < 1e-8 * 55

# %% [markdown]
# ### Exercise 2: break it, make every support two-sided
#
# Replace the one-sided constraints B u ≤ g0 by equalities B u = g0 (every support holds the plate
# both ways, as a linear FE model would). Solve, and check which KKT condition fails: stationarity
# and statics still hold, but dual feasibility R ≥ 0 does not (some supports pull the plate down).

# %%
u2 = cp.Variable(d.n)
eq = [d.B @ u2 == d.g0]
cp.Problem(cp.Minimize(0.5 * cp.quad_form(u2, cp.psd_wrap(d.K)) - d.f @ u2), eq).solve(solver="CLARABEL")
R2 = eq[0].dual_value
stat2 = np.linalg.norm(d.K @ u2.value - d.f + d.B.T @ R2) / np.linalg.norm(d.f)
print(f"stationarity {stat2:.1e}, reactions (scaled): {np.round(R2, 3)}")
assert stat2 < 1e-6                                  # still in equilibrium
assert abs(R2.sum() - R_p.sum()) < 1e-6 * R_p.sum()  # statics holds too
assert R2.min() < 0                                  # but dual feasibility fails: tension

# %% [markdown]
# ### Exercise 3: complementarity, support by support
#
# From the Lemke answer, list each support's gap (from `res.gaps`) and reaction, and check that at
# every support one of the two is zero, and that the supports in contact (`res.active`) are those
# with a reaction.

# %%
scale = np.abs(res.reactions).max()
for i, (g, r) in enumerate(zip(res.gaps, res.reactions)):
    print(f"support {i}: gap {g:.2e}, reaction {r:8.4f}")
assert np.all(np.minimum(np.abs(res.gaps) / abs(d.W), np.abs(res.reactions) / scale) < 1e-9)
assert np.array_equal(res.active, res.reactions > 1e-9 * scale)

# %% [markdown]
# ## Summary
#
# * Primal (displacements), condensed (gaps) and dual (reactions) are three convex QPs with one
#   solution; the dual needs a held plate because it needs K⁻¹.
# * KKT: stationarity, gap ≥ 0, R ≥ 0, R · gap = 0. A two-sided model keeps the first two and loses
#   R ≥ 0.
# * The condensed KKT system is the LCP R = M z + q, z ≥ 0, R ≥ 0, zᵀR = 0: lesson 4 solves it by
#   Lemke's method.
