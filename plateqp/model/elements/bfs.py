"""BFS (Bogner–Fox–Schmit) 16-dof conforming rectangle.

Dofs per node: w, ∂w/∂x, ∂w/∂y, ∂²w/∂x∂y. Interpolation: the bicubic Hermite polynomials
(all ξ^i η^j with i, j ≤ 3), so w and both slopes are continuous across element edges
(C¹-conforming on rectangles). Converges with order h⁴ in deflection on smooth problems.
"""

from __future__ import annotations

from .base import RectElement


class BFS(RectElement):
    name = "bfs"
    monomials = tuple((i, j) for i in range(4) for j in range(4))
    node_dofs = ((0, 0), (1, 0), (0, 1), (1, 1))
    dof_names = ("w", "wx", "wy", "wxy")
