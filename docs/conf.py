"""Sphinx configuration of plateqp's documentation (build: see docs/README.md)."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import plateqp  # noqa: E402

project = "plateqp"
author = "the plateqp developers"
release = version = plateqp.__version__
extensions = ["myst_nb", "sphinx.ext.autodoc", "sphinx.ext.autosummary", "sphinx.ext.napoleon", "sphinx.ext.mathjax", "sphinx.ext.viewcode"]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}  # .rst first: autosummary writes its stubs so
nb_execution_mode = "off"  # the lessons are committed executed (tests/test_notebooks.py runs them)
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
exclude_patterns = ["_build", "README.md"]
myst_heading_anchors = 3
html_theme = "furo"
html_title = f"plateqp {release}"
autodoc_member_order = "bysource"
autodoc_typehints = "none"
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False, "ignore-module-all": True}
nitpicky = False
# what the docstrings name but Sphinx cannot resolve inside this project: third-party types
nitpick_ignore_regex = [(r"py:.*", r"(np|numpy|scipy|sp|xr|xarray|pd|pandas|matplotlib|cvxpy)\..*")]
autosummary_generate = True
autosummary_ignore_module_all = True
napoleon_google_docstring = False
napoleon_numpy_docstring = True


def _bars(app, what, name, obj, options, lines):
    """The docstrings write absolute values and norms as |w| and ‖x‖, which reST would read as
    substitutions: escape the bars (plateqp's docstrings use no substitutions)."""
    import re

    for i, line in enumerate(lines):
        lines[i] = re.sub(r"(?<![\\`])\|(?=\S)([^|`]*?\S)\|", r"\\|\1\\|", line)


def setup(app):
    app.connect("autodoc-process-docstring", _bars)
napoleon_use_ivar = True  # an "Attributes" section as fields, not objects a dataclass's own members repeat
# Python cross-references in docstrings are not resolved strictly (nitpicky off): docstrings name
# internal helpers and short names (m, n, shape) that several classes define. Links between the
# pages and to missing documents still fail the build.
suppress_warnings = ["ref.python"]


def _scene_keys():
    """The reference of every scene key, written from the scene's dataclasses before the build."""
    from plateqp.model.schema import markdown

    path = Path(__file__).parent / "guide" / "scene-keys.md"
    text = markdown()
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


_scene_keys()


def _lessons():
    """The course's lessons (notebooks/*.ipynb, committed with their outputs) copied beside the
    course page, which lists them; the copies are not committed."""
    import shutil

    src = ROOT / "notebooks"
    dst = Path(__file__).parent / "lessons"
    dst.mkdir(exist_ok=True)
    for nb in sorted(src.glob("[0-9][0-9]_*.ipynb")):
        target = dst / nb.name
        if not target.exists() or target.read_bytes() != nb.read_bytes():
            shutil.copyfile(nb, target)


_lessons()
