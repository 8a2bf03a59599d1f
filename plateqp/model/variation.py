"""One scene with one value-field changed, made without copying or checking what the value
does not touch.

A sweep over a support's gap or stiffness, a load's magnitude, the bed's modulus or its gap
field (the fields that leave the mesh, K and the contact operator as they are: *value
leaves*, :func:`is_value_leaf`) makes one scene per value. :func:`set_param` deep-copies the
scene and validates all of it for each; here only the containers on the PATH are copied (the
list of supports, the support changed; the rest is shared with the scene given, which is
validated once), and only the checks that read the changed field are run again: the field's own
(:func:`plateqp.model.checks` through the scene's ``_num``: the same messages) and the
magnitudes (:func:`plateqp.model.scales.check_scales`). The scene made is marked validated, so
:func:`plateqp.solve` does not check it again. Any other PATH goes through :func:`set_param`.
"""

from __future__ import annotations

import copy
import re
from dataclasses import is_dataclass

import numpy as np

from ..errors import SceneError
from .checks import check_gap, check_soil_model
from . import paths
from .parts import plain
from .paths import _assign, _coerce, _path_parts, set_param
from .scene import Scene

#: The PATHs whose value changes no mesh, no K and no contact operator, and is checked by the
#: field's own checks and the magnitudes alone
VALUE_LEAF = re.compile(r"^(supports\.(\d+|\*)\.(gap|stiffness)|loads\.(\d+|\*)\.(q|P)|foundation\.k"
                        r"|foundation\.gap(\.[A-Za-z0-9_]+)?)$")


def is_value_leaf(path: str) -> bool:
    """True if PATH names a value leaf (see the module docstring)."""
    return isinstance(path, str) and VALUE_LEAF.match(path) is not None


def with_value(scene: Scene, path: str, value, checked: bool = False) -> Scene:
    """:func:`plateqp.model.paths.set_param`'s answer (a validated scene with PATH = value, the
    scene given unchanged), the same scene field for field; for a value leaf made by copying only
    the containers on the PATH and checking only the changed field, the rest shared with
    ``scene`` (checked here: :meth:`Scene.revalidate`; ``checked``: the caller validated it since
    its last change, as a sweep's :func:`check_values` did). Raises the same SceneError."""
    if not is_value_leaf(path):
        return set_param(scene, path, value)
    if not checked:
        scene.revalidate()
    new = _made(scene, path, value)
    new._checked = new._fingerprint()
    return new


def check_values(scene: Scene, path: str, values) -> None:
    """:func:`plateqp.model.paths.check_values` (every value of a sweep checked before any solve,
    the same SceneError for the first bad one), for a value leaf by :func:`check_leaf` alone."""
    if not is_value_leaf(path):
        return paths.check_values(scene, path, values)
    scene.revalidate()
    for v in values:
        try:
            _made(scene, path, v)
        except SceneError as exn:
            raise SceneError(f"{exn} (at {path} = {v!r}; nothing was solved)") from None


def _made(scene: Scene, path: str, value) -> Scene:
    """The scene with the value leaf PATH = ``value`` (its NumPy numbers made Python's, as the
    validation makes them), checked by :func:`check_leaf`; not marked validated."""
    new = _copy_path(scene, path)
    value = plain(value)
    if not _assign_items(new, path, value):
        _assign(new, path, value)
    check_leaf(new, path)
    return new


