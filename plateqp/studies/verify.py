"""The verification ladder: plateqp against closed forms and independent references, re-runnable.

Each :class:`Case` is one quantity of one plate whose answer is known from outside plateqp's
code: a closed form (Navier's series, the axisymmetric solutions of circular and annular plates,
Hertz's plate on an elastic bed), exact statics (a statically determinate plate on posts, a
square whose corner settles), or an independent element on a finer mesh. :func:`verify` solves
each case on two or three meshes that halve and reports, per mesh, plateqp's value, the
reference, the relative error and the observed rate of convergence (the order p in
error ∝ hᵖ, from the two meshes before it). A case passes when its error on its finest mesh is
within the case's tolerance; the coarser meshes show the trend. ``plateqp verify`` prints the
table (``--json`` the rows, ``--quick`` two meshes each, about a minute).

References (the tests in tests/model/test_plate.py, test_shapes.py and
tests/studies/test_homotopy.py check the same facts):
Timoshenko & Woinowsky-Krieger, *Theory of plates and shells* (1959): Navier's double series
(§ 28, § 34), the circular plate (§§ 15-19) and the annulus (§ 62's general axisymmetric
solution), the clamped square (Table 35, 0.00126 q a⁴/D; to more digits 0.0012653, Taylor and
Govindjee, 2004), the plate on an elastic foundation under a point load (§ 57, Hertz:
w₀ = P / (8 √(k D)), w(r) = −P ℓ² kei(r/ℓ) / (2π D), ℓ = (D/k)^¼); the plate on a two-parameter
foundation (Kerr, "Elastic and viscoelastic foundation models", J. Appl. Mech. 31, 1964;
Selvadurai, *Elastic analysis of soil-foundation interaction*, 1979, ch. 5).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import PlateQPError, PlateQPWarning
from ..model.scene import (Edge, Foundation, MeshSpec, Opening, Plate, PointLoad, Scene, Support,
                           UniformLoad)
from ..progress import track

NU = 0.3
#: A plate whose D is 1e7·0.01³/(12·0.91) ≈ 0.0916 (units cancel: errors are relative).
PLATE = {"h": 0.01, "E": 1.0e7, "nu": NU}


def _D() -> float:
    return Plate(**PLATE).D


#: half-spaces under the verification plate (D ≈ 0.0916, radius 1): E_s a³ / D = 1e-3 (the plate
#: a rigid punch on it) and 1e5 (the plate's bending negligible: the bare half-space's load)
_E_SOIL = 1e-3 * 0.0916
_E_SOFT = 1e5 * 0.0916


# -- closed forms -------------------------------------------------------------------------------
def navier_uniform(a: float, b: float, x: float, y: float, terms: int = 199) -> float:
    """w·D/q of a simply supported a × b plate under uniform q at (x, y): Navier's double series
    over odd m, n (§ 30), summed to ``terms`` (error below 1e-9 of the value)."""
    m = np.arange(1, terms + 1, 2)[:, None]
    n = np.arange(1, terms + 1, 2)[None, :]
    s = np.sin(m * np.pi * x / a) * np.sin(n * np.pi * y / b) / (m * n * ((m / a) ** 2 + (n / b) ** 2) ** 2)
    return float(16 / np.pi**6 * s.sum())


def navier_point(a: float, b: float, x0: float, y0: float, x: float, y: float, terms: int = 4001) -> float:
    """w·D/P of a simply supported a × b plate under a point load P at (x0, y0), at (x, y) (§ 34)."""
    m = np.arange(1, terms + 1)[:, None]
    n = np.arange(1, terms + 1)[None, :]
    s = (np.sin(m * np.pi * x0 / a) * np.sin(n * np.pi * y0 / b) * np.sin(m * np.pi * x / a)
         * np.sin(n * np.pi * y / b) / ((m / a) ** 2 + (n / b) ** 2) ** 2)
    return float(4 / (np.pi**4 * a * b) * s.sum())


def annulus(r: float, a: float, b: float, nu: float, kind: str) -> float:
    """w·D/q of an annulus b < r < a under uniform q, both edges clamped or both simply supported:
    w = A + B r² + C ln r + E r² ln r + r⁴/64 with the four edge conditions (§ 62)."""
    def rows(rr):
        w = [1.0, rr**2, math.log(rr), rr**2 * math.log(rr)]
        w1 = [0.0, 2 * rr, 1 / rr, 2 * rr * math.log(rr) + rr]
        w2 = [0.0, 2.0, -1 / rr**2, 2 * math.log(rr) + 3]
        p = 1 / 64
        if kind == "clamped":
            return [w, w1], [-p * rr**4, -4 * p * rr**3]
        return [w, [w2[k] + nu * w1[k] / rr for k in range(4)]], [-p * rr**4, -(12 + 4 * nu) * p * rr**2]
    (ra, fa), (rb, fb) = rows(a), rows(b)
    c = np.linalg.solve(np.array(ra + rb), np.array(fa + fb))
    return float(c @ [1.0, r**2, math.log(r), r**2 * math.log(r)] + r**4 / 64)


def hertz_bed(r: float, P: float, k: float, D: float) -> float:
    """w of an infinite plate on an elastic bed of modulus k under a point load P, at distance r:
    −P ℓ² kei(r/ℓ) / (2π D) with ℓ = (D/k)^¼ (at r = 0: P / (8 √(k D)))."""
    from scipy.special import kei

    ell = (D / k) ** 0.25
    return float(-P * ell**2 * kei(r / ell) / (2 * math.pi * D))


def kerr_bed(r: float, P: float, k: float, c2: float, D: float) -> float:
    """w of an infinite plate on a two-parameter (Pasternak) foundation, springs k and shear
    layer c2, under a point load P, at distance r (Kerr 1964; Selvadurai 1979, ch. 5): with
    ξ⁴ + (c2/D) ξ² + k/D = (ξ² + a1)(ξ² + a2), w = P [K0(√a2 r) − K0(√a1 r)] / (2π D (a1 − a2))
    (modified Bessel functions of complex argument; c2 = 0: Hertz's :func:`hertz_bed`)."""
    from scipy.special import kv

    b, c = c2 / D, k / D
    disc = complex(b * b - 4 * c) ** 0.5
    a1, a2 = (b + disc) / 2, (b - disc) / 2
    r = max(r, 1e-12)
    return float((P * (kv(0, a2**0.5 * r) - kv(0, a1**0.5 * r)) / (2 * math.pi * D * (a1 - a2))).real)


# -- the cases ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class Case:
    """One verified quantity: ``scene(level)`` the plate on the mesh of that level (levels halve
    the mesh size), ``h(level)`` that size, ``value(result)`` plateqp's quantity, ``reference()``
    the external answer, ``tol`` the largest relative error allowed on the finest mesh run."""
    name: str
    title: str
    source: str
    scene: Callable[[int], Scene]
    h: Callable[[int], float]
    mesh: Callable[[int], str]
    value: Callable
    reference: Callable[[], float]
    tol: float
    levels: tuple[int, ...] = (8, 16, 32)
    quick: tuple[int, ...] = (8, 16)
    solve: str = "solve"  # or "bilateral"
    #: the accuracy asked ("high" unless the case's own rounding floor is above it)
    accuracy: str | float = "high"


def _square(n: int, element: str, edge: str, load, ny_ratio: int = 1, **kw) -> Scene:
    return Scene(name="square", plate=Plate(a=1.0, b=float(ny_ratio), **PLATE), mesh=MeshSpec(n, ny_ratio * n, element),
                 edges={"all": Edge(edge)} if edge else {}, loads=[load], **kw)


def _disc(n: int, edge: str | None, load, held: tuple[str, ...] = ("all",), **kw) -> Scene:
    return Scene(name="disc", plate=Plate(shape={"circle": [0.0, 0.0, 1.0]}, **PLATE),
                 mesh=MeshSpec(element="dkt", size=1.0 / n), edges={e: Edge(edge) for e in held} if edge else {},
                 loads=list(load) if isinstance(load, (list, tuple)) else [load], **kw)


def _grid_case(name, title, source, edge, load, ref, tol, element="acm", at=(0.5, 0.5), **kw) -> Case:
    """A plate on the grid whose deflection at ``at`` is the quantity (``kw``: _square's)."""
    ratio = kw.get("ny_ratio", 1)
    return Case(name, title, source, lambda n: _square(n, element, edge, load, **kw), lambda n: 1.0 / n,
                lambda n: f"{element.upper()} {n}²" if ratio == 1 else f"{element.upper()} {n}×{ratio * n}", lambda r: r.deflection(*at), ref, tol, **_LEVELS_GRID)


def _disc_case(name, title, source, edge, load, ref, tol, at=(0.0, 0.0), **kw) -> Case:
    """A disc of radius 1 on DKT triangles whose deflection at ``at`` is the quantity."""
    return Case(name, title, source, lambda n: _disc(n, edge, load, **kw), lambda n: 1.0 / n,
                lambda n: f"DKT R/{n}", lambda r: r.deflection(*at), ref, tol, **_LEVELS_TRI)


_LEVELS_GRID = {"levels": (8, 16, 32, 64), "quick": (8, 16)}
_LEVELS_TRI = {"levels": (8, 16, 32, 64), "quick": (8, 16)}
_TIM = "Timoshenko & Woinowsky-Krieger"
_POSTS = [(0.0, 0.0), (1.0, 0.0), (0.5, 1.0)]
_CORNERS = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
_L = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]


