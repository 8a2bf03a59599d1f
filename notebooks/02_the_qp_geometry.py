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
# # 2. The QP's geometry: two supports as a picture
#
# With two one-sided supports the condensed problem lives in the plane, and everything a
# lecture says about convex contact can be drawn:
#
# * the unknowns are the two **gaps** z = (z₁, z₂) left at the supports; the feasible set is the
#   quadrant z ≥ 0 (no penetration);
# * the energy of the plate, condensed onto the gaps, is Π(z) = ½ zᵀMz + qᵀz (up to a
#   constant), with M the plate's stiffness seen from the two support points; its level sets
#   are ellipses;
# * at the optimum, −∇Π lies in the **normal cone** of the quadrant there, and the multipliers
#   of z ≥ 0 are the components of ∇Π = M z + q: the **reactions**.
#
# The scene: a 10 mm steel plate, 1 m × 1 m, simply supported on its edges, with two one-sided
# posts under it, a uniform load and a point load off the centre line.


# %% [markdown]
# ## Learning goals
#
# * draw the condensed contact problem of two supports: the feasible quadrant of the gaps, the
#   elliptic level sets of the energy Π, the unconstrained minimum;
# * find the optimum on a corner (both touch), a face (one touches) or inside (none), and read the
#   reactions as −∇Π in the normal cone there;
# * enumerate the four contact sets and see that exactly one is consistent when M is positive
#   definite;
# * check each case against the primal formulation and statics.

# %%
import numpy as np
import matplotlib.pyplot as plt
import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.contact import Scaled, formulate

posts = [(0.375, 0.5), (0.625, 0.5)]
def scene_with(gaps):
    return pq.Scene(name="two-posts", plate=pq.Plate(1.0, 1.0, 0.01, 2.1e11, 0.3), mesh=pq.MeshSpec(16, 16),
                    edges={k: "simple" for k in ("left", "right", "bottom", "top")},
                    loads=[pq.UniformLoad(5000.0), pq.PointLoad(2000.0, 0.58, 0.45)],
                    supports=[pq.Support(x, y, gap=g) for (x, y), g in zip(posts, gaps)])

# condense the plate onto the two support deflections (gaps zero), back in the user's units
data = Scaled.from_model(build_model(scene_with([0.0, 0.0])))
lcp = formulate(data, "condensed").lcp
M = lcp.M * data.F0 / data.W        # N/m: force at post i per unit gap at post j
r = lcp.q * data.F0                 # N: the reactions if both posts were rigid and level
w_free = np.linalg.solve(M, r)      # m: where the plate would sag without the posts
print("M [kN/mm] =\n", (M / 1e6).round(4))
print("reactions on level rigid posts r [N] =", r.round(2))
print("free deflection at the posts [mm] =", (w_free * 1e3).round(4))
assert np.allclose(M, M.T) and np.all(np.linalg.eigvalsh(M) > 0)   # symmetric positive definite

# %% [markdown]
# ## Moving the gaps moves the ellipses
#
# With initial gaps g0 (the posts lowered by g0) the gap left is z = g0 − w, and the linear term
# becomes q = r − M g0. The Hessian M does not change: the ellipses keep their shape, and their
# centre, the **unconstrained minimum** z* = −M⁻¹q = g0 − w_free, is the gap the plate would
# leave if the posts were not there. Four choices of g0 put the optimum in the four possible
# contact sets:

# %%
cases = {"both posts touch": np.array([0.0, 0.0]),
         "only post 1 touches": np.array([0.0, 1.6 * w_free[1]]),
         "only post 2 touches": np.array([1.6 * w_free[0], 0.0]),
         "no post touches": 1.25 * w_free}
def q_of(g0):
    return r - M @ g0

# for two supports we can try every contact set A (2² of them): z = 0 on A, R = 0 off A
def by_enumeration(g0):
    q, found = q_of(g0), []
    for A in ([0, 1], [0], [1], []):
        F = [i for i in (0, 1) if i not in A]
        z = np.zeros(2)
        if F:
            z[F] = np.linalg.solve(M[np.ix_(F, F)], -q[F])
        R = M @ z + q
        if np.all(z >= -1e-15) and np.all(R >= -1e-9 * np.abs(r).max()):
            found.append((tuple(A), z, np.where(z > 0, 0.0, R)))
    return found

