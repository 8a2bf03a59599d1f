"""README.md's examples run as they are written, and say what they claim.

References: statics (the reactions of a plate on supports balance its load: 100 + 5·1 = 105 for
the Python example; for the scene file the posts and the simply supported edge together carry
the load), the README's length (the first screen is a summary: at most 150 lines) and its links.
"""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import numpy as np
import pytest

import plateqp as pq

README = Path(__file__).resolve().parents[1] / "README.md"


def blocks(lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def test_readme_is_two_screens():
    assert len(README.read_text(encoding="utf-8").splitlines()) <= 150


def test_the_python_example_runs_and_balances():
    (code,) = blocks("python")
    out = io.StringIO()
    ns: dict = {}
    with contextlib.redirect_stdout(out):
        exec(compile(code, "README.md", "exec"), ns)  # noqa: S102 - the README's own example
    result = ns["result"]
    assert result.kkt.ok and result.status == pq.Status.OPTIMAL
    assert result.reactions.sum() == pytest.approx(105.0, rel=1e-8)
    assert "OPTIMAL True" in out.getvalue()


def test_the_scene_file_example_solves(tmp_path):
    pytest.importorskip("gmsh")
    (toml,) = blocks("toml")
    path = tmp_path / "raft.toml"
    path.write_text(toml, encoding="utf-8")
    scene = pq.Scene.from_toml(path)
    result = pq.solve(scene)
    assert result.kkt.ok and result.status == pq.Status.OPTIMAL
    assert len(result.reactions) == 4 and np.all(result.reactions >= 0)
    # statics: the load is carried by the posts and the simply supported edge (f − K u on its dofs)
    m = result.model
    edge = np.zeros(m.n_full)
    edge[m.fixed] = (m.f_full - m.K_full @ result.u)[m.fixed]
    w_dofs = slice(0, None, m.element.ndof_node)
    load = m.f_full[w_dofs].sum()
    assert result.reactions.sum() + edge[w_dofs].sum() == pytest.approx(load, rel=1e-8)
    assert result.reactions[0] > 0  # the heaved post carries load


def test_the_readme_links_exist():
    root = README.parent
    for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", README.read_text(encoding="utf-8")):
        if "://" not in target:
            assert (root / target).exists(), target
