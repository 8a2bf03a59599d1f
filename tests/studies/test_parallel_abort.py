"""Stopping a sweep's own worker processes never waits for ever on half a row: a worker stopped
while writing a row to the sweep's queue leaves a partial message in the pipe, and reading it
blocks until the rest comes, which it never does."""

import os
import struct
import time

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
