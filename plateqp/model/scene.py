"""The scene: what the user describes. Dataclasses, validation and TOML load/save.

A scene is pure data; :func:`plateqp.model.assembly.build_model` turns it into matrices.
Every check raises :class:`~plateqp.errors.SceneError` naming the field (``supports.3.gap``)
and, for a scene read from a file, the file.

Units: any consistent set. The plate occupies [0, a] × [0, b] (or, on triangles, a ``plate.shape``
less its ``holes``: :mod:`plateqp.model.geometry`); w and loads are positive downward; a gap ``g0 > 0`` is
settlement (support below the plate), ``g0 < 0`` heave (support pushed into the plate).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any, Callable

from .checks import check_scene
from .elements import ELEMENTS
from ..errors import SceneError
from .parts import _short, check_parts, check_path, check_table

#: Magnitudes plateqp computes with safely: a non-zero physical number (length, modulus, load,
#: gap, stiffness, prescribed displacement) must lie in this range, and so must the bending
#: stiffness D and the load's deflection scale 0.01 F L²/D derived from them (checked in
#: logarithms, so that an overflow is reported, not computed). The solve is nondimensional, so
#: any consistent units inside this range give the same answer scaled (tests/model/test_scene.py);
#: outside it products of the data overflow or underflow double precision: change units.
SAFE_RANGE = (1e-100, 1e100)
#: The derived quantities' range (wider: products of two or three safe numbers).
SAFE_DERIVED = (1e-200, 1e200)
#: A scene file larger than this is not a scene (it is read no further).
MAX_FILE_BYTES = 16 * 2**20

EDGE_NAMES = ("left", "right", "bottom", "top")  # x = 0, x = a, y = 0, y = b


@dataclass
class Plate:
    """Rectangle [0, a] × [0, b] (or a ``shape``: :mod:`plateqp.model.geometry`), thickness h, E, ν."""

    a: float = 1.0
    b: float = 1.0
    h: float = 0.01
    E: float = 1.0e7
    nu: float = 0.3
    shape: dict | None = None

    @property
    def D(self) -> float:
        """Bending stiffness D = E h³ / (12 (1 − ν²))."""
        return self.E * self.h**3 / (12.0 * (1.0 - self.nu**2))


@dataclass
class MeshSpec:
    """An nx × ny grid of equal rectangles and the element; "dkt": triangles of size ``size``.
    ``symmetry``: "x", "y" or "xy", a mesh that is its own mirror image in the plate's centre
    line x = xc, y = yc or both (:mod:`plateqp.model.symmetry`); None: no such demand."""

    nx: int = 16
    ny: int = 16
    element: str = "acm"
    size: float | None = None
    symmetry: str | None = None


@dataclass
class Edge:
    """Two-sided support along one edge.

    ``kind``: "free", "simple" (w = w_value) or "clamped" (w = w_value and ∂w/∂n = slope,
    n the outward normal). Non-zero ``w`` and ``slope`` are the source paper's w = f1,
    ∂w/∂n = f2 (constant along the edge).
    """

    kind: str = "free"
    w: float = 0.0
    slope: float = 0.0


@dataclass
class Opening:
    """A cut-out: every cell whose centre lies in [x0, x1] × [y0, y1] is removed."""

    x0: float
    x1: float
    y0: float
    y1: float


@dataclass
class Pin:
    """Two-sided point support at a mesh node: w = ``w`` there."""

    x: float
    y: float
    w: float = 0.0


@dataclass
class UniformLoad:
    """Pressure q over the whole plate (force/length²)."""

    q: float
    type: str = field(default="uniform", init=False)


@dataclass
class PatchLoad:
    """Pressure q over the box [x0, x1] × [y0, y1], or over ``region`` instead: a box
    [x0, x1, y0, y1], ``{polygon = [[x, y], ...]}`` or ``{circle = [xc, yc, r]}``, on every mesh
    (:func:`plateqp.model.geometry.parse_region`), integrated exactly over each cell's part in it
    (a circle's arcs to rounding: :mod:`plateqp.model.regions`)."""

    q: float
    x0: float | None = None
    x1: float | None = None
    y0: float | None = None
    y1: float | None = None
    region: list[float] | dict | None = None
    type: str = field(default="patch", init=False)

    @property
    def extent(self) -> list[float] | dict:
        """The patch's region in its scene form: ``region``, or the box [x0, x1, y0, y1]."""
        return self.region if self.region is not None else [self.x0, self.x1, self.y0, self.y1]


@dataclass
class PointLoad:
    """Point force P at (x, y), anywhere on the plate (consistent nodal loads)."""

    P: float
    x: float
    y: float
    type: str = field(default="point", init=False)


Load = UniformLoad | PatchLoad | PointLoad
_LOADS: dict[str, type] = {"uniform": UniformLoad, "patch": PatchLoad, "point": PointLoad}


@dataclass
class Support:
    """One-sided discrete support at (x, y) with initial gap g0 (``gap``).

    ``stiffness``: ``"rigid"`` or a positive number c (force/length): an elastic support with
    R = c s, s its compression. A support off the mesh nodes acts through the element's
    interpolation of w at that point.
    """

    x: float
    y: float
    gap: float = 0.0
    stiffness: float | str = "rigid"

    @property
    def rigid(self) -> bool:
        return isinstance(self.stiffness, str)


@dataclass
class Foundation:
    """Tensionless soil under the plate over ``region`` (whole plate if None): the box
    [x0, x1, y0, y1], ``{polygon = [[x, y], ...]}`` or ``{circle = [xc, yc, r]}``, on every mesh
    (:func:`plateqp.model.geometry.parse_region`). The soil never pulls the plate.

    ``model``: ``"winkler"`` (the default): independent springs of modulus ``k``
    (force/length³); ``"pasternak"``: springs ``k`` joined by a shear layer of ``shear`` (c2,
    force/length), the soil's surface its own unknowns; ``"halfspace"``: an elastic half-space
    of modulus ``E`` and Poisson's ratio ``nu`` (Boussinesq's surface flexibility), its surface
    its own unknowns (:mod:`plateqp.model.soil`).

    ``gap``: a number, a dict profile (``{profile = "linear", g0, gx, gy}``,
    ``{profile = "trough" | "bump", x, y, radius, depth}``) or, in Python, any callable
    g0(x, y) taking and returning arrays.
    """

    k: float | None = None
    region: list[float] | dict | None = None
    gap: float | dict | Callable = 0.0
    model: str = "winkler"
    shear: float | None = None
    E: float | None = None
    nu: float | None = None

    def gap_at(self, x, y):
        """The initial gap field g0 at points (arrays)."""
        import numpy as np

        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        g = self.gap
        if callable(g):
            return np.broadcast_to(np.asarray(g(x, y), dtype=float), x.shape).copy()
        if isinstance(g, dict):
            prof = g.get("profile", "uniform")
            if prof == "uniform":
                return np.full(x.shape, float(g.get("g0", 0.0)))
            if prof == "linear":
                return g.get("g0", 0.0) + g.get("gx", 0.0) * x + g.get("gy", 0.0) * y
            # trough (settlement, g0 > 0) or bump (heave, g0 < 0): smooth (1 − r²/R²)² bell
            r2 = ((x - g["x"]) ** 2 + (y - g["y"]) ** 2) / g["radius"] ** 2
            bell = np.where(r2 < 1.0, (1.0 - r2) ** 2, 0.0)
            sign = 1.0 if prof == "trough" else -1.0
            return sign * abs(g["depth"]) * bell
        return np.full(x.shape, float(g))


@dataclass
class Scene:
    """Everything a plate problem needs; validated on construction."""

    name: str = "scene"
    plate: Plate = field(default_factory=Plate)
    mesh: MeshSpec = field(default_factory=MeshSpec)
    edges: dict[str, Edge] = field(default_factory=dict)
    openings: list[Opening] = field(default_factory=list)
    pins: list[Pin] = field(default_factory=list)
    loads: list[Load] = field(default_factory=list)
    supports: list[Support] = field(default_factory=list)
    foundation: Foundation | None = None
    holes: list = field(default_factory=list)  # shapes (dicts) cut out of a triangle-meshed plate
    source: str | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        _check_parts(self)
        # tuples given in Python become lists, as they come back from TOML (exact round trips)
        for key in ("openings", "pins", "loads", "supports", "holes"):
            if isinstance(getattr(self, key), tuple):
                setattr(self, key, list(getattr(self, key)))
        if self.foundation is not None and isinstance(self.foundation.region, tuple):
            self.foundation.region = list(self.foundation.region)
        for ld in self.loads:
            if isinstance(ld, PatchLoad) and isinstance(ld.region, tuple):
                ld.region = list(ld.region)
        self.edges = {k: (v if isinstance(v, Edge) else _edge_from(v, f"edges.{k}", self.source))
                      for k, v in self.edges.items()}
        self.validate()

    def side_edges(self) -> dict:
        """The edges of a rectangle by side (left, right, bottom, top), ``edges.all`` filling the
        sides not named (the most specific name holds); a shaped plate's edges are not sides: {}."""
        if self.plate.shape is not None:
            return {}
        every = self.edges.get("all")
        sides = {n: self.edges.get(n, every) for n in EDGE_NAMES}
        return {n: e for n, e in sides.items() if e is not None}

    # -- validation -----------------------------------------------------------------------
    def _fail(self, where: str, what: str):
        prefix = f"{self.source}: " if self.source else ""
        raise SceneError(f"{prefix}{where}: {what}")

    def _num(self, where: str, v, *, positive=False, nonneg=False, physical=False) -> float:
        """A finite number (``physical``: 0 or of a magnitude in :data:`SAFE_RANGE`)."""
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            self._fail(where, f"must be a number (got {_short(v)})")
        try:
            fv = float(v)
        except OverflowError:  # an integer beyond double precision
            fv = math.inf
        if not math.isfinite(fv):
            self._fail(where, f"must be finite (got {_short(v)})")
        if positive and fv <= 0:
            self._fail(where, f"must be > 0 (got {v!r})")
        if nonneg and fv < 0:
            self._fail(where, f"must be >= 0 (got {v!r})")
        if physical and fv != 0.0 and not (SAFE_RANGE[0] <= abs(fv) <= SAFE_RANGE[1]):
            self._fail(where, f"{v!r} is outside the magnitudes plateqp computes with safely "
                       f"({SAFE_RANGE[0]:.0e} … {SAFE_RANGE[1]:.0e}); change units")
        return fv

    def _inside(self, where: str, x, y, grid=None, covered: bool | None = None) -> None:
        """Fail unless (x, y) lies on the plate. ``grid``: the scene's grid, built once per
        validation (building one per point cost ~0.15 ms, ~10 ms for 64 supports);
        ``covered``: the point's answer of ``grid.covers`` when already known (a batch)."""
        a, b = self.plate.a, self.plate.b
        tol = 1e-12 * max(a, b)
        if self.plate.shape is None and not (-tol <= x <= a + tol and -tol <= y <= b + tol):
            self._fail(where, f"point ({x}, {y}) lies outside the plate [0, {a}] x [0, {b}]")
        if covered is None:
            covered = not self.in_opening(x, y) if grid is None else grid.covers(x, y)
        if not covered:
            self._fail(where, f"point ({x}, {y}) lies in an opening, in a hole or outside its shape "
                       "(no plate there)")

    def in_opening(self, x: float, y: float) -> bool:
        """True if (x, y) lies off the plate's cover: inside the removed cells of a cut-out on the
        grid, in a hole or outside the shape on triangles (:func:`plateqp.model.checks.plate_cover`)."""
        from .checks import plate_cover

        return not plate_cover(self).covers(x, y)

    @staticmethod
    def _covered(grid, points) -> list[bool] | None:
        """``grid.covers`` of every point at once (one vectorised ``locate``, the same answer
        point by point), or None if a coordinate is not a finite number (the per-field checks
        then report it in order)."""
        xs, ys = [], []
        for x, y in points:
            for v in (x, y):
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                    return None
            xs.append(x)
            ys.append(y)
        if not xs:
            return []
        import numpy as np

        xs, ys = np.array(xs, dtype=float), np.array(ys, dtype=float)
        # far off the plate: not covered, and not handed to locate (cell indices would overflow)
        near = (np.abs(xs) <= 4 * grid.a) & (np.abs(ys) <= 4 * grid.b)
        out = np.zeros(xs.shape, dtype=bool)
        if near.any():
            out[near] = grid.locate(xs[near], ys[near])[0] >= 0
        return out.tolist()

    def validate(self) -> None:
        """Check every field; raises SceneError naming the first bad one. :func:`plateqp.solve`
        calls it again, so a scene changed after construction gets the same message. The
        checks: :func:`plateqp.model.checks.check_scene`."""
        self._checked = None
        _check_parts(self)
        check_scene(self)
        self._check_scales()
        self._checked = self._fingerprint()

    def revalidate(self) -> None:
        """:meth:`validate`, unless nothing has changed since the last validation (a snapshot of
        every field, taken after it: a scene changed after construction is checked again, one
        solved as it was built is not checked twice: 3 ms for 900 supports)."""
        if getattr(self, "_checked", None) is None or self._fingerprint() != self._checked:
            self.validate()

    def _fingerprint(self):
        """A snapshot of the scene's fields that compares equal only if nothing changed: the lists'
        items by their values (plain Python scalars only), the rest by their repr. None where a
        value is not a plain scalar (a NumPy number, a list): such a scene is always checked."""
        try:
            items = tuple(v for key in ("supports", "loads", "pins", "openings") for item in getattr(self, key)
                          for v in vars(item).values())
        except TypeError:  # an item that is no dataclass: the checks say what it is
            return None
        if not all(type(v) in _SCALARS for v in items) or any(v != v for v in items if type(v) is float):
            return None
        return (tuple(len(getattr(self, k)) for k in ("supports", "loads", "pins", "openings")), items,
                repr((self.name, self.plate, self.mesh, self.edges, self.foundation, self.holes, self.source)))

    def _check_scales(self) -> None:
        """D, each load's deflection scale and each spring's relative flexibility within
        :data:`SAFE_DERIVED` (:func:`plateqp.model.scales.check_scales`)."""
        from .scales import check_scales

        check_scales(self, SAFE_DERIVED)

    # -- convenience ----------------------------------------------------------------------
    triangles = property(lambda self: isinstance(self.mesh.element, str)
                         and getattr(ELEMENTS.get(self.mesh.element), "cell_type", None) == "triangle",
                         doc="True if meshed with triangles (its element's ``cell_type``: DKT).")

    @property
    def one_sided(self) -> bool:
        """True if the scene has one-sided supports (discrete or a tensionless bed)."""
        return bool(self.supports) or self.foundation is not None

    # -- TOML -----------------------------------------------------------------------------
    @classmethod
    def from_toml(cls, path: str | Path) -> Scene:
        """Load a scene from a TOML file (UTF-8, a byte-order mark allowed; unknown keys are errors).

        Anything that is not a readable scene file (no file, a directory, unreadable, not UTF-8,
        larger than :data:`MAX_FILE_BYTES`, not TOML, nested too deep) is a SceneError naming it.
        """
        check_path(path)
        if str(path) == "":
            raise SceneError("the scene file name is an empty path")
        path = Path(path)
        try:
            with open(path, "rb") as fh:
                raw = fh.read(MAX_FILE_BYTES + 1)
        except FileNotFoundError:
            raise SceneError(f"{path}: no such file") from None
        except IsADirectoryError:
            raise SceneError(f"{path}: is a directory, not a scene file") from None
        except OSError as exn:
            raise SceneError(f"{path}: cannot be read ({exn.strerror or exn})") from None
        if len(raw) > MAX_FILE_BYTES:
            raise SceneError(f"{path}: larger than {MAX_FILE_BYTES // 2**20} MiB: not a scene file")
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError as exn:
            raise SceneError(f"{path}: not UTF-8 text (byte {exn.start}); save the scene as UTF-8") from None
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exn:
            raise SceneError(f"{path}: not valid TOML: {exn}") from None
        except RecursionError:
            raise SceneError(f"{path}: not a scene: arrays or tables nested too deep") from None
        return cls.from_dict(data, source=str(path))

    @classmethod
    def from_dict(cls, data: dict, source: str | None = None) -> Scene:
        """Build a scene from the nested dict shape of the TOML file."""
        check_table(data, source)
        prefix = f"{source}: " if source else ""

        def fail(where, what):
            raise SceneError(f"{prefix}{where}: {what}")

        def build(klass, d, where):
            if not isinstance(d, dict):
                fail(where, f"must be a table (got {d!r})")
            names = {f.name for f in fields(klass) if f.init}
            extra = set(d) - names - ({"type"} if klass in _LOADS.values() else set())
            if extra:
                fail(f"{where}.{sorted(extra, key=str)[0]}", f"unknown key; allowed: {sorted(names)}")
            try:
                return klass(**{k: v for k, v in d.items() if k != "type"})
            except TypeError as exn:
                fail(where, f"missing or bad keys ({exn})")

        top = {"name", "plate", "mesh", "edges", "openings", "pins", "loads", "supports", "foundation", "holes"}
        extra = set(data) - top
        if extra:
            fail(sorted(extra, key=str)[0], f"unknown key; allowed top-level keys: {sorted(top)}")
        name = data.get("name", "scene")
        if not isinstance(name, str):
            fail("name", f"must be a string (got {_short(name)})")
        kw: dict[str, Any] = {"name": name}
        if "plate" in data:
            kw["plate"] = build(Plate, data["plate"], "plate")
        if "mesh" in data:
            kw["mesh"] = build(MeshSpec, data["mesh"], "mesh")
        if "edges" in data:
            if not isinstance(data["edges"], dict):
                fail("edges", "must be a table")
            kw["edges"] = {k: _edge_from(v, f"edges.{k}", source) for k, v in data["edges"].items()}
        for key, klass in (("openings", Opening), ("pins", Pin), ("supports", Support)):
            items = data.get(key, [])
            if not isinstance(items, list):
                fail(key, "must be an array of tables ([[" + key + "]], not [" + key + "])")
            kw[key] = [build(klass, d, f"{key}.{i + (key == 'supports')}") for i, d in enumerate(items)]
        loads = []
        if not isinstance(data.get("loads", []), list):
            fail("loads", "must be an array of tables ([[loads]])")
        for i, d in enumerate(data.get("loads", [])):
            t = d.get("type") if isinstance(d, dict) else None
            if not isinstance(t, str) or t not in _LOADS:
                fail(f"loads.{i}.type", f"must be one of {sorted(_LOADS)} (got {_short(t)})")
            loads.append(build(_LOADS[t], d, f"loads.{i}"))
        kw["loads"] = loads
        if "foundation" in data:
            kw["foundation"] = build(Foundation, data["foundation"], "foundation")
        if not isinstance(kw.setdefault("holes", data.get("holes", [])), list):
            fail("holes", "must be an array of tables ([[holes]])")
        return cls(**kw, source=source)

    def to_dict(self) -> dict:
        """The nested dict shape of the TOML file (exact inverse of :meth:`from_dict`)."""
        d: dict[str, Any] = {"name": self.name, "plate": asdict(self.plate), "mesh": asdict(self.mesh)}
        from .geometry import tidy_dict
        tidy_dict(self, d)  # the shape, holes and mesh size when set
        if self.mesh.symmetry is None:
            del d["mesh"]["symmetry"]
        if self.edges:
            d["edges"] = {k: (e.kind if (e.w == 0.0 and e.slope == 0.0) else asdict(e)) for k, e in self.edges.items()}
        for key in ("openings", "pins", "supports"):
            if getattr(self, key):
                d[key] = [asdict(o) for o in getattr(self, key)]
        if self.loads:
            d["loads"] = [{"type": ld.type, **{k: v for k, v in asdict(ld).items() if k != "type" and v is not None}}
                          for ld in self.loads]
        if self.foundation is not None:
            f = self.foundation
            if callable(f.gap):
                raise SceneError("foundation.gap: a Python callable cannot be saved to TOML; use a profile")
            fd: dict[str, Any] = {"gap": f.gap}
            if f.model != "winkler":
                fd["model"] = f.model
            fd.update({k: getattr(f, k) for k in ("k", "shear", "E", "nu") if getattr(f, k) is not None})
            if f.region is not None:
                fd["region"] = dict(f.region) if isinstance(f.region, dict) else list(f.region)
            d["foundation"] = fd
        return d

    def to_toml(self, path: str | Path | None = None) -> str:
        """The scene as TOML text; written to ``path`` if given (replacing a file there, and a
        symbolic link itself rather than its target: :func:`plateqp.io.safe.write`)."""
        import tomli_w

        text = tomli_w.dumps(self.to_dict())
        if path is not None:
            from ..io.safe import write

            write(path, text, force=True, label=str(path))
        return text


def _edge_from(v, where: str, source: str | None) -> Edge:
    prefix = f"{source}: " if source else ""
    if isinstance(v, str):
        return Edge(kind=v)
    if isinstance(v, dict):
        extra = set(v) - {"type", "kind", "w", "slope"}
        if extra:
            raise SceneError(f"{prefix}{where}.{sorted(extra)[0]}: unknown key; allowed: kind, w, slope")
        kind = v.get("kind", v.get("type", "free"))
        return Edge(kind=kind, w=v.get("w", 0.0), slope=v.get("slope", 0.0))
    raise SceneError(f"{prefix}{where}: must be a kind (\"free\", \"simple\", \"clamped\") or a table")


_SCALARS = {str, int, float, bool, type(None)}


def _check_parts(sc: Scene) -> None:
    """The parts of the scene of their types, its NumPy numbers made Python's (:mod:`plateqp.model.parts`)."""
    check_parts(sc, {"plate": Plate, "mesh": MeshSpec, "foundation": Foundation, "edges": Edge, "openings": Opening,
                     "pins": Pin, "loads": (UniformLoad, PatchLoad, PointLoad), "supports": Support, "holes": object})
