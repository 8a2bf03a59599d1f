r"""Studies on top of :func:`plateqp.solve`: scene paths, convergence by mesh halving, sweeps of
one scene parameter (with the breakpoints where the working scheme changes), regulation of the
reactions by the gaps, and the support stiffness that makes the contact pressure most uniform.

Scene paths
-----------
A PATH names a scene field with dots: ``plate.h``, ``mesh.nx``, ``loads.0.P``,
``supports.3.gap``, ``supports.*.stiffness`` (``*``: every item of a list), ``foundation.k``,
``edges.left`` (``"free"``, ``"simple"``, ``"clamped"``). :func:`get_param` reads one,
:func:`set_param` returns a validated deep copy with it changed. A support stiffness accepts
``"rigid"`` (also ``math.inf`` or ``"inf"``, stored as ``"rigid"``): the paper's stiffness study
starts from c = ∞.

Convergence (:func:`convergence`)
---------------------------------
The source paper's criterion: solve on meshes that halve (2, 4, 8, 16, 32 cells a side) and
watch each quantity's relative change from one mesh to the next. A mesh counts as converged
for a quantity when halving it (and every finer mesh after it) changes the quantity by less
than ``target``.

Sweeps (:func:`sweep`)
----------------------
One row per value: reactions, contact set, w_max, max σ1, KKT report, status, times (the
fields of ``plateqp solve --json`` plus ``value``). Between two successive values whose contact
sets differ, the change is located by bisection on the parameter (geometric for positive
parameters spanning a decade or more, e.g. a stiffness) until the bracket is within ``rtol``
relative. Re-use: the model (stiffness matrix, contact operator) is built once per worker
and only the gaps, support flexibilities or loads are changed in a copy when the parameter
does not change K; the max nodal σ1 of each row is then computed with operators built once
per mesh. Warm starts (``options={"active": ...}``: the previous solve's own final state,
``Result.extras["active"]``, else its contact set) go only to backends that take them
(:data:`WARM_START_BACKENDS`), with re-use on; ``warm_start=False`` turns them off alone. Local worker processes start from a fresh interpreter
(forkserver/spawn), never by forking a process whose numerical libraries have run threads.

Gaps that regulate the reactions (:func:`regulate_gaps`)
--------------------------------------------------------
With the prescribed reactions R acting on the plate as forces, the deflection at the
supports w follows, and the gaps that make R the contact solution are those that close
each loaded support exactly: with gap = g0 + ρR − w = 0,

.. math::

    g_0 = w(R) - \rho R .

On a held plate (two-sided supports, K nonsingular) this is the dual relation
gap = F R + (g0 − B K⁻¹ f) solved for g0 with gap = 0, and every R ≥ 0 is reachable. On a
floating plate R must also balance the load (force and moments); the target is first
projected, as a convex problem in cvxpy, onto the reachable set

.. math::

    \min_R \|R_r - R^*\|^2 \quad\text{s.t.}\quad V^T(f - B^T R) = 0,\ R \ge 0,

(V the rigid motions), and the rigid-motion part of the gaps, free on a floating plate, is
chosen closest to the scene's own gaps.
"""

from __future__ import annotations

import concurrent.futures as cf
import copy
import dataclasses
import itertools
import math
import pickle
import sys
import time
import uuid
import warnings
from collections import OrderedDict
from dataclasses import dataclass, field, fields, is_dataclass
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from .assembly import Model, build_model
from .solving import solve
from .errors import NoEquilibriumError, PlateQPError, PlateQPWarning, ProblemError, SceneError
from .scene import EDGE_NAMES, Edge, PointLoad, Scene

# =============================================================================================
# Scene paths
# =============================================================================================

_TOP = ("name", "plate", "mesh", "edges", "openings", "pins", "loads", "supports", "foundation")


def _path_parts(path: str) -> list[str]:
    if not isinstance(path, str) or not path or any(p == "" for p in path.split(".")):
        raise SceneError(f"bad path {path!r}: write dotted names such as 'supports.3.gap' or 'plate.h'")
    return path.split(".")


def _names(obj) -> list[str]:
    if isinstance(obj, Scene):
        return list(_TOP)
    if is_dataclass(obj):
        return [f.name for f in fields(obj) if f.init]
    return []


def _walk(obj, parts: list[str], where: str, create: bool):
    """Yield (container, key, where) for every leaf the path names (``*`` expands lists)."""
    if not parts:
        raise SceneError(f"{where}: names a whole section; name a field of it")
    key, rest = parts[0], parts[1:]
    here = f"{where}.{key}" if where else key
    if isinstance(obj, list):
        if key == "*":
            keys = range(len(obj))
            if not keys:
                raise SceneError(f"{here}: {where} is empty")
        else:
            try:
                k = int(key)
            except ValueError:
                raise SceneError(f"{here}: {where} is a list; use an index 0..{len(obj) - 1} or '*'") from None
            if not 0 <= k < len(obj):
                raise SceneError(f"{here}: index out of range; the scene has {len(obj)} {where} "
                                 f"(indices 0..{len(obj) - 1})" if obj else f"{here}: the scene has no {where}")
            keys = [k]
        for k in keys:
            sub = f"{where}.{k}"
            if rest:
                yield from _walk(obj[k], rest, sub, create)
            else:
                yield obj, k, sub
        return
    if isinstance(obj, dict):  # edges
        if key not in EDGE_NAMES:
            raise SceneError(f"{here}: unknown edge; edges are {', '.join(EDGE_NAMES)}")
        if key not in obj and create:
            obj[key] = Edge("free")
        if rest:
            yield from _walk(obj.get(key, Edge("free")), rest, here, create)
        else:
            yield obj, key, here
        return
    names = _names(obj)
    if key == "*" or key not in names:
        what = where or "the scene"
        raise SceneError(f"{here}: no such field in {what}; fields: {', '.join(names)}")
    if rest:
        sub = getattr(obj, key)
        if sub is None:
            raise SceneError(f"{here}: the scene has no {key}; add a [{key}] section first")
        if isinstance(sub, (str, int, float)) and not isinstance(sub, bool):
            raise SceneError(f"{here}.{rest[0]}: {here} is a value ({sub!r}), not a section")
        if isinstance(sub, dict) and key != "edges":  # e.g. foundation.gap as a profile
            if len(rest) != 1:
                raise SceneError(f"{here}.{'.'.join(rest)}: too deep")
            if rest[0] not in sub:
                raise SceneError(f"{here}.{rest[0]}: no such key; keys: {', '.join(sub)}")
            yield sub, rest[0], f"{here}.{rest[0]}"
            return
        yield from _walk(sub, rest, here, create)
    else:
        yield obj, key, here


def _read(container, key):
    if isinstance(container, (list, dict)):
        v = container[key] if not isinstance(container, dict) or key in container else Edge("free")
    else:
        v = getattr(container, key)
    return v.kind if isinstance(v, Edge) and v.w == 0.0 and v.slope == 0.0 else v


