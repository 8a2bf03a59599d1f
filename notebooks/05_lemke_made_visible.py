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
# # 5. Lemke made visible: the tableau, the path of z0, and a ray that proves no equilibrium
#
# Lesson 4 printed Lemke's pivots. Here we open the method up. We write it ourselves in about
# thirty lines on the dense tableau, print the tableau before every pivot, and check each pivot
# against plateqp's `lemke`. Then we follow the artificial variable z0 (the uniform
# pre-compression) along its path, and end with a plate that has **no** equilibrium: there Lemke
# stops on a *secondary ray*, and the ray is a certificate that no solution exists.
#
# The condensed LCP of a plate on one-sided supports: w = M z + q, z ≥ 0, w ≥ 0, zᵀw = 0, with
# z_i the **gap** of support i and w_i its **reaction** (scaled). Lemke works on
#
#   [ I | −M | −d | q ]:  w − M z − d z0 = q,
#
# keeping n basic variables. The first n columns of the current tableau are B⁻¹ and the last is
# the value of the basic variables.


# %% [markdown]
# ## Learning goals
#
# * write Lemke's method in thirty lines and print its tableau before every pivot;
# * check it pivot by pivot against plateqp's `lemke`, and every corner of its path as almost
#   complementary;
# * follow the artificial variable z0 along the path (it need not fall monotonically);
# * read a secondary ray as a proof that no equilibrium exists: a plate that tips off its posts.

# %%
import numpy as np
import matplotlib.pyplot as plt  # the notebook's own (inline) backend: the figure shows
import plateqp as pq
from plateqp.backends import lemke
from plateqp.model.assembly import build_model
from plateqp.contact import Scaled, formulate

def lcp_of(scene):
    data = Scaled.from_model(build_model(scene))
    return data, formulate(data, "condensed").lcp

def our_lemke(M, q, show=False, max_pivots=100):
    """Lemke's method on the dense tableau, plain minimum-ratio rule. Returns
    (kind, z or ray, steps), kind "solution" or "ray"; steps: (entering, leaving, z0, T, basis)."""
    n = len(q); d = np.ones(n)
    T = np.hstack([np.eye(n), -M, -d[:, None], q[:, None]])
    names = [f"w{i + 1}" for i in range(n)] + [f"z{i + 1}" for i in range(n)] + ["z0"]
    basis = list(range(n))                                  # w is basic: B = I
    enter, row = 2 * n, int(np.argmin(q / d))               # z0 enters at the most negative q_i/d_i
    steps = []
    for _ in range(max_pivots):
        if show:
            show_tableau(T, basis, names, (row, enter))
        T[row] /= T[row, enter]
        for i in range(n):
            if i != row:
                T[i] -= T[i, enter] * T[row]
        leave, basis[row] = basis[row], enter
        z0 = T[basis.index(2 * n), -1] if 2 * n in basis else 0.0
        steps.append((names[enter], names[leave], z0, T.copy(), list(basis)))
        if leave == 2 * n:                                  # z0 left: a complementary solution
            z = np.zeros(n)
            for i, b in enumerate(basis):
                if n <= b < 2 * n:
                    z[b - n] = T[i, -1]
            if show:
                show_tableau(T, basis, names, None)
            return "solution", z, steps
        enter = leave + n if leave < n else leave - n       # the complementary rule
        col = T[:, enter]
        rows = np.flatnonzero(col > 1e-12 * np.abs(col).max())
        if rows.size == 0:                                  # nothing blocks: a secondary ray
            y = np.zeros(n)                                 # its z part: the entering z grows by 1 …
            if enter >= n:
                y[enter - n] = 1.0
            for i, b in enumerate(basis):                   # … and basic z's move by −col
                if n <= b < 2 * n:
                    y[b - n] = -col[i]
            if show:
                print(f"{names[enter]} should enter, but its column has no positive entry: nothing blocks")
                show_tableau(T, basis, names, None)
            return "ray", y, steps
        row = int(rows[np.argmin(T[rows, -1] / col[rows])])   # the ratio test
    raise RuntimeError("too many pivots")

