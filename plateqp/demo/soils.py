"""One heaved slab on three soils, side by side: the ``soils`` study of ``plateqp demo`` and the
scene of the course's lesson 13 (``notebooks/13_choosing_a_soil_model.py`` imports it from here).

The scene (N, m): a 4 m × 4 m concrete slab, 25 cm thick (E = 30 GPa, ν = 0.2), free on its
edges, carrying its self-weight q = 25 kN/m³ × h and a 150 kN machine foot at (3, 2), over
ground that frost has heaved by 2 mm in a bump of radius 1 m centred at (1, 2)
(:data:`HEAVE`), on an ACM grid of :data:`MESH` cells a side (441 bed nodes: the half-space's
dense block stays small). The soil is a stiff clay, an elastic half-space of E_s = 30 MPa,
ν_s = 0.3, or one of two simpler soils given comparable stiffness by :func:`calibrate`:

* **k** (Winkler's and Pasternak's modulus): q over the mean settlement of the half-space
  bonded to the slab under the self-weight alone (a free plate on a Winkler or Pasternak bed
  under uniform q settles exactly q/k);
* **c2** (Pasternak's shear modulus): the root, in one variable, of "the bonded Pasternak bed
  settles under the foot alone as much as the half-space does".

:func:`soil_study` solves the heaved slab one-sided on the three soils; :func:`numbers` reads
each result's figures of merit from its own fields (max deflection, max contact pressure, the
lifted-off share of the bed's area, the largest Mx along :data:`SECTION`, the worst KKT
residual, the status); :func:`table`, :func:`lines`, :func:`data` and :func:`figures` are what
the demo prints, writes to ``soils.json`` and draws.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..model.scene import Foundation, MeshSpec, Plate, PointLoad, Scene, UniformLoad

#: The slab: side [m], Young's modulus [Pa], thickness [m], Poisson's ratio.
A, E, H, NU = 4.0, 3e10, 0.25, 0.2
#: The soil (a stiff clay) as an elastic half-space: modulus [Pa], Poisson's ratio.
E_S, NU_S = 3e7, 0.3
#: The self-weight [Pa] and the machine foot [N] at :data:`FOOT` [m].
Q, P = 25e3 * H, 1.5e5
FOOT = (3.0, 2.0)
#: The frost heave under the slab's left half: g0 < 0 over a smooth bump.
HEAVE = {"profile": "bump", "x": 1.0, "y": 2.0, "radius": 1.0, "depth": 2e-3}
#: Cells a side of the grid.
MESH = 20
#: The section through the heave and the foot, y = 2 m.
SECTION = ((0.0, 2.0), (4.0, 2.0))
#: The soils in the order they are shown.
SOILS = ("Winkler", "Pasternak", "half-space")
#: The KKT tolerance of the one-sided solves.
ACCURACY = 1e-10


def slab_scene(foundation: Foundation, loads=None, mesh: int = MESH) -> Scene:
    """The slab on ``foundation`` under ``loads`` (default: the self-weight and the foot) on a
    grid of ``mesh`` cells a side."""
    if loads is None:
        loads = [UniformLoad(Q), PointLoad(P=P, x=FOOT[0], y=FOOT[1])]
    return Scene(name="heaved-slab", plate=Plate(a=A, b=A, h=H, E=E, nu=NU), mesh=MeshSpec(nx=mesh, ny=mesh),
                 loads=list(loads), foundation=foundation)


def halfspace(gap=0.0) -> Foundation:
    """The clay as an elastic half-space, with the gap field ``gap``."""
    return Foundation(model="halfspace", E=E_S, nu=NU_S, gap=gap)


@dataclass
class Calibration:
    """Winkler's and Pasternak's parameters fitted to the half-space (see the module doc), and
    the settlements under the foot alone that fixed c2 (all bonded, no heave) [N, m]."""

    k: float  # N/m³
    c2: float  # N/m
    w_foot: float  # the half-space's settlement under the foot
    w_foot_winkler: float  # Winkler's with this k (Pasternak at c2 = 0)

    @property
    def length(self) -> float:
        """√(c2/k): the length over which Pasternak's ground feels a load [m]."""
        return math.sqrt(self.c2 / self.k)


