"""The source paper's stiffness studies (its figures 5 and 6) as studies of ``plateqp demo``.

Both are stated in the dimensionless support stiffness

.. math::

    \\kappa = c\\, s^2 / D,

c the stiffness of every support (force/length), s the support spacing (the median distance
from a support to its nearest neighbour), D = E h³/12(1 − ν²): κ → ∞ is rigid supports,
κ → 0 supports much softer than the plate (the plate moves as a rigid body on its springs).

**"fig5"** (:func:`stiffness_path`): the built-in ``stiffness`` scene (the 8 m slab on 25
supports at s = 200 cm, supports 1, 2, 8 heaved by 2 mm, as in the paper's figure 5), its
stiffness lowered from rigid to κ_min. The working scheme (the contact set) is followed with
:func:`plateqp.studies.sweep` on a log grid of κ; each change between grid values is located
by the sweep's bisection (to ``rtol`` relative). One scheme per interval between breakpoints;
each is drawn from a solve at the geometric middle of its interval (rigid for the first, κ_min
for the last). *Scaling*: the paper gives only its softest stiffness, c = 5 kgf/cm, and
shows its last scheme there; κ_min = 1 lies below our last breakpoint, so the paper's
c = 5 kgf/cm is read as κ = 1 (its plate then has D/s² = 5 kgf/cm; ours has
D/s² = 4167 kgf/cm, about 833 times stiffer relative to its supports).

**"fig6"** (:func:`contour_pressure`): the built-in ``contour`` scene (the slab on 64 elastic
supports along its edges, s = 50 cm): the reactions along the contour for several κ, three
uniformity measures (:func:`plateqp.studies.design.uniformity`) on a log grid of κ, and the κ
that minimises each (:func:`plateqp.studies.design.most_uniform_stiffness` with ``measure=``).

**"regulate"** lives in :mod:`plateqp.demo.regulation` (the paper's gap regulation on the
``heave`` scene) and **"soils"** in :mod:`plateqp.demo.soils` (one heaved slab on Winkler's,
Pasternak's and the half-space's soil); :func:`run_study` runs them like the other two.

This module computes; figures come from :mod:`plateqp.plotting.studies`, words from
:func:`path_lines` and :func:`contour_lines`. Support numbers users read are 1-based.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from .. import scenes
from ..errors import PlateQPWarning
from ..model.paths import set_param
from ..plotting.data import support_spacing
from ..model.scene import Scene

#: The studies ``plateqp demo`` knows besides the scenes, and the figures each draws.
STUDIES = {"soils": ("pressure", "sections"), "fig5": ("schemes", "sections"), "fig6": ("pressure", "uniformity"),
           "regulate": ("reactions",)}
#: The paper's values (kgf/cm): the softest stiffness of figure 5, the most uniform of figure 6.
PAPER_C_SOFTEST = 5.0
PAPER_C_UNIFORM = 3.2
#: κ the paper's softest value is read as (see the module doc).
KAPPA_MIN = 1.0
#: Sections 1-1 and 2-2 of the figure 5 study: the row of supports 1–5 (heaved 1, 2) and the
#: column of supports 3, 8, 13, 18, 23 (heaved 8), as fractions of the plate's sides.
FIG5_SECTIONS = (("y = 0 (supports 1–5)", (0.0, 0.0), (1.0, 0.0)),
                 ("x = a/2 (supports 3, 8, 13, 18, 23)", (0.5, 0.0), (0.5, 1.0)))


def kappa_unit(scene: Scene) -> tuple[float, float]:
    """(D/s², s) of a scene: c = κ · D/s²; s the support spacing (see the module doc)."""
    xy = np.array([[s.x, s.y] for s in scene.supports], dtype=float).reshape(-1, 2)
    s = support_spacing(xy)
    if not (math.isfinite(s) and s > 0):
        raise ValueError(f"scene {scene.name!r}: κ needs at least two supports")
    return scene.plate.D / s**2, s


def _with_mesh(scene: Scene, mesh: int | None) -> Scene:
    if mesh is None:
        return scene
    return set_param(set_param(scene, "mesh.nx", int(mesh)), "mesh.ny", int(mesh))


def _solve(scene: Scene, c, model=None):
    import plateqp as pq

    sc = set_param(scene, "supports.*.stiffness", c)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlateQPWarning)
        return pq.solve(sc, accuracy="high", model=model)


def _ids(active) -> list[int]:
    return [int(i) + 1 for i in np.flatnonzero(np.asarray(active, dtype=bool))]


# -- figure 5 ---------------------------------------------------------------------------------
@dataclass
class Scheme:
    """One working scheme of a stiffness path: its contact set, its κ interval (lo, hi), and the
    solve drawn for it (at ``kappa``)."""

    active: tuple
    lo: float
    hi: float
    kappa: float
    result: object

    @property
    def in_contact(self) -> list[int]:
        """1-based numbers of the supports in contact."""
        return _ids(self.active)


@dataclass
class StiffnessPath:
    """The figure 5 study: the working schemes as the stiffness falls from rigid to κ_min.

    ``breakpoints``: dicts {kappa (None if the bracket could not be refined), bracket [κ_hi,
    κ_lo] in the order of the path, c, on, off (1-based supports that come into contact /
    lift off there), note}; ``schemes``: :class:`Scheme`, in the order of the path; ``sweep``:
    the :class:`plateqp.studies.SweepResult` (values are stiffnesses c, "rigid" first).
    """

    scene: Scene
    unit: float  # D/s²: c = κ · unit
    spacing: float
    kappas: list[float]
    sweep: object
    breakpoints: list[dict]
    schemes: list[Scheme]
    sections: list = field(default_factory=list)


def stiffness_path(scene: Scene | None = None, kappa_max: float = 1e4, kappa_min: float = KAPPA_MIN,
                   n: int = 13, mesh: int | None = None, rtol: float = 1e-3) -> StiffnessPath:
    """Follow the working scheme of ``scene`` (default: the built-in ``stiffness``) as every
    support's stiffness falls from rigid through ``n`` values of κ, log-spaced from
    ``kappa_max`` to ``kappa_min``; ``mesh``: cells per side (default: the scene's)."""
    from ..studies import sweep

    scene = _with_mesh(scene if scene is not None else scenes.load("stiffness"), mesh)
    unit, s = kappa_unit(scene)
    kappas = [math.inf] + list(np.geomspace(kappa_max, kappa_min, n))
    values = ["rigid"] + [float(k * unit) for k in kappas[1:]]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlateQPWarning)
        sw = sweep(scene, "supports.*.stiffness", values, accuracy="high", executor="serial", progress=False,
                   rtol=rtol)

    def kap(v):
        return math.inf if v == "rigid" else float(v) / unit

    bps = []
    for b in sw.breakpoints:
        before, after = set(b["before"]), set(b["after"])
        bps.append({"kappa": None if b["at"] is None else kap(b["at"]),
                    "bracket": [kap(b["bracket"][0]), kap(b["bracket"][1])],
                    "c": None if b["at"] is None else float(b["at"]),
                    "on": sorted(i + 1 for i in after - before), "off": sorted(i + 1 for i in before - after),
                    "before": sorted(i + 1 for i in before), "after": sorted(i + 1 for i in after),
                    "note": b.get("note")})
    # the schemes: the rigid one, then the one after each breakpoint
    first = sw.rows[0]["active"]
    sets = [tuple(bool(a) for a in first)]
    m = len(first)
    for b in bps:
        sets.append(tuple(i + 1 in b["after"] for i in range(m)))
    edges = [math.inf] + [b["kappa"] if b["kappa"] is not None else math.sqrt(b["bracket"][0] * b["bracket"][1])
                          if all(map(math.isfinite, b["bracket"])) else b["bracket"][-1] for b in bps] + [kappa_min]
    from ..model.assembly import build_model
    from ..studies.reuse import adapt_model

    base = build_model(scene)
    schemes = []
    for j, act in enumerate(sets):
        hi, lo = edges[j], edges[j + 1]
        if j == 0:
            k = math.inf
        elif j == len(sets) - 1:
            k = kappa_min
        else:
            k = math.sqrt(lo * hi)
        c = "rigid" if math.isinf(k) else k * unit
        sc = set_param(scene, "supports.*.stiffness", c)
        res = _solve(scene, c, model=adapt_model(base, sc))
        schemes.append(Scheme(act, lo, hi, k, res))
    a, b = scene.plate.a, scene.plate.b
    secs = [(lab, (p0[0] * a, p0[1] * b), (p1[0] * a, p1[1] * b)) for lab, p0, p1 in FIG5_SECTIONS]
    return StiffnessPath(scene, unit, s, kappas, sw, bps, schemes, secs)