def show_tableau(T, basis, names, pivot):
    n, tiny = T.shape[0], 1e-9 * np.abs(T).max()          # rounding-level entries print as 0
    print("      " + "".join(f"{s:>9s}" for s in names + ["value"]))
    for i in range(n):
        cells = []
        for j in range(T.shape[1]):
            s = f"{T[i, j]:.3g}" if abs(T[i, j]) > tiny else "0"
            cells.append(f"{'[' + s + ']' if pivot == (i, j) else s:>9s}")
        print(f"{names[basis[i]]:>5s} " + "".join(cells))
    if pivot:
        print(f"pivot: {names[pivot[1]]} enters, {names[basis[pivot[0]]]} leaves\n")


# %% [markdown]
# ## The tableau, pivot by pivot
#
# A plate simply supported on its left edge, four one-sided posts with heave and settlement,
# and one point load. The row labels are the basic variables. Brackets mark the pivot element.

# %%
posts = [(1.0, 0.0), (1.0, 1.0), (0.6, 0.3), (0.6, 0.8)]
scene = pq.Scene(name="four posts", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
                 edges={"left": "simple"}, loads=[pq.PointLoad(40.0, 0.4, 0.9)],
                 supports=[pq.Support(x, y, gap=g) for (x, y), g in zip(posts, (-1e-3, 0.0, 2e-3, 3e-3))])
data, lcp = lcp_of(scene)
M, q = np.asarray(lcp.M), np.asarray(lcp.q)
kind, z, steps = our_lemke(M, q, show=True)
print("ended on:", kind, " gaps z =", np.round(z, 6), " reactions w =", np.round(M @ z + q, 6))

# %% [markdown]
# Checks. (1) Each printed tableau is B⁻¹ [I | −M | −d | q], with B the columns of the basic
# variables: recomputed from scratch with a linear solve. (2) The pivots and the values of z0 are
# those of plateqp's `lemke` (trace). (3) The answer is complementary and, in the user's units,
# matches plateqp's solve of the scene with its KKT check passed; the reactions balance the load's
# moment about the supported edge.

# %%
n = len(q)
full = np.hstack([np.eye(n), -M, -np.ones((n, 1)), q[:, None]])
for _, _, _, T, basis in steps:
    np.testing.assert_allclose(T, np.linalg.solve(full[:, basis], full), atol=1e-9 * np.abs(full).max())
trace = lemke.lemke(M, q, trace=True).extras["trace"]
label = lambda v: "z0" if v[0] == "z0" else f"{v[0]}{v[1] + 1}"
assert [(label(s["entering"]), label(s["leaving"])) for s in trace] == [(e, l) for e, l, _, _, _ in steps]
np.testing.assert_allclose([s["z0"] for s in trace], [s[2] for s in steps], rtol=1e-10, atol=1e-12)
w = M @ z + q
assert kind == "solution" and z.min() >= 0 and w.min() > -1e-12 and abs(z @ w) < 1e-12
res = pq.solve(scene, backend="lemke", accuracy="high")
assert res.kkt.ok
np.testing.assert_allclose(res.reactions, w * data.F0, atol=1e-9 * res.reactions.max())
np.testing.assert_allclose(res.gaps, z * data.W, atol=1e-9 * data.W)
print("reactions:", res.reactions.round(4), " gaps:", res.gaps.round(6))
# statics: moments about the simply supported left edge (x = 0), whose reactions have no lever arm
x_post = np.array([p[0] for p in posts])
assert abs(res.reactions @ x_post - 40.0 * 0.4) < 1e-9 * 40.0


# %% [markdown]
# ## The path of z0
#
# Between pivots the method walks along a line on which (z, w) solves the LCP with q replaced by
# q + d z0, a uniform pre-compression z0 of every support, and satisfies every complementarity
# pair but one. Each pivot is a corner of that path, where one support changes state. We check
# both facts at every corner, and draw z0 for this scene and for the nine-post scene of lesson
# 4. In general z0 need not fall monotonically, but without degenerate ties the path never
# revisits a basis (plateqp's lexicographic rule makes that hold with ties too).

# %%
def corners(M, q, steps):
    n = len(q); out = []
    for _, _, z0, T, basis in steps:
        v = np.zeros(2 * n + 1)
        v[basis] = T[:, -1]
        zz, ww = v[n:2 * n], v[:n]
        np.testing.assert_allclose(ww, M @ zz + q + z0, atol=1e-9 * np.abs(q).max())   # the LCP for q + d z0
        assert zz.min() > -1e-9 and ww.min() > -1e-9 and z0 >= -1e-12
        assert np.sum(np.abs(zz * ww) > 1e-9) <= 1                                    # almost complementary
        out.append(z0)
    return out

