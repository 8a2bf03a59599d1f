"""The scene's keys: every TOML key a scene file may hold, with its type, default, unit and meaning.

The keys, types and defaults are read from the scene's dataclasses (:mod:`plateqp.model.scene`),
the very fields :meth:`~plateqp.model.scene.Scene.from_dict` accepts; the unit and the meaning of
each are :data:`WORDS` here, and a test holds the two together (a field without words, or words
for a field that is gone, fails it). The values that are tables of their own (a shape, a bed's
gap profile) are :data:`NESTED`. :func:`markdown` writes the reference the documentation shows.

Units are any consistent set: L a length, F a force (the source paper uses cm and kgf).
"""

from __future__ import annotations

from dataclasses import MISSING, fields

from . import scene as S

#: (TOML table, dataclass, how it is written) in the order a scene file reads.
TABLES: list[tuple[str, type, str]] = [
    ("plate", S.Plate, "[plate]"),
    ("mesh", S.MeshSpec, "[mesh]"),
    ("edges.NAME", S.Edge, "[edges] NAME = \"kind\", or NAME = { kind = ..., w = ..., slope = ... }"),
    ("openings", S.Opening, "[[openings]]"),
    ("pins", S.Pin, "[[pins]]"),
    ("loads (uniform)", S.UniformLoad, "[[loads]] type = \"uniform\""),
    ("loads (patch)", S.PatchLoad, "[[loads]] type = \"patch\""),
    ("loads (point)", S.PointLoad, "[[loads]] type = \"point\""),
    ("supports", S.Support, "[[supports]]"),
    ("foundation", S.Foundation, "[foundation]"),
]

#: Unit and meaning of each dataclass field, by class then field.
WORDS: dict[type, dict[str, tuple[str, str]]] = {
    S.Plate: {
        "a": ("L", "side along x: a rectangular plate occupies [0, a] × [0, b]"),
        "b": ("L", "side along y"),
        "h": ("L", "thickness"),
        "E": ("F/L²", "Young's modulus"),
        "nu": ("1", "Poisson's ratio, in (−1, 0.5)"),
        "shape": ("", "a plate of any shape (triangle meshes): a polygon or a circle (see nested keys); "
                      "a, b are then unused"),
    },
    S.MeshSpec: {
        "nx": ("1", "cells along x (the rectangle grid)"),
        "ny": ("1", "cells along y"),
        "element": ("", "the plate element: \"acm\" or \"bfs\" (rectangles, the grid), \"dkt\" (triangles, gmsh)"),
        "size": ("L", "target element size h on triangle meshes (default: the plate's size / 16)"),
        "symmetry": ("", "\"x\", \"y\" or \"xy\": a mesh that is its own mirror image in the plate's centre "
                         "line x = xc, y = yc or both (triangles: one part meshed and mirrored); the scene must be "
                         "symmetric; \"none\" or absent: no such demand"),
    },
    S.Edge: {
        "kind": ("", "\"free\", \"simple\" (w prescribed) or \"clamped\" (w and the outward slope prescribed); "
                     "NAME: all (the outer boundary), left, right, bottom, top, outer, outer_I (a polygon's "
                     "segment I), holeK, holeK_I (a cut-out's boundary and segments)"),
        "w": ("L", "prescribed deflection along the edge (the paper's f1)"),
        "slope": ("1", "prescribed slope ∂w/∂n along a clamped edge, n the outward normal (the paper's f2)"),
    },
    S.Opening: {
        "x0": ("L", "left of the box cut out of the plate (its edges free unless named holeK)"),
        "x1": ("L", "right of the box"),
        "y0": ("L", "bottom of the box"),
        "y1": ("L", "top of the box"),
    },
    S.Pin: {
        "x": ("L", "x of a two-sided point support (a mesh node)"),
        "y": ("L", "y of the point support"),
        "w": ("L", "its prescribed deflection"),
    },
    S.UniformLoad: {"q": ("F/L²", "pressure over the whole plate, positive downward")},
    S.PatchLoad: {
        "q": ("F/L²", "pressure over the box (or the region), positive downward"),
        "x0": ("L", "left of the loaded box (the box, or region: not both)"),
        "x1": ("L", "right of the box"),
        "y0": ("L", "bottom of the box"),
        "y1": ("L", "top of the box"),
        "region": ("L", "the loaded region instead of the box: a box [x0, x1, y0, y1], "
                        "{ polygon = [[x, y], ...] } or { circle = [xc, yc, r] }"),
    },
    S.PointLoad: {
        "P": ("F", "point force, positive downward"),
        "x": ("L", "x of the force (anywhere on the plate)"),
        "y": ("L", "y of the force"),
    },
    S.Support: {
        "x": ("L", "x of a one-sided support"),
        "y": ("L", "y of the support"),
        "gap": ("L", "initial gap g0 between plate and support: > 0 settlement, < 0 heave, 0 touching"),
        "stiffness": ("F/L", "\"rigid\", or the spring stiffness c of an elastic support (R = c s)"),
    },
    S.Foundation: {
        "k": ("F/L³", "winkler, pasternak: the modulus of the soil's springs (c1)"),
        "region": ("L", "where the bed lies: the whole plate if absent, a box [x0, x1, y0, y1], "
                        "{ polygon = [[x, y], ...] } or { circle = [xc, yc, r] }"),
        "gap": ("L", "initial gap g0 of the bed: a number, or a profile table (see nested keys)"),
        "model": ("", "the soil: \"winkler\" (springs k; the default), \"pasternak\" (springs k and a shear "
                      "layer shear) or \"halfspace\" (an elastic half-space E, nu); tensionless in every model"),
        "shear": ("F/L", "pasternak: the shear layer's modulus c2 (0: Winkler's springs alone)"),
        "E": ("F/L²", "halfspace: the soil's Young's modulus"),
        "nu": ("1", "halfspace: the soil's Poisson's ratio, in (-1, 0.5]"),
    },
}

