"""``plateqp demo``: solve the built-in scenes, compare with two-sided support, run the studies
(:data:`plateqp.demo.paper.STUDIES`: the source paper's "fig5", "fig6", "regulate", and "soils",
one heaved slab on three soils), write a report.

For each scene: the one-sided solve (:func:`plateqp.solve`, accuracy "high") and, when the
scene has one-sided supports, the source paper's comparison (:func:`plateqp.solve_bilateral`:
every support made two-sided). Prints one summary line per scene to stdout, the paper's
quantitative statements for our scenes (:func:`compare`), and writes the figures (PNG), one
JSON file per scene and a self-contained ``report.html`` (figures embedded as base64 PNG)
into the output folder. Progress goes to stderr: a bar on a terminal (:mod:`plateqp.progress`),
log messages (``logging``, logger ``plateqp.demo``; skipped parts as warnings). The figures come from
:mod:`plateqp.plotting`, the summary table and the HTML from :mod:`plateqp.demo.report`;
:func:`output_files` lists every file a run may write, so that the command line can check
the folder before any work and refuse to overwrite without ``--force``.

The paper's statements, and how they are measured here
------------------------------------------------------
*Zones* (:func:`zones`) follow the supports' contact state in the one-sided solution, as the
paper defines them (contact zone: the supports that came into contact; lift-off zone: those
that did not). Each plate node belongs to its nearest support(s) — the support's tributary
area — provided that support is at most one support spacing away (the spacing is the median
distance from a support to its nearest neighbour). A node is in the **contact zone** if all
its nearest supports are in contact, in the **lift-off zone** if none is; nodes equidistant
from supports of both kinds, and nodes farther than one spacing from every support, are in
neither.

*Deflection difference in a zone*: max |w_one-sided − w_two-sided| over the zone's nodes,
absolute and relative to the largest |w| of either solution over the whole plate.

*The paper's sections 2 and 4* (its "at most 6 %"): the section lines of the figures
(:func:`plateqp.plotting.default_sections`: the rows of supports, numbered 1, 2, ... from
y = 0), and on sections 2 and 4 the mesh nodes of the contact zone. Their max |w_one − w_two|
is divided three ways, since the answer depends on it: by the largest |w_two| along
sections 2 and 4 (**the headline**: the paper compares the curves of its section plots), by
the largest |w| over the plate, and node by node by |w_two| there, counting only the nodes
where |w_two| is at least :data:`NODEWISE_FLOOR` (10 %) of its largest value along sections 2
and 4 (a ratio to |w_two| alone grows without bound where w_two crosses zero: at every rigid
support without a gap w_two is zero up to rounding).

*σ1 near the load*: σ1 (bottom face) at a **fixed distance** from the largest point load,
the mean of the nodal field at the four points (x ± r, y), (x, y ± r), r = half the support
spacing (interpolated bilinearly; mesh nodes when the load sits on mesh lines, as in our
scenes: 29.6, 29.4, 29.2 kgf/cm² one-sided on the heave scene at 16, 32, 64 cells), in each
solution, and the relative difference (σ1_one −
σ1_two) / |σ1_two|. The peak at the load itself does not converge under mesh refinement
(a point load's moments grow like log(1/h): 101, 135, 166, 196 kgf/cm² on the heave scene at
8, 16, 32, 64 cells per side); it is kept for reference (``s1_one``, ``s1_two``: the largest
nodal σ1 within max(half the support spacing, two mesh cells) of the load) but is not compared.

Scenes on a triangle mesh (``mesh.element = "dkt"``, a shaped plate such as the built-in
"tank") get the one-sided and two-sided solves and every figure (the field maps and the zones are
the same for every mesh); the parts measured on the structured grid are skipped, each with
its reason in :attr:`SceneRun.skipped` (printed, in the JSON file and in the report): the
paper's statements (:func:`compare`: zones, sections 2 and 4 and the ring around the load
read the grid's rows of nodes) and the convergence study by mesh halving (the studies halve
``nx`` × ``ny``, not ``mesh.size``).
"""

