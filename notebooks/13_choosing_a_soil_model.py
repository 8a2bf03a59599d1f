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
# # 13. Choosing a soil model: Winkler, Pasternak, the elastic half-space
#
# Lesson 10 put the slab on posts and on Winkler's springs. Real soil is neither: a footprint
# pressed into clay drags the ground beside it down too. plateqp offers three tensionless soils
# under a plate (`[foundation] model = "winkler" | "pasternak" | "halfspace"`), and this lesson
# puts one slab on all three: a 4 m × 4 m concrete slab, 25 cm thick, carrying its self-weight
# and a 150 kN machine foot, over ground that frost has heaved by 2 mm under one side.
#
# ## Learning goals
#
# * say what each model means physically: independent springs (Winkler), springs joined by a
#   shear layer (Pasternak), the elastic continuum (Boussinesq's half-space);
# * give the three soils comparable stiffness, so that what still differs is the model itself;
# * read the contact pressure, the lift-off zone, the deflection and the bending moment of each;
# * see why a coupled soil's surface needs unknowns of its own beyond the contact rows, and why
#   the problem is still a convex QP (the soil's block of K is symmetric positive definite);
# * measure what lift-off changes, against the same soil bonded to the slab (`pq.solve_bilateral`).
#
# ## Three soils
#
# **Winkler** (1867): a bed of independent springs, pressure p = k v with v the soil's settlement
# at that point. A spring knows nothing of its neighbours, so the ground settles only where it is
# pressed: a rigid slab on a uniform load sinks uniformly, with no pressure peak at its edges.
#
# **Pasternak** (1954): the same springs joined by a layer that carries shear only, of modulus c2
# (force per length): the soil's energy is ½∫(k v² + c2 |∇v|²) dA. A pressed point pulls its
# neighbours down with it; the ratio √(c2/k) is the length over which the ground feels a load.
#
# **Elastic half-space** (Boussinesq 1885): the soil is an unbounded elastic body with Young's
# modulus E and Poisson's ratio ν; a force P on its surface settles a point at distance r by
# P (1 − ν²)/(π E r). Every pressure settles every point of the surface, so its stiffness is a
# dense matrix (Zhemochkin's method: a uniform pressure over each node's share of the bed,
# the settlement taken at the nodes).

# %%
import time
import numpy as np
import matplotlib.pyplot as plt
import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.demo import soils as slab   # the scene and its calibration, shared with `plateqp demo soils`

start = time.perf_counter()
E, H, NU = slab.E, slab.H, slab.NU       # concrete slab [Pa, m]: 4 m × 4 m, 25 cm thick
E_S, NU_S = slab.E_S, slab.NU_S          # the soil: a stiff clay [Pa]
Q, P = slab.Q, slab.P                    # self-weight [Pa], the machine foot [N] at (3, 2)
heave = slab.HEAVE                       # a bump 2 mm deep, 1 m in radius, at (1, 2): g0 < 0, heave
scene = slab.slab_scene                  # scene(foundation, loads=[self-weight, foot]) on a 20 × 20 grid
half = dict(model="halfspace", E=E_S, nu=NU_S)   # 441 bed nodes: the half-space's dense block stays small

# %% [markdown]
# ## Comparable stiffness
#
# A Winkler modulus k is not a property of the soil: it depends on the size of the loaded area.
# So we calibrate the two simpler soils on the half-space, on this slab, with no heave:
#
# 1. **k** from the self-weight alone: the half-space (bonded) settles the slab by a mean w̄;
#    k = q / w̄ makes a Winkler or Pasternak bed carry the same load with the same mean settlement
#    (on a free plate under uniform q both settle exactly q/k: exercise 1).
# 2. **c2** from the machine foot alone: the shear layer's modulus for which the Pasternak bed
#    settles under the foot as much as the half-space does (a root in one variable).
#
# The scene and these two steps live in `plateqp.demo.soils` (`slab_scene`, `calibrate`), so
# that `plateqp demo soils` shows the same slab on the same three soils.

# %%
cal = slab.calibrate()   # both steps above: bonded solves, then brentq for c2 (read its twenty lines)
k, c2 = cal.k, cal.c2
print(f"k = {k / 1e6:.2f} MN/m³, c2 = {c2 / 1e6:.2f} MN/m, soil length √(c2/k) = {cal.length:.2f} m")
print(f"under the foot alone, bonded: half-space {cal.w_foot * 1e3:.3f} mm, "
      f"Winkler {cal.w_foot_winkler * 1e3:.3f} mm")
