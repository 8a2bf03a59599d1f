# Regenerates the teaching notebooks (python notebooks/make_notebooks.py); edit here, not in the .ipynb.
from pathlib import Path

import nbformat as nbf
from nbformat.v4 import new_notebook, new_markdown_cell as md, new_code_cell as code

HERE = Path(__file__).resolve().parent

def save(name, cells):
    nb = new_notebook(cells=cells, metadata={"kernelspec": {"name": "python3", "display_name": "Python 3", "language": "python"}})
    nbf.write(nb, HERE / name)

save("01_contact_as_a_qp.ipynb", [
md("""# 1. Contact as a convex QP: three formulations side by side

A plate on one-sided supports minimises its potential energy subject to *gap ≥ 0*. We write the
three standard forms of plateqp (primal, condensed, dual) **by hand in cvxpy** from the same
nondimensional data, solve each, and check the KKT conditions ourselves with NumPy:

* stationarity  K u − f + Bᵀ R = 0
* primal feasibility  gap = g0 + s − B u ≥ 0
* dual feasibility  R ≥ 0
* complementarity  R_i · gap_i = 0 for every support"""),
code("""import numpy as np
import cvxpy as cp
import plateqp as pq
from plateqp.assembly import build_model
from plateqp.contact import Scaled, formulate

# a free plate on a 3 x 3 grid of rigid supports; one corner support settled, a point load
supports = [pq.Support(x, y, gap=(0.002 if (x, y) == (1.0, 1.0) else 0.0))
            for x in (0.0, 0.5, 1.0) for y in (0.0, 0.5, 1.0)]
scene = pq.Scene(name="nb1", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
                 loads=[pq.PointLoad(50.0, 0.6, 0.4), pq.UniformLoad(5.0)], supports=supports)
d = Scaled.from_model(build_model(scene))   # K, f, B, g0, rho: nondimensional
print(f"{d.n} free dofs, {d.m} supports, floating plate: {d.floating}")"""),
md("""## Primal: all dofs
minimise ½ uᵀKu − fᵀu subject to B u ≤ g0 (rigid supports, so no spring variables).
The plate floats (no two-sided support), so K is only positive *semi*definite; the QP is
still bounded because the supports can carry the load."""),
code("""u = cp.Variable(d.n)
cons = [d.B @ u <= d.g0]
primal = cp.Problem(cp.Minimize(0.5 * cp.quad_form(u, cp.psd_wrap(d.K)) - d.f @ u), cons)
primal.solve(solver="CLARABEL")
u_p, R_p = u.value, cons[0].dual_value
print(primal.status, "reactions (scaled):", np.round(R_p, 4))"""),
md("""## Condensed: the gaps at the supports (the source paper's route)
Static condensation of every non-contact dof gives the LCP R = M z + q with z the gaps:
the KKT system of  minimise ½ zᵀMz + qᵀz, z ≥ 0."""),
code("""cond = formulate(d, "condensed")
M, q = cond.lcp.M, cond.lcp.q
z = cp.Variable(d.m)
c2 = [z >= 0]
cp.Problem(cp.Minimize(0.5 * cp.quad_form(z, cp.psd_wrap(M)) + q @ z), c2).solve(solver="CLARABEL")
R_c = M @ z.value + q       # the reactions are the multipliers of z >= 0
print("reactions (scaled):", np.round(R_c, 4))"""),
md("""## Dual: the reactions
With the flexibility G = B K⁻¹ Bᵀ the gaps are gap = G R + d. K⁻¹ needs two-sided supports
that hold the plate: ours floats, so plateqp refuses the dual clearly. We hold the plate with
three pins (its supports then act on top of a held plate) to show the dual."""),
code("""try:
    formulate(d, "dual")
except pq.ProblemError as exn:
    print("refused:", exn)

held = pq.Scene(name="nb1-held", plate=scene.plate, mesh=scene.mesh, loads=scene.loads,
                supports=[s for s in supports if (s.x, s.y) not in ((0, 0), (1, 0), (0, 1))],
                pins=[pq.Pin(0.0, 0.0), pq.Pin(1.0, 0.0), pq.Pin(0.0, 1.0)])
dh = Scaled.from_model(build_model(held))
dual = formulate(dh, "dual")
R = cp.Variable(dh.m)
cp.Problem(cp.Minimize(0.5 * cp.quad_form(R, cp.psd_wrap(dual.lcp.M)) + dual.lcp.q @ R), [R >= 0]).solve(solver="CLARABEL")
cond_h = formulate(dh, "condensed")
zh = cp.Variable(dh.m)
cp.Problem(cp.Minimize(0.5 * cp.quad_form(zh, cp.psd_wrap(cond_h.lcp.M)) + cond_h.lcp.q @ zh), [zh >= 0]).solve(solver="CLARABEL")
print("dual      R:", np.round(R.value, 5))
print("condensed R:", np.round(cond_h.lcp.M @ zh.value + cond_h.lcp.q, 5))"""),
md("## The KKT conditions, checked by hand (primal solution of the floating plate)"),
code("""gap = d.g0 - d.B @ u_p
stationarity = np.linalg.norm(d.K @ u_p - d.f + d.B.T @ R_p) / np.linalg.norm(d.f)
print(f"stationarity      {stationarity:.1e}")
print(f"min gap           {gap.min():.1e}   (>= 0 up to the solver tolerance)")
print(f"min reaction      {R_p.min():.1e}   (>= 0)")
print(f"max |R_i gap_i|   {np.abs(R_p * gap).max():.1e}")
assert stationarity < 1e-6 and gap.min() > -1e-6 and R_p.min() > -1e-6
np.testing.assert_allclose(R_p, R_c, atol=1e-5 * np.abs(R_c).max())   # primal and condensed agree"""),
md("## The same through plateqp, in the user's units, with its own KKT report"),
code("""res = pq.solve(scene, backend="lemke", formulation="condensed", accuracy="high")
print(res.status, res.kkt.as_dict())
print("reactions:", np.round(res.reactions, 3), " sum:", res.reactions.sum(), "= load", 50 + 5)
np.testing.assert_allclose(res.reactions / d.F0, R_c, atol=1e-5 * np.abs(R_c).max())"""),
])

