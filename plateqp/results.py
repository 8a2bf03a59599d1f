"""Result of a solve, and the recovery of fields from the nodal dofs.

Moments follow the convention of :mod:`plateqp.model.elements.base` (M = −D_b κ, Mx > 0 sags).
Surface stresses are those of the bottom face (z = +h/2, the face on the side of positive w):
σx = 6 Mx / h², σy = 6 My / h², τxy = 6 Mxy / h²; the top face has the opposite signs.
Principal stresses σ1 ≥ σ2 of the bottom face, with the angle of σ1 from the x axis.

For the ACM element moments are discontinuous between cells (non-conforming); values at a
point on a cell boundary come from one neighbour, and :meth:`Result.nodal` averages the
cells around each node for smooth plots. Nodal fields are (n,) arrays on every mesh, one value
per node of the plate in the order of ``model.grid.nodes``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .model import recovery as post
from .accuracy import Status
from .errors import ArgumentError


@dataclass
class KKTReport:
    """Residuals of the contact KKT conditions, in the plate's own terms (see :mod:`plateqp.contact.kkt`)."""

    stationarity: float = 0.0
    spring: float = 0.0
    primal: float = 0.0
    dual: float = 0.0
    complementarity: float = 0.0
    natural: float = 0.0
    tol: float = 0.0
    scale: float = 1.0  # deflection scale for gaps
    #: the stationarity residual's rounding floor, ε‖|K||u| + |f| + |Bᵀ||R|‖ relative as
    #: stationarity: an answer exact to double precision may show a residual up to about this
    floor: float = 0.0

    @property
    def at_floor(self) -> bool:
        """Not ok only because stationarity is at its rounding floor: the accuracy asked is
        below what double precision can show on this plate (the answer may be exact)."""
        return (not self.ok and self.stationarity <= self.floor
                and max(self.spring, self.primal, self.dual, self.complementarity, self.natural) <= self.tol)

    @property
    def worst(self) -> float:
        return max(self.stationarity, self.spring, self.primal, self.dual, self.complementarity, self.natural)

    @property
    def ok(self) -> bool:
        return bool(self.worst <= self.tol)

    def as_dict(self) -> dict:
        return {"stationarity": self.stationarity, "spring": self.spring, "primal": self.primal,
                "dual": self.dual, "complementarity": self.complementarity, "natural": self.natural,
                "tol": self.tol,
                "scale": self.scale, "floor": self.floor, "ok": self.ok}