a_eq = np.sqrt(16.0 / np.pi)   # the rigid disc of the slab's area: P (1 − ν²)/(2 a E) over P/A
print(f"a rigid disc of the same area would give k = {2 * a_eq * E_S / (16.0 * (1 - NU_S**2)) / 1e6:.2f} MN/m³")
soils = slab.beds(cal)   # Winkler, Pasternak and the half-space, all heaved by the bump

# %% [markdown]
# The fitted k (9.4 MN/m³) is close to what a rigid disc of the slab's area would give on this
# clay (Boussinesq's punch of exercise 2, k = 2aE / (A (1 − ν²)) = 9.3 MN/m³): the slab is
# stiff. The fitted soil length √(c2/k) comes out at about 1.2 m, over a quarter of the slab:
# the half-space spreads a point load's settlement that far, and Winkler's springs, with the
# same k, let the foot sink a quarter more (2.03 mm against 1.62 mm).
#
# ## One slab, three soils, one-sided and bonded

# %%
one, two = {}, {}
for name, fnd in soils.items():
    sc = scene(fnd)
    model = build_model(sc)                  # one assembly (the half-space's dense block) for both
    one[name] = pq.solve(sc, accuracy=1e-10, model=model)
    two[name] = pq.solve_bilateral(sc, model)
    assert one[name].status == pq.Status.OPTIMAL and one[name].kkt.ok


pressure = slab.pressure   # the contact pressure at each bed node: its reaction over its tributary area [Pa]
section = slab.SECTION     # y = 2 m, through the heave and the foot
print(f"{'':11s} {'lifted':>7s} {'p max':>8s} {'w foot':>7s} {'Mx max':>7s} | bonded: {'p min':>7s} {'Mx max':>7s}"
      f" {'max |Δw|':>8s}")
for name in soils:
    r, b = one[name], two[name]
    print(f"{name:11s} {(~r.active).sum():3d}/{r.active.size} {pressure(r).max() / 1e3:6.0f} kPa "
          f"{r.deflection(3.0, 2.0) * 1e3:5.2f}mm {r.section(*section, quantity='Mx')[1].max() / 1e3:5.1f}kN "
          f"|        {pressure(b).min() / 1e3:5.0f}kPa {b.section(*section, quantity='Mx')[1].max() / 1e3:5.1f}kN "
          f"{np.abs(r.w_nodes() - b.w_nodes()).max() * 1e3:6.2f}mm")
    total = Q * 16.0 + P
    assert abs(r.reactions.sum() - total) < 1e-8 * total          # statics: the soil carries it all
    assert r.reactions.min() >= 0 and (pressure(b) < 0).any()     # one-sided pushes; bonded pulls

# %% [markdown]
# (p is the contact pressure, Mx the largest bending moment along y = 2 m, max |Δw| the largest
# change of the deflection when the soil is bonded.) Read the table row by row. On **Winkler's**
# springs the bump is a pre-compression of the springs over it: pressed flat, they push back
# with only k × 2 mm ≈ 19 kPa, the slab tilts a little and lifts off a strip 0.2 m wide along
# its left edge (29 nodes); the pressure stays below 32 kPa everywhere. On **Pasternak's** bed
# the bump is much stiffer: to press a hump 1 m in radius flat, the shear layer must drag its
# surroundings down too. The slab rides on the crest (214 kPa there), lifts off over the ring
# around it and most of the left half (239 of 441 nodes), and spans to the ground under the
# foot. The **half-space** is in between (128 nodes lifted, about 90 kPa on the crest), and its
# pressure peaks at the far edge and corners (212 kPa at a corner): the continuum's edge
# singularity, the rigid punch's 1/√(a² − r²) of exercise 2. The moment under the foot changes
# by about a tenth between the models, the pressures by a factor of seven: the slab's stiffness
# smooths what the soil does, and the soil model matters most for the soil's own stresses.
#
# Bonded (two-sided), every soil pulls the slab down somewhere (a negative pressure), the
# coupled soils hardest (165 kPa of tension on Pasternak's bed), because they would have to hold
# down a whole region. On Winkler's springs lift-off changes the deflection by 0.02 mm; on the
# half-space by 0.19 mm; on Pasternak's bed by a millimetre, half the heave.
#
# ## The figure: pressure maps, then three sections along y = 2 m

