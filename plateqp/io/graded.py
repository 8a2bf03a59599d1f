r"""The graded family of plate contact problems of the qpbenchmark test set.

One instance per (mesh, support kind, gap pattern), each exported in the three formulations,
named ``n<mesh>_<kind>_<gaps>_<form>`` (:func:`grade_name`) so that the grade reads from the
name. The slab is :mod:`plateqp.scenes.families`' (8 m × 8 m, 20 cm concrete, kN and m, self-weight
and floor load q = 10 kN/m² plus a 300 kN column at (5, 4.5)), simply supported on its four
walls so that K is nonsingular and the dual form exists; the one-sided supports are

=========  ===================================================================================
rigid      a 7 × 7 grid of rigid posts at a·(i + 1)/8 (on nodes for every mesh of the grid)
elastic    the same posts as elastic piles, c = :data:`plateqp.scenes.families.PILE_STIFFNESS`
bed        a tensionless Winkler bed (k = :data:`plateqp.scenes.families.BED_MODULUS`) under the whole
           slab: every interior node a one-sided spring ((n − 1)² contact points)
=========  ===================================================================================

with initial gaps g0 (positive: settlement; δ = :data:`plateqp.scenes.families.GAP`, 1 mm)

=========  ===================================================================================
zero       g0 = 0 everywhere
heave      a bump at the corner (0, 0): g0 = −δ (1 − r²/R²)², R = a/2
settle     a trough at the corner (a, a): g0 = +δ (1 − r²/R²)², R = a/2
mixed      a smooth random field (six seeded cosine modes, seed 15, max |g0| = δ on the plan):
           the same field on every mesh
liftoff    ``mixed`` made degenerate: every contact point that lifts off in the exact solution
           of ``mixed`` gets g0 − gap, so that it touches with zero reaction (gap = R = 0, strict
           complementarity fails) while the solution is unchanged
=========  ===================================================================================

on meshes of 8², 16², 32², 64² ACM cells; the bed only up to :data:`BED_MAX_MESH` (its
condensed and dual matrices are dense (n − 1)² × (n − 1)²: 126 MB at 64²).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from ..errors import ProblemError
from ..scenes.families import BED_MODULUS, GAP, PILE_STIFFNESS, WALLS, A, _loads, _plate, positions
from ..model.scene import Foundation, MeshSpec, Scene, Support

MESHES = (8, 16, 32, 64)
SUPPORT_KINDS = ("rigid", "elastic", "bed")
GAP_PATTERNS = ("zero", "heave", "settle", "mixed", "liftoff")
FORMS = ("primal", "condensed", "dual")
#: The largest mesh of the bed instances (their dense forms grow as (n − 1)⁴).
BED_MAX_MESH = 32
#: Posts per row of the rigid and elastic instances.
POSTS = 7
#: The exact route each form's reference comes from (``bpp`` above :data:`LEMKE_MAX` contacts).
REFERENCE = {"primal": "pdas", "condensed": "lemke", "dual": "lemke"}
LEMKE_MAX = 300
#: The largest worst KKT residual (plateqp's check, on the plate's terms) a reference may have:
#: the dual form's flexibility matrix carries cond(K)·ε, 1.1e-9 at 64², a hair above ``high``.
REFERENCE_KKT = 1e-8
SEED = 15


def grade_name(mesh: int, kind: str, gaps: str, form: str) -> str:
    """``n08_rigid_heave_primal``: the instance's name, the grade readable from it."""
    return f"n{mesh:02d}_{kind}_{gaps}_{form}"


def parse_grade(name: str) -> dict:
    """The grade of an instance from its name: {mesh, kind, gaps, form} (inverse of :func:`grade_name`)."""
    parts = str(name).split("_")
    if (len(parts) != 4 or not parts[0].startswith("n") or not parts[0][1:].isdigit()
            or parts[1] not in SUPPORT_KINDS or parts[2] not in GAP_PATTERNS or parts[3] not in FORMS):
        raise ProblemError(f"{name!r} is not a graded instance name (n<mesh>_<kind>_<gaps>_<form>)")
    return {"mesh": int(parts[0][1:]), "kind": parts[1], "gaps": parts[2], "form": parts[3]}


def grades(meshes=MESHES, kinds=SUPPORT_KINDS, gaps=GAP_PATTERNS) -> list[tuple[int, str, str]]:
    """The (mesh, kind, gaps) instances of the grid, in order; no bed above :data:`BED_MAX_MESH`."""
    return [(n, k, g) for n in meshes for k in kinds for g in gaps if not (k == "bed" and n > BED_MAX_MESH)]