def path_lines(p: StiffnessPath, units: tuple[str, str] | None = None) -> list[str]:
    """The figure 5 study in words: scaling, each breakpoint (κ, c, supports 1-based), schemes."""
    L, F = units or ("", "")
    cu = f" {F}/{L}" if L and F else ""
    out = [f"kappa = c s^2/D with s = {p.spacing:g}{' ' + L if L else ''}, D/s^2 = {p.unit:.4g}{cu}; "
           f"path from rigid to kappa = {p.kappas[-1]:g} (the paper's softest c = {PAPER_C_SOFTEST:g} kgf/cm read as "
           f"kappa = {KAPPA_MIN:g}: the paper's plate has D/s^2 = {PAPER_C_SOFTEST / KAPPA_MIN:g} kgf/cm, ours "
           f"{p.unit:.4g}{cu}, {p.unit / (PAPER_C_SOFTEST / KAPPA_MIN):.0f} times stiffer)",
           f"{len(p.schemes)} working schemes, {len(p.breakpoints)} changes (the paper shows 6 schemes from rigid "
           f"to c = {PAPER_C_SOFTEST:g} kgf/cm)"]
    for j, b in enumerate(p.breakpoints, 1):
        where = (f"kappa = {b['kappa']:.4g} (c = {b['c']:.4g}{cu})" if b["kappa"] is not None
                 else f"kappa in ({b['bracket'][1]:.4g}, {b['bracket'][0]:.4g})")
        out.append(f"change {j} at {where}: comes into contact {_list(b['on'])}, lifts off {_list(b['off'])}"
                   + (f" ({b['note']})" if b.get("note") else ""))
    for j, s in enumerate(p.schemes, 1):
        off = [i + 1 for i, a in enumerate(s.active) if not a]
        out.append(f"scheme {j}: kappa in {_interval(s.lo, s.hi)}: {sum(s.active)} of {len(s.active)} in contact;"
                   f" lifted off {_list(off)}")
    return out


