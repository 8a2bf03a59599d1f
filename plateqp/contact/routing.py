"""Which backend and formulation: the "auto" rules, and what each backend can take.

Nothing here solves anything; :mod:`plateqp.contact.pipeline` asks :func:`choose` before it
formulates.
"""

from __future__ import annotations

import contextlib

from ..backends import get_backend, in_house, registry
from ..errors import ProblemError, SolverError
from .formulations import FORMULATIONS
from .scaling import Scaled

# The "auto" rules, measured by benchmarks/bench_fast.py --parts auto (benchmarks/README.md,
# "backend='auto'"): grid_rigid(n, k), n = 32…256, k = 3…30 (m = 9…900), accuracy 1e-10, CPU
# time of the whole plateqp.solve on a single cold solve (a new model each time).
# * backend="auto" on a single solve: PDAS on the sparse primal was the fastest exact route at
#   every size measured (32²–128², m = 9…900; Lemke on the condensed LCP and BPP on the dual
#   never faster); BPP on the condensed LCP, condensation included (one contacts-last
#   factorisation, plateqp.linalg.SchurFactor), took 1.08–1.54× PDAS's time for m ≤ 100 and
#   up to 3× above (m = 900 at 32²). So a single solve goes to PDAS whatever m.
# * repeated solves that share K and B (a sweep, plateqp.studies.sweep, inside
#   :func:`repeated_solves`): the condensed route while m ≤ AUTO_LCP_MAX. Its condensation is
#   cached and re-used by every solve that shares the model (a dense m × m solve per value
#   instead of a factorisation: a sweep of 10 gaps at 128² took 0.45× PDAS's time), and BPP's answer did not depend on its warm start
#   (bit-identical serial and parallel sweeps in tests/studies/test_parallel.py, where warm-started
#   PDAS differed at 1e-13). A single solve of a floating plate went to the condensed route
#   too while m ≤ AUTO_LCP_MAX, while PDAS had no first phase for a singular K; with the
#   anchored first set it goes to PDAS like any other: measured
#   on families.floating(n, k), 9–81 posts, CPU medians of 3, accuracy 1e-10, PDAS took
#   1.05–1.4× BPP's time then (0.04–0.05 s at 32², 0.13–0.15 s at 64², 0.76–1.0 s at 128²),
#   but at 128² BPP's answers were INACCURATE (KKT 1–2e-10: the condensation of a singular K,
#   shifted and unshifted, costs digits) where PDAS's were at 1–2e-11 (the statics along the
#   slab's rigid motions, checked since, put BPP's at 4–16e-10 there, PDAS's at 3e-13). Now
#   PDAS's exact steps run on the anchored factorisation itself (pdas.factor.TrailingFactor):
#   0.67–0.96× BPP's time (benchmarks/bench_floating.py, interleaved).
# * which backend, read from the declared capabilities (plateqp.backends.base.Backend): an
#   exact one that takes the formulation (answers exact to rounding at any tolerance), the
#   warm-startable ones first (sweeps re-use their final active set; of the exact LCP solvers
#   that is BPP, also measured 7–10× faster than Lemke from m = 225 on). An exact QP solver
#   (PDAS) is offered at most as many contact rows as dofs (it refuses more). With no exact
#   backend for the formulation, the first installed of AUTO_QP_BACKENDS, the external QP
#   solvers in the order measured.
# * a named QP backend (osqp, clarabel, qpsolvers:*, …): the condensed problem paid while
#   m ≤ AUTO_CONDENSED_FRACTION × free dofs, never beyond AUTO_CONDENSED_MAX (the dense work
#   grows like m³, its memory like 8 m² bytes). Re-measured once condensation came from one
#   factorisation's trailing block (bench_scaling.py --parts contacts --meshes 32,64,128
#   --ks 5,9,15,31, accuracy 1e-6): condensed was faster for
#   OSQP, Clarabel and ProxQP at every m up to 7.5 % of the dofs (225 posts at 32²: 1.8–2×),
#   and at 2 % (961 at 128²: OSQP 7.4 s against 181 s, Clarabel 2.5 against 9.3, ProxQP 2.0
#   against 15.9); at 7.9 % (961 at 64²) for OSQP and ProxQP but not Clarabel (2.1 s against
#   1.4); at 32 % (961 at 32²) the primal for OSQP and Clarabel (7–8×). So 10 %: the worst
#   case measured is Clarabel at 7.9 %, 1.5× its primal. (The 1 % before was measured while
#   condensation took m refined column solves.)
# * a backend that takes only one of them (lemke, bpp, pgs: LCPs; pdas: the primal) gets it.
# * an elastic half-space under the plate (plateqp.model.soil): its soil block of K is dense
#   (m² numbers) already, so the condensed problem costs no more than the primal, at any m the
#   dense route takes; its exact LCP solvers answer where PDAS's penalised rows meet a soil
#   block 1e9 times softer than the plate's diagonal (a 16-triangle-a-side rigid punch).
AUTO_LCP_MAX = 100
AUTO_CONDENSED_FRACTION = 0.10
AUTO_CONDENSED_MAX = 1000
AUTO_QP_BACKENDS = ("clarabel", "qpsolvers:clarabel", "osqp", "cvxpy")

