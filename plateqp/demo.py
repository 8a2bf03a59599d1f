"""``plateqp demo``: solve the built-in scenes, compare with two-sided support, write a report.

For each scene: the one-sided solve (:func:`plateqp.solve`, accuracy "high") and, when the
scene has one-sided supports, the source paper's comparison (:func:`plateqp.solve_bilateral`:
every support made two-sided). Prints one summary line per scene to stdout, the paper's
quantitative statements for our scenes (:func:`compare`), and writes the figures (PNG), one
JSON file per scene and a self-contained ``report.html`` (figures embedded as base64 PNG)
into the output folder. Progress goes to stderr.

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

*σ1 near the load*: the largest principal stress σ1 (bottom face, nodal values) within the
radius r of the largest point load, r = max(half the support spacing, two mesh cells), in each
solution; the relative difference (σ1_one − σ1_two) / |σ1_two|.
"""

from __future__ import annotations

import base64
import html
import json
import math
import sys
import time
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from . import scenes
from .errors import PlateQPWarning

DEFAULT_OUT = "plateqp-demo"
DPI = 100
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
def support_spacing(xy: np.ndarray) -> float:
    """Median distance from a support to its nearest neighbour (inf for fewer than two)."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    if xy.shape[0] < 2:
        return math.inf
    d = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
    np.fill_diagonal(d, np.inf)
    return float(np.median(d.min(axis=1)))


def zones(result) -> np.ndarray:
    """Per plate node, (ny+1, nx+1): +1 contact zone, −1 lift-off zone, 0 neither (see module doc)."""
    sc = result.scene
    g = result.model.grid
    n = len(sc.supports)
    out = np.zeros((g.ny + 1, g.nx + 1), dtype=int)
    if n == 0 or result.active.size < n:
        return out
    xy = np.array([[s.x, s.y] for s in sc.supports], dtype=float)
    active = np.asarray(result.active[:n], dtype=bool)
    spacing = support_spacing(xy)
    if not math.isfinite(spacing):
        spacing = max(g.a, g.b)
    nodes = g.node_xy()
    d = np.hypot(nodes[:, None, 0] - xy[None, :, 0], nodes[:, None, 1] - xy[None, :, 1])
    dmin = d.min(axis=1)
    tol = 1e-9 * max(g.a, g.b)
    nearest = d <= dmin[:, None] + tol
    all_on = np.all(~nearest | active[None, :], axis=1)
    all_off = np.all(~nearest | ~active[None, :], axis=1)
    z = np.where(all_on, 1, np.where(all_off, -1, 0))
    z[dmin > spacing + tol] = 0
    z[~g.node_mask()] = 0
    return z.reshape(g.ny + 1, g.nx + 1)


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
        if math.isfinite(self.s1_one):
            out.append(f"max sigma1 within {self.s1_radius:g}{Lu} of the load: {self.s1_one:.4g}{Su} one-sided,"
                       f" {self.s1_two:.4g}{Su} two-sided ({100 * self.s1_rel:+.1f} %)")
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
    w1, w2 = one.w_nodes(), two.w_nodes()
    on_plate = np.isfinite(w1) & np.isfinite(w2)
    dw = np.where(on_plate, np.abs(w1 - w2), 0.0)
    w_ref = float(max(np.abs(w1[on_plate]).max(initial=0.0), np.abs(w2[on_plate]).max(initial=0.0)))
    z = zones(one)

    def zone(val):
        sel = (z == val) & on_plate
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
        nodes = g.node_xy()
        near = (np.hypot(nodes[:, 0] - ld.x, nodes[:, 1] - ld.y) <= r * (1 + 1e-9)).reshape(g.ny + 1, g.nx + 1)
        S1, S2 = one.nodal("s1"), two.nodal("s1")
        near &= np.isfinite(S1) & np.isfinite(S2)
        if near.any():
            s1_one, s1_two = float(S1[near].max()), float(S2[near].max())
            s1_rel = (s1_one - s1_two) / abs(s1_two) if s1_two != 0 else (0.0 if s1_one == 0 else float("inf"))
    R2 = np.asarray(two.reactions[:n], dtype=float)
    rscale = max(np.abs(R2).max(initial=0.0), 1e-300)
    tension = [int(i) + 1 for i in np.flatnonzero(R2 < -1e-9 * rscale)]
    return Comparison(
        n_supports=n, n_contact=int(np.asarray(one.active[:n]).sum()), spacing=spacing, w_ref=w_ref,
        contact_nodes=nc, liftoff_nodes=nl, dw_contact=dwc, dw_contact_rel=dwc_rel, dw_liftoff=dwl,
        dw_liftoff_rel=dwl_rel, dw_max=float(dw.max(initial=0.0)), s1_radius=float(r), s1_one=s1_one,
        s1_two=s1_two, s1_rel=s1_rel, tension_supports=tension,
        min_R_two=float(R2.min()) if R2.size else float("nan"))


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

    @property
    def ok(self) -> bool:
        kkt_ok = self.one.kkt is None or self.one.kkt.ok
        return bool(self.one.ok and kkt_ok)


def _progress(msg: str) -> None:
    print(f"plateqp demo: {msg}", file=sys.stderr, flush=True)


def run_scene(name: str, figures: bool = True) -> SceneRun:
    """Solve one built-in scene one-sided and two-sided, compare, draw the figures."""
    import plateqp as pq

    from . import plotting as pl

    story, units = scene_notes(name)
    scene = scenes.load(name)
    _progress(f"{name}: solving one-sided" + (" and two-sided" if scene.one_sided else ""))
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlateQPWarning)  # the status says it; the summary shows it
        one = pq.solve(scene, accuracy="high")
    t1 = time.perf_counter()
    two = comp = None
    if scene.one_sided:
        two = pq.solve_bilateral(scene)
        comp = compare(one, two)
    t2 = time.perf_counter()
    figs: dict[str, bytes] = {}
    caps: dict[str, str] = {}
    if figures:
        _progress(f"{name}: drawing figures")
        secs = pl.default_sections(one)

        def put(stem, caption, make):
            fig = make()
            figs[f"{name}-{stem}"] = pl.png_bytes(fig, dpi=DPI)
            caps[f"{name}-{stem}"] = caption

        mesh = f"{scene.mesh.nx} × {scene.mesh.ny} mesh"
        if two is not None:
            put("mesh", f"The {mesh} and the supports: filled where in contact, hollow where lifted off; "
                "heaved ▲ / settled ▼; reactions of the supports in contact; the numbered section lines.",
                lambda: pl.plot_mesh(one, units, sections=secs))
            put("surface", "Axonometric view of the deflection: one-sided coloured, two-sided wire frame "
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
                "and of the lift-off zone (orange) used in the statements above.",
                lambda: pl.plot_difference(one, two, units, zones=zones(one)))
        put("sigma1", "Principal stress σ1 on the bottom face" + (": one-sided (left) and two-sided (right), "
            "same colour scale." if two is not None else "."), lambda: pl.plot_principal_stress(one, two, units))
        if scene.supports:
            put("reactions", "Support reactions: one-sided bars, two-sided dashed (negative: the support "
                "would have to pull the plate down).", lambda: pl.plot_reactions(one, two, units))
            conv = convergence_plot(scene, one)
            if conv is not None:
                fig, caption = conv
                figs[f"{name}-convergence"] = pl.png_bytes(fig, dpi=DPI)
                caps[f"{name}-convergence"] = caption
    t3 = time.perf_counter()
    return SceneRun(name, story, units, one, two, comp, figs, caps, t1 - t0, t2 - t1, t3 - t2)


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
    stderr if the study cannot run.
    """
    from . import plotting as pl
    from .errors import PlateQPError

    try:
        from .studies import convergence

        idx = characteristic_supports(one)
        quantities = ["w_max"] + [f"reactions.{i}" for i in idx]
        tab = convergence(scene, meshes=CONVERGENCE_MESHES, quantities=quantities, target=CONVERGENCE_TARGET,
                          accuracy="high")
        labels = {"w_max": "w at max |w|"}
        for k, i in enumerate(idx):
            s = scene.supports[i]
            what = ("most loaded" if k == 0 else "heaved" if s.gap < 0 else "settled" if s.gap > 0
                    else "least loaded in contact")
            labels[f"reactions.{i}"] = f"R of support {i + 1}" + (f" ({what})" if what else "")
        diffs = {labels[q]: np.asarray(tab.diff[q], dtype=float) for q in quantities}
        fig = pl.plot_convergence(tab.meshes, diffs, CONVERGENCE_TARGET,
                                  ylabel="relative change when the mesh is halved",
                                  title=f"{scene.name}: convergence under mesh halving")
    except (ImportError, AttributeError, TypeError, KeyError, ValueError, PlateQPError) as exn:
        _progress(f"{scene.name}: convergence study skipped ({type(exn).__name__}: {exn})")
        return None
    conv = [f"{labels[q]}: {'from ' + '×'.join(map(str, tab.converged_at[q])) if tab.converged_at[q] else 'not yet'}"
            for q in quantities]
    caption = ("Convergence under mesh halving (plateqp.studies.convergence): the relative change of each "
               f"quantity when the mesh is halved, drawn at the coarser mesh; target {CONVERGENCE_TARGET:g}. "
               "Converged (every further halving below the target): " + "; ".join(conv) + ".")
    return fig, caption