def _interval(lo: float, hi: float) -> str:
    return f"[{lo:.4g}, {'rigid' if math.isinf(hi) else format(hi, '.4g')}]"


def _list(ids) -> str:
    return ", ".join(map(str, ids)) if ids else "none"


def scheme_title(s: Scheme) -> str:
    """κ interval of a scheme, for a panel title."""
    if math.isinf(s.hi) and math.isinf(s.kappa):
        return "rigid" if math.isinf(s.lo) else f"κ > {s.lo:.3g} (drawn: rigid)"
    return f"κ ∈ ({s.lo:.3g}, {s.hi:.3g}) (drawn: {s.kappa:.3g})"


# -- figure 6 ---------------------------------------------------------------------------------
@dataclass
class ContourPressure:
    """The figure 6 study: reactions along an elastic contour and their uniformity against κ.

    ``curves``: (κ, Result) for the pressure figure; ``grid``: κ of the uniformity scan;
    ``measures``: measure → its value at each κ of ``grid``; ``optima``: measure →
    :class:`plateqp.studies.design.UniformStiffness` (its c in force/length; κ = c/unit).
    """

    scene: Scene
    unit: float
    spacing: float
    curves: list
    grid: np.ndarray
    measures: dict
    optima: dict


#: κ of the pressure curves drawn by the figure 6 study.
FIG6_KAPPAS = (100.0, 1.0, 0.1, 0.01, 1e-3, 1e-4)