def _l_dkt(n: int) -> Scene:
    return Scene(name="L", plate=Plate(shape={"polygon": _L}, **PLATE), mesh=MeshSpec(element="dkt", size=1.0 / n),
                 edges={"outer": Edge("clamped")}, loads=[UniformLoad(1.0)])


def _l_reference() -> float:
    """The same L on the grid: a 2 × 2 square less the quadrant [1, 2]², clamped all round, the
    cut-out's edges named clamped too, on BFS (a conforming element, not the DKT under test) at
    32², 64² and 128², extrapolated by Aitken's Δ² (the re-entrant corner slows both elements to
    about first order: BFS 128² alone is 0.2 % short)."""
    from ..solving import solve

    w = []
    for n in (32, 64, 128):
        sc = Scene(name="L-bfs", plate=Plate(a=2.0, b=2.0, **PLATE), mesh=MeshSpec(n, n, "bfs"),
                   openings=[Opening(1.0, 2.0, 1.0, 2.0)], loads=[UniformLoad(1.0)],
                   edges={"all": Edge("clamped"), "hole0": Edge("clamped")})
        w.append(solve(sc).deflection(0.5, 0.5))
    d1, d2 = w[1] - w[0], w[2] - w[1]
    return w[2] - d2 * d2 / (d2 - d1)


