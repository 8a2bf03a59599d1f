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
# # 11. Gaps as design variables: sensitivities, paths and regulation
#
# The source paper ends with "control the interaction forces by changing the gaps". While the
# contact set holds, the reactions are **linear** in the initial gaps: R(g0) = R(0) + S g0, with
# S = dR/dg0 from the active set (implicit differentiation of the KKT system). This notebook
# checks S against a closed form and finite differences, follows a settlement exactly through a
# change of the working scheme, and regulates the gaps for target reactions.
#
# The scene: a free square plate (side a) on four rigid corner supports under a uniform load q.
# By symmetry and statics each corner carries q a²/4.


# %% [markdown]
# ## Learning goals
#
# * compute the sensitivity of the reactions to the gaps, dR/dg0, and check it against the
#   closed form of a plate on four corners (a twist mode) and against finite differences;
# * follow an exact path of the reactions as one support settles, through a lift-off at the
#   closed-form settlement δ* = q a⁴ / (8 D (1 − ν));
# * regulate: find the gaps that give prescribed reactions, and check them by solving again;
# * know when the linear prediction R + S Δg holds (a fixed contact set) and when it fails.

# %%
import numpy as np
import plateqp as pq
from plateqp.studies import exact_path, regulate_gaps

a, h, E, nu, q = 1.0, 0.01, 2.1e11, 0.3, 1000.0
D = E * h**3 / (12 * (1 - nu**2))
corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
scene = pq.Scene(name="corners", plate=pq.Plate(a, a, h, E, nu), mesh=pq.MeshSpec(8, 8),
                 loads=[pq.UniformLoad(q)], supports=[pq.Support(x, y) for x, y in corners])
res = pq.solve(scene, backend="lemke", accuracy="high")
print("reactions", res.reactions.round(6), "  q a²/4 =", q * a**2 / 4)

# %% [markdown]
# ## The sensitivity matrix against the closed form
#
# The only redundant reaction pattern is the twist (+, −, +, −); its stiffness is
# k = 2 D (1 − ν) / a² (Kirchhoff theory: the pure twist w = c x y, which the ACM element
# represents exactly). So dR_i/dg0_j = −k p_i p_j with p = (1, −1, 1, −1): settling a corner
# unloads it and the opposite corner by k per unit of settlement, and loads the other two.

# %%
S = pq.sensitivity(res, "gaps")
k = 2 * D * (1 - nu) / a**2
print("dR_i/dg0_j in units of k = 2D(1-nu)/a^2:")
print((np.asarray(S) / k).round(9))
p = np.array([1.0, -1.0, 1.0, -1.0])
assert np.allclose(np.asarray(S), -k * np.outer(p, p), rtol=1e-9, atol=1e-9 * k)
assert np.allclose(np.asarray(S).sum(axis=0), 0.0, atol=1e-9 * k)   # statics: a settlement moves no net force

# %% [markdown]
# ## The multiplier as a sensitivity, by finite differences
#
# A small settlement of support 3 (the active set does not change) moves the reactions by the
# third column of S.

# %%
dg = 1e-7
g = np.zeros(4); g[2] = dg
res2 = pq.solve(pq.Scene(name="c2", plate=scene.plate, mesh=scene.mesh, loads=scene.loads,
                         supports=[pq.Support(x, y, gap=gi) for (x, y), gi in zip(corners, g)]),
                backend="lemke", accuracy="high")
fd = (res2.reactions - res.reactions) / dg
print("finite difference of column 3:", fd.round(3))
print("exact column 3:               ", np.asarray(S)[:, 2].round(3))
assert np.allclose(fd, np.asarray(S)[:, 2], rtol=1e-5, atol=1e-5 * k)

# %% [markdown]
# ## An exact path through a change of the working scheme
#
# Settle support 3 further: its reaction falls linearly until it reaches zero at
# δ* = (q a²/4) / k = q a⁴ / (8 D (1 − ν)), where the plate lifts off it. `exact_path` follows the
# piecewise-linear solution by parametric pivoting and reports the breakpoint exactly (to
# rounding), with no bisection.

# %%
delta_star = q * a**4 / (8 * D * (1 - nu))
path = exact_path(scene, "supports.3.gap", 0.0, 2 * delta_star)
print(path)
b = path.breakpoints[0]
print(f"lift-off at {b['at']:.12g}; closed form q a^4 / (8 D (1 - nu)) = {delta_star:.12g}")
assert abs(b["at"] - delta_star) <= 1e-9 * delta_star

