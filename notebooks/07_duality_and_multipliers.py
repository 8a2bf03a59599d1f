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
# # 7. Duality and multipliers: the reactions as prices
#
# One scene, two minimum principles. With K the plate's stiffness (held by its simply
# supported edges, so K is positive definite), f the loads, B u the deflections at the supports
# (positive down) and g0 the initial gaps (> 0 settlement, < 0 heave):
#
# * **primal** (minimum potential energy): Π(u) = ½ uᵀK u − fᵀu, over the deflections with
#   B u ≤ g0 (no penetration);
# * **dual** (minimum complementary energy): Π_c(R) = ½ (f − BᵀR)ᵀ K⁻¹ (f − BᵀR) + g0ᵀR, over
#   the reactions R ≥ 0 (no tension). The first term is the strain energy of the plate loaded
#   by f and R (statically admissible), the second the work of R through the gaps.
#
# Lagrangian duality: the dual function of the primal is −Π_c(R), so for every feasible pair
# Π(u) + Π_c(R) ≥ 0 (weak duality), with equality exactly at the solution (strong duality: a
# convex QP with feasible points has no duality gap).


# %% [markdown]
# ## Learning goals
#
# * write the potential energy Π(u) and the complementary energy Π_c(R) of one contact problem,
#   and see that their sum vanishes at the solution (no duality gap) and is positive elsewhere;
# * split the gap of any feasible pair into a mismatch of displacements plus complementarity;
# * read the reactions as prices: ∂Π*/∂g0_j = −R_j, checked by finite differences;
# * check plateqp's `sensitivity(result, "gaps")` (symmetric by Maxwell–Betti) against finite
#   differences.

# %%
import numpy as np
import scipy.sparse.linalg as spla
import matplotlib.pyplot as plt  # the notebook's own (inline) backend: the figure shows
import plateqp as pq

posts = [(x, y) for y in (0.25, 0.5, 0.75) for x in (0.25, 0.5, 0.75)]
gap0 = 1e-4 * np.array([0.0, 0.5, -0.5, 1.0, 0.0, -1.0, 0.5, 0.0, 3.0])

def make(gaps):
    return pq.Scene(name="duality", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(12, 12),
                    edges={e: "simple" for e in ("left", "right", "bottom", "top")},
                    loads=[pq.UniformLoad(10.0), pq.PointLoad(100.0, 0.65, 0.6)],
                    supports=[pq.Support(x, y, gap=g) for (x, y), g in zip(posts, gaps)])

solve = lambda gaps: pq.solve(make(gaps), backend="lemke", accuracy="high")
res = solve(gap0)
model = res.model
K, f, B, g = model.K.tocsc(), model.f, model.contacts.B, model.contacts.g0
assert np.allclose(g, gap0)              # the edges prescribe nothing: g0 is the scene's gaps
u_star, R_star = res.u[model.free], res.reactions
K_inv = spla.splu(K)

def Pi(u):                               # potential energy
    return 0.5 * u @ (K @ u) - f @ u

def Pi_c(R):                             # complementary energy
    v = K_inv.solve(f - B.T @ R)         # the deflection the loads and R alone give
    return 0.5 * v @ (K @ v) + g @ R

for j, (p, Rj) in enumerate(zip(posts, R_star)):
    print(f"support {j + 1} at {p}: gap0 {gap0[j] * 1e4:+.1f}e-4  R = {Rj:8.4f}  "
          f"{'contact' if res.active[j] else 'open'}")
print(f"Π(u*) = {Pi(u_star):.12f}   Π_c(R*) = {Pi_c(R_star):.12f}   sum {Pi(u_star) + Pi_c(R_star):.1e}")
assert abs(Pi(u_star) + Pi_c(R_star)) < 1e-12 * abs(Pi(u_star))   # strong duality: no gap
# Clapeyron: at the solution K u* = f − BᵀR* and B u* = g0 where R* > 0, so Π* = −½ (fᵀu* + g0ᵀR*)
assert abs(Pi(u_star) + 0.5 * (f @ u_star + g @ R_star)) < 1e-12 * abs(Pi(u_star))