for name, g0 in cases.items():
    sols = by_enumeration(g0)
    (A, z, R), = sols                      # exactly one set is consistent: M is positive definite
    print(f"{name:20s} g0 = {np.round(g0 * 1e3, 4)} mm  ->  contact set {[i + 1 for i in A]}, "
          f"z = {np.round(z * 1e3, 4)} mm, R = {np.round(R, 4)} N")

# %% [markdown]
# ## Checked against the full plate
#
# The same four scenes solved by plateqp on the **primal** form (all the plate's dofs, no
# condensation; its primal-dual active-set backend `pdas`): the same contact sets, gaps and reactions. And
# statics: whatever the contact set, the posts and the edges together carry the whole load.

# %%
results = {}
for name, g0 in cases.items():
    (A, z, R), = by_enumeration(g0)
    res = pq.solve(scene_with(g0), backend="pdas", formulation="primal", accuracy="high")
    results[name] = (g0, z, R)
    assert res.status == pq.Status.OPTIMAL
    assert list(np.flatnonzero(res.active)) == list(A), name
    np.testing.assert_allclose(res.reactions, R, rtol=0, atol=1e-6 * np.abs(r).max())
    np.testing.assert_allclose(res.gaps, z, rtol=0, atol=1e-6 * np.abs(w_free).max())
    # statics: edge reactions (K u − f on the prescribed dofs) plus post reactions = total load
    mdl = res.model                                              # res.u: every dof, prescribed ones too
    edge = -(mdl.K_full @ res.u - mdl.f_full)[mdl.fixed]
    total = 5000.0 * 1.0 + 2000.0
    print(f"{name:20s} primal agrees; edges {edge.sum():.6f} N + posts {res.reactions.sum():.6f} N = {total} N")
    assert abs(edge.sum() + res.reactions.sum() - total) <= 1e-7 * total   # to the solver's tolerance


# %% [markdown]
# ## The optimality condition: −∇Π in the normal cone
#
# The normal cone of the quadrant at z is the set of directions that point out of it there:
# v with vᵢ ≤ 0 where zᵢ = 0 (a post in contact) and vᵢ = 0 where zᵢ > 0 (a gap open). z is
# optimal exactly when −∇Π(z) = −(M z + q) lies in it; the components of ∇Π are the reactions,
# so this is R ≥ 0 on the posts in contact and R = 0 on the others. A descent direction that
# points out of the quadrant cannot be followed: the posts stop it, and the force they need is
# the multiplier.

# %%
def in_normal_cone(v, z, tol=1e-9 * np.abs(r).max()):
    """True if v is in the normal cone of {z >= 0} at z."""
    return bool(np.all(np.where(z > 0, np.abs(v) <= tol, v <= tol)))

for name, (g0, z, R) in results.items():
    grad = M @ z + q_of(g0)
    print(f"{name:20s} ∇Π = {np.round(grad, 4)} N = R;  −∇Π in the normal cone: {in_normal_cone(-grad, z)}")
    assert np.allclose(grad, R, rtol=0, atol=1e-9 * np.abs(r).max()) and in_normal_cone(-grad, z)
    # any other point of the quadrant fails the test (e.g. the corner when a gap is open)
    if np.any(z > 0):
        assert not in_normal_cone(-q_of(g0), np.zeros(2))

# %% [markdown]
# ## The picture
#
# In each panel: the feasible quadrant (white; shaded where z < 0, penetration), the energy's
# level sets (grey ellipses) around the unconstrained minimum ✕, the optimum ● with the level set through it (black: it touches the quadrant there), the **normal
# cone** of the quadrant at the optimum (green: the quarter-plane z ≤ 0 at the corner, a ray
# along the face, only the point itself inside), and the arrow −∇Π = −R, scaled, which must lie
# in that cone: the load pulls the plate into the posts with exactly the force the posts push
# back with. Where a post does not touch, its component of ∇Π is zero: no force, no
# multiplier.