# -- the summary -----------------------------------------------------------------------------------
HEADER = ("scene", "contact", "w one-sided", "w two-sided", "max sigma1", "KKT", "t one", "t two", "t figs",
          "units")


def summary_row(r: SceneRun) -> tuple[str, ...]:
    """One summary line: w is the signed value at the node of largest |w|; times in seconds."""
    one, two = r.one, r.two
    n = len(one.scene.supports)
    contact = f"{int(np.asarray(one.active[:n]).sum())}/{n}" if n else "-"
    w1 = one.w_max()[0]
    s1 = float(np.nanmax(one.nodal("s1")))
    kkt = "-" if one.kkt is None else ("ok" if one.kkt.ok else "NOT MET")
    if not one.ok:
        kkt += f" ({one.status.value})"
    return (r.name, contact, f"{w1:+.4g}", f"{two.w_max()[0]:+.4g}" if two is not None else "-", f"{s1:.4g}", kkt,
            f"{r.t_one:.2f}", f"{r.t_two:.2f}" if two is not None else "-", f"{r.t_figures:.2f}",
            ", ".join(r.units) if r.units else "-")


def format_table(rows: list[tuple[str, ...]]) -> str:
    rows = [HEADER] + rows
    widths = [max(len(row[k]) for row in rows) for k in range(len(HEADER))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


# -- the report ------------------------------------------------------------------------------------
_CSS = """
body { font-family: system-ui, -apple-system, Segoe UI, sans-serif; max-width: 1150px; margin: 2em auto;
       padding: 0 1em; color: #222; line-height: 1.45; }
h1 { font-size: 1.6em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: .2em; margin-top: 2em; }
table { border-collapse: collapse; margin: .8em 0; font-size: .92em; }
th, td { border: 1px solid #ccc; padding: .25em .6em; text-align: left; }
th { background: #f2f2f2; }
pre.story { background: #f8f8f4; border-left: 3px solid #bba; padding: .6em .9em; white-space: pre-wrap; }
figure { margin: 1.2em 0; } figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { font-size: .9em; color: #555; }
.bad { color: #b00; font-weight: bold; }
"""


def _img(png: bytes, alt: str) -> str:
    data = base64.b64encode(png).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="{html.escape(alt)}">'


def report_html(runs: list[SceneRun], table: str) -> str:
    """The self-contained HTML report (images embedded as base64 PNG)."""
    import plateqp as pq

    e = html.escape
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>plateqp demo</title>"
             f"<style>{_CSS}</style></head><body>",
             "<h1>plateqp demo: plates on one-sided supports, heave and settlement</h1>",
             f"<p>plateqp {e(pq.__version__)}, {e(time.strftime('%Y-%m-%d %H:%M'))}. Each scene is solved with "
             "one-sided supports (<code>pq.solve(scene, accuracy='high')</code>) and, as in the source paper "
             "(Lovtsov &amp; Dolgachev 2012, figures 3–6), with every support made two-sided "
             "(<code>pq.solve_bilateral(scene)</code>).</p>",
             "<p>Conventions: w is positive <b>downward</b> (the direction of the load), so every deflection axis "
             "points down; a gap g0 &lt; 0 is heave (the support pushed up into the plate), g0 &gt; 0 settlement; "
             "reactions R ≥ 0 push the plate up. Stresses are those of the bottom face (tension &gt; 0).</p>",
             "<h2>Summary</h2>",
             "<p>w: the signed deflection at the node of largest |w|; max sigma1: largest principal stress of the "
             "one-sided solution; KKT: the one-sided result meets the 'high' accuracy; times in seconds "
             "(one-sided solve, two-sided solve, figures).</p>",
             _table_html(table)]
    statements = [r for r in runs if r.comparison is not None]
    if statements:
        parts.append("<h2>The source paper's statements, measured on our scenes</h2>")
        parts.append(
            "<p>The paper (figures 3–4) finds large deflection differences between one- and two-sided support in "
            "the lift-off zones, at most 6 % in the contact zone, and σ1 fields that almost coincide at their "
            "maxima (2 % near the point load). Here: each plate node belongs to the tributary area of its nearest "
            "support(s) if that support is at most one support spacing away; the node is in the <b>contact zone</b> "
            "if all its nearest supports are in contact (one-sided solution), in the <b>lift-off zone</b> if none "
            "is, otherwise in neither. The difference is max |w<sub>one-sided</sub> − w<sub>two-sided</sub>| over "
            "the zone's nodes, also as a fraction of the largest |w| of either solution. σ1 near the load: the "
            "largest nodal σ1 within r of the point load, r = max(half the support spacing, two mesh cells), "
            "relative difference (σ1<sub>one</sub> − σ1<sub>two</sub>) / |σ1<sub>two</sub>|.</p>")
        rows = ["<tr><th>scene</th><th>in contact</th><th>contact zone: max |Δw|</th>"
                "<th>lift-off zone: max |Δw|</th><th>max σ1 near the load: one / two-sided</th>"
                "<th>two-sided tension</th></tr>"]
        for r in statements:
            c = r.comparison
            L = r.units[0] if r.units else ""
            F = r.units[1] if r.units else ""
            S = f" {F}/{L}²" if r.units else ""

            def zone(nodes, dw, rel, L=L):
                return "no nodes" if not nodes else f"{dw:.3g} {e(L)} ({100 * rel:.1f} %), {nodes} nodes"

            s1 = (f"{c.s1_one:.4g} / {c.s1_two:.4g}{e(S)} ({100 * c.s1_rel:+.1f} %), r = {c.s1_radius:g} {e(L)}"
                  if math.isfinite(c.s1_one) else "no point load")
            ten = (f"{len(c.tension_supports)} supports, min R = {c.min_R_two:.4g} {e(F)}" if c.tension_supports
                   else "none")
            rows.append(f"<tr><td>{e(r.name)}</td><td>{c.n_contact} of {c.n_supports}</td>"
                        f"<td>{zone(c.contact_nodes, c.dw_contact, c.dw_contact_rel)}</td>"
                        f"<td>{zone(c.liftoff_nodes, c.dw_liftoff, c.dw_liftoff_rel)}</td><td>{s1}</td>"
                        f"<td>{ten}</td></tr>")
        parts.append("<table>" + "".join(rows) + "</table>")
    for r in runs:
        parts.append(f"<h2 id='{e(r.name)}'>Scene “{e(r.name)}”</h2>")
        if r.story:
            parts.append(f"<pre class='story'>{e(r.story)}</pre>")
        parts.append(_scene_facts(r))
        if r.comparison is not None:
            parts.append("<ul>" + "".join(f"<li>{e(s)}</li>" for s in r.comparison.lines(r.units)) + "</ul>")
        for stem, png in r.figures.items():
            parts.append(f"<figure>{_img(png, stem)}<figcaption><b>{e(stem)}.png</b>: {e(r.captions[stem])}"
                         "</figcaption></figure>")
    parts.append("</body></html>")
    return "\n".join(parts)


