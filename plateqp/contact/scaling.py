"""Nondimensional contact data: the one place where a plate's model becomes numbers of order one.

Every formulation (:mod:`plateqp.contact.formulations`), the KKT report
(:mod:`plateqp.contact.kkt`) and the statics check (:mod:`plateqp.contact.statics`) start from
:class:`Scaled`: lengths by the plate's size L, deflections by the deflection the plate can
reach W, forces by F0 = W D / L².
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..model.assembly import Model
from ..errors import ProblemError
from ..linalg import pattern, row_stiffness
from ..linalg.keep import shared

# A plate's deflection is about 0.004–0.012 × F L²/D (Timoshenko's coefficients for square
# plates); scaling by F L²/D alone left deflections ~1e-3 and solvers' absolute tolerances
# 1000× short of the KKT tolerances (measured on the heave scene).
DEFLECTION_COEFFICIENT = 0.01

#: the contact points' spacing is searched on the grid's lattice where they are at least this
#: share of its nodes (a bed: all of them), by a tree where fewer (a few posts: a tree of 900
#: points takes under a millisecond, a pass over the lattice per offset 5 ms at 512²)
LATTICE_SHARE = 0.125


@dataclass
class Scaled:
    """Nondimensional contact data: lengths by L, deflections by W, forces by F0 = W D / L².

    Dofs u = S ũ with S = W (deflection), W/L (slopes), W/L² (twist); energies by F0·W.
    K̃ = S K S / (F0 W), f̃ = S f / F0·(1/W)·W, B̃ = B S / W, g̃ = g0 / W, ρ̃ = ρ D / L², R̃ = R / F0.
    W is the deflection the plate can actually have (:func:`deflection_scale`): the largest of
    the deflection the total load would cause (about 0.01 F_tot L²/D), the prescribed edge and
    pin displacements, the largest heave, and for a floating plate the largest gap. A
    settlement larger than that is never reached and does not set W (a support 1e2 × the free
    deflection below a held plate once made every deflection 1e-2 in scaled units).
    """

    K: sp.csc_matrix
    f: np.ndarray
    B: sp.csr_matrix
    g0: np.ndarray
    rho: np.ndarray
    dof_scale: np.ndarray  # S (per free dof)
    L: float
    W: float
    F0: float
    modes: np.ndarray  # rigid modes of K (n, k), scaled dofs
    is_w: np.ndarray  # (n,) bool: the dof is a deflection (not a slope or twist)
    # the model's own K and B, the key of what the formulations derive from them, and the model's
    # list that keeps it (Model.derived; plateqp.contact.formulations._cached)
    K_src: sp.csr_matrix | None = field(default=None, repr=False, compare=False)
    B_src: sp.csr_matrix | None = field(default=None, repr=False, compare=False)
    derived: list | None = field(default=None, repr=False, compare=False)
    # the deflection the load alone would cause (0.01 F L²/D), in units of W (≤ 1)
    w_load: float = 1.0
    # each contact point's distance to the nearest other held point (another contact point, or
    # a node whose w is prescribed), in units of L: bounds the plate's local stiffness there
    spacing: np.ndarray | None = field(default=None, repr=False, compare=False)
    #: the soil whose surface has unknowns of its own among K's ("pasternak", "halfspace"), or None
    soil: str | None = None
    #: a half-space held matrix-free (``Model.soil_flexibility``): s̃ = compliance(R̃), the
    #: compressions of every row (the posts' ρ̃ R̃ and the soil's settlement under the bed's rows);
    #: ``rho`` then holds on the bed's rows the soil's own point flexibility (the operator's
    #: diagonal), the series spring of the KKT check's local stiffness. None otherwise
    compliance: object = field(default=None, repr=False, compare=False)

    # inside plateqp.linalg.keep.sharing (a sweep): what this data derive from K, B and the contact
    # points' places alone (not from gaps, springs, loads nor W), kept in the model's list for the
    # next solve of the same K and B (:func:`structure`); None in a single solve
    memo: dict | None = field(default=None, repr=False, compare=False)

    @classmethod
    def from_model(cls, model: Model, operator: bool = False) -> Scaled:
        """The scaled data of ``model``. A model whose half-space is held matrix-free
        (``Model.soil_flexibility``) is scaled only for the route that takes the soil as an
        operator (``operator=True``, :mod:`plateqp.contact.pressures`); any other use is a
        ProblemError: its bed's rows alone would be a rigid bed."""
        c = model.contacts
        if c is None:
            raise ProblemError("the scene has no one-sided supports: nothing to formulate")
        if model.soil_flexibility is not None:
            if not operator:
                raise ProblemError(matrix_free_refusal(model))
            return with_compliance(cls._scale(model, None), model)
        return cls._scale(model, structure(model))

    @classmethod
    def _scale(cls, model: Model, memo: dict | None) -> Scaled:
        c = model.contacts
        if memo is not None and "K" in memo:
            return cls._again(model, memo)
        p = model.scene.plate
        L = max(p.a, p.b)
        D = p.D
        order = model.dof_orders  # the soil's unknowns (if any) are deflections
        modes = model.rigid_modes()
        W, W_load = deflection_scale(model, floating=modes.shape[1] > 0)
        F0 = W * D / L**2
        S = W / L ** order
        Sm = sp.diags(S)
        # CSC, the format every factorisation and the primal QP take: converted here, once, so
        # that no copy of it is alive beside this one when K is factorised (15 MB at 128²)
        K = pattern.scaled(pattern.csc_of_symmetric(model.K, model.symmetric), S,
                           1.0 / (F0 * W),  # its stored pattern kept (AMD); a copy, not model.K's arrays
                           spare=int(np.count_nonzero(c.rho > 0)))  # the primal Hessian's identity
        f = S * model.f / (F0 * W)
        B = (c.B @ Sm / W).tocsr()
        modes = modes / S[:, None]
        if modes.shape[1]:
            modes = modes / np.linalg.norm(modes, axis=0)
        nearest: list = []  # the points' search, kept for check_distinct_contacts
        data = cls(K, f, B, c.g0 / W, c.rho * D / L**2, S, L, W, F0, modes, order == 0, model.K, c.B,
                   w_load=W_load / W, spacing=contact_spacing(model, nearest) / L, derived=model.derived, memo=memo,
                   soil=soil_of(model))
        if memo is not None:  # K̃ = S K S / (F0 W) and B̃ = B S / W do not depend on W (S ∝ W, F0 ∝ W)
            memo.update(K=K, B=B, modes=modes, is_w=data.is_w, spacing=data.spacing, per_W=S / W)
        check_distinct_contacts(data, model, nearest[0] if nearest else None)
        return data

    @classmethod
    def _again(cls, model: Model, memo: dict) -> Scaled:
        """:meth:`from_model` where a solve before on the same K and B left its :func:`structure`:
        only W, F0 and the data that depend on them (S, f̃, g̃) and ρ̃ are made anew."""
        c = model.contacts
        p = model.scene.plate
        L = max(p.a, p.b)
        W, W_load = deflection_scale(model, floating=memo["modes"].shape[1] > 0)
        F0 = W * p.D / L**2
        S = W * memo["per_W"]
        data = cls(memo["K"], S * model.f / (F0 * W), memo["B"], c.g0 / W, c.rho * p.D / L**2, S, L, W, F0,
                   memo["modes"], memo["is_w"], model.K, c.B, w_load=W_load / W, spacing=memo["spacing"],
                   derived=model.derived, memo=memo, soil=soil_of(model))
        check_distinct_contacts(data, model)
        return data

    def share_K(self, P: sp.csc_matrix) -> None:
        """Let ``K`` be the leading n × n block of ``P`` (a matrix that holds K's values there, as
        the primal QP's Hessian does): the same values, one copy of the arrays alive instead of
        two (16 MB at 128²). The one change a formulation makes to its data, said here."""
        lead = pattern.leading(P, self.n)
        if lead.shape != self.K.shape or lead.nnz != self.K.nnz or not np.array_equal(lead.data, self.K.data):
            raise ValueError("share_K: P does not hold K as its leading block")
        self.K = lead

    @property
    def n(self) -> int:
        return self.K.shape[0]

    @property
    def m(self) -> int:
        return self.g0.shape[0]

    @property
    def floating(self) -> bool:
        """True if the two-sided supports leave rigid motions free (K singular)."""
        return self.modes.shape[1] > 0