#: Keys inside values that are tables of their own: (key, type, unit, meaning).
NESTED: list[tuple[str, str, str, str]] = [
    ("name", "str", "", "the scene's name (top level; default \"scene\")"),
    ("plate.shape.polygon", "[[x, y], ...]", "L", "the outline's vertices (at least 3, simple)"),
    ("plate.shape.circle", "[xc, yc, r]", "L", "a circular plate"),
    ("holes.polygon", "[[x, y], ...]", "L", "[[holes]]: a polygonal hole (its edges free unless named holeK)"),
    ("holes.circle", "[xc, yc, r]", "L", "[[holes]]: a circular hole"),
    ("foundation.region.polygon", "[[x, y], ...]", "L", "a polygonal bed region"),
    ("foundation.region.circle", "[xc, yc, r]", "L", "a circular bed region"),
    ("loads.region.polygon", "[[x, y], ...]", "L", "a patch load over a polygon"),
    ("loads.region.circle", "[xc, yc, r]", "L", "a patch load over a disc"),
    ("foundation.gap.profile", "str", "", "\"uniform\", \"linear\", \"trough\" (settlement) or \"bump\" (heave)"),
    ("foundation.gap.g0", "float", "L", "uniform and linear profiles: the gap at the origin"),
    ("foundation.gap.gx", "float", "1", "linear profile: the gap's slope along x"),
    ("foundation.gap.gy", "float", "1", "linear profile: the gap's slope along y"),
    ("foundation.gap.x", "float", "L", "trough, bump: x of the centre of the (1 − r²/R²)² bell"),
    ("foundation.gap.y", "float", "L", "trough, bump: y of its centre"),
    ("foundation.gap.radius", "float", "L", "trough, bump: its radius R"),
    ("foundation.gap.depth", "float", "L", "trough, bump: its depth (the gap's largest magnitude)"),
]


def _plain(text: str) -> str:
    """Docstring words as Markdown: reST roles and double backticks made plain code, pipes escaped."""
    import re

    text = re.sub(r":\w+:`~?([^`]+)`", r"`\1`", text).replace("``", "`")
    return text.replace("|", "\\|")


def _default(f) -> str:
    if f.default is not MISSING:
        return "—" if f.default is None else repr(f.default).replace("'", '"')
    if f.default_factory is not MISSING:  # type: ignore[misc]
        return repr(f.default_factory()).replace("'", '"')  # type: ignore[misc]
    return "required"


def rows() -> list[dict]:
    """Every key: ``key`` (dotted, as errors name it), ``table`` (how it is written), ``type``,
    ``default``, ``unit`` and ``meaning``."""
    out = []
    for table, klass, written in TABLES:
        words = WORDS[klass]
        for f in fields(klass):
            if not f.init:
                continue
            unit, meaning = words[f.name]
            out.append({"key": f"{table.split(' ')[0]}.{f.name}", "table": written, "type": str(f.type),
                        "default": _default(f), "unit": unit, "meaning": meaning})
    for key, typ, unit, meaning in NESTED:
        out.append({"key": key, "table": "", "type": typ, "default": "", "unit": unit, "meaning": meaning})
    return out


def markdown() -> str:
    """The reference of every scene key as Markdown tables, one per TOML table."""
    lines = ["# Scene keys", "",
             "Every key a scene file may hold, generated from the scene's dataclasses "
             "(`plateqp.model.schema`). Units: any consistent set, L a length and F a force; "
             "1 a pure number. An unknown key is an error naming it.", ""]
    for table, klass, written in TABLES:
        lines += [f"## `{written}`", "", _plain((klass.__doc__ or "").strip().splitlines()[0]), "",
                  "| key | type | default | unit | meaning |", "|---|---|---|---|---|"]
        lines += [f"| `{r['key']}` | `{_plain(r['type'])}` | {_plain(r['default'])} | {r['unit']} | {_plain(r['meaning'])} |"
                  for r in rows() if r["table"] == written]
        lines.append("")
    lines += ["## Nested keys and the top level", "", "| key | type | unit | meaning |", "|---|---|---|---|"]
    lines += [f"| `{k}` | `{_plain(t)}` | {u} | {_plain(m)} |" for k, t, u, m in NESTED]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":  # python -m plateqp.model.schema PATH: write the reference to PATH
    import sys
    from pathlib import Path

    Path(sys.argv[1]).write_text(markdown(), encoding="utf-8")