def _settled_corner(n: int) -> Scene:
    """A free square on four rigid corner posts under q = 1; post 3 (at (1, 1)) settles by half the
    settlement δ* = q a⁴ / (8 D (1 − ν)) at which it would lift off."""
    dstar = 1.0 / (8 * _D() * (1 - NU))
    gaps = [0.0, 0.0, 0.5 * dstar, 0.0]
    return _square(n, "acm", None, UniformLoad(1.0),
                   supports=[Support(x, y, gap=g) for (x, y), g in zip(_CORNERS, gaps)])


def cases() -> list[Case]:
    D = _D()
    k_bed = D / 0.15**4  # ℓ = 0.15: the disc of radius 1 is 6.7 ℓ, an infinite plate to 1e-3
    full_contact_q = 30.0  # q/k beats the point load's lift of the far field: every node in contact
    return [
        _grid_case("navier-ss-uniform", "simply supported square, uniform q: w at the centre",
                   f"Navier's series ({_TIM} § 30)", "simple", UniformLoad(1.0),
                   lambda: navier_uniform(1, 1, 0.5, 0.5) / D, 0.01),
        _grid_case("navier-ss-uniform-bfs", "the same on BFS",
                   f"Navier's series ({_TIM} § 30)", "simple", UniformLoad(1.0),
                   lambda: navier_uniform(1, 1, 0.5, 0.5) / D, 0.002, element="bfs"),
        _grid_case("navier-ss-point", "simply supported square, central point load: w at the centre",
                   f"Navier's series ({_TIM} § 34)", "simple", PointLoad(1.0, 0.5, 0.5),
                   lambda: navier_point(1, 1, 0.5, 0.5, 0.5, 0.5) / D, 0.01),
        _grid_case("clamped-square-uniform", "clamped square, uniform q: w at the centre",
                   f"{_TIM} Table 35; 0.0012653 q a⁴/D (Taylor & Govindjee 2004)", "clamped",
                   UniformLoad(1.0), lambda: 0.0012653 / D, 0.01),
        _disc_case("disc-clamped-uniform", "clamped circular plate, uniform q: w at the centre",
                   f"q R⁴ / (64 D) ({_TIM} § 15)", "clamped", UniformLoad(1.0), lambda: 1 / (64 * D), 0.01),
        _disc_case("disc-simple-uniform", "simply supported circular plate, uniform q: w at the centre",
                   f"(5 + ν) q R⁴ / (64 (1 + ν) D) ({_TIM} § 16)", "simple", UniformLoad(1.0),
                   lambda: (5 + NU) / (64 * (1 + NU) * D), 0.01),
        _disc_case("disc-clamped-point", "clamped circular plate, central point load: w at the centre",
                   f"P R² / (16 π D) ({_TIM} § 19)", "clamped", PointLoad(1.0, 0.0, 0.0),
                   lambda: 1 / (16 * math.pi * D), 0.02),
        _disc_case("disc-simple-point", "simply supported circular plate, central point load: w at the centre",
                   f"(3 + ν) P R² / (16 π (1 + ν) D) ({_TIM} § 19)", "simple", PointLoad(1.0, 0.0, 0.0),
                   lambda: (3 + NU) / (16 * math.pi * (1 + NU) * D), 0.02),
        _disc_case("annulus-clamped", "annulus 0.3 < r < 1 clamped on both edges, uniform q: w at r = 0.65",
                   f"the axisymmetric solution with four edge conditions ({_TIM} § 62)", "clamped",
                   UniformLoad(1.0), lambda: annulus(0.65, 1.0, 0.3, NU, "clamped") / D, 0.02,
                   at=(0.65 * math.cos(0.4), 0.65 * math.sin(0.4)), held=("all", "hole0"),
                   holes=[{"circle": [0.0, 0.0, 0.3]}]),
        _disc_case("tensionless-bed-hertz", "free disc on a tensionless bed, q + central P: w at the centre",
                   f"q/k + P / (8 √(k D)) (Hertz; {_TIM} § 57): the bed is pressed everywhere", None,
                   (UniformLoad(full_contact_q), PointLoad(1.0, 0.0, 0.0)), lambda: full_contact_q / k_bed + hertz_bed(0.0, 1.0, k_bed, D),
                   0.01, foundation=Foundation(k=k_bed)),
        _disc_case("annulus-simple", "annulus 0.3 < r < 1 simply supported on both edges, uniform q: w at r = 0.65",
                   f"the axisymmetric solution with four edge conditions ({_TIM} § 62)", "simple",
                   UniformLoad(1.0), lambda: annulus(0.65, 1.0, 0.3, NU, "simple") / D, 0.01,
                   at=(0.65 * math.cos(0.4), 0.65 * math.sin(0.4)), held=("all", "hole0"),
                   holes=[{"circle": [0.0, 0.0, 0.3]}]),
        _grid_case("navier-rectangle", "simply supported 1 × 2 rectangle, uniform q: w at the centre",
                   f"Navier's series ({_TIM} § 30)", "simple", UniformLoad(1.0),
                   lambda: navier_uniform(1, 2, 0.5, 1.0) / D, 0.01, at=(0.5, 1.0), ny_ratio=2),
        Case("bonded-bed-kelvin", "free disc on a two-sided bed, central P: w at r = 0.2",
             f"−P ℓ² kei(r/ℓ) / (2π D), ℓ = (D/k)^¼ (Hertz; {_TIM} § 57)",
             lambda n: _disc(n, None, PointLoad(1.0, 0.0, 0.0), foundation=Foundation(k=k_bed)),
             lambda n: 1.0 / n, lambda n: f"DKT R/{n}", lambda r: r.deflection(0.2, 0.0),
             lambda: hertz_bed(0.2, 1.0, k_bed, D), 0.01, solve="bilateral", **_LEVELS_TRI),  # the disc is
        # finite (R = 6.7 ℓ), the reference the infinite plate's: the error levels off near 2e-4
        Case("bonded-pasternak-kerr", "free disc on a two-sided Pasternak bed (c2 = √(kD)), central P: w at r = 0.2",
             "P [K0(√a2 r) − K0(√a1 r)] / (2π D (a1 − a2)) (Kerr 1964; Selvadurai 1979, ch. 5)",
             lambda n: _disc(n, None, PointLoad(1.0, 0.0, 0.0),
                             foundation=Foundation(k=k_bed, model="pasternak", shear=math.sqrt(k_bed * D))),
             lambda n: 1.0 / n, lambda n: f"DKT R/{n}", lambda r: r.deflection(0.2, 0.0),
             lambda: kerr_bed(0.2, 1.0, k_bed, math.sqrt(k_bed * D), D), 0.01, solve="bilateral", **_LEVELS_TRI),
        Case("halfspace-rigid-punch", "a disc 1e3 × stiffer than the half-space under it, central P: w at the centre",
             "a rigid circular punch settles P (1 − ν²) / (2 a E) (Boussinesq; Johnson, Contact Mechanics, § 5.2)",
             lambda n: _disc(n, None, PointLoad(1.0, 0.0, 0.0), foundation=Foundation(model="halfspace", E=_E_SOIL, nu=NU)),
             lambda n: 1.0 / n, lambda n: f"DKT R/{n}", lambda r: r.deflection(0.0, 0.0),
             lambda: (1 - NU**2) / (2 * _E_SOIL), 0.02, levels=(4, 8, 16), quick=(4, 8),
             accuracy=1e-6),  # a plate 1e3 × stiffer than its soil: the KKT's rounding floor is 2e-7
        Case("halfspace-flexible-disc", "a disc 1e5 × softer than the half-space under it, uniform q: w at the centre",
             "uniform q over a circle of radius a on a half-space: 2 q a (1 − ν²)/E at its centre (Timoshenko & Goodier § 138)",
             lambda n: _disc(n, None, UniformLoad(1.0), foundation=Foundation(model="halfspace", E=_E_SOFT, nu=NU)),
             lambda n: 1.0 / n, lambda n: f"DKT R/{n}", lambda r: r.deflection(0.0, 0.0),
             lambda: 2 * (1 - NU**2) / _E_SOFT, 0.02, levels=(4, 8, 16), quick=(4, 8)),
        Case("bed-uniform-sinks", "free disc on a tensionless bed, uniform q: w at r = 0.5",
             "q / k: a rigid translation, no bending (exact for lumped loads and springs on one area)",
             lambda n: _disc(n, None, UniformLoad(2.0), foundation=Foundation(k=100.0)),
             lambda n: 1.0 / n, lambda n: f"DKT R/{n}", lambda r: r.deflection(0.5, 0.0),
             lambda: 0.02, 1e-8, levels=(4, 8, 16), quick=(4, 8)),
        Case("floating-statics", "free square on three posts, uniform q: the reaction of the post at (0.5, 1)",
             "statics (a statically determinate plate): q a² / 2",
             lambda n: _square(n, "acm", None, UniformLoad(1.0), supports=[Support(x, y) for x, y in _POSTS]),
             lambda n: 1.0 / n, lambda n: f"ACM {n}²", lambda r: float(r.reactions[2]), lambda: 0.5, 1e-8,
             levels=(4, 8, 16), quick=(4, 8)),
        Case("corner-settlement", "free square on four corner posts, one settled by δ*/2: its reaction",
             "R = q a²/4 − 2 D (1 − ν) δ / a² (the plate twists, w = δ x y / a²: exact for the element)",
             _settled_corner, lambda n: 1.0 / n, lambda n: f"ACM {n}²", lambda r: float(r.reactions[2]),
             lambda: 0.25 - 2 * (1 - NU) * 0.5 / (8 * (1 - NU)), 1e-8, levels=(4, 8, 16), quick=(4, 8)),
        Case("l-shape-clamped", "clamped L (2 × 2 less a quadrant), uniform q: w at (0.5, 0.5)",
             "an independent element: BFS on 32², 64², 128² grids of the same L, extrapolated", _l_dkt, lambda n: 1.0 / n,
             lambda n: f"DKT 1/{n}", lambda r: r.deflection(0.5, 0.5), _l_reference, 0.01,
             levels=(8, 16, 32), quick=(8, 16)),
    ]