# %%
fig, axes = plt.subplots(2, 2, figsize=(8.5, 8))
for ax, (name, (g0, z, R)) in zip(axes.ravel(), results.items()):
    q = q_of(g0)
    zs = np.linalg.solve(M, -q)                                  # unconstrained minimum
    pts = np.array([zs, z, [0.0, 0.0]]) * 1e3                    # mm
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = 0.35 * max((hi - lo).max(), 1e-3)
    lo, hi = lo - pad, hi + pad
    Z1, Z2 = np.meshgrid(np.linspace(lo[0], hi[0], 200), np.linspace(lo[1], hi[1], 200))
    Zm = np.stack([Z1, Z2], axis=-1) / 1e3
    Pi = 0.5 * np.einsum("...i,ij,...j", Zm, M, Zm) + Zm @ q
    Pmin, Popt = 0.5 * zs @ M @ zs + q @ zs, 0.5 * z @ M @ z + q @ z
    if Popt - Pmin > 1e-9 * abs(Pmin):     # the level set through the optimum (bold) touches the quadrant there
        ax.contour(Z1, Z2, Pi, levels=Pmin + (Popt - Pmin) * np.array([0.1, 0.3, 0.6, 1.6, 2.5, 3.6, 5.0]),
                   colors="0.6", linewidths=0.7, linestyles="solid")
        ax.contour(Z1, Z2, Pi, levels=[Popt], colors="k", linewidths=1.3, linestyles="solid")
    else:
        ax.contour(Z1, Z2, Pi, levels=12, colors="0.6", linewidths=0.7, linestyles="solid")
    ax.fill_between([lo[0], hi[0]], lo[1], 0, color="C3", alpha=0.08, lw=0)   # z2 < 0
    ax.fill_betweenx([lo[1], hi[1]], lo[0], 0, color="C3", alpha=0.08, lw=0)  # z1 < 0
    ax.axhline(0, color="k", lw=0.8); ax.axvline(0, color="k", lw=0.8)
    # the normal cone at z (see in_normal_cone): the quarter-plane at the corner, a ray on a face
    zmm, big = z * 1e3, 3 * (hi - lo).max()
    touch = z <= 0
    if touch.all():
        ax.fill([zmm[0], zmm[0] - big, zmm[0] - big, zmm[0]], [zmm[1], zmm[1], zmm[1] - big, zmm[1] - big],
                color="C2", alpha=0.25, lw=0)
    for i in np.flatnonzero(touch if not touch.all() else []):
        e = np.zeros(2); e[i] = -big
        ax.plot([zmm[0], zmm[0] + e[0]], [zmm[1], zmm[1] + e[1]], color="C2", lw=4, alpha=0.5)
    scale = 0.3 * (hi - lo).max() / np.abs(r).max()              # mm per N
    if np.abs(R).max() > 0:
        ax.annotate("", xy=zmm - scale * R, xytext=zmm, arrowprops=dict(arrowstyle="-|>", color="C2", lw=1.5))
        ax.annotate(f"R = ({R[0]:.0f}, {R[1]:.0f}) N", zmm, xytext=(6, 6), textcoords="offset points", fontsize=8,
                    color="C2", bbox=dict(fc="w", ec="none", alpha=0.8))
    ax.plot(*(zs * 1e3), "kx", ms=8)
    ax.plot(*zmm, "o", color="C0", ms=7)
    ax.set_xlim(lo[0], hi[0]); ax.set_ylim(lo[1], hi[1]); ax.set_aspect("equal")
    ax.set_title(f"{name}\ng0 = ({g0[0] * 1e3:.2f}, {g0[1] * 1e3:.2f}) mm", fontsize=9)
    ax.set_xlabel("gap z₁ at post 1 [mm]"); ax.set_ylabel("gap z₂ at post 2 [mm]")
