"""The source paper's third claim as a study of ``plateqp demo``: "regulate the interaction
forces by changing the gaps" (:func:`plateqp.studies.design.regulate_gaps`).

**"regulate"** (:func:`regulation`): the built-in ``heave`` scene (the 8 m slab on 25
one-sided supports, supports 1, 2, 6 heaved by 2 mm, a 30 tf machine foot between supports
12, 13, 17, 18). Two regulations, each checked by an independent contact solve of the
regulated scene (``pq.solve``: the contact set is found again, not assumed):

* *equalise*: the four supports around the machine foot carry unequal reactions (the heave
  tilts the slab); new gaps (shims) under those four make each carry their mean, the other
  21 supports keep their gaps and find their own contact.
* *re-level*: the supports that were not heaved are shimmed so that every support carries the
  reaction it had on level ground (all gaps 0); geometry says the answer: raise each of them
  by the heave, 2 mm (a gap of −0.2 cm), wherever it touches on level ground.

Support numbers users read are 1-based; Python indices here are 0-based.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import scenes
from ..model.paths import set_param
from ..results import Result
from ..model.scene import Scene

#: The four supports around the machine foot of the ``heave`` scene (0-based: 12, 13, 17, 18).
FOOT = (11, 12, 16, 17)


@dataclass
class Regulation:
    """One regulation of the study: what was asked, the gaps found, and the check."""

    name: str
    supports: np.ndarray  # regulated, 0-based
    target: np.ndarray  # reactions asked of them
    gaps_before: np.ndarray  # every support's gap, scene order
    gaps: np.ndarray  # every support's regulated gap
    check: Result  # pq.solve of the regulated scene (accuracy "high"): the reactions its gaps give
    shim: np.ndarray | None = None  # dR_i/dg0_j among the regulated supports, at the regulated scene

    @property
    def error(self) -> float:
        """max |R − target| at the regulated supports in the check solve, relative to the load."""
        from ..scenes.families import total_load

        scale = abs(total_load(self.check.scene)) or float(np.abs(self.target).max())
        return float(np.abs(self.check.reactions[self.supports] - self.target).max() / scale)


@dataclass
class RegulationStudy:
    scene: Scene
    before: Result  # the heaved scene as it is
    level: Result  # the same slab with every gap 0
    runs: list[Regulation]


def _solve(scene: Scene) -> Result:
    from .. import solve

    return solve(scene, accuracy="high")


def regulation(scene: Scene | None = None) -> RegulationStudy:
    """Both regulations of the study on ``scene`` (default: the built-in ``heave``)."""
    from ..studies.design import regulate_gaps, shim_sensitivity

    scene = scene if scene is not None else scenes.load("heave")
    g0 = np.array([s.gap for s in scene.supports], dtype=float)
    before = _solve(scene)
    level = _solve(set_param(scene, "supports.*.gap", np.zeros(g0.size)))
    runs = []
    foot = np.array(FOOT)
    target = np.full(foot.size, before.reactions[foot].mean())
    r = regulate_gaps(scene, target, supports=foot.tolist())  # r.check: pq.solve of the regulated scene
    runs.append(Regulation("equalise", foot, target, g0, r.gaps, r.check, shim_sensitivity(r.check, foot)[0]))
    flat = np.flatnonzero(g0 == 0.0)
    r = regulate_gaps(scene, level.reactions[flat], supports=flat.tolist())
    runs.append(Regulation("re-level", flat, level.reactions[flat], g0, r.gaps, r.check))
    return RegulationStudy(scene, before, level, runs)


def _ids(idx) -> str:
    return ", ".join(str(int(i) + 1) for i in idx)


def regulation_lines(st: RegulationStudy, units: tuple[str, str] | None = None) -> list[str]:
    """The study in words: each regulation's gaps and its check (1-based support numbers)."""
    L, F = units or ("", "")
    eq, lv = st.runs
    out = [f"heaved as it is: supports {_ids(eq.supports)} carry "
           + ", ".join(f"{R:.0f}" for R in st.before.reactions[eq.supports]) + f" {F}".rstrip()]
    out.append(f"equalise: new gaps under {_ids(eq.supports)}: "
               + ", ".join(f"{g:+.4f}" for g in eq.gaps[eq.supports])
               + f" {L} (were " + ", ".join(f"{g:+.2g}" for g in eq.gaps_before[eq.supports]) + ")")
    out.append(f"  check (pq.solve of the regulated scene): each carries {eq.target[0]:.0f} {F}, "
               f"largest miss {eq.error:.1e} of the load; {int(eq.check.active.sum())} of "
               f"{eq.check.active.size} supports in contact ({int(st.before.active.sum())} before)")
    if eq.shim is not None:
        i, j = np.unravel_index(np.abs(eq.shim).argmax(), eq.shim.shape)
        out.append(f"  shim tolerance (plateqp.sensitivity at the regulated scene): a shim 0.01 {L} too thin "
                   f"under support {eq.supports[j] + 1} changes the reaction of support {eq.supports[i] + 1} by "
                   f"{0.01 * eq.shim[i, j]:+.0f} {F}, the largest of the four by four".rstrip())
    touching = lv.supports[st.level.reactions[lv.supports] > 0]
    shift = lv.gaps[touching] - lv.gaps_before[touching]
    out.append(f"re-level: the {lv.supports.size} supports not heaved shimmed so each carries its level-ground "
               f"reaction; those touching on level ground raised by {-shift.min():.4f} to {-shift.max():.4f} {L} "
               f"(the heave is {-st.scene.supports[0].gap:.4f} {L})")
    out.append(f"  check: largest miss {lv.error:.1e} of the load")
    return out


__all__ = ["FOOT", "Regulation", "RegulationStudy", "regulation", "regulation_lines"]
