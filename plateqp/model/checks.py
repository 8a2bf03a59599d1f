"""The scene's field checks, in the order a reader meets the fields: plate and mesh, edges,
cut-outs (and the mesh they leave), pins, loads, supports, foundation. Each raises a
:class:`~plateqp.errors.SceneError` naming the first bad field (through the scene's ``_fail``
and ``_num``: the file, where the scene came from one). :meth:`plateqp.model.scene.Scene.validate`
runs them after the parts' types are checked (:mod:`plateqp.model.parts`)."""

from __future__ import annotations

from .elements import ELEMENTS
from .parts import _short
from .symmetry import MODES, check_symmetry

#: No scene needs more cells than this; the memory a mesh needs is checked before assembly
#: (:func:`plateqp.model.memory.check_memory`), this only keeps validation itself small.
MAX_CELLS = 10_000_000
EDGE_KINDS = ("free", "simple", "clamped")
GAP_PROFILES = ("uniform", "linear", "trough", "bump")


def check_scene(sc) -> None:
    """Every field of the scene ``sc``; the checks that need the mesh's cover use one built once."""
    check_plate_and_mesh(sc)
    check_edges(sc)
    grid = check_cutouts(sc)
    check_pins(sc, grid)
    check_loads(sc, grid)
    check_supports(sc, grid)
    if sc.foundation is not None:
        check_foundation(sc, grid)
    if sc.mesh.symmetry is not None:
        check_symmetry(sc, grid.domain)


def check_plate_and_mesh(sc) -> None:
    p, m = sc.plate, sc.mesh
    for k in ("a", "b", "h", "E"):
        sc._num(f"plate.{k}", getattr(p, k), positive=True, physical=True)
    sc._num("plate.nu", p.nu)
    if not (-1.0 < p.nu < 0.5):
        sc._fail("plate.nu", f"must lie in (-1, 0.5) (got {p.nu})")
    for k in ("nx", "ny"):
        v = getattr(m, k)
        if isinstance(v, bool) or not isinstance(v, int) or v < 1:
            sc._fail(f"mesh.{k}", f"must be an integer >= 1 (got {_short(v)})")
        if v > MAX_CELLS:
            sc._fail(f"mesh.{k}", f"{_short(v)} cells is more than any plate needs (at most {MAX_CELLS:.0e})")
    if m.nx * m.ny > MAX_CELLS:
        sc._fail("mesh", f"{m.nx} x {m.ny} = {m.nx * m.ny:.2g} cells is more than any plate needs "
                 f"(at most {MAX_CELLS:.0e}); the memory a mesh needs is checked before assembly")
    if not isinstance(m.element, str) or m.element not in ELEMENTS:
        sc._fail("mesh.element", f"unknown element {_short(m.element)}; choose one of {tuple(ELEMENTS)}")
    if m.symmetry in ("none", ""):  # a path's way to ask for none
        m.symmetry = None
    if m.symmetry is not None and m.symmetry not in MODES:
        sc._fail("mesh.symmetry", f'must be "x", "y" or "xy" (a mesh mirrored in the plate\'s centre line x = xc, '
                 f"y = yc or both) or absent (got {_short(m.symmetry)})")
    from .generators import mesh_generator

    mesh_generator(sc).check_scene_fields(sc)  # e.g. a shape or an element size needs triangles


def check_edges(sc) -> None:
    """Each edge's kind and values (its name: :func:`check_cutouts`, once the boundaries are known)."""
    for name, e in sc.edges.items():
        if e.kind not in EDGE_KINDS:
            sc._fail(f"edges.{name}", f"unknown kind {e.kind!r}; choose one of {EDGE_KINDS}")
        sc._num(f"edges.{name}.w", e.w, physical=True)
        sc._num(f"edges.{name}.slope", e.slope, physical=True)
        if e.kind == "free" and (e.w != 0.0 or e.slope != 0.0):
            sc._fail(f"edges.{name}", "a free edge cannot carry a prescribed w or slope; make it simple or clamped")
        if e.kind == "simple" and e.slope != 0.0:
            sc._fail(f"edges.{name}.slope", "a slope can only be prescribed on a clamped edge")