from __future__ import annotations

import importlib.util
import logging
import math
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import scenes
from ..errors import PlateQPWarning, SceneError
from ..plotting.data import support_spacing
from ..progress import Progress
from .report import _json_safe, format_table, summary_row, write_files  # noqa: F401 - _json_safe: its old home
from .paper import STUDIES, TITLES, run_study

DEFAULT_OUT = "plateqp-demo"
DPI = 100
#: The figures of a scene, as ``<scene>-<stem>.png`` (a scene draws those that apply to it).
FIGURES = ("mesh", "surface", "contours", "sections", "difference", "sigma1", "reactions", "convergence")
#: Share of the largest |w_two| along sections 2 and 4 below which a node is left out of the
#: node-by-node ratio |w_one − w_two| / |w_two| (see the module doc).
NODEWISE_FLOOR = 0.1
# units of the built-in scenes that do not state them in a "# units: length, force" comment
UNITS_FALLBACK: dict[str, tuple[str, str]] = {"slab": ("m", "N")}


# -- scene metadata ------------------------------------------------------------------------------
def scene_notes(name: str) -> tuple[str, tuple[str, str] | None]:
    """(story, units) of a built-in scene, read from its leading TOML comment.

    The story is the comment block at the top of the file; a line ``# units: cm, kgf`` in it
    gives the (length, force) units.
    """
    story, units = [], UNITS_FALLBACK.get(name)
    for line in scenes.path(name).read_text().splitlines():
        s = line.strip()
        if not s.startswith("#"):
            if s:
                break
            continue
        text = s.lstrip("#").strip()
        if text.lower().startswith("units:"):
            parts = [p.strip() for p in text.split(":", 1)[1].split(",")]
            if len(parts) == 2 and all(parts):
                units = (parts[0], parts[1])
            continue
        story.append(text)
    return "\n".join(story).strip(), units


# -- the paper's statements ---------------------------------------------------------------------
def zones(result) -> np.ndarray:
    """Per node of the plate (``mesh.nodes`` order, on every mesh): +1 contact zone, −1 lift-off
    zone, 0 neither (see module doc)."""
    sc = result.scene
    nodes = result.model.grid.nodes
    n = len(sc.supports)
    out = np.zeros(len(nodes), dtype=int)
    if n == 0 or result.active.size < n:
        return out
    xy = np.array([[s.x, s.y] for s in sc.supports], dtype=float)
    active = np.asarray(result.active[:n], dtype=bool)
    span = float(np.ptp(nodes, axis=0).max())
    spacing = support_spacing(xy)
    if not math.isfinite(spacing):
        spacing = span
    d = np.hypot(nodes[:, None, 0] - xy[None, :, 0], nodes[:, None, 1] - xy[None, :, 1])
    dmin = d.min(axis=1)
    tol = 1e-9 * span
    nearest = d <= dmin[:, None] + tol
    all_on = np.all(~nearest | active[None, :], axis=1)
    all_off = np.all(~nearest | ~active[None, :], axis=1)
    z = np.where(all_on, 1, np.where(all_off, -1, 0))
    z[dmin > spacing + tol] = 0
    return z