# %%
fig, axes = plt.subplots(2, 3, figsize=(11, 6.4), layout="constrained")
vmax = max(pressure(r).max() for r in one.values()) / 1e3
for ax, (name, r) in zip(axes[0], one.items()):
    xy, p = r.model.contacts.xy, pressure(r) / 1e3
    dots = ax.scatter(xy[r.active, 0], xy[r.active, 1], c=p[r.active], s=22, marker="s", cmap="viridis",
                      vmin=0, vmax=min(vmax, 120))
    ax.scatter(xy[~r.active, 0], xy[~r.active, 1], s=8, c="C3", marker="x", label="lifted off")
    ax.add_patch(plt.Circle((1.0, 2.0), 1.0, fill=False, ls=":", color="k"))
    ax.plot(3.0, 2.0, "w*", ms=12, mec="k")
    ax.set_title(f"{name}: {(~r.active).sum()} of {r.active.size} lifted off", fontsize=9)
    ax.set_aspect("equal"); ax.set_xticks([0, 2, 4]); ax.set_yticks([0, 2, 4])
fig.colorbar(dots, ax=axes[0].tolist(), label="contact pressure [kPa] (capped)", shrink=0.8)
axes[0][0].legend(fontsize=7, loc="lower left")
for name, colour in zip(soils, ("C0", "C1", "C2")):
    r, b = one[name], two[name]
    s, w = r.section(*section, quantity="w")
    axes[1][0].plot(s, w * 1e3, colour, label=name)
    axes[1][0].plot(s, b.section(*section, quantity="w")[1] * 1e3, colour, ls="--", lw=0.8)
    axes[1][1].plot(s, r.section(*section, quantity="Mx")[1] / 1e3, colour, label=name)
    on = np.abs(r.model.contacts.xy[:, 1] - 2.0) < 1e-9
    axes[1][2].plot(r.model.contacts.xy[on, 0], pressure(r)[on] / 1e3, colour, marker=".", label=name)
axes[1][0].invert_yaxis(); axes[1][0].set_ylabel("w [mm] (down; dashed: bonded)")
axes[1][1].set_ylabel("Mx [kN·m/m]"); axes[1][2].set_ylabel("pressure [kPa]")
for ax in axes[1]:
    ax.set_xlabel("x along y = 2 m [m]"); ax.legend(fontsize=7)
plt.show()

# %% [markdown]
# ## Why the soil's surface has unknowns of its own
#
# For Winkler's springs a bed node that lifts off is simply a spring that is not touched: its
# settlement is zero and the flexibility 1/(k A) of each spring sits on its own contact row. A
# coupled soil is different: where the slab has lifted off, the ground is still moving, dragged
# down by the shear layer or settling under the pressure nearby. The gap between slab and soil is
# then g0 + v − w, and v is not known until the whole soil's equilibrium is. So plateqp appends
# the soil's settlement v at every bed node to the unknowns, beside the plate's dofs:
#
#     min  ½ uᵀ K u − fᵀ u + ½ vᵀ K_s v     s.t.   w(u) − v ≤ g0 .
#
# The multiplier of each row is the force R ≥ 0 between slab and soil, and stationarity in v is
# the soil's own equilibrium K_s v = R: where R = 0 the soil is where the pressures elsewhere put
# it. Below we check both: the ground beside the contact settles though no pressure acts on it,
# and K_s v = R row by row.

# %%
for name, r in one.items():
    v, lifted = r.compressions, ~r.active
    print(f"{name:11s} soil's settlement where the slab lifted off: up to {v[lifted].max() * 1e3 + 0.0:6.3f} mm"
          f"  (n_soil = {r.model.n_soil})")
    if r.model.n_soil:
        m = r.model
        Ks = m.K[m.n_free:, m.n_free:]
        Ks = Ks.toarray() if hasattr(Ks, "toarray") else np.asarray(Ks)
        assert np.allclose(Ks @ v, r.reactions, rtol=0, atol=1e-8 * r.reactions.max())
        eig = np.linalg.eigvalsh(0.5 * (Ks + Ks.T))
        print(f"{'':11s} K_s: {Ks.shape[0]} × {Ks.shape[1]}, {np.count_nonzero(Ks) / Ks.size:.1%} filled, "
              f"symmetric, eigenvalues {eig.min():.3g} … {eig.max():.3g} N/m")
        assert np.allclose(Ks, Ks.T, rtol=0, atol=1e-12 * np.abs(Ks).max()) and eig.min() > 0
    else:
        assert np.all(v[lifted] == 0)   # a spring nobody presses does not move

