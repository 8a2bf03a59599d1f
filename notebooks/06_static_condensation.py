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
# # 6. Static condensation by hand (the paper's route)
#
# The source paper solves contact on the **gaps at the supports only**: every other degree of
# freedom of the plate is eliminated first. This notebook does that elimination by hand with
# SciPy on a small mesh, and shows that it is exactly plateqp's `condensed` formulation:
#
# 1. partition the plate's stiffness into the contact dofs c (the deflections at the posts) and
#    the others o;
# 2. eliminate o: the **Schur complement** S = K_cc − K_co K_oo⁻¹ K_oc, the plate's stiffness
#    seen from the posts, and the condensed load r = f_c − K_co K_oo⁻¹ f_o;
# 3. its inverse is the **flexibility** G = S⁻¹ = B K⁻¹ Bᵀ (the dual formulation's matrix):
#    Gᵢⱼ is the deflection at post i from a unit force at post j;
# 4. both are symmetric (Maxwell–Betti) and positive definite, and the contact problem on the
#    gaps z is LCP(S, r − S g0), which Lemke solves.
#
# The scene: a 10 mm steel plate, 1 m × 1 m, simply supported on its edges, five one-sided posts
# at mesh nodes (some settled), a uniform load and a point load.


# %% [markdown]
# ## Learning goals
#
# * partition a plate's stiffness into contact dofs and the others, and eliminate the others: the
#   Schur complement S = K_cc − K_co K_oo⁻¹ K_oc;
# * check that S is plateqp's condensed matrix, and that its inverse is the flexibility
#   B K⁻¹ Bᵀ (the dual's matrix), symmetric by Maxwell–Betti and close to Navier's series;
# * solve the contact problem on the gaps with Lemke, and rebuild the whole displacement field;
# * see what is lost when the coupling term of the condensation is left out.

# %%
import numpy as np
import scipy.linalg as sla
import matplotlib.pyplot as plt
import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.contact import Scaled, formulate
from plateqp.backends.lemke import lemke

posts = [(0.25, 0.25), (0.75, 0.25), (0.5, 0.5), (0.25, 0.75), (0.75, 0.75)]
g0 = np.array([0.0, 0.1e-3, 0.0, 0.6e-3, 0.0])             # m: settlements of the posts
plate = pq.Plate(1.0, 1.0, 0.01, 2.1e11, 0.3)              # steel, D = E h³ / (12 (1 − ν²))
scene = pq.Scene(name="condensation", plate=plate, mesh=pq.MeshSpec(16, 16),
                 edges={k: "simple" for k in ("left", "right", "bottom", "top")},
                 loads=[pq.UniformLoad(5000.0), pq.PointLoad(2000.0, 0.625, 0.375)],
                 supports=[pq.Support(x, y, gap=g) for (x, y), g in zip(posts, g0)])
model = build_model(scene)
K, f = model.K.toarray(), model.f                          # free dofs (edge deflections eliminated)
B = model.contacts.B.toarray()                             # (posts × dofs): w at each post
print(f"K: {K.shape[0]} dofs;  B: {B.shape}, one non-zero per row: {np.all((B != 0).sum(axis=1) == 1)}")

# %% [markdown]
# ## 1–2. Partition and eliminate
#
# The posts sit on mesh nodes, so each row of B picks one deflection dof: those are c. For the
# others, the equilibrium rows K_oo u_o + K_oc u_c = f_o give u_o for any u_c; put back into
# the rows of c this leaves S u_c = r − R, R the posts' (upward) reactions. One dense Cholesky
# factorisation of K_oo does it.

# %%
c = np.argmax(np.abs(B), axis=1)                            # the contact dofs, in post order
o = np.setdiff1d(np.arange(K.shape[0]), c)
K_oo, K_oc, K_cc = K[np.ix_(o, o)], K[np.ix_(o, c)], K[np.ix_(c, c)]
chol = sla.cho_factor(K_oo)                                 # K_oo: the plate with every post held
S = K_cc - K_oc.T @ sla.cho_solve(chol, K_oc)              # N/m
r = f[c] - K_oc.T @ sla.cho_solve(chol, f[o])              # N
print("S [kN/mm] =\n", (S / 1e6).round(3))
print("r [N] =", r.round(2), " (the reactions if every post were rigid and level)")

# %% [markdown]
# ## The same matrix as plateqp's condensed formulation
#
# plateqp condenses with one sparse factorisation with the contact dofs ordered last, in its
# nondimensional units (gaps by W, forces by F0). Converted back, its LCP matrix is our S and
# its vector is r − S g0.