save("02_lemke_step_by_step.ipynb", [
md("""# 2. Lemke's method step by step

Lemke's complementary pivoting solves the condensed LCP  R = M z + q, z ≥ 0, R ≥ 0, zᵀR = 0
(z the gaps, R the reactions). It adds an artificial variable z0 with a *covering vector* d:
R = M z + q + d z0. Starting from z0 large enough every "reaction" is non-negative: the
source paper reads d z0 as a **uniform pre-compression** of all supports. Each pivot then
exchanges one support between the two states (its gap enters the basis: it opens; its
reaction enters: it presses) until the pre-compression z0 reaches zero."""),
code("""import numpy as np
import plateqp as pq
from plateqp.backends import lemke
from plateqp.assembly import build_model
from plateqp.contact import Scaled, formulate

supports = [pq.Support(x, y, gap=(-0.05 if (x, y) in ((0.5, 0.0), (1.0, 0.0)) else 0.0))
            for x in (0.5, 0.75, 1.0) for y in (0.0, 0.5, 1.0)]
scene = pq.Scene(name="nb2", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
                 edges={"left": "simple"}, loads=[pq.PointLoad(40.0, 0.7, 0.7)], supports=supports)
data = Scaled.from_model(build_model(scene))   # nondimensional: gaps in units of data.W
lcp = formulate(data, "condensed").lcp
raw = lemke.lemke(lcp.M, lcp.q, trace=True)
names = {"z": "gap of support", "w": "reaction at support"}
for step in raw.extras["trace"]:
    e, l = step["entering"], step["leaving"]
    ent = "z0 (pre-compression)" if e[0] == "z0" else f"{names[e[0]]} {e[1]}"
    lea = "z0 (pre-compression)" if l[0] == "z0" else f"{names[l[0]]} {l[1]}"
    print(f"pivot {step['step']:2d}: enters {ent:28s} leaves {lea:28s} z0 = {step['z0']:.4g}")"""),
md("Every pivot is a support entering or leaving contact; when z0 leaves, the working scheme is found:"),
code("""z = raw.x
R = lcp.M @ z + lcp.q
for i, s in enumerate(scene.supports):
    state = "contact" if R[i] > 1e-12 else "lifted off"
    print(f"support {i} at ({s.x}, {s.y}) gap0 {s.gap:+.3f}: {state:10s} R = {R[i] * data.F0:8.4f}, gap = {z[i] * data.W:.2e}")
assert np.all(z >= 0) and np.all(R >= -1e-12) and abs(z @ R) < 1e-12"""),
md("""## Any positive covering vector gives the same answer
The pre-compression may be non-uniform: the path of pivots changes, the solution does not
(M is positive definite here because the simple edge holds the plate)."""),
code("""for d in (np.ones(lcp.n), np.linspace(1, 5, lcp.n), np.random.default_rng(0).uniform(0.1, 10, lcp.n)):
    r = lemke.lemke(lcp.M, lcp.q, covering=d)
    print(f"{r.iterations:2d} pivots, max |z - z_uniform| = {np.abs(r.x - z).max():.1e}")
    np.testing.assert_allclose(r.x, z, atol=1e-12)"""),
md("""Notebook 12 opens the method up: the tableau before every pivot, the path of z0, and a plate
with no equilibrium, where Lemke ends on a ray that proves it."""),
])