# %% [markdown]
# ## Still a convex QP
#
# The energy adds ½ vᵀ K_s v to the plate's ½ uᵀ K u, and K_s is symmetric positive definite:
# for Pasternak the sparse sum k·diag(A) + c2·L (a mass-like diagonal plus the Laplacian's
# stiffness), for the half-space the inverse of a symmetric flexibility, dense. The constraints
# are still linear, w(u) − v ≤ g0 (one −1 per row in the soil's column). So the whole problem
# is a convex QP of the same shape as every lesson before: the primal, condensed and dual
# formulations, every backend and the KKT check hold it unchanged. What changes is the cost: the
# Pasternak block is as sparse as the plate's, the half-space block is full (here 441² numbers;
# plateqp takes up to 4000 bed nodes on this dense route).
#
# ### Exercise 1: a free slab on Pasternak's bed settles q/k
#
# A free plate under a uniform load q on a Pasternak bed over its whole area: if plate and soil
# both settle q/k everywhere, the shear layer stays flat (no shear force), every spring carries
# q, and the plate is not bent, so that is the answer, whatever c2 is. Check it on a
# 2 m × 1.5 m plate of triangles (DKT, whose uniform load puts no moment at the free edge, so the
# answer is exact to rounding): the plate's deflection and the soil's settlement at every node.

# %%
q1, k1 = 2e4, 1e7
sc1 = pq.Scene(plate=pq.Plate(a=2.0, b=1.5, h=0.2, E=E, nu=NU), mesh=pq.MeshSpec(element="dkt", size=0.25),
               loads=[pq.UniformLoad(q1)], foundation=pq.Foundation(model="pasternak", k=k1, shear=1e6))
r1 = pq.solve(sc1, backend="bpp", formulation="condensed", accuracy=1e-10)
print(f"w / (q/k): {r1.nodal('w').min() / (q1 / k1):.10f} … {r1.nodal('w').max() / (q1 / k1):.10f}")
assert r1.status == pq.Status.OPTIMAL and r1.active.all()
assert np.allclose(r1.nodal("w"), q1 / k1, rtol=1e-7, atol=0)        # the closed form q/k
assert np.allclose(r1.compressions, q1 / k1, rtol=1e-7, atol=0)      # the soil too
assert abs(r1.reactions.sum() - q1 * 3.0) < 1e-9 * q1 * 3.0          # statics

# %% [markdown]
# ### Exercise 2: a rigid disc on the half-space settles as Boussinesq's punch
#
# A rigid circular punch of radius a, pressed into an elastic half-space by a central force P,
# settles P (1 − ν²)/(2 a E) (Boussinesq; Johnson, *Contact Mechanics*, § 3.2). Make a disc of
# radius 1 m a thousand times stiffer than the soil (E_p h³ / (E_s a³) = 1000), put it on the
# clay on a coarse triangle mesh (size a/8, about 300 bed nodes), and check its settlement
# within 3 %. The error is the punch's edge singularity, which a coarse mesh smooths; it halves
# with the mesh size.

# %%
a, h2, P2 = 1.0, 0.5, 1e5
disc = pq.Scene(plate=pq.Plate(shape={"circle": [0.0, 0.0, a]}, h=h2, E=1e3 * E_S * a**3 / h2**3, nu=0.2),
                mesh=pq.MeshSpec(element="dkt", size=a / 8), loads=[pq.PointLoad(P=P2, x=0.0, y=0.0)],
                foundation=pq.Foundation(**half))
r2 = pq.solve(disc, accuracy=1e-8)
punch = P2 * (1 - NU_S**2) / (2 * a * E_S)
print(f"{r2.active.size} bed nodes; settlement {r2.deflection(0.0, 0.0) * 1e3:.4f} mm, "
      f"Boussinesq {punch * 1e3:.4f} mm ({r2.deflection(0.0, 0.0) / punch - 1:+.1%})")