# %%
data = Scaled.from_model(model)
cond = formulate(data, "condensed").lcp
M_pq = cond.M * data.F0 / data.W
q_pq = cond.q * data.F0
print(f"max |M_plateqp − S| / max |S| = {np.abs(M_pq - S).max() / np.abs(S).max():.1e}")
print(f"max |q_plateqp − (r − S g0)| / max |q| = {np.abs(q_pq - (r - S @ g0)).max() / np.abs(q_pq).max():.1e}")
assert np.allclose(M_pq, S, rtol=0, atol=1e-10 * np.abs(S).max())
assert np.allclose(q_pq, r - S @ g0, rtol=0, atol=1e-10 * np.abs(q_pq).max())

# %% [markdown]
# ## 3. Symmetric, positive definite, and what the entries mean
#
# * S is symmetric because K is, and positive definite because K is (the simply supported
#   edges hold the plate: no motion is free of strain): a Cholesky factorisation of S succeeds.
# * **Sᵢⱼ** (a stiffness): the force at post i when post j is pushed down by a unit deflection and
#   every other post is held at zero. Sⱼⱼ > 0; the nearest posts must pull down to stay put
#   (negative entries), a far one may have to push (S₁₅ > 0 here: the plate bends back up
#   beyond the centre post that holds it).
# * **Gᵢⱼ = (S⁻¹)ᵢⱼ** (a flexibility): the deflection at post i from a unit force at post j, with
#   only the edges holding the plate. It is B K⁻¹ Bᵀ, and the dual formulation's matrix. Gᵢⱼ = Gⱼᵢ is
#   **Maxwell–Betti**'s reciprocity.
#
# The flexibility has an external reference: Navier's double sine series for a simply supported
# rectangle under a unit point force at (ξ, η),
#
#     w(x, y) = 4 / (π⁴ D a b) Σₘ Σₙ sin(mπξ/a) sin(nπη/b) sin(mπx/a) sin(nπy/b) / ((m/a)² + (n/b)²)²,
#
# symmetric in (x, y) ↔ (ξ, η) term by term. The finite-element G must agree with it to the
# discretisation error (about 1 % at 16 × 16 elements).

# %%
sla.cholesky(S)                                             # succeeds: S is positive definite
print("eigenvalues of S [kN/mm]:", (np.linalg.eigvalsh(S) / 1e6).round(3))
print(f"asymmetry of S: {np.abs(S - S.T).max() / np.abs(S).max():.1e}")
assert np.all(np.linalg.eigvalsh(S) > 0) and np.allclose(S, S.T, rtol=0, atol=1e-12 * np.abs(S).max())
assert np.all(np.diag(S) > 0) and np.all(S[2, [0, 1, 3, 4]] < 0)    # the centre post's neighbours pull
assert S[0, 4] > 0                                                  # the far corner post pushes

G = B @ np.linalg.solve(K, B.T)                             # m/N: unit forces at the posts
G_dual = formulate(data, "dual").lcp.M * data.W / data.F0
print(f"|G − S⁻¹| / |G| = {np.abs(G - np.linalg.inv(S)).max() / np.abs(G).max():.1e},  "
      f"|G − dual| / |G| = {np.abs(G - G_dual).max() / np.abs(G).max():.1e}")
assert np.allclose(G, np.linalg.inv(S), rtol=0, atol=1e-10 * np.abs(G).max())
assert np.allclose(G, G_dual, rtol=0, atol=1e-10 * np.abs(G).max())

def navier(x, y, xi, eta, n=300):
    k = np.arange(1, n + 1)
    a, b, D = plate.a, plate.b, plate.D
    sx, sy = np.sin(k * np.pi * x / a) * np.sin(k * np.pi * xi / a), np.sin(k * np.pi * y / b) * np.sin(k * np.pi * eta / b)
    return 4 / (np.pi**4 * D * a * b) * (np.outer(sx, sy) / ((k[:, None] / a)**2 + (k[None, :] / b)**2)**2).sum()

G_navier = np.array([[navier(*pi, *pj) for pj in posts] for pi in posts])
print("G [mm/kN] (finite elements):\n", (G * 1e6).round(5))
print("relative difference to Navier's series:\n", ((G - G_navier) / G_navier).round(4))
assert np.all(np.abs(G - G_navier) <= 0.015 * G_navier)

# %% [markdown]
# The difference is the discretisation error, not a mistake: on a mesh twice as fine (a sparse
# LU this time, 3 000 dofs) it falls about fourfold, as the element's h² convergence says (a
# little less on the diagonal, where the point force's logarithmic singularity sits).