def get_param(scene: Scene, path: str):
    """The value a PATH names (a list of values for a path with ``*``).

    >>> get_param(scene, "supports.*.gap")     # one value per support
    >>> get_param(scene, "plate.h")
    """
    parts = _path_parts(path)
    leaves = list(_walk(scene, parts, "", create=False))
    vals = [_read(c, k) for c, k, _ in leaves]
    return vals if "*" in parts else vals[0]


def _coerce(where: str, old, value):
    """The value as the field wants it ("rigid"/inf for stiffness, int for mesh sizes, Edge for edges)."""
    leaf = where.rsplit(".", 1)[-1]
    if isinstance(value, np.generic):
        value = value.item()
    if leaf == "stiffness":
        if isinstance(value, str) and value.strip().lower() in ("rigid", "inf", "infinity"):
            return "rigid"
        if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isinf(value) and value > 0:
            return "rigid"
    edge_itself = where.startswith("edges.") and where.count(".") == 1
    if isinstance(value, str) and leaf not in ("name", "element", "kind", "profile") and not edge_itself:
        try:
            value = float(value)
        except ValueError:
            raise SceneError(f"{where}: not a number: {value!r}") from None
    if edge_itself:
        if isinstance(value, Edge):
            return copy.deepcopy(value)
        if isinstance(value, str):
            return Edge(kind=value)
        if isinstance(value, dict):
            return Edge(kind=value.get("kind", "free"), w=value.get("w", 0.0), slope=value.get("slope", 0.0))
        raise SceneError(f"{where}: must be an edge kind (free, simple, clamped)")
    if isinstance(old, int) and not isinstance(old, bool) and isinstance(value, float):
        if value.is_integer():
            return int(value)
        raise SceneError(f"{where}: must be an integer (got {value!r})")
    return value


def set_param(scene: Scene, path: str, value) -> Scene:
    """A validated deep copy of ``scene`` with the field PATH set to ``value``.

    With ``*`` in the path every item gets ``value``, or, if ``value`` is a sequence as long
    as the items, one entry each (``set_param(scene, "supports.*.gap", gaps)``).
    Raises SceneError naming the path for a bad path or value.
    """
    parts = _path_parts(path)
    new = copy.deepcopy(scene)
    leaves = list(_walk(new, parts, "", create=True))
    per_item = ("*" in parts and not isinstance(value, (str, dict)) and np.ndim(value) == 1
                and len(value) == len(leaves) and len(leaves) > 0)
    for j, (c, k, where) in enumerate(leaves):
        v = _coerce(where, _read(c, k) if not isinstance(c, dict) or k in c else None,
                    value[j] if per_item else value)
        if isinstance(c, (list, dict)):
            c[k] = v
        else:
            if k == "type":
                raise SceneError(f"{where}: the load type cannot be changed by a path; edit the scene")
            setattr(c, k, v)
    new.validate()
    return new


def _numeric(value) -> float:
    """A parameter value as a number ("rigid" is +inf)."""
    if isinstance(value, str):
        return math.inf if value.strip().lower() in ("rigid", "inf", "infinity") else float(value)
    return float(value)


# =============================================================================================
# Convergence by mesh halving
# =============================================================================================

@dataclass
class ConvergenceTable:
    """Quantities on a sequence of meshes and their relative change on halving each mesh.

    ``diff[q][k] = |q_{k+1} − q_k| / |q_{k+1}|``: the change of quantity q when mesh k is
    halved (NaN on the finest mesh). ``converged_at[q]``: the coarsest mesh from which every
    further halving changes q by less than ``target`` (None if none does).
    """

    meshes: list[tuple[int, int]]
    quantities: list[str]
    values: dict[str, np.ndarray]
    diff: dict[str, np.ndarray]
    converged_at: dict[str, tuple[int, int] | None]
    target: float
    errors: list[str | None] = field(default_factory=list)

    @property
    def rows(self) -> list[dict]:
        """One dict per mesh: nx, ny, each quantity and its change on halving ("<q> diff")."""
        out = []
        for k, (nx, ny) in enumerate(self.meshes):
            r: dict[str, Any] = {"nx": nx, "ny": ny}
            for q in self.quantities:
                r[q] = float(self.values[q][k])
                r[f"{q} diff"] = float(self.diff[q][k])
            r["error"] = self.errors[k] if self.errors else None
            out.append(r)
        return out

    def __str__(self) -> str:
        head = f"{'mesh':>9s}" + "".join(f" {q:>16s} {'change':>9s}" for q in self.quantities)
        lines = [head]
        for k, (nx, ny) in enumerate(self.meshes):
            line = f"{f'{nx}x{ny}':>9s}"
            for q in self.quantities:
                d = self.diff[q][k]
                line += f" {self.values[q][k]:16.6g} {('' if np.isnan(d) else f'{d:9.2%}'):>9s}"
            if self.errors and self.errors[k]:
                line += f"   ({self.errors[k]})"
            lines.append(line)
        for q in self.quantities:
            m = self.converged_at[q]
            lines.append(f"{q}: " + (f"converged at {m[0]}x{m[1]} (change < {self.target:g})" if m
                                     else f"not converged to {self.target:g} on these meshes"))
        return "\n".join(lines)


def quantity(result, name: str) -> float:
    """A named scalar of a result: ``w_max`` (signed w of largest |w|), ``s1_max`` (max nodal σ1),
    ``reactions.I`` (reaction at contact point I; also ``R3``), ``sum_reactions``,
    ``w:X,Y`` (deflection at a point)."""
    if name == "w_max":
        return result.w_max()[0]
    if name == "s1_max":
        return float(np.nanmax(result.nodal("s1")))
    if name == "sum_reactions":
        return float(np.sum(result.reactions))
    if name.startswith("reactions.") or (name.startswith("R") and name[1:].isdigit()):
        i = int(name.split(".", 1)[1] if "." in name else name[1:])
        if not 0 <= i < result.reactions.size:
            raise SceneError(f"quantity {name!r}: no contact point {i} (the scene has {result.reactions.size})")
        return float(result.reactions[i])
    if name.startswith("w:"):
        x, y = (float(v) for v in name[2:].split(","))
        return float(result.deflection(x, y))
    raise ValueError(f"unknown quantity {name!r}; use w_max, s1_max, sum_reactions, reactions.I, or w:X,Y")


def _quantity_scale(result, name: str) -> float:
    """The size of the family a built-in quantity belongs to (max |w|, max |R|, max |σ1|), so a
    quantity that is zero (a lifted support's reaction) is compared with its family, not with noise."""
    if name.startswith("reactions.") or name == "sum_reactions" or (name.startswith("R") and name[1:].isdigit()):
        return float(np.abs(result.reactions).max(initial=0.0))
    if name == "w_max" or name.startswith("w:"):
        return float(np.nanmax(np.abs(result.w_nodes())))
    if name == "s1_max":
        return float(np.nanmax(np.abs(result.nodal("s1"))))
    return 0.0