_REPEATED = [0]  # depth of repeated_solves() blocks in this process


@contextlib.contextmanager
def repeated_solves():
    """Within this block, backend="auto" counts on solves that share K and B (a sweep): it
    condenses while m ≤ AUTO_LCP_MAX, so that the condensation is paid once."""
    _REPEATED[0] += 1
    try:
        yield
    finally:
        _REPEATED[0] -= 1


def condensed_pays(data: Scaled, backend: str = "auto") -> bool:
    """True where formulation="auto" condenses (see the rules above).

    ``backend="auto"``: m ≤ AUTO_LCP_MAX for repeated solves (:func:`repeated_solves`), else
    never; a named QP backend: m ≤ AUTO_CONDENSED_FRACTION × free dofs and m ≤
    AUTO_CONDENSED_MAX.
    """
    if data.soil == "halfspace":  # its soil block is dense already: the condensed problem costs no more
        return True
    if backend == "auto":
        return data.m <= AUTO_LCP_MAX and _REPEATED[0] > 0
    return data.m <= min(AUTO_CONDENSED_MAX, AUTO_CONDENSED_FRACTION * data.n)


def _first_installed(names: tuple[str, ...]) -> str | None:
    return next((b for b in names if b in registry() and registry()[b].available()), None)


def exact_backends(formulation: str, data: Scaled | None = None) -> list[str]:
    """The installed backends declared ``exact`` that take ``formulation``, the warm-startable
    first (then in registry order); with ``data``, an exact QP backend only while the contact
    rows are at most the dofs. Every exact backend is plateqp's own (:data:`plateqp.backends.
    IN_HOUSE`): no third-party solver module is imported to find them."""
    found = [b for b in in_house().values() if getattr(b, "exact", False) and b.available()
             and formulation in formulations_for(b)
             and (data is None or "lcp" in b.accepts or data.m <= data.n)]
    return [b.name for b in sorted(found, key=lambda b: not getattr(b, "warm_start", False))]


def choose(data: Scaled, backend: str, formulation: str) -> tuple[str, str]:
    if formulation == "auto":
        takes = list(FORMULATIONS) if backend == "auto" else formulations_for(backend)
        if "condensed" not in takes:
            formulation = "primal" if "primal" in takes else takes[0]
        elif "primal" not in takes:
            formulation = "condensed"
        else:
            formulation = "condensed" if condensed_pays(data, backend) else "primal"
    if formulation not in FORMULATIONS:
        raise ProblemError(f"unknown formulation {formulation!r}; choose one of {FORMULATIONS}")
    if backend == "auto":
        backend = next(iter(exact_backends(formulation, data)), None) or _first_installed(AUTO_QP_BACKENDS)
        if backend is None:
            raise SolverError(f"the {formulation} formulation needs a QP backend; none is installed "
                              "(pip install 'plateqp[solvers]')")
    return backend, formulation


def fallback_routes(data: Scaled, first: str) -> list[tuple[str, str]]:
    """The exact routes backend="auto" tries, in order, after its first route (``first``,
    "backend/formulation") stopped short: pdas on the primal problem, then the exact LCP
    solvers (bpp, lemke) on the condensed problem and, where two-sided supports hold the plate,
    on the dual one. The condensed and dual problems are dense (m² numbers, m³ work), so they
    are offered while m ≤ AUTO_CONDENSED_MAX."""
    forms = ["primal"]
    if data.m <= AUTO_CONDENSED_MAX or data.soil == "halfspace":
        forms += ["condensed"] + ([] if data.floating else ["dual"])
    return [(b, f) for f in forms for b in exact_backends(f, data) if f"{b}/{f}" != first]


def formulations_for(backend) -> list[str]:
    """The formulations a backend can solve: every one for a QP backend, condensed and dual for
    an LCP backend, restricted further by the backend's optional ``formulations`` attribute
    (e.g. a solver built for the sparse primal). ``backend``: a Backend or its name."""
    if isinstance(backend, (set, frozenset)):  # a bare ``accepts`` set
        accepts, only = backend, None
    else:
        b = get_backend(backend) if isinstance(backend, str) else backend
        accepts, only = b.accepts, getattr(b, "formulations", None)
    return [f for f in FORMULATIONS if ("qp" in accepts or (f != "primal" and "lcp" in accepts))
            and (only is None or f in only)]