save("03_heave_and_settlement.ipynb", [
md("""# 3. Heave and settlement: one-sided against two-sided support

The source paper's first two studies: a plate on discrete supports under a point load, the
soil heaving under some supports (negative gaps) or settling (positive gaps). We compare the
one-sided solution with the two-sided one (every support holds the plate both ways), as the
paper does: in the lift-off zones the two differ a lot, in the contact zone little."""),
code("""import numpy as np
import plateqp as pq

def grid_scene(name, gaps):
    xs = (0.0, 100.0, 200.0, 300.0, 400.0)
    sups = [pq.Support(x, y, gap=gaps.get((x, y), 0.0)) for x in xs for y in xs]
    return pq.Scene(name=name, plate=pq.Plate(400.0, 400.0, 20.0, 2e5, 0.2), mesh=pq.MeshSpec(16, 16),
                    loads=[pq.PointLoad(20000.0, 150.0, 250.0), pq.UniformLoad(0.05)], supports=sups)

heave = grid_scene("heave", {(0.0, 0.0): -0.02, (100.0, 0.0): -0.02, (0.0, 100.0): -0.02})
settle = grid_scene("settlement", {(300.0, 300.0): 0.02, (400.0, 400.0): 0.02, (300.0, 400.0): 0.02})
for sc in (heave, settle):
    one = pq.solve(sc, backend="lemke", formulation="condensed", accuracy="high")
    two = pq.solve_bilateral(sc)
    w1, w2 = one.w_nodes(), two.w_nodes()
    print(f"{sc.name}: {one.active.sum()} of {one.active.size} supports in contact, "
          f"max w one-sided {np.nanmax(w1):.4f} cm, two-sided {np.nanmax(w2):.4f} cm, "
          f"max |difference| {np.nanmax(np.abs(w1 - w2)):.4f} cm")
    print("   two-sided reactions below zero (tension the soil cannot give):", int((two.reactions < 0).sum()))
    total = 20000.0 + 0.05 * 400.0**2
    assert abs(one.reactions.sum() - total) < 1e-8 * total     # statics: a floating plate"""),
md("## Deflection along a section through the load (solid one-sided, dashed two-sided)"),
code("""import matplotlib.pyplot as plt  # the notebook's own (inline) backend: the figure shows
fig, ax = plt.subplots(figsize=(6, 3))
for sc, colour in ((heave, "C0"), (settle, "C1")):
    one = pq.solve(sc, backend="lemke", formulation="condensed")
    two = pq.solve_bilateral(sc)
    s, w1 = one.section((0.0, 250.0), (400.0, 250.0))
    _, w2 = two.section((0.0, 250.0), (400.0, 250.0))
    ax.plot(s, w1, colour, label=f"{sc.name}, one-sided")
    ax.plot(s, w2, colour, ls="--", label=f"{sc.name}, two-sided")
ax.invert_yaxis(); ax.set_xlabel("x along y = 250 cm [cm]"); ax.set_ylabel("w [cm] (down)")
ax.legend(fontsize=7); fig.tight_layout()
plt.show()"""),
])

