r"""Contact of a network whose segments are printed stacks: one capsule per layer, one barrier.

A segment of a lattice printed in N layers presents N capsules of the layer radius r, their
centre lines offset by :math:`o_k` along the segment's material director m1
(:mod:`rotomorph.contact.stack`). :class:`StackedContact` binds a
:class:`~rotomorph.contact.potential.ContactPotential` to the *layer network* (segment
``v = k E + e`` is layer k of segment e, with its own two end points) with the stack's
exclusion, and maps its energy, gradient and Hessian to the rod's degrees of freedom: the node
positions and the twist angle θ of every segment, through

.. math::  P = x_a + o_k\, m_1(x_a, x_b, \theta) \quad (\text{and } x_b + o_k m_1),

with m1 the material director of the rod model (reference director transported in time from
the last accepted iterate, turned by θ; :mod:`rotomorph.solve.objective`). Derivatives are
taken at that base configuration, where the frames are re-based (every gradient and Hessian
of a Newton iteration is evaluated there). With :math:`e = x_b - x_a`, :math:`L = |e|`,
:math:`t = e/L` and :math:`m_2 = t \times m_1`,

.. math::

   \delta m_1 = -\,t\,(m_1\cdot\delta e)/L + m_2\,\delta\theta,

and for a vector G the second variation of :math:`G\cdot m_1` is

.. math::

   \partial^2_{\theta\theta} = -G\cdot m_1,\quad
   \partial^2_{\theta e} = -(G\cdot t)\,m_2/L,\quad
   \partial^2_{ee} = \big[(G\cdot t)(t m_1^T + m_1 t^T)
     - \tfrac12 (m_1 (PG)^T + (PG) m_1^T)\big]/L^2,

:math:`P = I - t t^T` (the minimal-rotation transport expanded to second order; checked
against finite differences of the rod model's own frames in the tests). The contact Hessian
is :math:`J^T H J` plus these terms contracted with :math:`\sum_k o_k (g_{P_0} + g_{P_1})`;
the positive semidefinite (Gauss–Newton) mode leaves the second, indefinite part out.

Step bounds and the check of a line-search trial act on the layer points along the straight
path between their positions at the two configurations: a continuous deformation of the
layers during which no two that may touch come into contact, so the end is reached without
any layer passing through another (the layers of one segment are one body, never tested
against each other).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numba import njit

from rotomorph._typing import FloatArray, IntArray
from rotomorph.contact.broadphase import stack_exclusion_masks, stack_near_pairs
from rotomorph.contact.friction import FrictionLag
from rotomorph.contact.potential import (
    DEFAULT_ACTIVATION,
    Contact,
    ContactPotential,
    HessianBlocks,
    InfeasibleContactError,
)
from rotomorph.contact.stack import Stack, layer_edges, layer_points, stack_exclusion
from rotomorph.design.network import Network
from rotomorph.errors import InvalidParameterError

__all__ = ["DofBlocks", "StackedContact", "StateLike"]

#: A configuration for the measures of a stacked contact: a rod ``State`` (positions and
#: material frames) or ``(positions (N, 3), material directors m1 (E, 3))``.
StateLike = Any

#: Width of a block: two segments' node coordinates and twist angles.
WIDTH = 14
#: Most layers whose layer-pair exclusions fit the broad phase's 64-bit masks.
MASK_LAYERS = 7


@dataclass(frozen=True, eq=False)
class DofBlocks:
    """A contact Hessian as dense blocks on generalised coordinates.

    Coordinate ``3 i + k`` is node i's k-th position coordinate (``i < n_nodes``), coordinate
    ``3 n_nodes + e`` the twist angle of segment e. Block ``b`` (``WIDTH`` x ``WIDTH``) couples
    the coordinates ``dofs[b]`` (``-1``: unused); ``keys[b]`` names the block (the same key
    always means the same coordinates), so positions in a sparse pattern can be remembered.
    """

    n_nodes: int
    n_edges: int
    dofs: IntArray  # (B, WIDTH)
    blocks: FloatArray  # (B, WIDTH, WIDTH)
    keys: IntArray  # (B,)

    def triplets(self) -> tuple[IntArray, IntArray, FloatArray]:
        """Rows, columns and values of the non-zero entries (generalised coordinates)."""
        rows = np.repeat(self.dofs, WIDTH, axis=1).ravel()
        cols = np.tile(self.dofs, (1, WIDTH)).ravel()
        vals = self.blocks.reshape(-1)
        keep = (rows >= 0) & (cols >= 0) & (vals != 0)
        return rows[keep], cols[keep], vals[keep]


def _state(x: StateLike) -> tuple[FloatArray, FloatArray]:
    """(positions, m1) of a State or a pair."""
    if hasattr(x, "material_directors") and hasattr(x, "positions"):
        return np.asarray(x.positions, dtype=float), x.material_directors()[0]
    if isinstance(x, tuple) and len(x) == 2:
        return np.asarray(x[0], dtype=float), np.asarray(x[1], dtype=float)
    raise InvalidParameterError(
        "state",
        "a stacked contact needs the material frames: pass the rod State (or a tuple of "
        "positions and material directors m1), not positions alone",
    )


class StackedContact:
    """:class:`~rotomorph.contact.potential.Contact` of a network of printed stacks.

    Parameters
    ----------
    contact
        The settings; ``contact.stack`` holds the layer offsets (more than one layer).
    network
        The printed network (rod centre lines).
    directors
        Material director m1 of every segment as printed ``(E, 3)`` (decides which layers
        are fused as printed).
    force_scale
        Typical nodal force (N) for the default barrier stiffness.
    """

    def __init__(
        self,
        contact: Contact,
        network: Network,
        directors: FloatArray,
        force_scale: float = 1.0,
    ) -> None:
        stack: Stack = contact.stack
        self.contact = contact
        self.network = network
        self.stack = stack
        self.edges = np.ascontiguousarray(network.edges, dtype=np.int64)
        ne = network.n_edges
        self.n_nodes, self.n_edges = network.n_nodes, ne
        m1 = np.asarray(directors, dtype=float)
        if m1.shape != (ne, 3) or not np.all(np.isfinite(m1)):
            raise InvalidParameterError("directors", f"must be finite with shape ({ne}, 3)")
        self.offsets = np.ascontiguousarray(stack.offsets, dtype=float)
        radius = contact.radii(ne)
        dhat = float(contact.activation_distance or DEFAULT_ACTIVATION * 2.0 * float(radius.min()))
        layer_net, excluded, masks = _layer_network(network, m1, radius, contact, dhat)
        inner = replace(contact, radius=np.tile(radius, stack.count), stack=Stack())

        def broad_phase(x0, x1, edges, incident, seg_share, node_share, keys):  # type: ignore[no-untyped-def]
            return stack_near_pairs(x0, x1, edges, seg_share, node_share, n_edges=ne, masks=masks)

        #: the contact of the layer network (virtual points ``2 (k E + e) + end``); the broad
        #: phase through the network's segments holds a layer pair's exclusion in one bit of a
        #: 64-bit mask (up to 7 layers; beyond, the layer network is swept as it is)
        self.layers = ContactPotential(
            inner,
            layer_net,
            force_scale,
            excluded=excluded,
            broad_phase=broad_phase if stack.count <= MASK_LAYERS else None,
        )
        self.kappa, self.dhat = self.layers.kappa, self.layers.dhat
        self.radius = radius

    # ------------------------------------------------------------------ geometry
    def points(self, positions: FloatArray, directors: FloatArray) -> FloatArray:
        """The layer points ``(2 N E, 3)`` (mm) of a configuration."""
        out = np.empty((2 * len(self.offsets) * self.n_edges, 3))
        _layer_points(
            np.ascontiguousarray(positions, dtype=float),
            self.edges,
            np.ascontiguousarray(directors, dtype=float),
            self.offsets,
            out,
        )
        return out

    # ------------------------------------------------------------------ energy
    def evaluate_blocks(
        self,
        positions: FloatArray,
        frames: tuple[FloatArray, FloatArray, FloatArray],
        need_grad: bool,
        need_hess: int,
    ) -> tuple[float, FloatArray | None, FloatArray | None, DofBlocks | None]:
        """Energy (N mm), gradient on the positions ``(N, 3)`` (N) and on the twist angles
        ``(E,)`` (N mm), and the Hessian's blocks, at a configuration with material frames
        ``frames = (t, m1, m2)`` (each ``(E, 3)``). Derivatives are those at the base of the
        rod objective (module docstring). The energy is inf when layers touch."""
        t, m1, m2 = frames
        pts = self.points(positions, m1)
        energy, g, blocks = self.layers.evaluate_blocks(
            pts, need_grad or bool(need_hess), need_hess
        )
        if not np.isfinite(energy):
            return np.inf, None, None, None
        length = np.linalg.norm(positions[self.edges[:, 1]] - positions[self.edges[:, 0]], axis=1)
        args = (
            self.edges,
            np.ascontiguousarray(t, dtype=float),
            np.ascontiguousarray(m1, dtype=float),
            np.ascontiguousarray(m2, dtype=float),
            np.ascontiguousarray(length),
            self.offsets,
        )
        gx = gth = None
        gsum = None
        if g is not None:
            gx = np.zeros((self.n_nodes, 3))
            gth = np.zeros(self.n_edges)
            gsum = np.zeros((self.n_edges, 3))  # sum_k o_k (g_P0 + g_P1) per segment
            _pull_gradient(np.ascontiguousarray(g), *args, gx, gth, gsum)
        out = None
        if need_hess:
            assert blocks is not None and gsum is not None
            out = self._pull_hessian(blocks, gsum, need_hess, args)
        return float(energy), (gx if need_grad else None), (gth if need_grad else None), out

    def _pull_hessian(
        self, blocks: HessianBlocks, gsum: FloatArray, need_hess: int, args: tuple
    ) -> DofBlocks:
        edges, t, m1, m2, length, offsets = args
        dofs, out, keys = _pull_hessian(
            np.ascontiguousarray(blocks.quads, dtype=np.int64),
            np.ascontiguousarray(blocks.pair),
            np.ascontiguousarray(blocks.nodes, dtype=np.int64),
            np.ascontiguousarray(blocks.node),
            gsum,
            need_hess == 1,  # the indefinite part of the frames' second variation
            self.n_nodes,
            edges,
            t,
            m1,
            m2,
            length,
            offsets,
        )
        return DofBlocks(
            n_nodes=self.n_nodes, n_edges=self.n_edges, dofs=dofs, blocks=out, keys=keys
        )

    # ------------------------------------------------------------------ steps
    def step_bound(
        self,
        start: tuple[FloatArray, FloatArray],
        end: tuple[FloatArray, FloatArray],
        close_fraction: float = 0.9,
    ) -> float:
        """Provably free fraction of the straight path of the layer points from the
        configuration ``start`` to ``end`` (each ``(positions, m1)``)."""
        p0 = self.points(*start)
        return self.layers.step_bound(p0, self.points(*end) - p0, close_fraction)

    def path_is_free(
        self, start: tuple[FloatArray, FloatArray], end: tuple[FloatArray, FloatArray]
    ) -> bool:
        """Whether the layer points' straight path from ``start`` to ``end`` never touches."""
        return self.layers.path_is_free(self.points(*start), self.points(*end))

    # ------------------------------------------------------------------ friction
    def set_lag(self, x0: StateLike) -> None:
        """Lag friction at configuration ``x0`` (a State or ``(positions, m1)``), or take the
        settings' own ``friction_lag`` (one of :meth:`lag`)."""
        self.layers.set_lag(self.points(*_state(x0)))

    @property
    def friction_lag(self) -> FrictionLag | None:
        """The lagged friction of the current solve, on the layer network (None without)."""
        return self.layers.friction_lag

    def lag(self, x0: StateLike, at: StateLike | None = None) -> FrictionLag:
        """:meth:`ContactPotential.lag` of the layer points: the contacts carrying force at
        configuration ``at`` (default ``x0``; States or ``(positions, m1)``), slips measured
        from ``x0``."""
        end = None if at is None else self.points(*_state(at))
        return self.layers.lag(self.points(*_state(x0)), at=end)

    # ------------------------------------------------------------------ measures
    def forces(self, x: StateLike) -> FloatArray:
        """Contact force on every node ``(N, 3)`` (N) at a configuration (a State or
        ``(positions, m1)``): minus the barrier gradient, the layers' forces carried to the
        centre line (their moments about it act on the twist angles and tangents)."""
        pos, m1 = _state(x)
        g = self.layers.forces(self.points(pos, m1))
        out = np.zeros((self.n_nodes, 3))
        ne = self.n_edges
        v = np.arange(len(g))
        np.add.at(out, self.edges[(v // 2) % ne, v % 2], g)
        return out

    def obstacle_forces(self, x: StateLike) -> list[FloatArray]:
        """Resultant contact force on each obstacle ``(3,)`` (N), in ``contact.obstacles``
        order; friction is not included."""
        return self.layers.obstacle_forces(self.points(*_state(x)))

    def distances(self, x: StateLike) -> tuple[FloatArray, FloatArray]:
        """Layer centre-line distances of the pairs near contact and their contact distances
        ``r_a + r_b`` (mm); floors as layer-point heights and radii."""
        return self.layers.distances(self.points(*_state(x)))

    def clearance(self, x: StateLike) -> float:
        """Smallest ``d / (r_a + r_b)`` over the layer pairs allowed to touch and obstacles."""
        return self.layers.clearance(self.points(*_state(x)))

    def contact_ratios(self, x: StateLike) -> FloatArray:
        """``d / (r_a + r_b)`` of every layer pair (and floor point) carrying contact force
        (:meth:`ContactPotential.contact_ratios
        <rotomorph.contact.potential.ContactPotential.contact_ratios>` of the layers)."""
        return self.layers.contact_ratios(self.points(*_state(x)))

    def active_contacts(self, x: StateLike) -> int:
        """Layer pairs (and floor points) inside the activation distance."""
        return self.layers.active_contacts(self.points(*_state(x)))

    def check_admissible(self, x: StateLike, field: str = "initial") -> None:
        """Raise :class:`InfeasibleContactError` if a layer touches or interpenetrates."""
        try:
            self.layers.check_admissible(self.points(*_state(x)), field)
        except InfeasibleContactError as err:
            raise InfeasibleContactError(field, f"(layers of the printed stack) {err}") from None


#: the layer network, its exclusion and the network's fully excluded pairs, per network and
#: settings (the solves of a ramp bind the same network once per step)
_LAYERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _layer_network(
    network: Network, directors: FloatArray, radius: FloatArray, contact: Contact, dhat: float
) -> tuple[Network, IntArray, tuple[IntArray, IntArray, IntArray]]:
    """The layer network of ``network`` as printed, the sorted keys of its layer pairs that
    never touch, and that exclusion per segment pair
    (:func:`~rotomorph.contact.broadphase.stack_exclusion_masks`), remembered per network and
    settings (shared, never written to)."""
    stack = contact.stack
    per = _LAYERS.setdefault(network, {})
    key = (
        stack.offsets, directors.tobytes(), radius.tobytes(), dhat, contact.reach,
        contact.self_contact,
    )  # fmt: skip
    if key not in per:
        edges = np.ascontiguousarray(network.edges, dtype=np.int64)
        ne, layers = len(edges), stack.count
        net = Network(
            layer_points(network.nodes, edges, directors, stack.offsets),
            layer_edges(ne, layers),
        )
        if contact.self_contact:
            excluded = stack_exclusion(
                network.nodes, edges, directors, radius, stack, dhat, contact.reach
            )
        else:
            excluded = np.zeros(0, dtype=np.int64)
        empty = np.zeros(0, dtype=np.int64)
        masks = (
            stack_exclusion_masks(excluded, ne, layers)
            if layers <= MASK_LAYERS
            else (empty, empty.copy(), empty.copy())
        )
        for arr in (excluded, *masks):
            arr.setflags(write=False)
        per[key] = (net, excluded, masks)
    return per[key]  # type: ignore[no-any-return]


@njit(cache=True)
def _pull_hessian(
    quads, pair, nodes, node, gsum, geometric, n_nodes, edges, t, m1, m2, length, offsets
):  # pragma: no cover - compiled
    """The Hessian of the layer points' blocks on the rod's coordinates (module docstring):
    7 x 7 blocks of single segments (a pair block against an obstacle, the floor blocks, the
    frames' second variation when ``geometric``) summed per segment, 14 x 14 blocks of two
    segments (layer pairs and their end points) summed per segment pair. Returns the blocks'
    generalised coordinates ``(B, 14)``, the blocks ``(B, 14, 14)`` and their keys."""
    ne = edges.shape[0]
    nv = 2 * offsets.shape[0] * ne
    seg_a, seg_b, pair14 = _pull_pairs(quads, pair, nv, edges, t, m1, m2, length, offsets)
    seg7 = np.zeros((ne, 7, 7))
    if nodes.shape[0]:
        node7 = _pull_nodes(nodes, node, edges, t, m1, m2, length, offsets)
        for q in range(nodes.shape[0]):
            e = (nodes[q] // 2) % ne
            for r in range(7):
                for c in range(7):
                    seg7[e, r, c] += node7[q, r, c]
    n_two = 0
    for p in range(seg_a.shape[0]):
        if seg_b[p] < 0:
            e = seg_a[p]
            for r in range(7):
                for c in range(7):
                    seg7[e, r, c] += pair14[p, r, c]
        else:
            n_two += 1
    if geometric:
        _geometric(gsum, edges, t, m1, m2, length, offsets, seg7)
    # the two-segment blocks, summed per segment pair (in key order)
    two_keys = np.empty(n_two, dtype=np.int64)
    two_rows = np.empty(n_two, dtype=np.int64)
    j = 0
    for p in range(seg_a.shape[0]):
        if seg_b[p] >= 0:
            two_keys[j] = seg_a[p] * (ne + 1) + seg_b[p]
            two_rows[j] = p
            j += 1
    order = np.argsort(two_keys, kind="mergesort")
    n_pairs = 0
    for i in range(n_two):
        if i == 0 or two_keys[order[i]] != two_keys[order[i - 1]]:
            n_pairs += 1
    used = np.zeros(ne, dtype=np.bool_)
    n_used = 0
    for e in range(ne):
        for r in range(7):
            for c in range(7):
                if seg7[e, r, c] != 0.0:
                    used[e] = True
        if used[e]:
            n_used += 1
    total = n_used + n_pairs
    dofs = np.full((total, 14), -1, dtype=np.int64)
    out = np.zeros((total, 14, 14))
    keys = np.empty(total, dtype=np.int64)
    b = 0
    for e in range(ne):
        if not used[e]:
            continue
        _segment_dofs(dofs, b, 0, e, edges, n_nodes)
        for r in range(7):
            for c in range(7):
                out[b, r, c] = seg7[e, r, c]
        keys[b] = e * (ne + 1) + ne
        b += 1
    for i in range(n_two):
        p = two_rows[order[i]]
        if i == 0 or two_keys[order[i]] != two_keys[order[i - 1]]:
            if i > 0:
                b += 1
            keys[b] = two_keys[order[i]]
            _segment_dofs(dofs, b, 0, seg_a[p], edges, n_nodes)
            _segment_dofs(dofs, b, 1, seg_b[p], edges, n_nodes)
        for r in range(14):
            for c in range(14):
                out[b, r, c] += pair14[p, r, c]
    return dofs, out, keys


@njit(cache=True)
def _segment_dofs(dofs, b, slot, e, edges, n_nodes):  # pragma: no cover - compiled
    """Generalised coordinates of segment e (its nodes' positions, its twist angle) into
    slot ``slot`` of block row ``b``."""
    base = 7 * slot
    for k in range(3):
        dofs[b, base + k] = 3 * edges[e, 0] + k
        dofs[b, base + 3 + k] = 3 * edges[e, 1] + k
    dofs[b, base + 6] = 3 * n_nodes + e


@njit(cache=True)
def _layer_points(x, edges, m1, offsets, out):  # pragma: no cover - compiled
    ne = edges.shape[0]
    for k in range(offsets.shape[0]):
        o = offsets[k]
        for e in range(ne):
            v = 2 * (k * ne + e)
            a, b = edges[e, 0], edges[e, 1]
            for c in range(3):
                out[v, c] = x[a, c] + o * m1[e, c]
                out[v + 1, c] = x[b, c] + o * m1[e, c]


@njit(cache=True)
def _pull_gradient(g, edges, t, m1, m2, length, offsets, gx, gth, gsum):  # pragma: no cover
    """Gradient on nodes and twist angles from the layer points' gradient ``g`` (module
    docstring); ``gsum`` receives sum_k o_k (g_P0 + g_P1) per segment."""
    ne = edges.shape[0]
    for k in range(offsets.shape[0]):
        o = offsets[k]
        for e in range(ne):
            v = 2 * (k * ne + e)
            a, b = edges[e, 0], edges[e, 1]
            for c in range(3):
                gx[a, c] += g[v, c]
                gx[b, c] += g[v + 1, c]
                gsum[e, c] += o * (g[v, c] + g[v + 1, c])
    for e in range(ne):
        a, b = edges[e, 0], edges[e, 1]
        tg = t[e, 0] * gsum[e, 0] + t[e, 1] * gsum[e, 1] + t[e, 2] * gsum[e, 2]
        s = tg / length[e]
        for c in range(3):
            gx[a, c] += s * m1[e, c]
            gx[b, c] -= s * m1[e, c]
        gth[e] += m2[e, 0] * gsum[e, 0] + m2[e, 1] * gsum[e, 1] + m2[e, 2] * gsum[e, 2]


@njit(cache=True)
def _pull_pairs(quads, pair, nv, edges, t, m1, m2, length, offsets):  # pragma: no cover
    """J^T H J (14 x 14) of every pair block on the 4 layer points ``quads``: slot 0 holds
    the segment of the first point, slot 1 that of the third (-1: an obstacle, or the same
    segment, then folded into slot 0). A point's Jacobian is the identity on its own node
    plus rank-one terms (module docstring), so H J and J^T (H J) are formed from H's
    products with t and m2 instead of dense 3 x 7 blocks."""
    ne = edges.shape[0]
    n = quads.shape[0]
    seg_a = np.empty(n, dtype=np.int64)
    seg_b = np.empty(n, dtype=np.int64)
    out = np.zeros((n, 14, 14))
    slot = np.empty(4, dtype=np.int64)
    seg = np.empty(4, dtype=np.int64)
    end = np.empty(4, dtype=np.int64)
    off = np.empty(4)
    ht = np.empty((4, 12))  # H[:, point i] @ t of i's segment
    hm = np.empty((4, 12))  # H[:, point i] @ m2
    HJ = np.empty((12, 14))
    tj = np.empty((4, 14))  # t . HJ[rows of point i]
    mj = np.empty((4, 14))  # m2 . HJ[rows of point i]
    for p in range(n):
        sa = -1
        sb = -1
        for i in range(4):
            v = quads[p, i]
            if v >= nv:
                slot[i] = -1
                continue
            e = (v // 2) % ne
            seg[i] = e
            end[i] = v % 2
            off[i] = offsets[(v // 2) // ne]
            if sa < 0:
                sa = e
            if e == sa:
                slot[i] = 0
            else:
                sb = e
                slot[i] = 1
        if sb >= 0 and sb < sa:  # lower segment first
            sa, sb = sb, sa
            for i in range(4):
                if slot[i] >= 0:
                    slot[i] = 1 - slot[i]
        seg_a[p] = sa
        seg_b[p] = sb
        for i in range(4):
            if slot[i] < 0:
                continue
            e = seg[i]
            for r in range(12):
                a0 = pair[p, r, 3 * i]
                a1 = pair[p, r, 3 * i + 1]
                a2 = pair[p, r, 3 * i + 2]
                ht[i, r] = a0 * t[e, 0] + a1 * t[e, 1] + a2 * t[e, 2]
                hm[i, r] = a0 * m2[e, 0] + a1 * m2[e, 1] + a2 * m2[e, 2]
        # H J: columns (slot s: x_a 0..2, x_b 3..5, theta 6)
        for r in range(12):
            for c in range(14):
                HJ[r, c] = 0.0
        for i in range(4):
            if slot[i] < 0:
                continue
            e = seg[i]
            base = 7 * slot[i]
            s_i = off[i] / length[e]
            col = base + 3 * end[i]
            for r in range(12):
                for c in range(3):
                    HJ[r, col + c] += pair[p, r, 3 * i + c]
                    w = s_i * m1[e, c] * ht[i, r]
                    HJ[r, base + c] += w
                    HJ[r, base + 3 + c] -= w
                HJ[r, base + 6] += off[i] * hm[i, r]
        # J^T (H J)
        for i in range(4):
            if slot[i] < 0:
                continue
            e = seg[i]
            for c in range(14):
                tj[i, c] = (
                    t[e, 0] * HJ[3 * i, c] + t[e, 1] * HJ[3 * i + 1, c] + t[e, 2] * HJ[3 * i + 2, c]
                )
                mj[i, c] = (
                    m2[e, 0] * HJ[3 * i, c]
                    + m2[e, 1] * HJ[3 * i + 1, c]
                    + m2[e, 2] * HJ[3 * i + 2, c]
                )
        for i in range(4):
            if slot[i] < 0:
                continue
            e = seg[i]
            base = 7 * slot[i]
            s_i = off[i] / length[e]
            row = base + 3 * end[i]
            for c in range(14):
                for r in range(3):
                    out[p, row + r, c] += HJ[3 * i + r, c]
                    w = s_i * m1[e, r] * tj[i, c]
                    out[p, base + r, c] += w
                    out[p, base + 3 + r, c] -= w
                out[p, base + 6, c] += off[i] * mj[i, c]
    return seg_a, seg_b, out


@njit(cache=True)
def _pull_nodes(nodes, node, edges, t, m1, m2, length, offsets):  # pragma: no cover
    """J^T H J (7 x 7) of the floor blocks (3 x 3) of layer points ``nodes`` (structured as
    :func:`_pull_pairs`)."""
    ne = edges.shape[0]
    out = np.zeros((nodes.shape[0], 7, 7))
    HJ = np.empty((3, 7))
    ht = np.empty(3)
    hm = np.empty(3)
    tj = np.empty(7)
    mj = np.empty(7)
    for q in range(nodes.shape[0]):
        v = nodes[q]
        e = (v // 2) % ne
        o = offsets[(v // 2) // ne]
        col = 3 * (v % 2)
        sc = o / length[e]
        for r in range(3):
            ht[r] = node[q, r, 0] * t[e, 0] + node[q, r, 1] * t[e, 1] + node[q, r, 2] * t[e, 2]
            hm[r] = node[q, r, 0] * m2[e, 0] + node[q, r, 1] * m2[e, 1] + node[q, r, 2] * m2[e, 2]
        for r in range(3):
            for c in range(7):
                HJ[r, c] = 0.0
            for c in range(3):
                HJ[r, col + c] += node[q, r, c]
                w = sc * m1[e, c] * ht[r]
                HJ[r, c] += w
                HJ[r, 3 + c] -= w
            HJ[r, 6] = o * hm[r]
        for c in range(7):
            tj[c] = t[e, 0] * HJ[0, c] + t[e, 1] * HJ[1, c] + t[e, 2] * HJ[2, c]
            mj[c] = m2[e, 0] * HJ[0, c] + m2[e, 1] * HJ[1, c] + m2[e, 2] * HJ[2, c]
        for c in range(7):
            for r in range(3):
                out[q, col + r, c] += HJ[r, c]
                w = sc * m1[e, r] * tj[c]
                out[q, r, c] += w
                out[q, 3 + r, c] -= w
            out[q, 6, c] += o * mj[c]
    return out


@njit(cache=True)
def _geometric(gsum, edges, t, m1, m2, length, offsets, seg7):  # pragma: no cover
    """Add the second variation of gsum . m1 (module docstring) to each segment's block."""
    for e in range(edges.shape[0]):
        G = gsum[e]
        if G[0] == 0.0 and G[1] == 0.0 and G[2] == 0.0:
            continue
        L = length[e]
        gt = G[0] * t[e, 0] + G[1] * t[e, 1] + G[2] * t[e, 2]
        gm = G[0] * m1[e, 0] + G[1] * m1[e, 1] + G[2] * m1[e, 2]
        pg = np.empty(3)
        for c in range(3):
            pg[c] = G[c] - gt * t[e, c]
        for r in range(3):
            for c in range(3):
                h = (
                    gt * (t[e, r] * m1[e, c] + m1[e, r] * t[e, c])
                    - 0.5 * (m1[e, r] * pg[c] + pg[r] * m1[e, c])
                ) / (L * L)
                seg7[e, r, c] += h
                seg7[e, 3 + r, 3 + c] += h
                seg7[e, r, 3 + c] -= h
                seg7[e, 3 + r, c] -= h
            hp = -gt * m2[e, r] / L  # d2/(d theta d e_r)
            seg7[e, r, 6] -= hp
            seg7[e, 6, r] -= hp
            seg7[e, 3 + r, 6] += hp
            seg7[e, 6, 3 + r] += hp
        seg7[e, 6, 6] -= gm