@dataclass
class Comparison:
    """One-sided vs two-sided support, measured as the source paper states its findings.

    Lengths and forces in the scene's units; ``*_rel`` are fractions (0.06 = 6 %). A zone with
    no nodes has ``nan`` differences; a scene without a point load has ``nan`` σ1 entries.
    """

    n_supports: int
    n_contact: int
    spacing: float
    w_ref: float  # largest |w| of either solution over the plate (the relative scale)
    contact_nodes: int
    liftoff_nodes: int
    dw_contact: float
    dw_contact_rel: float
    dw_liftoff: float
    dw_liftoff_rel: float
    dw_max: float  # over the whole plate
    s1_radius: float
    s1_one: float
    s1_two: float
    s1_rel: float
    tension_supports: list[int] = field(default_factory=list)  # 1-based: R < 0 when two-sided
    min_R_two: float = float("nan")
    # the paper's sections 2 and 4, contact-zone nodes on them (see the module doc)
    sections_nodes: int = 0
    sections_dw: float = float("nan")
    sections_rel: float = float("nan")  # / max |w_two| along sections 2 and 4 (the headline)
    sections_rel_plate: float = float("nan")  # / max |w| over the plate
    # max of |dw| / |w_two| node by node, over the nodes where |w_two| >= NODEWISE_FLOOR * max |w_two| on
    # sections 2 and 4 (sections_nodewise_nodes of them)
    sections_rel_nodewise: float = float("nan")
    sections_nodewise_nodes: int = 0
    sections_nodewise_floor: float = NODEWISE_FLOOR
    s1_ring_radius: float = float("nan")
    s1_ring_one: float = float("nan")
    s1_ring_two: float = float("nan")
    s1_ring_rel: float = float("nan")

    def lines(self, units: tuple[str, str] | None = None) -> list[str]:
        """The statements in words."""
        L, F = (units or ("", ""))
        Lu = f" {L}" if L else ""
        Fu = f" {F}" if F else ""
        Su = f" {F}/{L}²" if (L and F) else ""
        out = [f"{self.n_contact} of {self.n_supports} supports in contact"]
        for name, nodes, dw, rel in (("contact zone", self.contact_nodes, self.dw_contact, self.dw_contact_rel),
                                     ("lift-off zone", self.liftoff_nodes, self.dw_liftoff, self.dw_liftoff_rel)):
            if nodes:
                out.append(f"{name} ({nodes} nodes): max |w1 - w2| = {dw:.4g}{Lu} = {100 * rel:.1f} % of max |w|"
                           f" ({self.w_ref:.4g}{Lu})")
            else:
                out.append(f"{name}: no nodes")
        if self.sections_nodes:
            out.append(f"sections 2 and 4, contact zone ({self.sections_nodes} nodes): max |w1 - w2| = "
                       f"{self.sections_dw:.4g}{Lu} = {100 * self.sections_rel:.1f} % of the largest two-sided |w| "
                       f"on those sections (the paper: at most 6 %); {100 * self.sections_rel_plate:.1f} % of max |w| "
                       f"over the plate" + (f"; node by node up to {100 * self.sections_rel_nodewise:.1f} % of |w2| at the "
                       f"{self.sections_nodewise_nodes} of them where |w2| is at least {100 * self.sections_nodewise_floor:.0f} % of "
                       "that largest" if self.sections_nodewise_nodes else ""))
        if math.isfinite(self.s1_ring_one):
            out.append(f"sigma1 at {self.s1_ring_radius:g}{Lu} from the load (mean of the 4 points on the x, y lines"
                       " through it): "
                       f"{self.s1_ring_one:.4g}{Su} one-sided, {self.s1_ring_two:.4g}{Su} two-sided "
                       f"({100 * self.s1_ring_rel:+.1f} %; the paper: 2 %)")
        if math.isfinite(self.s1_one):
            out.append(f"max sigma1 within {self.s1_radius:g}{Lu} of the load: {self.s1_one:.4g}{Su} one-sided,"
                       f" {self.s1_two:.4g}{Su} two-sided ({100 * self.s1_rel:+.1f} %); warning: this peak at a point"
                       " load does not converge under mesh refinement, compare at a fixed distance (above)")
        if self.tension_supports:
            out.append(f"two-sided, {len(self.tension_supports)} supports would pull the plate down"
                       f" (min R = {self.min_R_two:.4g}{Fu}): supports {', '.join(map(str, self.tension_supports))}")
        else:
            out.append("two-sided, no support would be in tension")
        return out