save("04_backends_compared.ipynb", [
md("""# 4. Backends compared on speed and accuracy

Every installed backend on every formulation it takes, on one small scene: solve time, the
worst KKT residual, and the reaction error against Lemke on the condensed LCP (exact up to
rounding). A status `inaccurate` is the backend's answer with residuals above the preset's
tolerance: plateqp says so instead of passing it as optimal. (The full study is in
benchmarks/.)"""),
code("""import time, warnings
import numpy as np
import plateqp as pq
from plateqp.contact import formulations_for

supports = [pq.Support(x, y, gap=2e-4 * (x + y - 1.0)) for x in (0.2, 0.4, 0.6, 0.8) for y in (0.2, 0.4, 0.6, 0.8)]
scene = pq.Scene(name="nb4", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(12, 12),
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
assert all(e < 1e-4 for _, _, st, _, _, e in rows if st == "optimal")"""),
])
save("05_gaps_as_a_design_variable.ipynb", [
md("""# 5. Gaps as a design variable: sensitivities, exact paths, regulation

The source paper ends with "control the interaction forces by changing the gaps". While the
contact set holds, the reactions are **linear** in the initial gaps: R(g0) = R(0) + S g0, with
S = dR/dg0 from the active set (implicit differentiation of the KKT system). This notebook
checks S against a closed form and finite differences, follows a settlement exactly through a
change of the working scheme, and regulates the gaps for target reactions.

The scene: a free square plate (side a) on four rigid corner supports under a uniform load q.
By symmetry and statics each corner carries q a²/4."""),
code("""import numpy as np
import plateqp as pq
from plateqp.studies import exact_path, regulate_gaps

a, h, E, nu, q = 1.0, 0.01, 2.1e11, 0.3, 1000.0
D = E * h**3 / (12 * (1 - nu**2))
corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
scene = pq.Scene(name="corners", plate=pq.Plate(a, a, h, E, nu), mesh=pq.MeshSpec(8, 8),
                 loads=[pq.UniformLoad(q)], supports=[pq.Support(x, y) for x, y in corners])
res = pq.solve(scene, backend="lemke", accuracy="high")
print("reactions", res.reactions.round(6), "  q a²/4 =", q * a**2 / 4)"""),
md("""## The sensitivity matrix against the closed form

The only redundant reaction pattern is the twist (+, −, +, −); its stiffness is
k = 2 D (1 − ν) / a² (Kirchhoff theory: the pure twist w = c x y, which the ACM element
represents exactly). So dR_i/dg0_j = −k p_i p_j with p = (1, −1, 1, −1): settling a corner
unloads it and the opposite corner by k per unit of settlement, and loads the other two."""),
code("""S = pq.sensitivity(res, "gaps")
k = 2 * D * (1 - nu) / a**2
print("dR_i/dg0_j in units of k = 2D(1-nu)/a^2:")
print((np.asarray(S) / k).round(9))
p = np.array([1.0, -1.0, 1.0, -1.0])
assert np.allclose(np.asarray(S), -k * np.outer(p, p), rtol=1e-9, atol=1e-9 * k)
assert np.allclose(np.asarray(S).sum(axis=0), 0.0, atol=1e-9 * k)   # statics: a settlement moves no net force"""),
md("""## The multiplier as a sensitivity, by finite differences

A small settlement of support 3 (the active set does not change) moves the reactions by the
third column of S."""),
code("""dg = 1e-7
g = np.zeros(4); g[2] = dg
res2 = pq.solve(pq.Scene(name="c2", plate=scene.plate, mesh=scene.mesh, loads=scene.loads,
                         supports=[pq.Support(x, y, gap=gi) for (x, y), gi in zip(corners, g)]),
                backend="lemke", accuracy="high")
fd = (res2.reactions - res.reactions) / dg
print("finite difference of column 3:", fd.round(3))
print("exact column 3:               ", np.asarray(S)[:, 2].round(3))
assert np.allclose(fd, np.asarray(S)[:, 2], rtol=1e-5, atol=1e-5 * k)"""),
md("""## An exact path through a change of the working scheme

Settle support 3 further: its reaction falls linearly until it reaches zero at
δ* = (q a²/4) / k = q a⁴ / (8 D (1 − ν)), where the plate lifts off it. `exact_path` follows the
piecewise-linear solution by parametric pivoting and reports the breakpoint exactly (to
rounding), with no bisection."""),
code("""delta_star = q * a**4 / (8 * D * (1 - nu))
path = exact_path(scene, "supports.2.gap", 0.0, 2 * delta_star)
print(path)
b = path.breakpoints[0]
print(f"lift-off at {b['at']:.12g}; closed form q a^4 / (8 D (1 - nu)) = {delta_star:.12g}")
assert abs(b["at"] - delta_star) <= 1e-9 * delta_star"""),
md("""## The reactions along the path (the kink is the breakpoint)"""),
code("""import matplotlib.pyplot as plt  # the notebook's own (inline) backend: the figure shows
t = np.linspace(0.0, 2 * delta_star, 81)
R = np.array([path.reactions(ti) for ti in t])
fig, ax = plt.subplots(figsize=(6, 3.2))
for i in range(4):
    ax.plot(t / delta_star, R[:, i], label=f"support {i + 1}")
ax.axvline(1.0, color="k", lw=0.8, ls=":")
ax.set_xlabel("settlement of support 3 / δ*"); ax.set_ylabel("reaction"); ax.legend(fontsize=7)
fig.tight_layout()
plt.show()"""),
md("""## Regulation: the gaps that give target reactions

`regulate_gaps` (on the command line: `plateqp regulate SCENE --target ...`) finds initial
gaps that make the supports carry the reactions asked, here 300, 200, 300, 200 (in
equilibrium with the load). The regulated scene, solved again, gives them; and since the
contact set does not change, the sensitivity matrix predicts the same."""),
code("""reg = regulate_gaps(scene, [300.0, 200.0, 300.0, 200.0], backend="lemke")
print("gaps for R = (300, 200, 300, 200):", reg.gaps)
check = pq.solve(reg.scene, backend="lemke", accuracy="high")
print("reactions of the regulated scene:", check.reactions.round(6))
assert np.allclose(check.reactions, [300, 200, 300, 200], rtol=1e-9)
# the same from the sensitivities: the reactions are linear in the gaps while the contact set holds
pred = res.reactions + np.asarray(S) @ reg.gaps
assert np.allclose(pred, [300, 200, 300, 200], rtol=1e-9)"""),
])
print("written")

