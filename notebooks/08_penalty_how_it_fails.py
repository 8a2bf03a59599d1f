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
# # 8. Penalty: how it fails
#
# The most common way to impose a one-sided support in a finite-element code is not a
# constraint but a **stiff spring that only pushes**: add to the plate's energy
#
#     ½ k Σᵢ max(0, (B u − g0)ᵢ)²
#
# for a large "penalty" stiffness k. The plate then penetrates each support a little, by
# p = R / k, and the reaction is R = k p. This notebook measures what that costs against the
# exact QP (solved by Lemke, exact to rounding):
#
# * the penetration is R / k, and the error of the reactions is first order in 1/k;
# * the condition number of K + k BᵀB grows like k, and at large k floating point wins: the
#   error grows again, and at the end the method fails;
# * plateqp's `penalty` teaching backend says so in its status (`INACCURATE`);
# * an **elastic support** of true stiffness c *is* a penalty with k = c: there the same formula
#   is not an approximation but the physics.
#
# The scene: a simply supported square plate on a 3 × 3 grid of one-sided posts, some heaved,
# some settled, under a uniform and a point load.


# %% [markdown]
# ## Learning goals
#
# * replace the one-sided constraints by stiff springs that act only when penetrated (the
#   penalty method), and find its contact set by iteration;
# * measure its two errors: the penalty's own, first order in 1/k, and rounding, which grows like
#   k through the condition number of K + k BᵀB;
# * see plateqp's `penalty` backend report INACCURATE instead of passing a penalty answer off as
#   exact;
# * recognise elastic supports as the one case where the penalty is the exact model.

# %%
import warnings
import numpy as np
import matplotlib.pyplot as plt
import plateqp as pq
from plateqp.model.assembly import build_model

pts = [(x, y) for x in (0.25, 0.5, 0.75) for y in (0.25, 0.5, 0.75)]
gaps = [0.0, 1e-3, -1e-3, 2e-3, 0.0, -2e-3, 1e-3, 0.0, 0.0]      # m: + settled, − heaved
plate = pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3)
def scene(stiffness="rigid"):
    return pq.Scene(name="posts", plate=plate, mesh=pq.MeshSpec(8, 8),
                    edges={k: "simple" for k in ("left", "right", "bottom", "top")},
                    loads=[pq.UniformLoad(10.0), pq.PointLoad(100.0, 0.7, 0.6)],
                    supports=[pq.Support(x, y, gap=g, stiffness=stiffness) for (x, y), g in zip(pts, gaps)])

exact = pq.solve(scene(), backend="lemke", accuracy="high")
check = pq.solve(scene(), backend="pdas", formulation="primal", accuracy="high")   # an independent form
R_ref, on = exact.reactions, exact.active
print("exact reactions [N]:", R_ref.round(4), " in contact:", (np.flatnonzero(on) + 1).tolist())
np.testing.assert_allclose(check.reactions, R_ref, rtol=0, atol=1e-9 * R_ref.max())

model = build_model(scene())              # the plate's own K, f, B, g0 (two-sided edge dofs eliminated)
K, f = model.K.toarray(), model.f
B, g0 = model.contacts.B.toarray(), model.contacts.g0
D = plate.D
print(f"{K.shape[0]} dofs, {B.shape[0]} posts; D = {D:.4f} N m")


# %% [markdown]
# ## The penalty method by hand
#
# Minimising ½ uᵀKu − fᵀu + ½ k ‖(Bu − g0)₊‖² is a smooth problem whose stationarity is
# piecewise linear: with A the posts that are penetrated,
#
#     (K + k B_Aᵀ B_A) u = f + k B_Aᵀ g0_A,
#
# and A is found by the same "assume, solve, correct" loop as toggling springs. We write k in
# units of the plate's own stiffness D / L² (L = 1 m).

# %%
def penalty_by_hand(k, A=None, max_rounds=20):
    A = np.ones(len(g0), dtype=bool) if A is None else A      # a first guess of the penetrated posts
    seen = []
    for rounds in range(1, max_rounds + 1):
        seen.append(A)
        BA = B[A]
        u = np.linalg.solve(K + k * BA.T @ BA, f + k * BA.T @ g0[A])
        p = B @ u - g0                           # penetration (positive: into the post)
        if np.array_equal(p > 0, A):
            return u, k * np.maximum(p, 0.0), p, True
        A = p > 0
        if any(np.array_equal(A, old) for old in seen):
            break                                # a set seen before: the loop cycles
    return u, k * np.maximum(p, 0.0), p, False    # the set never settled

k = 1e6 * D
u, R, p, settled = penalty_by_hand(k)
print("penetration p [m]    :", p[on])
print("exact R / k [m]      :", R_ref[on] / k)
print("reaction error (rel.):", f"{np.abs(R - R_ref).max() / R_ref.max():.2e}")
assert settled
assert np.allclose(p[on], R_ref[on] / k, rtol=1e-4)                    # p = R/k, to O(1/k)
assert np.all(p[~on] < 0)                                              # the posts off contact stay off

