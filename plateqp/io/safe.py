"""Every file plateqp writes goes through here: never through a link, never outside the folder
named, never over an existing file unless forced.

The rules, the same for ``solve --out``, ``demo --out``, ``export``, ``regulate --out``,
``sweep --out`` and ``--store``, :meth:`plateqp.results.Result.write_vtu` and the qpbenchmark
test sets:

- a symbolic link is never followed. A link (dangling or not) where a file goes counts as a
  file that exists: refused without ``force``; with ``force`` the link itself is replaced by
  the new file and its target is left as it was. A folder given as the place to write
  (``--out DIR``) that is a link is refused, with or without ``force``, and so is a link on
  the way from that folder to a file in it;
- a file is first written whole under a hidden temporary name beside its target
  (``.<random>.<name>``, made with ``O_EXCL | O_NOFOLLOW``), then moved into place in one
  step (:func:`os.replace`, or :func:`os.link` without ``force``, which fails rather than
  overwrite something that appeared meanwhile); a write that fails leaves no temporary file
  and the target as it was;
- something that is not a regular file where a file goes (a FIFO, a device) is refused without
  ``force`` and replaced, never opened, with it; a folder there is refused.

Errors are one-line :class:`~plateqp.errors.ExportError` messages that start with ``label``
(``--out DIR``, or the path).
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import stat
from collections.abc import Callable, Iterator
from pathlib import Path

from ..errors import ExportError


def _why(exn: OSError) -> str:
    return exn.strerror or str(exn)


def _lstat(p: Path):
    try:
        return os.lstat(p)
    except (FileNotFoundError, NotADirectoryError):  # nothing there (or a file on the way)
        return None
    except OSError as exn:
        raise ExportError(f"{p}: cannot be read ({_why(exn)})") from None


def out_folder(folder, *, label: str | None = None, make: bool = True) -> Path:
    """The folder named as the place to write (``--out DIR``), checked and (with ``make``) made.

    Refused: a symbolic link (dangling or not: its files would land elsewhere), something that
    is not a folder, a folder that cannot be made or is not writable.
    """
    folder = Path(folder)
    label = label or str(folder)
    st = _lstat(folder)
    if st is not None and stat.S_ISLNK(st.st_mode):
        raise ExportError(f"{label}: is a symbolic link; name the folder itself (plateqp never writes through links)")
    if st is not None and not stat.S_ISDIR(st.st_mode):
        raise ExportError(f"{label}: exists and is not a folder")
    if st is None:
        if not make:
            _usable_parent(folder, label)
            return folder
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exn:
            raise ExportError(f"{label}: cannot be made ({_why(exn)})") from None
        if os.path.islink(folder):  # made by someone else meanwhile
            raise ExportError(f"{label}: is a symbolic link; name the folder itself")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ExportError(f"{label}: is not writable")
    return folder


def _usable_parent(path: Path, label: str) -> None:
    """The nearest existing one of ``path``'s parents must be a writable folder."""
    p = path
    while not os.path.lexists(p) and p != p.parent:
        p = p.parent
    if not p.is_dir():
        raise ExportError(f"{label}: cannot write ({p} is not a directory)")
    if not os.access(p, os.W_OK | os.X_OK):
        raise ExportError(f"{label}: cannot write ({p} is not writable)")


def _no_link_between(root: Path, path: Path, label: str) -> None:
    """No component of ``path`` below ``root`` but the last is a link or a file."""
    try:
        rel = path.relative_to(root)
    except ValueError:
        raise ExportError(f"{label}: {path} is not inside {root}") from None
    if ".." in rel.parts or rel.is_absolute():
        raise ExportError(f"{label}: {path} is not inside {root}")
    p = root
    for part in rel.parts[:-1]:
        p = p / part
        st = _lstat(p)
        if st is None:
            return
        if stat.S_ISLNK(st.st_mode):
            raise ExportError(f"{label}: {p} is a symbolic link (plateqp never writes through links)")
        if not stat.S_ISDIR(st.st_mode):
            raise ExportError(f"{label}: {p} is in the way (a file where a folder goes)")


def check_target(path, *, force: bool = False, label: str | None = None, flag: str = "--force",
                 root=None) -> Path:
    """Check, before any work, that a file may be written at ``path`` (see the module docstring);
    ``root``: the folder it must stay inside (no link on the way). Returns the path."""
    path = Path(path)
    here = f"{label}: {path.name}" if label else f"{path}:"
    label = label or str(path)
    if root is not None:
        _no_link_between(Path(root), path, label)
    st = _lstat(path)
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            raise ExportError(f"{here} is a directory, not a file")
        if not force:
            what = " (a symbolic link)" if stat.S_ISLNK(st.st_mode) else ""
            raise ExportError(f"{here} exists{what}; use {flag} to replace it")
    if root is None:
        _usable_parent(path.parent, label)
    return path