def contour_pressure(scene: Scene | None = None, kappas=FIG6_KAPPAS, kappa_range=(1e-5, 1e2), scan: int = 15,
                     mesh: int | None = None) -> ContourPressure:
    """Reactions along the contour of ``scene`` (default: the built-in ``contour``) for
    ``kappas``, the three uniformity measures on a log grid of ``scan`` κ over ``kappa_range``,
    and the κ minimising each (``most_uniform_stiffness(..., measure=...)``)."""
    from ..model.assembly import build_model
    from ..studies.design import UNIFORMITY_MEASURES, most_uniform_stiffness, uniformity
    from ..studies.reuse import adapt_model

    scene = _with_mesh(scene if scene is not None else scenes.load("contour"), mesh)
    unit, s = kappa_unit(scene)
    base = build_model(scene)

    def at(k):
        c = float(k * unit)
        return _solve(scene, c, model=adapt_model(base, set_param(scene, "supports.*.stiffness", c)))

    curves = [(float(k), at(k)) for k in kappas]
    grid = np.geomspace(kappa_range[0], kappa_range[1], scan)
    Rs = [at(k).reactions for k in grid]
    measures = {m: np.array([uniformity(R, m) for R in Rs]) for m in UNIFORMITY_MEASURES}
    optima = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlateQPWarning)
        for m in UNIFORMITY_MEASURES:
            optima[m] = most_uniform_stiffness(scene, (kappa_range[0] * unit, kappa_range[1] * unit), accuracy="high",
                                               scan=scan, measure=m)
    return ContourPressure(scene, unit, s, curves, grid, measures, optima)


def contour_lines(p: ContourPressure, units: tuple[str, str] | None = None) -> list[str]:
    """The figure 6 study in words: each measure's optimum beside the paper's 3.2 kgf/cm."""
    L, F = units or ("", "")
    cu = f" {F}/{L}" if L and F else ""
    k_paper = PAPER_C_UNIFORM / p.unit
    out = [f"kappa = c s^2/D with s = {p.spacing:g}{' ' + L if L else ''}, D/s^2 = {p.unit:.4g}{cu}; "
           f"scanned kappa {p.grid[0]:.3g} ... {p.grid[-1]:.3g}"]
    for m, u in p.optima.items():
        where = "at the soft end of the range: no interior optimum" if u.at_bound and u.c < math.sqrt(
            p.grid[0] * p.grid[-1]) * p.unit else ("at the stiff end of the range" if u.at_bound else "interior")
        out.append(f"most uniform by {m}: kappa = {u.c / p.unit:.3g} (c = {u.c:.4g}{cu}), {m} = {u.value:.4g},"
                   f" {int(np.count_nonzero(u.reactions > 0))} of {u.reactions.size} in contact ({where})")
    out.append(f"the paper: most uniform at c = {PAPER_C_UNIFORM:g} kgf/cm; in this scene that is kappa = "
               f"{k_paper:.2g}, in the rigid-plate limit (our slab is about 10^3 times stiffer relative to its "
               f"supports than the paper's values imply); with the figure 5 scaling (the paper's D/s^2 = "
               f"{PAPER_C_SOFTEST / KAPPA_MIN:g} kgf/cm at s = 200 cm, so at s = {p.spacing:g} cm D/s^2 = "
               f"{PAPER_C_SOFTEST / KAPPA_MIN * (200.0 / p.spacing) ** 2:g} kgf/cm) it would be kappa = "
               f"{PAPER_C_UNIFORM / (PAPER_C_SOFTEST / KAPPA_MIN * (200.0 / p.spacing) ** 2):.2g}")
    for m, v in p.measures.items():
        mono = bool(np.all(np.diff(v) >= -1e-12 * np.abs(v[:-1])))  # grid runs soft -> stiff
        what = ("rises monotonically with kappa: most uniform in the rigid-plate limit (soft supports: R = c times"
                " a plane), no interior optimum" if mono else "not monotonic in kappa")
        out.append(f"{m} on the scan grid: {what}")
    return out