def convergence(scene: Scene, meshes: Sequence = (2, 4, 8, 16, 32),
                quantities: Sequence = ("w_max",), target: float = 0.01, backend: str = "auto",
                formulation: str = "auto", accuracy: str = "default") -> ConvergenceTable:
    """Solve ``scene`` on meshes that halve and tabulate each quantity and its change.

    Parameters
    ----------
    meshes : cells a side (``n`` → nx = n, ny = n × the scene's ny/nx), or (nx, ny) pairs,
        coarse to fine
    quantities : names understood by :func:`quantity`, or (name, callable(result) → float) pairs
    target : relative change under which a quantity counts as converged

    Supports off the nodes of a coarse mesh act through the element's interpolation; pins
    must lie on the nodes of every mesh (else that mesh's row records the SceneError).
    """
    ratio = scene.mesh.ny / scene.mesh.nx
    mesh_list = [(int(m[0]), int(m[1])) if isinstance(m, (tuple, list)) else (int(m), max(1, round(m * ratio)))
                 for m in meshes]
    names, funcs = [], []
    for q in quantities:
        if isinstance(q, str):
            names.append(q)
            funcs.append(lambda r, q=q: (quantity(r, q), _quantity_scale(r, q)))
        else:
            names.append(str(q[0]))
            funcs.append(lambda r, fn=q[1]: (float(fn(r)), 0.0))
    vals = {q: np.full(len(mesh_list), np.nan) for q in names}
    scales = {q: np.zeros(len(mesh_list)) for q in names}
    errors: list[str | None] = []
    for k, (nx, ny) in enumerate(mesh_list):
        sc = copy.deepcopy(scene)
        sc.mesh.nx, sc.mesh.ny = nx, ny
        try:
            sc.validate()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", PlateQPWarning)
                res = solve(sc, backend=backend, formulation=formulation, accuracy=accuracy)
            for q, fn in zip(names, funcs):
                vals[q][k], scales[q][k] = fn(res)
            errors.append(None if res.ok else f"status {res.status.value}")
        except PlateQPError as exn:
            errors.append(f"{type(exn).__name__}: {exn}")
    diff, conv = {}, {}
    for q in names:
        v = vals[q]
        d = np.full(len(v), np.nan)
        for k in range(len(v) - 1):
            # relative to the finer value, floored by 1e-9 of its family's size (or of |q| over the meshes)
            fam = scales[q][k + 1] or (np.nanmax(np.abs(v)) if np.any(np.isfinite(v)) else 0.0)
            den = max(abs(v[k + 1]), 1e-9 * fam)
            d[k] = abs(v[k + 1] - v[k]) / den if den > 0 else 0.0
        diff[q] = d
        conv[q] = None
        for k in range(len(v) - 2, -1, -1):  # from the finest pair back while the changes stay small
            if not d[k] < target:
                break
            conv[q] = mesh_list[k]
    return ConvergenceTable(mesh_list, names, vals, diff, conv, target, errors)


# =============================================================================================
# Model re-use
# =============================================================================================

def _same_structure(a: Scene, b: Scene) -> bool:
    """True if the two scenes have the same K and contact operator B (only gaps, stiffnesses,
    bed modulus and gap field, or loads differ)."""
    if (a.plate, a.mesh, a.edges, a.openings, a.pins) != (b.plate, b.mesh, b.edges, b.openings, b.pins):
        return False
    if [(s.x, s.y) for s in a.supports] != [(s.x, s.y) for s in b.supports]:
        return False
    if (a.foundation is None) != (b.foundation is None):
        return False
    return a.foundation is None or a.foundation.region == b.foundation.region


def adapt_model(base: Model, scene: Scene) -> Model | None:
    """A copy of ``base`` for ``scene`` without re-assembly, or None if K or B would change.

    Gaps, support stiffnesses, the bed's modulus and gap field and the loads are changed in
    copies of the arrays; the stiffness matrix and contact operator are shared.
    """
    old = base.scene
    if not _same_structure(old, scene):
        return None
    model = dataclasses.replace(base, scene=scene)
    if old.loads != scene.loads:
        from .assembly import _loads  # the load vector alone (no stiffness assembly)

        f_full = _loads(scene, base.grid, base.element, base.cells, base.cell_dofs, base.n_full)
        model.f_full = f_full
        model.f = f_full[base.free] - base.K_full[base.free][:, base.fixed] @ base.values
    c = base.contacts
    if c is not None:
        g0, rho = c.g0.copy(), c.rho.copy()
        sup = c.source == "support"
        if np.any(sup):
            i = c.index[sup]
            g_old = np.array([old.supports[k].gap for k in i], dtype=float)
            g_new = np.array([scene.supports[k].gap for k in i], dtype=float)
            g0[sup] = c.g0[sup] + (g_new - g_old)  # keeps the shift by prescribed dofs
            rho[sup] = [0.0 if scene.supports[k].rigid else 1.0 / scene.supports[k].stiffness for k in i]
        bed = c.source == "bed"
        if np.any(bed):
            fo, fn = old.foundation, scene.foundation
            x, y = c.xy[bed, 0], c.xy[bed, 1]
            g0[bed] = c.g0[bed] + (fn.gap_at(x, y) - fo.gap_at(x, y))
            rho[bed] = c.rho[bed] * (fo.k / fn.k)
        model.contacts = dataclasses.replace(c, g0=g0, rho=rho)
    return model


# =============================================================================================
# Sweeps: the work a worker does
# =============================================================================================

#: Backends that accept ``options={"active": bool array}`` as a warm start.
WARM_START_BACKENDS = ("bpp", "pdas")
#: ``executor=None`` runs fewer values than this in the calling process.
SERIAL_BELOW = 8


@dataclass
class _Context:
    """What a worker needs to solve one value (picklable; the model is cached per process)."""

    token: str
    scene: Scene
    path: str
    backend: str
    formulation: str
    accuracy: str
    options: dict | None
    reuse: bool
    warm_start: bool = True


@dataclass
class _Base:
    """What a worker keeps of a sweep: the base model and, built on first use, the operator
    of the rows' max nodal σ1 on its mesh."""

    model: Model
    s1: _NodalS1 | None = None


_MODELS: OrderedDict[str, _Base] = OrderedDict()  # per process: the base of a sweep
_MODELS_KEEP = 4


def _base(ctx: _Context) -> _Base:
    b = _MODELS.get(ctx.token)
    if b is None:
        b = _Base(build_model(ctx.scene))
        _MODELS[ctx.token] = b
        while len(_MODELS) > _MODELS_KEEP:
            _MODELS.popitem(last=False)
    return b