def calibrate(mesh: int = MESH, model=None) -> Calibration:
    """k and c2 of comparable stiffness on this slab (see the module doc). ``model``: a model of
    the slab on the half-space on this mesh, whatever its loads and heave, to re-use its dense
    assembly (:func:`plateqp.studies.reuse.adapt_model`)."""
    from scipy.optimize import brentq

    from ..solving import solve_bilateral

    def bonded(foundation, loads):
        sc = slab_scene(foundation, loads, mesh)
        return solve_bilateral(sc, _adapted(model, sc))

    weight, foot = [UniformLoad(Q)], [PointLoad(P=P, x=FOOT[0], y=FOOT[1])]
    under_weight = bonded(halfspace(), weight)
    areas = under_weight.model.bed_areas()
    k = Q / (under_weight.w_nodes() @ areas / areas.sum())
    w_foot = bonded(halfspace(), foot).deflection(*FOOT)

    def foot_error(c2):
        return bonded(Foundation(model="pasternak", k=k, shear=c2), foot).deflection(*FOOT) - w_foot

    c2 = brentq(foot_error, 0.0, 1e8, xtol=1e4)
    return Calibration(float(k), float(c2), float(w_foot), float(foot_error(0.0) + w_foot))


def _adapted(model, scene: Scene):
    if model is None:
        return None
    from ..studies.reuse import adapt_model

    return adapt_model(model, scene)


def beds(cal: Calibration, gap=HEAVE) -> dict[str, Foundation]:
    """The three soils of comparable stiffness, heaved by ``gap``, in the order of :data:`SOILS`."""
    return {"Winkler": Foundation(k=cal.k, gap=gap),
            "Pasternak": Foundation(model="pasternak", k=cal.k, shear=cal.c2, gap=gap),
            "half-space": halfspace(gap)}


def pressure(result) -> np.ndarray:
    """The contact pressure at each bed node: its reaction over its tributary area [Pa]."""
    return result.reactions / result.model.bed_areas()[result.model.contacts.index]


@dataclass
class SoilStudy:
    """The heaved slab solved one-sided on each soil (``results``, in the order of :data:`SOILS`)."""

    calibration: Calibration
    results: dict = field(default_factory=dict)
    mesh: int = MESH

    @property
    def ok(self) -> bool:
        return all(r.ok and r.kkt is not None and r.kkt.ok for r in self.results.values())


def soil_study(mesh: int | None = None, accuracy: float | str = ACCURACY) -> SoilStudy:
    """Calibrate, then solve the heaved slab one-sided on the three soils (one assembly of the
    half-space's dense block for its calibration and its solve)."""
    from ..model.assembly import build_model
    from ..solving import solve

    mesh = MESH if mesh is None else int(mesh)
    hs_model = build_model(slab_scene(halfspace(HEAVE), mesh=mesh))  # the half-space needs no fitting
    cal = calibrate(mesh, hs_model)
    results = {}
    for name, fnd in beds(cal).items():
        sc = slab_scene(fnd, mesh=mesh)
        results[name] = solve(sc, accuracy=accuracy, model=hs_model if name == "half-space" else None)
    return SoilStudy(cal, results, mesh)


# -- the numbers ---------------------------------------------------------------------------------
def numbers(result) -> dict:
    """A result's figures of merit, read from its own fields [N, m, Pa]: ``w_max`` (the signed w
    of largest |w| over the plate's nodes, at ``w_max_x``, ``w_max_y``), ``p_max`` (the largest
    contact pressure, at ``p_max_x``, ``p_max_y``), ``lifted_share`` (the lifted-off nodes'
    share of the bed's area; ``lifted_nodes`` of ``bed_nodes``), ``Mx_max`` (the largest Mx
    along :data:`SECTION`, N·m/m), ``reactions_sum``, ``kkt_worst``, ``status``."""
    w, wx, wy = result.w_max()
    p = pressure(result)
    i = int(np.argmax(p))
    areas = result.model.bed_areas()[result.model.contacts.index]
    lifted = ~np.asarray(result.active, dtype=bool)
    return {"w_max": w, "w_max_x": wx, "w_max_y": wy, "p_max": float(p[i]),
            "p_max_x": float(result.model.contacts.xy[i, 0]), "p_max_y": float(result.model.contacts.xy[i, 1]),
            "lifted_share": float(areas[lifted].sum() / areas.sum()), "lifted_nodes": int(lifted.sum()),
            "bed_nodes": int(lifted.size), "Mx_max": float(result.section(*SECTION, quantity="Mx")[1].max()),
            "reactions_sum": float(result.reactions.sum()),
            "kkt_worst": float(result.kkt.worst) if result.kkt is not None else float("nan"),
            "status": result.status.value}


