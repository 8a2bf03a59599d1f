"""A solved plate as the tables and arrays users already work with: xarray and pandas.

:func:`node_fields` gives every named field (:data:`plateqp.post.QUANTITIES`) at the plate's
nodes; :func:`to_xarray` wraps them in an :class:`xarray.Dataset` on the node coordinates
(``y``, ``x``), NaN off the plate; :func:`supports_frame` is one row per one-sided contact
point (discrete supports in scene order, 1-based as in the figures, then bed nodes) as a
:class:`pandas.DataFrame`. The library imports neither package until one of these is called.

Units are the scene's own consistent units (plateqp has no unit system): a length L, a force
F; the attributes of each variable say which.

On a triangle mesh (``mesh.element = "dkt"``) the fields are (n_nodes,) arrays on the mesh's
nodes (every node on the plate; moments averaged over the triangles around a node,
:class:`plateqp.post.TriNodalOperator`), and :func:`to_xarray` puts them on a ``node``
dimension with ``x`` and ``y`` coordinates and the triangles as the variable ``triangles``
(``triangle`` × ``vertex``, 0-based node indices, counter-clockwise).
"""

from __future__ import annotations

import numpy as np

from ..errors import PlateQPError
from ..post import QUANTITIES, NodalOperator, TriNodalOperator, nodal_w

#: (long name, units in the scene's length L and force F) of each nodal field.
FIELD_ATTRS = {
    "w": ("deflection, positive downward (along the load)", "L"),
    "Mx": ("bending moment Mx per unit length (Mx > 0 sags)", "F L/L"),
    "My": ("bending moment My per unit length", "F L/L"),
    "Mxy": ("twisting moment Mxy per unit length", "F L/L"),
    "sx": ("σx on the bottom face (z = +h/2)", "F/L^2"),
    "sy": ("σy on the bottom face", "F/L^2"),
    "txy": ("τxy on the bottom face", "F/L^2"),
    "s1": ("principal stress σ1 ≥ σ2 on the bottom face", "F/L^2"),
    "s2": ("principal stress σ2 on the bottom face", "F/L^2"),
}


def _optional(name: str, extra: str = "results"):
    try:
        return __import__(name)
    except ImportError:
        raise PlateQPError(f"{name} is not installed: pip install 'plateqp[{extra}]'") from None


def _grid(result):
    grid = getattr(result.model, "grid", None)
    if grid is None or not hasattr(grid, "node_xy"):
        raise PlateQPError("nodal fields are available on the structured grid only (not yet on triangle meshes)")
    return grid


def on_triangles(result) -> bool:
    """Whether ``result`` is on a triangle mesh (a :class:`~plateqp.triassembly.TriModel`)."""
    from ..trimesh import TriMesh

    return isinstance(getattr(result.model, "grid", None), TriMesh)


def node_fields(result, quantities=QUANTITIES) -> dict[str, np.ndarray]:
    """Each field of ``quantities`` at the nodes: (ny+1, nx+1) arrays, NaN off the plate; w is
    the nodal dof itself, the others are averaged over the kept cells around a node
    (:class:`plateqp.post.NodalOperator`). On a triangle mesh (n_nodes,) arrays
    (:class:`plateqp.post.TriNodalOperator`)."""
    if on_triangles(result):
        top = TriNodalOperator(result.model)
        return {q: top(result.u, result.scene.plate, q) for q in quantities}
    _grid(result)
    op = NodalOperator(result.model)
    return {q: nodal_w(result.model, result.u) if q == "w" else op(result.u, result.scene.plate, q)
            for q in quantities}


def to_xarray(result, quantities=QUANTITIES):
    """The nodal fields of a result as an :class:`xarray.Dataset`.

    Dimensions ``y`` and ``x`` (the node coordinates), one variable per field of
    ``quantities`` with ``long_name`` and ``units`` attributes; the dataset's attributes name
    the scene, backend, formulation, status and the plate's E, ν, h. NaN off the plate.
    On a triangle mesh: dimension ``node`` with coordinates ``x``, ``y``, and ``triangles``
    (``triangle`` × ``vertex``) among the variables (see the module docstring).
    """
    xr = _optional("xarray")
    fields = node_fields(result, quantities)
    if on_triangles(result):
        mesh = result.model.grid
        dims = ("node",)
        coords = {"x": ("node", mesh.nodes[:, 0].copy(), {"units": "L"}),
                  "y": ("node", mesh.nodes[:, 1].copy(), {"units": "L"})}
    else:
        g = _grid(result)
        dims = ("y", "x")
        coords = {"x": ("x", np.arange(g.nx + 1) * g.hx, {"units": "L"}),
                  "y": ("y", np.arange(g.ny + 1) * g.hy, {"units": "L"})}
    data = {q: (dims, v, {"long_name": FIELD_ATTRS[q][0], "units": FIELD_ATTRS[q][1]})
            for q, v in fields.items()}
    if on_triangles(result):
        data["triangles"] = (("triangle", "vertex"), result.model.grid.triangles.astype(np.int64),
                             {"long_name": "the mesh's triangles: 0-based node indices, counter-clockwise"})
    plate = result.scene.plate
    attrs = {"scene": str(result.scene.name), "backend": str(result.backend),
             "formulation": str(result.formulation), "status": result.status.value,
             "E": float(plate.E), "nu": float(plate.nu), "h": float(plate.h),
             "units": "the scene's own consistent units: length L, force F"}
    return xr.Dataset(data, coords=coords, attrs=attrs)


#: The columns of :func:`supports_frame`, in order.
SUPPORT_COLUMNS = ("x", "y", "source", "number", "stiffness", "initial_gap", "gap", "reaction", "compression",
                   "active")


def supports_columns(result) -> dict[str, np.ndarray]:
    """The one-sided contact points as columns (see :func:`supports_frame`); empty columns for
    a two-sided scene."""
    c = result.model.contacts
    if c is None or c.m == 0:
        kinds = {"source": object, "number": int, "active": bool}
        return {k: np.zeros(0, dtype=kinds.get(k, float)) for k in SUPPORT_COLUMNS}
    rho = np.asarray(c.rho, dtype=float)
    with np.errstate(divide="ignore"):
        stiffness = np.where(rho > 0, 1.0 / np.where(rho > 0, rho, 1.0), np.inf)
    source = np.asarray(c.source).astype(object)
    number = np.where(source == "support", np.asarray(c.index) + 1, np.asarray(c.index))
    return {
        "x": np.asarray(c.xy)[:, 0].astype(float),
        "y": np.asarray(c.xy)[:, 1].astype(float),
        "source": source,
        "number": number.astype(int),
        "stiffness": stiffness,
        "initial_gap": np.asarray(c.scene_gaps, dtype=float),
        "gap": np.asarray(result.gaps, dtype=float),
        "reaction": np.asarray(result.reactions, dtype=float),
        "compression": np.asarray(result.compressions, dtype=float),
        "active": np.asarray(result.active, dtype=bool),
    }


def supports_frame(result):
    """One row per one-sided contact point as a :class:`pandas.DataFrame`.

    Columns: ``x``, ``y``; ``source`` ("support" or "bed"); ``number`` (a support's 1-based
    number in the scene, as in the figures, or the bed's node index); ``stiffness`` (inf for a
    rigid support); ``initial_gap`` (the scene's gap, positive = settlement, negative =
    heave); ``gap`` (the gap left after deformation, 0 where in contact); ``reaction`` (positive
    pushes the plate up); ``compression`` (the support's shortening); ``active`` (in contact).
    """
    pd = _optional("pandas")
    return pd.DataFrame(supports_columns(result))