def structure(model: Model) -> dict | None:
    """Inside :func:`plateqp.linalg.keep.sharing` (a sweep, the stiffness design), the memo the
    model keeps for its K and B (in ``Model.derived``, which the models adapted from it share:
    :func:`plateqp.studies.reuse.adapt_model`): what the scaled data, their formulation and their
    KKT check derive from K, B and the contact points' places alone, computed by the first solve
    and read by the next ones. None elsewhere: a single solve keeps nothing beside its Result."""
    if not shared() or model.contacts is None:
        return None
    K, B = model.K, model.contacts.B
    for k, b, kind, value in model.derived:
        if k is K and b is B and kind == "structure":
            return value
    value: dict = {}
    model.derived.append((K, B, "structure", value))
    return value


def matrix_free_refusal(model: Model, what: str = "this") -> str:
    """The one line that says a matrix-free half-space takes only its own route."""
    from ..model.soil import HALFSPACE_OPERATOR_FROM

    return (f"a half-space under {model.soil_rows.size} bed nodes (above {HALFSPACE_OPERATOR_FROM}) is held "
            f"matrix-free, solved in the contact forces by backend 'auto' or 'mprgp'; {what} needs the soil as "
            f"unknowns of K: use a coarser mesh or a smaller bed region")


def with_compliance(data: Scaled, model: Model) -> Scaled:
    """``data`` given the matrix-free soil's compliance (:attr:`Scaled.compliance`): s̃ = ρ̃ R̃ on
    the posts, s̃ = (D/L²) H_F R̃ on the bed's rows (F0/W = D/L²: ρ̃'s own scaling)."""
    p = model.scene.plate
    factor = p.D / max(p.a, p.b) ** 2
    H, rows = model.soil_flexibility, model.soil_rows
    posts = data.rho.copy()  # the posts' springs, 0 on the bed's rows
    rho = posts.copy()
    rho[rows] = factor * H.diagonal()

    def compliance(R: np.ndarray) -> np.ndarray:
        s = posts * R
        s[rows] += factor * (H @ R[rows])
        return s

    data.compliance = compliance
    data.rho = rho
    return data