save("10_toggle_the_springs.ipynb", [
md("""# 10. "Toggle the springs": the iteration commercial codes use, and where it cycles

General finite-element codes (and PyNite's tension-only supports) handle one-sided supports
by iterating linear solves:

1. solve the plate with **every** support holding it both ways;
2. drop the supports that pull (reaction in tension), add back the dropped ones that the plate
   now penetrates (gap < 0);
3. repeat until nothing changes.

When it stops, the answer is exact. But it changes *every* wrong support at once, with no
measure of progress, and it need not stop: even though the contact problem is a convex QP
(positive definite flexibility), the sequence of contact sets can **cycle**. plateqp has this
iteration as the teaching backend `toggle`, honest about it: status `MAX_ITER` and "cycled"
when a contact set comes back. Beside it, Lemke, BPP and PDAS (the same idea with safeguards)
finish with their KKT check passed.

On plates cycling is rare: a search over more than 45 000 random scenes on about 1 000 plate
geometries (posts on grids,
scattered posts, twin posts, loose clusters; every edge condition; mixed heave and settlement;
both formulations) found none. It appeared only in **tight clusters of posts**, several
within one or two mesh cells (a pile group under a column). There the posts' flexibilities are
nearly equal, the flexibility matrix is close to singular, and one round's change overshoots.
Below is such a cluster: eight posts under a simply supported slab, mixed heave and settlement,
three loads (found by that search, written here deterministically)."""),
code("""import warnings
import numpy as np
import matplotlib.pyplot as plt  # the notebook's own (inline) backend: the figures show
import plateqp as pq

posts = [(0.48, 0.52), (0.48, 0.55), (0.50, 0.55), (0.51, 0.62),
         (0.54, 0.52), (0.56, 0.58), (0.57, 0.52), (0.57, 0.61)]
gap0 = 1e-4 * np.array([1, 2, 1, -1, 1, 1, -2, 0])     # > 0 settlement, < 0 heave
scene = pq.Scene(name="cluster", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(10, 10),
                 edges={e: "simple" for e in ("left", "right", "bottom", "top")},
                 loads=[pq.UniformLoad(10.0), pq.PointLoad(100.0, 0.7, 0.7), pq.PointLoad(100.0, 0.2, 0.1)],
                 supports=[pq.Support(x, y, gap=g) for (x, y), g in zip(posts, gap0)])
m = len(posts)
one_based = lambda s: "{" + ", ".join(str(i + 1) for i in s) + "}"   # supports are numbered 1 … 8"""),
md("""## The toggle backend: it says it cycled

On the dual formulation (the unknowns are the reactions) `toggle` is exactly the recipe
above: the set it keeps is the set of supports in contact, and it starts with all of them."""),
code("""with warnings.catch_warnings():
    warnings.simplefilter("ignore")              # plateqp warns that the answer is not optimal
    tog = pq.solve(scene, backend="toggle", formulation="dual")
sets = [tuple(s) for s in tog.extras["sets"]]
print("status:", tog.status.value, "|", tog.extras["solver_status"])
for k, s in enumerate(sets, 1):
    print(f"round {k}: supports in contact {one_based(s)}")
print("KKT check passed:", tog.kkt.ok)
assert tog.status == pq.Status.MAX_ITER and "cycled" in tog.extras["solver_status"] and not tog.kkt.ok"""),
md("""## The same iteration by hand, the way an FE code does it

Each round is one *linear* plate solve: the scene with only the supports in the current set,
each made two-sided (`solve_bilateral`). We read the reactions of the supports in the set and
the gaps g0 − w at the others, and toggle. This uses none of `toggle`'s code and no contact
formulation, only linear solves, and it must visit the same sets."""),
code("""def toggle_by_hand(scene, rule="all", max_rounds=40):
    \"\"\"The contact sets visited; rule "all": flip every wrong support (the FE recipe);
    "least": flip only the lowest-numbered wrong one (Murty's least-index rule).\"\"\"
    g0 = np.array([s.gap for s in scene.supports])
    A = np.ones(len(g0), bool)
    visited = []
    for _ in range(max_rounds):
        visited.append(tuple(np.flatnonzero(A).tolist()))
        held = pq.Scene(name="round", plate=scene.plate, mesh=scene.mesh, edges=scene.edges,
                        loads=scene.loads, supports=[s for s, a in zip(scene.supports, A) if a])
        r = pq.solve_bilateral(held)
        R = np.zeros(len(g0)); R[A] = r.reactions
        gap = g0 - np.array([r.at(s.x, s.y) for s in scene.supports])   # w is positive down
        wrong = (A & (R < 0)) | (~A & (gap < 0))
        if not wrong.any():
            return visited, R
        if rule == "least":
            wrong[np.flatnonzero(wrong)[0] + 1:] = False
        A = A ^ wrong
        if rule == "all" and tuple(np.flatnonzero(A).tolist()) in visited:
            visited.append(tuple(np.flatnonzero(A).tolist()))
            return visited, None                   # a set came back: it will cycle for ever
    return visited, None

hand, _ = toggle_by_hand(scene)
for k, s in enumerate(hand, 1):
    print(f"round {k}: {one_based(s)}")
assert hand[:-1] == sets                            # the same sets, from plain linear solves
first = hand.index(hand[-1])
print(f"round {len(hand)} repeats round {first + 1}: a cycle of length {len(hand) - 1 - first}")
assert len(hand) - 1 - first == tog.extras["cycle"]"""),
md("""## The methods that finish

Lemke (complementary pivoting), BPP (block principal pivoting, which also changes many
supports per step but falls back to one at a time when the count of wrong supports stops
falling) and PDAS (the primal-dual active-set method: toggle plus safeguards) all finish with
the KKT check passed, and they agree. So does the toggle recipe with one change only:
flip **the lowest-numbered wrong support only** (Murty's least-index rule). For a positive
definite matrix this provably terminates (Murty 1974), at the price of more rounds."""),
code("""exact = {}
for backend, form in (("lemke", "dual"), ("bpp", "dual"), ("pdas", "primal")):
    r = pq.solve(scene, backend=backend, formulation=form, accuracy="high")
    exact[backend] = r
    print(f"{backend:6s} {form:7s} status {r.status.value:8s} KKT ok {r.kkt.ok}  iterations {r.iterations}  "
          f"contact {one_based(np.flatnonzero(r.active))}")
    assert r.status == pq.Status.OPTIMAL and r.kkt.ok
ref = exact["lemke"].reactions
for r in exact.values():                            # three independent algorithms, one answer
    np.testing.assert_allclose(r.reactions, ref, atol=1e-8 * np.abs(ref).max())
solution = tuple(np.flatnonzero(exact["lemke"].active).tolist())
assert solution not in sets                         # the cycle never meets the answer

murty, R_murty = toggle_by_hand(scene, rule="least")
print(f"least-index rule: {len(murty)} rounds, ends with contact {one_based(murty[-1])}")
assert murty[-1] == solution
np.testing.assert_allclose(R_murty, ref, atol=1e-6 * np.abs(ref).max())"""),
md("""## Which supports are on, round by round

Dark: in contact in that round. Left: the FE recipe goes round the same three sets for ever
(the bracket). Right: the least-index rule, one flip per round, ends at Lemke's contact set
(the row marked ★)."""),
code("""def pattern(visited):
    P = np.zeros((len(visited), m))
    for k, s in enumerate(visited):
        P[k, list(s)] = 1
    return P

fig, axes = plt.subplots(1, 3, figsize=(10, 3.6), gridspec_kw={"width_ratios": [1, 1, 1.1]})
for ax, vis, title in ((axes[0], hand, "toggle the springs (all flips)"),
                       (axes[1], murty, "least-index rule (one flip)")):
    ax.imshow(pattern(vis), cmap="Greys", vmin=0, vmax=1.4, aspect="auto")
    ax.set_xticks(range(m), [str(i + 1) for i in range(m)]); ax.set_xlabel("support")
    ax.set_yticks(range(len(vis)), [str(k + 1) for k in range(len(vis))]); ax.set_ylabel("round")
    ax.set_title(title, fontsize=9)
axes[0].annotate("", xy=(m - 0.4, first), xytext=(m - 0.4, len(hand) - 1),
                 arrowprops=dict(arrowstyle="->", color="C3", lw=1.5), annotation_clip=False)
axes[0].text(m - 0.3, (first + len(hand) - 1) / 2, " cycle", color="C3", va="center", fontsize=8)
axes[1].text(m - 0.4, len(murty) - 1, "★", color="C2", va="center", fontsize=12)
ax = axes[2]
x, y = np.array(posts).T
sc_ = ax.scatter(x, y, c=gap0 * 1e4, cmap="coolwarm", s=120, vmin=-2, vmax=2, edgecolor="k")
for i, (xi, yi) in enumerate(posts):
    ax.annotate(str(i + 1), (xi, yi), xytext=(6, 4), textcoords="offset points", fontsize=8)
ax.set_aspect("equal"); ax.set_title("the cluster (mesh cell 0.1)", fontsize=9)
ax.set_xticks(np.arange(0.4, 0.71, 0.1)); ax.set_yticks(np.arange(0.4, 0.71, 0.1)); ax.grid(lw=0.5)
fig.colorbar(sc_, ax=ax, label="gap0 [1e-4] (+ settlement)")
fig.tight_layout()
plt.show()"""),
md("""## Why it cycles here, and rarely elsewhere

Toggling is Newton's method on the nonsmooth equation min(R, gap) = 0 with full steps and no
measure of progress (the primal-dual active-set method without its safeguards). It provably
converges when the matrix is an M-matrix (Hintermüller, Ito & Kunisch 2002), which a plate's
flexibility is not (pushing the plate up at one post lifts it at the others too). In our search
it still converged on every scene but the tight clusters. A heuristic reading, not a proof:
posts far apart are weakly coupled, so dropping one moves its neighbours' reactions little.
Posts a fraction of a mesh cell apart are the opposite: dropping one throws its whole reaction onto its neighbours, which may then go into
tension, and so on round the cluster. The same happens on the 4 × 4 matrix of
tests/test_toggle.py. The cures are the ones above: pivot one support at a time (Lemke, the
least-index rule), fall back to it when progress stalls (BPP), or safeguard the step (PDAS)."""),
])