def compare(one, two, radius: float | None = None) -> Comparison:
    """The paper's statements for one scene: zones' deflection differences, σ1 near the load.

    ``one``: the one-sided Result; ``two``: the two-sided Result of the same scene
    (:func:`plateqp.solve_bilateral`); ``radius``: of the neighbourhood of the load for σ1
    (default max(half the support spacing, two mesh cells)). Definitions in the module doc.
    """
    sc = one.scene
    g = one.model.grid
    n = len(sc.supports)
    xy = np.array([[s.x, s.y] for s in sc.supports], dtype=float).reshape(n, 2)
    spacing = support_spacing(xy)
    w1, w2 = one.w_nodes(), two.w_nodes()  # one value per node of the plate
    dw = np.abs(w1 - w2)
    w_ref = float(max(np.abs(w1).max(initial=0.0), np.abs(w2).max(initial=0.0)))
    z = zones(one)

    def zone(val):
        sel = z == val
        if not sel.any():
            return 0, float("nan"), float("nan")
        m = float(dw[sel].max())
        return int(sel.sum()), m, (m / w_ref if w_ref > 0 else 0.0)

    nc, dwc, dwc_rel = zone(1)
    nl, dwl, dwl_rel = zone(-1)
    # sigma1 near the (largest) point load
    pl = [ld for ld in sc.loads if ld.type == "point"]
    h = max(g.hx, g.hy)
    r = radius if radius is not None else max(0.5 * spacing if math.isfinite(spacing) else 0.0, 2.0 * h)
    s1_one = s1_two = s1_rel = float("nan")
    if pl:
        ld = max(pl, key=lambda p: abs(p.P))
        nodes = g.nodes
        near = np.hypot(nodes[:, 0] - ld.x, nodes[:, 1] - ld.y) <= r * (1 + 1e-9)
        S1, S2 = one.nodal("s1"), two.nodal("s1")
        if near.any():
            s1_one, s1_two = float(S1[near].max()), float(S2[near].max())
            s1_rel = (s1_one - s1_two) / abs(s1_two) if s1_two != 0 else (0.0 if s1_one == 0 else float("inf"))
    sec = _sections_24(one, w1, w2, z, w_ref)
    ring = {}
    if pl:
        r_ring = 0.5 * spacing if math.isfinite(spacing) else 2.0 * h
        s1r_one, s1r_two = (_ring_mean(res, ld.x, ld.y, r_ring) for res in (one, two))
        ring = {"s1_ring_radius": float(r_ring), "s1_ring_one": s1r_one, "s1_ring_two": s1r_two,
                "s1_ring_rel": (s1r_one - s1r_two) / abs(s1r_two) if s1r_two != 0 else float("nan")}
    R2 = np.asarray(two.reactions[:n], dtype=float)
    rscale = max(np.abs(R2).max(initial=0.0), 1e-300)
    tension = [int(i) + 1 for i in np.flatnonzero(R2 < -1e-9 * rscale)]
    return Comparison(
        n_supports=n, n_contact=int(np.asarray(one.active[:n]).sum()), spacing=spacing, w_ref=w_ref,
        contact_nodes=nc, liftoff_nodes=nl, dw_contact=dwc, dw_contact_rel=dwc_rel, dw_liftoff=dwl,
        dw_liftoff_rel=dwl_rel, dw_max=float(dw.max(initial=0.0)), s1_radius=float(r), s1_one=s1_one,
        s1_two=s1_two, s1_rel=s1_rel, tension_supports=tension,
        min_R_two=float(R2.min()) if R2.size else float("nan"), **sec, **ring)


