"""Where the values of a sweep are solved: this process, local worker processes, any
:class:`concurrent.futures.Executor` or a Dask ``distributed.Client`` (:func:`connect` makes
one on an existing cluster from its scheduler's address). The progress bar is
:class:`plateqp.progress.Progress` (importable from here too, its old home).

Every runner has the same two calls: ``submit(fn, *args)`` and ``as_completed(tasks)``, which
yields (task, future) pairs as they finish (in order for :class:`Serial`, which runs each task
when its result is asked for), ``close()`` (wait for what runs) and ``abort()`` (on Ctrl-C or
SIGTERM: cancel what has not started and stop our own worker processes at once). Local worker
processes start from a fresh interpreter (forkserver/spawn), never by forking a process whose
numerical libraries have run threads, and ignore SIGINT: a Ctrl-C at the terminal reaches the
whole process group, and the sweep, not each worker, decides what happens (it stops them).
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import os
import pickle
import signal
import threading
import logging

from ..errors import ClusterError, ProblemError
from ..progress import Progress  # noqa: F401 - its old home: importable from here too

logger = logging.getLogger(__name__)

#: ``executor=None`` runs fewer values than this in the calling process.
SERIAL_BELOW = 8


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity where the system says, else all)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


class Serial:
    """Runs each task when its result is asked for, so progress advances as it goes."""

    kind = "serial"
    workers = 1
    rows = None

    class _Task:
        def __init__(self, fn, args):
            self.fn, self.args = fn, args

    def submit(self, fn, *args):
        return self._Task(fn, args)

    def as_completed(self, tasks):
        for t in tasks:
            fut: cf.Future = cf.Future()
            try:
                fut.set_result(t.fn(*t.args))
            except Exception as exn:  # pragma: no cover - tasks catch their own errors
                fut.set_exception(exn)
            yield t, fut

    def close(self):
        pass

    def abort(self):
        pass


class SignalGate:
    """Holds SIGINT and SIGTERM back while the calling thread is inside concurrent.futures or
    multiprocessing code, and acts on them when it leaves.

    A KeyboardInterrupt raised there can land between a lock's acquire and the ``try`` that
    releases it (``cf.wait`` takes every future's lock; a queue's ``get`` its reader lock).
    The executor's manager thread then blocks for ever on that lock as it marks the futures
    of the stopped workers, and the interpreter's exit blocks with it, as it joins that
    thread. :meth:`open` puts a handler in front of every Python-level handler of the two
    signals (in the main thread only: elsewhere Python runs no signal handlers); inside
    :meth:`held` a signal is recorded, and on leaving it the first one recorded goes to the
    handler that was in place (SIGINT's default raises KeyboardInterrupt there, outside the
    library's locks). :meth:`close` puts the handlers back."""

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self):
        # the handlers this gate stands in front of (kept after close(): a handler of ours that
        # other code put back then still hands the signal on)
        self.before: dict = {}
        self.is_open = False
        self.holding = False
        self.pending: list = []

    def open(self) -> "SignalGate":
        if threading.current_thread() is threading.main_thread():
            for sig in self.SIGNALS:
                handler = signal.getsignal(sig)
                if callable(handler):
                    self.before[sig] = handler
                    signal.signal(sig, self._on_signal)
            self.is_open = bool(self.before)
        return self

    def _on_signal(self, signum, frame):
        if self.holding:
            self.pending.append((signum, frame))
        else:
            self.before[signum](signum, frame)

    @contextlib.contextmanager
    def held(self, act: bool = True):
        """The block runs with the signals held; on leaving it the first that came is handed
        on (``act``) or dropped (``act=False``: the block is the stopping itself)."""
        if not self.is_open or threading.current_thread() is not threading.main_thread():
            yield
            return
        self.holding = True
        try:
            yield
        finally:
            self.holding = False
            got, self.pending = self.pending, []
            if got and act:
                signum, frame = got[0]
                self.before[signum](signum, frame)

    def close(self) -> None:
        if not self.is_open:
            return
        self.is_open = False
        for sig, handler in self.before.items():
            if signal.getsignal(sig) == self._on_signal:
                signal.signal(sig, handler)