def _base_model(ctx: _Context) -> Model:
    return _base(ctx).model


def _forget(token: str) -> None:
    _MODELS.pop(token, None)


class _NodalS1:
    """``max(Result.nodal("s1"))`` for many solutions on one mesh, the same numbers without
    re-locating the evaluation points for every solution.

    :meth:`Result.nodal` evaluates the curvatures just inside each corner of every kept cell
    and averages over the cells at each node; building those interpolation operators (point
    location, shape functions) cost ~9 ms a row on a 32 × 32 mesh, against ~0.3 ms for the
    products. Here they are built once per mesh, stacked (w,xx; w,yy; w,xy) per corner, and
    the moments, stresses and principal stress follow :class:`~plateqp.results.Result` term
    by term. Only valid for models that share the grid, element and kept cells (an adapted
    model: :func:`adapt_model`).
    """

    def __init__(self, model: Model) -> None:
        import scipy.sparse as sp

        g, cells = model.grid, model.cells
        cn = g.cell_nodes()[cells]
        x0 = (cells % g.nx) * g.hx
        y0 = (cells // g.nx) * g.hy
        self.ops = []
        cnt = np.zeros(g.n_nodes)
        for k, (cx, cy) in enumerate(((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))):
            xi = 1e-9 + (1 - 2e-9) * cx  # just inside the cell, as Result.nodal does
            eta = 1e-9 + (1 - 2e-9) * cy
            x, y = x0 + xi * g.hx, y0 + eta * g.hy
            op = sp.vstack([model.interpolation(x, y, 2, 0), model.interpolation(x, y, 0, 2),
                            model.interpolation(x, y, 1, 1)], format="csr")
            self.ops.append((op, cn[:, k]))
            np.add.at(cnt, cn[:, k], 1.0)
        self.cnt, self.n_nodes, self.nc = cnt, g.n_nodes, cells.size

    def __call__(self, result) -> float:
        from .elements import bending_matrix

        p = result.scene.plate
        Db = bending_matrix(p.D, p.nu)
        c = 6.0 / p.h**2
        acc = np.zeros(self.n_nodes)
        for op, nodes in self.ops:
            kxx, kyy, kxy = (op @ result.u).reshape(3, self.nc)
            sx = c * -(Db[0, 0] * kxx + Db[0, 1] * kyy)
            sy = c * -(Db[1, 0] * kxx + Db[1, 1] * kyy)
            txy = c * (-Db[2, 2] * 2.0 * kxy)
            s1 = 0.5 * (sx + sy) + np.hypot(0.5 * (sx - sy), txy)
            np.add.at(acc, nodes, s1)
        cnt = self.cnt
        out = np.where(cnt > 0, acc / np.where(cnt > 0, cnt, 1), np.nan)
        return float(np.nanmax(out))


def _solve_value(ctx: _Context, value, warm=None):
    """Solve the scene with PATH = value.

    Returns (row, contact set as a bool tuple or None, (backend, warm-start state) or None).
    The warm-start state is the backend's own ``extras["active"]`` when it returns one (bpp's
    is in the LCP's terms: on the dual formulation True means *not* in contact), else the
    contact set. Never raises for a failed solve: the row records the error and status.
    """

    t0 = time.perf_counter()
    try:
        scene = set_param(ctx.scene, ctx.path, value)
        t_scene = time.perf_counter() - t0
        model = base = None
        if ctx.reuse:
            base = _base(ctx)
            model = adapt_model(base.model, scene)
        t_adapt = time.perf_counter() - t0
        opts = dict(ctx.options or {})
        if warm is not None:
            opts["active"] = np.asarray(warm, dtype=bool)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlateQPWarning)  # the row's status says it
            res = solve(scene, backend=ctx.backend, formulation=ctx.formulation, accuracy=ctx.accuracy,
                        options=opts or None, model=model)
        t_post = time.perf_counter()
        row = {"value": value, **res.to_dict()}
        if model is not None:  # an adapted model shares the base's mesh: its operator serves
            if base.s1 is None:
                base.s1 = _NodalS1(base.model)
            row["s1_max"] = base.s1(res)
        else:
            row["s1_max"] = float(np.nanmax(res.nodal("s1")))
        row["kkt_worst"] = res.kkt.worst if res.kkt is not None else None
        row["error"] = None
        t1 = time.perf_counter()
        times = row["times"]
        times["build"] = (times["build"] or 0.0) + t_adapt
        times["total"] = t1 - t0
        times.update(scene=t_scene, formulate=res.times.get("formulate"), recover=res.times.get("recover"),
                     post=t1 - t_post)
        active = tuple(bool(a) for a in res.active)
        state = np.asarray(res.extras.get("active", res.active), dtype=bool).copy()
        return row, active, (res.backend, state)
    except Exception as exn:  # never lose a sweep to one value: record it and go on
        status = "infeasible" if isinstance(exn, NoEquilibriumError) else "error"
        row = {"value": value, "scene": ctx.scene.name, "backend": ctx.backend, "formulation": ctx.formulation,
               "accuracy": ctx.accuracy, "status": status, "w_max": None, "w_max_x": None, "w_max_y": None,
               "probes": [], "reactions": None, "active": None, "gaps": None, "residual": None, "kkt": None,
               "iterations": None,
               "times": {"build": None, "solve": None, "total": time.perf_counter() - t0, "scene": None,
                         "formulate": None, "recover": None, "post": None},
               "s1_max": None, "kkt_worst": None, "error": f"{type(exn).__name__}: {exn}"}
        return row, None, None


def _warm(ctx: _Context, state):
    """The warm start for the next solve: only for backends that take one, and only with re-use
    and warm starts on."""
    if state is None or not (ctx.reuse and ctx.warm_start) or state[0] not in WARM_START_BACKENDS:
        return None
    return state[1]


def _run_chunk(ctx: _Context, items: list[tuple[int, Any]], state=None):
    """Solve values in order, each warm-started from the one before when the backend allows."""
    out = []
    for i, v in items:
        row, _, new = _solve_value(ctx, v, _warm(ctx, state))
        out.append((i, row))
        state = new or state
    return out


@dataclass
class _Bisection:
    geometric: bool
    rtol: float
    floor: float  # absolute floor for linear bisection (a change at 0 still terminates)
    integer: bool
    max_steps: int = 200


def _close(b: _Bisection, x1: float, x2: float) -> bool:
    lo, hi = min(x1, x2), max(x1, x2)
    if b.integer:
        return hi - lo <= 1
    if b.geometric:
        return hi <= lo * (1.0 + b.rtol)
    return hi - lo <= b.rtol * max(abs(lo), abs(hi), b.floor)