def _assign_items(new: Scene, path: str, value) -> bool:
    """:func:`plateqp.model.paths._assign` for ``supports.*.F`` and ``loads.*.F`` without walking
    the path once per item (the same coercion, item by item); False where the path or an item
    needs the walk (then its SceneError says what is wrong)."""
    parts = _path_parts(path)
    if parts[0] not in ("supports", "loads") or parts[1] != "*":
        return False
    items, leaf = getattr(new, parts[0]), parts[2]
    if not items or not all(hasattr(it, leaf) and is_dataclass(it) for it in items):
        return False
    per_item = not isinstance(value, (str, dict)) and np.ndim(value) == 1 and len(value) == len(items)
    first = 1 if parts[0] == "supports" else 0
    made: dict = {}  # one value for all: coerced once per kind of old value (all _coerce reads of it)
    for j, it in enumerate(items):
        old = getattr(it, leaf)
        if isinstance(old, (list, dict)) or is_dataclass(old):
            return False
        if per_item:
            setattr(it, leaf, _coerce(f"{parts[0]}.{j + first}.{leaf}", old, value[j]))
            continue
        kind = isinstance(old, int) and not isinstance(old, bool)
        if kind not in made:
            made[kind] = _coerce(f"{parts[0]}.{j + first}.{leaf}", old, value)
        setattr(it, leaf, made[kind])
    return True


def check_leaf(sc: Scene, path: str) -> None:
    """The checks of :meth:`Scene.validate` that read the value leaf PATH (its field checks, in the
    order the validation makes them, then the magnitudes); every other field is taken as checked."""
    from .scales import check_scales
    from .scene import SAFE_DERIVED

    parts = _path_parts(path)
    if parts[0] == "supports":
        items = range(len(sc.supports)) if parts[1] == "*" else [int(parts[1]) - 1]
        passed = None  # the value checked last, found good: the same object, checked again, passes again
        for i in items:
            s, where = sc.supports[i], f"supports.{i + 1}"
            v = getattr(s, parts[2])
            if passed is not None and v is passed[0]:
                continue
            passed = (v,)
            if parts[2] == "gap":
                sc._num(f"{where}.gap", s.gap, physical=True)
            elif isinstance(s.stiffness, str):
                if s.stiffness != "rigid":
                    sc._fail(f"{where}.stiffness", f"must be \"rigid\" or a positive number (got {s.stiffness!r})")
            else:
                sc._num(f"{where}.stiffness", s.stiffness, positive=True, physical=True)
    elif parts[0] == "loads":
        items = range(len(sc.loads)) if parts[1] == "*" else [int(parts[1])]
        for i in items:
            sc._num(f"loads.{i}.{parts[2]}", getattr(sc.loads[i], parts[2]), physical=True)
    elif parts[1] == "k":
        check_soil_model(sc, sc.foundation)
    else:
        check_gap(sc, sc.foundation.gap)
    check_scales(sc, SAFE_DERIVED)


def _copy_path(scene: Scene, path: str) -> Scene:
    """A shallow copy of ``scene`` whose containers on PATH are copies too (a list, its item or
    every item for ``*``, the foundation and its gap table): assigning the leaf changes the copy
    alone. A PATH that names nothing there is left to :func:`_assign`'s SceneError."""
    parts = _path_parts(path)
    new = copy.copy(scene)
    if parts[0] in ("supports", "loads"):
        items = list(getattr(scene, parts[0]))
        setattr(new, parts[0], items)
        if parts[1] == "*":
            items[:] = [_shallow(it) for it in items]
        else:
            k = _index(parts[1]) - (1 if parts[0] == "supports" else 0)
            if 0 <= k < len(items):
                items[k] = copy.copy(items[k])
    elif scene.foundation is not None:
        new.foundation = copy.copy(scene.foundation)
        if isinstance(new.foundation.gap, dict):
            new.foundation.gap = dict(new.foundation.gap)
    return new


def _shallow(item):
    """``copy.copy(item)`` of a plain dataclass (its fields in its ``__dict__``) without copy's
    dispatch, which a sweep over every support paid 900 times a value."""
    cls = type(item)
    if hasattr(cls, "__copy__") or hasattr(cls, "__slots__") or not hasattr(item, "__dict__"):
        return copy.copy(item)
    new = object.__new__(cls)
    new.__dict__.update(item.__dict__)
    return new


def _index(key: str) -> int:
    try:
        return int(key)
    except ValueError:
        raise SceneError(f"bad index {key!r}") from None


__all__ = ["VALUE_LEAF", "check_leaf", "check_values", "is_value_leaf", "with_value"]
