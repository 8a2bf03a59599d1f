"""The layering of plateqp, checked on its source with ``ast`` (no import is executed).

DESIGN.md: the data flow goes one way (scene → model → contact problem → backend → result →
studies, plots, report, cli). These tests hold the package to it:

- no import circle between plateqp's modules (imports inside functions count too: a lazy
  import is still a dependency);
- nothing below the command line imports ``plateqp.cli``;
- the backends know QPs and LCPs, never plates: ``plateqp.backends`` imports only the shared
  words (accuracy, errors), the linear algebra, and itself;
- CHOLMOD's bindings (cvxopt, scikit-sparse) are imported in ``plateqp.linalg`` only;
- no source file over :data:`MAX_LINES` lines (a file that needs a table of contents wants to
  be two files);
- no function over :data:`MAX_FUNCTION_LINES` lines in the model and contact floors (a body of
  stages wants its stages as functions), no module docstring over :data:`MAX_DOCSTRING_LINES`
  lines anywhere (docstrings state contracts; the design story belongs in the docs).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "plateqp"
MAX_LINES = 600

#: What plateqp.backends may import from plateqp (besides itself).
BACKEND_MAY_IMPORT = ("plateqp.accuracy", "plateqp.errors", "plateqp.linalg")
#: Third-party packages that bind CHOLMOD: only plateqp.linalg may import them.
CHOLMOD_BINDINGS = ("cvxopt", "sksparse")

#: Known failures, declared as data (the work they describe is not finished): each entry must still fail its
#: check, so that a fix removes it from here and nothing new can hide behind it.
KNOWN_TOO_LONG: set[str] = set()
KNOWN_CHOLMOD_OUTSIDE_LINALG: set[str] = set()
MAX_FUNCTION_LINES = 80
MAX_DOCSTRING_LINES = 60
#: The model floor (scene to matrices) and the contact floor (the contact problem and its
#: answer): the modules whose functions :data:`MAX_FUNCTION_LINES` holds.
FLOORS = ("plateqp.model.scene", "plateqp.model.checks", "plateqp.model.parts", "plateqp.model.geometry", "plateqp.model.crossings", "plateqp.model.paths", "plateqp.model.grid", "plateqp.model.trimesh",
          "plateqp.model.elements", "plateqp.model.constraints", "plateqp.model.assembly",
          "plateqp.contact", "plateqp.backends.pdas")
#: the backends' active-set solver joined the floors with two bodies still to split into steps
KNOWN_LONG_FUNCTIONS: set[str] = {"plateqp.backends.pdas.dense:first_set", "plateqp.backends.pdas.driver:pdas"}
KNOWN_LONG_DOCSTRINGS: set[str] = set()


def module_name(path: Path) -> str:
    rel = path.relative_to(ROOT.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def sources() -> dict[str, Path]:
    return {module_name(p): p for p in sorted(ROOT.rglob("*.py"))}


def imports_of(name: str, path: Path) -> set[str]:
    """Every module ``name`` imports (absolute names), at any depth of the file."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.add(mod)
            for a in node.names:  # `from . import x` may import the submodule x
                out.add(f"{mod}.{a.name}")
    return out


def internal_graph() -> dict[str, set[str]]:
    """plateqp module → the plateqp modules it imports (names resolved to existing modules)."""
    mods = sources()
    graph = {}
    for name, path in mods.items():
        deps = set()
        for imp in imports_of(name, path):
            if imp in mods:
                deps.add(imp)
        deps.discard(name)
        graph[name] = deps
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle, or None (depth-first search, three colours)."""
    WHITE, GREY, BLACK = 0, 1, 2
    colour = dict.fromkeys(graph, WHITE)
    stack: list[str] = []

    def visit(v: str) -> list[str] | None:
        colour[v] = GREY
        stack.append(v)
        for w in sorted(graph[v]):
            # a package's __init__ importing its own submodules is not a cycle through them
            if v.startswith(w + ".") and w in graph:
                continue
            if colour[w] == GREY:
                return stack[stack.index(w):] + [w]
            if colour[w] == WHITE:
                found = visit(w)
                if found:
                    return found
        stack.pop()
        colour[v] = BLACK
        return None

    for v in sorted(graph):
        if colour[v] == WHITE:
            found = visit(v)
            if found:
                return found
    return None


def parent_init_edges(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """The graph without the edges from a submodule to the __init__ of its own package that
    merely re-exports: importing ``plateqp.contact.kkt`` runs ``plateqp.contact``'s __init__
    first anyway, so a cycle through it is the package's own re-exports, judged by its parts."""
    out = {}
    for v, deps in graph.items():
        out[v] = {w for w in deps if not (v.startswith(w + ".") or w == "plateqp")}
    return out


