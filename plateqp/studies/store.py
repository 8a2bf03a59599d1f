"""A sweep's rows on disk, written one by one as they are solved, so that a stopped sweep keeps
them and can resume.

The store is a JSON Lines file: a header line (what the sweep is: the scene's fingerprint, the
parameter path, the values, backend, formulation, accuracy, options, the plateqp version), then
one line per value solved ``{"index": i, "row": {...}}`` (the row of
:class:`plateqp.studies.SweepResult`), each flushed and synced to the disk before the next
value's result is taken. Rows arrive in the main process whatever the executor (serial, local
processes, Dask), so one writer serves them all. On resuming, the header must match the sweep
asked (the same scene, path, values and solver settings): a store of another sweep is a clear
error, never mixed in. A last line cut off by a crash is ignored (its value is solved again).
The file is never opened through a symbolic link, and a link, a FIFO or a device given as the
store is refused at once (:mod:`plateqp.io.safe`).

:meth:`SweepResult.to_xarray` turns the rows into an :class:`xarray.Dataset` with the
parameter value as the dimension (``plateqp sweep --out FILE.nc`` writes it as netCDF).
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from ..errors import ProblemError
from ..io.safe import regular_or_absent, write

#: The header's format; a store written by another format is refused.
FORMAT = "plateqp-sweep-rows/1"


def scene_fingerprint(scene) -> str:
    """A hash of the scene's full definition (its TOML form), so that a store is resumed only by
    the same scene."""
    text = json.dumps(scene.to_dict(), sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


class RowStore:
    """Rows of one sweep in a JSON Lines file (see the module docstring).

    Parameters
    ----------
    path : the file (made if missing, with its folder)
    header : what the sweep is (a JSON-able dict); must equal the stored one to resume
    """

    def __init__(self, path, header: dict) -> None:
        self.path = Path(path)
        self.header = {"format": FORMAT, **json.loads(json.dumps(header, default=str))}
        self.done: dict[int, dict] = {}
        label = f"sweep store {self.path}"
        # a link, a folder, a FIFO or a device is refused at once (reading a FIFO would block)
        there = regular_or_absent(self.path, label)
        if there and self.path.stat().st_size > 0:
            self._read()
        else:  # a new file (or an empty one, replaced), never through a link
            write(self.path, lambda tmp: _write_synced(tmp, json.dumps(self.header) + "\n"), force=there,
                  label=label)

    def _read(self) -> None:
        try:
            fd = os.open(self.path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
            with open(fd, encoding="utf-8") as fh:
                text = fh.read()
            lines = text.splitlines()
        except (OSError, UnicodeDecodeError) as exn:
            raise ProblemError(f"sweep store {self.path}: cannot be read ({exn})") from None
        try:
            stored = json.loads(lines[0])
        except (IndexError, json.JSONDecodeError):
            raise ProblemError(f"sweep store {self.path}: not a plateqp sweep store (no header line)") from None
        if not isinstance(stored, dict) or stored.get("format") != FORMAT:
            raise ProblemError(f"sweep store {self.path}: not a plateqp sweep store ({FORMAT})")
        diff = sorted(k for k in set(stored) | set(self.header) if stored.get(k) != self.header.get(k)
                      and k != "version")
        if diff:
            raise ProblemError(f"sweep store {self.path}: holds another sweep (differs in {', '.join(diff)}); "
                               "name a new file, or delete it to start again")
        n = len(self.header.get("values", []))
        kept = [lines[0]]
        for k, line in enumerate(lines[1:], start=2):
            try:
                rec = json.loads(line)
                i = int(rec["index"])
                row = rec["row"]
            except (json.JSONDecodeError, KeyError, TypeError, ValueError):
                if k == len(lines):  # the last line, cut off by a crash: that value is solved again
                    break
                raise ProblemError(f"sweep store {self.path}: line {k} is damaged") from None
            if not 0 <= i < n:
                raise ProblemError(f"sweep store {self.path}: line {k} names value {i} of {n}")
            self.done[i] = row
            kept.append(line)
        if len(kept) < len(lines) or not text.endswith("\n"):
            text = "\n".join(kept) + "\n"  # drop the cut line before appending
            write(self.path, lambda tmp: _write_synced(tmp, text), force=True, label=f"sweep store {self.path}")

    def append(self, index: int, row: dict) -> None:
        """Write the row of value ``index`` and sync it to the disk."""
        fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | getattr(os, "O_NOFOLLOW", 0))
        with open(fd, "a", encoding="utf-8") as fh:
            fh.write(json.dumps({"index": int(index), "row": row}, default=_jsonable) + "\n")
            fh.flush()
            os.fsync(fh.fileno())
        self.done[int(index)] = row


def _write_synced(path, text: str) -> None:
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)
        fh.flush()
        os.fsync(fh.fileno())


def _jsonable(v):
    """numpy scalars and arrays in a row, as JSON."""
    if hasattr(v, "tolist"):
        return v.tolist()
    if hasattr(v, "item"):
        return v.item()
    return str(v)