# %% [markdown]
# ## The reactions along the path (the kink is the breakpoint)

# %%
import matplotlib.pyplot as plt  # the notebook's own (inline) backend: the figure shows
t = np.linspace(0.0, 2 * delta_star, 81)
R = np.array([path.reactions(ti) for ti in t])
fig, ax = plt.subplots(figsize=(6, 3.2))
for i in range(4):
    ax.plot(t / delta_star, R[:, i], label=f"support {i + 1}")
ax.axvline(1.0, color="k", lw=0.8, ls=":")
ax.set_xlabel("settlement of support 3 / δ*"); ax.set_ylabel("reaction"); ax.legend(fontsize=7)
fig.tight_layout()
plt.show()

# %% [markdown]
# ## Regulation: the gaps that give target reactions
#
# `regulate_gaps` (on the command line: `plateqp regulate SCENE --target ...`) finds initial
# gaps that make the supports carry the reactions asked, here 300, 200, 300, 200 (in
# equilibrium with the load). The regulated scene, solved again, gives them; and since the
# contact set does not change, the sensitivity matrix predicts the same.

# %%
reg = regulate_gaps(scene, [300.0, 200.0, 300.0, 200.0], backend="lemke")
print("gaps for R = (300, 200, 300, 200):", reg.gaps)
check = pq.solve(reg.scene, backend="lemke", accuracy="high")
print("reactions of the regulated scene:", check.reactions.round(6))
assert np.allclose(check.reactions, [300, 200, 300, 200], rtol=1e-9)
# the same from the sensitivities: the reactions are linear in the gaps while the contact set holds
pred = res.reactions + np.asarray(S) @ reg.gaps
assert np.allclose(pred, [300, 200, 300, 200], rtol=1e-9)

# %% [markdown]
# ### Exercise 1: a settlement predicted by the sensitivity
#
# Settle support 1 by δ = δ*/2 (below the lift-off value, so all four corners stay in contact).
# The closed form is R_i = q a²/4 − k p_i p_1 δ with the twist mode p = (1, −1, 1, −1): predict
# the reactions with it, solve the settled scene, and check both against each other and statics
# (the four reactions carry q a²).

# %%
def settled(i, d):
    gi = np.zeros(4); gi[i] = d
    return pq.Scene(name="settled", plate=scene.plate, mesh=scene.mesh, loads=scene.loads,
                    supports=[pq.Support(x, y, gap=g_) for (x, y), g_ in zip(corners, gi)])

d = delta_star / 2
R_half = pq.solve(settled(0, d), backend="lemke", accuracy="high").reactions
R_pred = q * a**2 / 4 - k * p * p[0] * d
print("solved:   ", R_half.round(6), "\npredicted:", R_pred.round(6))
assert np.allclose(R_half, R_pred, rtol=1e-8, atol=1e-8 * q * a**2)
assert abs(R_half.sum() - q * a**2) < 1e-9 * q * a**2

# %% [markdown]
# ### Exercise 2: break it, settle past the lift-off
#
# Settle support 1 by 1.5 δ*. The linear prediction now asks support 1 for a negative reaction,
# a pull the corner cannot give; the solved scene has lifted off there instead (R = 0, and the
# opposite corner 3 with it: a plate on two diagonal corners), and the corners still in contact
# carry the whole load (here the diagonal pair 2 and 4). Check both.

# %%
d = 1.5 * delta_star
R_far = pq.solve(settled(0, d), backend="lemke", accuracy="high").reactions
R_lin = q * a**2 / 4 - k * p * p[0] * d
print("solved:", R_far.round(6), "| linear prediction:", R_lin.round(6))
assert R_lin[0] < 0                                  # the prediction pulls
assert abs(R_far[0]) < 1e-9 * q * a**2               # the plate lifts off instead
assert abs(R_far.sum() - q * a**2) < 1e-9 * q * a**2 and R_far.min() >= -1e-9 * q * a**2

# %% [markdown]
# ## Summary
#
# * While the contact set holds, the reactions are linear in the gaps: R(g0 + Δg) = R + S Δg, with
#   S = `pq.sensitivity(result, "gaps")`, symmetric and negative semidefinite.
# * An exact path through the gaps is piecewise linear, with breakpoints where a support lifts off
#   or touches; the first one here is at the closed-form δ*.
# * Regulation inverts the relation for the gaps that give chosen reactions; a new solve checks it.
#   Past a breakpoint the linear prediction fails and only a new solve tells the truth.