# -- the checks ---------------------------------------------------------------------------------


def test_the_checker_sees_a_cycle():
    """The cycle finder finds a planted cycle (a check that cannot fail is no check)."""
    g = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}
    assert find_cycle(g) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_relative_imports_are_resolved():
    mods = sources()
    imps = imports_of("plateqp.contact.pipeline", mods["plateqp.contact.pipeline"])
    assert "plateqp.model.assembly" in imps and "plateqp.contact.kkt" in imps


def test_no_import_cycle():
    cycle = find_cycle(parent_init_edges(internal_graph()))
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_nothing_below_the_cli_imports_it():
    graph = internal_graph()
    bad = sorted(m for m, deps in graph.items()
                 if any(d == "plateqp.cli" or d.startswith("plateqp.cli.") for d in deps)
                 and m != "plateqp.cli" and not m.startswith("plateqp.cli."))
    assert not bad, f"imports plateqp.cli from below it: {bad}"


def test_backends_know_no_plates():
    mods = sources()
    bad = []
    for name, path in mods.items():
        if not name.startswith("plateqp.backends"):
            continue
        for imp in imports_of(name, path):
            if imp.startswith("plateqp") and not imp.startswith("plateqp.backends") and not any(
                    imp == ok or imp.startswith(ok + ".") for ok in BACKEND_MAY_IMPORT) and imp != "plateqp":
                bad.append(f"{name} imports {imp}")
    assert not bad, bad


def test_cholmod_bindings_only_in_linalg():
    mods = sources()
    bad = {name for name, path in mods.items() if not name.startswith("plateqp.linalg")
           for imp in imports_of(name, path) if imp.split(".")[0] in CHOLMOD_BINDINGS}
    assert bad == KNOWN_CHOLMOD_OUTSIDE_LINALG, sorted(bad)