def _sections_24(one, w1, w2, z, w_ref) -> dict:
    """Contact-zone nodes on the figures' sections 2 and 4 and their deflection differences."""
    from ..plotting.plan import default_sections

    secs = default_sections(one)
    if len(secs) < 4:
        return {}
    nodes = one.model.grid.nodes
    tol = 1e-9 * float(np.ptp(nodes, axis=0).max())
    on_line = np.zeros(nodes.shape[0], dtype=bool)
    for _lab, p0, p1 in (secs[1], secs[3]):
        d = np.array(p1) - np.array(p0)
        length = float(np.hypot(*d))
        rel = nodes - np.array(p0)
        t = rel @ d / length**2
        off = np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0]) / length
        on_line |= (off <= tol) & (t >= -1e-9) & (t <= 1 + 1e-9)
    sel = on_line & (z == 1)
    if not sel.any():
        return {}
    dw = np.abs(w1 - w2)
    m = float(dw[sel].max())
    w2_sec = float(np.abs(w2[on_line]).max())
    big = sel & (np.abs(w2) >= NODEWISE_FLOOR * w2_sec) & (np.abs(w2) > 0)
    nodewise = float((dw[big] / np.abs(w2[big])).max()) if big.any() else float("nan")
    return {"sections_nodes": int(sel.sum()), "sections_dw": m,
            "sections_rel": m / w2_sec if w2_sec > 0 else float("nan"),
            "sections_rel_plate": m / w_ref if w_ref > 0 else float("nan"), "sections_rel_nodewise": nodewise,
            "sections_nodewise_nodes": int(big.sum())}


def _ring_mean(res, x0: float, y0: float, r: float, k: int = 4) -> float:
    """Mean of the nodal σ1 (bottom face), interpolated bilinearly, at k points on the circle of
    radius r around (x0, y0), the first at (x0 + r, y0) (points off the plate left out; nan if
    none is on it). k = 4: the points on the mesh lines through (x0, y0)."""
    from scipy.interpolate import RegularGridInterpolator

    g = res.model.grid
    S = g.to_grid(res.nodal("s1"))  # the structured grid's view, NaN off the plate
    f = RegularGridInterpolator((np.linspace(0.0, g.b, g.ny + 1), np.linspace(0.0, g.a, g.nx + 1)), S,
                                bounds_error=False, fill_value=np.nan)
    t = 2 * np.pi * np.arange(k) / k
    v = f(np.column_stack([y0 + r * np.sin(t), x0 + r * np.cos(t)]))
    v = v[np.isfinite(v)]
    return float(v.mean()) if v.size else float("nan")


# -- one scene -----------------------------------------------------------------------------------
@dataclass
class SceneRun:
    """Everything the demo computed for one scene."""

    name: str
    story: str
    units: tuple[str, str] | None
    one: object
    two: object | None
    comparison: Comparison | None
    figures: dict[str, bytes]  # file stem → PNG bytes, in display order
    captions: dict[str, str]
    t_one: float
    t_two: float
    t_figures: float
    skipped: dict[str, str] = field(default_factory=dict)  # part of the demo -> why it did not run

    @property
    def ok(self) -> bool:
        kkt_ok = self.one.kkt is None or self.one.kkt.ok
        return bool(self.one.ok and kkt_ok)


logger = logging.getLogger(__name__)