def check_cutouts(sc):
    """The openings' boxes (regions: :func:`plateqp.model.geometry.parse_region`), the shape and
    holes (on triangles), what they leave of the plate, and
    the edge names on its boundaries (:func:`plateqp.model.constraints.edge_table`). Returns the cover
    the point checks ask (``covers``, ``locate``, ``node_at``, ``cells_in``):
    the grid, or on triangles the plate's region."""
    from .constraints import edge_table, warn_changed_all
    from .geometry import parse_region

    for i, o in enumerate(sc.openings):
        for k in ("x0", "x1", "y0", "y1"):
            sc._num(f"openings.{i}.{k}", getattr(o, k))
        parse_region([o.x0, o.x1, o.y0, o.y1], f"openings.{i}", sc._fail)  # a box region, as a patch's
    grid = plate_cover(sc)
    if not grid.cell_mask.any():
        sc._fail("openings" if sc.openings else "holes", "the cut-outs remove every cell of the plate")
    edge_table(sc, grid.domain)  # every edge name known, and no segment named twice
    warn_changed_all(sc, grid.domain)
    return grid


def plate_cover(sc):
    """What the point checks ask of the plate (``covers``, ``locate``, ``node_at``,
    ``cells_in``, ``domain``): the grid, or on triangles the plate's region (its shape and
    cut-outs checked: :func:`plateqp.model.geometry.validate_shaped`), as the scene's mesh
    generator gives it (``cover``)."""
    from .generators import mesh_generator

    return mesh_generator(sc).cover(sc)


def check_pins(sc, grid) -> None:
    for i, pin in enumerate(sc.pins):
        sc._num(f"pins.{i}.x", pin.x)
        sc._num(f"pins.{i}.y", pin.y)
        sc._num(f"pins.{i}.w", pin.w, physical=True)
        sc._inside(f"pins.{i}", pin.x, pin.y, grid)
        if grid.node_at(pin.x, pin.y) is None:
            sc._fail(f"pins.{i}", f"({pin.x}, {pin.y}) is not a mesh node (node spacing {grid.hx:g} x {grid.hy:g});"
                     " move the pin or change mesh.nx / mesh.ny")


def check_loads(sc, grid) -> None:
    for i, ld in enumerate(sc.loads):
        where = f"loads.{i}"
        kind = getattr(ld, "type", None)
        if kind not in ("uniform", "patch", "point"):
            sc._fail(where, f"not a load: {ld!r}")
        if kind == "point":
            sc._num(f"{where}.P", ld.P, physical=True)
            sc._num(f"{where}.x", ld.x)
            sc._num(f"{where}.y", ld.y)
            sc._inside(where, ld.x, ld.y, grid)
            continue
        sc._num(f"{where}.q", ld.q, physical=True)
        if kind == "patch":
            check_patch(sc, ld, where, grid)


def check_patch(sc, ld, where: str, grid) -> None:
    """A patch's region: the box x0, x1, y0, y1 or ``region`` (a box, a polygon or a circle:
    :func:`plateqp.model.geometry.parse_region`), not both, over some of the plate."""
    from .geometry import parse_region

    box = (ld.x0, ld.x1, ld.y0, ld.y1)
    given = [v is not None for v in box]
    if ld.region is not None and any(given):
        sc._fail(where, "give the patch either x0, x1, y0, y1 or region (a box, a polygon or a circle), not both")
    if ld.region is None and not all(given):
        sc._fail(where, "needs x0, x1, y0, y1 or region (a box, a polygon or a circle)")
    if ld.region is None:
        for k, v in zip(("x0", "x1", "y0", "y1"), box):
            sc._num(f"{where}.{k}", v)
        shape = parse_region(list(box), where, sc._fail)
    else:
        where = f"{where}.region"
        shape = parse_region(ld.region, where, sc._fail)
        ld.region = _scene_form(ld.region, shape)
    xs, ys = _inside_points(shape)
    x0, x1, y0, y1 = grid.domain.outer.bbox
    near = (xs > x0) & (xs < x1) & (ys > y0) & (ys < y1)
    if not near.any():
        sc._fail(where, "the patch does not overlap the plate")
    if not (grid.locate(xs[near], ys[near])[0] >= 0).any():
        sc._fail(where, "the patch lies entirely in an opening, a hole or outside the plate's shape "
                 "(no plate there to load)")


def _scene_form(value, shape):
    """A region given in Python as a Polygon or Circle kept in its scene form (as TOML gives it)."""
    return shape.to_dict() if hasattr(value, "to_dict") else value


def _inside_points(shape):
    """Points inside a region (:func:`plateqp.model.geometry.sample_points`)."""
    from .geometry import sample_points

    return sample_points(shape)


