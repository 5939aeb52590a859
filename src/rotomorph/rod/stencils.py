"""Bend–twist stencils and degree-of-freedom layout of a rod network.

A stencil couples an *incoming* edge ``e`` (pointing into the node) and an *outgoing* edge
``f`` (pointing away from it) at one node. Stored edges keep their own orientation; a sign
``+1`` means the stored edge already points the stencil's way, ``-1`` that the stencil sees it
reversed (tangent and ``m2`` flipped, twist angle negated, ``m1`` unchanged).

* An ordinary rod vertex (a non-branch node of degree two) gives one stencil with the rod's
  anisotropic bending stiffnesses.
* A branch node of degree ``k`` gives one stencil for each of the ``k(k-1)/2`` unique pairs of
  incident edges (the paper's junction rule, its ref. 70; the same pair rule as disMech's
  joints), each with isotropic stiffness, its own reference frames and reference twist.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.design.network import Network
from rotomorph.errors import InvalidDesignError


@dataclass(frozen=True, eq=False)
class Stencils:
    """Stencil topology of a network (arrays of length S).

    Attributes
    ----------
    nodes
        ``(S, 3)`` node indices ``[x0, x1, x2]``: far end of ``e``, shared node, far end of ``f``.
    edge_e, edge_f
        ``(S,)`` indices of the incoming and outgoing edges.
    sign_e, sign_f
        ``(S,)`` orientation signs (+1 or -1, as floats).
    junction
        ``(S,)`` True for branch-node pair stencils (isotropic stiffness).
    """

    nodes: IntArray
    edge_e: IntArray
    edge_f: IntArray
    sign_e: FloatArray
    sign_f: FloatArray
    junction: BoolArray

    @property
    def count(self) -> int:
        """Number of stencils S."""
        return len(self.edge_e)


_STENCILS: weakref.WeakKeyDictionary[Network, Stencils] = weakref.WeakKeyDictionary()
_LAYOUTS: weakref.WeakKeyDictionary[Network, DofLayout] = weakref.WeakKeyDictionary()


def build_stencils(network: Network) -> Stencils:
    """Stencils of ``network``: one per rod vertex, one per edge pair at each branch node.

    Cached per (immutable) network, so models that differ only in their natural fields (a
    heating ramp) share the topology work.

    Raises
    ------
    InvalidDesignError
        If a non-branch node has more than two edges, or the network has no stencil at all
        (a single segment cannot bend).
    """
    cached = _STENCILS.get(network)
    if cached is not None:
        return cached
    st = _build_stencils(network)
    _STENCILS[network] = st
    return st


def _build_stencils(network: Network) -> Stencils:
    edges = network.edges
    incident: list[list[int]] = [[] for _ in range(network.n_nodes)]
    for j, (a, b) in enumerate(edges):
        incident[a].append(j)
        incident[b].append(j)
    rows: list[tuple[int, int, int, int, int, float, float, bool]] = []
    for n, inc in enumerate(incident):
        k = len(inc)
        if k < 2:
            continue
        if not network.branch[n] and k > 2:
            raise InvalidDesignError(
                "Network.branch",
                f"node {n} joins {k} segments but is not flagged as a branch node",
            )
        pairs = (
            [_rod_vertex_pair(edges, n, inc[0], inc[1])]
            if k == 2 and not network.branch[n]
            else [(inc[p], inc[q]) for p in range(k) for q in range(p + 1, k)]
        )
        for a, b in pairs:
            sa = 1.0 if edges[a, 1] == n else -1.0
            sb = 1.0 if edges[b, 0] == n else -1.0
            far_a = edges[a, 0] if sa > 0 else edges[a, 1]
            far_b = edges[b, 1] if sb > 0 else edges[b, 0]
            rows.append((far_a, n, far_b, a, b, sa, sb, bool(network.branch[n])))
    if not rows:
        raise InvalidDesignError(
            "Network", "has no node joining two segments; a rod needs N >= 3 nodes"
        )
    arr = np.array([r[:5] for r in rows], dtype=np.int64)
    return Stencils(
        nodes=arr[:, :3].copy(),
        edge_e=arr[:, 3].copy(),
        edge_f=arr[:, 4].copy(),
        sign_e=np.array([r[5] for r in rows]),
        sign_f=np.array([r[6] for r in rows]),
        junction=np.array([r[7] for r in rows], dtype=bool),
    )


def _rod_vertex_pair(edges: IntArray, n: int, a: int, b: int) -> tuple[int, int]:
    """Order the two segments of a rod vertex so that one pointing into the node comes first.

    Segments are listed by index, so where a ring closes (node 0 of ``Network.ring``: segment 0
    leaves it, the last segment enters it) the pair would otherwise be seen reversed on both
    sides; ordered, the closing vertex is a vertex like any other, with the ring's orientation.
    """
    if edges[a, 1] != n and edges[b, 1] == n:
        return b, a
    return a, b


@dataclass(frozen=True, eq=False)
class DofLayout:
    """Interleaved global DOF numbering: each node's 3 coordinates, then the twist angles of
    the edges that start at it (a chain gets ``[x0, theta0, x1, theta1, ...]``, whose Hessian is
    banded with half-bandwidth 10)."""

    pos: IntArray
    theta: IntArray
    count: int

    def stencil_dofs(self, st: Stencils) -> IntArray:
        """``(S, 11)`` global DOFs in kernel order ``[x0, th_e, x1, th_f, x2]``."""
        p = self.pos[st.nodes]
        out = np.empty((st.count, 11), dtype=np.int64)
        for k in range(3):
            out[:, k] = p[:, 0] + k
            out[:, 4 + k] = p[:, 1] + k
            out[:, 8 + k] = p[:, 2] + k
        out[:, 3] = self.theta[st.edge_e]
        out[:, 7] = self.theta[st.edge_f]
        return out

    def edge_dofs(self, edges: IntArray) -> IntArray:
        """``(E, 6)`` global DOFs ``[x_a, x_b]`` of each edge's end nodes."""
        p = self.pos[edges]
        return np.concatenate([p[:, :1] + np.arange(3), p[:, 1:] + np.arange(3)], axis=1)


def dof_layout(network: Network) -> DofLayout:
    """Node-interleaved DOF layout of ``network`` (see :class:`DofLayout`); cached."""
    cached = _LAYOUTS.get(network)
    if cached is not None:
        return cached
    layout = _dof_layout(network)
    _LAYOUTS[network] = layout
    return layout


def _dof_layout(network: Network) -> DofLayout:
    starts = np.bincount(network.edges[:, 0], minlength=network.n_nodes)
    sizes = 3 + starts
    pos = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    order = np.argsort(network.edges[:, 0], kind="stable")
    rank = np.empty(network.n_edges, dtype=np.int64)
    first = network.edges[order, 0]
    # rank of each edge among the edges starting at the same node
    group_start = np.searchsorted(first, first, side="left")
    rank[order] = np.arange(network.n_edges) - group_start
    theta = pos[network.edges[:, 0]] + 3 + rank
    return DofLayout(pos=pos, theta=theta.astype(np.int64), count=int(sizes.sum()))