def make_folders(root, rel, *, label: str | None = None) -> Path:
    """Make the folder ``root/rel`` (and those on the way) without following any link."""
    root = Path(root)
    label = label or str(root)
    p = root
    for part in Path(rel).parts:
        p = p / part
        _no_link_between(root, p / "x", label)
        try:
            os.mkdir(p)
        except FileExistsError:
            pass
        except OSError as exn:
            raise ExportError(f"{label}: {p} cannot be made ({_why(exn)})") from None
    return p


@contextlib.contextmanager
def target(path, *, force: bool = False, label: str | None = None, flag: str = "--force",
           root=None) -> Iterator[Path]:
    """Write one file safely: yields a fresh temporary path beside ``path`` for the caller (or a
    library) to write; when the block ends without error it is moved to ``path`` (see the
    module docstring), else removed.

    >>> with target(out / "w.npy", force=True, root=out) as tmp:
    ...     np.save(tmp, w)
    """
    path = Path(path)
    label = label or str(path)
    check_target(path, force=force, label=label, flag=flag, root=root)
    parent = path.parent
    if root is None and not parent.is_dir():
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as exn:
            raise ExportError(f"{label}: {parent} cannot be made ({_why(exn)})") from None
    tmp = parent / f".{secrets.token_hex(6)}.{path.name}"
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o666)
    except OSError as exn:
        raise ExportError(f"{label}: {path.name} cannot be written ({_why(exn)})") from None
    os.close(fd)
    try:
        yield tmp
        _place(tmp, path, force, label, flag)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _place(tmp: Path, path: Path, force: bool, label: str, flag: str) -> None:
    """Move the written temporary file to its name: over what is there with ``force`` (a link is
    replaced, not followed), else only if nothing is there."""
    try:
        if force:
            st = _lstat(path)
            if st is not None and stat.S_ISDIR(st.st_mode):
                raise ExportError(f"{label}: {path.name} is a directory, not a file")
            os.replace(tmp, path)
            return
        try:
            os.link(tmp, path, follow_symlinks=False)
        except FileExistsError:
            raise ExportError(f"{label}: {path.name} exists; use {flag} to replace it") from None
        except OSError as exn:
            if exn.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK):
                raise
            if os.path.lexists(path):  # a file system without hard links
                raise ExportError(f"{label}: {path.name} exists; use {flag} to replace it") from None
            os.replace(tmp, path)
            return
        os.unlink(tmp)
    except OSError as exn:
        raise ExportError(f"{label}: {path.name} cannot be written ({_why(exn)})") from None


def write(path, data: bytes | str | Callable[[Path], object], *, force: bool = False, label: str | None = None,
          flag: str = "--force", root=None, encoding: str = "utf-8") -> Path:
    """Write ``data`` (bytes, text, or a function that writes the file at the path it is given)
    to ``path`` by :func:`target`'s rules. Returns ``path``."""
    path = Path(path)
    with target(path, force=force, label=label, flag=flag, root=root) as tmp:
        try:
            if callable(data):
                data(tmp)
            elif isinstance(data, bytes):
                tmp.write_bytes(data)
            else:
                tmp.write_text(data, encoding=encoding)
        except OSError as exn:
            raise ExportError(f"{label or path}: {path.name} cannot be written ({_why(exn)})") from None
    return path


def regular_or_absent(path, label: str | None = None) -> bool:
    """True if a regular file is at ``path``, False if nothing is; a link, a folder or a special
    file (FIFO, device, socket) is an error (reading a FIFO would block)."""
    path = Path(path)
    label = label or str(path)
    st = _lstat(path)
    if st is None:
        return False
    if stat.S_ISLNK(st.st_mode):
        raise ExportError(f"{label}: is a symbolic link; name the file itself (plateqp never writes through links)")
    if stat.S_ISDIR(st.st_mode):
        raise ExportError(f"{label}: is a directory, not a file")
    if not stat.S_ISREG(st.st_mode):
        raise ExportError(f"{label}: is not a regular file (a FIFO, device or socket)")
    return True


__all__ = ["check_target", "make_folders", "out_folder", "regular_or_absent", "target", "write"]