def check_supports(sc, grid) -> None:
    """Each support's place (on the plate, not on another's point), gap and stiffness; supports
    are numbered from 1, as in every table."""
    seen: dict[tuple[float, float], int] = {}
    tol = 1e-9 * max(sc.plate.a, sc.plate.b)
    covered = sc._covered(grid, [(getattr(s, "x", None), getattr(s, "y", None)) for s in sc.supports])
    for i, s in enumerate(sc.supports):
        where = f"supports.{i + 1}"
        sc._num(f"{where}.x", s.x)
        sc._num(f"{where}.y", s.y)
        sc._num(f"{where}.gap", s.gap, physical=True)
        sc._inside(where, s.x, s.y, grid, None if covered is None else covered[i])
        if isinstance(s.stiffness, str):
            if s.stiffness != "rigid":
                sc._fail(f"{where}.stiffness", f"must be \"rigid\" or a positive number (got {s.stiffness!r})")
        else:
            sc._num(f"{where}.stiffness", s.stiffness, positive=True, physical=True)
        key = (round(s.x / tol), round(s.y / tol))
        if key in seen:
            sc._fail(where, f"lies on the same point as supports.{seen[key] + 1}; merge them into one support")
        seen[key] = i


def check_foundation(sc, grid) -> None:
    """The bed's modulus, region (a box, a polygon or a circle:
    :func:`plateqp.model.geometry.parse_region`, over some cell of the plate) and gap (a number
    or a profile)."""
    from .geometry import parse_region

    f = sc.foundation
    check_soil_model(sc, f)
    if f.region is not None:
        shape = parse_region(f.region, "foundation.region", sc._fail)
        f.region = _scene_form(f.region, shape)
        if not grid.domain.outer.contains(*_inside_points(shape)).any() or not grid.cells_in(shape).any():
            sc._fail("foundation.region", f"{_short(f.region)} does not overlap the plate or holds the centre of "
                     "no cell of it (it is off the plate, in an opening, or smaller than a cell): the bed would "
                     "have no node")
    check_gap(sc, f.gap)


#: the soil models and the parameters each takes (all required)
SOIL_MODELS = {"winkler": ("k",), "pasternak": ("k", "shear"), "halfspace": ("E", "nu")}


def check_soil_model(sc, f) -> None:
    """The soil model's name and its parameters: each one it takes present and physical
    (``k`` > 0, ``shear`` ≥ 0, ``E`` > 0, −1 < ``nu`` ≤ 0.5), none it does not take."""
    if not isinstance(f.model, str) or f.model not in SOIL_MODELS:
        sc._fail("foundation.model", f"unknown soil model {_short(f.model)}; choose one of {list(SOIL_MODELS)}")
    takes = SOIL_MODELS[f.model]
    for key in ("k", "shear", "E", "nu"):
        v = getattr(f, key)
        if key not in takes:
            if v is not None:
                users = [m for m, keys in SOIL_MODELS.items() if key in keys]
                sc._fail(f"foundation.{key}", f"the {f.model} model does not take it (it is a parameter of "
                         f"model = {' or '.join(repr(u) for u in users)})")
            continue
        if v is None:
            sc._fail(f"foundation.{key}", f"missing: model = {f.model!r} needs {', '.join(takes)}")
        if key == "nu":
            nu = sc._num("foundation.nu", v)
            if not -1.0 < nu <= 0.5:
                sc._fail("foundation.nu", f"Poisson's ratio {nu:g} is outside (-1, 0.5]")
        else:
            sc._num(f"foundation.{key}", v, positive=key != "shear", nonneg=key == "shear", physical=True)


def check_gap(sc, g) -> None:
    if isinstance(g, dict):
        prof = g.get("profile")
        if prof not in GAP_PROFILES:
            sc._fail("foundation.gap.profile", f"unknown profile {prof!r}; choose one of {GAP_PROFILES}")
        need = {"uniform": ("g0",), "linear": (), "trough": ("x", "y", "radius", "depth"),
                "bump": ("x", "y", "radius", "depth")}[prof]
        allowed = {"profile", *need, *(("gx", "gy", "g0") if prof == "linear" else ())}
        for k in need:
            if k not in g:
                sc._fail(f"foundation.gap.{k}", f"missing (profile {prof!r} needs {need})")
        for k, v in g.items():
            if k not in allowed:
                sc._fail(f"foundation.gap.{k}", f"unknown key for profile {prof!r}; allowed {sorted(allowed)}")
            if k != "profile":
                sc._num(f"foundation.gap.{k}", v, positive=(k == "radius"), physical=True)
    elif not callable(g):
        sc._num("foundation.gap", g, physical=True)