# %%
import dataclasses
from scipy.sparse.linalg import splu
fine = build_model(dataclasses.replace(scene, mesh=pq.MeshSpec(32, 32)))
Bf = fine.contacts.B
G_fine = Bf @ splu(fine.K.tocsc()).solve(Bf.T.toarray())
err16, err32 = np.abs(G - G_navier) / G_navier, np.abs(G_fine - G_navier) / G_navier
print(f"largest difference to Navier: {err16.max():.2%} at 16 x 16, {err32.max():.2%} at 32 x 32")
print("ratio per entry:\n", (err16 / err32).round(2))
assert np.all(err32 < 0.004) and np.all(err16 > 3 * err32)

# %% [markdown]
# ## 4. The contact problem on the gaps, solved by Lemke
#
# With the posts settled by g0 the gaps left are z = g0 − u_c and the posts' reactions are
# R = S z + r − S g0 (the forces needed to hold the plate at u_c). One-sided contact is the LCP
# z ≥ 0, R ≥ 0, zᵀR = 0. After Lemke, the plate's other dofs come back from the same
# factorisation: u_o = K_oo⁻¹ (f_o − K_oc u_c).

# %%
q = r - S @ g0
z = lemke(S, q, accuracy="high").x
R = S @ z + q
R[np.abs(R) < 1e-9 * np.abs(q).max()] = 0.0                 # rounding where a post does not touch
u = np.zeros(K.shape[0])
u[c] = g0 - z
u[o] = sla.cho_solve(chol, f[o] - K_oc @ u[c])
for i, (p, gi, zi, Ri) in enumerate(zip(posts, g0, z, R)):
    print(f"post {i + 1} at {p}: settled {gi * 1e3:.1f} mm, gap left {zi * 1e3:.4f} mm, R = {Ri:9.3f} N")

# %% [markdown]
# The KKT conditions of the whole plate, by hand: the recovered u with these reactions is in
# equilibrium, and gaps and reactions are non-negative and complementary.

# %%
# the KKT conditions of the full plate, by hand
stat = np.abs(K @ u - f + B.T @ R).max() / np.abs(f).max()
print(f"stationarity |K u − f + Bᵀ R| / |f| = {stat:.1e}")
assert stat < 1e-10 and z.min() >= 0 and R.min() >= 0 and np.abs(z * R).max() < 1e-12 * np.abs(q).max()

# %% [markdown]
# And against plateqp: its `lemke` backend on its own condensed form, its `pdas` backend on the
# primal form (no condensation at all), and statics (edges plus posts carry the load).

# %%
mine = pq.solve(scene, backend="lemke", formulation="condensed", accuracy="high")
ref = pq.solve(scene, backend="pdas", formulation="primal", accuracy="high")
np.testing.assert_allclose(R, mine.reactions, rtol=0, atol=1e-9 * np.abs(R).max())
np.testing.assert_allclose(R, ref.reactions, rtol=0, atol=1e-8 * np.abs(R).max())
edge = -(model.K_full @ ref.u - model.f_full)[model.fixed]  # the edges' reactions
total = 5000.0 * plate.a * plate.b + 2000.0
print(f"lemke and primal agree; statics: edges {edge.sum():.3f} N + posts {R.sum():.3f} N = {total:.1f} N")
assert abs(edge.sum() + R.sum() - total) <= 1e-8 * total     # edges from the primal solve: to its tolerance

# %% [markdown]
# ## The picture: a flexibility column, and the matrices
#
# Left: the plate's deflection under a unit force at post 1 alone (only the edges holding it),
# K⁻¹ Bᵀ e₁; its values at the posts are the first column of G. Right: S and G side by side,
# both symmetric; in G each post moves most under its own force (the largest entry of each
# column is on the diagonal, the centre post's largest of all), in S the posts next to a pushed
# one must pull down to stay put (negative entries).

# %%
j = 0
u_unit = np.zeros(model.n_full)
u_unit[model.free] = np.linalg.solve(K, B[j])              # unit force at post j
nxy = model.grid.node_xy()
w_nodes = u_unit[0::model.element.ndof_node]
fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
ax = axes[0]
tc = ax.tricontourf(nxy[:, 0], nxy[:, 1], w_nodes * 1e6, levels=15, cmap="viridis")
fig.colorbar(tc, ax=ax, label=f"w [mm] per kN at post {j + 1}")
for i, (x, y) in enumerate(posts):
    ax.plot(x, y, "wo" if i != j else "r*", ms=8, mec="k")
    ax.annotate(f"G{i + 1}{j + 1} = {G[i, j] * 1e6:.4f}", (x, y), xytext=(-30 if x > 0.5 else 4, 7),
                textcoords="offset points", fontsize=7, color="w")