# -- running it ---------------------------------------------------------------------------------
@dataclass
class Row:
    """One mesh of one case: ``passed`` is None on the coarser meshes (they show the trend)."""
    case: str
    mesh: str
    h: float
    value: float
    reference: float
    error: float
    rate: float | None
    passed: bool | None
    tol: float

    def to_dict(self) -> dict:
        return asdict(self)


def _solve(case: Case, scene: Scene):
    from ..solving import solve, solve_bilateral

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlateQPWarning)
        res = solve_bilateral(scene) if case.solve == "bilateral" else solve(scene, accuracy=case.accuracy)
    if hasattr(res, "kkt") and res.kkt is not None and not res.kkt.ok:
        raise PlateQPError(f"verify {case.name}: the KKT check failed on {case.mesh(0)}")
    return res


def run_case(case: Case, quick: bool = False) -> list[Row]:
    """The rows of one case, one per mesh, coarse to fine."""
    ref = float(case.reference())
    rows: list[Row] = []
    levels = case.quick if quick else case.levels
    for i, n in enumerate(levels):
        val = float(case.value(_solve(case, case.scene(n))))
        err = abs(val - ref) / abs(ref)
        rate = None  # not where both errors are rounding (exact statics)
        if rows and rows[-1].error > 1e-10 and err > 1e-10:
            rate = math.log(rows[-1].error / err) / math.log(rows[-1].h / case.h(n))
        last = i == len(levels) - 1
        rows.append(Row(case.name, case.mesh(n), case.h(n), val, ref, err, rate,
                        (err <= case.tol) if last else None, case.tol))
    return rows


