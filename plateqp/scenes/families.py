r"""Generated scene families for benchmarks and tests, parametrised by mesh size and supports.

Every family is one square concrete slab in **kN and m** (so stresses in kPa):

=========  =====================================================================
plate      8 m × 8 m, h = 0.20 m, E = 3.0·10⁷ kN/m² (30 GPa), ν = 0.2,
           D = E h³ / 12(1 − ν²) ≈ 20 833 kN·m
mesh       n × n ACM cells (``element="bfs"`` as an option), node spacing 8/n m
loads      self-weight and floor load q = 10 kN/m² over the slab, plus a column
           load P = 300 kN at (5 m, 4.5 m) (on a node for every n divisible by 16)
=========  =====================================================================

Families (``k`` is the number of supports per row, or ``"all"``: one at every node that
can carry one):

``grid_rigid(n, k)``
    The slab simply supported on its four walls (two-sided edges) and resting on a k × k grid
    of rigid one-sided posts inside, with mixed gaps (:func:`gap_pattern`): heave near the
    corner (0, 0), settlement near (8, 8), a band of zero gap along the other diagonal.
``grid_elastic(n, k)``
    The same grid of posts as elastic piles of stiffness :data:`PILE_STIFFNESS` (kN/m) with
    the same gaps (heave pre-compresses the heaved piles).
``floating(n, k)``
    The slab held only by a k × k grid of rigid one-sided posts that includes the edges and
    corners: no walls, no pins, so the two-sided problem is singular (three rigid motions).
    Only the posts and statics hold it. Same gap pattern with δ = :data:`GAP_FLOATING`; some
    posts near the heaved and the settled corners lift off (k ≥ 5).
``bed(n)``
    A free slab on a tensionless Winkler bed of modulus :data:`BED_MODULUS` (kN/m³) over the
    whole plan, every node a one-sided spring; the column load alone (no q), so the slab
    lifts off the bed away from the load. ``k`` is ignored.

Supports sit on mesh nodes for every n: positions are snapped to the nearest node, and they
are evenly spaced when the grid divides the mesh (grid families: (k + 1) | n; floating:
(k − 1) | n; e.g. n = 16, 32, … with k = 3, 7, 15 or k = 5, 9, 17). Distinct supports need
k ≤ n − 1 (grid families, interior nodes only) or k ≤ n + 1 (floating); ``"all"`` is that
maximum. The total one-sided contact count is ``m = k²`` (bed: ``(n + 1)²``).

>>> from plateqp.scenes.families import family, FAMILIES
>>> scene = family("grid_rigid", 32, 7)          # 32² ACM slab, 49 posts
>>> sorted(FAMILIES)
['bed', 'floating', 'grid_elastic', 'grid_rigid']
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..model.scene import (
    Edge,
    Foundation,
    MeshSpec,
    Plate,
    PointLoad,
    Scene,
    Support,
    UniformLoad,
)

#: The slab, in kN and m.
A = 8.0
SLAB = {"a": A, "b": A, "h": 0.20, "E": 3.0e7, "nu": 0.2}
#: Uniform load (kN/m²): self-weight 5 plus floor load 5.
Q = 10.0
#: Column load (kN) and its position (m).
P, PX, PY = 300.0, 5.0, 4.5
#: Largest gap magnitude (m) of the grid families: 1 mm of heave or settlement.
GAP = 1.0e-3
#: The same for the floating slab, 5 mm: a rigid tilt of the slab takes up much of a gap
#: pattern, so it needs larger gaps to lift off its posts (about a fifth do at k = 5).
GAP_FLOATING = 5.0e-3
#: Stiffness of an elastic pile (kN/m).
PILE_STIFFNESS = 2.0e5
#: Modulus of the tensionless bed (kN/m³): a medium-dense soil.
BED_MODULUS = 2.0e4

K = int | str  # supports per row, or "all"


def _plate() -> Plate:
    return Plate(**SLAB)


def _mesh(n: int, element: str) -> MeshSpec:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
        raise TypeError(f"n must be an integer (got {n!r})")
    if n < 2:
        raise ValueError(f"n must be >= 2 (got {n})")
    return MeshSpec(int(n), int(n), element)


def _loads(point_only: bool = False) -> list:
    pt = PointLoad(P, PX, PY)
    return [pt] if point_only else [UniformLoad(Q), pt]


def positions(n: int, k: K, interior: bool) -> np.ndarray:
    """Node coordinates (m) of ``k`` supports along one side of the n × n mesh.

    ``interior``: the grid families' posts avoid the walls, at a·(i + 1)/(k + 1); the floating
    plate's include the edges, at a·i/(k − 1). Each is snapped to the nearest node.
    """
    kmax = n - 1 if interior else n + 1
    if k == "all":
        k = kmax
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
        raise TypeError(f"k must be an integer or 'all' (got {k!r})")
    kmin = 1 if interior else 2
    if not (kmin <= k <= kmax):
        raise ValueError(f"k = {k} supports per row do not fit on distinct nodes of an n = {n} mesh "
                         f"({kmin} ≤ k ≤ {kmax}{', interior nodes' if interior else ''})")
    i = np.arange(k)
    t = (i + 1) / (k + 1) if interior else i / (k - 1)
    nodes = np.floor(t * n + 0.5).astype(int)
    return nodes * (A / n)


def gap_pattern(x, y, amplitude: float = GAP):
    r"""Initial gaps (m) of the grid families: heave, a zero band, settlement.

    With t = (x + y)/a − 1 ∈ [−1, 1],

    .. math:: g_0 = \delta\,\mathrm{sign}(t)\,\max(|t| - \tfrac14,\,0) / \tfrac34,

    so g0 = −δ (heave) at (0, 0), +δ (settlement) at (a, a), and exactly 0 where
    |x + y − a| ≤ a/4.
    """
    t = (np.asarray(x, float) + np.asarray(y, float)) / A - 1.0
    return amplitude * np.sign(t) * np.maximum(np.abs(t) - 0.25, 0.0) / 0.75


def _grid_supports(n: int, k: K, stiffness, interior: bool, amplitude: float = GAP) -> list[Support]:
    xs = positions(n, k, interior)
    return [Support(float(x), float(y), gap=float(gap_pattern(x, y, amplitude)), stiffness=stiffness)
            for x in xs for y in xs]


WALLS = {e: Edge("simple") for e in ("left", "right", "bottom", "top")}


def grid_rigid(n: int, k: K = 7, element: str = "acm") -> Scene:
    """Slab on four walls and a k × k grid of rigid one-sided posts with mixed gaps (see module)."""
    return Scene(name=f"grid_rigid-{n}-{k}", plate=_plate(), mesh=_mesh(n, element), edges=dict(WALLS),
                 loads=_loads(), supports=_grid_supports(n, k, "rigid", interior=True))


def grid_elastic(n: int, k: K = 7, element: str = "acm") -> Scene:
    """Slab on four walls and a k × k grid of elastic piles (:data:`PILE_STIFFNESS`) with mixed gaps."""
    return Scene(name=f"grid_elastic-{n}-{k}", plate=_plate(), mesh=_mesh(n, element), edges=dict(WALLS),
                 loads=_loads(), supports=_grid_supports(n, k, PILE_STIFFNESS, interior=True))


def floating(n: int, k: K = 5, element: str = "acm") -> Scene:
    """Slab held only by a k × k grid of rigid one-sided posts, edges and corners included."""
    return Scene(name=f"floating-{n}-{k}", plate=_plate(), mesh=_mesh(n, element),
                 loads=_loads(), supports=_grid_supports(n, k, "rigid", interior=False, amplitude=GAP_FLOATING))


def bed(n: int, k: K | None = None, element: str = "acm") -> Scene:
    """Free slab on a tensionless bed (:data:`BED_MODULUS`) under the column load alone; ``k`` ignored."""
    return Scene(name=f"bed-{n}", plate=_plate(), mesh=_mesh(n, element), loads=_loads(point_only=True),
                 foundation=Foundation(k=BED_MODULUS))


#: name → scene builder ``f(n, k, element="acm")``.
FAMILIES: dict[str, Callable[..., Scene]] = {
    "grid_rigid": grid_rigid,
    "grid_elastic": grid_elastic,
    "floating": floating,
    "bed": bed,
}


def family(name: str, n: int, k: K | None = None, element: str = "acm") -> Scene:
    """The scene of family ``name`` at mesh n × n with k supports per row (the family's default if None)."""
    if name not in FAMILIES:
        raise ValueError(f"unknown family {name!r}; choose one of {sorted(FAMILIES)}")
    f = FAMILIES[name]
    return f(n, element=element) if k is None else f(n, k, element=element)


def total_load(scene: Scene) -> float:
    """The total downward load (kN) of a family's scene: q·a·b plus the point loads."""
    p = scene.plate
    return sum(ld.q * p.a * p.b if isinstance(ld, UniformLoad) else ld.P for ld in scene.loads)


def n_contacts(name: str, n: int, k: K | None = None) -> int:
    """The number m of one-sided contact points of ``family(name, n, k)`` (without building it)."""
    if name == "bed":
        return (n + 1) ** 2
    if k is None:
        k = {"grid_rigid": 7, "grid_elastic": 7, "floating": 5}[name]
    return len(positions(n, k, interior=name != "floating")) ** 2
