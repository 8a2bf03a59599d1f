"""Where an export may write, checked before any work is done (the writing itself, and the rules
for links: :mod:`plateqp.io.safe`).

The promise: nothing is written outside the path asked for, nothing that exists is
overwritten unless forced, and a path that cannot be written says so in one line before the
problem is built, not with a traceback after. A symbolic link at the path counts as something
that exists (a dangling one too: writing through it would write somewhere else).
"""

from __future__ import annotations

import os
import re
from pathlib import Path, PurePath

from ..errors import ExportError
from .safe import _usable_parent, check_target

#: Characters allowed in a file name made from a scene's name.
_SAFE = re.compile(r"[^A-Za-z0-9._-]+")


def safe_filename(name: str) -> str:
    """A scene name as a plain file name: no directories, no leading dot, at most 100 characters."""
    out = _SAFE.sub("_", str(name)).lstrip(".")[:100]
    return out or "scene"


def check_file(path, *, force: bool = False, label: str | None = None, flag: str = "force=True") -> Path:
    """Check that one file may be written at ``path``: not a directory, not there unless
    ``force`` (a symbolic link counts as there), in a folder that is (or can be made) writable:
    :func:`plateqp.io.safe.check_target`, the rule the writing itself keeps.

    ``label`` names the path in messages (default: the path); ``flag`` is how to force.
    """
    return check_target(path, force=force, label=label, flag=flag)


def inside(relative: str, what: str) -> PurePath:
    """``relative`` as a path that stays inside the folder it is taken from: not absolute, no
    ``..``, not empty."""
    p = PurePath(relative)
    if p.is_absolute() or ".." in p.parts or not p.parts or p.drive:
        raise ExportError(f"{what} {relative!r}: must be a relative path inside the output directory, without '..'")
    return p


def check_folder(directory, files=(), folders=(), *, force: bool = False, label: str | None = None,
                 flag: str = "force=True") -> Path:
    """Check that ``files`` and ``folders`` (paths relative to ``directory``) may be written in
    ``directory``: it is a directory or can be made one, empty unless ``force``, and with
    ``force`` nothing of another kind stands where they go (a folder where a file goes, a file
    where a folder goes, also along the way).
    """
    directory = Path(directory)
    label = label or str(directory)
    if os.path.islink(directory):
        raise ExportError(f"{label}: is a symbolic link; name the directory itself (plateqp never writes through links)")
    if os.path.lexists(directory) and not directory.is_dir():
        raise ExportError(f"{label}: exists and is not a directory")
    if not directory.is_dir():
        _usable_parent(directory, label)
        return directory
    if any(directory.iterdir()) and not force:
        raise ExportError(f"{label}: exists and is not an empty directory; use {flag} to write into it")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise ExportError(f"{label}: is not writable")
    wanted = [(inside(str(f), "file"), False) for f in files] + [(inside(str(f), "folder"), True) for f in folders]
    for rel, is_folder in wanted:
        p = directory
        for k, part in enumerate(rel.parts):
            p = p / part
            must_be_folder = is_folder or k < len(rel.parts) - 1
            if not os.path.lexists(p):
                break
            if must_be_folder and os.path.islink(p):
                raise ExportError(f"{label}: {p} is a symbolic link (plateqp never writes through links)")
            if must_be_folder and not p.is_dir():
                raise ExportError(f"{label}: {p} is in the way (a file where a directory goes)")
            if not must_be_folder and p.is_dir():
                raise ExportError(f"{label}: {p} is in the way (a directory where a file goes)")
    return directory
