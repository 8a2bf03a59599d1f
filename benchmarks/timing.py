"""Timing helpers shared by the benchmark scripts: CPU time of one call, and one call in a
child forked from the benchmark's process (every route then starts from the same heap)."""

from __future__ import annotations

import time


def cpu(fn):
    t0 = time.process_time()
    out = fn()
    return time.process_time() - t0, out


def _in_child(conn, fn) -> None:
    try:
        conn.send(fn())
    except BaseException as exn:  # sent back and raised in the parent, not lost
        conn.send(RuntimeError(f"{type(exn).__name__}: {exn}"))
    finally:
        conn.close()


def forked(fn):
    """``fn()`` (returning something small to pickle) in a child forked from this process, where
    fork exists (Linux): every route then starts from the same heap and the same imports, so
    the order the routes run in does not move their times. Run one after another in one
    process, the same route (auto's choice and pdas/primal) took 1.0-1.8 s at 256² with 9
    posts depending on which route freed its memory before it (the primal formulation's
    copies of K paid their pages again). Elsewhere ``fn()`` runs here."""
    import multiprocessing

    if "fork" not in multiprocessing.get_all_start_methods():
        return fn()
    ctx = multiprocessing.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_in_child, args=(child, fn))
    proc.start()
    child.close()
    try:
        out = parent.recv()
    except EOFError:
        out = RuntimeError(f"the child ended without an answer (exit code {proc.exitcode})")
    proc.join()
    if isinstance(out, BaseException):
        raise out
    return out