def run_scene(name: str, figures: bool = True) -> SceneRun:
    """Solve one built-in scene one-sided and two-sided, compare, draw the figures."""
    import plateqp as pq

    from .. import plotting as pl

    story, units = scene_notes(name)
    scene = scenes.load(name)
    logger.info(f"{name}: solving one-sided" + (" and two-sided" if scene.one_sided else ""))
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlateQPWarning)  # the status says it; the summary shows it
        one = pq.solve(scene, accuracy="high")
    t1 = time.perf_counter()
    two = comp = None
    skipped: dict[str, str] = {}
    later = dict(one.model.grid.not_yet_studied)  # the studies not yet run on this mesh, with why
    if "convergence" in later:
        skipped["convergence"] = later["convergence"]
    if scene.one_sided:
        two = pq.solve_bilateral(scene)
        if "comparison" in later:
            skipped["comparison"] = later["comparison"]
        else:
            comp = compare(one, two)
    for part, why in skipped.items():
        logger.info(f"{name}: {part} skipped ({why})")
    t2 = time.perf_counter()
    figs: dict[str, bytes] = {}
    caps: dict[str, str] = {}
    if figures:
        logger.info(f"{name}: drawing figures")
        secs = pl.default_sections(one)

        def put(stem, caption, make):
            if stem not in FIGURES:  # output_files must know every file the demo may write
                raise ValueError(f"figure {stem!r} is not in demo.FIGURES")
            fig = make()
            figs[f"{name}-{stem}"] = pl.png_bytes(fig, dpi=DPI)
            caps[f"{name}-{stem}"] = caption

        mesh = one.model.grid.caption(scene.mesh.element)
        if two is not None:
            put("mesh", f"The {mesh} and the supports: filled where in contact, hollow where lifted off; "
                "heaved ▲ / settled ▼; reactions of the supports in contact; the numbered section lines.",
                lambda: pl.plot_mesh(one, units, sections=secs))
            put("surface", "Axonometric view of the deflection: one-sided coloured, two-sided the cells' edges "
                "(w positive down, drawn downward).", lambda: pl.plot_deflection_surface(one, two, units))
            put("contours", "Contour lines of w: one-sided (left) and two-sided (right), on the same levels.",
                lambda: pl.plot_deflection_contours(one, two, units))
            put("sections", "Deflection along the sections drawn on the mesh: solid one-sided, dashed two-sided.",
                lambda: pl.plot_sections(one, two, secs, units))
        else:
            put("mesh", f"The {mesh}, the two-sided supports and the numbered section lines.",
                lambda: pl.plot_mesh(one, units, sections=secs))
            put("surface", "Axonometric view of the deflection (w positive down, drawn downward).",
                lambda: pl.plot_deflection_surface(one, None, units))
            put("contours", "Contour lines of w.", lambda: pl.plot_deflection_contours(one, None, units))
            put("sections", "Deflection along the sections drawn on the mesh.",
                lambda: pl.plot_sections(one, None, secs, units))
        if two is not None:
            put("difference", "One-sided minus two-sided deflection, with the nodes of the contact zone (green) "
                "and of the lift-off zone (orange)" + (" used in the statements above." if comp is not None else "."),
                lambda: pl.plot_difference(one, two, units, zones=zones(one)))
        put("sigma1", "Principal stress σ1 on the bottom face" + (": one-sided (left) and two-sided (right), "
            "same colour scale." if two is not None else "."), lambda: pl.plot_principal_stress(one, two, units))
        if scene.supports:
            put("reactions", "Support reactions: one-sided bars, two-sided dashed (negative: the support "
                "would have to pull the plate down).", lambda: pl.plot_reactions(one, two, units))
            conv = None if "convergence" in skipped else convergence_plot(scene, one)
            if conv is not None:
                put("convergence", conv[1], lambda: conv[0])
    t3 = time.perf_counter()
    return SceneRun(name, story, units, one, two, comp, figs, caps, t1 - t0, t2 - t1, t3 - t2, skipped)


CONVERGENCE_MESHES = (4, 8, 16, 32)
CONVERGENCE_TARGET = 0.01


def characteristic_supports(one) -> list[int]:
    """Supports whose reactions the convergence study follows (0-based): the most loaded one and
    the most loaded heaved or settled one in contact, else the least loaded one in contact (at
    the edge of the contact zone)."""
    n = len(one.scene.supports)
    R = np.asarray(one.reactions[:n])
    if n == 0:
        return []
    first = int(np.argmax(R))
    moved = [i for i, s in enumerate(one.scene.supports) if s.gap != 0 and one.active[i] and i != first]
    if moved:
        return [first, max(moved, key=lambda i: R[i])]
    rest = [int(i) for i in np.flatnonzero(np.asarray(one.active[:n])) if i != first and R[i] > 0]
    return [first] + ([min(rest, key=lambda i: R[i])] if rest else [])


