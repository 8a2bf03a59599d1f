"""The course: each lesson is a jupytext percent script paired with its .ipynb (committed with
outputs), and executing it checks its own physics and its exercises' solutions (asserts inside).

A lesson has learning goals, at least 300 words of prose, at least one figure, 2 to 4 exercises
(a markdown cell opening with a heading "Exercise", followed by a code cell whose `assert`
checks the solution) and a summary."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
jupytext = pytest.importorskip("jupytext")
pytest.importorskip("ipykernel")

HERE = Path(__file__).resolve().parent.parent / "notebooks"
LESSONS = sorted(HERE.glob("[0-9][0-9]_*.py"))
EXERCISE = re.compile(r"^#+\s*Exercise\b", re.MULTILINE)
WORD = re.compile(r"[A-Za-z][A-Za-z'’-]*")


def words(nb) -> int:
    return sum(len(WORD.findall(c.source)) for c in nb.cells if c.cell_type == "markdown")


def exercises(nb) -> list[int]:
    """The indices of the markdown cells that set an exercise."""
    return [i for i, c in enumerate(nb.cells) if c.cell_type == "markdown" and EXERCISE.search(c.source)]


def images(nb) -> list:
    return [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
            if "image/png" in o.get("data", {})]


def test_the_course_is_numbered_as_read():
    assert len(LESSONS) >= 10
    numbers = [int(p.name[:2]) for p in LESSONS]
    assert numbers == list(range(1, len(LESSONS) + 1)), numbers
    assert not (HERE / "make_notebooks.py").exists()
    index = (HERE / "README.md").read_text()
    for p in LESSONS:
        assert p.with_suffix(".ipynb").name in index, f"notebooks/README.md does not list {p.stem}"


def test_no_python_file_in_notebooks_is_over_600_lines():
    for p in HERE.glob("*.py"):
        n = len(p.read_text().splitlines())
        assert n <= 600, f"{p.name} has {n} lines"


def test_every_notebook_is_a_lesson():
    """No stray .ipynb without its source."""
    assert sorted(p.stem for p in HERE.glob("*.ipynb")) == [p.stem for p in LESSONS]


@pytest.mark.parametrize("path", LESSONS, ids=lambda p: p.stem)
def test_lesson_is_paired_and_committed_with_outputs(path):
    text = jupytext.reads(path.read_text(), fmt="py:percent")
    committed = nbformat.read(path.with_suffix(".ipynb"), as_version=4)
    ours = [(c.cell_type, c.source) for c in text.cells]
    theirs = [(c.cell_type, c.source) for c in committed.cells]
    assert ours == theirs, f"{path.with_suffix('.ipynb').name} is out of sync with {path.name}"
    assert images(committed), f"{path.with_suffix('.ipynb').name} is committed without its figures"


@pytest.mark.parametrize("path", LESSONS, ids=lambda p: p.stem)
def test_lesson_structure(path):
    nb = jupytext.reads(path.read_text(), fmt="py:percent")
    prose = "\n".join(c.source for c in nb.cells if c.cell_type == "markdown")
    assert re.search(r"^#+\s*Learning goals", prose, re.MULTILINE), f"{path.name}: no learning goals"
    assert re.search(r"^#+\s*Summary", prose, re.MULTILINE), f"{path.name}: no summary"
    assert words(nb) >= 300, f"{path.name}: {words(nb)} words of prose"
    found = exercises(nb)
    assert 2 <= len(found) <= 4, f"{path.name}: {len(found)} exercises"
    for i in found:
        solution = nb.cells[i + 1] if i + 1 < len(nb.cells) else None
        assert solution is not None and solution.cell_type == "code" and "assert" in solution.source, \
            f"{path.name}: exercise at cell {i} has no checked solution after it"


@pytest.mark.parametrize("path", LESSONS, ids=lambda p: p.stem)
def test_lesson_runs(path, tmp_path):
    nb = jupytext.reads(path.read_text(), fmt="py:percent")
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    client = nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()  # raises CellExecutionError on any failing cell or exercise check
    assert images(nb), f"{path.name} shows no figure"
    printed = "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code"
                      for o in c.get("outputs", []) if o.get("output_type") == "stream")
    assert "Copyright (c)" not in printed, f"{path.name} prints a solver's licence banner"