# %% [markdown]
# ## The error against k, and the condition number
#
# For every k: the reaction error against the exact QP, and the condition number of the matrix
# the penalty method factorises, K + k B_Aᵀ B_A with A the posts in contact (numpy's 2-norm
# condition number; K is small here). Two
# straight lines on a log-log plot are the whole story:
#
# * the **penalty error** ~ 1/k (the penetration R/k is the error in the gaps);
# * the **rounding error** ~ k ε ‖u‖ / ‖R‖: the reaction is k times the penetration p = Bu − g0,
#   a difference of two numbers of size ‖u‖ each known to machine precision ε.

# %%
eps = np.finfo(float).eps
kD = 10.0 ** np.arange(0, 19)                    # k in units of D / L²
err, cond, ok = [], [], []
for kd in kD:
    u_k, R_k, p_k, settled = penalty_by_hand(kd * D, A=on.copy())   # start from the exact contact set
    err.append(np.abs(R_k - R_ref).max() / R_ref.max())
    cond.append(np.linalg.cond(K + kd * D * B[on].T @ B[on]))
    ok.append(settled)
err, cond, ok = np.array(err), np.array(cond), np.array(ok)
for kd, e, c, s in zip(kD, err, cond, ok):
    print(f"k = 1e{np.log10(kd):2.0f} D/L²   reaction error {e:9.2e}   cond {c:8.1e}   {'' if s else 'the contact set never settled'}")

# first order in 1/k where rounding is negligible; condition number linear in k once k dominates K
slope_err = np.polyfit(np.log10(kD[4:10]), np.log10(err[4:10]), 1)[0]
slope_cond = np.polyfit(np.log10(kD[6:15]), np.log10(cond[6:15]), 1)[0]
print(f"slope of the error {slope_err:.3f} (expected -1),  slope of cond {slope_cond:.3f} (expected +1)")
assert abs(slope_err + 1) < 0.02 and abs(slope_cond - 1) < 0.02
best = np.argmin(err)
print(f"best: {err[best]:.1e} at k = 1e{np.log10(kD[best]):.0f} D/L²; at 1e16: {err[16]:.1e}")
assert 1e-10 < err[best] < 1e-7                  # about 8 digits at best
assert err[16] > 100 * err[best]                 # floating point wins at large k
assert not ok[-1] or err[-1] > 1e-2              # and at the end the method fails outright

# %%
u0 = np.abs(B @ np.linalg.solve(K + 1e8 * D * B[on].T @ B[on], f)).max() + np.abs(g0).max()
fig, (ax, bx) = plt.subplots(1, 2, figsize=(9, 3.4))
ax.loglog(kD[ok], err[ok], "o-", ms=4, label="penalty vs exact QP")
ax.loglog(kD[~ok], err[~ok], "x", color="C3", ms=8, label="contact set never settled")
ax.loglog(kD, err[6] * kD[6] / kD, "k--", lw=0.8, label="∝ 1/k (the penalty)")
ax.loglog(kD, kD * D * eps * u0 / R_ref.max(), "k:", lw=0.8, label="k ε ‖u‖/‖R‖ (rounding)")
ax.set_ylim(1e-10, 10); ax.set_xlabel("k  [D / L²]"); ax.set_ylabel("max reaction error / max R")
ax.legend(fontsize=7)
rounding = kD * D * eps * u0 / R_ref.max()
big = (kD >= 1e13) & ok
print("measured error / rounding model at k >= 1e13 D/L²:", (err[big] / rounding[big]).round(2))
assert np.all((err[big] > rounding[big] / 20) & (err[big] < 20 * rounding[big]))
bx.loglog(kD, cond, "o-", ms=4, color="C1")
bx.loglog(kD, 1 / eps * np.ones_like(kD), "k:", lw=0.8)
bx.text(kD[0], 1.5 / eps, "1/ε", fontsize=8)
bx.set_xlabel("k  [D / L²]"); bx.set_ylabel("cond(K + k B_Aᵀ B_A), A in contact")
fig.tight_layout()
plt.show()

# %% [markdown]
# No k gives the exact answer, and the best k is a compromise found only by knowing the exact
# answer. The exact formulations (primal with constraints, condensed, dual) have no such
# parameter: their conditioning is that of the plate.
#
# ## plateqp's `penalty` backend is honest about it
#
# The teaching backend applies the same idea to the dual problem: each post gets a compliance
# ε = ratio · max diag(G) on the flexibility's diagonal (G + εI instead of G), which *is* a
# spring of stiffness 1/ε. Its answer goes through plateqp's KKT check like any other: the
# status is `OPTIMAL` only when the penetration it leaves is within the accuracy asked (here the
# default, 1e-6), otherwise `INACCURATE`, with a warning. The backend's own message compares the
# natural residual with its internal tolerance (1e-9 at the default preset): at ratio 1e-8 it
# still says "> 1e-09", and the plate's check at 1e-6 passes the answer.

