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
from plateqp.model.assembly import build_model
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
from plateqp.model.assembly import build_model
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
path = exact_path(scene, "supports.3.gap", 0.0, 2 * delta_star)
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
tests/backends/test_toggle.py. The cures are the ones above: pivot one support at a time (Lemke, the
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
    # the closed form above, to 1e-8 and to the rounding of the two energies that cancel in gap_d
    floor = 64 * np.finfo(float).eps * (abs(Pi(u_d)) + abs(Pi_c(R_d)))
    assert gap_d > 0 and abs(gap_d - d * R_d.sum()) < 1e-8 * gap_d + floor
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
from plateqp.model.assembly import build_model
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

save("06_beam_on_obstacles.ipynb", [
md("""# 6. A 1-D warm-up: a beam on rigid obstacles

Before plates, the smallest contact problem with all the ingredients: a simply supported
Euler–Bernoulli beam (span L, bending stiffness EI) under a uniform load q, above rigid
one-sided obstacles with initial gaps g. The beam may touch an obstacle, never pass through it,
and an obstacle can only push.

We discretise by hand with **Hermite cubic elements** (deflection w and slope θ = w′ at each
node; w positive downwards), then solve the contact problem twice:

* as a **QP** in cvxpy: minimise ½ uᵀKu − fᵀu subject to B u ≤ g (B picks w at the obstacles);
* as an **LCP** in the reactions: gap = G R + d ≥ 0, R ≥ 0, Rᵀgap = 0, with the flexibility
  G = B K⁻¹ Bᵀ and d = g − B K⁻¹ f, solved by plateqp's Lemke.

Hermite cubics reproduce the exact Euler–Bernoulli deflection at the nodes for these loads, so
the closed forms below must come out to rounding."""),
code("""import numpy as np
import cvxpy as cp
import matplotlib.pyplot as plt
from plateqp.backends.lemke import lemke

L, EI, q = 4.0, 2.0e6, 1.0e4          # m, N m², N/m
nel = 8                               # elements; nodes at L/8, ..., the midspan is node 4
h = L / nel
x_nodes = np.linspace(0.0, L, nel + 1)

def beam(q):
    \"\"\"Stiffness and consistent load of the whole beam, dofs (w0, θ0, w1, θ1, ...).\"\"\"
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
print(f"{free.size} free dofs; K symmetric positive definite: {np.linalg.eigvalsh(K).min() > 0}")"""),
md("""## One obstacle at midspan: the closed form

Without the obstacle the midspan deflection is 5 q L⁴ / (384 EI). If that exceeds the gap g,
the beam touches, and the reaction follows from superposition with a point force R at
midspan (deflection R L³ / (48 EI) upwards):

    R = (5 q L⁴ / (384 EI) − g) · 48 EI / L³      (when positive, else 0)

The lift-off load, below which the beam does not touch, is q* = 384 EI g / (5 L⁴)."""),
code("""g = 0.010                                            # m
B = np.zeros((1, free.size)); B[0, list(free).index(2 * (nel // 2))] = 1.0   # w at midspan

R_closed = max(0.0, (5 * q * L**4 / (384 * EI) - g) * 48 * EI / L**3)
q_star = 384 * EI * g / (5 * L**4)
print(f"free midspan deflection {5 * q * L**4 / (384 * EI) * 1e3:.3f} mm > gap {g * 1e3:.1f} mm")
print(f"closed form: R = {R_closed:.3f} N,  lift-off load q* = {q_star:.1f} N/m")"""),
md("""### As a QP
The obstacle is one linear inequality on the midspan deflection, B u ≤ g. The reaction is its
multiplier, which cvxpy returns as the constraint's `dual_value`."""),
code("""u = cp.Variable(free.size)
contact = [B @ u <= g]
cp.Problem(cp.Minimize(0.5 * cp.quad_form(u, cp.psd_wrap(K)) - f @ u), contact).solve(solver="CLARABEL")
R_qp = contact[0].dual_value
print(f"QP  (cvxpy):   R = {R_qp[0]:.6f} N")
assert abs(R_qp[0] - R_closed) <= 1e-5 * R_closed              # interior point: to its tolerance"""),
md("""### As an LCP
Eliminating u leaves the reactions: the gap left is gap = G R + d with the flexibility
G = B K⁻¹ Bᵀ and d the gap the beam would leave without the obstacle. Complementarity
(R ≥ 0, gap ≥ 0, R·gap = 0) is the LCP that Lemke's method solves by pivoting, exactly."""),
code("""Kinv_Bt = np.linalg.solve(K, B.T)
G = B @ Kinv_Bt                         # flexibility: deflection at the obstacle per unit force there
d = g - B @ np.linalg.solve(K, f)       # the gap the beam would leave without the obstacle
R_lcp = lemke(G, d).x
print(f"LCP (Lemke):   R = {R_lcp[0]:.9f} N")
print(f"G = {G[0, 0]:.6e} m/N,  L³/(48 EI) = {L**3 / (48 * EI):.6e} m/N")

assert abs(G[0, 0] - L**3 / (48 * EI)) <= 1e-12 * G[0, 0]      # nodally exact flexibility
assert abs(R_lcp[0] - R_closed) <= 1e-9 * R_closed             # exact method: to rounding"""),
md("""## The reaction against the load: zero, then linear

Below q* the obstacle carries nothing; above it R grows with slope 5L/8 (the share of the
load a rigid midspan support takes). The kink is the change of the contact set."""),
code("""qs = np.linspace(0.0, 2.5 * q_star, 51)
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
plt.show()"""),
md("""## Three obstacles: which ones touch?

Obstacles at L/4, L/2 and 3L/4 with different gaps (the middle one lowest). Now the contact set is the unknown: the
solvers find it. As an independent check we take the contact set they found and solve the
beam by **superposition of closed forms** (uniform load plus point forces on a simply
supported beam), then confirm that the obstacles left out really have a gap."""),
code("""x_obs = np.array([L / 4, L / 2, 3 * L / 4])
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
print("gaps left [mm]:   ", np.round((g_obs - B3 @ u_lcp) * 1e3, 6))"""),
md("""### The contact set, checked by closed forms
Deflection of a simply supported beam under the uniform load, and under a unit point force at
a (Euler–Bernoulli): on the touching obstacles the gap is zero, which fixes their reactions;
on the others the gap must come out non-negative."""),
code("""# closed forms (Euler-Bernoulli, simply supported): uniform load, and a point force P at a
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
assert np.allclose(G3, flex, rtol=1e-12)                           # the Hermite flexibility is exact"""),
md("""### Statics
The end supports' reactions come from the full stiffness (K u − f on the eliminated dofs);
with the obstacles' they carry the whole load."""),
code("""# statics: the end reactions (from the full stiffness) and the obstacles carry the whole load
u_all = np.zeros(2 * (nel + 1)); u_all[free] = u_lcp
ends = -(K_full @ u_all - f_full)[[0, 2 * nel]]     # upward forces (w is downward)
print(f"end reactions {np.round(ends, 3)} N; total {ends.sum() + R3.sum():.6f} N = q L = {q * L:.1f} N")
assert abs(ends.sum() + R3.sum() - q * L) <= 1e-9 * q * L"""),
md("""## Deflection and contact forces

The deflection between the nodes comes from the Hermite shape functions; the triangles are
the obstacles' tops at their gap level, the bars the contact forces (upwards: an obstacle can
only push). The middle obstacle, the lowest, is not reached."""),
code("""def deflection_curve(u_all, n=20):
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
plt.show()"""),
md("""**What to take to the plate.** The same three ingredients come back in two dimensions:
a stiffness K from elements, an operator B that reads the deflection at the contact points,
and a QP whose multipliers are the reactions (or, after condensation, an LCP). What changes is
size, and that the plate's flexibility G has no closed form: notebook 09 builds it by hand."""),
])

save("07_two_supports_geometry.ipynb", [
md("""# 7. Two supports: the geometry of a contact QP

With two one-sided supports the condensed problem lives in the plane, and everything a
lecture says about convex contact can be drawn:

* the unknowns are the two **gaps** z = (z₁, z₂) left at the supports; the feasible set is the
  quadrant z ≥ 0 (no penetration);
* the energy of the plate, condensed onto the gaps, is Π(z) = ½ zᵀMz + qᵀz (up to a
  constant), with M the plate's stiffness seen from the two support points; its level sets
  are ellipses;
* at the optimum, −∇Π lies in the **normal cone** of the quadrant there, and the multipliers
  of z ≥ 0 are the components of ∇Π = M z + q: the **reactions**.

The scene: a 10 mm steel plate, 1 m × 1 m, simply supported on its edges, with two one-sided
posts under it, a uniform load and a point load off the centre line."""),
code("""import numpy as np
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
print("M [kN/mm] =\\n", (M / 1e6).round(4))
print("reactions on level rigid posts r [N] =", r.round(2))
print("free deflection at the posts [mm] =", (w_free * 1e3).round(4))
assert np.allclose(M, M.T) and np.all(np.linalg.eigvalsh(M) > 0)   # symmetric positive definite"""),
md("""## Moving the gaps moves the ellipses

With initial gaps g0 (the posts lowered by g0) the gap left is z = g0 − w, and the linear term
becomes q = r − M g0. The Hessian M does not change: the ellipses keep their shape, and their
centre, the **unconstrained minimum** z* = −M⁻¹q = g0 − w_free, is the gap the plate would
leave if the posts were not there. Four choices of g0 put the optimum in the four possible
contact sets:"""),
code("""cases = {"both posts touch": np.array([0.0, 0.0]),
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
          f"z = {np.round(z * 1e3, 4)} mm, R = {np.round(R, 4)} N")"""),
md("""## Checked against the full plate

The same four scenes solved by plateqp on the **primal** form (all the plate's dofs, no
condensation; its primal-dual active-set backend `pdas`): the same contact sets, gaps and reactions. And
statics: whatever the contact set, the posts and the edges together carry the whole load."""),
code("""results = {}
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
    assert abs(edge.sum() + res.reactions.sum() - total) <= 1e-7 * total   # to the solver's tolerance"""),
md("""## The optimality condition: −∇Π in the normal cone

The normal cone of the quadrant at z is the set of directions that point out of it there:
v with vᵢ ≤ 0 where zᵢ = 0 (a post in contact) and vᵢ = 0 where zᵢ > 0 (a gap open). z is
optimal exactly when −∇Π(z) = −(M z + q) lies in it; the components of ∇Π are the reactions,
so this is R ≥ 0 on the posts in contact and R = 0 on the others. A descent direction that
points out of the quadrant cannot be followed: the posts stop it, and the force they need is
the multiplier."""),
code("""def in_normal_cone(v, z, tol=1e-9 * np.abs(r).max()):
    \"\"\"True if v is in the normal cone of {z >= 0} at z.\"\"\"
    return bool(np.all(np.where(z > 0, np.abs(v) <= tol, v <= tol)))

for name, (g0, z, R) in results.items():
    grad = M @ z + q_of(g0)
    print(f"{name:20s} ∇Π = {np.round(grad, 4)} N = R;  −∇Π in the normal cone: {in_normal_cone(-grad, z)}")
    assert np.allclose(grad, R, rtol=0, atol=1e-9 * np.abs(r).max()) and in_normal_cone(-grad, z)
    # any other point of the quadrant fails the test (e.g. the corner when a gap is open)
    if np.any(z > 0):
        assert not in_normal_cone(-q_of(g0), np.zeros(2))"""),
md("""## The picture

In each panel: the feasible quadrant (white; shaded where z < 0, penetration), the energy's
level sets (grey ellipses) around the unconstrained minimum ✕, the optimum ● with the level set through it (black: it touches the quadrant there), the **normal
cone** of the quadrant at the optimum (green: the quarter-plane z ≤ 0 at the corner, a ray
along the face, only the point itself inside), and the arrow −∇Π = −R, scaled, which must lie
in that cone: the load pulls the plate into the posts with exactly the force the posts push
back with. Where a post does not touch, its component of ∇Π is zero: no force, no
multiplier."""),
code("""fig, axes = plt.subplots(2, 2, figsize=(8.5, 8))
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
    ax.set_title(f"{name}\\ng0 = ({g0[0] * 1e3:.2f}, {g0[1] * 1e3:.2f}) mm", fontsize=9)
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
plt.show()"""),
md("""**What the picture says.**

* *Both touch*: the optimum is the corner, the whole third quadrant is the normal cone, and
  −∇Π points into it: both reactions positive.
* *One touches*: the optimum slides along a face, where the level set is tangent to the face;
  the cone is a ray and the gradient has one non-zero component, the reaction of the post in
  contact.
* *None*: the unconstrained minimum is feasible, ∇Π = 0, no forces.

Complementarity zᵢRᵢ = 0 is the statement that the optimum is on the face whose normal the
force follows. With m supports the quadrant becomes an orthant with 2ᵐ faces, and finding the
right face is the whole difficulty: that is what Lemke, active-set and interior-point methods
do in different ways."""),
])

save("08_penalty_vs_exact.ipynb", [
md("""# 8. The penalty method against the exact QP

The most common way to impose a one-sided support in a finite-element code is not a
constraint but a **stiff spring that only pushes**: add to the plate's energy

    ½ k Σᵢ max(0, (B u − g0)ᵢ)²

for a large "penalty" stiffness k. The plate then penetrates each support a little, by
p = R / k, and the reaction is R = k p. This notebook measures what that costs against the
exact QP (solved by Lemke, exact to rounding):

* the penetration is R / k, and the error of the reactions is first order in 1/k;
* the condition number of K + k BᵀB grows like k, and at large k floating point wins: the
  error grows again, and at the end the method fails;
* plateqp's `penalty` teaching backend says so in its status (`INACCURATE`);
* an **elastic support** of true stiffness c *is* a penalty with k = c: there the same formula
  is not an approximation but the physics.

The scene: a simply supported square plate on a 3 × 3 grid of one-sided posts, some heaved,
some settled, under a uniform and a point load."""),
code("""import warnings
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
print(f"{K.shape[0]} dofs, {B.shape[0]} posts; D = {D:.4f} N m")"""),
md("""## The penalty method by hand

Minimising ½ uᵀKu − fᵀu + ½ k ‖(Bu − g0)₊‖² is a smooth problem whose stationarity is
piecewise linear: with A the posts that are penetrated,

    (K + k B_Aᵀ B_A) u = f + k B_Aᵀ g0_A,

and A is found by the same "assume, solve, correct" loop as toggling springs. We write k in
units of the plate's own stiffness D / L² (L = 1 m)."""),
code("""def penalty_by_hand(k, A=None, max_rounds=20):
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
assert np.all(p[~on] < 0)                                              # the posts off contact stay off"""),
md("""## The error against k, and the condition number

For every k: the reaction error against the exact QP, and the condition number of the matrix
the penalty method factorises, K + k B_Aᵀ B_A with A the posts in contact (numpy's 2-norm
condition number; K is small here). Two
straight lines on a log-log plot are the whole story:

* the **penalty error** ~ 1/k (the penetration R/k is the error in the gaps);
* the **rounding error** ~ k ε ‖u‖ / ‖R‖: the reaction is k times the penetration p = Bu − g0,
  a difference of two numbers of size ‖u‖ each known to machine precision ε."""),
code("""eps = np.finfo(float).eps
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
assert not ok[-1] or err[-1] > 1e-2              # and at the end the method fails outright"""),
code("""u0 = np.abs(B @ np.linalg.solve(K + 1e8 * D * B[on].T @ B[on], f)).max() + np.abs(g0).max()
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
plt.show()"""),
md("""No k gives the exact answer, and the best k is a compromise found only by knowing the exact
answer. The exact formulations (primal with constraints, condensed, dual) have no such
parameter: their conditioning is that of the plate.

## plateqp's `penalty` backend is honest about it

The teaching backend applies the same idea to the dual problem: each post gets a compliance
ε = ratio · max diag(G) on the flexibility's diagonal (G + εI instead of G), which *is* a
spring of stiffness 1/ε. Its answer goes through plateqp's KKT check like any other: the
status is `OPTIMAL` only when the penetration it leaves is within the accuracy asked (here the
default, 1e-6), otherwise `INACCURATE`, with a warning. The backend's own message compares the
natural residual with its internal tolerance (1e-9 at the default preset): at ratio 1e-8 it
still says "> 1e-09", and the plate's check at 1e-6 passes the answer."""),
code("""rows = []
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
        assert res.status == pq.Status.INACCURATE and not res.kkt.ok"""),
md("""## Elastic supports: the penalty is the physics

Now make every post an elastic support of true stiffness c (a spring that only pushes, R = c s
for a compression s). The energy of the plate on these posts is *exactly* the penalty energy
with k = c: what was an error above is now the compression of the springs. Take c equal to the
spring the penalty backend used at ratio 1e-4: the backend's ε is in plateqp's nondimensional
units (compliance × D / L²), so c = D / (L² ε). Three different routes give the same reactions
to rounding:

1. the penalty backend on the rigid posts;
2. the exact elastic-support problem (Lemke on the condensed form, springs built in);
3. the penalty formula by hand with k = c."""),
code("""with warnings.catch_warnings():
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
np.testing.assert_allclose(elastic.compressions, elastic.reactions / c, rtol=1e-9, atol=1e-15)"""),
md("""**Summary for the lecture.** A penalty is a spring. If the support *is* a spring, use its true
stiffness and the answer is exact (plateqp's elastic supports). If the support is rigid, the
penalty leaves a penetration R/k and an error of order 1/k, and raising k trades that error
for ill-conditioning: with about 16 digits the best one can get here is about
8 digits (the minimum of the V above), and only by knowing the exact answer to pick k. A
constrained QP has neither problem."""),
])

save("09_static_condensation.ipynb", [
md("""# 9. Static condensation by hand

The source paper solves contact on the **gaps at the supports only**: every other degree of
freedom of the plate is eliminated first. This notebook does that elimination by hand with
SciPy on a small mesh, and shows that it is exactly plateqp's `condensed` formulation:

1. partition the plate's stiffness into the contact dofs c (the deflections at the posts) and
   the others o;
2. eliminate o: the **Schur complement** S = K_cc − K_co K_oo⁻¹ K_oc, the plate's stiffness
   seen from the posts, and the condensed load r = f_c − K_co K_oo⁻¹ f_o;
3. its inverse is the **flexibility** G = S⁻¹ = B K⁻¹ Bᵀ (the dual formulation's matrix):
   Gᵢⱼ is the deflection at post i from a unit force at post j;
4. both are symmetric (Maxwell–Betti) and positive definite, and the contact problem on the
   gaps z is LCP(S, r − S g0), which Lemke solves.

The scene: a 10 mm steel plate, 1 m × 1 m, simply supported on its edges, five one-sided posts
at mesh nodes (some settled), a uniform load and a point load."""),
code("""import numpy as np
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
print(f"K: {K.shape[0]} dofs;  B: {B.shape}, one non-zero per row: {np.all((B != 0).sum(axis=1) == 1)}")"""),
md("""## 1–2. Partition and eliminate

The posts sit on mesh nodes, so each row of B picks one deflection dof: those are c. For the
others, the equilibrium rows K_oo u_o + K_oc u_c = f_o give u_o for any u_c; put back into
the rows of c this leaves S u_c = r − R, R the posts' (upward) reactions. One dense Cholesky
factorisation of K_oo does it."""),
code("""c = np.argmax(np.abs(B), axis=1)                            # the contact dofs, in post order
o = np.setdiff1d(np.arange(K.shape[0]), c)
K_oo, K_oc, K_cc = K[np.ix_(o, o)], K[np.ix_(o, c)], K[np.ix_(c, c)]
chol = sla.cho_factor(K_oo)                                 # K_oo: the plate with every post held
S = K_cc - K_oc.T @ sla.cho_solve(chol, K_oc)              # N/m
r = f[c] - K_oc.T @ sla.cho_solve(chol, f[o])              # N
print("S [kN/mm] =\\n", (S / 1e6).round(3))
print("r [N] =", r.round(2), " (the reactions if every post were rigid and level)")"""),
md("""## The same matrix as plateqp's condensed formulation

plateqp condenses with one sparse factorisation with the contact dofs ordered last, in its
nondimensional units (gaps by W, forces by F0). Converted back, its LCP matrix is our S and
its vector is r − S g0."""),
code("""data = Scaled.from_model(model)
cond = formulate(data, "condensed").lcp
M_pq = cond.M * data.F0 / data.W
q_pq = cond.q * data.F0
print(f"max |M_plateqp − S| / max |S| = {np.abs(M_pq - S).max() / np.abs(S).max():.1e}")
print(f"max |q_plateqp − (r − S g0)| / max |q| = {np.abs(q_pq - (r - S @ g0)).max() / np.abs(q_pq).max():.1e}")
assert np.allclose(M_pq, S, rtol=0, atol=1e-10 * np.abs(S).max())
assert np.allclose(q_pq, r - S @ g0, rtol=0, atol=1e-10 * np.abs(q_pq).max())"""),
md("""## 3. Symmetric, positive definite, and what the entries mean

* S is symmetric because K is, and positive definite because K is (the simply supported
  edges hold the plate: no motion is free of strain): a Cholesky factorisation of S succeeds.
* **Sᵢⱼ** (a stiffness): the force at post i when post j is pushed down by a unit deflection and
  every other post is held at zero. Sⱼⱼ > 0; the nearest posts must pull down to stay put
  (negative entries), a far one may have to push (S₁₅ > 0 here: the plate bends back up
  beyond the centre post that holds it).
* **Gᵢⱼ = (S⁻¹)ᵢⱼ** (a flexibility): the deflection at post i from a unit force at post j, with
  only the edges holding the plate. It is B K⁻¹ Bᵀ, and the dual formulation's matrix. Gᵢⱼ = Gⱼᵢ is
  **Maxwell–Betti**'s reciprocity.

The flexibility has an external reference: Navier's double sine series for a simply supported
rectangle under a unit point force at (ξ, η),

    w(x, y) = 4 / (π⁴ D a b) Σₘ Σₙ sin(mπξ/a) sin(nπη/b) sin(mπx/a) sin(nπy/b) / ((m/a)² + (n/b)²)²,

symmetric in (x, y) ↔ (ξ, η) term by term. The finite-element G must agree with it to the
discretisation error (about 1 % at 16 × 16 elements)."""),
code("""sla.cholesky(S)                                             # succeeds: S is positive definite
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
print("G [mm/kN] (finite elements):\\n", (G * 1e6).round(5))
print("relative difference to Navier's series:\\n", ((G - G_navier) / G_navier).round(4))
assert np.all(np.abs(G - G_navier) <= 0.015 * G_navier)"""),
md("""The difference is the discretisation error, not a mistake: on a mesh twice as fine (a sparse
LU this time, 3 000 dofs) it falls about fourfold, as the element's h² convergence says (a
little less on the diagonal, where the point force's logarithmic singularity sits)."""),
code("""import dataclasses
from scipy.sparse.linalg import splu
fine = build_model(dataclasses.replace(scene, mesh=pq.MeshSpec(32, 32)))
Bf = fine.contacts.B
G_fine = Bf @ splu(fine.K.tocsc()).solve(Bf.T.toarray())
err16, err32 = np.abs(G - G_navier) / G_navier, np.abs(G_fine - G_navier) / G_navier
print(f"largest difference to Navier: {err16.max():.2%} at 16 x 16, {err32.max():.2%} at 32 x 32")
print("ratio per entry:\\n", (err16 / err32).round(2))
assert np.all(err32 < 0.004) and np.all(err16 > 3 * err32)"""),
md("""## 4. The contact problem on the gaps, solved by Lemke

With the posts settled by g0 the gaps left are z = g0 − u_c and the posts' reactions are
R = S z + r − S g0 (the forces needed to hold the plate at u_c). One-sided contact is the LCP
z ≥ 0, R ≥ 0, zᵀR = 0. After Lemke, the plate's other dofs come back from the same
factorisation: u_o = K_oo⁻¹ (f_o − K_oc u_c)."""),
code("""q = r - S @ g0
z = lemke(S, q, accuracy="high").x
R = S @ z + q
R[np.abs(R) < 1e-9 * np.abs(q).max()] = 0.0                 # rounding where a post does not touch
u = np.zeros(K.shape[0])
u[c] = g0 - z
u[o] = sla.cho_solve(chol, f[o] - K_oc @ u[c])
for i, (p, gi, zi, Ri) in enumerate(zip(posts, g0, z, R)):
    print(f"post {i + 1} at {p}: settled {gi * 1e3:.1f} mm, gap left {zi * 1e3:.4f} mm, R = {Ri:9.3f} N")"""),
md("""The KKT conditions of the whole plate, by hand: the recovered u with these reactions is in
equilibrium, and gaps and reactions are non-negative and complementary."""),
code("""# the KKT conditions of the full plate, by hand
stat = np.abs(K @ u - f + B.T @ R).max() / np.abs(f).max()
print(f"stationarity |K u − f + Bᵀ R| / |f| = {stat:.1e}")
assert stat < 1e-10 and z.min() >= 0 and R.min() >= 0 and np.abs(z * R).max() < 1e-12 * np.abs(q).max()"""),
md("""And against plateqp: its `lemke` backend on its own condensed form, its `pdas` backend on the
primal form (no condensation at all), and statics (edges plus posts carry the load)."""),
code("""mine = pq.solve(scene, backend="lemke", formulation="condensed", accuracy="high")
ref = pq.solve(scene, backend="pdas", formulation="primal", accuracy="high")
np.testing.assert_allclose(R, mine.reactions, rtol=0, atol=1e-9 * np.abs(R).max())
np.testing.assert_allclose(R, ref.reactions, rtol=0, atol=1e-8 * np.abs(R).max())
edge = -(model.K_full @ ref.u - model.f_full)[model.fixed]  # the edges' reactions
total = 5000.0 * plate.a * plate.b + 2000.0
print(f"lemke and primal agree; statics: edges {edge.sum():.3f} N + posts {R.sum():.3f} N = {total:.1f} N")
assert abs(edge.sum() + R.sum() - total) <= 1e-8 * total     # edges from the primal solve: to its tolerance"""),
md("""## The picture: a flexibility column, and the matrices

Left: the plate's deflection under a unit force at post 1 alone (only the edges holding it),
K⁻¹ Bᵀ e₁; its values at the posts are the first column of G. Right: S and G side by side,
both symmetric; in G each post moves most under its own force (the largest entry of each
column is on the diagonal, the centre post's largest of all), in S the posts next to a pushed
one must pull down to stay put (negative entries)."""),
code("""j = 0
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
assert np.all(np.argmax(G, axis=0) == np.arange(5))        # each post moves most under its own force"""),
md("""**Cost.** By hand we factorised K_oo densely and solved for m columns: fine for a few posts
on a small mesh. plateqp gets S as the trailing block of one sparse factorisation of K with
the contact dofs ordered last (no column solves), and forms G only when the dual is asked
for. G taken as S⁻¹ from that block carries the condition number of K into its entries, so
plateqp checks the dual's answer against the exact gaps and, where G's error shows, hands the
backend the problem again with the gaps corrected (a defect correction: one round is typical)."""),
])

print("written")
