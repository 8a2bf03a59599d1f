"""Export a small family of plate contact problems as two qpbenchmark test sets.

    python benchmarks/qpbenchmark/make_testsets.py            # writes beside this file

writes ``plateqp_primal.py`` + ``data/primal/*.npz`` (the sparse primal QPs; qpbenchmark runs
its sparse solvers on them) and ``plateqp_condensed.py`` + ``data/condensed/*.npz`` (the dense
condensed QPs, ½ zᵀMz + qᵀz, z ≥ 0; every solver), and ``results/optcosts.csv``: each
problem's size and its optimal objective from plateqp's exact solvers (Lemke on the condensed
LCP, PDAS on the primal), a reference for the objectives the solvers reach.

The family: the source paper's 8 m × 8 m, 20 cm slab floating on a 5 × 5 grid of one-sided
supports (kgf, cm), on the paper's 16 × 16 mesh and on 32 × 32:

- ``mixed``: rigid supports, heave (gap −0.2 cm) under supports 1, 2, 6 and settlement
  (+0.2 cm) under 16, 17, 21, 22 (the built-in ``heave`` scene with the ``settlement`` gaps added);
- ``stiffness``: elastic supports (c = 1e5 kgf/cm), supports 1, 2, 8 heaved (built-in);
- ``contour``: the slab on 64 elastic supports along its edges, corners curling up (built-in).

The .npz files are not kept in git (about 3 MB); this script makes them again in seconds.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import sys
from pathlib import Path

import numpy as np

import plateqp as pq
from plateqp import scenes
from plateqp.io import contact_qp, write_qpbenchmark

HERE = Path(__file__).resolve().parent
MESHES = (16, 32)
EXACT = {"primal": "pdas", "condensed": "lemke"}


def family() -> list[pq.Scene]:
    """The scenes, each on every mesh of MESHES."""
    mixed = scenes.load("heave")
    settled = {i for i, s in enumerate(scenes.load("settlement").supports) if s.gap > 0}
    mixed = dataclasses.replace(
        mixed, name="mixed",
        supports=[dataclasses.replace(s, gap=0.2) if i in settled else s for i, s in enumerate(mixed.supports)])
    out = []
    for base in (mixed, scenes.load("stiffness"), scenes.load("contour")):
        for n in MESHES:
            out.append(dataclasses.replace(base, name=f"{base.name}{n}", mesh=dataclasses.replace(base.mesh, nx=n, ny=n)))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(HERE), help="the folder to write the test sets into")
    args = ap.parse_args(argv)
    out = Path(args.out)
    rows = []
    exported = {"primal": [], "condensed": []}
    for scene in family():
        for form in exported:
            e = contact_qp(scene, form)
            ref = pq.solve(scene, backend=EXACT[form], formulation=form, accuracy="high", model=e.model)
            if ref.status != pq.Status.OPTIMAL:
                print(f"{e.name}: plateqp's {EXACT[form]} ended {ref.status.value}", file=sys.stderr)
                return 1
            x = e.x_from_result(ref)
            qp = e.qp
            exported[form].append(e)
            rows.append({"problem": e.name, "formulation": form, "n": qp.n,
                         "m_ineq": 0 if qp.G is None else qp.G.shape[0],
                         "nnz_P": qp.P.nnz if qp.sparse else int(np.count_nonzero(qp.P)),
                         "contacts": int(ref.active.sum()), "supports": len(ref.active),
                         "objective": repr(e.objective(x)), "reference": f"plateqp {EXACT[form]} (KKT {ref.kkt.worst:.1e})"})
            print(f"{e.name:24s} n={qp.n:5d}  {rows[-1]['contacts']:2d}/{rows[-1]['supports']} in contact  "
                  f"objective {e.objective(x):.12g}")
    for form, problems in exported.items():
        title = {"primal": "plateqp plate contact, primal form (sparse)",
                 "condensed": "plateqp plate contact, condensed form (dense)"}[form]
        descr = {
            "primal": "Kirchhoff plate (ACM elements) floating on one-sided supports, the primal contact QP: "
                      "min 1/2 u'Ku + 1/2 t't - f'u s.t. Bu - sqrt(rho) t <= g0, nondimensional (deflections by W, "
                      "forces by F0). K is singular (the slab floats: rigid motions are held only by the "
                      "supports). 16x16 and 32x32 meshes of the source paper's slab: mixed heave and settlement "
                      "on 25 rigid supports, 25 elastic supports with heave, 64 elastic edge supports.",
            "condensed": "The same problems condensed onto the contact points (static condensation, the "
                         "source paper's route): min 1/2 z'Mz + q'z s.t. z >= 0, z the gaps, M = (I + S rho)^-1 S "
                         "dense and positive semidefinite (singular for rigid supports: the slab floats).",
        }[form]
        module = write_qpbenchmark(problems, out, name=f"plateqp_{form}", title=title, description=descr,
                                   data_dir=f"data/{form}", force=True)
        print(f"wrote {module}")
    (out / "results").mkdir(exist_ok=True)
    with open(out / "results" / "optcosts.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {out / 'results' / 'optcosts.csv'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