save("11_duality_and_multipliers.ipynb", [
md("""# 11. Duality: potential energy, complementary energy, and reactions as prices

One scene, two minimum principles. With K the plate's stiffness (held by its simply
supported edges, so K is positive definite), f the loads, B u the deflections at the supports
(positive down) and g0 the initial gaps (> 0 settlement, < 0 heave):

* **primal** (minimum potential energy): Π(u) = ½ uᵀK u − fᵀu, over the deflections with
  B u ≤ g0 (no penetration);
* **dual** (minimum complementary energy): Π_c(R) = ½ (f − BᵀR)ᵀ K⁻¹ (f − BᵀR) + g0ᵀR, over
  the reactions R ≥ 0 (no tension). The first term is the strain energy of the plate loaded
  by f and R (statically admissible), the second the work of R through the gaps.

Lagrangian duality: the dual function of the primal is −Π_c(R), so for every feasible pair
Π(u) + Π_c(R) ≥ 0 (weak duality), with equality exactly at the solution (strong duality: a
convex QP with feasible points has no duality gap)."""),
code("""import numpy as np
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
assert abs(Pi(u_star) + 0.5 * (f @ u_star + g @ R_star)) < 1e-12 * abs(Pi(u_star))"""),
md("""## The duality gap of a feasible pair that is not optimal

Raise every support by δ (gaps g0 − δ) and solve: that deflection u_δ is feasible for the
original scene (B u_δ ≤ g0 − δ ≤ g0) and its reactions R_δ ≥ 0 are feasible for the dual. For
any u and R ≥ 0 the gap splits into two non-negative parts (expand the squares):

  Π(u) + Π_c(R) = ½ ‖u − K⁻¹(f − BᵀR)‖²_K + Rᵀ(g0 − B u)

a kinematic/static mismatch and the complementarity product. For (u_δ, R_δ) the mismatch is
zero (they are in equilibrium with each other) and every support in contact has gap δ, so the
gap is **δ · Σ R_δ**: it closes linearly as δ → 0."""),
code("""deltas = np.logspace(-4, -8, 5)
gaps = []
for d in deltas:
    r = solve(gap0 - d)
    u_d, R_d = r.u[model.free], r.reactions
    assert np.all(B @ u_d <= g + 1e-15) and np.all(R_d >= 0)          # a feasible pair
    gap_d = Pi(u_d) + Pi_c(R_d)
    gaps.append(gap_d)
    assert gap_d > 0 and abs(gap_d - d * R_d.sum()) < 1e-8 * gap_d     # the closed form above
    print(f"δ = {d:.0e}: Π(u_δ) + Π_c(R_δ) = {gap_d:.6e}   δ·ΣR_δ = {d * R_d.sum():.6e}")

# a pair not in equilibrium with each other: u_δ and some other non-negative reactions
rng = np.random.default_rng(1)
u_d, R_any = solve(gap0 - 1e-5).u[model.free], rng.uniform(0, 50, len(posts))
v = K_inv.solve(f - B.T @ R_any)
split = 0.5 * (u_d - v) @ (K @ (u_d - v)) + R_any @ (g - B @ u_d)
print(f"any pair: gap {Pi(u_d) + Pi_c(R_any):.6e} = mismatch + complementarity {split:.6e}")
assert abs(Pi(u_d) + Pi_c(R_any) - split) < 1e-10 * split and split > 0"""),
md("""## Multipliers are sensitivities

The reaction R_j is the Lagrange multiplier of the constraint (B u)_j ≤ g0_j, so it is the
rate at which the optimal energy changes with that gap. **Sign convention:** g0_j > 0 is
settlement. Increasing g0_j gives the plate more room, so the energy can only fall:

  ∂Π*/∂g0_j = −R_j,  or, with the elevation of support j, e_j = −g0_j:  ∂Π*/∂e_j = +R_j.

The reaction is the price of raising the support. We check it by central finite differences
of Π* = Π(u*(g0)). While the contact set holds, Π* is quadratic in g0, so the central
difference is exact up to rounding."""),
code("""h = 1e-7
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
np.testing.assert_allclose(-dPi, R_star, atol=1e-6 * R_star.max())"""),
md("""## The second derivative: `plateqp.sensitivity` against finite differences

Differentiating once more, dR_i/dg0_j = −∂²Π*/∂g0_i∂g0_j. `pq.sensitivity(result, "gaps")`
gives this matrix S from the active set (implicit differentiation of the KKT system). It must
match finite differences of the reactions, and as a Hessian it is **symmetric** (Maxwell–Betti
reciprocity: settling support j changes R_i as much as settling i changes R_j) and negative
semidefinite. Rows and columns of open supports are zero (their reaction stays 0)."""),
code("""S = np.asarray(pq.sensitivity(res, "gaps"))
print("dR_i/dg0_j (supports in contact):")
on = np.flatnonzero(res.active)
print("   ", "".join(f"{j + 1:>10d}" for j in on))
for i in on:
    print(f"{i + 1:3d} ", "".join(f"{S[i, j]:10.2f}" for j in on))
np.testing.assert_allclose(S, dR, atol=1e-6 * np.abs(S).max())
assert np.abs(S - S.T).max() < 1e-9 * np.abs(S).max()
assert np.linalg.eigvalsh(S).max() < 1e-9 * np.abs(S).max()
assert np.all(S[~res.active] == 0) and np.all(S[:, ~res.active] == 0)"""),
md("## The gap closing, and the prices"),
code("""fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.4))
a1.loglog(deltas, gaps, "o-", label="Π(u_δ) + Π_c(R_δ)")
a1.loglog(deltas, deltas * R_star.sum(), "k--", lw=0.8, label="δ · ΣR* (slope 1)")
a1.set_xlabel("δ (all supports raised)"); a1.set_ylabel("duality gap"); a1.legend(fontsize=8)
idx = np.arange(len(posts))
a2.bar(idx - 0.2, R_star, 0.4, label="R*  (the multipliers)")
a2.bar(idx + 0.2, -dPi, 0.4, label="−∂Π*/∂g0  (finite differences)")
a2.set_xticks(idx, [str(i + 1) for i in idx]); a2.set_xlabel("support"); a2.legend(fontsize=8)
fig.tight_layout()
plt.show()"""),
])