# -- the demo's runs ---------------------------------------------------------------------------
@dataclass
class StudyRun:
    """What ``plateqp demo`` computed for one study: its words, figures and JSON."""

    name: str
    title: str
    story: str
    lines: list[str]
    figures: dict[str, bytes]  # file stem → PNG bytes, in display order
    captions: dict[str, str]
    data: dict
    t: float
    ok: bool = True
    table: str = ""  # a plain-text table of the study's numbers, printed as it is


TITLES = {"soils": "One heaved slab on Winkler, Pasternak and half-space soil: pressure, lift-off, moments",
          "fig5": "Figure 5: the working scheme as the support stiffness falls (heaved supports 1, 2, 8)",
          "fig6": "Figure 6: the contact pressure along an elastic contour, and its most uniform stiffness",
          "regulate": "Regulating the interaction forces by changing the gaps (the paper's third claim)"}


def run_study(name: str, figures: bool = True, mesh: int | None = None, dpi: int = 100) -> StudyRun:
    """Compute one study ("fig5", "fig6", "regulate" or "soils"), its lines, JSON and (``figures``) its PNGs."""
    import time

    if name not in STUDIES:
        raise ValueError(f"unknown study {name!r}")
    t0 = time.perf_counter()
    units = ("cm", "kgf")
    figs: dict[str, bytes] = {}
    caps: dict[str, str] = {}
    table = ""

    def put(stem, caption, make):
        if stem not in STUDIES[name]:  # output_files must know every file the demo may write
            raise ValueError(f"figure {stem!r} is not in paper.STUDIES[{name!r}]")
        from .. import plotting as pl

        figs[f"{name}-{stem}"] = pl.png_bytes(make(), dpi=dpi)
        caps[f"{name}-{stem}"] = caption

    if name == "fig5":
        p = stiffness_path(mesh=mesh)
        lines = path_lines(p, units)
        story = (f"The built-in scene 'stiffness' ({p.scene.mesh.nx} x {p.scene.mesh.ny} mesh), every support's "
                 "stiffness lowered from rigid to kappa = 1, followed with plateqp.studies.sweep (log grid of "
                 f"{len(p.kappas) - 1} kappa values plus rigid; each change located by its bisection to 1e-3 "
                 "relative). Module doc of plateqp.demo.paper: the scaling.")
        ok = all(s.result.ok and tuple(bool(a) for a in s.result.active) == s.active for s in p.schemes)
        data = {"kappa_unit_D_over_s2": p.unit, "spacing": p.spacing, "kappa_min": p.kappas[-1],
                "breakpoints": [_json(b) for b in p.breakpoints],
                "schemes": [{"kappa_interval": [_json(s.lo), _json(s.hi)], "kappa_drawn": _json(s.kappa),
                             "in_contact": s.in_contact, "reactions": s.result.reactions.tolist()}
                            for s in p.schemes],
                "sweep": p.sweep.to_dict()}
        if figures:
            from ..plotting.studies import plot_scheme_sections, plot_schemes

            titles = [scheme_title(s) for s in p.schemes]
            put("schemes", "The working schemes, one panel per scheme, in the order the stiffness falls: supports "
                "filled where in contact, hollow where lifted off, red ▲ heaved (1, 2, 8); the κ interval of the "
                "scheme and the κ drawn.", lambda: plot_schemes([s.result for s in p.schemes], titles, units))
            put("sections", "Deflection along sections 1-1 and 2-2, one curve per scheme (drawn at the κ of its "
                "panel).", lambda: plot_scheme_sections([s.result for s in p.schemes],
                                                        [f"{j}: κ = {_k(s.kappa)}" for j, s in
                                                         enumerate(p.schemes, 1)], p.sections, units))
    elif name == "soils":
        from . import soils as sl

        st = sl.soil_study(mesh=mesh)
        story, lines, table, data, ok = sl.story(st), sl.lines(st), sl.table(st), sl.data(st), st.ok
        if figures:
            for stem, (caption, make) in sl.figures(st).items():
                put(stem, caption, make)
    elif name == "regulate":
        from .regulation import regulation, regulation_lines

        st = regulation(_with_mesh(scenes.load("heave"), mesh))
        lines = regulation_lines(st, units)
        story = (f"The built-in scene 'heave' ({st.scene.mesh.nx} x {st.scene.mesh.ny} mesh): new gaps (shims) from "
                 "plateqp.studies.design.regulate_gaps (plateqp regulate on the command line), each checked by "
                 "solving the regulated scene's contact problem again. Module doc of plateqp.demo.regulation.")
        ok = all(r.check.ok and r.error <= 1e-8 for r in st.runs)
        data = {"before": st.before.reactions.tolist(), "level_ground": st.level.reactions.tolist(),
                "regulations": [{"name": r.name, "supports": [int(i) + 1 for i in r.supports],
                                 "target": r.target.tolist(), "gaps": r.gaps.tolist(),
                                 "reactions_checked": r.check.reactions.tolist(), "largest_miss_of_load": r.error,
                                 "dR_dg0": None if r.shim is None else r.shim.tolist()}
                                for r in st.runs]}
        if figures:
            from ..plotting.studies import plot_regulation

            put("reactions", "Reactions of the 25 supports as the heaved slab stands, after equalising the four "
                "supports around the machine foot, and after re-levelling the supports that were not heaved "
                "(hatched: the regulated supports); right: the gap changes (negative: a shim up).",
                lambda: plot_regulation(st.before, st.runs, units))
    else:
        q = contour_pressure(mesh=mesh)
        lines = contour_lines(q, units)
        story = (f"The built-in scene 'contour' ({q.scene.mesh.nx} x {q.scene.mesh.ny} mesh): the reactions of its "
                 "64 edge supports for several kappa, and the kappa that makes them most uniform by each measure "
                 "(plateqp.studies.design.most_uniform_stiffness(measure=...)).")
        ok = all(r.ok for _, r in q.curves)
        data = {"kappa_unit_D_over_s2": q.unit, "spacing": q.spacing,
                "curves": [{"kappa": k, "c": k * q.unit, "reactions": r.reactions.tolist()} for k, r in q.curves],
                "scan": {"kappa": q.grid.tolist(), **{m: v.tolist() for m, v in q.measures.items()}},
                "optima": {m: {"kappa": u.c / q.unit, "c": u.c, "value": u.value, "at_bound": u.at_bound}
                           for m, u in q.optima.items()},
                "paper_c": PAPER_C_UNIFORM, "paper_kappa_in_this_scene": PAPER_C_UNIFORM / q.unit}
        if figures:
            from ..plotting.studies import plot_contour_pressure, plot_uniformity

            put("pressure", "Reactions of the 64 contour supports along the contour, one curve per κ (stiff to "
                "soft): lifted-off supports at 0.", lambda: plot_contour_pressure(
                    [r for _, r in q.curves], [f"κ = {_k(k)} (c = {k * q.unit:.3g} kgf/cm)" for k, _ in q.curves],
                    units))
            put("uniformity", "Uniformity of the reactions against κ: std/mean, peak/mean, (max − min)/mean; "
                "dashed: the minimum of each; dotted: the paper's c = 3.2 kgf/cm in this scene.",
                lambda: plot_uniformity(q.grid, q.measures, {m: u.c / q.unit for m, u in q.optima.items()},
                                        {"paper's 3.2 kgf/cm": PAPER_C_UNIFORM / q.unit}))
    return StudyRun(name, TITLES[name], story, lines, figs, caps, data, time.perf_counter() - t0, ok, table)


def _k(k: float) -> str:
    return "rigid" if math.isinf(k) else f"{k:.3g}"


def _json(v):
    if isinstance(v, dict):
        return {k: _json(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_json(x) for x in v]
    if isinstance(v, float) and not math.isfinite(v):
        return "rigid" if v > 0 else None
    return v


__all__ = ["FIG5_SECTIONS", "FIG6_KAPPAS", "KAPPA_MIN", "PAPER_C_SOFTEST", "PAPER_C_UNIFORM", "STUDIES", "TITLES",
           "ContourPressure", "Scheme", "StiffnessPath", "StudyRun", "contour_lines", "contour_pressure",
           "kappa_unit", "path_lines", "run_study", "scheme_title", "stiffness_path"]