def verify(quick: bool = False, names: Iterable[str] | None = None, progress: bool = True) -> list[Row]:
    """Run the ladder (every case, or those ``names``), two meshes each if ``quick``."""
    chosen = cases()
    if names is not None:
        names = list(names)
        known = {c.name for c in chosen}
        unknown = [n for n in names if n not in known]
        if unknown:
            raise PlateQPError(f"verify: unknown case {unknown[0]!r}; choose from {', '.join(sorted(known))}")
        chosen = [c for c in chosen if c.name in names]
    rows: list[Row] = []
    for case in track(chosen, desc="verify", enabled=progress):
        rows.extend(run_case(case, quick))
    return rows


def format_rows(rows: list[Row]) -> str:
    """The ladder as a plain-text table: case, mesh, plateqp, reference, error, rate, pass/fail."""
    head = f"{'case':26s} {'mesh':11s} {'plateqp':>12s} {'reference':>12s} {'error':>9s} {'rate':>5s}  result"
    out = [head, "-" * len(head)]
    for r in rows:
        verdict = "" if r.passed is None else ("pass" if r.passed else f"FAIL (tol {r.tol:.0e})")
        rate = "" if r.rate is None else f"{r.rate:5.2f}"
        out.append(f"{r.case:26s} {r.mesh:11s} {r.value:12.6g} {r.reference:12.6g} {r.error:9.2e} {rate:>5s}  {verdict}")
    finals = [r for r in rows if r.passed is not None]
    out.append(f"{sum(r.passed for r in finals)} of {len(finals)} cases pass")
    return "\n".join(out)