@dataclass
class Result:
    """The outcome of :func:`plateqp.solve`.

    Attributes
    ----------
    u : full dof vector (prescribed values included)
    reactions, gaps, compressions, active : one entry per contact point (discrete supports in
        scene order, then bed nodes); empty for a two-sided scene
    residual : ‖K u − f + Bᵀ R‖ / ‖f‖ of the final field
    deflection_unique : False when the reactions are unique but the deflection is not: the
        supports that carry load leave a rigid motion of a floating plate free (a load exactly
        on a support, or on the line between two). ``u`` is then the canonical answer, the
        same whatever the backend: the lowest position, nearest the level
        (:func:`plateqp.contact.statics.settle`)
    kkt : :class:`KKTReport` (contact scenes)
    status : :class:`~plateqp.backends.base.Status`
    times : seconds for "build", "formulate", "solve", "recover", "total"
    """

    scene: Any
    model: Any
    u: np.ndarray
    status: Status = Status.OPTIMAL
    backend: str = "direct"
    formulation: str = "two-sided"
    accuracy: str | float = "default"
    reactions: np.ndarray = field(default_factory=lambda: np.zeros(0))
    gaps: np.ndarray = field(default_factory=lambda: np.zeros(0))
    compressions: np.ndarray = field(default_factory=lambda: np.zeros(0))
    active: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    residual: float = 0.0
    deflection_unique: bool = True
    kkt: KKTReport | None = None
    iterations: int | None = None
    times: dict = field(default_factory=dict)
    extras: dict = field(default_factory=dict)

    # -- fields at points ---------------------------------------------------------------------
    def _eval(self, x, y, dx, dy):
        x, y = _coordinates(x, "x"), _coordinates(y, "y")
        try:
            shape = np.broadcast(x, y).shape
        except ValueError:
            raise ArgumentError(f"x and y: shapes {x.shape} and {y.shape} do not broadcast together") from None
        xb, yb = np.broadcast_arrays(x, y)
        if xb.size == 0:  # no points: no values
            return np.zeros(shape)
        vals = self.model.interpolation(xb.ravel(), yb.ravel(), dx, dy) @ self.u
        return vals.reshape(shape) if shape else float(vals[0])

    def deflection(self, x, y):
        """w at points (positive downward); arrays broadcast."""
        return self._eval(x, y, 0, 0)

    def slopes(self, x, y):
        """(∂w/∂x, ∂w/∂y) at points."""
        return self._eval(x, y, 1, 0), self._eval(x, y, 0, 1)

    def curvatures(self, x, y):
        """(w,xx, w,yy, w,xy) at points."""
        return self._eval(x, y, 2, 0), self._eval(x, y, 0, 2), self._eval(x, y, 1, 1)

    def moments(self, x, y):
        """(Mx, My, Mxy) per unit length at points: M = −D_b κ (:func:`plateqp.model.recovery.moments`)."""
        return tuple(_unwrap(m) for m in post.moments(self.scene.plate, *self.curvatures(x, y)))

    def stresses(self, x, y):
        """(σx, σy, τxy) on the bottom face: 6 M / h²."""
        return tuple(_unwrap(s) for s in post.stresses(self.scene.plate, *self.curvatures(x, y)))

    def principal_stresses(self, x, y):
        """(σ1, σ2, θ1) on the bottom face: σ1 ≥ σ2 and the angle of σ1 from x (radians)."""
        return tuple(_unwrap(s) for s in post.principal(*self.stresses(x, y)))

    def section(self, p0, p1, n: int = 101, quantity: str = "w"):
        """Values along the segment p0 → p1: returns (s, values) with s the distance from p0.

        ``quantity``: "w", "Mx", "My", "Mxy", "sx", "sy", "txy", "s1", "s2".
        """
        p0, p1, n = _point(p0, "p0"), _point(p1, "p1"), _count(n, "n")
        _quantity(quantity)
        t = np.linspace(0.0, 1.0, n)
        x = p0[0] + t * (p1[0] - p0[0])
        y = p0[1] + t * (p1[1] - p0[1])
        s = t * np.hypot(p1[0] - p0[0], p1[1] - p0[1])
        return s, self.at(x, y, quantity)

    def at(self, x, y, quantity: str = "w"):
        """Any named quantity at points (see :meth:`section`)."""
        table = {
            "w": lambda: self.deflection(x, y),
            "Mx": lambda: self.moments(x, y)[0],
            "My": lambda: self.moments(x, y)[1],
            "Mxy": lambda: self.moments(x, y)[2],
            "sx": lambda: self.stresses(x, y)[0],
            "sy": lambda: self.stresses(x, y)[1],
            "txy": lambda: self.stresses(x, y)[2],
            "s1": lambda: self.principal_stresses(x, y)[0],
            "s2": lambda: self.principal_stresses(x, y)[1],
        }
        return table[_quantity(quantity)]()

    def nodal(self, quantity: str = "w") -> np.ndarray:
        """(n,) smoothed nodal values, one per node of the plate in ``mesh.nodes`` order, on
        every mesh: each cell's own value at its corner, averaged over the cells around the node
        (:class:`plateqp.model.recovery.NodalOperator`). On the structured grid ``model.grid.to_grid``
        gives the (ny+1, nx+1) view (NaN off the plate), and :meth:`to_xarray` the same on x, y.
        ``quantity`` as for :meth:`section`."""
        return post.nodal_operator(self.model)(self.u, self.scene.plate, _quantity(quantity))

    # -- summaries --------------------------------------------------------------------------
    def w_nodes(self) -> np.ndarray:
        """(n,) w at the nodes of the plate (``mesh.nodes`` order): each node's own dof."""
        return post.nodal_w(self.model, self.u)

    def w_max(self) -> tuple[float, float, float]:
        """(w, x, y) of the node with the largest |w|."""
        w = self.w_nodes()
        k = int(np.argmax(np.abs(w)))
        x, y = self.model.grid.nodes[k]
        return float(w[k]), float(x), float(y)

    @property
    def ok(self) -> bool:
        return self.status == Status.OPTIMAL

    def to_dict(self, probes=()) -> dict:
        """The JSON shape of ``plateqp solve --json`` (see DESIGN.md): scene, backend, formulation,
        accuracy, status, w_max and its x, y, ``probes`` (w at each (x, y) given), reactions,
        active, gaps, residual, ``deflection_unique`` (False: reactions unique, deflection not
        unique; see the class), kkt, iterations, times (build, solve, total); with
        ``accuracy="auto"`` also the discretisation error estimate; where the status is not
        OPTIMAL, ``why`` (the solver's own words and the KKT residual, ``extras["why"]``)."""
        probes = _probes(probes)
        w, x, y = self.w_max()
        d = {
            "scene": self.scene.name,
            "backend": self.backend,
            "formulation": self.formulation,
            "accuracy": self.accuracy,
            "status": self.status.value,
            "w_max": w,
            "w_max_x": x,
            "w_max_y": y,
            "probes": [{"x": px, "y": py, "w": float(self.deflection(px, py))} for px, py in probes],
            "reactions": np.asarray(self.reactions).tolist(),
            "active": np.asarray(self.active).tolist(),
            "gaps": np.asarray(self.gaps).tolist(),
            "residual": self.residual,
            "deflection_unique": bool(self.deflection_unique),
            "kkt": self.kkt.as_dict() if self.kkt is not None else None,
            "iterations": self.iterations,
            "times": {k: self.times.get(k) for k in ("build", "solve", "total")},
        }
        if self.extras.get("accuracy") == "auto":
            d["discretisation_error"] = self.extras.get("discretisation_error")
        if self.status != Status.OPTIMAL and self.extras.get("why"):
            d["why"] = self.extras["why"]  # why the solver stopped short, in words
        return d

    # -- in the tools users already use (plateqp.io.fields, plateqp.io.vtk) -----------------------
    def to_xarray(self, quantities=post.QUANTITIES, *, nodes: bool = False):
        """The nodal fields (w, moments, stresses, σ1, σ2) as an :class:`xarray.Dataset`: on the
        structured grid its grid view on ``x``, ``y`` (NaN off the plate), on a triangle mesh (or
        with ``nodes=True`` on any mesh) on a ``node`` dimension: :func:`plateqp.io.fields.to_xarray`."""
        from .io.fields import to_xarray
        return to_xarray(self, quantities, nodes=nodes)

    @property
    def supports(self):
        """One row per one-sided contact point (1-based support numbers, position, stiffness,
        gaps, reaction, contact) as a :class:`pandas.DataFrame`:
        :func:`plateqp.io.fields.supports_frame`."""
        from .io.fields import supports_frame
        return supports_frame(self)

    def write_vtu(self, folder, stem: str | None = None, force: bool = False) -> list:
        """``<stem>.vtu`` (the plate and its fields) and ``<stem>-supports.vtu`` into ``folder``
        (made if missing, as ``plateqp solve --out`` does) for ParaView / pyvista; nothing
        overwritten unless ``force``, no link followed: :func:`plateqp.io.vtk.write_vtu`.
        ``stem`` defaults to the scene's name made a plain file name."""
        from .io.files import safe_filename
        from .io.vtk import write_vtu
        return write_vtu(self, folder, stem or safe_filename(self.scene.name), force=force)