def convergence_plot(scene, one):
    """The paper's convergence panels: max w and characteristic reactions under mesh halving.

    Uses :func:`plateqp.studies.convergence` on meshes 4, 8, 16, 32 (a mesh on which the
    scene cannot be built is left out). Returns (figure, caption), or None with a note on
    stderr if the study cannot run: plateqp.studies or matplotlib is not installed, or the
    study raises a :class:`~plateqp.errors.PlateQPError`. Any other exception is a bug and
    propagates.
    """
    from .. import plotting as pl
    from ..errors import PlateQPError

    # Only what is expected is caught (a missing module, a scene the study cannot take); a
    # programming error (AttributeError, TypeError, KeyError, ...) must surface, not vanish
    # into a "skipped" note.
    try:
        from ..studies import convergence
    except ModuleNotFoundError as exn:  # plateqp.studies, or a package it needs, is not installed
        logger.warning(f"{scene.name}: convergence study skipped ({type(exn).__name__}: {exn})")
        return None
    if importlib.util.find_spec("matplotlib") is None:
        logger.warning(f"{scene.name}: convergence study skipped (matplotlib is not installed)")
        return None
    idx = characteristic_supports(one)
    quantities = ["w_max"] + [f"reactions.{i}" for i in idx]
    try:
        tab = convergence(scene, meshes=CONVERGENCE_MESHES, quantities=quantities, target=CONVERGENCE_TARGET,
                          accuracy="high")
    except PlateQPError as exn:  # the scene cannot be studied on these meshes (one mesh failing is a row)
        logger.warning(f"{scene.name}: convergence study skipped ({type(exn).__name__}: {exn})")
        return None
    labels = {"w_max": "w at max |w|"}
    for k, i in enumerate(idx):
        s = scene.supports[i]
        what = ("most loaded" if k == 0 else "heaved" if s.gap < 0 else "settled" if s.gap > 0
                else "least loaded in contact")
        labels[f"reactions.{i}"] = f"R of support {i + 1}" + (f" ({what})" if what else "")
    diffs = {labels[q]: np.asarray(tab.diff[q], dtype=float) for q in quantities}
    fig = pl.plot_convergence(tab.meshes, diffs, CONVERGENCE_TARGET, ylabel="relative change when the mesh is halved",
                              title=f"{scene.name}: convergence under mesh halving")
    conv = [f"{labels[q]}: {'from ' + '×'.join(map(str, tab.converged_at[q])) if tab.converged_at[q] else 'not yet'}"
            for q in quantities]
    caption = ("Convergence under mesh halving (plateqp.studies.convergence): the relative change of each "
               f"quantity when the mesh is halved, drawn at the coarser mesh; target {CONVERGENCE_TARGET:g}. "
               "Converged (every further halving below the target): " + "; ".join(conv) + ".")
    return fig, caption


# -- entry point -----------------------------------------------------------------------------------
def names_all() -> list[str]:
    """Every name ``plateqp demo`` takes: the built-in scenes, then the studies (:data:`STUDIES`)."""
    return scenes.names() + list(STUDIES)


def _split(names: list[str] | None) -> tuple[list[str], list[str]]:
    """(scenes, studies) of ``names`` (all when None or empty); SceneError for an unknown name."""
    names = list(names) if names else names_all()
    for n in names:
        if n not in STUDIES and n not in scenes.names():
            raise SceneError(f"no built-in scene or study {n!r}; built-in scenes: {', '.join(scenes.names())}; "
                             f"studies: {', '.join(STUDIES)}")
    return [n for n in names if n not in STUDIES], [n for n in names if n in STUDIES]


