"""A solved plate as VTK files for ParaView or pyvista, written through meshio.

:func:`write_vtu` writes two VTK unstructured-grid files:

- ``<stem>.vtu``: the plate's cells (``mesh.cells``: the kept quads of the structured grid, or the
  triangles of a triangle mesh) on its nodes (``mesh.nodes``), z = 0, with the nodal fields
  (:data:`plateqp.model.recovery.QUANTITIES`: w, moments, surface stresses, σ1, σ2; averaged over the
  cells around a node) and ``displacement`` = (0, 0, −w) for ParaView's "Warp By Vector" (w is
  positive downward, z up); for a tensionless bed also the bed's ``reaction`` and ``contact``
  (1 in contact, 0 lifted, NaN where the bed does not reach) at its nodes;
- ``<stem>-supports.vtu`` (when the scene has discrete one-sided supports): one vertex per
  support at its position with its ``number`` (1-based, as in the figures), ``reaction``,
  ``initial_gap``, ``gap``, ``stiffness`` and ``contact``.

Both are plain XML VTK files, opened by ParaView, pyvista or meshio without conversion.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ExportError
from .files import safe_filename
from .fields import _optional, node_fields, supports_columns


def vtu_files(stem: str, result=None) -> list[str]:
    """The names :func:`write_vtu` writes for ``stem`` (both when ``result`` is None: the files it
    may write, for checking a folder before any work)."""
    names = [f"{stem}.vtu"]
    if result is None or _has_supports(result):
        names.append(f"{stem}-supports.vtu")
    return names


def _has_supports(result) -> bool:
    c = result.model.contacts
    return c is not None and bool(np.any(np.asarray(c.source) == "support"))


def plate_mesh(result):
    """The meshio Mesh of the plate (see the module docstring)."""
    meshio = _optional("meshio")
    model = result.model
    mesh = model.grid
    xy = mesh.nodes
    points = np.column_stack([xy, np.zeros(len(xy))])
    cells = (mesh.cell_type, mesh.cells.astype(np.int64))
    data = node_fields(result)
    data["displacement"] = np.column_stack([np.zeros(len(xy)), np.zeros(len(xy)), -data["w"]])
    c = model.contacts
    if c is not None and np.any(np.asarray(c.source) == "bed"):
        bed = np.asarray(c.source) == "bed"
        nodes = np.asarray(c.index)[bed].astype(np.int64)  # the bed's nodes, numbered as the dofs
        react = np.full(mesh.n_nodes, np.nan)
        contact = np.full(mesh.n_nodes, np.nan)
        react[nodes] = np.asarray(result.reactions, dtype=float)[bed]
        contact[nodes] = np.asarray(result.active, dtype=float)[bed]
        data["reaction"] = react[mesh.plate_node_ids]
        data["contact"] = contact[mesh.plate_node_ids]
    return meshio.Mesh(points, [cells], point_data=data)


def supports_mesh(result):
    """The meshio Mesh of the discrete one-sided supports as vertices (see the module docstring)."""
    meshio = _optional("meshio")
    cols = supports_columns(result)
    sel = cols["source"] == "support"
    n = int(sel.sum())
    points = np.column_stack([cols["x"][sel], cols["y"][sel], np.zeros(n)])
    data = {k: np.asarray(cols[k][sel], dtype=float) for k in ("number", "reaction", "initial_gap", "gap",
                                                                 "stiffness")}
    data["contact"] = cols["active"][sel].astype(float)
    return meshio.Mesh(points, [("vertex", np.arange(n).reshape(-1, 1))], point_data=data)


def write_vtu(result, folder, stem: str, force: bool = False) -> list[Path]:
    """Write ``<stem>.vtu`` (and ``<stem>-supports.vtu``) into ``folder``, made if missing;
    returns the paths.

    The files are written by :mod:`plateqp.io.safe`'s rules: nothing is overwritten unless
    ``force``, a link is never followed (with ``force`` a link where a file goes is replaced,
    not its target), a ``folder`` that is a link is refused, and every target is checked
    before the first is written. Raises :class:`~plateqp.errors.ExportError` for a target
    that exists or cannot be written, :class:`~plateqp.errors.PlateQPError` when meshio is
    missing.
    """
    from .safe import check_target, out_folder, write

    meshio = _optional("meshio")
    if safe_filename(stem) != stem:
        raise ExportError(f"{stem!r}: not a plain file name (letters, digits, '._-', no leading dot); "
                          f"for example {safe_filename(stem)!r}")
    folder = out_folder(folder)
    paths = [folder / name for name in vtu_files(stem, result)]
    for p in paths:
        check_target(p, force=force, flag="force=True", root=folder)
    meshes = [plate_mesh(result)] + ([supports_mesh(result)] if len(paths) > 1 else [])
    for p, mesh in zip(paths, meshes):
        write(p, lambda tmp, mesh=mesh: meshio.write(tmp, mesh, file_format="vtu"), force=force,
              flag="force=True", root=folder)
    return paths