z0_four = corners(M, q, steps)
supports9 = [pq.Support(x, y, gap=(-0.05 if (x, y) in ((0.5, 0.0), (1.0, 0.0)) else 0.0))
             for x in (0.5, 0.75, 1.0) for y in (0.0, 0.5, 1.0)]
nine = pq.Scene(name="nb2", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
                edges={"left": "simple"}, loads=[pq.PointLoad(40.0, 0.7, 0.7)], supports=supports9)
_, lcp9 = lcp_of(nine)
kind9, z9, steps9 = our_lemke(np.asarray(lcp9.M), np.asarray(lcp9.q))
z0_nine = corners(np.asarray(lcp9.M), np.asarray(lcp9.q), steps9)
assert kind9 == "solution"
np.testing.assert_allclose(z9, lemke.lemke(lcp9.M, lcp9.q).x, atol=1e-10)
print("z0 along the path, four posts:", np.round(z0_four, 3))
print("z0 along the path, nine posts:", np.round(z0_nine, 3))

# %% [markdown]
# ## A plate with no equilibrium: the secondary ray
#
# A free plate (no edge support) on six posts, all at x ≤ 0.25, with a point load at x = 0.8.
# The load lies outside the posts, so the plate tips off them. plateqp refuses it before any
# solve (a statics check). We hand the LCP to Lemke directly: z0 can no longer be driven to zero.
# The entering column has no positive entry, so the method stops on a ray. Its z part y is a
# **Farkas certificate**:
#
#   y ≥ 0,  Mᵀy ≤ 0,  qᵀy < 0.
#
# If a solution existed, 0 ≤ yᵀw = (Mᵀy)ᵀz + qᵀy < 0, a contradiction. In plate terms, y is a set
# of gap openings that costs no strain energy (a rigid tilt about the line x = 0.25, opening the
# posts at x = 0), while the load does positive work −qᵀy on it. The energy is unbounded below.

# %%
tip_posts = [(x, y) for x in (0.0, 0.25) for y in (0.0, 0.5, 1.0)]
tip = pq.Scene(name="tips off", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
               loads=[pq.PointLoad(40.0, 0.8, 0.5)], supports=[pq.Support(x, y) for x, y in tip_posts])
try:
    pq.solve(tip, backend="lemke")
    raise AssertionError("a plate that tips off its supports was solved")
except pq.NoEquilibriumError as exn:
    print("plateqp.solve:", str(exn)[:120], "…")

tdata, tlcp = lcp_of(tip)
Mt, qt = np.asarray(tlcp.M), np.asarray(tlcp.q)
kind_t, y, steps_t = our_lemke(Mt, qt, show=True)
ref = lemke.lemke(Mt, qt)
print("plateqp lemke:", ref.status.value, "|", ref.solver_status[:80], "…")
assert kind_t == "ray" and ref.status == pq.Status.INFEASIBLE
np.testing.assert_allclose(y / y.max(), ref.extras["certificate"] / ref.extras["certificate"].max(), atol=1e-9)

# %% [markdown]
# The certificate, checked numerically (Mᵀy is zero up to rounding, relative to ‖M‖), and
# its physics: y is proportional to the gap opening of a rotation θ about x = 0.25,
# Δgap_j = θ (0.25 − x_j). In the user's units, the energy qᵀy·F0·W is the work of the load
# on that tilt with the sign reversed: −P (0.8 − 0.25) θ.

# %%
scale = np.abs(Mt).max()
print("y      =", np.round(y, 6))
print("Mᵀy    =", np.array2string(Mt.T @ y, precision=2), " (‖M‖max", f"{scale:.1f})")
print(f"qᵀy    = {qt @ y:.6f}")
assert y.min() >= 0 and (Mt.T @ y).max() <= 1e-9 * scale * y.max() and qt @ y < 0
x_post = np.array([p[0] for p in tip_posts])
np.testing.assert_allclose(y / y.max(), (0.25 - x_post) / 0.25, atol=1e-9)   # a rigid tilt about x = 0.25
theta = tdata.W * y.max() / 0.25                                               # that tilt, in radians
work = 40.0 * (0.8 - 0.25) * theta
print(f"energy along the ray: qᵀy·F0·W = {qt @ y * tdata.F0 * tdata.W:.6f},  −P·0.55·θ = {-work:.6f}")
assert abs(qt @ y * tdata.F0 * tdata.W + work) < 1e-9 * work
z0_tip = [s[2] for s in steps_t]
print("z0 along the path:", np.round(z0_tip, 3), "(it never reaches 0: the pre-compression cannot all be removed)")
# the second pivot was degenerate (the leaving w3 was 0 to rounding: z0 did not move); plateqp's
# lexicographic rule breaks such ties otherwise and leaves by another pivot, on the same ray