class Futures:
    """A concurrent.futures executor (ours or the user's) or a Dask distributed Client.

    ``rows``: for our own worker processes, the queue on which they send each row as soon as
    it is solved (:func:`stream_row`), so that the sweep stores it then, not when the whole
    chunk of values returns; None for other executors (the sweep then sends one value per
    task)."""

    def __init__(self, executor, own: bool, dask: bool, workers: int, rows=None):
        self.ex, self.own, self.dask, self.workers = executor, own, dask, workers
        self.kind = "dask" if dask else "futures"
        self.submitted: list = []
        self.rows = rows
        self.gate = SignalGate() if dask else SignalGate().open()

    def drain(self):
        """The rows the workers have sent so far: a list of (token, index, row), without waiting."""
        import queue

        out = []
        with self.gate.held():  # a KeyboardInterrupt inside get() could leave the queue's lock held
            while self.rows is not None:
                try:
                    out.append(self.rows.get_nowait())
                except (queue.Empty, OSError, ValueError, EOFError):
                    break
        return out

    def wait_any(self, futs, timeout: float = 0.1):
        """The futures of ``futs`` done within ``timeout`` seconds (not for Dask). A Ctrl-C or
        SIGTERM that comes meanwhile is acted on once the wait has returned (see
        :class:`SignalGate`)."""
        with self.gate.held():
            done, _ = cf.wait(list(futs), timeout=timeout, return_when=cf.FIRST_COMPLETED)
        return done

    def submit(self, fn, *args):
        fut = self.ex.submit(fn, *args, pure=False) if self.dask else self.ex.submit(fn, *args)
        self.submitted.append(fut)
        return fut

    def as_completed(self, futs):
        if self.dask:
            from distributed import as_completed

            # the client's own loop: without it Dask looks for a default client (there may be none)
            for f in as_completed(list(futs), loop=self.ex.loop):
                yield f, f
        else:  # by short waits, each of which a signal does not interrupt (see wait_any)
            pending = set(futs)
            while pending:
                for f in self.wait_any(pending):
                    pending.discard(f)
                    yield f, f

    def close(self):
        try:
            if self.own:
                self.ex.shutdown(wait=True)
                self.rows.close()
        finally:
            self.gate.close()

    def abort(self, grace: float = 2.0):
        """Cancel every task not yet started; stop our own worker processes (SIGTERM, then
        SIGKILL after ``grace`` seconds), without waiting for the tasks they run, and then the
        executor's manager thread (``grace`` seconds at most). A user's executor or Dask client
        is left running (only our tasks are cancelled).

        The manager thread is joined because the interpreter's exit wakes it through a pipe
        that the thread closes as it ends: left running, the two raced and an exit after
        SIGTERM printed ``OSError: [Errno 9] Bad file descriptor`` with a traceback
        (concurrent.futures in Python 3.11; seen in a CI run of the SIGTERM interrupt test)."""
        try:
            with self.gate.held(act=False):  # a second Ctrl-C does not cut the stopping short
                self._abort(grace)
        finally:
            self.gate.close()

    def _abort(self, grace: float):
        for fut in self.submitted:
            try:
                fut.cancel()
            except Exception:  # noqa: BLE001 - a Dask client already closed: nothing to cancel
                pass
        if not self.own:
            return
        first = self._drain_within(grace)  # what the workers sent before they are stopped
        procs = list((getattr(self.ex, "_processes", None) or {}).values())
        manager = getattr(self.ex, "_executor_manager_thread", None)  # shutdown() forgets it
        self.ex.shutdown(wait=False, cancel_futures=True)
        for p in procs:
            if p.is_alive():
                p.terminate()
        for p in procs:
            p.join(grace)
            if p.is_alive():
                p.kill()
                p.join(grace)
        if manager is not None:
            manager.join(grace)
            if manager.is_alive():
                _forget_manager(manager)
        # the rows sent since (not where the first read is still stuck: it holds the queue)
        late = self._drain_within(grace) if first is not None else None
        self.drain_left = (first or []) + (late or [])
        if late is not None:
            self.rows.close()

    def _drain_within(self, grace: float):
        """:meth:`drain` in a thread given ``grace`` seconds, or None where it did not end: a
        worker stopped while writing a row leaves half a message in the pipe, and reading it
        would wait for ever (that row was never stored: it is not done)."""
        got: list = []
        reader = threading.Thread(target=lambda: got.extend(self.drain()), daemon=True)
        reader.start()
        reader.join(grace)
        return None if reader.is_alive() else got


#: Manager threads of our process pools that :meth:`Futures.abort` could not end.
_LEFT_RUNNING: list = []


def _forget_manager(thread) -> None:
    """A pool's manager thread that did not end after :meth:`Futures.abort` (blocked reading a
    result that a stopped worker left half written, say): the interpreter's exit would wait
    for it for ever (it joins every non-daemon thread), so it is recorded for
    :func:`exit_if_left_running`."""
    logger.warning("the worker pool's manager thread did not end within the grace time; not waiting for it")
    _LEFT_RUNNING.append(thread)


def left_running() -> list:
    """The manager threads of stopped pools still running (see :func:`exit_if_left_running`)."""
    return [t for t in _LEFT_RUNNING if t.is_alive()]