def _unwrap(v):
    a = np.asarray(v)
    return float(a) if a.ndim == 0 else a


# -- the public methods' arguments: an ArgumentError naming the argument, NumPy numbers taken -------
def _coordinates(v, name: str) -> np.ndarray:
    """A number or an array of numbers (NumPy's too) as a float array."""
    try:
        a = np.asarray(v)
    except (ValueError, TypeError):  # a ragged list
        a = np.asarray(None)
    if a.dtype.kind not in "iuf":
        raise ArgumentError(f"{name}: must be a number or an array of numbers (got {_short(v)})")
    return a.astype(float)


def _point(p, name: str) -> tuple[float, float]:
    a = _coordinates(p, name)
    if a.shape != (2,):
        raise ArgumentError(f"{name}: must be a point (x, y) (got {_short(p)})")
    return float(a[0]), float(a[1])


def _count(n, name: str) -> int:
    n = n.item() if isinstance(n, np.generic) else n
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ArgumentError(f"{name}: must be an integer >= 1 (got {_short(n)})")
    return n


def _quantity(q) -> str:
    if not isinstance(q, str) or q not in post.QUANTITIES:
        raise ArgumentError(f"quantity: unknown quantity {_short(q)}; choose one of {sorted(post.QUANTITIES)}")
    return str(q)


def _probes(probes) -> list[tuple[float, float]]:
    try:
        items = list(probes)
    except TypeError:
        raise ArgumentError(f"probes: must be a list of points (x, y) (got {_short(probes)})") from None
    return [_point(p, f"probes.{i}") for i, p in enumerate(items)]


def _short(v, n: int = 60) -> str:
    from .model.parts import _short as short
    return short(v, n)
