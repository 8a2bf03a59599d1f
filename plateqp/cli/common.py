"""Helpers shared by the ``plateqp`` subcommands: argument parsing, ``--out`` checked before any
work, solver output kept off standard output, the memory limit, and what goes to standard
error (``--quiet`` / ``--verbose``: log messages, progress bars, warnings).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import os
import stat
import sys
import warnings
from pathlib import Path


from .. import scenes
from ..backends import get_backend
from ..accuracy import accuracy_tol
from ..errors import PlateQPError, ProblemError, SceneError, SolverError
from ..model.scene import Scene
from .. import progress

#: The log of the command line itself (notes such as "meshio is not installed").
log = logging.getLogger("plateqp.cli")


class _StderrHandler(logging.Handler):
    """Log records as lines on the standard error of the moment (tests and ``_stdout_to_stderr``
    swap it), above any open progress bar."""

    def emit(self, record):
        try:
            progress.write(self.format(record))
        except Exception:  # noqa: BLE001 - logging must not break the command
            self.handleError(record)


@contextlib.contextmanager
def _output(quiet: bool = False, verbose: int = 0):
    """While a command runs: plateqp's log messages on standard error (WARNING and above; with
    ``verbose`` 1 INFO, 2 or more DEBUG; with ``quiet`` ERROR only), progress bars on (off
    with ``quiet``; they still show only on a terminal), Python warnings ignored with
    ``quiet``. The library's own loggers are configured here, never the root logger; all is
    restored afterwards."""
    top = logging.getLogger("plateqp")
    level = logging.ERROR if quiet else (logging.WARNING, logging.INFO)[verbose] if verbose < 2 else logging.DEBUG
    handler = _StderrHandler(level)
    handler.setFormatter(logging.Formatter("plateqp: %(levelname)s %(name)s: %(message)s" if verbose
                                           else "plateqp: %(message)s"))
    old_level = top.level
    top.addHandler(handler)
    top.setLevel(level)
    was = progress.set_enabled(not quiet)
    try:
        with warnings.catch_warnings():
            if quiet:
                warnings.simplefilter("ignore")
            yield
    finally:
        progress.set_enabled(was)
        top.removeHandler(handler)
        top.setLevel(old_level)


def _probe(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"--probe wants X,Y (got {text!r})") from None
    return x, y


def _accuracy(text: str):
    """--accuracy: a preset, "auto", or a tolerance such as 1e-7."""
    if text in ("low", "default", "high", "auto"):
        return text
    try:
        return accuracy_tol(text)
    except PlateQPError as exn:
        raise argparse.ArgumentTypeError(f"{exn} (or auto)") from None


def _target(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not 1e-8 <= v < 1.0:
        raise argparse.ArgumentTypeError(f"--target wants a relative error between 1e-8 and 1 (got {text!r})")
    return v


def _options(text: str | None) -> dict | None:
    """--options: a JSON object, or a one-line error naming what is wrong with it."""
    if not text:
        return None
    try:
        opts = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exn:
        raise ProblemError(f"--options: not valid JSON ({getattr(exn, 'msg', 'nested too deep')})") from None
    if not isinstance(opts, dict):
        raise ProblemError(f"--options: must be a JSON object such as '{{\"max_iter\": 100}}' (got {type(opts).__name__})")
    return opts


def _backend_name(name: str) -> str:
    """An unknown backend is bad input (exit 2), found before any work."""
    if name != "auto":
        try:
            get_backend(name)
        except SolverError as exn:  # unknown or not installed: what was asked is not there
            raise ProblemError(f"--backend: {exn}") from None
    return name


def _out_dir(text: str, files: list[str], force: bool) -> Path:
    """Check ``--out`` before any work (:mod:`plateqp.io.safe`): a folder, not a link, made if
    missing, writable, where none of ``files`` exists (unless ``force``) and nothing on the way
    to them is a link."""
    from ..io.safe import check_target, out_folder

    label = f"--out {text}"
    out = out_folder(text, label=label)
    for f in files:
        check_target(out / f, force=force, label=label, root=out)
    return out


@contextlib.contextmanager
def _stdout_to_stderr():
    """Send everything written to standard output (Python's and the C libraries') to standard
    error while the block runs; the command's own output is printed after it."""
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:  # no file descriptor 1 (embedded): Python-level redirection only
        saved = None
    try:
        if saved is not None:
            os.dup2(2, 1)
        with contextlib.redirect_stdout(sys.stderr):
            yield
    finally:
        sys.stdout.flush()
        if saved is not None:
            try:
                sys.__stdout__.flush()
            except (OSError, ValueError, AttributeError):
                pass
            os.dup2(saved, 1)
            os.close(saved)


def _set_memory_limit(text: str | None) -> None:
    if text:
        from ..model.memory import MEMORY_ENV, parse_bytes
        parse_bytes(text, "--max-memory")
        os.environ[MEMORY_ENV] = text  # worker processes inherit it


def _scene_or_builtin(text: str) -> Scene:
    """A scene file, or the name of a built-in scene (``plateqp demo`` lists them)."""
    path = Path(text)
    if not path.exists():
        if text in scenes.names():
            return scenes.load(text)
        raise SceneError(f"{text}: no such file, nor a built-in scene ({', '.join(scenes.names())})")
    # a FIFO, a device or a folder: refused before it is opened (reading a FIFO blocks)
    if not stat.S_ISREG(path.stat().st_mode):
        raise SceneError(f"{text}: is not a regular file (a FIFO, a device or a folder); name a scene file")
    return Scene.from_toml(path)


def _numbers(text: str, what: str, cast=float) -> list:
    try:
        vals = [cast(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise PlateQPError(f"{what}: a comma-separated list of numbers (got {text!r})") from None
    if not vals:
        raise PlateQPError(f"{what}: empty")
    return vals
