"""The backend registry and the one shape of a backend (plateqp.backends, plateqp.backends.base).

Every registered backend is a :class:`~plateqp.backends.base.Backend` with declared capabilities,
and every one turns an option it does not know into a ProblemError (exit code 2 on the command
line), never a solver failure (exit 4) and never a silent success, except where the solver's own
wrapper drops unknown keys without a word: those are declared below as data, and each must still
do so (a declared failure that stops failing fails the test, so the list stays true).
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse as sp

import plateqp as pq
from plateqp.backends import _FAMILY, _MODULES, get_backend, in_house, registry
from plateqp.backends.base import LCP, QP, Backend, Status
from plateqp.contact.formulations import FORMULATIONS
from plateqp.errors import ProblemError

#: Backends whose solver (or its wrapper) drops an unknown option silently, and why; each must
#: still solve with one (strict), so an entry that starts complaining must be removed.
SILENT_ABOUT_UNKNOWN_OPTIONS: dict[str, str] = {
    "cvxpy:CVXOPT": "cvxpy copies every option into cvxopt.solvers.options, a plain dict CVXOPT reads known keys from",
    "cvxpy:DAQP": "cvxpy passes DAQP only the option names it lists itself",
    "cvxpy:PROXQP": "cvxpy passes ProxQP only eps_abs, eps_rel, max_iter, rho, mu_eq, mu_in, backend",
    "qpsolvers:cvxopt": "qpsolvers passes the options as cvxopt.solvers.options, a plain dict",
    "qpsolvers:highs": "qpsolvers ignores the status HiGHS's setOptionValue returns for an unknown name",
}

INSTALLED = [n for n, b in sorted(registry().items()) if b.available()]


def problem_for(b: Backend):
    """A small problem the backend takes: an LCP, or a QP with sparse P and G (the primal's shape)."""
    if b.accepts == frozenset({"lcp"}):
        return LCP(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-1.0, 2.0]))
    return QP(P=sp.csc_matrix(np.diag([2.0, 1.0])), q=np.array([-2.0, -1.0]),
              G=sp.csc_matrix(np.array([[1.0, 1.0], [-1.0, 0.0]])), h=np.array([1.0, 10.0]))


def test_every_backend_has_the_one_shape():
    for name, b in registry().items():
        assert isinstance(b, Backend), name
        assert b.name == name and b.accepts and b.accepts <= {"qp", "lcp"}
        assert b.formulations is None or set(b.formulations) <= set(FORMULATIONS)
        assert isinstance(b.exact, bool) and isinstance(b.warm_start, bool)
        assert isinstance(b.available(), bool)
        if b.available():
            assert isinstance(b.version(), str)


def test_declared_capabilities():
    """Exact to rounding at every accuracy: the direct methods; warm start from an active set:
    the two that take options["active"]."""
    reg = registry()
    assert {n for n, b in reg.items() if b.exact} == {"lemke", "bpp", "pdas"}
    assert {n for n, b in reg.items() if b.warm_start} == {"bpp", "pdas"}
    assert reg["pdas"].formulations == ("primal",)


@pytest.mark.parametrize("name", INSTALLED)
def test_unknown_option_is_a_problem_error(name):
    b = get_backend(name)
    if name in SILENT_ABOUT_UNKNOWN_OPTIONS:
        sol = b.solve(problem_for(b), accuracy="default", options={"no_such_setting": 1})
        assert sol.status is Status.OPTIMAL, "declared silent, but it no longer is: remove it from the list"
        return
    with pytest.raises(ProblemError, match="no_such_setting"):
        b.solve(problem_for(b), accuracy="default", options={"no_such_setting": 1})


@pytest.mark.parametrize("name", ["osqp", "clarabel", "lemke"])
def test_unknown_option_is_exit_code_2(name, capsys):
    """The command line: a bad option is bad input (2), not a solver failure (4)."""
    if name not in INSTALLED:
        pytest.skip(f"{name} not installed")
    from plateqp import scenes
    from plateqp.cli import main

    code = main(["solve", str(scenes.path("heave")), "--backend", name, "--options", '{"no_such_setting": 1}'])
    err = capsys.readouterr().err
    assert code == 2 and "no_such_setting" in err and len(err.strip().splitlines()) == 1