save("12_lemke_visible.ipynb", [
md("""# 12. Lemke made visible: the tableau, the path of z0, and a ray that proves no equilibrium

Notebook 2 printed Lemke's pivots. Here we open the method up. We write it ourselves in about
thirty lines on the dense tableau, print the tableau before every pivot, and check each pivot
against plateqp's `lemke`. Then we follow the artificial variable z0 (the uniform
pre-compression) along its path, and end with a plate that has **no** equilibrium: there Lemke
stops on a *secondary ray*, and the ray is a certificate that no solution exists.

The condensed LCP of a plate on one-sided supports: w = M z + q, z ≥ 0, w ≥ 0, zᵀw = 0, with
z_i the **gap** of support i and w_i its **reaction** (scaled). Lemke works on

  [ I | −M | −d | q ]:  w − M z − d z0 = q,

keeping n basic variables. The first n columns of the current tableau are B⁻¹ and the last is
the value of the basic variables."""),
code("""import numpy as np
import matplotlib.pyplot as plt  # the notebook's own (inline) backend: the figure shows
import plateqp as pq
from plateqp.backends import lemke
from plateqp.assembly import build_model
from plateqp.contact import Scaled, formulate

def lcp_of(scene):
    data = Scaled.from_model(build_model(scene))
    return data, formulate(data, "condensed").lcp

def our_lemke(M, q, show=False, max_pivots=100):
    \"\"\"Lemke's method on the dense tableau, plain minimum-ratio rule. Returns
    (kind, z or ray, steps), kind "solution" or "ray"; steps: (entering, leaving, z0, T, basis).\"\"\"
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
        print(f"pivot: {names[pivot[1]]} enters, {names[basis[pivot[0]]]} leaves\\n")"""),
md("""## The tableau, pivot by pivot

A plate simply supported on its left edge, four one-sided posts with heave and settlement,
and one point load. The row labels are the basic variables. Brackets mark the pivot element."""),
code("""posts = [(1.0, 0.0), (1.0, 1.0), (0.6, 0.3), (0.6, 0.8)]
scene = pq.Scene(name="four posts", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
                 edges={"left": "simple"}, loads=[pq.PointLoad(40.0, 0.4, 0.9)],
                 supports=[pq.Support(x, y, gap=g) for (x, y), g in zip(posts, (-1e-3, 0.0, 2e-3, 3e-3))])
data, lcp = lcp_of(scene)
M, q = np.asarray(lcp.M), np.asarray(lcp.q)
kind, z, steps = our_lemke(M, q, show=True)
print("ended on:", kind, " gaps z =", np.round(z, 6), " reactions w =", np.round(M @ z + q, 6))"""),
md("""Checks. (1) Each printed tableau is B⁻¹ [I | −M | −d | q], with B the columns of the basic
variables: recomputed from scratch with a linear solve. (2) The pivots and the values of z0 are
those of plateqp's `lemke` (trace). (3) The answer is complementary and, in the user's units,
matches plateqp's solve of the scene with its KKT check passed; the reactions balance the load's
moment about the supported edge."""),
code("""n = len(q)
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
assert abs(res.reactions @ x_post - 40.0 * 0.4) < 1e-9 * 40.0"""),
md("""## The path of z0

Between pivots the method walks along a line on which (z, w) solves the LCP with q replaced by
q + d z0, a uniform pre-compression z0 of every support, and satisfies every complementarity
pair but one. Each pivot is a corner of that path, where one support changes state. We check
both facts at every corner, and draw z0 for this scene and for the nine-post scene of notebook
2. In general z0 need not fall monotonically, but without degenerate ties the path never
revisits a basis (plateqp's lexicographic rule makes that hold with ties too)."""),
code("""def corners(M, q, steps):
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
print("z0 along the path, nine posts:", np.round(z0_nine, 3))"""),
md("""## A plate with no equilibrium: the secondary ray

A free plate (no edge support) on six posts, all at x ≤ 0.25, with a point load at x = 0.8.
The load lies outside the posts, so the plate tips off them. plateqp refuses it before any
solve (a statics check). We hand the LCP to Lemke directly: z0 can no longer be driven to zero.
The entering column has no positive entry, so the method stops on a ray. Its z part y is a
**Farkas certificate**:

  y ≥ 0,  Mᵀy ≤ 0,  qᵀy < 0.

If a solution existed, 0 ≤ yᵀw = (Mᵀy)ᵀz + qᵀy < 0, a contradiction. In plate terms, y is a set
of gap openings that costs no strain energy (a rigid tilt about the line x = 0.25, opening the
posts at x = 0), while the load does positive work −qᵀy on it. The energy is unbounded below."""),
code("""tip_posts = [(x, y) for x in (0.0, 0.25) for y in (0.0, 0.5, 1.0)]
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
np.testing.assert_allclose(y / y.max(), ref.extras["certificate"] / ref.extras["certificate"].max(), atol=1e-9)"""),
md("""The certificate, checked numerically (Mᵀy is zero up to rounding, relative to ‖M‖), and
its physics: y is proportional to the gap opening of a rotation θ about x = 0.25,
Δgap_j = θ (0.25 − x_j). In the user's units, the energy qᵀy·F0·W is the work of the load
on that tilt with the sign reversed: −P (0.8 − 0.25) θ."""),
code("""scale = np.abs(Mt).max()
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
# lexicographic rule breaks such ties otherwise and leaves by another pivot, on the same ray"""),
md("## The three paths of z0"),
code("""fig, ax = plt.subplots(figsize=(6.5, 3.4))
for vals, lab in ((z0_four, "four posts (solution)"), (z0_nine, "nine posts, notebook 2 (solution)"),
                  (z0_tip, "plate that tips off (ray)")):
    ax.plot(range(1, len(vals) + 1), vals, "o-", label=lab)
ax.plot(len(z0_tip), z0_tip[-1], "x", color="k", ms=12, mew=2)
ax.annotate("secondary ray", (len(z0_tip), z0_tip[-1]), xytext=(10, 10), textcoords="offset points", fontsize=8)
ax.axhline(0, color="k", lw=0.6)
ax.set_xticks(range(1, max(len(z0_four), len(z0_nine), len(z0_tip)) + 1))
ax.set_xlabel("pivot"); ax.set_ylabel("z0 (uniform pre-compression, scaled)"); ax.legend(fontsize=8)
fig.tight_layout()
plt.show()"""),
])
