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
# # 10. The plate: the paper's heave, settlement and stiffness studies
#
# Lessons 1 to 9 built the machinery on small problems: a beam, two supports, a tableau. Now the
# full plate of the source paper: an 8 m × 8 m floor slab of concrete, 20 cm thick, floating on
# a 5 × 5 grid of one-sided supports (pedestals on the soil, the slab not tied to them), carrying
# its self-weight and a 30 tf machine foot. The scenes are the demo's own
# (`plateqp.scenes.load("heave")`, the same files that `plateqp demo` solves), so every number
# below is the demo's number.
#
# ## Learning goals
#
# * load the paper's scenes and solve them one-sided (the contact QP) and two-sided (every
#   support holds the plate both ways, a linear solve);
# * read a working scheme: which supports are in contact, which lift off, which the slab bridges;
# * see why the two-sided model is wrong exactly where the soil moved: it asks the supports to
#   pull the slab down;
# * check an answer by statics (the reactions carry the whole load of a floating plate) and by
#   the constitutive law of an elastic support (R = c · compression).

# %%
import numpy as np
import matplotlib.pyplot as plt
import plateqp as pq
from plateqp import scenes

studies = {name: scenes.load(name) for name in ("heave", "settlement", "stiffness")}
one, two = {}, {}
for name, sc in studies.items():
    one[name] = pq.solve(sc, backend="lemke", formulation="condensed", accuracy="high")
    two[name] = pq.solve_bilateral(sc)
    w1, w2 = one[name].w_nodes(), two[name].w_nodes()
    print(f"{name:10s}: {one[name].active.sum():2d} of {one[name].active.size} supports in contact, "
          f"max w one-sided {np.nanmax(w1):.4f} cm, two-sided {np.nanmax(w2):.4f} cm, "
          f"two-sided reactions in tension: {int((two[name].reactions < 0).sum())}")
    plate = sc.plate
    total = sum(l.P for l in sc.loads if l.type == "point") + \
        sum(l.q for l in sc.loads if l.type == "uniform") * plate.a * plate.b
    assert abs(one[name].reactions.sum() - total) < 1e-8 * total   # statics: a floating plate

# %% [markdown]
# In the heave study, frost has pushed supports 1, 2 and 6 (near the corner at the origin) up by
# 2 mm, a negative initial gap. The one-sided slab rides on the heaved supports, bridges over
# their neighbours and lifts off several supports far away: 17 of 25 stay in contact. Held
# two-sided, the same slab would need several supports to pull it down, which pedestals standing
# on soil cannot do. The settlement study is the mirror image: three supports have sunk (positive
# gaps), the slab spans over them and the other supports carry more. In the stiffness study each
# support is a pad footing on soil, an elastic support whose reaction grows with its compression.
#
# ## Deflection along a section through the load (solid one-sided, dashed two-sided)
#
# The section runs along y = 500 cm, through the machine foot. Where the two curves agree the
# contact set and the two-sided set coincide; where they part, the one-sided plate has lifted off.

# %%
fig, ax = plt.subplots(figsize=(6, 3))
for (name, colour) in (("heave", "C0"), ("settlement", "C1"), ("stiffness", "C2")):
    s, w1 = one[name].section((0.0, 500.0), (800.0, 500.0))
    _, w2 = two[name].section((0.0, 500.0), (800.0, 500.0))
    ax.plot(s, w1, colour, label=f"{name}, one-sided")
    ax.plot(s, w2, colour, ls="--", label=f"{name}, two-sided")
ax.invert_yaxis(); ax.set_xlabel("x along y = 500 cm [cm]"); ax.set_ylabel("w [cm] (down)")
ax.legend(fontsize=7); fig.tight_layout()
plt.show()

# %% [markdown]
# ## The working scheme of the heave study
#
# Each support drawn as a dot, filled where it presses on the slab, open where the slab lifts off
# (or just touches with no force). The size of a filled dot is its reaction.

