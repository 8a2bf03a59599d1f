"""The parts of a scene checked for their types before any field is, and NumPy numbers made the
Python numbers they stand for (a ``np.float32`` thickness, an ``np.int64`` cell count, a 0-d
array, a NumPy array of polygon vertices), so that a scene holds plain numbers and lists whatever
it was built from and saves to TOML as it is.

:meth:`plateqp.model.scene.Scene.validate` runs these checks first, on construction and again at
:func:`plateqp.solve`; a part of the wrong type is a SceneError naming it (``supports.1``,
``edges``), never an AttributeError from deeper down.
"""

from __future__ import annotations

from dataclasses import fields

from ..errors import SceneError


def plain(v):
    """``v`` with NumPy scalars and arrays (at any depth of lists and dicts) made Python numbers
    and lists; ``v`` itself when it holds none."""
    if type(v).__module__ == "numpy" and hasattr(v, "tolist"):
        return v.tolist()  # a scalar or 0-d array: its Python number; an array: nested lists
    if isinstance(v, (list, tuple)):
        new = [plain(x) for x in v]
        return new if any(a is not b for a, b in zip(new, v)) else v
    if isinstance(v, dict):
        new = {k: plain(x) for k, x in v.items()}
        return new if any(new[k] is not v[k] for k in v) else v
    return v


def _short(v, n: int = 60) -> str:
    """repr(v), cut to n characters (a hostile value must not flood the one-line message)."""
    try:
        r = repr(v)
    except Exception:  # noqa: BLE001 - a repr that fails is still a bad value
        r = f"<{type(v).__name__}>"
    return r if len(r) <= n else r[: n - 1] + "…"


def check_source(source) -> None:
    """A scene's ``source``: a file name or None."""
    if source is not None and not isinstance(source, str):
        raise SceneError(f"source: must be a file name (a str) or None (got {_short(source)})")


def check_table(data, source) -> None:
    """The argument of :meth:`Scene.from_dict <plateqp.model.scene.Scene.from_dict>`: a dict, and its
    ``source`` a file name or None."""
    check_source(source)
    if not isinstance(data, dict):
        prefix = f"{source}: " if source else ""
        raise SceneError(f"{prefix}scene: must be a table (a dict in the scene file's shape), got {_short(data)}")


def check_path(path) -> None:
    """A scene file's name: a str or a path-like object."""
    import os

    if not isinstance(path, (str, os.PathLike)):
        raise SceneError(f"path: must be a scene file name, a str or a Path (got {_short(path)})")


def _named(types) -> str:
    types = types if isinstance(types, tuple) else (types,)
    return " or ".join(("an " if t.__name__[0] in "AEIOU" else "a ") + t.__name__ for t in types)


def check_parts(sc, types: dict) -> None:
    """Every part of scene ``sc`` of its type; ``types``: the type (or tuple of types) of
    ``plate``, ``mesh``, ``foundation`` (or None), each value of ``edges`` (or a kind string or
    a table), and each item of the lists ``openings``, ``pins``, ``loads``, ``supports``,
    ``holes``. Fails through ``sc._fail`` naming the first part that is not; then replaces NumPy
    numbers in the parts' fields by Python numbers (:func:`plain`)."""
    check_source(sc.source)
    def wrong(where, v, what):
        hint = "; a dict in the scene file's shape goes through Scene.from_dict" if isinstance(v, dict) else ""
        sc._fail(where, f"must be {what} (got {_short(v)}){hint}")

    if not isinstance(sc.name, str):
        sc._fail("name", f"must be a string (got {_short(sc.name)})")
    for key in ("plate", "mesh"):
        if not isinstance(getattr(sc, key), types[key]):
            wrong(key, getattr(sc, key), _named(types[key]))
    if sc.foundation is not None and not isinstance(sc.foundation, types["foundation"]):
        wrong("foundation", sc.foundation, _named(types["foundation"]) + " or None")
    if not isinstance(sc.edges, dict):
        wrong("edges", sc.edges, 'a dict of edge name to kind, e.g. {"left": "simple"}')
    for k, e in sc.edges.items():
        if not isinstance(k, str):
            wrong("edges", k, "keyed by edge names (strings)")
        if not isinstance(e, (types["edges"], str, dict)):
            wrong(f"edges.{k}", e, 'a kind ("free", "simple", "clamped"), a table or ' + _named(types["edges"]))
    for key in ("openings", "pins", "loads", "supports", "holes"):
        items, t = getattr(sc, key), types[key]
        if not isinstance(items, (list, tuple)):
            wrong(key, items, "a list" + ("" if t is object else f" (each {_named(t)})"))
        for i, item in enumerate(items):
            if not isinstance(item, t):  # supports numbered from 1, as in every table
                wrong(f"{key}.{i + 1 if key == 'supports' else i}", item, _named(t))
    parts = [sc.plate, sc.mesh, *(e for e in sc.edges.values() if isinstance(e, types["edges"])), sc.foundation,
             *sc.openings, *sc.pins, *sc.loads, *sc.supports]
    for part in parts:
        for f in fields(part) if part is not None else ():
            v = getattr(part, f.name)
            new = v if callable(v) else plain(v)
            if new is not v:
                setattr(part, f.name, new)
    if plain(sc.holes) is not sc.holes:
        sc.holes = plain(list(sc.holes))
