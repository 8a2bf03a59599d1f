r"""Contact problems in standard formats, so that other people's solvers can be run on them.

Two formats:

- **QPS** (Maros–Meszaros): free MPS with a ``QUADOBJ`` section holding the lower triangle of
  P. The QP is

  .. math::

      \min_x\ \tfrac12 x^T P x + q^T x + c_0
      \quad\text{s.t.}\quad G x \le h\ (\text{L rows}),\quad A x = b\ (\text{E rows}),
      \quad lb \le x \le ub\ (\text{BOUNDS}).

  Every number is written with ``repr`` (the shortest string that reads back to the same
  double, at most 17 significant digits), so a reader that parses with ``strtod`` gets the
  very same matrices. Free MPS, not fixed-column: fixed columns leave 12 characters per
  number, too few for full precision. :func:`read_qps` reads it back (and the usual QPS
  files: N/L/G/E rows, RANGES, BOUNDS, QUADOBJ or QMATRIX).
- **qpbenchmark test set**: a directory with one ``.npz`` per problem (dense vectors q, h, b,
  lb, ub; matrices P, G, A either dense or as their CSC components ``P_data``,
  ``P_indices``, ``P_indptr``, ``P_shape``: never densified) and a generated module
  ``<name>.py`` that defines the qpbenchmark ``TestSet`` loading them, runnable as
  ``qpbenchmark <dir>/<name>.py run``. It needs only numpy, scipy and qpbenchmark, not plateqp.

The problem exported is the one plateqp's backends see (:func:`contact_qp`): the
nondimensional data of :class:`plateqp.contact.scaling.Scaled` (deflections by W, forces by F0,
lengths by L), formulated as ``primal``, ``condensed`` or ``dual`` and taken in its QP form
(the condensed and dual LCPs as the bound-constrained QPs ½ zᵀMz + qᵀz, z ≥ 0). The scales and
the variables' names travel with the file (QPS comment lines, the ``meta`` entry of the
``.npz``), and :meth:`ExportedQP.result` maps any solver's x back to a plateqp
:class:`~plateqp.results.Result` with its KKT report on the plate's own terms.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from .accuracy import Status
from .backends.base import QP, RawSolution
from .errors import ExportError, PlateQPError, ProblemError

FORMATS = ("qps", "qpbenchmark")

#: qpbenchmark's settings and the tolerance each validates primal residual, dual residual and
#: duality gap with (its TestSet.define_tolerances, v2.7); plateqp's nearest accuracy preset.
QPBENCHMARK_TOLERANCES = {
    "default": (1.0, None),
    "low_accuracy": (1e-3, "low"),
    "mid_accuracy": (1e-6, "default"),
    "high_accuracy": (1e-9, "high"),
}

_NAME_OK = re.compile(r"[^A-Za-z0-9_.\-]")


# --------------------------------------------------------------------------------------------
# the contact problem as plateqp's backends see it


@dataclass
class ExportedQP:
    """A contact problem in standard QP form, with what maps a solution back to the plate.

    Attributes
    ----------
    name : problem name (safe for file names and MPS)
    formulation : "primal", "condensed" or "dual"
    qp : the :class:`~plateqp.backends.base.QP` handed to QP backends
    var_names : one name per variable (primal: ``w_17``, ``wx_17``, … node dofs, ``t_3``
        scaled spring variables; condensed: ``z_3`` gaps; dual: ``R_3`` reactions)
    row_names : one name per row of G (primal: ``gap_3``); empty for the bound-constrained forms
    meta : scene name, formulation, scales L, W, F0 and what x means (JSON-able)
    """

    name: str
    formulation: str
    qp: QP
    var_names: list[str]
    row_names: list[str]
    meta: dict
    model: object = field(default=None, repr=False)
    data: object = field(default=None, repr=False)
    form: object = field(default=None, repr=False)

    def objective(self, x: np.ndarray) -> float:
        """½ xᵀ P x + qᵀ x."""
        x = np.asarray(x, dtype=float)
        return float(0.5 * x @ (self.qp.P @ x) + self.qp.q @ x)

    def x_from_result(self, result) -> np.ndarray:
        """The standard-form x of a plateqp :class:`~plateqp.results.Result` of the same scene.

        Primal: (u / S, t) with S the dof scales and t = √ρ̃ R̃ for the elastic supports;
        condensed: the scaled gaps gap / W; dual: the scaled reactions R / F0.
        """
        d = self.data
        if self.formulation == "primal":
            u = result.u[self.model.free] / d.dof_scale
            el = np.flatnonzero(d.rho > 0)
            return np.concatenate([u, np.sqrt(d.rho[el]) * result.reactions[el] / d.F0])
        if self.formulation == "condensed":
            return np.asarray(result.gaps) / d.W
        return np.asarray(result.reactions) / d.F0

    def result(self, x, z=None, accuracy: str = "default", solver: str = "external"):
        """A plateqp Result (user units, KKT report) from a solution of the exported QP.

        ``x``: the primal solution; ``z``: the multipliers of G x ≤ h, needed for the primal
        form only (they are the scaled reactions). The status is OPTIMAL if the KKT residuals
        meet ``accuracy``, else INACCURATE.
        """
        from .contact import finish

        if self.form is None:
            raise ExportError("this problem was read from a file: build it with contact_qp() to map solutions back")
        x = np.asarray(x, dtype=float).reshape(-1)
        if x.shape[0] != self.qp.n:
            raise ExportError(f"x has length {x.shape[0]}, expected {self.qp.n}")
        if self.formulation == "primal" and z is None:
            raise ExportError("the primal form needs z, the multipliers of G x <= h (the scaled reactions)")
        raw = RawSolution(Status.OPTIMAL, x=x, z=None if z is None else np.asarray(z, dtype=float))
        return finish(self.model, self.form, raw, accuracy, solver)


def _safe_name(name: str) -> str:
    out = _NAME_OK.sub("_", str(name)).strip("_")
    return out or "plateqp"


def contact_qp(scene_or_model, formulation: str = "primal", name: str | None = None) -> ExportedQP:
    """The contact problem of a scene (or a built Model) in standard QP form.

    The very problem :func:`plateqp.solve` hands a QP backend for this formulation: the data
    are scaled by :meth:`Scaled.from_model <plateqp.contact.scaling.Scaled.from_model>` and
    formulated by :func:`plateqp.contact.formulations.formulate`.

    Parameters
    ----------
    scene_or_model : a :class:`~plateqp.scene.Scene` or a :class:`~plateqp.assembly.Model`
    formulation : "primal", "condensed" or "dual" (no "auto": an export says what it is)
    name : problem name (default: the scene's name and the formulation)
    """
    from .assembly import Model, build_model
    from .contact import FORMULATIONS, Scaled, equilibrium_possible, formulate

    if formulation not in FORMULATIONS:
        raise ProblemError(f"unknown formulation {formulation!r}; choose one of {FORMULATIONS}")
    model = scene_or_model if isinstance(scene_or_model, Model) else build_model(scene_or_model)
    if model.contacts is None or model.contacts.m == 0:
        raise ProblemError(f"scene {model.scene.name!r} has no one-sided supports: there is no contact problem to export")
    data = Scaled.from_model(model)
    form = formulate(data, formulation)
    qp = form.problem(frozenset({"qp"}))
    c = model.contacts
    # contact point i: a discrete support (its index in the scene) or a bed node
    tags = [f"{i}" if src == "support" else f"bed{j}" for i, (src, j) in enumerate(zip(c.source, c.index))]
    if formulation == "primal":
        el = np.flatnonzero(data.rho > 0)
        nd = model.element.ndof_node
        dn = model.element.dof_names
        var_names = [f"{dn[k % nd]}_{k // nd}" for k in model.free] + [f"t_{tags[i]}" for i in el]
        row_names = [f"gap_{t}" for t in tags]
        meaning = ("x = (u / S, t): free dofs u (w, slopes, twist per node) over their scales S "
                   "(W, W/L, W/L^2), then t = sqrt(rho~) R~ for each elastic support; "
                   "the multipliers of the G rows are the reactions R / F0")
    elif formulation == "condensed":
        var_names, row_names = [f"z_{t}" for t in tags], []
        meaning = "x = gaps / W at the contact points; reactions R / F0 = P x + q"
    else:
        var_names, row_names = [f"R_{t}" for t in tags], []
        meaning = "x = reactions / F0 at the contact points; gaps / W = P x + q"
    possible, why = equilibrium_possible(data)
    sc = model.scene
    meta = {
        "generator": f"plateqp {_version()} (plateqp.export.contact_qp)",
        "scene": sc.name,
        "formulation": formulation,
        "plate": {"a": sc.plate.a, "b": sc.plate.b, "h": sc.plate.h, "E": sc.plate.E, "nu": sc.plate.nu},
        "mesh": {"nx": sc.mesh.nx, "ny": sc.mesh.ny, "element": sc.mesh.element},
        "n_dofs": int(data.n),
        "n_contacts": int(data.m),
        "n_elastic": int(np.count_nonzero(data.rho > 0)),
        "floating": bool(data.floating),
        "equilibrium_possible": bool(possible),
        "L": float(data.L),
        "W": float(data.W),
        "F0": float(data.F0),
        "x": meaning,
        "objective": "scaled potential energy / (F0 W)" if formulation == "primal" else
                     "scaled complementary form (not the potential energy)",
    }
    if not possible:
        meta["why_no_equilibrium"] = why
    return ExportedQP(_safe_name(name or f"{sc.name}_{formulation}"), formulation, qp, var_names, row_names,
                      meta, model=model, data=data, form=form)


def _version() -> str:
    from . import __version__

    return __version__


# --------------------------------------------------------------------------------------------
# QPS (Maros–Meszaros), free MPS


@dataclass
class QPSInfo:
    """What a QPS file says besides the QP: names, objective constant, comment lines."""

    name: str
    var_names: list[str]
    row_names: list[str]  # the rows of G (L rows, G rows negated, ranged rows split)
    eq_names: list[str]  # the rows of A (E rows)
    offset: float = 0.0
    comments: list[str] = field(default_factory=list)


def _num(v: float) -> str:
    return repr(float(v))


def _unpack(qp) -> tuple[QP, list[str] | None, list[str] | None, dict | None]:
    if isinstance(qp, ExportedQP):
        return qp.qp, qp.var_names, qp.row_names, qp.meta
    return qp, None, None, None


def write_qps(qp, path, name: str | None = None, *, var_names=None, row_names=None, eq_names=None,
              offset: float = 0.0, comments=()) -> Path:
    """Write a QP as a Maros–Meszaros QPS file (free MPS with QUADOBJ).

    Parameters
    ----------
    qp : a :class:`~plateqp.backends.base.QP` or an :class:`ExportedQP` (then its names and
        metadata are used: the metadata goes to ``*`` comment lines as JSON)
    path : the file to write
    name : the NAME record (default: the exported problem's name, else the file's stem)
    var_names, row_names, eq_names : names of the variables, G rows and A rows
        (default ``x0…``, ``g0…``, ``e0…``); no spaces
    offset : objective constant c0, written as −c0 on the objective row of RHS (the MPS sign)
    comments : extra comment lines

    P is written as its lower triangle; a reader mirrors it, so a P that is not exactly
    symmetric comes back as tril(P) + tril(P, −1)ᵀ.
    """
    if name is None:
        name = qp.name if isinstance(qp, ExportedQP) else Path(path).stem
    qp, vn, rn, meta = _unpack(qp)
    path = Path(path)
    n = qp.n
    var_names = list(var_names or vn or [f"x{j}" for j in range(n)])
    mG = 0 if qp.G is None else qp.G.shape[0]
    mA = 0 if qp.A is None else qp.A.shape[0]
    row_names = list(row_names or rn or [f"g{i}" for i in range(mG)])
    eq_names = list(eq_names or [f"e{i}" for i in range(mA)])
    if not name or any(ch.isspace() for ch in name):
        raise ExportError(f"problem name {name!r}: must be non-empty and without spaces")
    for what, names, size in (("var_names", var_names, n), ("row_names", row_names, mG), ("eq_names", eq_names, mA)):
        if len(names) != size:
            raise ExportError(f"{what} has {len(names)} names, expected {size}")
        bad = [s for s in names if not s or any(ch.isspace() for ch in s)]
        if bad:
            raise ExportError(f"{what}: names must be non-empty and without spaces (got {bad[0]!r})")
    all_rows = ["obj", *row_names, *eq_names]
    if len(set(all_rows)) != len(all_rows) or len(set(var_names)) != n:
        raise ExportError("row and variable names must be unique (the objective row is 'obj')")

    P = sp.csc_matrix(qp.P)
    Pl = sp.tril(P, format="csc")
    Pl.eliminate_zeros()
    Pl.sort_indices()
    G = sp.csc_matrix(qp.G, copy=True) if mG else sp.csc_matrix((0, n))  # copies: the caller's QP stays as it is
    A = sp.csc_matrix(qp.A, copy=True) if mA else sp.csc_matrix((0, n))
    for M in (G, A):
        M.eliminate_zeros()
        M.sort_indices()
    lb = np.full(n, -np.inf) if qp.lb is None else qp.lb
    ub = np.full(n, np.inf) if qp.ub is None else qp.ub
    if np.any(lb > ub):
        raise ExportError("lb > ub for some variable")

    out: list[str] = []
    w = out.append
    w(f"* {name}: convex QP in Maros-Meszaros QPS form (free MPS), objective 1/2 x'Px + q'x + c0")
    w("* QUADOBJ holds the lower triangle of P; numbers are Python repr() of IEEE doubles (exact)")
    if meta is not None:
        for line in json.dumps(meta, indent=1, sort_keys=True).splitlines():
            w(f"* {line}")
    for c in comments:
        for line in str(c).splitlines():
            w(f"* {line}")
    w(f"NAME          {name}")
    w("ROWS")
    w(" N  obj")
    for r in row_names:
        w(f" L  {r}")
    for r in eq_names:
        w(f" E  {r}")
    w("COLUMNS")
    q = qp.q
    for j in range(n):
        vj = var_names[j]
        gl, gh = G.indptr[j], G.indptr[j + 1]
        al, ah = A.indptr[j], A.indptr[j + 1]
        if q[j] != 0.0 or (gl == gh and al == ah):  # every column appears at least once
            w(f"    {vj}  obj  {_num(q[j])}")
        for i, v in zip(G.indices[gl:gh], G.data[gl:gh]):
            w(f"    {vj}  {row_names[i]}  {_num(v)}")
        for i, v in zip(A.indices[al:ah], A.data[al:ah]):
            w(f"    {vj}  {eq_names[i]}  {_num(v)}")
    w("RHS")
    if offset:
        w(f"    rhs  obj  {_num(-offset)}")
    for r, v in zip(row_names, qp.h if mG else ()):
        if v != 0.0:
            w(f"    rhs  {r}  {_num(v)}")
    for r, v in zip(eq_names, qp.b if mA else ()):
        if v != 0.0:
            w(f"    rhs  {r}  {_num(v)}")
    w("BOUNDS")
    for j in range(n):
        lo, hi, vj = lb[j], ub[j], var_names[j]
        if lo == hi:
            w(f" FX bnd  {vj}  {_num(lo)}")
        elif lo == -np.inf and hi == np.inf:
            w(f" FR bnd  {vj}")
        else:
            # the lower bound first and always explicit: an UP < 0 without one is read as
            # (−inf, UP] by some readers and (0, UP] (infeasible) by others
            w(f" MI bnd  {vj}" if lo == -np.inf else f" LO bnd  {vj}  {_num(lo)}")
            if hi != np.inf:
                w(f" UP bnd  {vj}  {_num(hi)}")
    if Pl.nnz:
        w("QUADOBJ")
        for j in range(n):
            for i, v in zip(Pl.indices[Pl.indptr[j]:Pl.indptr[j + 1]], Pl.data[Pl.indptr[j]:Pl.indptr[j + 1]]):
                w(f"    {var_names[j]}  {var_names[i]}  {_num(v)}")
    w("ENDATA")
    path.write_text("\n".join(out) + "\n")
    return path


def read_qps(path, with_info: bool = False):
    """Read a QPS / MPS file (free format, or fixed format whose names have no spaces) as a QP.

    Rows: N (the first is the objective), L and G (as G x ≤ h, a G row negated), E (A x = b);
    RANGES split a row into two inequalities (or bound an E row); BOUNDS LO, UP, FX, FR, MI,
    PL; QUADOBJ / QSECTION (lower triangle, mirrored) or QMATRIX (full). Integer markers are
    refused. ``with_info``: also return a :class:`QPSInfo` (names, objective constant, comments).
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exn:
        raise ExportError(f"{path}: cannot read ({exn})") from exn
    name = ""
    comments: list[str] = []
    obj_row = None
    row_kind: dict[str, str] = {}
    row_order: list[str] = []
    cols: dict[str, int] = {}
    entries: list[tuple[str, int, float]] = []  # (row, col, value)
    q_obj: dict[int, float] = {}
    rhs: dict[str, float] = {}
    ranges: dict[str, float] = {}
    bounds: list[tuple[str, int, float]] = []
    quad: list[tuple[int, int, float]] = []
    quad_full = False
    offset = 0.0
    section = None

    def fail(lineno, what):
        raise ExportError(f"{path}:{lineno}: {what}")

    def col(lineno, c):
        if c not in cols:
            fail(lineno, f"unknown column {c!r}")
        return cols[c]

    def pairs(lineno, toks):
        if len(toks) % 2:
            fail(lineno, "expected name/value pairs")
        for k in range(0, len(toks), 2):
            try:
                yield toks[k], float(toks[k + 1])
            except ValueError:
                fail(lineno, f"not a number: {toks[k + 1]!r}")

    for lineno, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        if line.startswith("*"):
            comments.append(line[1:].strip() if not line.startswith("* ") else line[2:])
            continue
        toks = line.split()
        if not line[0].isspace():  # a section header
            section = toks[0].upper()
            if section == "NAME":
                name = " ".join(toks[1:])
            elif section in ("QMATRIX",):
                quad_full = True
            elif section == "OBJSENSE":
                fail(lineno, "OBJSENSE is not supported (minimisation only)")
            elif section not in ("ROWS", "COLUMNS", "RHS", "RANGES", "BOUNDS", "QUADOBJ", "QSECTION", "ENDATA"):
                fail(lineno, f"unknown section {section!r}")
            if section == "ENDATA":
                break
            continue
        if section == "ROWS":
            kind, r = toks[0].upper(), toks[1]
            if kind not in ("N", "L", "G", "E"):
                fail(lineno, f"unknown row type {kind!r}")
            if kind == "N":
                if obj_row is None:
                    obj_row = r
                continue  # further N rows are free rows: ignored
            row_kind[r] = kind
            row_order.append(r)
        elif section == "COLUMNS":
            if "'MARKER'" in line:
                fail(lineno, "integer markers: not a continuous QP")
            c = toks[0]
            if c not in cols:
                cols[c] = len(cols)
            j = cols[c]
            for r, v in pairs(lineno, toks[1:]):
                if r == obj_row:
                    q_obj[j] = q_obj.get(j, 0.0) + v
                elif r in row_kind:
                    entries.append((r, j, v))
                else:
                    fail(lineno, f"unknown row {r!r}")
        elif section in ("RHS", "RANGES"):
            vals = toks[1:] if len(toks) % 2 else toks  # the set name is optional
            for r, v in pairs(lineno, vals):
                if section == "RHS" and r == obj_row:
                    offset = -v
                elif r in row_kind:
                    (rhs if section == "RHS" else ranges)[r] = v
                else:
                    fail(lineno, f"unknown row {r!r}")
        elif section == "BOUNDS":
            kind = toks[0].upper()
            if kind in ("FR", "MI", "PL"):
                c = toks[-1] if len(toks) in (2, 3) else fail(lineno, "bad bound record")
                bounds.append((kind, col(lineno, c), 0.0))
            elif kind in ("LO", "UP", "FX"):
                if len(toks) not in (3, 4):
                    fail(lineno, "bad bound record")
                try:
                    v = float(toks[-1])
                except ValueError:
                    fail(lineno, f"not a number: {toks[-1]!r}")
                bounds.append((kind, col(lineno, toks[-2]), v))
            else:
                fail(lineno, f"bound type {kind!r} is not supported")
        elif section in ("QUADOBJ", "QSECTION", "QMATRIX"):
            if len(toks) != 3:
                fail(lineno, "expected: column column value")
            try:
                v = float(toks[2])
            except ValueError:
                fail(lineno, f"not a number: {toks[2]!r}")
            quad.append((col(lineno, toks[0]), col(lineno, toks[1]), v))
        else:
            fail(lineno, f"data outside a section: {line.strip()!r}")
    if obj_row is None:
        raise ExportError(f"{path}: no objective (N) row")
    n = len(cols)
    var_names = list(cols)
    q = np.zeros(n)
    for j, v in q_obj.items():
        q[j] = v
    # rows: L and G become G x <= h (a G row negated); E rows A x = b; a range adds the other side
    ineq: list[tuple[str, str, float, float]] = []  # (name, source row, sign, rhs)
    eqs: list[str] = []
    eq_rhs: list[float] = []
    for r in row_order:
        k, v, R = row_kind[r], rhs.get(r, 0.0), ranges.get(r)
        if k == "E" and R is None:
            eqs.append(r)
            eq_rhs.append(v)
            continue
        if k == "E":  # [v, v + R] if R > 0 else [v + R, v]
            lo, hi = (v, v + R) if R > 0 else (v + R, v)
        elif k == "L":
            lo, hi = (-np.inf if R is None else v - abs(R)), v
        else:  # G
            lo, hi = v, (np.inf if R is None else v + abs(R))
        if hi < np.inf:
            ineq.append((r if k != "G" else r + "_hi", r, 1.0, hi))
        if lo > -np.inf:
            ineq.append((r if k == "G" else r + "_lo", r, -1.0, -lo))
    rows_of: dict[str, list[tuple[int, float]]] = {}
    for k, (_, r, s, _) in enumerate(ineq):
        rows_of.setdefault(r, []).append((k, s))
    eq_index = {r: i for i, r in enumerate(eqs)}
    gi, gj, gv, ai, aj, av = [], [], [], [], [], []
    for r, j, v in entries:
        if r in eq_index:
            ai.append(eq_index[r])
            aj.append(j)
            av.append(v)
        for k, s in rows_of.get(r, ()):
            gi.append(k)
            gj.append(j)
            gv.append(s * v)
    G = sp.csc_matrix((gv, (gi, gj)), shape=(len(ineq), n)) if ineq else None
    A = sp.csc_matrix((av, (ai, aj)), shape=(len(eqs), n)) if eqs else None
    # bounds: the MPS default is [0, +inf)
    lb, ub = np.zeros(n), np.full(n, np.inf)
    for kind, j, v in bounds:
        if kind == "LO":
            lb[j] = v
        elif kind == "UP":
            ub[j] = v
        elif kind == "FX":
            lb[j] = ub[j] = v
        elif kind == "FR":
            lb[j], ub[j] = -np.inf, np.inf
        elif kind == "MI":
            lb[j] = -np.inf
        else:  # PL
            ub[j] = np.inf
    if quad:
        qi, qj, qv = (np.array(t) for t in zip(*quad))
        qi, qj = qi.astype(int), qj.astype(int)
        if quad_full:
            P = sp.csc_matrix((qv, (qi, qj)), shape=(n, n))
        else:
            L = sp.csc_matrix((qv, (np.maximum(qi, qj), np.minimum(qi, qj))), shape=(n, n))
            P = (L + sp.tril(L, -1, format="csc").T).tocsc()
    else:
        P = sp.csc_matrix((n, n))
    P.sort_indices()
    qp = QP(P=P, q=q, G=G, h=None if G is None else np.array([t[3] for t in ineq]),
            A=A, b=None if A is None else np.array(eq_rhs),
            lb=None if np.all(lb == -np.inf) else lb, ub=None if np.all(ub == np.inf) else ub)
    if not with_info:
        return qp
    return qp, QPSInfo(name, var_names, [t[0] for t in ineq], eqs, offset, comments)


# --------------------------------------------------------------------------------------------
# qpbenchmark test sets: one .npz per problem and a generated TestSet module


def write_npz(qp, path, meta: dict | None = None) -> Path:
    """One problem as ``.npz``: vectors as arrays, sparse matrices as CSC components.

    Keys: ``q`` and, where present, ``h``, ``b``, ``lb``, ``ub``; a matrix M in P, G, A is
    either ``M`` (dense 2-D array) or ``M_data``, ``M_indices``, ``M_indptr``, ``M_shape``
    (its CSC components, never densified); ``meta``: a JSON string (names, scales).
    """
    qp, vn, rn, emeta = _unpack(qp)
    meta = dict(emeta or {}, **(meta or {}))
    if vn is not None:
        meta.setdefault("var_names", vn)
        meta.setdefault("row_names", rn)
    arrays: dict[str, np.ndarray] = {"q": qp.q}
    for key in ("h", "b", "lb", "ub"):
        v = getattr(qp, key)
        if v is not None:
            arrays[key] = np.asarray(v, dtype=float)
    for key in ("P", "G", "A"):
        M = getattr(qp, key)
        if M is None:
            continue
        if sp.issparse(M):
            M = sp.csc_matrix(M, copy=True)
            M.sort_indices()
            arrays[f"{key}_data"] = M.data.astype(float)
            arrays[f"{key}_indices"] = M.indices.astype(np.int64)
            arrays[f"{key}_indptr"] = M.indptr.astype(np.int64)
            arrays[f"{key}_shape"] = np.array(M.shape, dtype=np.int64)
        else:
            arrays[key] = np.asarray(M, dtype=float)
    arrays["meta"] = np.array(json.dumps(meta, sort_keys=True))
    path = Path(path)
    np.savez_compressed(path, **arrays)
    return path


def read_npz(path, with_meta: bool = False):
    """Read a problem written by :func:`write_npz` as a QP (and its metadata)."""
    with np.load(path, allow_pickle=False) as f:
        keys = set(f.files)

        def mat(key):
            if key in keys:
                return np.array(f[key])
            if f"{key}_data" in keys:
                shape = tuple(int(s) for s in f[f"{key}_shape"])
                return sp.csc_matrix((f[f"{key}_data"], f[f"{key}_indices"], f[f"{key}_indptr"]), shape=shape)
            return None

        def vec(key):
            return np.array(f[key]) if key in keys else None

        qp = QP(P=mat("P"), q=vec("q"), G=mat("G"), h=vec("h"), A=mat("A"), b=vec("b"), lb=vec("lb"), ub=vec("ub"))
        meta = json.loads(str(f["meta"])) if "meta" in keys else {}
    return (qp, meta) if with_meta else qp


def qpbenchmark_class_name(module_name: str) -> str:
    """The class name qpbenchmark looks for in a test-set module (its ``load_test_set``)."""
    return module_name.title().replace("_", "")


_TESTSET_TEMPLATE = '''"""qpbenchmark test set: {title}.

Generated by {generator} (plateqp.export.write_qpbenchmark); regenerate rather than edit.
Run it with ``qpbenchmark {module}.py run`` (or ``... --results-path results/{module}.csv run``).
It needs numpy, scipy and qpbenchmark only: the problems are the .npz files in {data_dir}/.

{description}
"""

from pathlib import Path

import numpy as np
import scipy.sparse as spa
from qpbenchmark import Problem, TestSet, Tolerance

DATA = Path(__file__).resolve().parent / {data_dir!r}
PROBLEMS = {problems!r}


def load_problem(path) -> Problem:
    """One problem: vectors as arrays, matrices dense or as CSC components (M_data, ...)."""
    path = Path(path)
    with np.load(path, allow_pickle=False) as f:
        keys = set(f.files)

        def mat(key):
            if key in keys:
                return np.array(f[key])
            if key + "_data" in keys:
                shape = tuple(int(s) for s in f[key + "_shape"])
                return spa.csc_matrix((np.array(f[key + "_data"]), np.array(f[key + "_indices"]),
                                       np.array(f[key + "_indptr"])), shape=shape)
            return None

        def vec(key):
            return np.array(f[key]) if key in keys else None

        return Problem(mat("P"), vec("q"), mat("G"), vec("h"), mat("A"), vec("b"), vec("lb"), vec("ub"),
                       name=path.stem)


class {cls}(TestSet):
    """{title}"""

    @property
    def description(self) -> str:
        return {description!r}

    @property
    def title(self) -> str:
        return {title!r}

    @property
    def sparse_only(self) -> bool:
        return {sparse_only!r}

    def define_tolerances(self, runtime: float = {runtime!r}) -> None:
        # primal residual, dual residual and duality gap, each absolute, per settings
        self.tolerances = {{
            name: Tolerance(primal=tol, dual=tol, gap=tol, runtime=runtime)
            for name, tol in {tolerances!r}.items()
        }}

    def __iter__(self):
        for name in PROBLEMS:
            yield load_problem(DATA / (name + ".npz"))
'''


def write_qpbenchmark(problems, directory, name: str = "plateqp_contact", *, title: str | None = None,
                      description: str | None = None, sparse_only: bool | None = None, runtime: float = 10.0,
                      data_dir: str = "data", force: bool = False) -> Path:
    """Write a qpbenchmark test set: ``directory/<name>.py`` and ``directory/<data_dir>/*.npz``.

    Parameters
    ----------
    problems : :class:`ExportedQP` objects (or (name, QP) pairs); names must be unique
    name : the module name (a Python identifier); qpbenchmark loads the class
        ``name.title().replace("_", "")`` from it (:func:`qpbenchmark_class_name`)
    sparse_only : restrict the run to solvers with a sparse API (default: if any problem has a
        sparse P, as the primal form does)
    runtime : the time limit of every settings, in seconds
    force : write into a non-empty directory (files of the same names are replaced)

    Returns the path of the module.
    """
    if not name.isidentifier() or name.startswith("_"):
        raise ExportError(f"test-set name {name!r} must be a Python identifier (it is imported as a module)")
    directory = Path(directory)
    if directory.exists() and not directory.is_dir():
        raise ExportError(f"{directory}: exists and is not a directory")
    if directory.is_dir() and any(directory.iterdir()) and not force:
        raise ExportError(f"{directory}: exists and is not empty; use --force (force=True) to write into it")
    items = []
    for p in problems:
        if isinstance(p, ExportedQP):
            items.append((p.name, p))
        else:
            pname, qp = p
            items.append((_safe_name(pname), qp))
    names = [n for n, _ in items]
    if not items:
        raise ExportError("no problems to export")
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise ExportError(f"problem names must be unique (twice: {dup!r})")
    if sparse_only is None:
        sparse_only = any(sp.issparse(_unpack(qp)[0].P) for _, qp in items)
    (directory / data_dir).mkdir(parents=True, exist_ok=True)
    (directory / "results").mkdir(exist_ok=True)  # where `qpbenchmark ... --results-path results/...` writes
    for pname, qp in items:
        write_npz(qp, directory / data_dir / f"{pname}.npz")
    forms = sorted({qp.formulation for _, qp in items if isinstance(qp, ExportedQP)})
    title = title or f"plateqp contact problems ({', '.join(forms) or 'QP'})"
    description = description or (
        "Kirchhoff plates on one-sided supports (rigid or elastic, with gaps), the contact problem as "
        "a convex QP exported by plateqp: nondimensional (deflections by W, forces by F0), in the "
        f"formulation(s) {', '.join(forms) or '-'}. Each problem's .npz holds its scales and the "
        "meaning of x in its 'meta' entry.")
    text = _TESTSET_TEMPLATE.format(
        title=title, description=description, generator=f"plateqp {_version()}", module=name,
        data_dir=data_dir, problems=names, cls=qpbenchmark_class_name(name), sparse_only=bool(sparse_only),
        runtime=float(runtime), tolerances={k: v[0] for k, v in QPBENCHMARK_TOLERANCES.items()})
    module = directory / f"{name}.py"
    module.write_text(text)
    return module