@pytest.mark.parametrize("path", sorted(ROOT.rglob("*.py")), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_source_file_is_too_long(path):
    n = len(path.read_text(encoding="utf-8").splitlines())
    rel = str(path.relative_to(ROOT))
    if rel in KNOWN_TOO_LONG:
        assert n > MAX_LINES, f"{rel} is now {n} lines: remove it from KNOWN_TOO_LONG"
    else:
        assert n <= MAX_LINES, f"{path.relative_to(ROOT.parent)} has {n} lines (> {MAX_LINES}): split it"


def test_known_failures_name_existing_files():
    """A known-too-long entry whose file is gone (moved, split) would pass silently: refuse it."""
    missing = sorted(rel for rel in KNOWN_TOO_LONG if not (ROOT / rel).is_file())
    assert not missing, f"KNOWN_TOO_LONG names files that do not exist: {missing}"


def long_functions() -> dict[str, int]:
    """``module:function`` → its length in lines, for the functions of the floors over the limit."""
    out = {}
    for name, path in sources().items():
        if not any(name == f or name.startswith(f + ".") for f in FLOORS):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_FUNCTION_LINES:
                    out[f"{name}:{node.name}"] = n
    return out


def test_the_floors_functions_are_short():
    found = long_functions()
    assert set(found) - KNOWN_LONG_FUNCTIONS == set(), f"functions over {MAX_FUNCTION_LINES} lines: {found}"
    fixed = KNOWN_LONG_FUNCTIONS - set(found)
    assert not fixed, f"{sorted(fixed)} are short now (or gone): remove them from KNOWN_LONG_FUNCTIONS"


def test_module_docstrings_state_contracts():
    long = {}
    for name, path in sources().items():
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
        if doc and len(doc.splitlines()) > MAX_DOCSTRING_LINES:
            long[name] = len(doc.splitlines())
    assert set(long) - KNOWN_LONG_DOCSTRINGS == set(), f"module docstrings over {MAX_DOCSTRING_LINES} lines: {long}"
    fixed = KNOWN_LONG_DOCSTRINGS - set(long)
    assert not fixed, f"{sorted(fixed)} are short now: remove them from KNOWN_LONG_DOCSTRINGS"


def test_the_length_checks_see_a_long_function(tmp_path, monkeypatch):
    """The function-length check finds a planted long function (a check that cannot fail is no check)."""
    pkg = tmp_path / "plateqp"
    (pkg / "model").mkdir(parents=True)
    (pkg / "model" / "scene.py").write_text("def f():\n" + "    x = 1\n" * MAX_FUNCTION_LINES + "    return x\n")
    monkeypatch.setattr(__import__(__name__), "ROOT", pkg)
    assert long_functions() == {"plateqp.model.scene:f": MAX_FUNCTION_LINES + 2}


# -- which mesh a module holds: asked only where meshes are made and elements chosen -------------
#: The mesh generators and element families: the only modules that may ask which kind of mesh
#: they hold.
MESH_KIND_MODULES = ("plateqp.model.grid", "plateqp.model.trimesh", "plateqp.model.elements")
#: Names a scene goes by, whose ``.triangles`` read asks which generator meshes it.
SCENE_NAMES = {"scene", "sc", "a", "b", "s", "self"}
#: Known remaining questions about the mesh kind, ``module:function`` → how many, declared as
#: data: each must still be there, so that removing one removes it from here.
KNOWN_MESH_KIND_BRANCHES: dict[str, int] = {
    # none: every question about the mesh kind is asked in a generator or an element
}


def _asks_mesh_kind(node: ast.AST) -> bool:
    """Whether ``node`` asks which kind of mesh is held: a scene's ``triangles``, a call of
    ``on_triangles``, a comparison with a ``cell_type`` or of ``grid_shape`` with None, an
    ``isinstance`` with Grid or TriMesh."""
    def name(n):
        return n.id if isinstance(n, ast.Name) else n.attr if isinstance(n, ast.Attribute) else None

    if isinstance(node, ast.Attribute) and node.attr == "triangles" and isinstance(node.ctx, ast.Load):
        return name(node.value) in SCENE_NAMES
    if isinstance(node, ast.Call):
        if name(node.func) == "on_triangles":
            return True
        if name(node.func) == "isinstance" and len(node.args) == 2:
            kinds = node.args[1].elts if isinstance(node.args[1], ast.Tuple) else [node.args[1]]
            return any(name(k) in ("Grid", "TriMesh") for k in kinds)
    if isinstance(node, ast.Compare):
        sides = [node.left, *node.comparators]
        if any(name(s) == "cell_type" for s in sides):
            return True
        return any(name(s) == "grid_shape" for s in sides) and any(
            isinstance(s, ast.Constant) and s.value is None for s in sides)
    return False


def mesh_kind_branches() -> dict[str, int]:
    """``module:function`` (``module:`` at module level) → how many questions about the kind of
    mesh it asks, outside :data:`MESH_KIND_MODULES`."""
    out: dict[str, int] = {}
    for name, path in sources().items():
        if any(name == m or name.startswith(m + ".") for m in MESH_KIND_MODULES):
            continue

        def visit(node, where, name=name):
            for child in ast.iter_child_nodes(node):
                inner = where
                if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                    inner = f"{where}.{child.name}" if where else child.name
                if _asks_mesh_kind(child):
                    key = f"{name}:{inner}"
                    out[key] = out.get(key, 0) + 1
                visit(child, inner, name)

        visit(ast.parse(path.read_text(encoding="utf-8")), "")
    return out


def test_no_code_asks_which_mesh_it_holds():
    found = mesh_kind_branches()
    new = {k: n for k, n in found.items() if n > KNOWN_MESH_KIND_BRANCHES.get(k, 0)}
    assert not new, f"code outside the mesh generators and elements asks which mesh it holds: {new}"
    fixed = {k: n for k, n in KNOWN_MESH_KIND_BRANCHES.items() if found.get(k, 0) < n}
    assert not fixed, f"{sorted(fixed)} ask less now (or are gone): lower them in KNOWN_MESH_KIND_BRANCHES"


def test_the_mesh_kind_check_sees_a_branch(tmp_path, monkeypatch):
    """The check finds each planted kind of question (a check that cannot fail is no check)."""
    pkg = tmp_path / "plateqp"
    (pkg / "plotting").mkdir(parents=True)
    (pkg / "plotting" / "plan.py").write_text(
        "def f(sc, mesh, result):\n"
        "    if sc.triangles or on_triangles(result) or mesh.cell_type == 'quad':\n"
        "        return isinstance(mesh, (Grid, int)) or mesh.grid_shape is None\n"
        "    return mesh.triangles\n")
    (pkg / "model").mkdir()
    (pkg / "model" / "trimesh.py").write_text("def g(sc):\n    return sc.triangles\n")
    monkeypatch.setattr(__import__(__name__), "ROOT", pkg)
    assert mesh_kind_branches() == {"plateqp.plotting.plan:f": 5}