def _table_html(table: str) -> str:
    lines = table.splitlines()
    rows = [HEADER]
    for line in lines[2:]:
        rows.append(tuple(_split_row(line)))
    out = ["<table><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in HEADER) + "</tr>"]
    for row in rows[1:]:
        cells = []
        for h, v in zip(HEADER, row):
            cls = " class='bad'" if (h == "KKT" and v not in ("ok", "-")) else ""
            cells.append(f"<td{cls}>{html.escape(v)}</td>")
        out.append("<tr>" + "".join(cells) + "</tr>")
    return "".join(out) + "</table>"


def _split_row(line: str) -> list[str]:
    # columns are separated by two or more spaces (values never contain two spaces)
    import re

    cells = re.split(r" {2,}", line.strip())
    return cells + [""] * (len(HEADER) - len(cells))


def _scene_facts(r: SceneRun) -> str:
    sc = r.one.scene
    p = sc.plate
    L = r.units[0] if r.units else ""
    F = r.units[1] if r.units else ""
    e = html.escape
    loads = []
    for ld in sc.loads:
        if ld.type == "point":
            loads.append(f"point P = {ld.P:g} {F} at ({ld.x:g}, {ld.y:g})")
        elif ld.type == "uniform":
            loads.append(f"uniform q = {ld.q:g} {F}/{L}²" if r.units else f"uniform q = {ld.q:g}")
        else:
            loads.append(f"patch q = {ld.q:g} on [{ld.x0:g}, {ld.x1:g}] × [{ld.y0:g}, {ld.y1:g}]")
    n = len(sc.supports)
    Eu, Du = (f" {F}/{L}²", f" {F}·{L}") if r.units else ("", "")
    facts = [f"plate {p.a:g} × {p.b:g} {L}, h = {p.h:g} {L}, E = {p.E:g}{Eu}, ν = {p.nu:g}, "
             f"D = {p.D:.4g}{Du}; mesh {sc.mesh.nx} × {sc.mesh.ny} {sc.mesh.element.upper()}",
             "loads: " + "; ".join(loads)]
    if n:
        heaved = [i + 1 for i, s in enumerate(sc.supports) if s.gap < 0]
        settled = [i + 1 for i, s in enumerate(sc.supports) if s.gap > 0]
        elastic = sum(not s.rigid for s in sc.supports)
        on = np.asarray(r.one.active[:n], dtype=bool)
        facts.append(f"{n} one-sided supports ({elastic} elastic, {n - elastic} rigid); heaved: "
                     f"{_ids(heaved)}; settled: {_ids(settled)}")
        facts.append(f"in contact ({int(on.sum())}): {_ids(np.flatnonzero(on) + 1)}; lifted off ({int((~on).sum())}): "
                     f"{_ids(np.flatnonzero(~on) + 1)}")
        facts.append(f"sum of reactions {r.one.reactions.sum():.6g} {F}; status {r.one.status.value} "
                     f"({r.one.backend}, {r.one.formulation}); worst KKT residual "
                     f"{r.one.kkt.worst:.1e} (tol {r.one.kkt.tol:.0e})" if r.one.kkt is not None else "")
    else:
        facts.append(f"two-sided only (no one-sided supports): status {r.one.status.value}")
    return "<ul>" + "".join(f"<li>{e(f)}</li>" for f in facts if f) + "</ul>"


def _ids(ids) -> str:
    ids = [int(i) for i in ids]
    return ", ".join(map(str, ids)) if ids else "none"


# -- entry point -----------------------------------------------------------------------------------
def run(names: list[str] | None = None, out: Path | None = None) -> int:
    """Solve the built-in scenes ``names`` (all when None or empty), print the summary, write the report.

    Writes ``<scene>-<figure>.png``, ``<scene>.json`` and ``report.html`` into ``out``
    (default ``plateqp-demo`` in the current directory). Returns 0 when every one-sided result
    met its accuracy, else 5 (the exit code of ``plateqp solve`` for a missed accuracy).
    Raises :class:`~plateqp.errors.SceneError` for an unknown scene name, before any work.
    """

    names = list(names) if names else scenes.names()
    for n in names:
        scenes.path(n)  # unknown name: SceneError now, not after minutes of work
    out = Path(out) if out is not None else Path.cwd() / DEFAULT_OUT
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    import importlib.util

    figures = importlib.util.find_spec("matplotlib") is not None
    if not figures:
        _progress("matplotlib is not installed (pip install 'plateqp[plot]'): the report will have no figures")
    runs = [run_scene(n, figures=figures) for n in names]
    table = format_table([summary_row(r) for r in runs])
    print(table)
    if any(r.comparison is not None for r in runs):
        print("\ntwo-sided comparison (the source paper's statements, measured on these scenes):")
        for r in runs:
            if r.comparison is not None:
                print(f"  {r.name}:")
                for line in r.comparison.lines(r.units):
                    print(f"    {line}")
    for r in runs:
        for stem, png in r.figures.items():
            (out / f"{stem}.png").write_bytes(png)
        rep = {"one_sided": r.one.to_dict()}
        if r.two is not None:
            rep["two_sided"] = r.two.to_dict()
            rep["comparison"] = _json_safe(asdict(r.comparison))
        (out / f"{r.name}.json").write_text(json.dumps(rep, indent=1))
    (out / "report.html").write_text(report_html(runs, table), encoding="utf-8")
    n_png = sum(len(r.figures) for r in runs)
    print(f"\nwrote {n_png} figures, {len(runs)} JSON files and report.html to {out}"
          f" ({time.perf_counter() - t0:.1f} s)")
    return 0 if all(r.ok for r in runs) else 5


def _json_safe(d):
    if isinstance(d, dict):
        return {k: _json_safe(v) for k, v in d.items()}
    if isinstance(d, list):
        return [_json_safe(v) for v in d]
    if isinstance(d, float) and not math.isfinite(d):
        return None
    return d