def exit_if_left_running(code: int) -> None:
    """End the process now with ``code`` (standard output and error flushed) if a stopped
    pool's manager thread still runs: the interpreter's own exit would wait for it for ever.
    Returns (does nothing) otherwise. For a command that has written all it had to write."""
    import sys

    if left_running():
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(code)


#: In a worker process of ours: the queue its rows go to as they are solved (see :class:`Futures`).
_ROWS = None


def _init_worker(rows=None):
    """Worker initializer: Ctrl-C is the parent's to handle (it stops the workers); ``rows`` is
    the queue for :func:`stream_row`."""
    global _ROWS
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _ROWS = rows


def _ignore_sigint():
    _init_worker(None)


def stream_row(token: str, index: int, row: dict) -> None:
    """In one of our worker processes, send a row to the sweep as soon as it is solved (nothing
    elsewhere: there the chunk's result carries it)."""
    if _ROWS is not None:
        _ROWS.put((token, index, row))


def mp_context():
    """Worker processes start from a clean server process ("forkserver"; "spawn" where there is
    none), never by forking this one: a fork after SuiteSparse/OpenMP or BLAS threads have run
    here deadlocks the workers (seen: both blocked on a futex after a 32x32 serial sweep)."""
    import multiprocessing as mp

    return mp.get_context("forkserver" if "forkserver" in mp.get_all_start_methods() else "spawn")


def is_dask(executor) -> bool:
    return type(executor).__module__.split(".")[0] == "distributed" and hasattr(executor, "submit")


#: Seconds :func:`connect` waits for a Dask scheduler to answer.
CONNECT_TIMEOUT = 10.0


def connect(address: str, timeout: float = CONNECT_TIMEOUT):
    """A Dask ``distributed.Client`` on the existing cluster whose scheduler is at ``address``
    (e.g. ``tcp://host:8786``), to pass as a sweep's ``executor`` (close it when done; the
    cluster keeps running).

    Raises
    ------
    ClusterError
        dask.distributed is not installed, or no scheduler answered within ``timeout`` seconds.
    """
    try:
        import distributed
    except ImportError:
        raise ClusterError(f"--scheduler {address}: dask.distributed is not installed "
                           "(pip install 'dask[distributed]')") from None
    if not isinstance(address, str) or not address.strip():
        raise ClusterError(f"--scheduler: a scheduler address such as tcp://host:8786 (got {address!r})")
    from distributed.comm import parse_address, parse_host_port

    try:  # a malformed address fails here, before a Client exists (its cleanup would print at exit)
        scheme, loc = parse_address(address)
        if scheme in ("tcp", "tls", "ws", "wss"):
            parse_host_port(loc)
    except ValueError as exn:
        raise ClusterError(f"--scheduler {address}: not a scheduler address such as tcp://host:8786 ({exn})") from None
    logger.info("connecting to the Dask scheduler at %s (timeout %g s)", address, timeout)
    try:
        client = distributed.Client(address, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError) as exn:
        why = str(exn).splitlines()[0] if str(exn) else type(exn).__name__
        raise ClusterError(f"--scheduler {address}: no Dask scheduler answered within {timeout:g} s ({why})") from None
    logger.info("connected: %d worker thread(s)", sum(client.nthreads().values()))
    return client


def make_runner(executor, n: int, max_workers: int, payload):
    """The runner for ``executor`` (see :func:`plateqp.studies.sweep.sweep`) and ``n`` tasks;
    ``payload``, what every task is sent, must pickle for local processes (else: this process)."""
    if executor == "serial" or (executor is None and n < SERIAL_BELOW) or max_workers <= 1 and executor is None:
        return Serial()
    if executor is None or executor in ("process", "processes"):
        try:
            pickle.dumps(payload)
        except Exception:
            logger.warning("the scene cannot be pickled (a Python callable in it?): sweeping in this process")
            return Serial()
        ctx = mp_context()
        rows = ctx.Queue()
        return Futures(cf.ProcessPoolExecutor(max_workers=max_workers, mp_context=ctx, initializer=_init_worker,
                                              initargs=(rows,)), True, False, max_workers, rows)
    if is_dask(executor):
        try:
            workers = max(1, sum(executor.nthreads().values()))
        except Exception:
            workers = max_workers
        return Futures(executor, False, True, workers)
    if isinstance(executor, cf.Executor):
        return Futures(executor, False, False, getattr(executor, "_max_workers", max_workers) or max_workers)
    raise ProblemError(f"executor must be None, 'serial', 'process', a concurrent.futures.Executor or a "
                       f"dask distributed Client (got {executor!r})")


__all__ = ["CONNECT_TIMEOUT", "SERIAL_BELOW", "available_cores", "connect", "exit_if_left_running", "left_running",
           "stream_row", "Futures", "Progress", "Serial", "SignalGate", "is_dask", "make_runner", "mp_context"]