# %% [markdown]
# ## The three paths of z0

# %%
fig, ax = plt.subplots(figsize=(6.5, 3.4))
for vals, lab in ((z0_four, "four posts (solution)"), (z0_nine, "nine posts, lesson 4 (solution)"),
                  (z0_tip, "plate that tips off (ray)")):
    ax.plot(range(1, len(vals) + 1), vals, "o-", label=lab)
ax.plot(len(z0_tip), z0_tip[-1], "x", color="k", ms=12, mew=2)
ax.annotate("secondary ray", (len(z0_tip), z0_tip[-1]), xytext=(10, 10), textcoords="offset points", fontsize=8)
ax.axhline(0, color="k", lw=0.6)
ax.set_xticks(range(1, max(len(z0_four), len(z0_nine), len(z0_tip)) + 1))
ax.set_xlabel("pivot"); ax.set_ylabel("z0 (uniform pre-compression, scaled)"); ax.legend(fontsize=8)
fig.tight_layout()
plt.show()

# %% [markdown]
# ### Exercise 1: a 2 × 2 LCP in closed form
#
# For M = [[2, 1], [1, 2]] and q = (−1, −1) both gaps are positive only if both reactions vanish:
# M z = −q gives z = (1/3, 1/3). For q = (−1, 2) the second support presses and the first opens:
# z = (1/2, 0), R = (0, 2.5). Check `our_lemke` on both against these closed forms.

# %%
M2 = np.array([[2.0, 1.0], [1.0, 2.0]])
for q2, z_exact in ((np.array([-1.0, -1.0]), np.array([1 / 3, 1 / 3])), (np.array([-1.0, 2.0]), np.array([0.5, 0.0]))):
    kind2, z2, _ = our_lemke(M2, q2)
    print(kind2, z2, "R =", M2 @ z2 + q2)
    assert kind2 == "solution" and np.allclose(z2, z_exact, atol=1e-14)
    assert np.allclose(M2 @ z2 + q2, np.maximum(M2 @ z_exact + q2, 0.0), atol=1e-14)

# %% [markdown]
# ### Exercise 2: break it, move the load off the posts' footprint
#
# The six posts of the tipping plate stand on the strip 0 ≤ x ≤ 0.25. With the point load inside
# that strip (x = 0.2) the plate stands: Lemke ends with a solution and the reactions balance the
# load and its moment. Move the load out (x = 0.8, as above) and the same method ends on a ray.
# Check both, with statics for the first.

# %%
def tip_scene(x_load):
    return pq.Scene(name="tip", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
                    loads=[pq.PointLoad(40.0, x_load, 0.5)], supports=[pq.Support(x, y) for x, y in tip_posts])

inside = pq.solve(tip_scene(0.2), backend="lemke", accuracy="high")
print("load at x = 0.2:", inside.status.value, "R =", np.round(inside.reactions, 3))
assert abs(inside.reactions.sum() - 40.0) < 1e-9 * 40 and abs(inside.reactions @ x_post - 40 * 0.2) < 1e-9 * 40
for x_load, expected in ((0.2, "solution"), (0.8, "ray")):
    _, lcp_x = lcp_of(tip_scene(x_load))
    kind_x, _, _ = our_lemke(np.asarray(lcp_x.M), np.asarray(lcp_x.q))
    print(f"load at x = {x_load}: our Lemke ends with a {kind_x}")
    assert kind_x == expected

# %% [markdown]
# ## Summary
#
# * Lemke's method is a walk along almost complementary corners, one pivot at a time, driven by
#   the artificial pre-compression z0; it ends when z0 leaves the basis.
# * A thirty-line tableau version agrees with plateqp's `lemke` pivot by pivot and with closed
#   forms on small LCPs.
# * When no equilibrium exists, the walk ends on a secondary ray y ≥ 0 with Mᵀy ≤ 0 and qᵀy < 0:
#   a rigid motion that lowers the energy for ever, a proof, not a failure to converge.