TABLE_HEADER = ("soil", "w max [mm]", "p max [kPa] at (x, y) [m]", "lifted off [% of bed area]",
                "Mx max on y = 2 m [kN·m/m]", "KKT worst", "status")


def table(st: SoilStudy) -> str:
    """The numbers of :func:`numbers` as a small plain-text table, one row per soil."""
    rows = [TABLE_HEADER]
    for name, r in st.results.items():
        n = numbers(r)
        rows.append((name, f"{n['w_max'] * 1e3:.3f}", f"{n['p_max'] / 1e3:.1f} at ({n['p_max_x']:g}, {n['p_max_y']:g})",
                     f"{100 * n['lifted_share']:.1f} % ({n['lifted_nodes']} of {n['bed_nodes']} nodes)",
                     f"{n['Mx_max'] / 1e3:.1f}", f"{n['kkt_worst']:.1e}", n["status"]))
    widths = [max(len(row[j]) for row in rows) for j in range(len(TABLE_HEADER))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def story(st: SoilStudy) -> str:
    return (f"The heaved slab of the course's lesson 13 (4 m x 4 m, h = 0.25 m, self-weight and a 150 kN foot at "
            f"(3, 2), ground heaved 2 mm over a bump of radius 1 m at (1, 2); {st.mesh} x {st.mesh} ACM grid) on "
            "Winkler's springs, Pasternak's shear layer and an elastic half-space (E = 30 MPa, nu = 0.3), the "
            "first two fitted to the half-space (k: the same mean settlement under the self-weight; c2: the same "
            f"settlement under the foot). Each solved one-sided (pq.solve, KKT tolerance {ACCURACY:g}). Module doc "
            "of plateqp.demo.soils; the lesson notebooks/13_choosing_a_soil_model.")


def lines(st: SoilStudy) -> list[str]:
    """The study in words: the calibration and the statics."""
    c = st.calibration
    load = Q * A * A + P
    worst = max(abs(r.reactions.sum() - load) for r in st.results.values()) / load
    return [f"comparable stiffness: k = {c.k / 1e6:.2f} MN/m^3 (the half-space's mean settlement under the "
            f"self-weight), c2 = {c.c2 / 1e6:.2f} MN/m (its settlement under the foot, {c.w_foot * 1e3:.3f} mm; "
            f"Winkler's with this k: {c.w_foot_winkler * 1e3:.3f} mm), soil length sqrt(c2/k) = {c.length:.2f} m",
            f"statics: on every soil the contact forces carry the {load / 1e3:g} kN applied (largest miss "
            f"{worst:.1e} of it); the heave changes where, not how much",
            "contact pressure at the far corner (4, 0), the far edge's middle (4, 2) and inside at (3, 1): "
            + "; ".join(f"{name} " + " / ".join(_at(r, x, y) for x, y in PROBES) + " kPa"
                        for name, r in st.results.items())]


#: Where :func:`lines` reads the pressure: a corner, an edge's middle and a point inside, far from the heave.
PROBES = ((4.0, 0.0), (4.0, 2.0), (3.0, 1.0))


def _at(result, x: float, y: float) -> str:
    """The contact pressure at the bed node (x, y) in kPa, or "lifted off" (or "-" off the bed)."""
    xy = result.model.contacts.xy
    hit = np.flatnonzero(np.hypot(xy[:, 0] - x, xy[:, 1] - y) < 1e-9 * A)
    if hit.size == 0:
        return "-"
    return f"{pressure(result)[hit[0]] / 1e3:.0f}" if result.active[hit[0]] else "lifted off"


def data(st: SoilStudy) -> dict:
    """The JSON of the study: the scene's parameters, the calibration and each soil's numbers."""
    c = st.calibration
    return {"scene": {"a": A, "b": A, "h": H, "E": E, "nu": NU, "q": Q, "P": P, "foot": list(FOOT), "heave": HEAVE,
                      "mesh": st.mesh, "soil_E": E_S, "soil_nu": NU_S, "units": ["m", "N"]},
            "calibration": {"k": c.k, "c2": c.c2, "length": c.length, "w_foot_halfspace": c.w_foot,
                            "w_foot_winkler": c.w_foot_winkler},
            "applied_load": Q * A * A + P, "section": [list(SECTION[0]), list(SECTION[1])],
            "soils": {name: numbers(r) for name, r in st.results.items()}}


# -- the figures ---------------------------------------------------------------------------------
def figures(st: SoilStudy) -> dict:
    """stem → (caption, function drawing the figure)."""
    return {"pressure": ("Contact pressure under the heaved slab on the three soils, one colour scale (square root, "
                         "so that the peaks and the tens of kPa between them both show); hatched: lifted off; "
                         "dotted: the heave's bump; ★ the foot.", lambda: plot_pressure_maps(st)),
            "sections": ("Deflection (down) and bending moment Mx along y = 2 m, through the heave (x = 1 m) and the "
                         "foot (x = 3 m), on the three soils.", lambda: plot_soil_sections(st))}


def plot_pressure_maps(st: SoilStudy):
    """Three pressure maps side by side: each bed node's pressure over its share of the grid."""
    from matplotlib.colors import PowerNorm
    from matplotlib.patches import Circle, Patch, Rectangle

    from ..plotting.style import _figure

    fig = _figure((12.0, 4.1))
    axes = fig.subplots(1, len(st.results))
    vmax = max(pressure(r).max() for r in st.results.values()) / 1e3
    norm = PowerNorm(0.5, vmin=0.0, vmax=vmax)
    n = st.mesh
    h = A / n
    edges = np.clip(np.arange(n + 2) * h - h / 2, 0.0, A)
    for ax, (name, r) in zip(np.atleast_1d(axes), st.results.items()):
        xy = r.model.contacts.xy
        i, j = np.rint(xy[:, 0] / h).astype(int), np.rint(xy[:, 1] / h).astype(int)
        grid = np.ma.masked_all((n + 1, n + 1))
        on = np.asarray(r.active, dtype=bool)
        grid[j[on], i[on]] = pressure(r)[on] / 1e3
        ax.add_patch(Rectangle((0, 0), A, A, facecolor="0.93", edgecolor="0.5", hatch="///", lw=0.6, zorder=0))
        mesh = ax.pcolormesh(edges, edges, grid, cmap="viridis", norm=norm, zorder=1)
        ax.add_patch(Circle((HEAVE["x"], HEAVE["y"]), HEAVE["radius"], fill=False, ls=":", color="k", lw=1.2,
                            zorder=2, label="heave (2 mm)"))
        ax.plot(*FOOT, "w*", ms=13, mec="k", zorder=3, ls="none", label="foot (150 kN)")
        nb = numbers(r)
        ax.set_title(f"{name}: {100 * nb['lifted_share']:.0f} % lifted off, p max {nb['p_max'] / 1e3:.0f} kPa",
                     fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlim(0, A)
        ax.set_ylim(0, A)
        ax.set_xlabel("x (m)")
    np.atleast_1d(axes)[0].set_ylabel("y (m)")
    fig.colorbar(mesh, ax=list(np.atleast_1d(axes)), label="contact pressure (kPa)", shrink=0.85)
    first = np.atleast_1d(axes)[0]
    handles = [Patch(facecolor="0.93", edgecolor="0.5", hatch="///", label="lifted off")]
    first.legend(handles=handles + first.get_legend_handles_labels()[0], loc="lower left", fontsize=7)
    return fig


def plot_soil_sections(st: SoilStudy):
    """Deflection and Mx along :data:`SECTION` for each soil."""
    from ..plotting.style import _figure

    fig = _figure((10.5, 3.8))
    ax_w, ax_m = fig.subplots(1, 2)
    for (name, r), colour in zip(st.results.items(), ("C0", "C1", "C2")):
        s, w = r.section(*SECTION, quantity="w")
        ax_w.plot(s, w * 1e3, colour, label=name)
        ax_m.plot(s, r.section(*SECTION, quantity="Mx")[1] / 1e3, colour, label=name)
    ax_w.invert_yaxis()  # w is positive down
    ax_w.set_ylabel("w (mm), down")
    ax_m.set_ylabel("Mx (kN·m/m)")
    ax_m.axhline(0.0, color="0.6", lw=0.6)
    for ax in (ax_w, ax_m):
        ax.axvline(HEAVE["x"], color="0.6", ls=":", lw=0.8, label="heave's centre")
        ax.axvline(FOOT[0], color="0.6", ls="--", lw=0.8, label="foot")
        ax.set_xlabel("x along y = 2 m (m)")
        ax.legend(fontsize=8)
    return fig


__all__ = ["A", "ACCURACY", "Calibration", "E", "E_S", "FOOT", "H", "HEAVE", "MESH", "NU", "NU_S", "P", "Q",
           "SECTION", "SOILS", "SoilStudy", "beds", "calibrate", "data", "figures", "halfspace", "lines", "numbers",
           "plot_pressure_maps", "plot_soil_sections", "pressure", "slab_scene", "soil_study", "story", "table"]
