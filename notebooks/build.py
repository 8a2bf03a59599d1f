"""Pairs each lesson's source (NN_name.py, a jupytext percent script) with its notebook, executed
with outputs: python notebooks/build.py [NN_name.py ...] (every lesson when none is named)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import jupytext
import nbclient
import nbformat

HERE = Path(__file__).resolve().parent
KERNEL = {"name": "python3", "display_name": "Python 3", "language": "python"}


def build(source: Path) -> float:
    nb = jupytext.reads(source.read_text(), fmt="py:percent")
    nb.metadata["kernelspec"] = KERNEL
    nb.metadata.pop("jupytext", None)
    start = time.perf_counter()
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(HERE)}}).execute()
    nbformat.write(nb, source.with_suffix(".ipynb"))
    return time.perf_counter() - start


if __name__ == "__main__":
    names = [HERE / Path(a).name for a in sys.argv[1:]] or sorted(HERE.glob("[0-9][0-9]_*.py"))
    for path in names:
        print(f"{path.name}: executed in {build(path):.1f} s")
