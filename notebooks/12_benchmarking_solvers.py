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
# # 12. Benchmarking solvers on plate contact
#
# The last lesson puts every backend plateqp knows on one scene and asks three questions: does it
# answer, is the answer right, and how long does it take? The scene is small (a 12 × 12 mesh, a
# simply supported plate over a 4 × 4 grid of posts with graded gaps), so the comparison is about
# behaviour rather than scale; the full study, on the paper's plates and on larger meshes, is in
# benchmarks/. Each backend solves each formulation it takes (primal, condensed, dual, lesson 3),
# and plateqp checks every answer against the KKT conditions: a backend whose residuals stay above
# the preset's tolerance is reported `inaccurate`, never passed off as optimal.
#
# ## Learning goals
#
# * run every installed backend on every formulation it takes, and read status, time, KKT
#   residual and the reaction error against an exact reference (Lemke on the condensed LCP);
# * tell a direct method (Lemke, BPP, PDAS, active-set QP solvers: exact up to rounding) from an
#   iterative one (interior point, ADMM: right to a tolerance);
# * see what the accuracy presets buy, and what a starved iterative solver answers.

# %%
import os, sys, time, warnings
import numpy as np
import matplotlib.pyplot as plt
import plateqp as pq
from plateqp.contact import formulations_for

# HiGHS greets with its licence banner on the C stdout the first time it starts in a process,
# before any option can silence it: start it once with that stdout pointed at /dev/null.
try:
    import highspy
    sys.stdout.flush(); saved, devnull = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    try:
        highspy.Highs()
    finally:
        os.dup2(saved, 1); os.close(saved); os.close(devnull)
except ImportError:
    pass

supports = [pq.Support(x, y, gap=2e-4 * (x + y - 1.0)) for x in (0.2, 0.4, 0.6, 0.8) for y in (0.2, 0.4, 0.6, 0.8)]
scene = pq.Scene(name="nb12", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(12, 12),
                 edges={k: "simple" for k in ("left", "right", "bottom", "top")},
                 loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.7, 0.6)], supports=supports)
ref = pq.solve(scene, backend="lemke", formulation="condensed", accuracy="high").reactions
rows = []
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    for b in pq.available_backends():
        for f in formulations_for(b):
            try:
                r = pq.solve(scene, backend=b, formulation=f, accuracy="default")
                err = np.abs(r.reactions - ref).max() / np.abs(ref).max()
                rows.append((b, f, r.status.value, r.times["solve"], r.kkt.worst, err))
            except pq.PlateQPError as exn:
                rows.append((b, f, type(exn).__name__, np.nan, np.nan, np.nan))
print(f"{'backend':22s} {'formulation':10s} {'status':12s} {'solve s':>8s} {'KKT':>8s} {'R error':>8s}")
for b, f, st, t, k, e in sorted(rows, key=lambda r: (np.nan_to_num(r[3], nan=1e9))):
    print(f"{b:22s} {f:10s} {st:12s} {t:8.4f} {k:8.1e} {e:8.1e}")
# the promise: whatever claims optimal at 'default' is right to about the tolerance
assert all(e < 1e-4 for _, _, st, _, _, e in rows if st == "optimal")

# %% [markdown]
# ## Time against accuracy
#
# Each point is one backend on one formulation. Down is more accurate (the reaction error against
# Lemke), left is faster. The direct methods sit on the floor of rounding error; the iterative
# ones stop as soon as the preset's tolerance is met, which is all `default` asks. On a scene
# this small, the solve times are dominated by each backend's fixed costs (setting up, checking,
# converting matrices), so read the vertical axis more than the horizontal one.

# %%
fig, ax = plt.subplots(figsize=(6, 3.4))
for f, marker in (("primal", "o"), ("condensed", "s"), ("dual", "^")):
    pts = [(t, max(e, 1e-17)) for b, ff, st, t, k, e in rows if ff == f and np.isfinite(t)]
    if pts:
        ax.scatter(*zip(*pts), marker=marker, label=f, alpha=0.7)
ax.set_xscale("log"); ax.set_yscale("log")
ax.set_xlabel("solve time [s]"); ax.set_ylabel("max reaction error / max R")
ax.legend(fontsize=8); fig.tight_layout()
plt.show()

# %% [markdown]
# ### Exercise 1: what the accuracy preset buys
#
# Solve the scene with the interior-point backend `clarabel` at the presets "low" and "high".
# Check that the KKT residual plateqp reports shrinks, and that at "high" the reactions agree
# with the exact Lemke reference to 1e-7 of the largest reaction.

# %%
low = pq.solve(scene, backend="clarabel", accuracy="low")
high = pq.solve(scene, backend="clarabel", accuracy="high")
e_low = np.abs(low.reactions - ref).max() / np.abs(ref).max()
e_high = np.abs(high.reactions - ref).max() / np.abs(ref).max()
print(f"low: KKT {low.kkt.worst:.1e}, error {e_low:.1e};  high: KKT {high.kkt.worst:.1e}, error {e_high:.1e}")
assert high.kkt.worst <= low.kkt.worst
assert e_high < 1e-7

# %% [markdown]
# ### Exercise 2: two exact methods, two routes
#
# A direct method on the primal problem (PDAS, every dof) and Lemke on the condensed LCP (the
# gaps only) share no code past the model. Check that their reactions agree to rounding, and that
# no post pulls on the plate (a one-sided support only pushes).

# %%
a = pq.solve(scene, backend="pdas", formulation="primal", accuracy="high")
b = pq.solve(scene, backend="lemke", formulation="condensed", accuracy="high")
print("max |R_pdas - R_lemke| / max R =", np.abs(a.reactions - b.reactions).max() / np.abs(b.reactions).max())
assert np.allclose(a.reactions, b.reactions, rtol=1e-8, atol=1e-10 * np.abs(b.reactions).max())
assert np.all(a.reactions >= -1e-12 * np.abs(b.reactions).max())

# %% [markdown]
# ### Exercise 3: break it, starve an iterative solver
#
# ADMM (OSQP) converges slowly to high accuracy. Give it only a handful of iterations
# (`options={"max_iter": 5}`) and ask for "high" accuracy: plateqp must not call the answer
# optimal. Check that it does not, and that the reactions it returns are indeed far from the
# reference.

# %%
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    try:
        starved = pq.solve(scene, backend="osqp", accuracy="high", options={"max_iter": 5})
        status, err = starved.status.value, np.abs(starved.reactions - ref).max() / np.abs(ref).max()
    except pq.PlateQPError as exn:
        status, err = type(exn).__name__, np.inf
print(f"osqp with 5 iterations: {status}, reaction error {err:.1e}")
assert status != "optimal"
assert err > 1e-6

# %% [markdown]
# ## Summary
#
# * Every backend is checked against the KKT conditions; `inaccurate` means the residuals missed
#   the tolerance, and an answer marked optimal is right to about that tolerance.
# * Direct methods (Lemke, BPP, PDAS, active-set QP solvers) are exact up to rounding on small
#   contact problems; iterative ones are as accurate as the preset asks.
# * An independent route (primal against condensed) and statics check a solver; a starved
#   iterative solver is caught by the KKT check, not passed on.
# * For scale and the routing rule that picks a backend, see benchmarks/README.md.