# %%
rows = []
with warnings.catch_warnings():
    warnings.simplefilter("ignore")          # an INACCURATE status also warns: we print it instead
    for ratio in (1e-2, 1e-4, 1e-6, 1e-8, 1e-11):
        res = pq.solve(scene(), backend="penalty", formulation="dual", options={"ratio": ratio})
        e = np.abs(res.reactions - R_ref).max() / R_ref.max()
        rows.append((ratio, res))
        print(f"ratio {ratio:7.0e}: status {res.status.value:10s} KKT ok {str(res.kkt.ok):5s} "
              f"reaction error {e:8.1e}   {res.extras['solver_status']}")
for ratio, res in rows:
    if ratio >= 1e-6:
        assert res.status == pq.Status.INACCURATE and not res.kkt.ok

# %% [markdown]
# ## Elastic supports: the penalty is the physics
#
# Now make every post an elastic support of true stiffness c (a spring that only pushes, R = c s
# for a compression s). The energy of the plate on these posts is *exactly* the penalty energy
# with k = c: what was an error above is now the compression of the springs. Take c equal to the
# spring the penalty backend used at ratio 1e-4: the backend's ε is in plateqp's nondimensional
# units (compliance × D / L²), so c = D / (L² ε). Three different routes give the same reactions
# to rounding:
#
# 1. the penalty backend on the rigid posts;
# 2. the exact elastic-support problem (Lemke on the condensed form, springs built in);
# 3. the penalty formula by hand with k = c.

# %%
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    pen = pq.solve(scene(), backend="penalty", formulation="dual", options={"ratio": 1e-4})
c = D / (plate.a**2 * pen.extras["epsilon"])           # N/m, the spring the penalty stands for
elastic = pq.solve(scene(stiffness=c), backend="lemke", accuracy="high")
_, R_hand, s_hand, _ = penalty_by_hand(c)
print(f"c = {c:.4e} N/m = {c / D:.3e} D/L²")
print("penalty backend :", pen.reactions.round(6))
print("elastic, exact  :", elastic.reactions.round(6), elastic.status.value)
print("by hand, k = c  :", R_hand.round(6))
print("spring compressions [m]:", elastic.compressions[elastic.active], " = R/c:", (elastic.reactions / c)[elastic.active])
assert elastic.status == pq.Status.OPTIMAL
for R_other in (pen.reactions, R_hand):
    np.testing.assert_allclose(R_other, elastic.reactions, rtol=0, atol=1e-9 * elastic.reactions.max())
np.testing.assert_allclose(elastic.compressions, elastic.reactions / c, rtol=1e-9, atol=1e-15)

# %% [markdown]
# **Summary for the lecture.** A penalty is a spring. If the support *is* a spring, use its true
# stiffness and the answer is exact (plateqp's elastic supports). If the support is rigid, the
# penalty leaves a penetration R/k and an error of order 1/k, and raising k trades that error
# for ill-conditioning: with about 16 digits the best one can get here is about
# 8 digits (the minimum of the V above), and only by knowing the exact answer to pick k. A
# constrained QP has neither problem.

# %% [markdown]
# ### Exercise 1: extrapolate the penalty away
#
# The penalty error is first order: R(k) = R* + a/k + O(1/k²). Combine two answers,
# 2 R(2k) − R(k), and the first-order term cancels. Check at k = 1e6 D/L² that the extrapolated
# reactions are at least a hundred times closer to the exact ones than R(k) itself.

# %%
k1 = 1e6 * D
R_k = penalty_by_hand(k1, A=on.copy())[1]
R_2k = penalty_by_hand(2 * k1, A=on.copy())[1]
e_k = np.abs(R_k - R_ref).max() / R_ref.max()
e_x = np.abs(2 * R_2k - R_k - R_ref).max() / R_ref.max()
print(f"error at k: {e_k:.2e};  extrapolated: {e_x:.2e}")
assert e_x < e_k / 100

# %% [markdown]
# ### Exercise 2: break it, springs that also pull
#
# The penalty springs act only when a post is penetrated. Make them act both ways (every post a
# two-sided spring, no iteration on the contact set) and check what goes wrong: the posts the
# exact solution leaves open now pull the plate down (negative reactions).

# %%
u_two = np.linalg.solve(K + k1 * B.T @ B, f + k1 * B.T @ g0)
R_two = k1 * (B @ u_two - g0)
print("two-sided springs:", R_two.round(3), "\nexact:            ", R_ref.round(3))
assert (~on).any() and R_two[~on].min() < 0

# %% [markdown]
# ## Summary
#
# * The penalty method trades the constraint for a stiff spring: the reactions come out wrong by
#   O(1/k), and the contact set still has to be found by iteration.
# * Raising k lowers that error until rounding takes over (the condition number grows like k):
#   about eight digits at best, and outright failure beyond.
# * plateqp's `penalty` backend says INACCURATE when its KKT residuals show it; with elastic
#   supports the penalty is the model itself, and exact.
