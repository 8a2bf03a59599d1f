"""``plateqp sweep --scheduler ADDRESS``: the same sweep on an existing Dask cluster, with its row
store (``--store``) kept and resumed after an interruption; clear one-line errors when the
cluster cannot be used.

The cluster is a ``distributed.LocalCluster`` in this process (threads, over TCP so that its
address is a real ``tcp://host:port``). References: statics (every row's reactions sum to the
heave slab's total load, 62 000 kgf) and a serial sweep of the same values, solved
independently in this process without a store.
"""

from __future__ import annotations

import json
import socket
import sys

import numpy as np
import pytest

import plateqp as pq
from plateqp import scenes
from plateqp.cli import main
from plateqp.errors import ClusterError
from plateqp.studies import sweep
from plateqp.studies import store as store_mod
from plateqp.studies import worker as worker_mod
from plateqp.studies.parallel import connect

distributed = pytest.importorskip("distributed")

VALUES = [-0.3, -0.2, -0.1, 0.0, 0.1]
TOTAL = 62000.0
ARGV = ["sweep", "heave", "--param", "supports.2.gap", "--values", ",".join(map(str, VALUES)), "--json"]


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, protocol="tcp://",
                                  host="127.0.0.1", dashboard_address=None) as c:
        yield c


@pytest.fixture(scope="module")
def serial():
    return sweep(pq.Scene.from_toml(scenes.path("heave")), "supports.2.gap", VALUES, executor="serial",
                 progress=False)


def _same_as_serial(rows, breakpoints, serial):
    assert [r["value"] for r in rows] == VALUES
    for row, ref in zip(rows, serial.rows):
        assert sum(row["reactions"]) == pytest.approx(TOTAL, rel=1e-9)  # statics
        np.testing.assert_allclose(row["reactions"], ref["reactions"], rtol=1e-9, atol=1e-9 * TOTAL)
        assert row["active"] == ref["active"]
    assert [(b["between"], b["before"], b["after"]) for b in breakpoints] == \
        [(b["between"], b["before"], b["after"]) for b in serial.to_dict()["breakpoints"]]  # JSON: numbered from 1
    for b, ref in zip(breakpoints, serial.breakpoints):
        assert b["at"] == pytest.approx(ref["at"], rel=1e-9, abs=1e-12)


def _solves(monkeypatch):
    """Counts the values the cluster's workers (threads of this process) solve."""
    seen = []
    real = worker_mod.solve_value

    def counting(ctx, value, start):
        seen.append(value)
        return real(ctx, value, start)

    monkeypatch.setattr(worker_mod, "solve_value", counting)
    return seen


def test_cli_sweep_on_a_cluster_equals_a_serial_sweep(cluster, serial, tmp_path, capsys, monkeypatch):
    addr = cluster.scheduler_address
    assert addr.startswith("tcp://")
    seen = _solves(monkeypatch)
    assert main(ARGV + ["--scheduler", addr, "--store", str(tmp_path / "rows.jsonl")]) == 0
    d = json.loads(capsys.readouterr().out)
    _same_as_serial(d["rows"], d["breakpoints"], serial)
    assert sorted(v for v in seen if v in VALUES) == sorted(VALUES)  # the values ran on the cluster's workers
    lines = (tmp_path / "rows.jsonl").read_text().splitlines()
    assert sorted(json.loads(x)["index"] for x in lines[1:]) == [0, 1, 2, 3, 4]
    with distributed.Client(addr, set_as_default=False) as again:  # the cluster is left running
        assert sum(again.nthreads().values()) == 2


def test_an_interrupted_cluster_sweep_keeps_its_rows_and_resumes(cluster, serial, tmp_path, capsys, monkeypatch):
    store = tmp_path / "rows.jsonl"
    real = store_mod.RowStore.append
    kept = []

    def ctrl_c_after_two(self, index, row):  # a Ctrl-C in the main process once two rows are on disk
        if len(kept) == 2:
            raise KeyboardInterrupt
        kept.append(index)
        real(self, index, row)

    monkeypatch.setattr(store_mod.RowStore, "append", ctrl_c_after_two)
    argv = ARGV + ["--scheduler", cluster.scheduler_address, "--store", str(store)]
    assert main(argv) == 130
    part = json.loads(capsys.readouterr().out)
    assert part["interrupted"]["done"] >= 2  # (the row being stored when Ctrl-C came is in memory, not on disk)
    lines = store.read_text().splitlines()
    assert sorted(json.loads(x)["index"] for x in lines[1:]) == sorted(kept)
    monkeypatch.undo()
    seen = _solves(monkeypatch)
    assert main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    _same_as_serial(d["rows"], d["breakpoints"], serial)
    # the resumed run solves only the values the store lacked (bisection solves are other values)
    assert sorted(v for v in seen if v in VALUES) == sorted(VALUES[i] for i in range(5) if i not in kept)
    assert sorted(json.loads(x)["index"] for x in store.read_text().splitlines()[1:]) == [0, 1, 2, 3, 4]


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]  # free once closed: nothing listens there


@pytest.mark.parametrize("extra, words", [
    (["--scheduler", "tcp://127.0.0.1:{port}", "--scheduler-timeout", "0.5"], "no Dask scheduler answered within 0.5 s"),
    (["--scheduler", "nonsense"], "not a scheduler address"),
    (["--scheduler", "tcp://127.0.0.1:{port}", "--workers", "2"], "--workers and --scheduler: choose one"),
])
def test_cli_cluster_errors_are_one_line(capsys, extra, words):
    port = _closed_port()
    assert main(ARGV + [a.format(port=port) for a in extra]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and words in err and "Traceback" not in err


def test_without_dask_a_cluster_is_a_clear_error(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "distributed", None)  # as if it were not installed
    with pytest.raises(ClusterError, match="not installed"):
        connect("tcp://127.0.0.1:8786")
    assert main(ARGV + ["--scheduler", "tcp://127.0.0.1:8786"]) == 2
    assert "dask.distributed is not installed" in capsys.readouterr().err
