"""The summary table and the self-contained HTML report of ``plateqp demo``.

:func:`summary_row` and :func:`format_table` make the plain-text summary the demo prints (one
line per scene); :func:`report_html` makes ``report.html``: the summary, the source paper's
statements measured on the scenes (with the normalisations written out), per scene its story,
facts, statements and figures, and per study (the paper's figures 5 and 6) its words and
figures (PNG embedded as base64, so the file stands alone).

The functions read the demo's per-scene runs (:class:`plateqp.demo.SceneRun`: ``name``,
``story``, ``units``, ``one``, ``two``, ``comparison``, ``figures``, ``captions``, the
times and ``skipped``: the parts that did not run on the scene, with the reason, shown in the report) and study runs (:class:`plateqp.demo.paper.StudyRun`) by their attributes; this module
imports neither the demo nor matplotlib.
"""

from __future__ import annotations

import base64
import html
import json
import math
import re
import time
from dataclasses import asdict

import numpy as np

# -- the summary -----------------------------------------------------------------------------------
HEADER = ("scene", "contact", "w one-sided", "w two-sided", "max sigma1", "KKT", "t one", "t two", "t figs",
          "units")


def summary_row(r) -> tuple[str, ...]:
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


def report_html(runs: list, table: str, studies: list = ()) -> str:
    """The self-contained HTML report (images embedded as base64 PNG).

    ``studies``: the demo's study runs (:class:`plateqp.demo.paper.StudyRun`: ``name``,
    ``title``, ``story``, ``lines``, ``figures``, ``captions``), each a section after the scenes.
    """
    import plateqp as pq

    e = html.escape
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>plateqp demo</title>"
             f"<style>{_CSS}</style></head><body>",
             "<h1>plateqp demo: plates on one-sided supports, heave and settlement</h1>",
             "<p>Support numbers are 1-based (scene order), in the text, the tables and the figures.</p>",
             f"<p>plateqp {e(pq.__version__)}, {e(time.strftime('%Y-%m-%d %H:%M'))}. Each scene is solved with "
             "one-sided supports (<code>pq.solve(scene, accuracy='high')</code>) and, as in the source paper "
             "(Lovtsov &amp; Dolgachev 2012, figures 3–6), with every support made two-sided "
             "(<code>pq.solve_bilateral(scene)</code>).</p>",
             "<p>Conventions: w is positive <b>downward</b> (the direction of the load), so every deflection axis "
             "points down; a gap g0 &lt; 0 is heave (the support pushed up into the plate), g0 &gt; 0 settlement; "
             "reactions R ≥ 0 push the plate up. Stresses are those of the bottom face (tension &gt; 0).</p>",
             ]
    if runs:
        parts += ["<h2>Summary</h2>",
                  "<p>w: the signed deflection at the node of largest |w|; max sigma1: largest principal stress of "
                  "the one-sided solution; KKT: the one-sided result meets the 'high' accuracy; times in seconds "
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
            "the zone's nodes, also as a fraction of the largest |w| of either solution.</p>"
            "<p><b>The paper's “at most 6 %”</b> (sections 2 and 4): the section lines are the rows of supports, "
            "numbered 1, 2, … from y = 0 as on the mesh figure; the nodes counted are the contact-zone nodes on "
            "sections 2 and 4; their max |w<sub>one</sub> − w<sub>two</sub>| is divided by the largest "
            "|w<sub>two</sub>| along sections 2 and 4 (the headline; the paper compares its section curves). The "
            "same difference divided by the largest |w| over the plate, or node by node by |w<sub>two</sub>| at the "
            f"nodes where |w<sub>two</sub>| is at least {100 * statements[0].comparison.sections_nodewise_floor:.0f} % "
            "of its largest value on sections 2 and 4 (a ratio to "
            "|w<sub>two</sub>| alone is unbounded where w<sub>two</sub> crosses zero, as it does at every rigid "
            "support without a gap), gives other numbers: all three are listed under each scene.</p>"
            "<p><b>σ1 near the load</b> (the paper: 2 %) is compared at a fixed distance: the mean σ1 at the four "
            "points (x ± r, y), (x, y ± r) around the point load, r = half the support spacing, relative difference "
            "(σ1<sub>one</sub> − σ1<sub>two</sub>) / |σ1<sub>two</sub>|. <span class='bad'>Warning:</span> the peak "
            "σ1 at a point load does not converge under mesh refinement (it grows like log(1/h): 101, 135, 166, "
            "196 kgf/cm² on the heave scene at 8, 16, 32, 64 cells per side); it is shown for reference only.</p>")
        rows = ["<tr><th>scene</th><th>in contact</th><th>contact zone: max |Δw|</th>"
                "<th>lift-off zone: max |Δw|</th><th>sections 2 and 4, contact zone: max |Δw| / max |w<sub>two</sub>|"
                "</th><th>σ1 at r from the load: one / two-sided</th><th>peak σ1 at the load (does not converge)</th>"
                "<th>two-sided tension</th></tr>"]
        for r in statements:
            c = r.comparison
            L = r.units[0] if r.units else ""
            F = r.units[1] if r.units else ""
            S = f" {F}/{L}²" if r.units else ""

            def zone(nodes, dw, rel, L=L):
                return "no nodes" if not nodes else f"{dw:.3g} {e(L)} ({100 * rel:.1f} %), {nodes} nodes"

            s1 = (f"{c.s1_one:.4g} / {c.s1_two:.4g}{e(S)} ({100 * c.s1_rel:+.1f} %), within {c.s1_radius:g} {e(L)}"
                  if math.isfinite(c.s1_one) else "no point load")
            ring = (f"{c.s1_ring_one:.4g} / {c.s1_ring_two:.4g}{e(S)} ({100 * c.s1_ring_rel:+.1f} %), r = "
                    f"{c.s1_ring_radius:g} {e(L)}" if math.isfinite(c.s1_ring_one) else "no point load")
            sec = (f"{100 * c.sections_rel:.1f} % ({c.sections_dw:.3g} {e(L)}, {c.sections_nodes} nodes)"
                   if c.sections_nodes else "no nodes")
            ten = (f"{len(c.tension_supports)} supports, min R = {c.min_R_two:.4g} {e(F)}" if c.tension_supports
                   else "none")
            rows.append(f"<tr><td>{e(r.name)}</td><td>{c.n_contact} of {c.n_supports}</td>"
                        f"<td>{zone(c.contact_nodes, c.dw_contact, c.dw_contact_rel)}</td>"
                        f"<td>{zone(c.liftoff_nodes, c.dw_liftoff, c.dw_liftoff_rel)}</td><td>{sec}</td>"
                        f"<td>{ring}</td><td>{s1}</td>"
                        f"<td>{ten}</td></tr>")
        parts.append("<table>" + "".join(rows) + "</table>")
    for r in runs:
        parts.append(f"<h2 id='{e(r.name)}'>Scene “{e(r.name)}”</h2>")
        if r.story:
            parts.append(f"<pre class='story'>{e(r.story)}</pre>")
        parts.append(_scene_facts(r))
        for part, why in getattr(r, "skipped", {}).items():
            parts.append(f"<p class='skipped'><b>{e(part)} skipped</b>: {e(why)}.</p>")
        if r.comparison is not None:
            parts.append("<ul>" + "".join(f"<li>{e(s)}</li>" for s in r.comparison.lines(r.units)) + "</ul>")
        for stem, png in r.figures.items():
            parts.append(f"<figure>{_img(png, stem)}<figcaption><b>{e(stem)}.png</b>: {e(r.captions[stem])}"
                         "</figcaption></figure>")
    for st in studies:
        parts.append(f"<h2 id='{e(st.name)}'>Study “{e(st.name)}”: {e(st.title)}</h2>")
        parts.append(f"<pre class='story'>{e(st.story)}</pre>")
        parts.append("<ul>" + "".join(f"<li>{e(s)}</li>" for s in st.lines) + "</ul>")
        if getattr(st, "table", ""):
            parts.append(f"<pre>{e(st.table)}</pre>")
        for stem, png in st.figures.items():
            parts.append(f"<figure>{_img(png, stem)}<figcaption><b>{e(stem)}.png</b>: {e(st.captions[stem])}"
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
    cells = re.split(r" {2,}", line.strip())
    return cells + [""] * (len(HEADER) - len(cells))


def _scene_facts(r) -> str:
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
        elif ld.region is None:
            loads.append(f"patch q = {ld.q:g} on [{ld.x0:g}, {ld.x1:g}] × [{ld.y0:g}, {ld.y1:g}]")
        else:
            loads.append(f"patch q = {ld.q:g} on {', '.join(f'{k} {v}' for k, v in ld.region.items())}"
                         if isinstance(ld.region, dict) else f"patch q = {ld.q:g} on {ld.region}")
    n = len(sc.supports)
    Eu, Du = (f" {F}/{L}²", f" {F}·{L}") if r.units else ("", "")
    shape = ", ".join(f"{k} {v}" for k, v in (p.shape or {}).items()) or f"{p.a:g} × {p.b:g}"
    plan = f"plate {shape} {L}" + (f" with {len(sc.holes)} hole(s)" if sc.holes else "")
    mesh_txt = r.one.model.grid.summary_text(sc.mesh.element, L)
    facts = [f"{plan}, h = {p.h:g} {L}, E = {p.E:g}{Eu}, ν = {p.nu:g}, "
             f"D = {p.D:.4g}{Du}; {mesh_txt}",
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


# -- the files ---------------------------------------------------------------------------------------
def _json_safe(d):
    if isinstance(d, dict):
        return {k: _json_safe(v) for k, v in d.items()}
    if isinstance(d, list):
        return [_json_safe(v) for v in d]
    if isinstance(d, float) and not math.isfinite(d):
        return None
    return d


def write_files(out, runs, studies, table: str, force: bool = True) -> None:
    """Write the demo's figures (``<stem>.png``), one JSON file per scene and study and
    ``report.html`` into the folder ``out``, by :mod:`plateqp.io.safe`'s rules (no link
    followed; an existing file replaced only with ``force``)."""
    from ..io.safe import write

    def put(name: str, data) -> None:
        write(out / name, data, force=force, label=f"--out {out}", root=out)

    for r in runs:
        for stem, png in r.figures.items():
            put(f"{stem}.png", png)
        rep = {"one_sided": r.one.to_dict()}
        if r.two is not None:
            rep["two_sided"] = r.two.to_dict()
        if r.comparison is not None:
            rep["comparison"] = _json_safe(asdict(r.comparison))
        if r.skipped:
            rep["skipped"] = dict(r.skipped)
        put(f"{r.name}.json", json.dumps(rep, indent=1))
    for st in studies:
        for stem, png in st.figures.items():
            put(f"{stem}.png", png)
        put(f"{st.name}.json", json.dumps(_json_safe({"lines": st.lines, **st.data}), indent=1))
    put("report.html", report_html(runs, table, studies))