def output_files(names: list[str] | None = None) -> list[str]:
    """Every file :func:`run` may write for the scenes and studies ``names`` (all when None or
    empty): ``report.html``, ``<scene>.json`` and ``<scene>-<figure>.png`` for each of
    :data:`FIGURES` (whether or not the scene draws it), ``<study>.json`` and
    ``<study>-<figure>.png`` for each figure of :data:`STUDIES`, so that a folder can be
    checked before any work.

    Raises :class:`~plateqp.errors.SceneError` for an unknown name.
    """
    sc_names, st_names = _split(names)
    return (["report.html"] + [f for n in sc_names for f in [f"{n}.json"] + [f"{n}-{stem}.png" for stem in FIGURES]]
            + [f for n in st_names for f in [f"{n}.json"] + [f"{n}-{stem}.png" for stem in STUDIES[n]]])


def run(names: list[str] | None = None, out: Path | None = None, *, study_mesh: int | None = None,
        force: bool = True) -> int:
    """Solve the built-in scenes and run the studies ``names`` (all when None or empty), print
    the summary, write the report.

    Writes ``<name>-<figure>.png``, ``<name>.json`` and ``report.html`` into ``out``
    (default ``plateqp-demo`` in the current directory). The studies "fig5" and "fig6"
    (:mod:`plateqp.demo.paper`, the source paper's figures 5 and 6) run on their scenes' own
    meshes, or on ``study_mesh`` cells per side (coarser for tests). Returns 0 when every
    one-sided result met its accuracy, else 5 (the exit code of ``plateqp solve`` for a
    missed accuracy). Raises :class:`~plateqp.errors.SceneError` for an unknown name, before
    any work. Files are written by :mod:`plateqp.io.safe`'s rules: never through a link (an
    ``out`` that is a link is refused), and over an existing file only with ``force`` (a link
    there is then replaced, not its target).
    """

    names, study_names = _split(names)  # unknown name: SceneError now, not after minutes of work
    from ..io.safe import out_folder

    out = out_folder(Path(out) if out is not None else Path.cwd() / DEFAULT_OUT, label=f"--out {out or DEFAULT_OUT}")
    t0 = time.perf_counter()
    figures = importlib.util.find_spec("matplotlib") is not None
    if not figures:
        logger.warning("matplotlib is not installed (pip install 'plateqp[plot]'): the report will have no figures")
    runs, studies = [], []
    with Progress(len(names) + len(study_names), "demo") as bar:
        for n in names:
            bar.describe(f"demo: {n}")
            runs.append(run_scene(n, figures=figures))
            bar.update()
        for n in study_names:
            bar.describe(f"demo: {n}")
            logger.info(f"{n}: {TITLES[n]}")
            studies.append(run_study(n, figures=figures, mesh=study_mesh, dpi=DPI))
            bar.update()
    table = format_table([summary_row(r) for r in runs]) if runs else ""
    if table:
        print(table)
    if any(r.comparison is not None for r in runs):
        print("\ntwo-sided comparison (the source paper's statements, measured on these scenes):")
        for r in runs:
            if r.comparison is not None:
                print(f"  {r.name}:")
                for line in r.comparison.lines(r.units):
                    print(f"    {line}")
    for r in runs:
        for part, why in r.skipped.items():
            print(f"{r.name}: {part} skipped: {why}")
    for st in studies:
        print(f"\n{st.name}: {st.title}")
        for line in st.lines:
            print(f"  {line}")
        for line in st.table.splitlines():
            print(f"  {line}")
    write_files(out, runs, studies, table, force=force)
    n_png = sum(len(r.figures) for r in runs) + sum(len(st.figures) for st in studies)
    print(f"\nwrote {n_png} figures, {len(runs) + len(studies)} JSON files and report.html to {out}"
          f" ({time.perf_counter() - t0:.1f} s)")
    return 0 if all(r.ok for r in runs) and all(st.ok for st in studies) else 5