assert r2.active.all() and abs(r2.reactions.sum() - P2) < 1e-8 * P2
assert abs(r2.deflection(0.0, 0.0) / punch - 1) < 0.03

# %% [markdown]
# ### Exercise 3: Pasternak without shear is Winkler
#
# Set `shear = 0` in the heaved slab's Pasternak bed. The shear layer is gone and the soil's
# energy is ½∫k v² dA with Winkler's own nodal areas: the same soil as Winkler's springs, posed
# the other way (settlements as unknowns instead of flexibilities on the rows). Check that the
# reactions, the lift-off zone and the deflection are Winkler's, to rounding.

# %%
r3 = pq.solve(scene(pq.Foundation(model="pasternak", k=k, shear=0.0, gap=heave)), accuracy=1e-10)
win = one["Winkler"]
print(f"n_soil {r3.model.n_soil} against {win.model.n_soil}; "
      f"largest reaction difference {np.abs(r3.reactions - win.reactions).max():.2e} N")
assert (r3.active == win.active).all()
assert np.allclose(r3.reactions, win.reactions, rtol=0, atol=1e-7 * win.reactions.max())
assert np.allclose(r3.w_nodes(), win.w_nodes(), rtol=0, atol=1e-7 * np.abs(win.w_nodes()).max())

# %% [markdown]
# ### Exercise 4: break it, glue the slab to the half-space
#
# `pq.solve_bilateral` bonds the soil to the slab: a linear solve, no contact conditions. Statics
# still holds (the reactions still carry the load), but somewhere the half-space now pulls the
# slab down. Find where, and check that the pull sits where the one-sided slab lifted off (the
# bond holds down what would have let go), and how much the bond changes the deflection and the
# largest moment.

# %%
r, b = one["half-space"], two["half-space"]
pull = b.reactions < 0
Mx = {n: res.section(*section, quantity="Mx")[1].max() for n, res in (("one", r), ("bonded", b))}
print(f"bonded: {pull.sum()} of {pull.size} bed nodes in tension, pulling {-b.reactions[pull].sum() / 1e3:.1f} kN "
      f"in all, centred at x = {b.reactions[pull] @ b.model.contacts.xy[pull, 0] / b.reactions[pull].sum():.2f} m")
print(f"w over the heave {r.deflection(1, 2) * 1e3:.3f} → {b.deflection(1, 2) * 1e3:.3f} mm; "
      f"Mx max {Mx['one'] / 1e3:.1f} → {Mx['bonded'] / 1e3:.1f} kN·m/m; "
      f"{(pull & ~r.active).sum()} of the {pull.sum()} pulling nodes lift off one-sided")
assert abs(b.reactions.sum() - r.reactions.sum()) < 1e-8 * r.reactions.sum()   # statics holds both ways
assert pull.any() and r.reactions.min() >= 0                                    # the bond pulls
assert (pull & ~r.active).sum() >= 0.9 * pull.sum()                            # where it would let go
print(f"the lesson ran in {time.perf_counter() - start:.1f} s")

# %% [markdown]
# ## Summary
#
# * Winkler's springs are independent: the ground settles only where pressed, a heave is a
#   pre-compression, and the pressure under a stiff slab stays flat. Pasternak's shear layer and
#   the elastic half-space couple the surface: the ground around a heave rises over a region,
#   the slab spans it and lifts off far more, and the pressure peaks at the slab's edges.
# * Give the models comparable stiffness before comparing them (here k from the mean settlement
#   under the self-weight, c2 from the settlement under the foot, both fitted to the half-space);
#   what remains different is the model.
# * A coupled soil's surface moves where nothing presses it, so its settlement v is an unknown at
#   every bed node; the soil's block K_s is symmetric positive definite (sparse for Pasternak,
#   dense for the half-space), and the problem stays a convex QP solved by every formulation.
# * Checked against: q/k on a free plate (Pasternak), Boussinesq's rigid punch (half-space),
#   `shear = 0` against Winkler's springs, and the bonded soil, which pulls the slab down where
#   the one-sided slab lifts off.
# * The numbers here: with comparable stiffness, 29, 239 and 128 of 441 bed nodes lift off on
#   Winkler, Pasternak and the half-space; the largest pressure is 32, 214 and 212 kPa; the
#   largest moment 51.5, 54.8 and 57.1 kN·m/m. Which model to choose is a question about the
#   soil (does its surface couple, and over what length?), not about the slab.
