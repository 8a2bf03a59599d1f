"""Progress bars for long runs (sweeps, refinement studies, exact paths, the demo, benchmarks),
on standard error, only where someone is watching.

A bar is drawn when its caller asks for one (``enabled``), standard error is a terminal, the
environment variable ``CI`` is not set to a true value ("true", "1", "yes"), and bars have
not been turned off for the whole process (:func:`set_enabled`: ``plateqp --quiet`` does).
Otherwise nothing at all is written, so output redirected to a file, a pipe or a JSON parser
stays clean. tqdm draws the bar when it is installed; else one counter line rewrites itself
and is wiped when the run ends. Messages are not this module's business: library code logs
them (``logging.getLogger(__name__)``); :func:`write` puts a line on standard error without
tearing an open bar (the command line's log handler uses it).
"""

from __future__ import annotations

import os
import sys
import weakref
from collections.abc import Iterable, Iterator

#: Process-wide switch (:func:`set_enabled`).
_ENABLED = True
#: Bars drawn now (so that :func:`write` can keep them whole); a bar left open by an exception
#: closes when it is dropped.
_OPEN: weakref.WeakSet = weakref.WeakSet()


def set_enabled(flag: bool) -> bool:
    """Turn every progress bar of this process on (the default: where :func:`shown` allows) or
    off; returns the previous setting (to restore it)."""
    global _ENABLED
    old, _ENABLED = _ENABLED, bool(flag)
    return old


def in_ci() -> bool:
    """True when the environment variable CI says a continuous-integration run."""
    return os.environ.get("CI", "").strip().lower() in ("1", "true", "yes")


def shown(enabled: bool = True, stream=None) -> bool:
    """Whether a bar asked for with ``enabled`` is drawn on ``stream`` (default: standard error)."""
    if not (enabled and _ENABLED) or in_ci():
        return False
    stream = sys.stderr if stream is None else stream
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):  # no isatty, or a closed stream
        return False


class Progress:
    """A progress bar on standard error (see the module docstring for when it is drawn).

    ``total``: the number of steps, or None when unknown (a counter without an end).
    ``update(k)`` advances, ``moveto(n)`` sets the count, ``describe(text)`` changes the label,
    ``close()`` removes the bar; usable as a context manager. ``n`` counts even when hidden.
    """

    def __init__(self, total: int | None, desc: str = "", enabled: bool = True):
        self.total, self.desc, self.n = total, desc, 0
        self.enabled = shown(enabled) and (total is None or total > 0)
        self.bar = None
        self._width = 0
        if not self.enabled:
            return
        self.stream = sys.stderr
        try:
            from tqdm import tqdm
        except ImportError:
            self._line()
        else:
            self.bar = tqdm(total=total, desc=desc, file=self.stream, leave=False, dynamic_ncols=True)
        _OPEN.add(self)

    def _line(self):
        text = f"{self.desc}: {self.n}" + (f"/{self.total}" if self.total is not None else "")
        self.stream.write("\r" + text.ljust(self._width))
        self.stream.flush()
        self._width = max(self._width, len(text))

    def update(self, k: int = 1) -> None:
        self.moveto(self.n + k)

    def moveto(self, n: int) -> None:
        """Set the count to ``n`` (forward or back)."""
        step, self.n = n - self.n, n
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.update(step)
        else:
            self._line()

    def describe(self, desc: str) -> None:
        self.desc = desc
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.set_description(desc)
        else:
            self._line()

    def close(self) -> None:
        if not self.enabled:
            return
        self.enabled = False
        _OPEN.discard(self)
        if self.bar is not None:
            self.bar.close()
        else:  # wipe the counter line
            self.stream.write("\r" + " " * self._width + "\r")
            self.stream.flush()

    def __del__(self):
        try:
            self.close()
        except Exception:  # noqa: BLE001 - at interpreter exit the stream may be gone
            pass

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def track(iterable: Iterable, desc: str = "", total: int | None = None, enabled: bool = True) -> Iterator:
    """Yield the items of ``iterable`` with a :class:`Progress` bar that advances after each
    (``total`` defaults to ``len(iterable)`` when it has one); the bar closes when the loop ends
    or is left."""
    if total is None:
        try:
            total = len(iterable)  # type: ignore[arg-type]
        except TypeError:
            total = None
    bar = Progress(total, desc, enabled)
    try:
        for item in iterable:
            yield item
            bar.update()
    finally:
        bar.close()


def write(line: str) -> None:
    """Write one line on standard error, above any open bar (tqdm redraws it after)."""
    if any(b.bar is not None for b in _OPEN):
        from tqdm import tqdm

        tqdm.write(line, file=sys.stderr)
        return
    bars = list(_OPEN)
    if bars:  # a counter line: wipe it, write, redraw
        for b in bars:
            b.stream.write("\r" + " " * b._width + "\r")
        sys.stderr.write(line + "\n")
        for b in bars:
            b._line()
        sys.stderr.flush()
        return
    sys.stderr.write(line + "\n")
    sys.stderr.flush()


__all__ = ["Progress", "in_ci", "set_enabled", "shown", "track", "write"]
