"""A solved plate as the tables and arrays users already work with: xarray and pandas.

:func:`node_fields` gives every named field (:data:`plateqp.model.recovery.QUANTITIES`) at the plate's
nodes, (n,) arrays in ``mesh.nodes`` order on every mesh; :func:`to_xarray` wraps them in an
:class:`xarray.Dataset`; :func:`supports_frame` is one row per one-sided contact
point (discrete supports in scene order, 1-based as in the figures, then bed nodes) as a
:class:`pandas.DataFrame`. The library imports neither package until one of these is called.

Units are the scene's own consistent units (plateqp has no unit system): a length L, a force
F; the attributes of each variable say which.

The dataset's layout: on the structured grid the grid view, dimensions ``y`` and ``x`` (the
node coordinates), NaN at nodes off the plate, so that ``ds["w"].sel(x=..., y=...)`` reads a
node; on a triangle mesh (``mesh.element = "dkt"``), or on any mesh with ``nodes=True``, a
``node`` dimension (one entry per node of the plate, ``mesh.nodes`` order) with ``x`` and ``y``
coordinates and the cells as the variable ``triangles`` (``triangle`` × ``vertex``) or
``quads`` (``quad`` × ``vertex``): 0-based node indices, counter-clockwise.
"""

from __future__ import annotations

import numpy as np

from ..errors import PlateQPError
from ..model.recovery import QUANTITIES, NodalOperator, nodal_w

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


def node_fields(result, quantities=QUANTITIES) -> dict[str, np.ndarray]:
    """Each field of ``quantities`` at the plate's nodes: (n,) arrays in ``mesh.nodes`` order
    on every mesh; w is the nodal dof itself, the others are averaged over the cells around a
    node (:class:`plateqp.model.recovery.NodalOperator`)."""
    op = NodalOperator(result.model)
    return {q: nodal_w(result.model, result.u) if q == "w" else op(result.u, result.scene.plate, q)
            for q in quantities}


def to_xarray(result, quantities=QUANTITIES, *, nodes: bool = False):
    """The nodal fields of a result as an :class:`xarray.Dataset`.

    One variable per field of ``quantities`` with ``long_name`` and ``units`` attributes; the
    dataset's attributes name the scene, backend, formulation, status and the plate's E, ν, h.
    On the structured grid: dimensions ``y`` and ``x`` (the grid view, NaN off the plate, equal
    to ``model.grid.to_grid`` of each nodal field). On a triangle mesh, or with ``nodes=True``
    on any mesh: dimension ``node`` (``mesh.nodes`` order, the values of
    :meth:`~plateqp.results.Result.nodal`) with coordinates ``x``, ``y``, and the cells among
    the variables (see the module docstring).
    """
    xr = _optional("xarray")
    fields = node_fields(result, quantities)
    mesh = result.model.grid
    dims, coords, fields = mesh.field_layout(fields, nodes=nodes)  # the grid view where the mesh has one
    data = {q: (dims, v, {"long_name": FIELD_ATTRS[q][0], "units": FIELD_ATTRS[q][1]})
            for q, v in fields.items()}
    if dims == ("node",):
        kind = mesh.cell_type
        data[f"{kind}s"] = ((kind, "vertex"), mesh.cells.astype(np.int64),
                            {"long_name": f"the mesh's {kind}s: 0-based node indices, counter-clockwise"})
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