def _mid(b: _Bisection, x1: float, x2: float) -> float:
    if b.integer:
        return float(int((x1 + x2) // 2))
    return math.sqrt(x1 * x2) if b.geometric else 0.5 * (x1 + x2)


def _contact_set(active) -> list[int]:
    return [i for i, a in enumerate(active) if a]


def _refine_bracket(ctx: _Context, bis: _Bisection, v1, a1, v2, a2):
    """Breakpoints between sweep values v1 and v2 (contact sets a1 ≠ a2), in sweep order."""
    # "warm": contact set -> warm-start state of a solve that ended in it; "steps": backend iterations
    state = {"warm": {}, "solves": 0, "steps": 0}

    def at(x, warm_from):
        val = int(x) if bis.integer else x
        row, act, new = _solve_value(ctx, val, _warm(ctx, state["warm"].get(warm_from)))
        state["solves"] += 1
        state["steps"] += row["iterations"] or 0
        if new is not None:
            state["warm"][act] = new
        return act, row

    def bp(x1, s1, x2, s2, note=None):
        at_v = None
        if math.isfinite(x1) and math.isfinite(x2) and not bis.integer:
            at_v = _mid(bis, x1, x2) if _close(bis, x1, x2) else None
        d = {"between": [v1, v2], "at": at_v,
             "bracket": [_out(x1), _out(x2)],
             "before": _contact_set(s1), "after": _contact_set(s2)}
        if note:
            d["note"] = note
        return d

    def rec(x1, s1, x2, s2, depth=0):
        if _close(bis, x1, x2) or depth > bis.max_steps:
            return [bp(x1, s1, x2, s2, None if depth <= bis.max_steps else "bisection stopped")]
        xm = _mid(bis, x1, x2)
        sm, row = at(xm, s1)
        if sm is None:
            return [bp(x1, s1, x2, s2, f"bisection stopped at {xm:g}: {row['error']}")]
        if sm == s1:
            return rec(xm, sm, x2, s2, depth + 1)
        if sm == s2:
            return rec(x1, s1, xm, sm, depth + 1)
        return rec(x1, s1, xm, sm, depth + 1) + rec(xm, sm, x2, s2, depth + 1)

    x1, x2 = _numeric(v1), _numeric(v2)
    if math.isinf(x1) or math.isinf(x2):
        # one end rigid: walk from the finite end towards it by decades, then bisect
        flip = math.isinf(x1)
        xf, sf, si = (x2, a2, a1) if flip else (x1, a1, a2)
        chain = [(xf, sf)]
        x = xf
        found = False
        for _ in range(12):
            x = x * 10.0 if x > 0 else 1.0
            s, _ = at(x, chain[-1][1])
            if s is None:
                break
            chain.append((x, s))
            if s == si:
                found = True
                break
        out = []
        for (xa, sa), (xb, sb) in itertools.pairwise(chain):
            if sa != sb:
                out += rec(xa, sa, xb, sb)
        if not found:
            out.append(bp(chain[-1][0], chain[-1][1], math.inf, si,
                          note=f"the contact set still differs from the rigid one at {chain[-1][0]:g}"))
            out[-1]["bracket"] = [_out(chain[-1][0]), "rigid"]
        if flip:  # sweep order: from rigid to the finite end
            out = [{**d, "before": d["after"], "after": d["before"], "bracket": d["bracket"][::-1]}
                   for d in reversed(out)]
        return out, (state["solves"], state["steps"])
    return rec(x1, a1, x2, a2), (state["solves"], state["steps"])


def _out(x):
    if isinstance(x, float) and math.isinf(x):
        return "rigid"
    return x


# =============================================================================================
# Sweeps: executors and progress
# =============================================================================================

class _Serial:
    """Runs each task when its result is asked for, so progress advances as it goes."""

    kind = "serial"
    workers = 1

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


class _Futures:
    """A concurrent.futures executor (ours or the user's) or a Dask distributed Client."""

    def __init__(self, executor, own: bool, dask: bool, workers: int):
        self.ex, self.own, self.dask, self.workers = executor, own, dask, workers
        self.kind = "dask" if dask else "futures"

    def submit(self, fn, *args):
        if self.dask:
            return self.ex.submit(fn, *args, pure=False)
        return self.ex.submit(fn, *args)

    def as_completed(self, futs):
        if self.dask:
            from distributed import as_completed

            for f in as_completed(list(futs)):
                yield f, f
        else:
            for f in cf.as_completed(list(futs)):
                yield f, f

    def close(self):
        if self.own:
            self.ex.shutdown(wait=True)


def _mp_context():
    """Worker processes start from a clean server process ("forkserver"; "spawn" where there is
    none), never by forking this one: a fork after SuiteSparse/OpenMP or BLAS threads have run
    here deadlocks the workers (seen: both blocked on a futex after a 32x32 serial sweep)."""
    import multiprocessing as mp

    return mp.get_context("forkserver" if "forkserver" in mp.get_all_start_methods() else "spawn")


def _is_dask(executor) -> bool:
    return type(executor).__module__.split(".")[0] == "distributed" and hasattr(executor, "submit")


def _runner(executor, n: int, max_workers: int, ctx: _Context):
    if executor == "serial" or (executor is None and n < SERIAL_BELOW) or max_workers <= 1 and executor is None:
        return _Serial()
    if executor is None or executor in ("process", "processes"):
        try:
            pickle.dumps(ctx)
        except Exception:
            warnings.warn("the scene cannot be pickled (a Python callable in it?): sweeping in this process",
                          PlateQPWarning, stacklevel=3)
            return _Serial()
        return _Futures(cf.ProcessPoolExecutor(max_workers=max_workers, mp_context=_mp_context()), True, False,
                        max_workers)
    if _is_dask(executor):
        try:
            workers = max(1, sum(executor.nthreads().values()))
        except Exception:
            workers = max_workers
        return _Futures(executor, False, True, workers)
    if isinstance(executor, cf.Executor):
        return _Futures(executor, False, False, getattr(executor, "_max_workers", max_workers) or max_workers)
    raise ProblemError(f"executor must be None, 'serial', 'process', a concurrent.futures.Executor or a "
                       f"dask distributed Client (got {executor!r})")


class _Progress:
    """tqdm on stderr if installed, else one counter line that rewrites itself."""

    def __init__(self, total: int, desc: str, enabled: bool):
        self.total, self.desc, self.enabled, self.n = total, desc, enabled and total > 0, 0
        self.bar = None
        if self.enabled:
            try:
                from tqdm import tqdm

                self.bar = tqdm(total=total, desc=desc, file=sys.stderr, leave=False)
            except ImportError:
                self._line()

    def _line(self):
        sys.stderr.write(f"\r{self.desc}: {self.n}/{self.total}")
        sys.stderr.flush()

    def update(self, k: int = 1):
        self.n += k
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.update(k)
        else:
            self._line()

    def close(self):
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.close()
        else:
            sys.stderr.write("\n")
            sys.stderr.flush()


# =============================================================================================
# Sweeps: the public function
# =============================================================================================

@dataclass
class SweepResult:
    """The rows of a sweep (one per value) and the breakpoints between them.

    ``rows``: dicts with the fields of ``plateqp solve --json`` plus ``value``, ``s1_max``,
    ``kkt_worst`` and ``error`` (None, or the failure of that value: its status is then
    "infeasible" for no equilibrium, else "error"). A row's ``times`` (seconds) has, besides
    ``build`` (scene copy and model, adapted or built), ``solve`` (the backend) and ``total``,
    the parts ``scene`` (copy and validation of the scene), ``formulate`` (scaling, statics
    check, formulation), ``recover`` (fields and KKT report) and ``post`` (the row itself:
    w_max, s1_max, lists). ``breakpoints``: dicts
    ``{between: [v1, v2], at, bracket: [lo, hi], before, after}``, where the contact set
    (indices of the contact points in contact) changes from ``before`` to ``after`` at
    ``at`` (the middle of the final bracket; None if it could not be refined). ``times``:
    seconds for "values", "breakpoints" and "total"; "bisection_solves" (solves the bisection
    took) and "bisection_iterations" (the backend's iterations in them); "executor".
    """

    path: str
    values: list
    rows: list[dict]
    breakpoints: list[dict]
    times: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """The JSON shape of ``plateqp sweep --json``: {rows, breakpoints}."""
        return {"rows": self.rows, "breakpoints": self.breakpoints}

    @property
    def reactions(self) -> np.ndarray:
        """(n_values, m) reactions; NaN rows for failed values."""
        m = max((len(r["reactions"]) for r in self.rows if r["reactions"] is not None), default=0)
        return np.array([r["reactions"] if r["reactions"] is not None else [np.nan] * m for r in self.rows])

    @property
    def active(self) -> list:
        """Contact set (bool list) per value; None for failed values."""
        return [r["active"] for r in self.rows]

    def __str__(self) -> str:
        head = (f"{'value':>12s} {'status':>10s} {'contact':>8s} {'sum R':>12s} {'w_max':>12s}"
                f" {'max s1':>12s} {'KKT worst':>9s} {'time s':>8s}")
        lines = [f"sweep of {self.path}: {len(self.rows)} values", head]
        for r in self.rows:
            v = r["value"]
            vs = v if isinstance(v, str) else f"{v:.6g}"
            if r["error"]:
                lines.append(f"{vs:>12s} {r['status']:>10s}   {r['error']}")
                continue
            lines.append(f"{vs:>12s} {r['status']:>10s} {sum(r['active']):>4d}/{len(r['active']):<3d}"
                         f" {sum(r['reactions']):12.6g} {r['w_max']:12.6g} {r['s1_max']:12.6g}"
                         f" {r['kkt_worst'] if r['kkt_worst'] is not None else float('nan'):9.1e}"
                         f" {r['times']['total']:8.3f}")
        if self.breakpoints:
            lines.append("changes of the contact set (working scheme):")
            for b in self.breakpoints:
                on = sorted(set(b["after"]) - set(b["before"]))
                off = sorted(set(b["before"]) - set(b["after"]))
                where = f"at {b['at']:.6g}" if b["at"] is not None else f"in {b['bracket']}"
                lines.append(f"  between {b['between'][0]} and {b['between'][1]}: {where};"
                             f" comes into contact {on or '-'}, lifts off {off or '-'}"
                             + (f" ({b['note']})" if b.get("note") else ""))
        else:
            lines.append("the contact set is the same for every value")
        return "\n".join(lines)


def sweep(scene: Scene, path: str, values: Iterable, backend: str = "auto", formulation: str = "auto",
          accuracy: str = "default", executor=None, progress: bool = True, refine_breakpoints: bool = True,
          rtol: float = 1e-3, options: dict | None = None, reuse: bool = True, max_workers: int = 2,
          bisection: str = "auto", warm_start: bool = True) -> SweepResult:
    """Solve ``scene`` for each value of the field PATH; find where the contact set changes.

    Parameters
    ----------
    scene, path : the scene and the field to vary (see :func:`set_param`)
    values : the values, in sweep order ("rigid" allowed for a stiffness)
    backend, formulation, accuracy, options : as for :func:`plateqp.solve`
    executor : None (local processes, ``max_workers`` of them, or this process for fewer
        than :data:`SERIAL_BELOW` values), "serial", "process", any
        :class:`concurrent.futures.Executor`, or a Dask ``distributed.Client``. Local
        processes start from a fresh interpreter (forkserver/spawn), so a script that sweeps
        with them needs the usual ``if __name__ == "__main__":`` guard.
    progress : a progress bar on stderr (tqdm if installed, else a counter line)
    refine_breakpoints : bisect each change of the contact set between successive values
        until its bracket is within ``rtol`` relative
    reuse : build the model once and change only gaps, stiffnesses or loads in a copy (the
        condensation is then computed once too); False rebuilds and solves everything from
        scratch for each value, without warm starts (the reference for timing the re-use)
    warm_start : with ``reuse``, start each solve of a backend that takes a warm start
        (:data:`WARM_START_BACKENDS`) from the final state of the solve before it (in a
        chunk of values, or in a bisection from the bracket's end it continues); False
        re-uses the model but starts every solve cold (to measure what warm starts save).
        Other backends ignore it. Each row's ``iterations`` counts the backend's steps.
    bisection : "auto" (geometric when every value is positive and they span a decade or
        more, else linear), "geometric" or "linear"

    Returns
    -------
    SweepResult. A value whose solve fails is recorded as a row with its status and error;
    the sweep goes on. A change between a failed value and its neighbours is not bisected.
    """
    values = [v.item() if isinstance(v, np.generic) else v for v in values]
    if not values:
        raise ProblemError("sweep: no values given")
    if bisection not in ("auto", "geometric", "linear"):
        raise ProblemError(f"bisection must be 'auto', 'geometric' or 'linear' (got {bisection!r})")
    if not isinstance(warm_start, (bool, np.bool_)):
        raise ProblemError(f"warm_start must be True or False (got {warm_start!r})")
    current = get_param(scene, path)  # a bad path fails here, naming what exists
    set_param(scene, path, values[0])  # and a bad value
    first = current[0] if isinstance(current, list) else current
    is_int = isinstance(first, int) and not isinstance(first, bool)  # mesh.nx: bisect on integers
    finite = [x for x in (_numeric(v) for v in values) if math.isfinite(x)]
    geometric = {"geometric": True, "linear": False}.get(
        bisection, bool(finite) and min(finite) > 0 and max(finite) >= 10.0 * min(finite))
    if geometric and not (finite and min(finite) > 0):
        raise ProblemError("geometric bisection needs positive values")
    bis = _Bisection(geometric, rtol, 1e-3 * max((abs(x) for x in finite), default=1.0), is_int)

    t0 = time.perf_counter()
    ctx = _Context(uuid.uuid4().hex, scene, path, backend, formulation, accuracy, options, reuse,
                   bool(warm_start))
    runner = _runner(executor, len(values), max_workers, ctx)
    n = len(values)
    rows: list[dict | None] = [None] * n
    actives: list = [None] * n
    found: dict[int, list[dict]] = {}
    solves = bisection_steps = 0
    try:
        bar = _Progress(n, f"sweep {path}", progress)
        try:
            if runner.kind == "serial":
                # a plain loop, warm-starting each value from the one before
                state = None
                for i in range(n):
                    row, act, new = _solve_value(ctx, values[i], _warm(ctx, state))
                    rows[i], actives[i] = row, act
                    state = new or state
                    bar.update()
            else:
                size = max(1, math.ceil(n / (4 * runner.workers)))
                chunks = [[(i, values[i]) for i in range(j, min(n, j + size))] for j in range(0, n, size)]
                futs = {runner.submit(_run_chunk, ctx, ch): ch for ch in chunks}
                for key, fut in runner.as_completed(futs):
                    ch = futs[key]
                    try:
                        done = fut.result()
                    except Exception:  # a worker died or could not run it: do this chunk here
                        done = _run_chunk(ctx, ch)
                    for i, row in done:
                        rows[i] = row
                        actives[i] = tuple(row["active"]) if row["active"] is not None else None
                    bar.update(len(ch))
        finally:
            bar.close()
        t1 = time.perf_counter()

        # breakpoints between successive values whose contact sets differ
        pairs = [i for i in range(n - 1)
                 if actives[i] is not None and actives[i + 1] is not None and actives[i] != actives[i + 1]]
        if refine_breakpoints and pairs:
            bar = _Progress(len(pairs), "refining breakpoints", progress)
            try:
                args = {i: (ctx, bis, values[i], actives[i], values[i + 1], actives[i + 1]) for i in pairs}
                futs = {runner.submit(_refine_bracket, *args[i]): i for i in pairs}
                for key, fut in runner.as_completed(futs):
                    i = futs[key]
                    try:
                        found[i], (k, steps) = fut.result()
                    except Exception:  # a worker died: refine this one here
                        found[i], (k, steps) = _refine_bracket(*args[i])
                    solves += k
                    bisection_steps += steps
                    bar.update()
            finally:
                bar.close()
        else:
            for i in pairs:
                found[i] = [{"between": [values[i], values[i + 1]], "at": None,
                             "bracket": [values[i], values[i + 1]],
                             "before": _contact_set(actives[i]), "after": _contact_set(actives[i + 1])}]
    finally:
        runner.close()
        _forget(ctx.token)
    breakpoints = [b for i in sorted(found) for b in found[i]]
    t2 = time.perf_counter()
    return SweepResult(path, values, rows, breakpoints,
                       times={"values": t1 - t0, "breakpoints": t2 - t1, "total": t2 - t0,
                              "bisection_solves": solves, "bisection_iterations": bisection_steps,
                              "executor": runner.kind})


# =============================================================================================
# Regulating the interaction forces by the gaps
# =============================================================================================

@dataclass
class GapRegulation:
    """Gaps that make the regulated supports carry prescribed reactions.

    ``gaps``: new initial gap of every support (scene order); ``scene``: a copy with them;
    ``supports``: the regulated supports; ``target``: the reactions asked; ``reactions``: the
    reactions the gaps produce (the target, projected onto equilibrium on a floating plate);
    ``other_reactions``: those of the unregulated supports; ``projection``: relative distance
    ‖reactions − target‖ / ‖target‖ (0 when the target is reachable).
    """

    gaps: np.ndarray
    scene: Scene
    supports: np.ndarray
    target: np.ndarray
    reactions: np.ndarray
    other_reactions: np.ndarray
    projection: float

    @property
    def reachable(self) -> bool:
        return self.projection <= 1e-9


def _project_reactions(A: np.ndarray, b: np.ndarray, target: np.ndarray, n_other: int) -> np.ndarray:
    """min ‖R_r − R*‖² s.t. A [R_r; R_u] = b, R ≥ 0, as a convex problem in cvxpy.

    ``A`` has the regulated supports' columns first. Returns [R_r; R_u].
    """
    import cvxpy as cp

    r = target.size
    scale = max(np.abs(target).max(initial=0.0), np.abs(b).max(initial=0.0), 1e-300)
    rs = cp.Variable(r + n_other, nonneg=True)
    cons = []
    if A.shape[0]:
        An = A / np.linalg.norm(A, axis=1, keepdims=True)
        bn = b / np.linalg.norm(A, axis=1) / scale
        cons.append(An @ rs == bn)
    prob = cp.Problem(cp.Minimize(cp.sum_squares(rs[:r] - target / scale)), cons)
    try:
        prob.solve()
    except cp.error.SolverError as exn:
        raise ProblemError(f"regulate_gaps: the projection of the target reactions failed: {exn}") from exn
    if prob.status not in ("optimal", "optimal_inaccurate"):
        raise NoEquilibriumError("regulate_gaps: no reactions R ≥ 0 of these supports balance the load "
                                 f"(cvxpy: {prob.status})")
    R = np.maximum(np.asarray(rs.value, dtype=float), 0.0) * scale
    if n_other == 0 and A.shape[0] and np.all(R[:r] > 1e-9 * R.max()):
        # polish: with no bound active, the exact projection onto {A R = b}
        R = target - A.T @ np.linalg.solve(A @ A.T, A @ target - b)
    return R


def regulate_gaps(scene: Scene, target_reactions, supports: Sequence[int] | None = None,
                  backend: str = "auto", formulation: str = "auto") -> GapRegulation:
    r"""Initial gaps that make the chosen supports carry the target reactions.

    Parameters
    ----------
    scene : the scene (its other supports keep their gaps)
    target_reactions : one value per regulated support, or one value for all
    supports : indices of the regulated supports (default: every support)

    The regulated supports act on the plate as the forces R; the plate (with the other
    one-sided supports in contact as the contact problem says, solved with
    :func:`plateqp.solve`) deflects by w; the gap of each regulated support is then
    g0 = w − R/c (c its stiffness; R/c = 0 for a rigid one), so that it touches with exactly R.
    A target of 0 leaves that support touching with zero force (add a margin to lift it off).
    On a floating plate the target is first projected onto equilibrium (see module docs).
    Check the answer with ``pq.solve(result.scene)``.
    """
    ns = len(scene.supports)
    if ns == 0:
        raise SceneError("supports: the scene has no one-sided supports to regulate")
    reg = np.arange(ns) if supports is None else np.asarray(list(supports), dtype=int)
    if reg.size == 0 or reg.min() < 0 or reg.max() >= ns or len(set(reg.tolist())) != reg.size:
        raise SceneError(f"supports: regulated supports must be distinct indices 0..{ns - 1} (got {list(reg)})")
    target = np.broadcast_to(np.asarray(target_reactions, dtype=float), reg.shape).copy()
    if np.any(target < 0) or not np.all(np.isfinite(target)):
        raise ProblemError("target_reactions: reactions must be finite and >= 0 (compression)")
    others = np.setdiff1d(np.arange(ns), reg)
    if scene.foundation is not None:
        raise ProblemError("regulate_gaps: a scene with a tensionless bed is not supported; "
                           "regulate discrete supports only")

    model = build_model(scene)
    c = model.contacts
    V = model.rigid_modes()
    order = np.concatenate([reg, others])
    if V.shape[1]:
        A = (c.B[order] @ V).T  # force/moment balance: (B V)ᵀ R = Vᵀ f
        A = np.asarray(A)
        b = V.T @ model.f
    else:
        A, b = np.zeros((0, ns)), np.zeros(0)
    if V.shape[1]:
        R_all = _project_reactions(A, b, target, others.size)
        R_reg = R_all[: reg.size]
    else:
        R_reg = target.copy()
    proj = float(np.linalg.norm(R_reg - target) / max(np.linalg.norm(target), 1e-300))

    # the plate under the load and the regulated reactions (as upward point forces)
    R_other = np.zeros(others.size)
    if others.size:
        sc = copy.deepcopy(scene)
        sc.supports = [scene.supports[k] for k in others]
        sc.loads = list(sc.loads) + [PointLoad(P=-float(R), x=scene.supports[k].x, y=scene.supports[k].y)
                                     for k, R in zip(reg, R_reg)]
        sc.validate()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlateQPWarning)
            res = solve(sc, backend=backend, formulation=formulation, accuracy="high")
        w_reg = np.asarray(res.deflection(np.array([scene.supports[k].x for k in reg]),
                                          np.array([scene.supports[k].y for k in reg])), dtype=float)
        R_other = res.reactions.copy()
    else:
        rhs = model.f - c.B[reg].T @ R_reg
        u = _solve_held_or_floating(model, rhs, V)
        g_scene = np.array([scene.supports[k].gap for k in reg], dtype=float)
        # actual deflection at the supports: B u plus the prescribed dofs' part (scene gap − model g0)
        w_reg = c.B[reg] @ u + (g_scene - c.g0[reg])
        if V.shape[1]:
            # a floating plate's rigid motion is free: choose it so the gaps are closest to the scene's
            BV = np.asarray(c.B[reg] @ V)
            alpha, *_ = np.linalg.lstsq(BV, g_scene - (w_reg - c.rho[reg] * R_reg), rcond=None)
            w_reg = w_reg + BV @ alpha
    gaps = np.array([s.gap for s in scene.supports], dtype=float)
    gaps[reg] = w_reg - c.rho[reg] * R_reg
    new = set_param(scene, "supports.*.gap", gaps)
    return GapRegulation(gaps, new, reg, target, R_reg, R_other, proj)


def _solve_held_or_floating(model: Model, rhs: np.ndarray, V: np.ndarray) -> np.ndarray:
    """K u = rhs; on a floating plate the solution orthogonal to the rigid motions V."""
    from .linalg import Factor

    if V.shape[1] == 0:
        fac = Factor(model.K)
        return fac.solve(rhs)
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    k = V.shape[1]
    s = float(np.median(np.abs(model.K.diagonal())))
    Vn = V / np.linalg.norm(V, axis=0) * s
    A = sp.bmat([[model.K, sp.csr_matrix(Vn)], [sp.csr_matrix(Vn.T), None]], format="csc")
    full = np.concatenate([rhs, np.zeros(k)])
    lu = spla.splu(A)
    x = lu.solve(full)
    for _ in range(2):
        x = x + lu.solve(full - A @ x)
    return x[: model.n_free]


# =============================================================================================
# The most uniform contact pressure
# =============================================================================================

@dataclass
class UniformStiffness:
    """The stiffness that makes the reactions of the chosen supports most uniform.

    ``c``: the stiffness; ``cv``: coefficient of variation std(R)/mean(R) there; ``reactions``:
    of the chosen supports; ``evaluations``: every (c, cv) tried; ``at_bound``: the best c lies
    within one scan step of an end of ``c_range`` (no interior optimum found: e.g. on a floating
    plate on equal springs the pressure only gets more uniform as c falls towards the rigid-body
    distribution).
    """

    c: float
    cv: float
    reactions: np.ndarray
    evaluations: list[tuple[float, float]]
    at_bound: bool = False


def most_uniform_stiffness(scene: Scene, c_range: tuple[float, float], supports: Sequence[int] | None = None,
                           backend: str = "auto", formulation: str = "auto", accuracy: str = "default",
                           scan: int = 17, xatol: float = 1e-4) -> UniformStiffness:
    """The support stiffness c (all supports) that makes the contact pressure most uniform.

    Minimises the coefficient of variation of the reactions over ``supports`` (default: every
    support, e.g. a contour) on log c: a coarse log scan of ``scan`` points first, then
    :func:`scipy.optimize.minimize_scalar` (bounded) around the best scan point. The model is
    built once; only the support flexibilities change.
    """
    from scipy.optimize import minimize_scalar

    lo, hi = (float(v) for v in c_range)
    if not (0 < lo < hi):
        raise ProblemError(f"c_range must be (low, high) with 0 < low < high (got {c_range!r})")
    sel = np.arange(len(scene.supports)) if supports is None else np.asarray(list(supports), dtype=int)
    base = build_model(scene)
    evals: list[tuple[float, float]] = []

    def cv_at(logc: float) -> float:
        c = float(np.exp(logc))
        sc = set_param(scene, "supports.*.stiffness", c)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlateQPWarning)
            res = solve(sc, backend=backend, formulation=formulation, accuracy=accuracy,
                        model=adapt_model(base, sc))
        R = res.reactions[sel]
        m = R.mean()
        v = float(R.std() / m) if m > 0 else math.inf
        evals.append((c, v))
        return v

    grid = np.linspace(np.log(lo), np.log(hi), max(scan, 3))
    cvs = [cv_at(x) for x in grid]
    k = int(np.argmin(cvs))
    a, b = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    opt = minimize_scalar(cv_at, bounds=(a, b), method="bounded", options={"xatol": xatol})
    best = min(evals, key=lambda e: e[1])
    sc = set_param(scene, "supports.*.stiffness", best[0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlateQPWarning)
        res = solve(sc, backend=backend, formulation=formulation, accuracy=accuracy, model=adapt_model(base, sc))
    del opt
    step = grid[1] - grid[0]
    at_bound = bool(min(np.log(best[0]) - grid[0], grid[-1] - np.log(best[0])) < step)
    return UniformStiffness(best[0], best[1], res.reactions[sel].copy(), evals, at_bound)
