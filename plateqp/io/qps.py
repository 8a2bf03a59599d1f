r"""Maros–Meszaros QPS files: free MPS with a ``QUADOBJ`` section holding the lower triangle of P.

The QP is

.. math::

    \min_x\ \tfrac12 x^T P x + q^T x + c_0
    \quad\text{s.t.}\quad G x \le h\ (\text{L rows}),\quad A x = b\ (\text{E rows}),
    \quad lb \le x \le ub\ (\text{BOUNDS}).

Every number is written with ``repr`` (the shortest string that reads back to the same double,
at most 17 significant digits), so a reader that parses with ``strtod`` gets the very same
matrices. Free MPS, not fixed-column: fixed columns leave 12 characters per number, too few for
full precision. :func:`read_qps` reads it back (and the usual QPS files: N/L/G/E rows, RANGES,
BOUNDS, QUADOBJ or QMATRIX).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..backends.base import QP
from ..errors import ExportError
from .export import ExportedQP, unpack


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
    qp, vn, rn, meta = unpack(qp)
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
    from .safe import write

    return write(path, "\n".join(out) + "\n", force=True)  # over a file, never through a link


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