ax.set_aspect("equal"); ax.set_title(f"deflection from a unit force at post {j + 1}", fontsize=9)
for ax, A, title, unit in ((axes[1], S / 1e6, "S = K_cc − K_co K_oo⁻¹ K_oc", "kN/mm"),
                           (axes[2], G * 1e6, "G = S⁻¹ = B K⁻¹ Bᵀ", "mm/kN")):
    lim = np.abs(A).max()
    im = ax.imshow(A, cmap="RdBu_r", vmin=-lim, vmax=lim)
    fig.colorbar(im, ax=ax, label=unit)
    ax.set_xticks(range(5), [f"{k + 1}" for k in range(5)]); ax.set_yticks(range(5), [f"{k + 1}" for k in range(5)])
    ax.set_xlabel("post j"); ax.set_ylabel("post i"); ax.set_title(title, fontsize=9)
fig.tight_layout()
plt.show()
post_nodes = model.free[c] // model.element.ndof_node      # the node of each post's deflection dof
assert np.allclose(w_nodes[post_nodes], G[:, j], rtol=1e-12)
assert np.all(np.argmax(G, axis=0) == np.arange(5))        # each post moves most under its own force

# %% [markdown]
# **Cost.** By hand we factorised K_oo densely and solved for m columns: fine for a few posts
# on a small mesh. plateqp gets S as the trailing block of one sparse factorisation of K with
# the contact dofs ordered last (no column solves), and forms G only when the dual is asked
# for. G taken as S⁻¹ from that block carries the condition number of K into its entries, so
# plateqp checks the dual's answer against the exact gaps and, where G's error shows, hands the
# backend the problem again with the gaps corrected (a defect correction: one round is typical).

# %% [markdown]
# ### Exercise 1: condense in two stages
#
# Elimination can be done in steps: condense out the first half of the other dofs, then the
# second half from what is left. The Schur complement has the quotient property, so the result
# must equal S. Check it, to rounding.

# %%
keep = np.concatenate([o[len(o) // 2:], c])       # stage 1 eliminates o[:len(o)//2]
o1 = o[:len(o) // 2]
K1 = K[np.ix_(keep, keep)] - K[np.ix_(keep, o1)] @ np.linalg.solve(K[np.ix_(o1, o1)], K[np.ix_(o1, keep)])
n2 = len(o) - len(o) // 2                          # stage 2 eliminates the rest of o from K1
S2 = K1[n2:, n2:] - K1[n2:, :n2] @ np.linalg.solve(K1[:n2, :n2], K1[:n2, n2:])
print(f"max |S_two-stage − S| / max |S| = {np.abs(S2 - S).max() / np.abs(S).max():.1e}")
assert np.allclose(S2, S, rtol=0, atol=1e-9 * np.abs(S).max())

# %% [markdown]
# ### Exercise 2: break it, drop the coupling
#
# A tempting shortcut keeps only K_cc, as if each post only felt the plate right above it and the
# rest of the plate did not carry load from one post to another. Solve the LCP with K_cc in place
# of S (and the load reduced the same wrong way, f_c) and rebuild u as before. Check what fails:
# the reactions are far from the right ones, and the rebuilt field is not in equilibrium.

# %%
q_bad = f[c] - K_cc @ g0
z_bad = lemke(K_cc, q_bad, accuracy="high").x
R_bad = K_cc @ z_bad + q_bad
u_bad = np.zeros(K.shape[0]); u_bad[c] = g0 - z_bad
u_bad[o] = sla.cho_solve(chol, f[o] - K_oc @ u_bad[c])
stat_bad = np.abs(K @ u_bad - f + B.T @ R_bad).max() / np.abs(f).max()
print("reactions without the coupling:", R_bad.round(1), "\nright reactions:              ", R.round(1))
print(f"stationarity of the rebuilt field: {stat_bad:.1e}")
assert np.abs(R_bad - R).max() > 0.1 * np.abs(R).max()
assert stat_bad > 1e-3

# %% [markdown]
# ## Summary
#
# * Static condensation turns the plate's many dofs into a small, dense matrix on the contact
#   dofs: S = K_cc − K_co K_oo⁻¹ K_oc, exactly plateqp's condensed matrix.
# * Its inverse is the flexibility B K⁻¹ Bᵀ: symmetric (Maxwell–Betti), positive definite, and
#   converging to Navier's series as the mesh is refined.
# * The LCP on the gaps is small; its answer rebuilds the whole field by one back-substitution.
#   Leaving out the coupling term gives an answer that is not in equilibrium.