handles = [plt.Line2D([], [], color="0.6", lw=0.7, label="level sets of Π"),
           plt.Line2D([], [], color="k", lw=1.3, label="the level set through the optimum"),
           plt.Line2D([], [], color="k", marker="x", ls="", label="unconstrained minimum z*"),
           plt.Line2D([], [], color="C0", marker="o", ls="", label="optimum"),
           plt.Rectangle((0, 0), 1, 1, color="C2", alpha=0.3, label="normal cone at the optimum"),
           plt.Line2D([], [], color="C2", marker=">", lw=1.5, label="−∇Π = −R (scaled)"),
           plt.Rectangle((0, 0), 1, 1, color="C3", alpha=0.1, label="z < 0: penetration")]
fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=8)
fig.tight_layout(rect=(0, 0.07, 1, 1))
plt.show()

# %% [markdown]
# **What the picture says.**
#
# * *Both touch*: the optimum is the corner, the whole third quadrant is the normal cone, and
#   −∇Π points into it: both reactions positive.
# * *One touches*: the optimum slides along a face, where the level set is tangent to the face;
#   the cone is a ray and the gradient has one non-zero component, the reaction of the post in
#   contact.
# * *None*: the unconstrained minimum is feasible, ∇Π = 0, no forces.
#
# Complementarity zᵢRᵢ = 0 is the statement that the optimum is on the face whose normal the
# force follows. With m supports the quadrant becomes an orthant with 2ᵐ faces, and finding the
# right face is the whole difficulty: that is what Lemke, active-set and interior-point methods
# do in different ways.

# %% [markdown]
# ### Exercise 1: the minimum principle, by sampling
#
# The optimum of a convex QP has the least energy of every feasible point. For each of the four
# cases, evaluate Π(z) = ½ zᵀ M z + qᵀ z at 2000 random points of the quadrant z ≥ 0 (in a box a
# few times the size of the free deflection) and check that none is lower than Π at the optimum.

# %%
rng = np.random.default_rng(1)
for name, (g0, z, R) in results.items():
    qq = q_of(g0)
    Zs = rng.uniform(0.0, 3.0, (2000, 2)) * np.abs(w_free).max()
    Pi_s = 0.5 * np.einsum("ki,ij,kj->k", Zs, M, Zs) + Zs @ qq
    Pi_opt = 0.5 * z @ M @ z + qq @ z
    print(f"{name:20s} Π* = {Pi_opt:10.4f} N·m, lowest sample {Pi_s.min():10.4f} N·m")
    assert Pi_s.min() >= Pi_opt - 1e-12 * abs(Pi_opt)

# %% [markdown]
# ### Exercise 2: break it, a concave energy
#
# Uniqueness rests on M being positive definite. Flip its sign (an energy that falls as the gaps
# open: no material does this, but a wrong sign in an assembly does) and enumerate the contact
# sets again. Check that with level posts (g0 = 0) all four sets are now consistent (four
# "answers"), and that in the case "no post touches" none is (no answer at all).

# %%
def consistent_sets(Mx, qq):
    found = []
    for A in ([0, 1], [0], [1], []):
        F = [i for i in (0, 1) if i not in A]
        z = np.zeros(2)
        if F:
            z[F] = np.linalg.solve(Mx[np.ix_(F, F)], -qq[F])
        if np.all(z >= -1e-15) and np.all(Mx @ z + qq >= -1e-9 * np.abs(r).max()):
            found.append(A)
    return found

level, none = consistent_sets(-M, q_of(cases["both posts touch"])), consistent_sets(-M, q_of(cases["no post touches"]))
print("concave energy, level posts:", level, "| no post touches:", none)
assert len(consistent_sets(M, q_of(cases["both posts touch"]))) == 1
assert len(level) == 4 and len(none) == 0

# %% [markdown]
# ## Summary
#
# * The condensed problem of two supports lives in the quadrant of the gaps; its energy's level
#   sets are ellipses, and the optimum is where the lowest one touches the quadrant.
# * At the optimum the reactions are ∇Π, and −∇Π lies in the normal cone: zero on an open gap,
#   pointing out of the quadrant on a closed one. This is the KKT system (lesson 3) drawn.
# * Positive definite M: one consistent contact set, found by enumeration here, by pivoting
#   (lessons 4 and 5) when there are too many sets to try.