# %% [markdown]
# ## The duality gap of a feasible pair that is not optimal
#
# Raise every support by δ (gaps g0 − δ) and solve: that deflection u_δ is feasible for the
# original scene (B u_δ ≤ g0 − δ ≤ g0) and its reactions R_δ ≥ 0 are feasible for the dual. For
# any u and R ≥ 0 the gap splits into two non-negative parts (expand the squares):
#
#   Π(u) + Π_c(R) = ½ ‖u − K⁻¹(f − BᵀR)‖²_K + Rᵀ(g0 − B u)
#
# a kinematic/static mismatch and the complementarity product. For (u_δ, R_δ) the mismatch is
# zero (they are in equilibrium with each other) and every support in contact has gap δ, so the
# gap is **δ · Σ R_δ**: it closes linearly as δ → 0.

# %%
deltas = np.logspace(-4, -8, 5)
gaps = []
for d in deltas:
    r = solve(gap0 - d)
    u_d, R_d = r.u[model.free], r.reactions
    assert np.all(B @ u_d <= g + 1e-15) and np.all(R_d >= 0)          # a feasible pair
    gap_d = Pi(u_d) + Pi_c(R_d)
    gaps.append(gap_d)
    # the closed form above, to 1e-8 and to the rounding of the two energies that cancel in gap_d
    floor = 64 * np.finfo(float).eps * (abs(Pi(u_d)) + abs(Pi_c(R_d)))
    assert gap_d > 0 and abs(gap_d - d * R_d.sum()) < 1e-8 * gap_d + floor
    print(f"δ = {d:.0e}: Π(u_δ) + Π_c(R_δ) = {gap_d:.6e}   δ·ΣR_δ = {d * R_d.sum():.6e}")

# a pair not in equilibrium with each other: u_δ and some other non-negative reactions
rng = np.random.default_rng(1)
u_d, R_any = solve(gap0 - 1e-5).u[model.free], rng.uniform(0, 50, len(posts))
v = K_inv.solve(f - B.T @ R_any)
split = 0.5 * (u_d - v) @ (K @ (u_d - v)) + R_any @ (g - B @ u_d)
print(f"any pair: gap {Pi(u_d) + Pi_c(R_any):.6e} = mismatch + complementarity {split:.6e}")
assert abs(Pi(u_d) + Pi_c(R_any) - split) < 1e-10 * split and split > 0

# %% [markdown]
# ## Multipliers are sensitivities
#
# The reaction R_j is the Lagrange multiplier of the constraint (B u)_j ≤ g0_j, so it is the
# rate at which the optimal energy changes with that gap. **Sign convention:** g0_j > 0 is
# settlement. Increasing g0_j gives the plate more room, so the energy can only fall:
#
#   ∂Π*/∂g0_j = −R_j,  or, with the elevation of support j, e_j = −g0_j:  ∂Π*/∂e_j = +R_j.
#
# The reaction is the price of raising the support. We check it by central finite differences
# of Π* = Π(u*(g0)). While the contact set holds, Π* is quadratic in g0, so the central
# difference is exact up to rounding.

# %%
h = 1e-7
dPi, dR = [], []
for j in range(len(posts)):
    e = np.zeros(len(posts)); e[j] = h
    plus, minus = solve(gap0 + e), solve(gap0 - e)
    assert np.array_equal(plus.active, res.active) and np.array_equal(minus.active, res.active)
    dPi.append((Pi(plus.u[model.free]) - Pi(minus.u[model.free])) / (2 * h))
    dR.append((plus.reactions - minus.reactions) / (2 * h))
dPi, dR = np.array(dPi), np.array(dR).T           # dR[i, j] = dR_i / dg0_j
print("−∂Π*/∂g0 by finite differences:", np.round(-dPi, 6))
print("reactions R*:                  ", np.round(R_star, 6))
np.testing.assert_allclose(-dPi, R_star, atol=1e-6 * R_star.max())

# %% [markdown]
# ## The second derivative: `plateqp.sensitivity` against finite differences
#
# Differentiating once more, dR_i/dg0_j = −∂²Π*/∂g0_i∂g0_j. `pq.sensitivity(result, "gaps")`
# gives this matrix S from the active set (implicit differentiation of the KKT system). It must
# match finite differences of the reactions, and as a Hessian it is **symmetric** (Maxwell–Betti
# reciprocity: settling support j changes R_i as much as settling i changes R_j) and negative
# semidefinite. Rows and columns of open supports are zero (their reaction stays 0).

