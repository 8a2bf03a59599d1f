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
# # 1. A 1-D warm-up: a beam on rigid obstacles
#
# Before plates, the smallest contact problem with all the ingredients: a simply supported
# Euler–Bernoulli beam (span L, bending stiffness EI) under a uniform load q, above rigid
# one-sided obstacles with initial gaps g. The beam may touch an obstacle, never pass through it,
# and an obstacle can only push.
#
# We discretise by hand with **Hermite cubic elements** (deflection w and slope θ = w′ at each
# node; w positive downwards), then solve the contact problem twice:
#
# * as a **QP** in cvxpy: minimise ½ uᵀKu − fᵀu subject to B u ≤ g (B picks w at the obstacles);
# * as an **LCP** in the reactions: gap = G R + d ≥ 0, R ≥ 0, Rᵀgap = 0, with the flexibility
#   G = B K⁻¹ Bᵀ and d = g − B K⁻¹ f, solved by plateqp's Lemke.
#
# Hermite cubics reproduce the exact Euler–Bernoulli deflection at the nodes for these loads, so
# the closed forms below must come out to rounding.


# %% [markdown]
# ## Learning goals
#
# * pose a one-sided contact problem as a QP (minimise the potential energy subject to
#   gap ≥ 0) and as an LCP in the reactions (R ≥ 0, gap ≥ 0, R · gap = 0);
# * build the beam's stiffness from Hermite cubics by hand and see that its flexibility at the
#   nodes is exact;
# * check every answer against closed forms: the midspan reaction, the lift-off load,
#   superposition for three obstacles, statics;
# * see that the contact set is part of the answer, not of the data.

# %%
import numpy as np
import cvxpy as cp
import matplotlib.pyplot as plt
from plateqp.backends.lemke import lemke

L, EI, q = 4.0, 2.0e6, 1.0e4          # m, N m², N/m
nel = 8                               # elements; nodes at L/8, ..., the midspan is node 4
h = L / nel
x_nodes = np.linspace(0.0, L, nel + 1)

def beam(q):
    """Stiffness and consistent load of the whole beam, dofs (w0, θ0, w1, θ1, ...)."""
    ke = EI / h**3 * np.array([[12, 6 * h, -12, 6 * h],
                               [6 * h, 4 * h**2, -6 * h, 2 * h**2],
                               [-12, -6 * h, 12, -6 * h],
                               [6 * h, 2 * h**2, -6 * h, 4 * h**2]])
    fe = q * h * np.array([1 / 2, h / 12, 1 / 2, -h / 12])
    n = 2 * (nel + 1)
    K, f = np.zeros((n, n)), np.zeros(n)
    for e in range(nel):
        dofs = np.arange(2 * e, 2 * e + 4)
        K[np.ix_(dofs, dofs)] += ke
        f[dofs] += fe
    return K, f

K_full, f_full = beam(q)
free = np.setdiff1d(np.arange(2 * (nel + 1)), [0, 2 * nel])   # w = 0 at both ends (simple supports)
K, f = K_full[np.ix_(free, free)], f_full[free]
print(f"{free.size} free dofs; K symmetric positive definite: {np.linalg.eigvalsh(K).min() > 0}")

# %% [markdown]
# ## One obstacle at midspan: the closed form
#
# Without the obstacle the midspan deflection is 5 q L⁴ / (384 EI). If that exceeds the gap g,
# the beam touches, and the reaction follows from superposition with a point force R at
# midspan (deflection R L³ / (48 EI) upwards):
#
#     R = (5 q L⁴ / (384 EI) − g) · 48 EI / L³      (when positive, else 0)
#
# The lift-off load, below which the beam does not touch, is q* = 384 EI g / (5 L⁴).