def soil_of(model: Model) -> str | None:
    """The soil model whose surface has unknowns among K's (:attr:`Scaled.soil`), or None."""
    return model.scene.foundation.model if model.n_soil else None


def contact_spacing(model: Model, nearest: list | None = None) -> np.ndarray:
    """Distance from each contact point to the nearest other point that holds the plate: another
    contact point, a node whose deflection is prescribed (pins, edges), or a held edge's line;
    the plate's size where there is none. ``nearest``: a list that, where the points were
    searched, is given each point's distance to the nearest other point (contact point or held
    node, 0 for a point given twice): what :func:`check_distinct_contacts` would search again."""
    from scipy.spatial import cKDTree

    c = model.contacts
    nd = model.element.ndof_node
    held = model.fixed[model.fixed % nd == 0] // nd
    pts = np.vstack([c.xy, model.grid.node_xy()[held]])
    p = model.scene.plate
    if pts.shape[0] < 2:
        return np.full(c.m, max(p.a, p.b))
    # first within a cell's reach (a bed's nodes, posts on a grid: most points have a neighbour
    # there), on the grid's lattice where every point is one of its nodes, else by a tree whose
    # bounded search that reach prunes; then without bound for the points left
    reach = 1.5 * max(model.grid.hx, model.grid.hy)
    near = model.grid.nearest_other(pts, c.m, reach) if c.m >= LATTICE_SHARE * model.grid.n_nodes else None
    tree = None
    if near is None:
        tree = cKDTree(pts, balanced_tree=False, compact_nodes=False)
        near = tree.query(c.xy, k=2, distance_upper_bound=reach)[0][:, 1]
    far = ~np.isfinite(near)
    if far.any():
        tree = tree if tree is not None else cKDTree(pts, balanced_tree=False, compact_nodes=False)
        near[far] = tree.query(c.xy[far], k=2)[0][:, 1]
    if nearest is not None:
        nearest.append(near)
    s = np.where(near > 0, near, max(p.a, p.b))
    # an edge held along its length (w prescribed at both its nodes) holds the plate between its
    # nodes too: nearer than its nodes
    edges = model.grid.boundary_edges()[0]
    is_held = np.zeros(model.n_full // nd, dtype=bool)
    is_held[held] = True
    edges = edges[is_held[edges[:, 0]] & is_held[edges[:, 1]]]
    if edges.size:
        xy = model.grid.node_xy()
        a, b = xy[edges[:, 0]], xy[edges[:, 1]]
        k = min(4, len(edges))
        _, near = cKDTree(0.5 * (a + b)).query(c.xy, k=k)  # the nearest edges by midpoint, then exactly
        near = near.reshape(c.m, k)
        d = b[near] - a[near]
        t = np.clip(np.einsum("mkj,mkj->mk", c.xy[:, None] - a[near], d) / np.einsum("mkj,mkj->mk", d, d), 0, 1)
        dist = np.hypot(*(c.xy[:, None] - a[near] - t[..., None] * d).transpose(2, 0, 1)).min(axis=1)
        s = np.where(dist > 0, np.minimum(s, dist), s)
    return s


def deflection_scale(model: Model, floating: bool) -> tuple[float, float]:
    """The deflection scale W of :class:`Scaled` (what the plate's deflection can reach), and the
    part of it due to the load alone, 0.01 F L²/D.

    The largest of 0.01 F L²/D (F the applied load, Σ|f| on the deflection dofs), the prescribed
    displacements (slopes × L), the heaves (−g0 > 0) and, for a floating plate, every gap (it
    can settle onto its supports as a body). Settlements of a held plate do not count: one it
    cannot reach would only make every deflection small in scaled units.
    """
    p = model.scene.plate
    L = max(p.a, p.b)
    nd = model.element.ndof_node
    orders = np.array([dx + dy for dx, dy in model.element.node_dofs])
    w_dofs = np.arange(0, model.n_full, nd)  # the deflection dof of every node (kind 0)
    load = np.abs(model.f_full[w_dofs]).sum()
    prescribed = np.abs(model.values) * L ** orders[model.fixed % nd]
    g0 = model.contacts.g0
    gaps = np.abs(g0) if floating else np.maximum(-g0, 0.0)
    W_load = DEFLECTION_COEFFICIENT * load * L**2 / p.D
    W = max(W_load, prescribed.max(initial=0.0), gaps.max(initial=0.0))
    if W == 0.0:  # no load, nothing prescribed, only settlements: nothing moves, any scale will do
        W = np.abs(g0).max(initial=0.0) or 1e-3 * L
    return float(W), float(W_load)


#: Two contact points whose difference mode is this much more flexible than either point (row
#: difference of B squared, plus their springs, relative to one point's flexibility) cannot be told
#: apart: how the load splits between them is then decided by rounding (relative error ~ ε / this,
#: 2e-4). Two rigid supports 1e-9 of a cell apart split it 10 % differently from backend to
#: backend, every one passing the KKT check of the time. 1e-12 is reached by two rigid supports
#: about 2e-5 of a cell apart; closer than about half a cell the KKT check compares the
#: reactions with an exact solve instead (:func:`plateqp.kkt.close_pairs_error`).
DEPENDENT_ROWS = 1e-12


def check_distinct_contacts(data: Scaled, model: Model, nearest: np.ndarray | None = None) -> None:
    """ProblemError if two contact points are too close (and too stiff) to carry separate reactions.
    ``nearest``: each point's distance to the nearest other point among the contact points and
    more (:func:`contact_spacing`'s); where every one is beyond the closeness searched for, no two
    contact points are that close, and the search is not made again."""
    c = model.contacts
    if data.m < 2:
        return
    from scipy.spatial import cKDTree

    h = min(model.grid.hx, model.grid.hy)
    if nearest is not None and nearest.min(initial=np.inf) > 1e-3 * h:
        return
    memo = data.memo if data.memo is not None else {}
    if "close_points" not in memo:  # the points' places alone
        memo["close_points"] = cKDTree(c.xy).query_pairs(1e-3 * h, output_type="ndarray")
    pairs = memo["close_points"]
    if not len(pairs):
        return
    B = data.B.tocsr()
    kb = np.maximum(row_stiffness(data.K, B, "diagonal"), 1e-300)  # Σ B² diag K, as in kkt.close_pairs_error
    nb = np.maximum(np.asarray(B.multiply(B).sum(axis=1)).ravel(), 1e-300)
    for i, j in pairs:
        e = B[i] - B[j]
        rel = float(e.multiply(e).sum()) / max(nb[i], nb[j])
        flex = max(1.0 / kb[i] + data.rho[i], 1.0 / kb[j] + data.rho[j])
        ratio = (rel / max(kb[i], kb[j]) + data.rho[i] + data.rho[j]) / flex
        if ratio < DEPENDENT_ROWS:
            names = [f"supports.{c.index[k] + 1}" if c.source[k] == "support"
                     else f"the foundation node at ({c.xy[k, 0]:g}, {c.xy[k, 1]:g})" for k in (i, j)]
            d = float(np.hypot(*(c.xy[i] - c.xy[j])))
            raise ProblemError(
                f"{names[0]} and {names[1]} are {d:.2g} apart ({d / h:.1g} of a mesh cell) and too stiff to "
                f"tell apart: the plate's deflections there differ by {np.sqrt(rel):.0e} of the deflection, "
                "so how the load splits between them is decided by rounding, not by the plate; merge them "
                "into one support, move them apart, or make them elastic")
