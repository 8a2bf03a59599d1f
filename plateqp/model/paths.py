"""Scene paths: read or change one field of a scene named with dots.

A PATH names a scene field with dots: ``plate.h``, ``mesh.nx``, ``loads.0.P``,
``supports.3.gap``, ``supports.*.stiffness`` (``*``: every item of a list), ``foundation.k``,
``edges.left`` (``"free"``, ``"simple"``, ``"clamped"``; on a triangle mesh also ``edges.all``,
``edges.outer``, ``edges.outer_I-J``, ``edges.holeK``: :mod:`plateqp.model.geometry`). :func:`get_param` reads one,
:func:`set_param` returns a validated deep copy with it changed. A support stiffness accepts
``"rigid"`` (also ``math.inf`` or ``"inf"``, stored as ``"rigid"``): the paper's stiffness study
starts from c = ∞. A bad path or value is a :class:`~plateqp.errors.SceneError` that names the
path and what exists there; so is a path that names a table or a list (``plate``,
``supports``, ``supports.0``) where :func:`set_param` wants a value: it lists the fields to
name instead.

Supports are named by their number from 1, the number every table, JSON file and message
gives them: ``supports.1.gap`` is the first ``[[supports]]`` (``scene.supports[0]``), and
``supports.0.gap`` is an error that says so. The other lists keep their index from 0
(``loads.0.P`` is the first load). The same language serves the command line
(``--param``) and Python (:func:`plateqp.studies.sweep`, :func:`plateqp.studies.exact_path`).
"""

from __future__ import annotations

import copy
import math
from dataclasses import fields, is_dataclass

import numpy as np

from ..errors import SceneError
from .constraints import EDGE_KEY
from .scene import EDGE_NAMES, Edge, Scene

_TOP = ("name", "plate", "mesh", "edges", "openings", "pins", "loads", "supports", "foundation")


#: The number of a list's first item in a path: supports are numbered from 1, as in every table,
#: JSON file and message; the other lists (loads, openings, pins) by their index from 0.
FIRST = {"supports": 1}


def _numbering(where: str, n: int) -> str:
    """How the items of the list ``where`` (of ``n``) are numbered in a path, for a message."""
    first = FIRST.get(where, 0)
    if first == 1:
        return f"numbered from 1 (1..{n}), as in the tables"
    return f"indexed from 0 (0..{n - 1})"


def _path_parts(path: str) -> list[str]:
    if not isinstance(path, str) or not path or any(p == "" for p in path.split(".")):
        raise SceneError(f"bad path {path!r}: write dotted names such as 'supports.3.gap' or 'plate.h'")
    return path.split(".")


def _names(obj) -> list[str]:
    if isinstance(obj, Scene):
        return list(_TOP)
    if is_dataclass(obj):
        return [f.name for f in fields(obj) if f.init]
    return []