# %%
g = 0.010                                            # m
B = np.zeros((1, free.size)); B[0, list(free).index(2 * (nel // 2))] = 1.0   # w at midspan

R_closed = max(0.0, (5 * q * L**4 / (384 * EI) - g) * 48 * EI / L**3)
q_star = 384 * EI * g / (5 * L**4)
print(f"free midspan deflection {5 * q * L**4 / (384 * EI) * 1e3:.3f} mm > gap {g * 1e3:.1f} mm")
print(f"closed form: R = {R_closed:.3f} N,  lift-off load q* = {q_star:.1f} N/m")

# %% [markdown]
# ### As a QP
# The obstacle is one linear inequality on the midspan deflection, B u ≤ g. The reaction is its
# multiplier, which cvxpy returns as the constraint's `dual_value`.

# %%
u = cp.Variable(free.size)
contact = [B @ u <= g]
cp.Problem(cp.Minimize(0.5 * cp.quad_form(u, cp.psd_wrap(K)) - f @ u), contact).solve(solver="CLARABEL")
R_qp = contact[0].dual_value
print(f"QP  (cvxpy):   R = {R_qp[0]:.6f} N")
assert abs(R_qp[0] - R_closed) <= 1e-5 * R_closed              # interior point: to its tolerance

# %% [markdown]
# ### As an LCP
# Eliminating u leaves the reactions: the gap left is gap = G R + d with the flexibility
# G = B K⁻¹ Bᵀ and d the gap the beam would leave without the obstacle. Complementarity
# (R ≥ 0, gap ≥ 0, R·gap = 0) is the LCP that Lemke's method solves by pivoting, exactly.

# %%
Kinv_Bt = np.linalg.solve(K, B.T)
G = B @ Kinv_Bt                         # flexibility: deflection at the obstacle per unit force there
d = g - B @ np.linalg.solve(K, f)       # the gap the beam would leave without the obstacle
R_lcp = lemke(G, d).x
print(f"LCP (Lemke):   R = {R_lcp[0]:.9f} N")
print(f"G = {G[0, 0]:.6e} m/N,  L³/(48 EI) = {L**3 / (48 * EI):.6e} m/N")

assert abs(G[0, 0] - L**3 / (48 * EI)) <= 1e-12 * G[0, 0]      # nodally exact flexibility
assert abs(R_lcp[0] - R_closed) <= 1e-9 * R_closed             # exact method: to rounding

# %% [markdown]
# ## The reaction against the load: zero, then linear
#
# Below q* the obstacle carries nothing; above it R grows with slope 5L/8 (the share of the
# load a rigid midspan support takes). The kink is the change of the contact set.

# %%
qs = np.linspace(0.0, 2.5 * q_star, 51)
R_of_q = np.array([lemke(G, g - B @ np.linalg.solve(K, beam(qi)[1][free]))
                   .x[0] for qi in qs])
R_formula = np.maximum(0.0, 5 * qs * L / 8 - 48 * EI * g / L**3)
assert np.allclose(R_of_q, R_formula, rtol=0, atol=1e-9 * R_formula.max())

fig, ax = plt.subplots(figsize=(5.5, 3))
ax.plot(qs / 1e3, R_of_q / 1e3, "o", ms=3, label="Lemke on the Hermite model")
ax.plot(qs / 1e3, R_formula / 1e3, "k-", lw=0.8, label="closed form")
ax.axvline(q_star / 1e3, color="grey", ls=":", lw=0.8)
ax.annotate("lift-off load q*", (q_star / 1e3, 0), xytext=(-90, 40), textcoords="offset points", fontsize=8)
ax.set_xlabel("q [kN/m]"); ax.set_ylabel("R [kN]"); ax.legend(fontsize=8); fig.tight_layout()
plt.show()

# %% [markdown]
# ## Three obstacles: which ones touch?
#
# Obstacles at L/4, L/2 and 3L/4 with different gaps (the middle one lowest). Now the contact set is the unknown: the
# solvers find it. As an independent check we take the contact set they found and solve the
# beam by **superposition of closed forms** (uniform load plus point forces on a simply
# supported beam), then confirm that the obstacles left out really have a gap.

# %%
x_obs = np.array([L / 4, L / 2, 3 * L / 4])
g_obs = np.array([0.0095, 0.016, 0.0098])
B3 = np.zeros((3, free.size))
for i, xo in enumerate(x_obs):
    B3[i, list(free).index(2 * int(round(xo / h)))] = 1.0

u3 = cp.Variable(free.size)
c3 = [B3 @ u3 <= g_obs]
cp.Problem(cp.Minimize(0.5 * cp.quad_form(u3, cp.psd_wrap(K)) - f @ u3), c3).solve(solver="CLARABEL")
G3 = B3 @ np.linalg.solve(K, B3.T)
d3 = g_obs - B3 @ np.linalg.solve(K, f)
R3 = lemke(G3, d3).x
u_lcp = np.linalg.solve(K, f - B3.T @ R3)
print("QP  reactions [N]:", np.round(c3[0].dual_value, 3))
print("LCP reactions [N]:", np.round(R3, 6))
print("gaps left [mm]:   ", np.round((g_obs - B3 @ u_lcp) * 1e3, 6))


# %% [markdown]
# ### The contact set, checked by closed forms
# Deflection of a simply supported beam under the uniform load, and under a unit point force at
# a (Euler–Bernoulli): on the touching obstacles the gap is zero, which fixes their reactions;
# on the others the gap must come out non-negative.

# %%
# closed forms (Euler-Bernoulli, simply supported): uniform load, and a point force P at a
def w_uniform(x):
    return q * x * (L**3 - 2 * L * x**2 + x**3) / (24 * EI)
def w_point(x, a):              # deflection at x per unit force at a
    lo, hi = np.minimum(x, a), np.maximum(x, a)
    return lo * (L - hi) * (2 * L * hi - hi**2 - lo**2) / (6 * L * EI)

A = np.flatnonzero(R3 > 0)
flex = w_point(x_obs[:, None], x_obs[None, :])
R_super = np.zeros(3)
R_super[A] = np.linalg.solve(flex[np.ix_(A, A)], w_uniform(x_obs[A]) - g_obs[A])   # touching: gap = 0
gap_super = g_obs - (w_uniform(x_obs) - flex @ R_super)
print("superposition:   ", np.round(R_super, 6), " contact set", A.tolist())
assert np.allclose(R3, R_super, rtol=0, atol=1e-9 * R_super.max())
assert np.all(R_super >= 0) and np.all(gap_super >= -1e-12)        # a consistent contact set
assert np.allclose(c3[0].dual_value, R_super, rtol=0, atol=1e-5 * R_super.max())
assert np.allclose(G3, flex, rtol=1e-12)                           # the Hermite flexibility is exact

# %% [markdown]
# ### Statics
# The end supports' reactions come from the full stiffness (K u − f on the eliminated dofs);
# with the obstacles' they carry the whole load.

# %%
# statics: the end reactions (from the full stiffness) and the obstacles carry the whole load
u_all = np.zeros(2 * (nel + 1)); u_all[free] = u_lcp
ends = -(K_full @ u_all - f_full)[[0, 2 * nel]]     # upward forces (w is downward)
print(f"end reactions {np.round(ends, 3)} N; total {ends.sum() + R3.sum():.6f} N = q L = {q * L:.1f} N")
assert abs(ends.sum() + R3.sum() - q * L) <= 1e-9 * q * L


# %% [markdown]
# ## Deflection and contact forces
#
# The deflection between the nodes comes from the Hermite shape functions; the triangles are
# the obstacles' tops at their gap level, the bars the contact forces (upwards: an obstacle can
# only push). The middle obstacle, the lowest, is not reached.

# %%
def deflection_curve(u_all, n=20):
    xi = np.linspace(0.0, 1.0, n)
    N = np.array([1 - 3 * xi**2 + 2 * xi**3, h * (xi - 2 * xi**2 + xi**3),
                  3 * xi**2 - 2 * xi**3, h * (-xi**2 + xi**3)])
    xs = np.concatenate([x_nodes[e] + h * xi for e in range(nel)])
    ws = np.concatenate([N.T @ u_all[2 * e: 2 * e + 4] for e in range(nel)])
    return xs, ws

u_free = np.zeros(2 * (nel + 1)); u_free[free] = np.linalg.solve(K, f)
fig, (ax, bx) = plt.subplots(2, 1, figsize=(6.5, 4.5), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
for uu, style, label in ((u_free, "--", "no obstacles"), (u_all, "-", "on the obstacles")):
    xs, ws = deflection_curve(uu)
    ax.plot(xs, ws * 1e3, style, label=label)
ax.plot(x_obs, g_obs * 1e3, "k^", ms=9, label="obstacle tops (gap g)")
ax.plot(xs, w_uniform(xs) * 1e3 - sum(w_point(xs, a) * r for a, r in zip(x_obs, R3)) * 1e3, "k:", lw=0.8,
        label="closed form (superposition)")
ax.invert_yaxis(); ax.set_ylabel("w [mm] (down)"); ax.legend(fontsize=7)
bx.bar(x_obs, R3 / 1e3, width=0.08, color="C3")
for xo, r in zip(x_obs, R3):
    bx.annotate(f"{r / 1e3:.2f} kN", (xo, r / 1e3), ha="center", va="bottom", fontsize=8)
bx.set_ylabel("R [kN] (up)"); bx.set_xlabel("x [m]"); bx.set_ylim(0, 1.3 * R3.max() / 1e3)
fig.tight_layout()
plt.show()

# %% [markdown]
# **What to take to the plate.** The same three ingredients come back in two dimensions:
# a stiffness K from elements, an operator B that reads the deflection at the contact points,
# and a QP whose multipliers are the reactions (or, after condensation, an LCP). What changes is
# size, and that the plate's flexibility G has no closed form: lesson 6 builds it by hand.

# %% [markdown]
# ### Exercise 1: a point load instead
#
# Remove the uniform load and put a point load P = 20 kN at midspan, above the obstacle with gap
# g = 10 mm. The beam touches when its free deflection P L³ / (48 EI) exceeds g, and then the
# obstacle carries R = P − 48 EI g / L³ (the rest goes to the ends). Solve it as an LCP with the
# Hermite model (G and d as above) and check the closed form.

# %%
P = 20e3
f_P = np.zeros(free.size); f_P[list(free).index(2 * (nel // 2))] = P
d_P = g - B @ np.linalg.solve(K, f_P)
R_P = lemke(G, d_P).x[0]
R_P_closed = max(0.0, P - 48 * EI * g / L**3)
print(f"free deflection {P * L**3 / (48 * EI) * 1e3:.2f} mm; R Lemke {R_P:.6f} N, closed form {R_P_closed:.6f} N")
assert R_P_closed > 0 and abs(R_P - R_P_closed) <= 1e-9 * R_P_closed

# %% [markdown]
# ### Exercise 2: break it, glue the beam to all three obstacles
#
# A two-sided model keeps every obstacle in contact: gap = 0 at all three, the linear system
# G R = d instead of the LCP. Solve it, and check what goes wrong: statics still holds (the ends
# and obstacles carry q L), but obstacles now pull the beam down, R < 0, which a rigid obstacle
# cannot do: held at the top of the middle obstacle (which the one-sided beam leaves), the beam
# is lifted there, and the outer obstacles must hold it down.

# %%
R_glued = np.linalg.solve(G3, d3)
u_glued = np.zeros(2 * (nel + 1)); u_glued[free] = np.linalg.solve(K, f - B3.T @ R_glued)
ends_glued = -(K_full @ u_glued - f_full)[[0, 2 * nel]]
print("glued reactions [N]:", np.round(R_glued, 3), "| one-sided:", np.round(R3, 3))
assert abs(ends_glued.sum() + R_glued.sum() - q * L) <= 1e-9 * q * L   # statics holds
assert R_glued.min() < 0                                              # but one obstacle pulls

# %% [markdown]
# ## Summary
#
# * One-sided contact is a QP in the displacements and an LCP in the reactions; both give the
#   closed-form answers here (to the QP solver's tolerance, and to rounding for Lemke).
# * The flexibility G = B K⁻¹ Bᵀ of a Hermite beam is exact at the nodes, so the 1-D problem has
#   no discretisation error at the obstacles.
# * The contact set is unknown in advance; guessing it (gluing) keeps statics but breaks R ≥ 0.
# * Lesson 2 draws the same problem for two supports: the geometry of the QP.