# %%
S = np.asarray(pq.sensitivity(res, "gaps"))
print("dR_i/dg0_j (supports in contact):")
on = np.flatnonzero(res.active)
print("   ", "".join(f"{j + 1:>10d}" for j in on))
for i in on:
    print(f"{i + 1:3d} ", "".join(f"{S[i, j]:10.2f}" for j in on))
np.testing.assert_allclose(S, dR, atol=1e-6 * np.abs(S).max())
assert np.abs(S - S.T).max() < 1e-9 * np.abs(S).max()
assert np.linalg.eigvalsh(S).max() < 1e-9 * np.abs(S).max()
assert np.all(S[~res.active] == 0) and np.all(S[:, ~res.active] == 0)

# %% [markdown]
# ## The gap closing, and the prices

# %%
fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.4))
a1.loglog(deltas, gaps, "o-", label="Π(u_δ) + Π_c(R_δ)")
a1.loglog(deltas, deltas * R_star.sum(), "k--", lw=0.8, label="δ · ΣR* (slope 1)")
a1.set_xlabel("δ (all supports raised)"); a1.set_ylabel("duality gap"); a1.legend(fontsize=8)
idx = np.arange(len(posts))
a2.bar(idx - 0.2, R_star, 0.4, label="R*  (the multipliers)")
a2.bar(idx + 0.2, -dPi, 0.4, label="−∂Π*/∂g0  (finite differences)")
a2.set_xticks(idx, [str(i + 1) for i in idx]); a2.set_xlabel("support"); a2.legend(fontsize=8)
fig.tight_layout()
plt.show()

# %% [markdown]
# ### Exercise 1: weak duality, by sampling
#
# For every displacement u that respects the supports (B u ≤ g0) and every R ≥ 0,
# Π(u) + Π_c(R) ≥ 0: the split above is a sum of a square and a product of two non-negative
# vectors. Check it on the feasible displacements of the raised scenes (one per δ) paired with
# 50 random non-negative reaction vectors each.

# %%
worst = np.inf
for d in deltas:
    u_d = solve(gap0 - d).u[model.free]
    assert np.all(B @ u_d <= g + 1e-15)
    for R_any in rng.uniform(0, 50, (50, len(posts))):
        worst = min(worst, Pi(u_d) + Pi_c(R_any))
print(f"smallest Π(u) + Π_c(R) over {50 * len(deltas)} feasible pairs: {worst:.3e}")
assert worst >= 0

# %% [markdown]
# ### Exercise 2: break it, let the plate penetrate
#
# Weak duality needs u feasible. Lower every support by δ = 1e-5 instead (gap0 + δ): the plate
# then sinks below the original supports, B u > g0 somewhere. Check that the bound fails: the sum
# is now negative, and by the same argument as above it equals −δ · ΣR exactly.

# %%
d = 1e-5
low = solve(gap0 + d)
u_low, R_low = low.u[model.free], low.reactions
sum_low = Pi(u_low) + Pi_c(R_low)
print(f"max penetration {(B @ u_low - g).max():.1e};  Π + Π_c = {sum_low:.6e},  −δ·ΣR = {-d * R_low.sum():.6e}")
assert (B @ u_low - g).max() > 0                         # infeasible: it penetrates
assert sum_low < 0 and abs(sum_low + d * R_low.sum()) < 1e-8 * abs(sum_low) + 64 * np.finfo(float).eps * abs(Pi(u_low))

# %% [markdown]
# ## Summary
#
# * The potential energy (minimised over displacements that respect the supports) and the
#   complementary energy (minimised over reactions R ≥ 0) are dual: at the solution their sum is
#   zero, elsewhere it is positive and measures how far from the solution a pair is.
# * The reactions are the multipliers of the gap constraints and the prices of the gaps:
#   −∂Π*/∂g0_j = R_j.
# * The sensitivity of the reactions to the gaps is symmetric and negative semidefinite; lesson 11
#   uses it to design the gaps.