def _walk(obj, parts: list[str], where: str, create: bool):
    """Yield (container, key, where) for every leaf the path names (``*`` expands lists)."""
    if not parts:
        raise SceneError(f"{where}: names a whole section; name a field of it")
    key, rest = parts[0], parts[1:]
    here = f"{where}.{key}" if where else key
    if isinstance(obj, list):
        first = FIRST.get(where, 0)  # supports: the tables' numbers, from 1
        if key == "*":
            keys = range(len(obj))
            if not keys:
                raise SceneError(f"{here}: {where} is empty")
        else:
            try:
                k = int(key) - first
            except ValueError:
                raise SceneError(f"{here}: {where} is a list whose items are {_numbering(where, len(obj))}; "
                                 "use a number or '*'") from None
            if not obj:
                raise SceneError(f"{here}: the scene has no {where}")
            if not 0 <= k < len(obj):
                raise SceneError(f"{here}: no such item; the scene has {len(obj)} {where}, "
                                 f"{_numbering(where, len(obj))}")
            keys = [k]
        for k in keys:
            sub = f"{where}.{k + first}"
            if rest:
                yield from _walk(obj[k], rest, sub, create)
            else:
                yield obj, k, sub
        return
    if isinstance(obj, dict):  # edges
        if key not in EDGE_NAMES and key != "all" and EDGE_KEY.match(key) is None:
            raise SceneError(f"{here}: unknown edge; edges are {', '.join(EDGE_NAMES)} (on a triangle mesh also "
                             "all, outer, outer_I, outer_I-J, holeK, holeK_I, holeK_I-J)")
        if key not in obj and create:
            obj[key] = Edge("free")
        if rest:
            yield from _walk(obj.get(key, Edge("free")), rest, here, create)
        else:
            yield obj, key, here
        return
    names = _names(obj)
    if key == "*" or key not in names:
        what = where or "the scene"
        raise SceneError(f"{here}: no such field in {what}; fields: {', '.join(names)}")
    if rest:
        sub = getattr(obj, key)
        if sub is None:
            raise SceneError(f"{here}: the scene has no {key}; add a [{key}] section first")
        if isinstance(sub, (str, int, float)) and not isinstance(sub, bool):
            raise SceneError(f"{here}.{rest[0]}: {here} is a value ({sub!r}), not a section")
        if isinstance(sub, dict) and key != "edges":  # e.g. foundation.gap as a profile
            if len(rest) != 1:
                raise SceneError(f"{here}.{'.'.join(rest)}: too deep")
            if rest[0] not in sub:
                raise SceneError(f"{here}.{rest[0]}: no such key; keys: {', '.join(sub)}")
            yield sub, rest[0], f"{here}.{rest[0]}"
            return
        yield from _walk(sub, rest, here, create)
    else:
        yield obj, key, here


def _read(container, key):
    if isinstance(container, (list, dict)):
        v = container[key] if not isinstance(container, dict) or key in container else Edge("free")
    else:
        v = getattr(container, key)
    return v.kind if isinstance(v, Edge) and v.w == 0.0 and v.slope == 0.0 else v


def get_param(scene: Scene, path: str):
    """The value a PATH names (a list of values for a path with ``*``).

    >>> get_param(scene, "supports.*.gap")     # one value per support
    >>> get_param(scene, "plate.h")
    """
    parts = _path_parts(path)
    leaves = list(_walk(scene, parts, "", create=False))
    vals = [_read(c, k) for c, k, _ in leaves]
    return vals if "*" in parts else vals[0]


def _coerce(where: str, old, value):
    """The value as the field wants it ("rigid"/inf for stiffness, int for mesh sizes, Edge for edges)."""
    leaf = where.rsplit(".", 1)[-1]
    if isinstance(value, np.generic):
        value = value.item()
    if leaf == "stiffness":
        if isinstance(value, str) and value.strip().lower() in ("rigid", "inf", "infinity"):
            return "rigid"
        if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isinf(value) and value > 0:
            return "rigid"
    edge_itself = where.startswith("edges.") and where.count(".") == 1
    if isinstance(value, str) and leaf not in ("name", "element", "kind", "profile", "symmetry") and not edge_itself:
        try:
            value = float(value)
        except ValueError:
            raise SceneError(f"{where}: not a number: {value!r}") from None
    if edge_itself:
        if isinstance(value, Edge):
            return copy.deepcopy(value)
        if isinstance(value, str):
            return Edge(kind=value)
        if isinstance(value, dict):
            return Edge(kind=value.get("kind", "free"), w=value.get("w", 0.0), slope=value.get("slope", 0.0))
        raise SceneError(f"{where}: must be an edge kind (free, simple, clamped)")
    if isinstance(old, int) and not isinstance(old, bool) and isinstance(value, float):
        if value.is_integer():
            return int(value)
        raise SceneError(f"{where}: must be an integer (got {value!r})")
    return value


def _is_table(where: str, old) -> bool:
    """True if the field at ``where`` holds a table or a list of them, not a value: the scene's
    sections (``plate``, ``supports``, ``foundation`` even when absent), one item of a list, the
    edges. (An edge itself, ``edges.left``, and a gap profile, ``foundation.gap``, are values.)"""
    if "." not in where and where in _TOP and where != "name":
        return True
    if isinstance(old, Edge):
        return False
    return isinstance(old, list) or is_dataclass(old) or (isinstance(old, dict) and where == "edges")