def test_a_module_giving_something_else_is_refused(monkeypatch):
    """No adapter for the earlier module shape is left: a module whose backends() gives anything
    but Backend instances is a TypeError at registration, not a backend without capabilities."""
    import plateqp.backends as B
    from plateqp.backends import pdas

    monkeypatch.setattr(pdas, "backends", lambda: [pdas])
    for name, fresh in (("_known", {}), ("_names", {})):  # nothing imported yet
        monkeypatch.setattr(B, name, fresh)
    with pytest.raises(TypeError, match="Backend instances"):
        B.registry()
    monkeypatch.undo()
    assert isinstance(B.registry()["pdas"], Backend)


def test_unknown_backend_names_the_installed_ones():
    with pytest.raises(pq.SolverError, match="unknown backend 'nope'.*lemke"):
        get_backend("nope")


def test_every_exact_backend_is_plateqps_own():
    """``backend="auto"`` chooses among the exact backends from plateqp's own modules alone
    (plateqp.backends.IN_HOUSE): that is right only while no other module declares one."""
    reg, own = registry(), in_house()
    assert {"lemke", "bpp", "pdas"} <= set(own)
    assert all(reg[n] is b for n, b in own.items())
    assert [n for n, b in reg.items() if b.exact and n not in own] == []
    assert list(own) == [n for n in reg if n in own]  # the registry's order


THIRD_PARTY = ("cvxpy", "qpsolvers", "osqp", "clarabel")


@pytest.mark.skipif(not any(importlib.util.find_spec(m) for m in THIRD_PARTY),
                    reason="no third-party solver installed: nothing that could be imported")
def test_a_solve_with_plateqps_own_backends_imports_no_third_party_solver():
    """A fresh process's first solve with ``auto`` or an in-house backend imported every
    backend module, cvxpy among them (0.3 s of a 0.8 s first solve at 128²): now only what it uses."""
    code = ("import sys, plateqp as pq\n"
            "from plateqp.scenes.families import grid_rigid\n"
            "s = grid_rigid(8, 3)\n"
            "for b in ('auto', 'pdas', 'bpp', 'lemke'):\n"
            "    assert pq.solve(s, backend=b).status.name == 'OPTIMAL'\n"
            f"print(sorted(m for m in {THIRD_PARTY!r} if m in sys.modules))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_a_backend_of_another_family_is_found_by_its_name_alone():
    """``get_backend`` imports the module a name's family points to (``cvxpy:SCS`` → cvxpy's)
    before it would import every module: one installed backend of each family is found that
    way, in a fresh process, and is the registry's."""
    first = {}  # one installed backend of each other family
    for n in INSTALLED:
        if n not in in_house():
            first.setdefault(n.split(":")[0], n)
    others = list(first.values())
    if not others:
        pytest.skip("no third-party backend installed")
    code = ("import sys\n"
            "from plateqp.backends import _names, get_backend, registry\n"
            "found = {n: get_backend(n) for n in sys.argv[1:]}\n"
            "print(len(_names))\n"
            "assert all(registry()[n] is b for n, b in found.items())\n")
    for name in others:
        out = subprocess.run([sys.executable, "-c", code, name], capture_output=True, text=True, timeout=300)
        assert out.returncode == 0, (name, out.stderr)
        assert int(out.stdout.split()[0]) <= _MODULES.index(_FAMILY[name.split(":")[0]]) + 1, name  # not every module


def test_the_registry_order_does_not_depend_on_which_name_came_first():
    """Names looked up first from several threads at once, in a fresh process, the last family's
    first: no error, and the registry ends in the order of a plain build (plateqp's own first)."""
    names = list(reversed(INSTALLED))
    code = ("import sys, threading\n"
            "from plateqp.backends import get_backend, registry\n"
            "errors = []\n"
            "def look(n):\n"
            "    try:\n"
            "        get_backend(n)\n"
            "    except Exception as exn:\n"
            "        errors.append(repr(exn))\n"
            "ts = [threading.Thread(target=look, args=(n,)) for n in sys.argv[1:]]\n"
            "[t.start() for t in ts]\n"
            "[t.join() for t in ts]\n"
            "assert not errors, errors\n"
            "print(','.join(registry()))\n")
    out = subprocess.run([sys.executable, "-c", code, *names], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1].split(",") == list(registry())
