"""ACM (Adini–Clough–Melosh) 12-dof non-conforming rectangle.

Dofs per node: w, ∂w/∂x, ∂w/∂y (deflection and two rotations, the dof set of the source
paper). Interpolation: the 12-term polynomial 1, ξ, η, ξ², ξη, η², ξ³, ξ²η, ξη², η³, ξ³η, ξη³.
The normal slope is not continuous across element edges (non-conforming); the element passes
the patch test and converges with order h² in deflection, from above on the classical
problems (Zienkiewicz & Taylor, vol. 2).
"""

from __future__ import annotations

from .base import RectElement


class ACM(RectElement):
    name = "acm"
    monomials = ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2), (3, 0), (2, 1), (1, 2), (0, 3), (3, 1), (1, 3))
    node_dofs = ((0, 0), (1, 0), (0, 1))
    dof_names = ("w", "wx", "wy")