def _table_error(path: str, old) -> SceneError:
    """What to write instead of a PATH that names a table or a list (a one-line SceneError)."""
    if isinstance(old, dict) or path == "edges":
        return SceneError(f"{path}: names the table of edges, not a value; name one edge: "
                          f"{', '.join(f'edges.{e}' for e in EDGE_NAMES)}")
    if isinstance(old, list) or old is None and path in ("openings", "pins", "loads", "supports"):
        if not old:
            return SceneError(f"{path}: names a list of tables, not a value (and the scene has no {path})")
        return SceneError(f"{path}: names a list of tables, not a value; name a field of one item: "
                          f"{', '.join(f'{path}.{FIRST.get(path, 0)}.{n}' for n in _names(old[0]))} "
                          f"(or {path}.*.<field>)")
    if old is None:  # an absent section (foundation)
        return SceneError(f"{path}: names a table, not a value (and the scene has no [{path}] section)")
    return SceneError(f"{path}: names a table, not a value; name one of its fields: "
                      f"{', '.join(f'{path}.{n}' for n in _names(old))}")


def set_param(scene: Scene, path: str, value) -> Scene:
    """A validated deep copy of ``scene`` with the field PATH set to ``value``.

    With ``*`` in the path every item gets ``value``, or, if ``value`` is a sequence as long
    as the items, one entry each (``set_param(scene, "supports.*.gap", gaps)``).
    Raises SceneError naming the path for a bad path or value.
    """
    new = copy.deepcopy(scene)
    _assign(new, path, value)
    new.validate()
    return new


def check_values(scene: Scene, path: str, values) -> None:
    """Check every value of a sweep before any solve: each one set in turn on one copy of
    ``scene`` and validated. Raises :class:`SceneError` for the first bad one, naming the path
    and the value (a range that crosses E = 0, a negative thickness)."""
    new = copy.deepcopy(scene)
    parts = _path_parts(path)
    leaves = list(_walk(new, parts, "", create=False))  # an edge not named stays not named
    original = [copy.deepcopy(c[k] if isinstance(c, list) or (isinstance(c, dict) and k in c)
                              else None if isinstance(c, dict) else getattr(c, k)) for c, k, _ in leaves]
    for v in values:
        try:
            _assign(new, path, v)
            new.validate()
        except SceneError as exn:
            raise SceneError(f"{exn} (at {path} = {v!r}; nothing was solved)") from None
        for (c, k, _), old in zip(leaves, original):  # each value is checked on the scene as given
            if isinstance(c, dict) and old is None:
                c.pop(k, None)
            elif isinstance(c, (list, dict)):
                c[k] = copy.deepcopy(old)
            else:
                setattr(c, k, copy.deepcopy(old))


def _assign(new: Scene, path: str, value) -> None:
    """Set the field PATH of ``new`` to ``value`` in place (not validated)."""
    parts = _path_parts(path)
    leaves = list(_walk(new, parts, "", create=True))
    per_item = ("*" in parts and not isinstance(value, (str, dict)) and np.ndim(value) == 1
                and len(value) == len(leaves) and len(leaves) > 0)
    for j, (c, k, where) in enumerate(leaves):
        old = _read(c, k) if not isinstance(c, dict) or k in c else None
        if _is_table(where, old) and not (is_dataclass(value) and type(value) is type(old)):
            raise _table_error(path, old)
        v = _coerce(where, old, value[j] if per_item else value)
        if isinstance(c, (list, dict)):
            c[k] = v
        else:
            if k == "type":
                raise SceneError(f"{where}: the load type cannot be changed by a path; edit the scene")
            setattr(c, k, v)


def as_number(value) -> float:
    """A parameter value as a number ("rigid" is +inf)."""
    if isinstance(value, str):
        return math.inf if value.strip().lower() in ("rigid", "inf", "infinity") else float(value)
    return float(value)


__all__ = ["as_number", "check_values", "get_param", "set_param"]
