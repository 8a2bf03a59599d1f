"""Stopping a sweep's own worker processes never waits for ever on half a row: a worker stopped
while writing a row to the sweep's queue leaves a partial message in the pipe, and reading it
blocks until the rest comes, which it never does."""

import os
import struct
import time

import pytest

from plateqp.studies.parallel import make_runner


def test_abort_does_not_wait_for_half_a_row():
    runner = make_runner("process", 4, 2, None)
    fut = runner.submit(time.sleep, 0.0)
    fut.result(timeout=60)  # the workers are up
    # a message header announcing 1000 bytes, 3 of them written: what a worker killed mid-write leaves
    os.write(runner.rows._writer.fileno(), struct.pack("!i", 1000) + b"abc")
    t0 = time.monotonic()
    runner.abort(grace=0.5)
    assert time.monotonic() - t0 < 10.0
    assert runner.drain_left == []  # the half row is not a row done


STUCK_MANAGER = """
import sys, time
from plateqp.studies.parallel import exit_if_left_running, left_running, make_runner

if __name__ == "__main__":
    runner = make_runner("process", 4, 2, None)
    futs = [runner.submit(time.sleep, 30.0) for _ in range(2)]
    t0 = time.monotonic()
    while not all(f.running() for f in futs) and time.monotonic() - t0 < 60:
        time.sleep(0.05)
    # what a KeyboardInterrupt between cf.wait's lock acquires leaves: a future's lock held by
    # this thread, on which the manager thread blocks as it marks the stopped workers' futures
    futs[0]._condition.acquire()
    runner.abort(grace=0.5)
    print("aborted", len(left_running()), flush=True)
    exit_if_left_running(7)
"""


def test_a_manager_thread_stuck_after_abort_does_not_hold_the_exit(tmp_path):
    """The interpreter's exit joins a process pool's manager thread without a time limit; one
    that abort() could not end (here blocked on a future's lock) is named, and the command
    that has written its output ends the process with its exit code (without: the process
    never ended, as an interrupted sweep once did in CI)."""
    import subprocess
    import sys
    from pathlib import Path

    import plateqp as pq

    script = tmp_path / "stuck.py"
    script.write_text(STUCK_MANAGER)
    env = dict(os.environ, PYTHONPATH=str(Path(pq.__file__).resolve().parents[1]))
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, env=env)
    assert run.returncode == 7 and run.stdout.split() == ["aborted", "1"], run.stderr[-2000:]
    assert "did not end within the grace time" in run.stderr  # and it says so


@pytest.fixture
def keyboard_interrupt():
    """Python's own SIGINT handler (KeyboardInterrupt) in place for the test: a process started
    with SIGINT ignored (``cmd &`` from a shell without job control) has none, and nothing there
    would ever raise KeyboardInterrupt."""
    import signal

    before = signal.getsignal(signal.SIGINT)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


def test_a_signal_inside_the_gate_is_acted_on_when_the_block_ends(keyboard_interrupt):
    import signal

    from plateqp.studies.parallel import SignalGate

    gate = SignalGate().open()
    try:
        reached = []
        try:
            with gate.held():
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.05)  # Python runs its handlers between bytecodes: many have run here
                reached.append(True)
        except KeyboardInterrupt:
            interrupted = True
        else:
            interrupted = False
        assert reached and interrupted  # the block ran to its end, and then the Ctrl-C came
        with gate.held(act=False):  # the stopping itself: a second Ctrl-C is dropped
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)
        with pytest.raises(KeyboardInterrupt):  # outside a held block the handler acts at once
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(1.0)
    finally:
        gate.close()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_sigterm_handler_of_the_caller_gets_the_held_signal():
    import signal

    from plateqp.studies.parallel import SignalGate

    got = []
    old = signal.signal(signal.SIGTERM, lambda signum, frame: got.append(signum))
    try:
        gate = SignalGate().open()
        with gate.held():
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.05)
            assert got == []
        assert got == [signal.SIGTERM]
        gate.close()
        assert signal.getsignal(signal.SIGTERM) is not gate._on_signal
    finally:
        signal.signal(signal.SIGTERM, old)


def test_a_gate_handler_left_in_place_after_close_hands_on():
    """Another handler set over the gate's while it was open is left alone by close(); where
    that code later puts the gate's back, a signal still reaches the handler the gate stood
    in front of (not a KeyError inside a signal handler)."""
    import signal

    from plateqp.studies.parallel import SignalGate

    got = []
    old = signal.signal(signal.SIGTERM, lambda signum, frame: got.append(signum))
    try:
        gate = SignalGate().open()
        mine = signal.signal(signal.SIGTERM, lambda signum, frame: None)  # someone else's, on top
        gate.close()
        assert signal.getsignal(signal.SIGTERM) is not mine  # theirs stays: not ours to undo
        signal.signal(signal.SIGTERM, mine)  # they put ours back
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(0.05)
        assert got == [signal.SIGTERM]
    finally:
        signal.signal(signal.SIGTERM, old)