def gap_field(pattern: str, x, y) -> np.ndarray:
    """Initial gaps g0 (m) of a pattern at points (x, y) of the plan (not ``liftoff``: it needs a solve)."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if pattern == "zero":
        return np.zeros(np.broadcast(x, y).shape)
    if pattern in ("heave", "settle"):
        cx, sign = (0.0, -1.0) if pattern == "heave" else (A, 1.0)
        r2 = ((x - cx) ** 2 + (y - cx) ** 2) / (A / 2) ** 2
        return sign * GAP * np.where(r2 < 1.0, (1.0 - r2) ** 2, 0.0)
    if pattern == "mixed":
        return GAP * _mixed(x, y) / _MIXED_MAX
    raise ProblemError(f"unknown gap pattern {pattern!r}; choose one of {GAP_PATTERNS[:-1]}")


_rng = np.random.default_rng(SEED)
_MODES = [(int(_rng.integers(1, 4)), int(_rng.integers(1, 4)), float(_rng.normal()), float(_rng.uniform(0, 2 * np.pi)),
           float(_rng.uniform(0, 2 * np.pi))) for _ in range(6)]
del _rng


def _mixed(x, y):
    return sum(c * np.cos(np.pi * p * x / A + f) * np.cos(np.pi * q * y / A + g) for p, q, c, f, g in _MODES)


_t = np.linspace(0.0, A, 257)
_MIXED_MAX = float(np.abs(_mixed(_t[:, None], _t[None, :])).max())
del _t


def _scene(mesh: int, kind: str, gaps: str, g0) -> Scene:
    """The instance's scene with the gap function ``g0(x, y)``."""
    name = f"n{mesh:02d}_{kind}_{gaps}"
    base = dict(name=name, plate=_plate(), mesh=MeshSpec(mesh, mesh, "acm"), edges=dict(WALLS), loads=_loads())
    if kind == "bed":
        return Scene(**base, foundation=Foundation(k=BED_MODULUS, gap=g0))
    if kind not in ("rigid", "elastic"):
        raise ProblemError(f"unknown support kind {kind!r}; choose one of {SUPPORT_KINDS}")
    xs = positions(mesh, POSTS, interior=True)
    stiffness = "rigid" if kind == "rigid" else PILE_STIFFNESS
    return Scene(**base, supports=[Support(float(x), float(y), gap=float(g0(x, y)), stiffness=stiffness)
                                   for x in xs for y in xs])


def graded_scene(mesh: int, kind: str, gaps: str) -> Scene:
    """The scene of one instance of the grid (``liftoff`` solves ``mixed`` exactly first)."""
    if gaps != "liftoff":
        return _scene(mesh, kind, gaps, lambda x, y: gap_field(gaps, x, y))
    from ..solving import solve

    mixed = graded_scene(mesh, kind, "mixed")
    ref = solve(mixed, backend="pdas", formulation="primal", accuracy="high")
    if not ref.kkt.ok:
        raise ProblemError(f"{mixed.name}: the exact solve for the lift-off gaps missed its KKT check")
    from ..model.assembly import build_model
    xy = build_model(mixed).contacts.xy
    lifted = ~np.asarray(ref.active)
    # the exact lift-off gap: g0 − gap, at the points that lift off (their R = 0, s = 0)
    g_new = gap_field("mixed", xy[:, 0], xy[:, 1]) - np.where(lifted, ref.gaps, 0.0)
    h = A / mesh
    table = np.full((mesh + 1, mesh + 1), np.nan)
    ij = np.rint(xy / h).astype(int)
    table[ij[:, 0], ij[:, 1]] = g_new

    def g0(x, y):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        i, j = np.rint(x / h).astype(int), np.rint(y / h).astype(int)
        inside = (i >= 0) & (i <= mesh) & (j >= 0) & (j <= mesh)
        out = gap_field("mixed", x, y)
        got = table[np.where(inside, i, 0), np.where(inside, j, 0)]
        return np.where(inside & ~np.isnan(got), got, out)

    return _scene(mesh, kind, gaps, g0)


def reference_route(form: str, m: int) -> str:
    """The exact backend of a form's reference: pdas (primal), lemke (≤ LEMKE_MAX contacts) or bpp."""
    route = REFERENCE[form]
    return "bpp" if route == "lemke" and m > LEMKE_MAX else route


def reference_solution(exported, result) -> dict:
    """A plateqp result as the reference solution of the exported QP, in qpsolvers' convention.

    Returns x, z (multipliers of G x ≤ h, None without G), z_box (of lb ≤ x ≤ ub, None
    without bounds), reactions (R / F0 at the contact points, the same in every form) and
    objective, such that P x + q + Gᵀz + z_box = 0, z ≥ 0, z_box ≤ 0 at the lower bounds.
    """
    qp, d = exported.qp, exported.data
    x = exported.x_from_result(result)
    R = np.asarray(result.reactions, dtype=float) / d.F0
    z = z_box = None
    if exported.formulation == "primal":
        z = R.copy()
    else:  # bound-constrained: z_box = −(P x + q), the reactions (condensed) or the gaps (dual)
        z_box = -(qp.P @ x + qp.q)
    return {"x": x, "z": z, "z_box": z_box, "reactions": R, "objective": exported.objective(x)}


def graded_problems(meshes=MESHES, kinds=SUPPORT_KINDS, gaps=GAP_PATTERNS, forms=FORMS,
                    accuracy: str = "high") -> Iterator[tuple]:
    """(ExportedQP, reference dict, plateqp Result) for every instance and form of the grid.

    Each reference comes from plateqp's exact route for the form (:func:`reference_route`),
    asked for ``accuracy``, and its worst KKT residual must be at most :data:`REFERENCE_KKT`; its
    dict (:func:`reference_solution`) also holds ``meta``: the grade, the route, its status and
    worst KKT residual, the contact count.
    """
    from ..model.assembly import build_model
    from ..solving import solve
    from .export import contact_qp

    for mesh, kind, g in grades(meshes, kinds, gaps):
        scene = graded_scene(mesh, kind, g)
        model = build_model(scene)
        for form in forms:
            e = contact_qp(model, form, name=grade_name(mesh, kind, g, form))
            route = reference_route(form, model.contacts.m)
            res = solve(scene, backend=route, formulation=form, accuracy=accuracy, model=model)
            if not res.kkt.worst <= REFERENCE_KKT:
                raise ProblemError(f"{e.name}: plateqp's {route} missed its KKT check ({res.kkt.worst:.1e})")
            ref = reference_solution(e, res)
            ref["meta"] = {"grade": {"mesh": mesh, "kind": kind, "gaps": g, "form": form}, "route": route,
                           "status": res.status.value, "plateqp_kkt_worst": float(res.kkt.worst),
                           "contacts": int(np.count_nonzero(res.active)), "m": int(model.contacts.m)}
            yield e, ref, res