# %%
sc, r = studies["heave"], one["heave"]
x = np.array([s.x for s in sc.supports]); y = np.array([s.y for s in sc.supports])
fig, ax = plt.subplots(figsize=(3.6, 3.6))
ax.scatter(x[r.active], y[r.active], s=4 + r.reactions[r.active] / 60.0, c="C0", label="contact")
ax.scatter(x[~r.active], y[~r.active], s=30, facecolors="none", edgecolors="C3", label="lifted off")
ax.plot([300.0], [500.0], "k*", label="machine foot")
ax.set_aspect("equal"); ax.set_xlim(-60, 860); ax.set_ylim(-60, 860); ax.legend(fontsize=7, loc="upper right")
plt.show()

# %% [markdown]
# ### Exercise 1: statics by hand
#
# The slab floats: only the supports hold it. Compute, from the scene file alone, the total load
# (the machine foot plus the self-weight q · a · b) and the moment of the load about the axis
# x = 0, and check that the one-sided reactions of the settlement study balance both.

# %%
sc, r = studies["settlement"], one["settlement"]
P = [l for l in sc.loads if l.type == "point"][0]
q = [l for l in sc.loads if l.type == "uniform"][0].q
load = P.P + q * sc.plate.a * sc.plate.b
moment = P.P * P.x + q * sc.plate.a * sc.plate.b * sc.plate.a / 2      # about x = 0
xs = np.array([s.x for s in sc.supports])
print(f"load {load:.1f} kgf, reactions {r.reactions.sum():.1f}; moment {moment:.4g}, reactions' {r.reactions @ xs:.4g}")
assert abs(r.reactions.sum() - load) < 1e-8 * load
assert abs(r.reactions @ xs - moment) < 1e-6 * moment

# %% [markdown]
# ### Exercise 2: an elastic support obeys its law
#
# In the stiffness study each support is a spring of stiffness c (kgf/cm) under a heaved base
# (initial gap g0 < 0 for the heaved ones). A spring in contact is compressed by w − g0, where w
# is the slab's deflection at the support. Check R = c · (w − g0) at every support in contact,
# with w read from the deflection field, an independent route from the solver's reactions.

# %%
sc, r = studies["stiffness"], one["stiffness"]
for i, s in enumerate(sc.supports):
    if r.active[i]:
        law = s.stiffness * (r.deflection(s.x, s.y) - s.gap)
        assert abs(r.reactions[i] - law) < 1e-6 * max(r.reactions), (i, r.reactions[i], law)
print(f"{r.active.sum()} springs in contact, each with R = c (w - g0)")

# %% [markdown]
# ### Exercise 3: break it, hold the slab two-sided
#
# Replace the one-sided supports by two-sided ones (`pq.solve_bilateral`) in the heave study.
# Statics still holds (the reactions still add up to the load), but what the soil would have to
# give is no longer a push: find the supports with a negative reaction and check that the
# one-sided answer has none. This is the failure the whole course is about.

# %%
r2 = two["heave"]
tension = np.flatnonzero(r2.reactions < 0)
print("two-sided supports pulling the slab down:", [int(i) + 1 for i in tension],
      f"(largest pull {-r2.reactions.min() / 1000:.1f} tf)")
assert abs(r2.reactions.sum() - one["heave"].reactions.sum()) < 1e-6 * r2.reactions.sum()
assert tension.size > 0                              # the two-sided model needs tension
assert np.all(one["heave"].reactions >= 0)           # the one-sided one does not

# %% [markdown]
# ## Summary
#
# * The demo's scenes (`plateqp.scenes.load`) are the paper's studies; solving them here gives
#   the demo's numbers: 17 of 25 supports in contact under heave.
# * Two-sided support is a linear solve and is wrong where the soil moved: it pulls the slab down.
# * Statics (force and moment) and each support's constitutive law check an answer without
#   trusting the solver.
# * Lesson 11 turns the gaps from data into design variables.
